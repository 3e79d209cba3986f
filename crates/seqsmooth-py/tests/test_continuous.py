"""ContinuousModel and ContinuousKalmanFilter (the library's model::continuous, discretised
exactly over each irregular step) against independent oracles: filterpy 2.0.0's
Q_continuous_white_noise with a hand-made F per step through LinearKalmanFilter (nearly
constant velocity), scipy's expm of Van Loan's block matrix (Singer, and any A), and
KalmanFilter(degree=, q=) (the polynomial model's closed form); and their refusals of bad
input."""

import numpy as np
import pytest
from filterpy.common import Q_continuous_white_noise
from scipy.linalg import block_diag, expm

import seqsmooth as ss
from conftest import bad_value

TOL = 1e-12


def rel(a, b):
    """The largest difference relative to the largest entry of the reference."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    assert a.shape == b.shape, (a.shape, b.shape)
    return np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300)


def van_loan(A, Qc, dt):
    """F = e^{A dt} and Q(dt) from scipy's expm of [[-A, Qc], [0, Aᵀ]] dt (Van Loan 1978)."""
    n = A.shape[0]
    M = np.zeros((2 * n, 2 * n))
    M[:n, :n], M[:n, n:], M[n:, n:] = -A, Qc, A.T
    E = expm(M * dt)
    F = E[n:, n:].T
    return F, F @ E[:n, n:]


def irregular_times(rng, count, t0=0.0):
    return t0 + np.cumsum(rng.uniform(0.05, 2.5, size=count))


def axis_order(blocks, d, per):
    """A block-diagonal matrix of `d` axes (each `per × per`, state ordered axis then
    derivative) reordered to derivative then axis."""
    m = block_diag(*blocks)
    order = [a * per + k for k in range(per) for a in range(d)]
    return m[np.ix_(order, order)]


def ncv_by_hand(q, dt):
    """Nearly constant velocity on len(q) axes over dt: F by hand, Q from filterpy's
    Q_continuous_white_noise, in the derivative-then-axis order."""
    d = len(q)
    F = np.block([[np.eye(d), dt * np.eye(d)], [np.zeros((d, d)), np.eye(d)]])
    Q = axis_order([Q_continuous_white_noise(dim=2, dt=dt, spectral_density=qa) for qa in q], d, 2)
    return F, Q


def run_both(model, by_hand, H, R, x0, P0, t, z):
    """The continuous filter's update_many and LinearKalmanFilter's with the per-step F and Q
    of `by_hand(dt)` (the first step from t0 = 0)."""
    ckf = ss.ContinuousKalmanFilter(model, H, R, x0, P0, t0=0.0)
    got = ckf.update_many(t, z)
    steps = np.diff(np.concatenate([[0.0], t]))
    Fs, Qs = zip(*(by_hand(dt) for dt in steps))
    n = len(x0)
    lkf = ss.LinearKalmanFilter(x0, P0, np.eye(n), H, np.zeros((n, n)), R)
    want = lkf.update_many(z, Fs=np.array(Fs), Qs=np.array(Qs))
    return ckf, got, lkf, want, np.array(Fs), np.array(Qs)


