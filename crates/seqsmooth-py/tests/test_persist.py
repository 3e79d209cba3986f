"""Every filter class saved and resumed bit for bit (``pickle`` protocols 2 to 5, ``copy.copy``,
``copy.deepcopy``): a run of seeded random data (irregular times, missing components where the
class takes them) cut at a random sample, the filter saved, restored and continued, gives the
numbers of the unbroken filter continued, ``np.array_equal`` on every output (σ included); a
damaged pickle or saved state is refused (``DamagedStateError`` where the damage reaches the
library's bytes), never a crash."""

from __future__ import annotations

import copy
import pickle
import zlib

import numpy as np
import pytest

import seqsmooth as ss

SEEDS = 40


def times(rng, n):
    return np.cumsum(rng.uniform(0.3, 1.7, n))


def outputs(result):
    """Every array of a call's result, flattened into a list (dicts by key, tuples in order)."""
    if result is None:
        return []
    if isinstance(result, dict):
        return [np.asarray(result[k]) for k in sorted(result)]
    if isinstance(result, (tuple, list)):
        out = []
        for r in result:
            out += outputs(r)
        return out
    if isinstance(result, (ss.State,)):
        return [np.asarray(result.time), np.asarray(result.derivatives)] + (
            [] if result.covariance is None else [np.asarray(result.covariance)]
        )
    return [np.asarray(result)]


def same(a, b):
    assert len(a) == len(b)
    for x, y in zip(a, b):
        assert x.dtype == y.dtype and x.shape == y.shape
        if x.dtype.kind == "f":
            # bit for bit, NaN included
            bits = [np.ascontiguousarray(v).reshape(-1).view(np.uint8) for v in (x, y)]
            assert np.array_equal(*bits), (x, y)
        else:
            assert np.array_equal(x, y)


# Each case: (name, make(rng) -> filter, data(rng) -> rows, run(filter, rows) -> outputs);
# `rows` is sliced at the cut.


def poly_data(rng):
    n = int(rng.integers(20, 80))
    t = times(rng, n)
    return np.column_stack([t, np.sin(0.3 * t) + 0.1 * rng.standard_normal(n)])


def poly_run(f, rows):
    out = outputs(f.update_many(rows[:, 0], rows[:, 1], return_sigma=True))
    return out + (outputs(f.estimate()) if f.is_determined else [])


def auto_run(f, rows):
    return outputs(f.update_many(rows[:, 0], rows[:, 1])) + outputs(f.estimate())


def bank_data(rng):
    return rng.standard_normal((int(rng.integers(10, 40)), 3)) + np.arange(3.0)


def bank_run(f, rows):
    for r in rows:
        f.update(r)
    return outputs(f.estimate())


def kalman_data(rng, axes=2, missing=0.15):
    n = int(rng.integers(10, 60))
    t = times(rng, n)
    z = np.column_stack([np.sin(0.2 * t), np.cos(0.1 * t)][:axes]) + 0.1 * rng.standard_normal(
        (n, axes)
    )
    z[rng.random((n, axes)) < missing] = np.nan
    return np.column_stack([t, z])


def kalman_run(f, rows):
    out = outputs(f.update_many(rows[:, 0], rows[:, 1:], 0.01))
    return out + [np.asarray(f.state), np.asarray(f.covariance)]


def bayes_run(f, rows):
    out = outputs(f.update_many(rows[:, 0], rows[:, 1:], 0.01))
    return out + outputs((f.state, f.covariance)) if f.is_determined else out


def linear_make(rng):
    dt = float(rng.uniform(0.5, 1.5))
    F = np.array([[1.0, dt], [0.0, 1.0]])
    return ss.LinearKalmanFilter(
        x0=[0.0, 0.0], P0=100.0, F=F, H=[[1.0, 0.0]], Q=0.01 * np.eye(2), R=0.25
    )


def linear_data(rng):
    n = int(rng.integers(10, 60))
    z = np.cumsum(rng.standard_normal(n))[:, None]
    z[rng.random((n, 1)) < 0.15] = np.nan
    return z


def linear_run(f, rows):
    return outputs(f.update_many(rows)) + outputs((f.x, f.P))


def lag_make(rng):
    return ss.LinearFixedLagSmoother(linear_make(rng), int(rng.integers(1, 5)))


