"""`RadarTracker` against `seqsmooth track` bit for bit (every method, per-row sigmas, missing
components, bearings), against filterpy's `ExtendedKalmanFilter`, and its refusals."""

from __future__ import annotations

import csv
import subprocess

import numpy as np
import pytest

import seqsmooth as ss
from conftest import cli_path
from seqsmooth.errors import InvalidInputError, ParameterError

SR, SA = 10.0, 1e-3


def radar_pass(rng: np.random.Generator, n: int = 300, site=(0.0, 0.0, 0.0), missing=0.03):
    """`n` rows of a constant-velocity target from `site`: Unix-epoch times at steps
    U(0.5, 1.5) s, σ 10 m and 1 mrad, a fraction `missing` of components missing (NaN)."""
    t = 1.7e9 + np.cumsum(rng.uniform(0.5, 1.5, n))
    s = t - 1.7e9
    x = 20_000.0 + 150.0 * s - site[0]
    y = -8_000.0 + 60.0 * s - site[1]
    z = 3_000.0 - 4.0 * s - site[2]
    r = np.sqrt(x * x + y * y + z * z)
    rows = np.column_stack([r, np.arctan2(y, x), np.arcsin(z / r)])
    rows += rng.standard_normal((n, 3)) * [SR, SA, SA]
    rows[rng.random((n, 3)) < missing] = np.nan
    return t, rows