def test_nearly_constant_velocity_equals_filterpy_q_continuous_white_noise():
    """Two axes, per-axis q, irregular steps, missing components: the continuous filter's
    states, covariances (and the smoother's) equal LinearKalmanFilter's given filterpy's
    Q_continuous_white_noise and the hand F of each step, within 1e-12."""
    rng = np.random.default_rng(1)
    q = [0.7, 3.0]
    model = ss.ContinuousModel.nearly_constant_velocity(q=q, axes=2)
    for dt in (0.0, 0.3, 1.7, 40.0):
        F, Q = model.discretise(dt)
        Fh, Qh = ncv_by_hand(q, dt)
        assert rel(F, Fh) <= TOL and (dt == 0 or rel(Q, Qh) <= TOL), dt
    t = irregular_times(rng, 60)
    truth = np.outer(t, [1.5, -0.4]) + [3.0, 7.0]
    z = truth + rng.normal(0, 0.5, size=truth.shape)
    z[5, 0] = z[17, 1] = np.nan
    z[30] = np.nan
    H = np.hstack([np.eye(2), np.zeros((2, 2))])
    R = np.diag([0.25, 0.36])
    x0, P0 = np.zeros(4), np.eye(4) * 100.0
    ckf, got, lkf, want, Fs, Qs = run_both(model, lambda dt: ncv_by_hand(q, dt), H, R, x0, P0, t, z)
    assert rel(got[0], want[0]) <= TOL and rel(got[1], want[1]) <= TOL
    assert ckf.time == t[-1] and rel(ckf.state, lkf.x) <= TOL
    # The smoother against the linear filter's RTS over its own pass (next step's F, Q).
    xs, Ps = ckf.__class__(model, H, R, x0, P0).smooth(t, z)
    rts = lkf.rts_smoother(want[0], want[1], Fs=Fs, Qs=Qs)
    assert rel(xs, rts[0]) <= 1e-11 and rel(Ps, rts[1]) <= 1e-11
    # The smoother gains and predicted covariances from the same pass: filterpy's K and Pp.
    xg, Pg, K, Pp = ckf.__class__(model, H, R, x0, P0).smooth(t, z, return_gains=True)
    assert np.array_equal(xg, xs) and np.array_equal(Pg, Ps)
    assert K.shape == Pp.shape == (len(t), 4, 4) and not K[-1].any()
    assert rel(K, rts[2]) <= 1e-11 and rel(Pp, rts[3]) <= 1e-11


def test_singer_equals_scipy_van_loan_on_irregular_steps():
    """The Singer model's F and Q on irregular steps equal scipy's expm of Van Loan's block
    matrix within 1e-12 (each matrix relative to its largest entry), and the filter on it equals
    LinearKalmanFilter given those matrices."""
    rng = np.random.default_rng(2)
    alpha, var = 0.3, 4.0
    model = ss.ContinuousModel.singer(manoeuvre_alpha=alpha, manoeuvre_variance=var, axes=2)
    A, Qc = model.A, model.Qc
    assert Qc[4, 4] == 2 * alpha * var and A[4, 4] == -alpha
    for dt in rng.uniform(0.01, 6.0, size=40):
        F, Q = model.discretise(dt)
        Fv, Qv = van_loan(A, Qc, dt)
        assert rel(F, Fv) <= TOL and rel(Q, Qv) <= TOL, (dt, rel(F, Fv), rel(Q, Qv))
    # Singer (1970)'s acceleration variance σ_m² (1 − e^{−2αζ}) and the long-step limit.
    assert abs(model.discretise(2.0)[1][4, 4] - var * (1 - np.exp(-4 * alpha))) < 1e-14
    t = irregular_times(rng, 50)
    z = np.column_stack([np.sin(t / 5) * 30, np.cos(t / 7) * 20])
    z += rng.normal(0, 1.0, size=z.shape)
    H = np.hstack([np.eye(2), np.zeros((2, 4))])
    x0, P0 = np.zeros(6), np.eye(6) * 50.0
    ckf, got, _, want, _, _ = run_both(model, lambda dt: van_loan(A, Qc, dt), H, 1.0, x0, P0, t, z)
    assert rel(got[0], want[0]) <= TOL and rel(got[1], want[1]) <= TOL


def test_any_a_equals_scipy_van_loan():
    """A user's A (a damped oscillator with a drift) and a full Qc: F and Q against scipy."""
    A = np.array([[0.0, 1.0, 0.0], [-2.0, -0.3, 1.0], [0.0, 0.0, -0.5]])
    Qc = np.array([[0.1, 0.02, 0.0], [0.02, 0.4, 0.1], [0.0, 0.1, 0.9]])
    model = ss.ContinuousModel(A, Qc)
    for dt in (0.01, 0.37, 1.0, 2.9):
        F, Q = model.discretise(dt)
        Fv, Qv = van_loan(A, Qc, dt)
        assert rel(F, Fv) <= TOL and rel(Q, Qv) <= TOL, dt