def lag_run(f, rows):
    out = []
    for z in rows:
        out += outputs(f.update(z))
    return out + [np.asarray(f.pushed)]


def continuous_make(rng):
    """A continuous-model filter (nearly constant velocity or Singer, two axes) with R a
    number, one variance per component or a full matrix."""
    if rng.random() < 0.5:
        model = ss.ContinuousModel.nearly_constant_velocity([0.05, 0.1])
    else:
        model = ss.ContinuousModel.singer(float(rng.uniform(0.1, 1.0)), 0.2, axes=2)
    n = model.dimension
    R = [0.01, [0.01, 0.02], [[0.02, 0.005], [0.005, 0.03]]][int(rng.integers(0, 3))]
    return ss.ContinuousKalmanFilter(model, np.eye(2, n), R, np.zeros(n), 100.0)


def continuous_run(f, rows):
    out = outputs(f.smooth(rows[:, 0], rows[:, 1:]))
    out += outputs(f.update_many(rows[:, 0], rows[:, 1:]))
    return out + [np.asarray(f.state), np.asarray(f.covariance), np.asarray(f.R)]


# The caller's own model, module-level so that pickle finds it: nearly constant velocity on
# two axes, observed in position.


def cv_f(x, t0, t1):
    dt = t1 - t0
    return np.array([x[0] + dt * x[2], x[1] + dt * x[3], x[2], x[3]])


def cv_F(x, t0, t1):
    F = np.eye(4)
    F[0, 2] = F[1, 3] = t1 - t0
    return F


def cv_dxdt(x, t):
    return np.array([x[2], x[3], 0.0, 0.0])


def cv_h(x, t):
    return np.array([x[0], x[1]])


def cv_H(x, t):
    return np.eye(2, 4)


def cv_Q(t0, t1):
    dt = t1 - t0
    q = np.array([[dt**3 / 3, dt**2 / 2], [dt**2 / 2, dt]]) * 0.05
    return np.kron(q, np.eye(2))


def user_keywords(rng, jacobians):
    """The callables of the caller's model, drawn: f or dxdt, with or without Jacobians, Q a
    callable, a constant or none, an angle component or none."""
    kw = {"h": cv_h, "angles": [1] if rng.random() < 0.5 else None}
    ode = rng.random() < 0.25
    if ode:
        kw["dxdt"] = cv_dxdt
    else:
        kw["f"] = cv_f
    if jacobians and rng.random() < 0.5:
        kw["H_jacobian"] = cv_H
        if not ode:
            kw["F_jacobian"] = cv_F
    kw["Q"] = [cv_Q, 0.01 * np.eye(4), None][int(rng.integers(0, 3))]
    return kw


def extended_make(rng):
    kw = user_keywords(rng, jacobians=True)
    return ss.ExtendedKalmanFilter(
        np.zeros(4), 100.0, iterations=int(rng.integers(1, 3)), tolerance=1e-8, **kw
    )


def unscented_user_make(rng):
    kw = user_keywords(rng, jacobians=False)
    return ss.UnscentedKalmanFilter(x0=np.zeros(4), P0=100.0, **kw)


def radar_data(rng, missing=0.05):
    n = int(rng.integers(15, 60))
    t = 1.7e9 + np.cumsum(rng.uniform(0.5, 1.5, n))
    s = t - 1.7e9
    x, y, z = 20_000.0 + 150.0 * s, -8_000.0 + 60.0 * s, 3_000.0 - 4.0 * s
    r = np.sqrt(x * x + y * y + z * z)
    rows = np.column_stack([r, np.arctan2(y, x), np.arcsin(z / r)])
    rows += rng.standard_normal((n, 3)) * [10.0, 1e-3, 1e-3]
    rows[rng.random((n, 3)) < missing] = np.nan
    return np.column_stack([t, rows])


def tracker_run(f, rows):
    out = outputs(f.update_many(rows[:, 0], rows[:, 1], rows[:, 2], rows[:, 3]))
    return out + outputs(f.smoothed())


def unscented_radar_data(rng):
    rows = radar_data(rng, missing=0.05)
    rows[:, 0] -= 1.7e9
    return rows


def online_make(rng):
    t = times(rng, 40)
    return ss.OnlineSmoother(t, 0.1, degree=int(rng.integers(1, 4)))


