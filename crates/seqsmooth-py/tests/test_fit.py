"""`SlidingFit` against `seqsmooth fit` bit for bit (radar: Unix-epoch times, missing
components, a site, bearings; polynomial: degrees 1-3, epochs end, centre and a time),
against numpy's weighted least squares for the polynomial model, and its refusals."""

from __future__ import annotations

import csv
import math
import subprocess

import numpy as np
import pytest

import seqsmooth as ss
from conftest import cli_path, irregular_series
from seqsmooth.errors import InvalidInputError, ParameterError

SR, SA = 10.0, 1e-3


def radar_pass(rng: np.random.Generator, n: int, site=(0.0, 0.0, 0.0), missing=0.05):
    """`n` rows of a constant-velocity target from `site`: Unix-epoch times at steps
    U(0.5, 1.5) s, σ 10 m and 1 mrad, a fraction `missing` of components missing (NaN)."""
    t = 1.7e9 + np.cumsum(rng.uniform(0.5, 1.5, n))
    s = t - 1.7e9
    x = 20_000.0 + 150.0 * s - site[0]
    y = -8_000.0 + 60.0 * s - site[1]
    z = 3_000.0 - 4.0 * s + 0.05 * s**2 - site[2]
    r = np.sqrt(x * x + y * y + z * z)
    rows = np.column_stack([r, np.arctan2(y, x), np.arcsin(z / r)])
    rows += rng.standard_normal((n, 3)) * [SR, SA, SA]
    rows[rng.random((n, 3)) < missing] = np.nan
    return t, rows