@pytest.mark.parametrize("degree", [0, 1, 2, 3])
def test_polynomial_model_equals_kalman_filter(degree):
    """ContinuousModel.polynomial(degree, q) in the continuous filter equals
    KalmanFilter(degree=, q=) (Morrison (15.2.23)'s closed form) within 1e-12."""
    rng = np.random.default_rng(10 + degree)
    axes, q = 2, 0.8
    n = (degree + 1) * axes
    t = irregular_times(rng, 40, t0=0.0)
    z = np.column_stack([t**1.5, np.sin(t)]) + rng.normal(0, 0.3, size=(40, 2))
    z[7, 1] = np.nan
    x0, P0 = np.zeros(n), np.eye(n) * 10.0
    model = ss.ContinuousModel.polynomial(degree, q, axes=axes)
    H = np.eye(axes, n)
    ckf = ss.ContinuousKalmanFilter(model, H, 0.09, x0, P0)
    kf = ss.KalmanFilter(degree, x0, P0, axes=axes, q=q)
    got, want = ckf.update_many(t, z), kf.update_many(t, z, 0.09)
    for g, w in zip(got, want):
        assert rel(np.nan_to_num(g), np.nan_to_num(w)) <= TOL
    s_got = ss.ContinuousKalmanFilter(model, H, 0.09, x0, P0).smooth(t, z)
    s_want = ss.KalmanFilter(degree, x0, P0, axes=axes, q=q).smooth(t, z, 0.09)
    assert rel(s_got[0], s_want[0]) <= TOL and rel(s_got[1], s_want[1]) <= TOL


def test_update_one_at_a_time_equals_the_batch():
    """update(t, z) a measurement at a time (with predict between) equals update_many."""
    rng = np.random.default_rng(4)
    model = ss.ContinuousModel.nearly_constant_acceleration([0.5])
    t = irregular_times(rng, 20)
    z = t**2 + rng.normal(0, 1, size=20)

    def make():
        return ss.ContinuousKalmanFilter(model, [1.0, 0.0, 0.0], 1.0, [0, 0, 0], 100.0)

    batch = make().update_many(t, z)
    one = make()
    for k, (tk, zk) in enumerate(zip(t, z)):
        innovation = one.update(tk, zk)
        assert innovation.nis == pytest.approx(batch[2][k], rel=1e-14)
        assert np.array_equal(one.state, batch[0][k])
    # Per-update R: a larger R gives the measurement less weight.
    a, b = make(), make()
    a.update(1.0, 5.0)
    b.update(1.0, 5.0, R=100.0)
    assert abs(b.state[0]) < abs(a.state[0])


def bad(call, *words):
    with pytest.raises(ss.SeqsmoothError) as e:
        call()
    for w in words:
        assert w in str(e.value), (w, str(e.value))
    return e.value


def test_bad_models_are_refused_by_name():
    ok = np.eye(2)
    bad(lambda: ss.ContinuousModel(np.zeros((2, 3)), ok), "A")
    bad(lambda: ss.ContinuousModel([[0, 1], [0, np.nan]], ok), "A")
    bad(lambda: ss.ContinuousModel(np.zeros((2, 2)), [[1, 0.5], [0, 1]]), "Qc", "symmetric")
    bad(lambda: ss.ContinuousModel(np.zeros((2, 2)), [[1, 2], [2, 1]]), "Qc", "semi-definite")
    bad(lambda: ss.ContinuousModel(np.zeros((2, 2)), np.eye(3)), "Qc")
    bad(lambda: ss.ContinuousModel(np.zeros((2, 2)), [[np.inf, 0], [0, 1]]), "Qc")
    e = bad(lambda: ss.ContinuousModel.singer(0.0, 1.0), "manoeuvre_alpha")
    assert isinstance(e, ss.ParameterError)
    bad(lambda: ss.ContinuousModel.singer(0.5, -1.0), "manoeuvre_variance")
    bad(lambda: ss.ContinuousModel.singer(0.5, 1.0, axes=0), "axes")
    bad(lambda: ss.ContinuousModel.nearly_constant_velocity([1.0, -2.0]), "q")
    bad(lambda: ss.ContinuousModel.nearly_constant_velocity([1.0, 2.0], axes=3), "q")
    bad(lambda: ss.ContinuousModel.polynomial(ss.MAX_DEGREE + 1, 1.0), "degree")
    bad(lambda: ss.ContinuousModel.polynomial(1, []), "axes")
    m = ss.ContinuousModel.nearly_constant_velocity(1.0)
    bad(lambda: m.discretise(-1.0), "step")
    bad(lambda: m.discretise(np.nan), "step")