def online_run(f, rows):
    f.push_all(rows)
    done = f.taken == f.size
    return (outputs(f.polynomial_samples()) if done else []) + [np.asarray(f.taken)]


def sliding_polynomial(rng):
    degree = int(rng.integers(0, 3))
    epoch = str(rng.choice(["end", "centre"]))
    window = int(rng.integers(degree + 2, 12))
    return ss.SlidingFit("polynomial", degree=degree, window=window, sigma=0.1, epoch=epoch)


def sliding_run(f, rows):
    out = outputs(f.update_many(rows[:, 0], *rows[:, 1:].T))
    return out + [np.asarray(f.rows_taken), np.asarray(repr(f))]


def tracker(method):
    extra = {"smooth": {"lag": 3}, "window": {"window": 8}}.get(method, {})
    return lambda rng: ss.RadarTracker(method, sigma_range=10.0, sigma_angle=1e-3, **extra)


CASES = [
    (
        "ExpandingMemory",
        lambda rng: ss.ExpandingMemory(
            int(rng.integers(0, 4)), engine=str(rng.choice(["exact", "gain"])), sigma=0.1
        ),
        poly_data,
        poly_run,
    ),
    (
        "FadingMemory",
        lambda rng: ss.FadingMemory(
            int(rng.integers(0, 4)),
            theta=float(rng.uniform(0.5, 0.95)),
            tau=float(rng.uniform(0.5, 2.0)),
            engine=str(rng.choice(["exact", "gain"])),
            sigma=0.1,
        ),
        poly_data,
        poly_run,
    ),
    (
        "FixedMemory",
        lambda rng: ss.FixedMemory(
            int(rng.integers(0, 3)),
            int(rng.integers(4, 12)),
            engine=str(rng.choice(["adaptive", "irregular"])),
            sigma=0.1,
        ),
        poly_data,
        poly_run,
    ),
    (
        "AutomaticFilter",
        lambda rng: ss.AutomaticFilter(int(rng.integers(1, 3)), theta=0.9, sigma=0.1),
        poly_data,
        auto_run,
    ),
    ("FadingBank", lambda rng: ss.FadingBank(int(rng.integers(0, 3)), 0.8, 3), bank_data, bank_run),
    (
        "ExpandingBank",
        lambda rng: ss.ExpandingBank(int(rng.integers(0, 3)), 3),
        bank_data,
        bank_run,
    ),
    (
        "KalmanFilter",
        lambda rng: ss.KalmanFilter(
            1,
            x0=np.zeros(4),
            P0=100.0,
            axes=2,
            q=0.05,
            theta=float(rng.uniform(0.8, 0.99)),
            tau=1.0,
        ),
        kalman_data,
        kalman_run,
    ),
    (
        "BayesFilter",
        lambda rng: ss.BayesFilter(1, axes=2, theta=float(rng.uniform(0.8, 0.99)), tau=2.0),
        kalman_data,
        bayes_run,
    ),
    (
        "UnscentedKalmanFilter",
        lambda rng: ss.UnscentedKalmanFilter(1, x0=np.zeros(4), P0=100.0, axes=2, q=0.05),
        kalman_data,
        kalman_run,
    ),
    ("LinearKalmanFilter", linear_make, linear_data, linear_run),
    ("LinearFixedLagSmoother", lag_make, linear_data, lag_run),
    ("RadarTracker-kalman", tracker("kalman"), radar_data, tracker_run),
    ("RadarTracker-fading", tracker("fading"), radar_data, tracker_run),
    ("RadarTracker-smooth", tracker("smooth"), radar_data, tracker_run),
    ("RadarTracker-window", tracker("window"), radar_data, tracker_run),
    ("OnlineSmoother", online_make, lambda rng: rng.standard_normal(40), online_run),
    ("ContinuousKalmanFilter", continuous_make, kalman_data, continuous_run),
    ("ExtendedKalmanFilter", extended_make, kalman_data, kalman_run),
    ("UnscentedKalmanFilter-callables", unscented_user_make, kalman_data, kalman_run),
    ("SlidingFit-polynomial", sliding_polynomial, poly_data, sliding_run),
    (
        "SlidingFit-radar",
        lambda rng: ss.SlidingFit(
            "radar",
            sigma_range=10.0,
            sigma_angle=1e-3,
            window=int(rng.integers(4, 10)),
            azimuth=str(rng.choice(["from-x", "bearing"])),
        ),
        radar_data,
        sliding_run,
    ),
]