def run_track(tmp_path, t, rows, *args, sigmas=None):
    """`seqsmooth track` on the rows (NaN written as an empty cell); its numbers, NaN where a
    cell is empty, and its flag column: `(states, sigmas, nis, flags)`."""
    source = tmp_path / "radar.csv"
    cell = lambda v: "" if np.isnan(v) else repr(float(v))  # noqa: E731
    header = "t,range,azimuth,elevation" + (",sr,sa" if sigmas is not None else "")
    with open(source, "w") as f:
        f.write(header + "\n")
        for i in range(len(t)):
            cells = [repr(float(t[i]))] + [cell(v) for v in rows[i]]
            if sigmas is not None:
                cells += [cell(sigmas[0][i]), cell(sigmas[1][i])]
            f.write(",".join(cells) + "\n")
    extra = ["--sigma-range-col", "sr", "--sigma-angle-col", "sa"] if sigmas is not None else []
    out = subprocess.run(
        [str(cli_path()), "track", str(source), "--sigma-range", str(SR)]
        + ["--sigma-angle", str(SA), *extra, *args],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    body = list(csv.reader(out.splitlines()))[1:]
    table = np.array([[float(c) if c else np.nan for c in r[1:-1]] for r in body])
    flags = np.array([r[-1] for r in body], dtype="<U7")
    return table[:, :6], table[:, 6:12], table[:, 12], flags


def tracked(tracker, t, rows, **kw):
    """Every row through `update_many`, the smoother's rows from `finish()`; σ from the
    covariance's diagonal as the command writes it."""
    x, p, nis, flags = tracker.update_many(t, rows[:, 0], rows[:, 1], rows[:, 2], **kw)
    held, xs, ps, ns, fs = tracker.finish()
    x[held], p[held], nis[held], flags[held] = xs, ps, ns, fs
    sigma = np.sqrt(np.maximum(np.diagonal(p, axis1=1, axis2=2), 0.0))
    return x, sigma, nis, flags


def same(a, b):
    if a.dtype.kind == "U" or b.dtype.kind == "U":
        return a.dtype == b.dtype and np.array_equal(a, b)
    return np.array_equal(np.isnan(a), np.isnan(b)) and np.array_equal(
        np.nan_to_num(a).view(np.int64), np.nan_to_num(b).view(np.int64)
    )


METHODS = [
    ({"method": "kalman", "q": 0.5}, ["--method", "kalman", "--q", "0.5"]),
    ({"method": "kalman"}, ["--method", "kalman"]),
    (
        {"method": "fading", "theta": 0.9, "tau": 1.0},
        ["--method", "fading", "--theta", "0.9", "--tau", "1"],
    ),
    (
        {"method": "fading", "theta": 0.9, "tau": 0.5},
        ["--method", "fading", "--theta", "0.9", "--tau", "0.5"],
    ),
    (
        {"method": "fading", "theta_per_update": 0.8},
        ["--method", "fading", "--theta-per-update", "0.8"],
    ),
    ({"method": "smooth", "q": 0.2}, ["--method", "smooth", "--q", "0.2"]),
    ({"method": "smooth", "q": 0.2, "lag": 7}, ["--method", "smooth", "--q", "0.2", "--lag", "7"]),
    ({"method": "smooth", "q": 0.2, "lag": 0}, ["--method", "smooth", "--q", "0.2", "--lag", "0"]),
    ({"method": "window", "window": 12}, ["--method", "window", "--window", "12"]),
    (
        {"method": "kalman", "model": "coordinated-turn"},
        ["--method", "kalman", "--model", "coordinated-turn"],
    ),
    (
        {"method": "kalman", "model": "coordinated-turn", "q": 0.5, "turn_rate_noise": 1e-3},
        ["--method", "kalman", "--model", "coordinated-turn", "--q", "0.5"]
        + ["--turn-rate-noise", "1e-3"],
    ),
    (
        {"method": "smooth", "model": "constant-acceleration", "q": 0.1, "lag": 5},
        ["--method", "smooth", "--model", "constant-acceleration", "--q", "0.1", "--lag", "5"],
    ),
    (
        {"method": "kalman", "model": "singer", "manoeuvre_alpha": 0.05, "manoeuvre_variance": 4.0},
        ["--method", "kalman", "--model", "singer", "--manoeuvre-alpha", "0.05"]
        + ["--manoeuvre-variance", "4"],
    ),
    (
        {"method": "fading", "model": "coordinated-turn", "theta_per_update": 0.8},
        ["--method", "fading", "--model", "coordinated-turn", "--theta-per-update", "0.8"],
    ),
]


@pytest.mark.parametrize("kw,args", METHODS, ids=lambda v: str(v))
def test_equals_the_command_to_the_last_bit(tmp_path, kw, args):
    rng = np.random.default_rng(11)
    site = (100.0, -50.0, 10.0)
    t, rows = radar_pass(rng, site=site)
    want = run_track(tmp_path, t, rows, *args, "--site", "100,-50,10")
    tracker = ss.RadarTracker(**kw, sigma_range=SR, sigma_angle=SA, site=site)
    got = tracked(tracker, t, rows)
    for g, w in zip(got, want):
        assert same(g, w)
    assert np.isfinite(got[0][-1]).all() and tracker.rows_taken == len(t)
    assert set(got[3]) <= {"", "outlier", "misfit"}


def test_per_row_sigmas_bearings_and_batches_equal_the_command(tmp_path):
    rng = np.random.default_rng(12)
    t, rows = radar_pass(rng, n=200)
    bearing = rows.copy()
    bearing[:, 1] = np.pi / 2 - rows[:, 1]
    sr = np.where(rng.random(len(t)) < 0.5, np.nan, rng.uniform(5, 20, len(t)))
    sa = np.where(rng.random(len(t)) < 0.5, np.nan, rng.uniform(5e-4, 2e-3, len(t)))
    want = run_track(
        tmp_path,
        t,
        bearing,
        "--method",
        "kalman",
        "--q",
        "1",
        "--azimuth",
        "bearing",
        sigmas=(sr, sa),
    )
    tracker = ss.RadarTracker("kalman", q=1.0, sigma_range=SR, sigma_angle=SA, azimuth="bearing")
    # In three batches: the same as one.
    parts = [
        tracker.update_many(
            t[a:b],
            bearing[a:b, 0],
            bearing[a:b, 1],
            bearing[a:b, 2],
            sigma_range=sr[a:b],
            sigma_angle=sa[a:b],
        )
        for a, b in [(0, 1), (1, 77), (77, 200)]
    ]
    x = np.concatenate([p[0] for p in parts])
    sigma = np.sqrt(np.maximum(np.diagonal(np.concatenate([p[1] for p in parts]), 0, 1, 2), 0))
    nis = np.concatenate([p[2] for p in parts])
    flags = np.concatenate([p[3] for p in parts])
    for g, w in zip((x, sigma, nis, flags), want):
        assert same(g, w)


def test_extended_kalman_equals_filterpy():
    """From the tracker's start, filterpy's `ExtendedKalmanFilter` (Joseph form, the radar's
    Jacobian, the azimuth residual wrapped) gives the same states and covariances ≤ 1e-9
    relative."""
    from filterpy.kalman import ExtendedKalmanFilter

    rng = np.random.default_rng(13)
    t, rows = radar_pass(rng, n=150, missing=0.0)
    tracker = ss.RadarTracker("kalman", q=0.0, sigma_range=SR, sigma_angle=SA)
    x, p, _, flags = tracker.update_many(t, rows[:, 0], rows[:, 1], rows[:, 2])
    k0 = int(np.argmax(np.isfinite(x[:, 0])))
    ekf = ExtendedKalmanFilter(dim_x=6, dim_z=3)
    ekf.x, ekf.P = x[k0].copy(), p[k0].copy()
    ekf.R = np.diag([SR**2, SA**2, SA**2])
    ekf.Q = np.zeros((6, 6))

    def hx(s):
        r = np.sqrt(s[0] ** 2 + s[1] ** 2 + s[2] ** 2)
        return np.array([r, np.arctan2(s[1], s[0]), np.arcsin(s[2] / r)])

    def jacobian(s):
        px, py, pz = s[:3]
        rho2 = px * px + py * py
        r2 = rho2 + pz * pz
        r, rho = np.sqrt(r2), np.sqrt(rho2)
        h = np.zeros((3, 6))
        h[0, :3] = [px / r, py / r, pz / r]
        h[1, :2] = [-py / rho2, px / rho2]
        h[2, :3] = [-px * pz / (r2 * rho), -py * pz / (r2 * rho), rho / r2]
        return h

    def residual(a, b):
        d = a - b
        d[1] = (d[1] + np.pi) % (2 * np.pi) - np.pi
        return d

    for k in range(k0 + 1, len(t)):
        dt = t[k] - t[k - 1]
        ekf.F = np.eye(6)
        ekf.F[:3, 3:] = dt * np.eye(3)
        ekf.predict()
        if flags[k] != "outlier":  # the gate left the row out: the prediction
            ekf.update(rows[k], jacobian, hx, residual=residual)
        scale = np.abs(ekf.x).max()
        assert np.abs(ekf.x - x[k]).max() <= 1e-9 * scale, k
        assert np.abs(ekf.P - p[k]).max() <= 1e-9 * np.abs(ekf.P).max(), k


def test_refused_rows_name_their_index_and_keep_the_rows_before():
    rng = np.random.default_rng(14)
    t, rows = radar_pass(rng, n=50)
    for column, value in [(0, -5.0), (1, 7.0), (2, 2.0)]:
        bad = rows.copy()
        bad[30, column] = value
        tracker = ss.RadarTracker("kalman", sigma_range=SR, sigma_angle=SA)
        with pytest.raises(InvalidInputError) as e:
            tracker.update_many(t, bad[:, 0], bad[:, 1], bad[:, 2])
        assert e.value.index == 30 and tracker.rows_taken == 30
        # The rest goes on as if the bad row had never come.
        reference = ss.RadarTracker("kalman", sigma_range=SR, sigma_angle=SA)
        reference.update_many(t[:30], rows[:30, 0], rows[:30, 1], rows[:30, 2])
        a = tracker.update_many(t[31:], rows[31:, 0], rows[31:, 1], rows[31:, 2])
        b = reference.update_many(t[31:], rows[31:, 0], rows[31:, 1], rows[31:, 2])
        assert all(same(u, v) for u, v in zip(a, b))
    for method in ["kalman", "window", "smooth"]:
        tracker = ss.RadarTracker(method, sigma_range=SR, sigma_angle=SA)
        tt = t.copy()
        tt[20] = tt[19]
        with pytest.raises(InvalidInputError) as e:
            tracker.update_many(tt, rows[:, 0], rows[:, 1], rows[:, 2])
        assert e.value.index == 20, method
    tracker = ss.RadarTracker("kalman", sigma_angle=SA)
    with pytest.raises(InvalidInputError) as e:
        tracker.update_many(t, rows[:, 0], rows[:, 1], rows[:, 2])
    assert "sigma_range" in str(e.value) and e.value.index == 0


@pytest.mark.parametrize(
    "kw",
    [
        {"method": "kalman", "max_iterations": 0},
        {"method": "fading", "theta": 0.9, "tau": 1.0, "theta_per_update": 0.9},
        {"method": "fading", "theta": 1.5, "tau": 1.0},
        {"method": "fading", "theta_per_update": 1.0},
        {"method": "fading", "theta": 0.9},
        {"method": "fading", "beta": 0.9},
        {"method": "kalman", "q": -1.0},
        {"method": "kalman", "theta_per_update": 0.9},
        {"method": "window", "q": 1.0},
        {"method": "window", "window": 1},
        {"method": "kalman", "window": 10},
        {"method": "kalman", "lag": 10},
        {"method": "fading", "theta": 0.9, "tau": 1.0, "lag": 10},
        {"method": "ekf"},
        {"method": "kalman", "azimuth": "north"},
        {"method": "kalman", "sigma_range": -1.0},
        {"method": "kalman", "site": (np.nan, 0.0, 0.0)},
    ],
)
def test_bad_settings_raise_parameter_errors(kw):
    with pytest.raises(ParameterError):
        ss.RadarTracker(**kw)


def test_flags_name_an_outlier_and_a_manoeuvre():
    """A range 30σ off is flagged ``"outlier"`` and left out (the next row is not), by every
    method at its defaults; a 5g turn the constant-velocity model does not follow is
    flagged ``"misfit"`` by every method; the flags are the command's ``flag`` column."""
    rng = np.random.default_rng(21)
    n = 240
    t = np.cumsum(rng.uniform(1.0, 3.0, n))
    # Straight at 200 m/s, then a turn of 0.25 rad/s (50 m/s², about 5g) from t = 200 s.
    heading = 0.3 + 0.25 * np.clip(t - 200.0, 0.0, 12.0)
    v = 200.0 * np.column_stack([np.cos(heading), np.sin(heading)])
    dt = np.diff(t, prepend=0.0)
    xy = np.array([30_000.0, -5_000.0]) + np.cumsum(v * dt[:, None], axis=0)
    z = np.full(n, 4_000.0)
    r = np.sqrt(xy[:, 0] ** 2 + xy[:, 1] ** 2 + z**2)
    rows = np.column_stack([r, np.arctan2(xy[:, 1], xy[:, 0]), np.arcsin(z / r)])
    rows += rng.standard_normal((n, 3)) * [SR, SA, SA]
    k = 60
    rows[k, 0] += 30 * SR
    turn = (t > 200.0) & (t < 240.0)
    for method in ["kalman", "fading", "smooth", "window"]:
        tracker = ss.RadarTracker(method, sigma_range=SR, sigma_angle=SA)
        x, sigma, nis, flags = tracked(tracker, t, rows)
        assert flags.dtype.kind == "U" and set(flags) <= {"", "outlier", "misfit"}
        assert flags[k] == "outlier" and flags[k + 1] != "outlier", method
        assert (flags[turn] == "misfit").any(), method
        assert (flags != "").mean() < 0.5, method


def test_smoothed_streams_with_the_lag():
    """With `lag` L, `smoothed()` after each batch gives row k once row k + L is in (and only
    then), in order, each row once; with `finish()` they are every row after the start, the
    numbers of taking them all at `finish()` (flags too); lag 0 gives the kalman filter's rows and
    flags, with a given and with the adaptive driving noise."""
    rng = np.random.default_rng(14)
    t, rows = radar_pass(rng, n=240)
    lag = 15
    whole = ss.RadarTracker("smooth", q=0.5, lag=lag, sigma_range=SR, sigma_angle=SA)
    x, _, _, _ = whole.update_many(t, rows[:, 0], rows[:, 1], rows[:, 2])
    start = int(np.flatnonzero(np.isfinite(x[:, 0]))[0])
    want = whole.finish()
    assert np.array_equal(want[0], np.arange(start + 1, len(t)))
    tracker = ss.RadarTracker("smooth", q=0.5, lag=lag, sigma_range=SR, sigma_angle=SA)
    got, last = [], start  # the last row given so far
    for a, b in [(0, 1), (1, 70), (70, 71), (71, 200), (200, 240)]:
        tracker.update_many(t[a:b], rows[a:b, 0], rows[a:b, 1], rows[a:b, 2])
        part = tracker.smoothed()
        # Row k is given once row k + lag is in (rows 0..b-1 are in).
        assert np.array_equal(part[0], np.arange(last + 1, max(last + 1, b - lag))), (a, b)
        last = max(last, b - lag - 1)
        got.append(part)
    assert tracker.smoothed()[0].size == 0
    got.append(tracker.finish())
    for k in range(5):
        assert same(np.concatenate([g[k] for g in got]), want[k]), k
    for q in [{"q": 0.5}, {}]:
        kalman = ss.RadarTracker("kalman", **q, sigma_range=SR, sigma_angle=SA)
        kx, kp, kn, kf = kalman.update_many(t, rows[:, 0], rows[:, 1], rows[:, 2])
        zero = ss.RadarTracker("smooth", **q, lag=0, sigma_range=SR, sigma_angle=SA)
        zero.update_many(t, rows[:, 0], rows[:, 1], rows[:, 2])
        held, xs, ps, ns, fs = zero.smoothed()
        assert np.array_equal(held, np.arange(start + 1, len(t)))
        assert same(xs, kx[held]) and same(ps, kp[held]) and same(ns, kn[held]), q
        assert same(fs, kf[held]), q


def test_models_a_method_cannot_use_are_refused_in_pythons_words():
    """The library's refusals of a model (``seqsmooth track --model``'s), named by keyword."""
    cases = [
        ({"model": "spiral"}, "model 'spiral' is invalid: must be one of constant-velocity"),
        (
            {"method": "window", "model": "singer"},
            "model singer is invalid: the window method fits the constant-velocity model only",
        ),
        ({"model": "singer", "q": 1.0}, "q 1 is invalid: does not apply to the singer model"),
        (
            {"model": "constant-velocity", "turn_rate_noise": 1e-4},
            "turn_rate_noise 0.0001 is invalid: is not a parameter of the constant-velocity",
        ),
        ({"model": "singer", "manoeuvre_alpha": -1.0}, "manoeuvre_alpha -1 is invalid"),
        (
            {"method": "fading", "model": "singer", "manoeuvre_variance": 1.0},
            "manoeuvre_variance 1 is invalid: does not apply to the fading method",
        ),
    ]
    for kw, message in cases:
        with pytest.raises(ParameterError) as e:
            ss.RadarTracker(**kw, sigma_range=SR, sigma_angle=SA)
        assert str(e.value).startswith(message), (kw, str(e.value))