def test_bad_filter_input_is_refused_and_the_filter_unchanged():
    model = ss.ContinuousModel.nearly_constant_velocity([1.0, 1.0])
    H = np.hstack([np.eye(2), np.zeros((2, 2))])

    def make():
        return ss.ContinuousKalmanFilter(model, H, 1.0, np.zeros(4), np.eye(4))

    bad(lambda: ss.ContinuousKalmanFilter(model, np.eye(2, 3), 1.0, np.zeros(4), 1.0), "H")
    bad(lambda: ss.ContinuousKalmanFilter(model, H, [[1, 2], [2, 1]], np.zeros(4), 1.0), "R")
    bad(lambda: ss.ContinuousKalmanFilter(model, H, 1.0, np.zeros(3), 1.0))
    bad(lambda: ss.ContinuousKalmanFilter(model, H, 1.0, np.zeros(4), -np.eye(4)))
    kf = make()
    kf.update(1.0, [1.0, 2.0])
    x, P, time = kf.state, kf.covariance, kf.time
    bad(lambda: kf.update(0.5, [1.0, 2.0]), "before")
    bad(lambda: kf.update(2.0, [1.0, 2.0, 3.0]))
    bad(lambda: kf.update(2.0, [np.inf, 2.0]))
    bad(lambda: kf.update(2.0, [1.0, 2.0], R=[[1, 0], [0, -1]]))
    bad(lambda: kf.update(np.nan, [1.0, 2.0]))
    assert np.array_equal(kf.state, x) and np.array_equal(kf.covariance, P)
    assert kf.time == time
    t = np.array([2.0, 3.0, 4.0, 3.5, 5.0])
    z = np.ones((5, 2))
    e = bad(lambda: kf.update_many(t, z), "sample 3")
    assert e.index == 3 and kf.time == 4.0
    kf = make()
    z[2, 1] = np.inf
    e = bad(lambda: kf.update_many(np.arange(1.0, 6.0), z))
    assert e.index == 2 and kf.time == 2.0


def test_ten_thousand_random_bad_calls_never_panic():
    """10⁴ seeded random calls on the new entry points with bad shapes and values: each works
    or raises a SeqsmoothError (never a panic or another exception); a refused update leaves
    the filter as it was."""
    rng = np.random.default_rng(33)
    specials = [np.nan, np.inf, -np.inf, -1.0, 0.0, 1e308, 1e-308]

    def junk():
        return bad_value(rng, specials)

    def number():
        return float(rng.choice(specials)) if rng.random() < 0.5 else float(rng.normal())

    model = ss.ContinuousModel.nearly_constant_velocity(1.0)

    def fresh():
        return ss.ContinuousKalmanFilter(model, [1.0, 0.0], 1.0, [0.0, 0.0], 10.0)

    kf = fresh()
    refused = 0
    for _ in range(10_000):
        call = rng.integers(7)
        x, P, time = kf.state, kf.covariance, kf.time
        try:
            if call == 0:
                ss.ContinuousModel(junk(), junk())
            elif call == 1:
                ss.ContinuousModel.singer(number(), number(), int(rng.integers(0, 3)))
            elif call == 2:
                ss.ContinuousModel.nearly_constant_velocity(junk()).discretise(number())
            elif call == 3:
                ss.ContinuousKalmanFilter(model, junk(), junk(), junk(), junk())
            elif call == 4:
                kf.update(time + number(), junk(), R=junk() if rng.random() < 0.5 else None)
            elif call == 5:
                kf.update_many(time + np.abs(junk()), junk())
            else:
                kf.predict(time + number())
        except ss.SeqsmoothError:
            refused += 1
            if call in (4, 6):
                assert np.array_equal(kf.state, x) and np.array_equal(kf.covariance, P)
        if not np.all(np.isfinite(kf.covariance)):
            raise AssertionError("the filter holds a number that is not finite")
        if rng.random() < 0.02 or kf.time > 1e6:
            kf = fresh()
    assert refused > 3_000