def ways(rng):
    """The ways a filter is saved and restored: each pickle protocol, copy and deepcopy."""
    protocol = int(rng.integers(2, pickle.HIGHEST_PROTOCOL + 1))
    return [
        (f"pickle {protocol}", lambda f: pickle.loads(pickle.dumps(f, protocol=protocol))),
        ("copy", copy.copy),
        ("deepcopy", copy.deepcopy),
    ]


@pytest.mark.parametrize("name,make,data,run", CASES, ids=[c[0] for c in CASES])
def test_cut_saved_restored_continued_is_the_unbroken_run(name, make, data, run):
    for seed in range(SEEDS):
        rng = np.random.default_rng([seed, len(name)])
        f = make(rng)
        rows = data(rng)
        cut = int(rng.integers(1, len(rows)))
        run(f, rows[:cut])
        restored = [(how, save(f)) for how, save in ways(rng)]
        want = run(f, rows[cut:])
        for how, g in restored:
            assert type(g) is type(f), how
            same(run(g, rows[cut:]), want)


def test_a_copy_runs_apart():
    """A copy is a deep copy: updating it leaves the original as it was."""
    f = ss.FadingMemory(1, theta=0.9, sigma=0.1)
    f.update_many([0.0, 1.0, 2.5], [1.0, 2.0, 2.5])
    before = outputs(f.estimate())
    g = copy.copy(f)
    g.update(3.0, 10.0)
    same(outputs(f.estimate()), before)
    assert g.samples == f.samples + 1


def saved(f):
    """The library's bytes inside `f`'s pickle state."""
    _, (cls, state) = f.__reduce__()
    return cls, state


def test_damaged_state_is_refused():
    """The library's bytes truncated at every length, each byte flipped, another class's
    bytes: DamagedStateError, never another exception, never a crash."""
    rng = np.random.default_rng(7)
    f = ss.FadingMemory(2, theta=0.9, sigma=0.1)
    f.update_many(times(rng, 30), rng.standard_normal(30))
    cls, state = saved(f)
    assert isinstance(state, bytes)
    for n in range(len(state)):
        with pytest.raises(ss.DamagedStateError):
            cls._from_state(state[:n])
    for i in range(len(state)):
        for bit in (0, 3, 7):
            b = bytearray(state)
            b[i] ^= 1 << bit
            with pytest.raises(ss.DamagedStateError):
                cls._from_state(bytes(b))
    # another class's bytes, a newer version, not bytes
    _, other = saved(ss.ExpandingMemory(1))
    with pytest.raises(ss.DamagedStateError, match="not of a FadingMemory"):
        cls._from_state(other)
    _, kalman = saved(ss.KalmanFilter(1, x0=[0.0, 0.0], P0=1.0))
    with pytest.raises(ss.DamagedStateError, match="KalmanFilter"):
        cls._from_state(kalman)
    newer = bytearray(state)
    newer[8] = 9
    with pytest.raises(ss.DamagedStateError, match="version 9"):
        cls._from_state(bytes(newer))
    with pytest.raises(ss.DamagedStateError):
        cls._from_state("not bytes")


