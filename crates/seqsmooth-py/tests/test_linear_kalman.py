"""LinearKalmanFilter (the library's kalman::discrete) against filterpy 2.0.0's KalmanFilter,
batch_filter, rts_smoother and FixedLagSmoother on stored fixtures
(tests/fixtures/filterpy_linear.json, made by scripts/make_linear_kalman_fixtures.py), and its
refusals of bad matrices."""

import json
import os

import numpy as np
import pytest

import seqsmooth as ss
from conftest import bad_value

FIXTURES = os.path.join(os.path.dirname(__file__), "fixtures", "filterpy_linear.json")
with open(FIXTURES) as f:
    PROBLEMS = json.load(f)["problems"]

TOL = 1e-10


def rel(a, b):
    """The largest difference relative to the largest entry of the reference."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    assert a.shape == b.shape, (a.shape, b.shape)
    return np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300)


def zs_of(problem):
    p = np.atleast_2d(np.asarray(problem["H"])).shape[0]
    return np.array([[np.nan] * p if z is None else np.atleast_1d(z) for z in problem["zs"]])


def make(problem, **extra):
    return ss.LinearKalmanFilter(
        problem["x0"],
        problem["P0"],
        problem["F"],
        problem["H"],
        problem["Q"],
        problem["R"],
        **extra,
    )


def per_step(problem):
    return {k: np.asarray(problem[k]) for k in ("Fs", "Qs", "Hs", "Rs") if k in problem}


@pytest.mark.parametrize("name", ["cv_qdwn", "control_diag", "per_step"])
def test_batch_filter_matches_filterpy(name):
    """update_many gives filterpy's batch_filter: means, covariances, and the predicted ones
    (Q_discrete_white_noise, diagonal and full Q; a scalar R; B u; per-step F, Q, H, R;
    missing measurements)."""
    p = PROBLEMS[name]
    extra = {"B": p["B"]} if "B" in p else {}
    kf = make(p, **extra)
    args = per_step(p)
    if "us" in p:
        args["us"] = np.asarray(p["us"])
    out = kf.update_many(zs_of(p), **args)
    for got, key in zip(out, ["means", "covariances", "means_p", "covariances_p"]):
        assert rel(got, p[key]) < TOL, (name, key, rel(got, p[key]))
    assert kf.steps == len(p["zs"])
    assert rel(kf.x, p["means"][-1]) < TOL and rel(kf.P, p["covariances"][-1]) < TOL


@pytest.mark.parametrize("name", ["cv_qdwn", "control_diag", "per_step"])
def test_rts_smoother_matches_filterpy(name):
    """rts_smoother over update_many's own pass gives filterpy's rts_smoother: states,
    covariances, gains and predicted covariances (filterpy's smoother predicts F x without
    B u, so the control problem's smoother is asked without us)."""
    p = PROBLEMS[name]
    extra = {"B": p["B"]} if "B" in p else {}
    kf = make(p, **extra)
    args = per_step(p)
    run = dict(args)
    if "us" in p:
        run["us"] = np.asarray(p["us"])
    xs, ps, _, _ = kf.update_many(zs_of(p), **run)
    smooth_args = {k: v for k, v in args.items() if k in ("Fs", "Qs")}
    x, P, K, Pp = make(p, **extra).rts_smoother(xs, ps, **smooth_args)
    for got, key in zip((x, P, K, Pp), ["rts_x", "rts_P", "rts_K", "rts_Pp"]):
        assert rel(got, p[key]) < TOL, (name, key, rel(got, p[key]))


def test_step_by_step_is_the_batch():
    """predict() and update() one step at a time, with this step's matrices passed in, give
    update_many's numbers bit for bit; the innovation is filterpy's y and S at that step."""
    p = PROBLEMS["per_step"]
    kf = make(p)
    zs = zs_of(p)
    xs, ps, xp, pp = make(p).update_many(zs, **per_step(p))
    for k, z in enumerate(zs):
        kf.predict(F=p["Fs"][k], Q=p["Qs"][k])
        assert np.array_equal(kf.x, xp[k]) and np.array_equal(kf.P, pp[k])
        inn = kf.update(z, R=p["Rs"][k], H=p["Hs"][k])
        assert np.array_equal(kf.x, xs[k]) and np.array_equal(kf.P, ps[k])
        H = np.asarray(p["Hs"][k])
        assert rel(inn.innovation, z - H @ xp[k]) < 1e-12
        assert rel(inn.covariance, H @ pp[k] @ H.T + np.asarray(p["Rs"][k])) < 1e-12


def test_fixed_lag_is_exact_and_filterpys_is_not():
    """The fixed-lag smoother gives each step's estimate from the LAG steps after it: filterpy's
    own rts_smoother over the measurements up to k + LAG, read at k, within 1e-10 (states and
    covariances). filterpy's FixedLagSmoother does not give these numbers (it starts each
    smoothed gain from the updated P, and keeps the filter's estimate for the first N steps):
    its difference from the exact estimates is recorded here, not hidden."""
    p = PROBLEMS["fixed_lag"]
    kf = make(p)
    x, P = kf.fixed_lag_smoother(np.asarray(p["zs"]), p["lag"])
    assert rel(x, p["exact_x"]) < TOL, rel(x, p["exact_x"])
    assert rel(P, p["exact_P"]) < TOL, rel(P, p["exact_P"])
    assert kf.steps == 0  # the filter itself is not moved
    assert rel(p["filterpy_fls_x"], p["exact_x"]) > 1e-3


def test_streamed_fixed_lag_is_the_batch():
    """LinearFixedLagSmoother, a measurement at a time with this step's matrices, gives
    fixed_lag_smoother's numbers bit for bit, each step once, the last lag at finish."""
    p = PROBLEMS["per_step"]
    lag = 3
    xs, ps = make(p).fixed_lag_smoother(zs_of(p), lag, **per_step(p))
    s = ss.LinearFixedLagSmoother(make(p), lag)
    seen = []
    for k, z in enumerate(zs_of(p)):
        out = s.update(z, F=p["Fs"][k], Q=p["Qs"][k], H=p["Hs"][k], R=p["Rs"][k])
        assert (out is None) == (k < lag)
        if out is not None:
            i, x, P = out
            assert i == k - lag and np.array_equal(x, xs[i]) and np.array_equal(P, ps[i])
            seen.append(i)
    with pytest.raises(ss.ParameterError):
        s.update(zs_of(p)[0], R=[[1.0, 2.0], [2.0, 1.0]])  # refused, the smoother unchanged
    indices, x, P = s.finish()
    assert list(indices) == list(range(len(xs) - lag, len(xs)))
    assert np.array_equal(x, xs[-lag:]) and np.array_equal(P, ps[-lag:])
    assert seen == list(range(len(xs) - lag))
    with pytest.raises(ss.SeqsmoothError):
        s.update(zs_of(p)[0])


def test_polynomial_model_from_matrices():
    """The polynomial KalmanFilter on unit steps and the same model as matrices agree."""
    F = np.array([[1.0, 1.0], [0.0, 1.0]])
    Q = 0.3 * np.array([[1 / 3, 1 / 2], [1 / 2, 1.0]])
    poly = ss.KalmanFilter(1, [0.0, 1.0], [[4.0, 0.0], [0.0, 1.0]], t0=0.0, q=0.3)
    lin = ss.LinearKalmanFilter([0.0, 1.0], [[4.0, 0.0], [0.0, 1.0]], F, [1.0, 0.0], Q, 0.5)
    zs = np.array([1.2, 1.9, np.nan, 4.3, 4.8])
    xs, ps, _ = poly.update_many(np.arange(1.0, 6.0), zs, 0.5)
    lx, lp, _, _ = lin.update_many(zs)
    assert rel(lx, xs) < 1e-14 and rel(lp, ps) < 1e-14


BAD = {
    "not square": np.ones((2, 3)),
    "not symmetric": np.array([[1.0, 0.5], [0.0, 1.0]]),
    "indefinite": np.array([[1.0, 2.0], [2.0, 1.0]]),
    "nan": np.array([[np.nan, 0.0], [0.0, 1.0]]),
    "inf": np.array([[np.inf, 0.0], [0.0, 1.0]]),
}


def cv():
    F = np.array([[1.0, 1.0], [0.0, 1.0]])
    return ss.LinearKalmanFilter([0.0, 1.0], np.eye(2), F, [[1.0, 0.0]], 0.01 * np.eye(2), 1.0)


@pytest.mark.parametrize("what", list(BAD))
@pytest.mark.parametrize("where", ["P0", "Q", "F", "predict_Q", "predict_F", "set_P", "set_Q"])
def test_bad_matrices_are_refused_by_name(what, where):
    bad = BAD[what]
    if where in ("F", "predict_F") and what in ("not symmetric", "indefinite"):
        bad = np.ones((3, 3))  # F need not be symmetric: a wrong shape instead
    kf = cv()
    x, P = kf.x, kf.P
    word = where.split("_")[-1][0]
    with pytest.raises(ss.SeqsmoothError) as e:
        if where == "P0":
            ss.LinearKalmanFilter([0.0, 1.0], bad, np.eye(2), [[1.0, 0.0]], np.eye(2), 1.0)
        elif where == "Q":
            ss.LinearKalmanFilter([0.0, 1.0], np.eye(2), np.eye(2), [[1.0, 0.0]], bad, 1.0)
        elif where == "F":
            ss.LinearKalmanFilter([0.0, 1.0], np.eye(2), bad, [[1.0, 0.0]], np.eye(2), 1.0)
        elif where == "predict_Q":
            kf.predict(Q=bad)
        elif where == "predict_F":
            kf.predict(F=bad)
        elif where == "set_P":
            kf.P = bad
        elif where == "set_Q":
            kf.Q = bad
    if where != "P0":
        assert word in str(e.value), str(e.value)
    assert np.array_equal(kf.x, x) and np.array_equal(kf.P, P) and kf.steps == 0


def test_bad_per_step_matrix_names_the_step():
    """A bad R at step 7 of a batch: the error names R and step 7; steps 0-6 are taken."""
    kf = cv()
    Rs = np.ones((12, 1, 1))
    Rs[7, 0, 0] = -1.0
    with pytest.raises(ss.ParameterError) as e:
        kf.update_many(np.arange(12.0), Rs=Rs)
    assert e.value.index == 7 and "R" in str(e.value), str(e.value)
    assert kf.steps == 7
    before = (kf.x, kf.P)
    with pytest.raises(ss.SeqsmoothError):
        kf.update([1.0], R=[[-2.0]])
    assert np.array_equal(kf.x, before[0]) and np.array_equal(kf.P, before[1])


def test_ten_thousand_random_bad_calls_never_panic():
    """10⁴ seeded random calls with bad shapes, values and matrices (the filter, its batch and
    smoothers, the streamed fixed-lag smoother): each either works or raises a SeqsmoothError
    (never a panic or another exception); a refused call leaves the filter's estimate (the
    smoother's count) as it was."""
    rng = np.random.default_rng(32)
    specials = [np.nan, np.inf, -np.inf, -1.0, 0.0, 1e308, 1e-308]

    def junk():
        return bad_value(rng, specials)

    kf = cv()
    lagged = ss.LinearFixedLagSmoother(kf, 3)
    refused = 0
    for _ in range(10_000):
        call = rng.integers(8)
        x, P = kf.x, kf.P
        try:
            if call == 0:
                kf.predict(F=junk(), Q=junk() if rng.random() < 0.5 else None)
            elif call == 1:
                kf.update(junk(), R=junk() if rng.random() < 0.5 else None)
            elif call == 2:
                kf.update_many(junk(), Rs=junk() if rng.random() < 0.5 else None)
            elif call == 3:
                kf.P = junk()
            elif call == 4:
                kf.x = junk()
            elif call == 5:
                ss.LinearKalmanFilter(junk(), junk(), junk(), junk(), junk(), junk())
            elif call == 6:
                kf.rts_smoother(junk(), junk(), Fs=junk() if rng.random() < 0.5 else None)
            else:
                pushed = lagged.pushed
                try:
                    lagged.update(junk(), R=junk() if rng.random() < 0.5 else None)
                except ss.SeqsmoothError:
                    assert lagged.pushed == pushed
                    raise
        except ss.SeqsmoothError:
            refused += 1
            if call in (0, 1, 3, 4):
                assert np.array_equal(kf.x, x) and np.array_equal(kf.P, P)
        if not np.all(np.isfinite(kf.P)) or kf.steps > 10**6:
            raise AssertionError("the filter holds a number that is not finite")
        if rng.random() < 0.01:
            kf = cv()
    assert refused > 5_000