def run_fit(tmp_path, header, columns, *args) -> dict:
    """`seqsmooth fit` on the columns (repr round-trips; NaN an empty cell): its columns as
    float arrays keyed by header name, NaN where a cell is empty."""
    source = tmp_path / "in.csv"
    cell = lambda v: "" if np.isnan(v) else repr(float(v))  # noqa: E731
    with open(source, "w") as f:
        f.write(",".join(header) + "\n")
        for row in zip(*columns):
            f.write(",".join(cell(v) for v in row) + "\n")
    out = subprocess.run(
        [str(cli_path()), "fit", str(source), *args],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    rows = list(csv.reader(out.splitlines()))
    head, body = rows[0], rows[1:]
    return {
        name: (
            np.array([r[i] for r in body], dtype="<U7")
            if name == "flag"
            else np.array([float(r[i]) if r[i] else np.nan for r in body])
        )
        for i, name in enumerate(head)
    }


def same(a, b):
    """Equal to the last bit, NaN where the other is NaN."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return (
        a.shape == b.shape
        and np.array_equal(np.isnan(a), np.isnan(b))
        and np.array_equal(np.nan_to_num(a).view(np.int64), np.nan_to_num(b).view(np.int64))
    )


def check_against_command(got, want, names, sigma_names, epoch_column):
    """Every cell of the command's row against the binding's numbers; the rows compared."""
    x, p, info = got
    sigma = np.sqrt(np.diagonal(p, axis1=1, axis2=2))
    for k, name in enumerate(names):
        assert same(x[:, k], want[name]), name
    for k, name in enumerate(sigma_names):
        assert same(sigma[:, k], want[name]), name
    assert same(info["iterations"], want["iterations"])
    assert same(info["chi2"], want["chi2"])
    if epoch_column:
        assert same(info["epoch"], want["epoch"])
    if "flag" in want:
        assert np.array_equal(info["flag"], want["flag"])
        assert set(info["flag"]) <= {"", "misfit"}
    return len(want["t"])


RADAR = ["x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az"]
ROWS_COMPARED = {"radar": 0, "polynomial": 0}


@pytest.mark.parametrize(
    "window,degree,epoch",
    [(12, 1, "end"), (40, 1, "centre"), (25, 2, "end"), (7, 1, 1.7e9 + 100.0)],
)
def test_radar_equals_the_command_to_the_last_bit(tmp_path, window, degree, epoch):
    rng = np.random.default_rng(window + degree)
    site = (100.0, -50.0, 10.0)
    t, rows = radar_pass(rng, 250, site=site)
    args = ["--model", "radar", "--sigma-range", str(SR), "--sigma-angle", str(SA)]
    args += ["--window", str(window), "--degree", str(degree), "--epoch", str(epoch)]
    want = run_fit(
        tmp_path,
        ["t", "range", "azimuth", "elevation"],
        [t, *rows.T],
        *args,
        "--site",
        "100,-50,10",
    )
    fit = ss.SlidingFit(
        "radar",
        window=window,
        degree=degree,
        epoch=epoch,
        site=site,
        sigma_range=SR,
        sigma_angle=SA,
    )
    got = fit.update_many(t, rows[:, 0], rows[:, 1], rows[:, 2])
    names = RADAR[: 3 * (degree + 1)]
    n = check_against_command(got, want, names, ["s" + v for v in names], epoch != "end")
    ROWS_COMPARED["radar"] += n
    assert np.isfinite(got[0][-1]).all() and fit.rows_taken == len(t)
    assert got[0].shape == (len(t), len(names)) and got[1].shape == (len(t),) + (len(names),) * 2


def test_radar_bearings_in_batches_equal_the_command(tmp_path):
    """A bearing b is the angle pi/2 - b from +x: the command, which takes only the angle
    from +x, gets that (within (-pi, pi), where the binding's wrap leaves it as it is)."""
    rng = np.random.default_rng(5)
    t, rows = radar_pass(rng, 200)
    bearing = rows.copy()
    bearing[:, 1] = np.pi / 2 - rows[:, 1]
    from_x = rows.copy()
    from_x[:, 1] = np.pi / 2 - bearing[:, 1]
    assert np.nanmax(np.abs(from_x[:, 1])) < np.pi
    args = ["--model", "radar", "--sigma-range", str(SR), "--sigma-angle", str(SA)]
    want = run_fit(
        tmp_path,
        ["t", "range", "azimuth", "elevation"],
        [t, *from_x.T],
        *args,
        "--window",
        "15",
    )
    fit = ss.SlidingFit(window=15, sigma_range=SR, sigma_angle=SA, azimuth="bearing")
    parts = [
        fit.update_many(t[a:b], bearing[a:b, 0], bearing[a:b, 1], bearing[a:b, 2])
        for a, b in [(0, 1), (1, 60), (60, 200)]
    ]
    got = (
        np.concatenate([p[0] for p in parts]),
        np.concatenate([p[1] for p in parts]),
        {k: np.concatenate([p[2][k] for p in parts]) for k in parts[0][2]},
    )
    names = RADAR[:6]
    ROWS_COMPARED["radar"] += check_against_command(
        got, want, names, ["s" + v for v in names], False
    )
    assert fit.rows_taken == 200


POLYNOMIAL = [
    (1, 5, "end"),
    (1, 30, "centre"),
    (2, 9, "end"),
    (2, 40, "centre"),
    (3, 12, "at"),
    (3, 60, "end"),
    (2, 3, "at"),
]


def polynomial_case(degree, window, epoch):
    rng = np.random.default_rng(100 * degree + window)
    t, y = irregular_series(rng, 200, start=1.7e9)
    if epoch == "at":
        epoch = float(t[0] + 57.25)
    return t, y, epoch


@pytest.mark.parametrize("degree,window,epoch", POLYNOMIAL)
def test_polynomial_equals_the_command_to_the_last_bit(tmp_path, degree, window, epoch):
    t, y, epoch = polynomial_case(degree, window, epoch)
    want = run_fit(
        tmp_path,
        ["t", "y"],
        [t, y],
        "--model",
        "polynomial",
        "--degree",
        str(degree),
        "--window",
        str(window),
        "--sigma",
        "0.3",
        "--epoch",
        repr(epoch) if isinstance(epoch, float) else epoch,
    )
    fit = ss.SlidingFit("polynomial", degree=degree, window=window, sigma=0.3, epoch=epoch)
    got = fit.update_many(t, y)
    names = [f"d{k}" for k in range(degree + 1)]
    ROWS_COMPARED["polynomial"] += check_against_command(
        got, want, names, [f"s{k}" for k in range(degree + 1)], epoch != "end"
    )
    assert same(want["y"], y) and np.isfinite(got[0][degree:]).all()


MAX_DEVIATION = {"state κ≤1e4": 0.0, "state": 0.0, "κ": 0.0, "covariance": 0.0, "rows": 0}


@pytest.mark.parametrize("degree,window,epoch", POLYNOMIAL)
def test_polynomial_equals_numpy_weighted_least_squares(degree, window, epoch):
    """Row i's state is the least-squares fit of its window with weights 1/σ: the Taylor
    coefficients d_k of y(t) = Σ d_k (t - t_c)^k / k! at the epoch t_c, by `np.linalg.lstsq`
    of the whitened design A (times relative to t_c, so that Unix-epoch times keep their
    digits); its covariance (AᵀA)⁻¹ = R⁻¹R⁻ᵀ from numpy's QR of A.

    Each d_k within 1e-9 of numpy's, relative, where A is conditioned (κ(A) ≤ 1e4: every
    row at the epochs end and centre); at a fixed epoch the late windows extrapolate ~100 s
    from spans of a few seconds (κ up to ~1e10), where two backward-stable solvers agree to
    κ·ε only: there within 1e-13·κ. The covariance within 1e-9 of its largest entry."""
    t, y, epoch = polynomial_case(degree, window, epoch)
    sigma = 0.3
    fit = ss.SlidingFit("polynomial", degree=degree, window=window, sigma=sigma, epoch=epoch)
    x, p, info = fit.update_many(t, y)
    rows = 0
    for i in range(len(t)):
        if np.isnan(x[i]).any():
            assert i < degree and np.isnan(p[i]).all()
            continue
        j = slice(max(0, i - window + 1), i + 1)
        dt = t[j] - info["epoch"][i]
        a = np.column_stack([dt**k / math.factorial(k) for k in range(degree + 1)]) / sigma
        want = np.linalg.lstsq(a, y[j] / sigma, rcond=None)[0]
        r_inv = np.linalg.inv(np.linalg.qr(a)[1])
        want_p = r_inv @ r_inv.T
        cond = np.linalg.cond(a)
        dev = np.max(np.abs(x[i] - want) / np.abs(want))
        dev_p = np.max(np.abs(p[i] - want_p)) / np.max(np.abs(want_p))
        assert dev <= max(1e-9, 1e-13 * cond), (i, dev, cond)
        assert dev_p <= 1e-9, (i, dev_p)
        if cond <= 1e4:
            MAX_DEVIATION["state κ≤1e4"] = max(MAX_DEVIATION["state κ≤1e4"], dev)
        MAX_DEVIATION["state"] = max(MAX_DEVIATION["state"], dev)
        MAX_DEVIATION["κ"] = max(MAX_DEVIATION["κ"], cond)
        MAX_DEVIATION["covariance"] = max(MAX_DEVIATION["covariance"], dev_p)
        rows += 1
    assert rows == len(t) - degree
    MAX_DEVIATION["rows"] += rows


def test_report_the_numbers(capsys):
    """Prints the rows compared and the largest deviation against numpy (run with -s)."""
    with capsys.disabled():
        print(f"\nrows compared with seqsmooth fit: {ROWS_COMPARED}")
        print(f"against numpy: {MAX_DEVIATION}")


def test_refused_rows_name_their_index_and_leave_the_fit_unchanged():
    t, y = irregular_series(np.random.default_rng(3), 30)
    clean = ss.SlidingFit("polynomial", degree=1, window=6, sigma=0.3)
    want = clean.update_many(np.delete(t, 10), np.delete(y, 10))[0]
    for bad_t, bad_y in [(np.nan, None), (None, np.inf), (None, np.nan), (t[8], None)]:
        tt, yy = t.copy(), y.copy()
        if bad_t is not None:
            tt[10] = bad_t
        if bad_y is not None:
            yy[10] = bad_y
        fit = ss.SlidingFit("polynomial", degree=1, window=6, sigma=0.3)
        fit.update_many(tt[:4], yy[:4])
        with pytest.raises(InvalidInputError) as e:
            fit.update_many(tt[4:], yy[4:])
        assert e.value.index == 6 and fit.rows_taken == 10, (bad_t, bad_y, str(e.value))
        rest = fit.update_many(tt[11:], yy[11:])[0]
        assert same(rest, want[10:])


@pytest.mark.parametrize(
    "k,value",
    [(0, -5.0), (0, 0.0), (1, 7.0), (1, np.inf), (2, 1.6), (2, -2.0)],
)
def test_refused_radar_rows(k, value):
    t, rows = radar_pass(np.random.default_rng(4), 20)
    kept = rows[7, k]
    rows[7, k] = value
    fit = ss.SlidingFit(window=10, sigma_range=SR, sigma_angle=SA)
    with pytest.raises(InvalidInputError) as e:
        fit.update_many(t, rows[:, 0], rows[:, 1], rows[:, 2])
    assert e.value.index == 7 and fit.rows_taken == 7
    # Unsorted time.
    t[12] = t[11]
    rows[7, k] = kept
    fit = ss.SlidingFit(window=10, sigma_range=SR, sigma_angle=SA)
    with pytest.raises(InvalidInputError, match="time") as e:
        fit.update_many(t, rows[:, 0], rows[:, 1], rows[:, 2])
    assert e.value.index == 12 and fit.rows_taken == 12


@pytest.mark.parametrize(
    "kw",
    [
        {"model": "kalman"},
        {"window": 0},
        {"window": -3},
        {"degree": 3},
        {"degree": 0},
        {"degree": -1},
        {"sigma_range": 0.0},
        {"sigma_range": -1.0},
        {"sigma_range": np.nan},
        {"sigma_angle": 1e-200},
        {"sigma_angle": np.inf},
        {"sigma": 1.0},
        {"sigma_range": None},
        {"epoch": "middle"},
        {"epoch": np.nan},
        {"epoch": [1.0]},
        {"azimuth": "north"},
        {"max_iterations": 0},
        {"max_iterations": 1001},
        {"site": (0.0, np.nan, 0.0)},
        {"model": "polynomial", "degree": 2, "sigma": 0.3, "window": 2},
        {"model": "polynomial", "sigma": 0.3},
        {"model": "polynomial", "degree": 1},
        {"model": "polynomial", "degree": 1, "sigma": 0.0},
        {"model": "polynomial", "degree": 25, "sigma": 1.0, "window": 100},
        {"model": "polynomial", "degree": 1, "sigma": 1.0, "site": (1.0, 0.0, 0.0)},
        {"model": "polynomial", "degree": 1, "sigma": 1.0, "azimuth": "bearing"},
    ],
    ids=str,
)
def test_bad_settings_raise_parameter_error(kw):
    base = {"sigma_range": SR, "sigma_angle": SA}
    if kw.get("model") == "polynomial":
        base = {}
    with pytest.raises(ParameterError):
        ss.SlidingFit(**{**base, **kw})


def test_bad_calls_and_repr():
    fit = ss.SlidingFit("polynomial", degree=2, window=5, sigma=1.0, epoch=3.5)
    assert repr(fit) == (
        "SlidingFit(model='polynomial', degree=2, window=5, epoch=3.5, rows_taken=0)"
    )
    with pytest.raises(InvalidInputError):
        fit.update_many([0.0, 1.0], [1.0, 2.0], [3.0, 4.0])
    with pytest.raises(InvalidInputError):
        fit.update_many([0.0, 1.0], [1.0])
    with pytest.raises(InvalidInputError):
        fit.update_many([], [])
    radar = ss.SlidingFit(sigma_range=SR, sigma_angle=SA, epoch="center")
    assert repr(radar) == (
        "SlidingFit(model='radar', degree=1, window=8, epoch='centre', rows_taken=0)"
    )
    with pytest.raises(InvalidInputError):
        radar.update_many([0.0], [1.0])
    x, p, info = radar.update_many([0.0], [1000.0], [0.1], [0.2])
    assert np.isnan(x).all() and np.isnan(p).all() and np.isnan(info["chi2"]).all()
    assert x.shape == (1, 6) and p.shape == (1, 6, 6) and radar.rows_taken == 1


def test_a_full_window_that_does_not_determine_the_state_is_an_error():
    """Two rows of a constant-velocity radar with only ranges never determine the state:
    while the window fills, NaN rows; once full, an error naming the row."""
    fit = ss.SlidingFit(window=3, sigma_range=SR, sigma_angle=SA)
    nan = np.full(3, np.nan)
    with pytest.raises(ss.SeqsmoothError) as e:
        fit.update_many([0.0, 1.0, 2.0], [1000.0, 1001.0, 1002.0], nan, nan)
    assert e.value.index == 2 and fit.rows_taken == 2