@pytest.mark.parametrize("name,make,data,run", CASES, ids=[c[0] for c in CASES])
def test_damaged_pickle_is_refused_never_a_crash(name, make, data, run):
    """A pickle truncated at random lengths or with a byte flipped at random positions: an
    exception (pickle's own where the damage breaks its framing, DamagedStateError where it
    reaches the library's bytes), or, where the flip leaves the data as they were (a flag
    pickle ignores), the very same filter; never a crash."""
    rng = np.random.default_rng([99, len(name)])
    f = make(rng)
    rows = data(rng)
    run(f, rows[: len(rows) // 2])
    blob = pickle.dumps(f)
    want = run(copy.deepcopy(f), rows[len(rows) // 2 :])
    for _ in range(60):
        b = bytearray(blob)
        if rng.random() < 0.5:
            b = b[: int(rng.integers(0, len(b)))]
        else:
            b[int(rng.integers(0, len(b)))] ^= 1 << int(rng.integers(0, 8))
        try:
            g = pickle.loads(bytes(b))
        except Exception:  # noqa: BLE001 - any refusal; a PanicException is not an Exception
            continue
        if type(g) is type(f):
            same(run(g, rows[len(rows) // 2 :]), want)


def test_crafted_body_is_refused():
    """A body with a valid checksum whose numbers break the filter's invariants (a covariance
    not positive semi-definite) is refused by the checks after decoding."""
    f = ss.KalmanFilter(1, x0=[0.0, 0.0], P0=1.0)
    _, state = saved(f)
    # P0 = I is stored after its key as CBOR 1.0s (0xf9 0x3c 0x00, a half); make one −1.0.
    i = state.find(bytes([0xF9, 0x3C, 0x00]), state.find(b"covariance"))
    assert i > 0
    body = bytearray(state)
    body[i + 1] = 0xBC
    header = 8 + 2 + 1 + body[10] + 8
    crc = zlib.crc32(bytes(body[:header]) + bytes(body[header + 4 :]))
    body[header : header + 4] = crc.to_bytes(4, "little")
    with pytest.raises(ss.DamagedStateError, match="covariance|state"):
        ss.KalmanFilter._from_state(bytes(body))


def test_continuous_filter_noise_is_in_the_checked_bytes():
    """ContinuousKalmanFilter's R is inside the library's bytes: a damaged R is refused, and
    another class's bytes are."""
    f = continuous_make(np.random.default_rng(3))
    cls, state = saved(f)
    assert isinstance(state, bytes)
    assert b"NoiseCovariance" in state
    for n in range(0, len(state), 7):
        with pytest.raises(ss.DamagedStateError):
            cls._from_state(state[:n])
    _, kalman = saved(ss.KalmanFilter(1, x0=[0.0, 0.0], P0=1.0))
    with pytest.raises(ss.DamagedStateError, match="KalmanFilter"):
        cls._from_state(kalman)


@pytest.mark.parametrize("make", [extended_make, unscented_user_make])
def test_callables_model_damaged_state_is_refused(make):
    """A filter over the caller's callables: its library bytes (the filter over the stand-in
    models) truncated or flipped, its callables tuple of the wrong length, an item not
    callable, or another class's bytes: DamagedStateError."""
    rng = np.random.default_rng(5)
    f = make(rng)
    rows = kalman_data(rng)
    kalman_run(f, rows[:5])
    cls, state = saved(f)
    user = isinstance(state[0], str)
    bytes_, callables = state[1] if user else state

    def again(b, c):
        return cls._from_state(("user", (b, c)) if user else (b, c))

    for n in range(0, len(bytes_), 5):
        with pytest.raises(ss.DamagedStateError):
            again(bytes_[:n], callables)
    for i in range(0, len(bytes_), 3):
        b = bytearray(bytes_)
        b[i] ^= 1 << (i % 8)
        with pytest.raises(ss.DamagedStateError):
            again(bytes(b), callables)
    with pytest.raises(ss.DamagedStateError):
        again(bytes_, callables[:-1])
    with pytest.raises(ss.DamagedStateError, match="h"):
        again(bytes_, callables[:4] + (None,) + callables[5:])
    with pytest.raises(ss.DamagedStateError, match="Q"):
        again(bytes_, callables[:6] + (np.eye(4),))
    with pytest.raises(ss.DamagedStateError):
        again(bytes_, callables[:4] + (3.0,) + callables[5:])
    _, kalman = saved(ss.KalmanFilter(1, x0=[0.0, 0.0], P0=1.0))
    with pytest.raises(ss.DamagedStateError, match="KalmanFilter"):
        again(kalman, callables)
    # the model is restored as given: the same callables, not copies
    g = copy.deepcopy(f)
    same(kalman_run(g, rows[5:]), kalman_run(f, rows[5:]))


def test_a_lambda_gives_pickles_own_error():
    """A callable pickle cannot find (a lambda) is pickle's own error when pickling; copy and
    deepcopy, which do not pickle the callables, still work."""
    f = ss.ExtendedKalmanFilter(np.zeros(4), 100.0, f=lambda x, t0, t1: cv_f(x, t0, t1), h=cv_h)
    with pytest.raises((pickle.PicklingError, AttributeError, TypeError)):
        pickle.dumps(f)
    g = copy.deepcopy(f)
    assert np.array_equal(g.state, f.state)
