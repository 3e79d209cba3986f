"""The user's own model as Python callables: ExtendedKalmanFilter (f, h, Jacobians, Q) and
UnscentedKalmanFilter(f=, h=) against filterpy's ExtendedKalmanFilter and UnscentedKalmanFilter
with MerweScaledSigmaPoints, live, within 1e-10; the library's differenced Jacobians; angle
residuals across +-pi; the smoother; and bad callables (raising, wrong shape, NaN, infinity)
refused naming the callable and the sample, the filter unchanged, in a seeded loop of 10^4 bad
calls without a panic."""

from __future__ import annotations

import math

import numpy as np
import pytest
from filterpy.common import Q_discrete_white_noise
from filterpy.kalman import ExtendedKalmanFilter as FilterpyEKF
from filterpy.kalman import MerweScaledSigmaPoints
from filterpy.kalman import UnscentedKalmanFilter as FilterpyUKF

import seqsmooth as ss

TOL = 1e-10
SITE = (0.0, 0.0)
R = np.diag([4.0, 1e-4])


def F(dt):
    """Constant velocity on two axes, the state (x, vx, y, vy)."""
    return np.array([[1, dt, 0, 0], [0, 1, 0, 0], [0, 0, 1, dt], [0, 0, 0, 1]], dtype=float)


def f_linear(x, t0, t1):
    return F(t1 - t0) @ x


def F_jacobian(x, t0, t1):
    return F(t1 - t0)


def h(x, t=0.0):
    """Range and bearing (radians, from +x towards +y) of (x, y) from SITE."""
    dx, dy = x[0] - SITE[0], x[2] - SITE[1]
    return np.array([math.hypot(dx, dy), math.atan2(dy, dx)])


def H_jacobian(x, t=0.0):
    dx, dy = x[0] - SITE[0], x[2] - SITE[1]
    r2 = dx * dx + dy * dy
    r = math.sqrt(r2)
    return np.array([[dx / r, 0, dy / r, 0], [-dy / r2, 0, dx / r2, 0]])


def wrap(a):
    return (a + math.pi) % (2 * math.pi) - math.pi


def track(x0, n, rng, dt=1.0):
    """A constant-velocity target's range and bearing, noisy (R), at t = dt, 2 dt, ..."""
    x, zs = np.array(x0, float), []
    for _ in range(n):
        x = F(dt) @ x
        z = h(x) + rng.normal(0.0, np.sqrt(np.diag(R)))
        z[1] = wrap(z[1])
        zs.append(z)
    return np.arange(1, n + 1) * dt, np.array(zs)


def close(a, b, tol=TOL):
    a, b = np.asarray(a, float), np.asarray(b, float)
    scale = max(np.abs(b).max(), 1e-300)
    return np.abs(a - b).max() / scale <= tol


X0 = np.array([-300.0, 4.0, 40.0, -2.0])
P0 = np.diag([100.0, 4.0, 100.0, 4.0])
Q = Q_discrete_white_noise(dim=2, dt=1.0, var=0.05, block_size=2)


def filterpy_ekf(prior, zs, angles):
    ekf = FilterpyEKF(dim_x=4, dim_z=2)
    ekf.x, ekf.P, ekf.F, ekf.Q, ekf.R = prior.reshape(4, 1).copy(), P0.copy(), F(1.0), Q, R

    def hx(x):
        return h(np.ravel(x)).reshape(2, 1)

    def hj(x):
        return H_jacobian(np.ravel(x))

    def residual(a, b):
        y = a - b
        if angles:
            y[1, 0] = wrap(y[1, 0])
        return y

    out = []
    for z in zs:
        ekf.predict()
        ekf.update(z.reshape(2, 1), hj, hx, R=R, residual=residual)
        nis = (ekf.y.T @ ekf.SI @ ekf.y).item()
        out.append((ekf.x.ravel().copy(), ekf.P.copy(), nis))
    return out


@pytest.mark.parametrize("crossing", [False, True])
def test_ekf_equals_filterpy(crossing):
    """filterpy's ExtendedKalmanFilter with the same hx and HJacobian (its F and Q matrices:
    a linear f), a range/bearing target; with crossing, the bearing passes +-pi (a target west
    of the site crossing y = 0) and both wrap the bearing residual."""
    rng = np.random.default_rng(7)
    # Crossing: y passes 0 slowly at x near -290, so that noisy bearings and predictions
    # straddle +-pi (without the wrap the estimate leaves filterpy's by 4 times its size).
    x0 = np.array([-300.0, 4.0, 10.0, -0.5]) if crossing else np.array([300.0, -4.0, 40.0, 2.0])
    ts, zs = track(x0, 40, rng)
    # Far from +-pi the wrap changes nothing: filterpy without it there.
    want = filterpy_ekf(x0, zs, angles=crossing)
    ekf = ss.ExtendedKalmanFilter(
        x0, P0, f_linear, h, Q=Q, F_jacobian=F_jacobian, H_jacobian=H_jacobian, angles=[1]
    )
    for t, z, (x, p, nis) in zip(ts, zs, want):
        i = ekf.update(t, z, R)
        assert close(ekf.state, x) and close(ekf.covariance, p), t
        assert abs(i.nis - nis) <= TOL * max(nis, 1.0)
    if crossing:
        assert np.ptp(zs[:, 1]) > 6.0  # the bearing did cross +-pi
    # update_many gives the same numbers as update, bit for bit.
    again = ss.ExtendedKalmanFilter(
        x0, P0, f_linear, h, Q=Q, F_jacobian=F_jacobian, H_jacobian=H_jacobian, angles=[1]
    )
    states, covs, nis = again.update_many(ts, zs, R)
    assert np.array_equal(states[-1], ekf.state) and np.array_equal(covs[-1], ekf.covariance)
    assert close(states, np.array([x for x, _, _ in want]))


def test_the_angle_residual_is_wrapped_only_with_angles():
    """A target just north of the -x axis (bearing pi - 0.002) measured just south of it
    (-pi + 0.001): with angles=[1] the bearing's innovation is 0.003, without it -2 pi + 0.003
    - the angle rule is what the filterpy comparison across +-pi rests on."""
    x0 = np.array([-1000.0, 0.0, 2.0, 0.0])
    z = np.array([1000.0, -math.pi + 0.001])
    want = wrap(z[1] - h(x0)[1])
    wrapped = ss.ExtendedKalmanFilter(x0, P0, f_linear, h, angles=[1]).update(0.0, z, R)
    plain = ss.ExtendedKalmanFilter(x0, P0, f_linear, h).update(0.0, z, R)
    assert abs(want - 0.003) < 1e-5
    assert abs(wrapped.innovation[1] - want) < 1e-15
    assert abs(plain.innovation[1] - (want - 2 * math.pi)) < 1e-12


def test_differenced_jacobians_and_callable_q():
    """No F_jacobian or H_jacobian: the library's central differences, within 1e-7 of the
    analytic ones' run; Q as a callable Q(t0, t1) equal to the constant one bit for bit; the
    smoother ends at the filter's estimate and shrinks the covariance before it."""
    rng = np.random.default_rng(3)
    ts, zs = track(np.array([300.0, -4.0, 40.0, 2.0]), 30, rng)
    exact = ss.ExtendedKalmanFilter(
        X0, P0, f_linear, h, Q=Q, F_jacobian=F_jacobian, H_jacobian=H_jacobian
    )
    differenced = ss.ExtendedKalmanFilter(X0, P0, f_linear, h, Q=Q)
    called = ss.ExtendedKalmanFilter(
        X0, P0, f_linear, h, Q=lambda a, b: Q, F_jacobian=F_jacobian, H_jacobian=H_jacobian
    )
    a, pa, _ = exact.update_many(ts, zs, R)
    b, pb, _ = differenced.update_many(ts, zs, R)
    c, pc, _ = called.update_many(ts, zs, R)
    assert close(b, a, 1e-7) and close(pb, pa, 1e-6)
    assert np.array_equal(a, c) and np.array_equal(pa, pc)
    fresh = ss.ExtendedKalmanFilter(
        X0, P0, f_linear, h, Q=Q, F_jacobian=F_jacobian, H_jacobian=H_jacobian
    )
    xs, ps = fresh.smooth(ts, zs, R)
    assert fresh.time == 0.0  # smooth does not move the filter
    assert close(xs[-1], a[-1], 1e-12) and close(ps[-1], pa[-1], 1e-12)
    assert np.all(
        np.diagonal(ps[:-1], axis1=1, axis2=2)
        <= np.diagonal(pa[:-1], axis1=1, axis2=2) * (1 + 1e-12)
    )


def test_iterated_update_moves_towards_the_measurement():
    """iterations > 1: the iterated update (Morrison (12.5.10)-(12.5.17)); on a linear h it
    equals the plain update, on range/bearing with a poor prior it differs."""
    lin = lambda x, t: np.array([x[0], x[2]])  # noqa: E731
    rng = np.random.default_rng(5)
    ts, zs = track(np.array([300.0, -4.0, 40.0, 2.0]), 5, rng)
    zl = np.array([[z[0], z[1]] for z in zs])
    plain = ss.ExtendedKalmanFilter(X0, P0, f_linear, lin, Q=Q)
    iterated = ss.ExtendedKalmanFilter(X0, P0, f_linear, lin, Q=Q, iterations=5)
    assert close(plain.update_many(ts, zl, R)[0], iterated.update_many(ts, zl, R)[0], 1e-9)
    poor = np.diag([1e4, 25.0, 1e4, 25.0])
    one = ss.ExtendedKalmanFilter(X0, poor, f_linear, h, Q=Q)
    more = ss.ExtendedKalmanFilter(X0, poor, f_linear, h, Q=Q, iterations=20)
    one.update(ts[0], zs[0], R)
    more.update(ts[0], zs[0], R)
    assert not close(one.state, more.state, 1e-6)


def fx_drag(x, dt):
    """A nonlinear motion: velocity decaying with its own square (quadratic drag)."""
    k = 1e-3
    v = np.array([x[1], x[3]])
    s = np.hypot(*v)
    v1 = v / (1.0 + k * s * dt)
    return np.array([x[0] + v1[0] * dt, v1[0], x[2] + v1[1] * dt, v1[1]])


@pytest.mark.parametrize("alpha,beta,kappa", [(1.0, 2.0, 0.0), (0.3, 2.0, 1.0)])
def test_ukf_equals_filterpy(alpha, beta, kappa):
    """filterpy's UnscentedKalmanFilter with MerweScaledSigmaPoints and the same fx and hx
    (quadratic drag, range/bearing), irregular steps; then the unscented smoother against
    filterpy's rts_smoother (constant dt and Q there, so a regular run)."""
    rng = np.random.default_rng(11)
    x0 = np.array([300.0, -8.0, 40.0, 3.0])
    ts = np.cumsum(rng.uniform(0.5, 2.0, 30))
    x, zs = x0.copy(), []
    prev = 0.0
    for t in ts:
        x = fx_drag(x, t - prev)
        prev = t
        zs.append(h(x) + rng.normal(0.0, np.sqrt(np.diag(R))))
    zs = np.array(zs)
    points = MerweScaledSigmaPoints(4, alpha=alpha, beta=beta, kappa=kappa)

    def both():
        fp = FilterpyUKF(dim_x=4, dim_z=2, dt=1.0, hx=h, fx=fx_drag, points=points)
        fp.x, fp.P, fp.Q, fp.R = x0.copy(), P0.copy(), Q, R
        f = lambda x, a, b: fx_drag(x, b - a)  # noqa: E731
        ours = ss.UnscentedKalmanFilter(
            x0=x0, P0=P0, f=f, h=h, Q=Q, sigma_points=(alpha, beta, kappa)
        )
        return fp, ours

    fp, ukf = both()
    prev = 0.0
    for t, z in zip(ts, zs):
        fp.predict(dt=t - prev)
        fp.update(z)
        prev = t
        i = ukf.update(t, z, R)
        assert close(ukf.state, fp.x) and close(ukf.covariance, fp.P), t
        nis = fp.y @ fp.SI @ fp.y
        assert abs(i.nis - nis) <= TOL * max(nis, 1.0)
    # The smoother on a regular run.
    tr = np.arange(1.0, 21.0)
    fp, ukf = both()
    mu, cov = fp.batch_filter(zs[:20])
    xs, ps, _ = fp.rts_smoother(mu, cov)
    sx, sp = ukf.smooth(tr, zs[:20], R)
    assert close(sx, xs) and close(sp, ps)


def test_ukf_keywords_are_exclusive():
    with pytest.raises(ss.ParameterError):
        ss.UnscentedKalmanFilter(1, X0, P0, f=f_linear, h=h)
    with pytest.raises(ss.ParameterError):
        ss.UnscentedKalmanFilter(x0=X0, P0=P0, f=f_linear)
    with pytest.raises(ss.ParameterError, match="angles"):
        ss.UnscentedKalmanFilter(x0=X0, P0=P0, f=f_linear, h=h, angles=[2])
    with pytest.raises(ss.InvalidTypeError, match="h must be callable"):
        ss.ExtendedKalmanFilter(X0, P0, f_linear, 3.0)


def snapshot(flt):
    return flt.state.copy(), flt.covariance.copy(), flt.time


def unchanged(flt, before):
    x, p, t = snapshot(flt)
    return np.array_equal(x, before[0]) and np.array_equal(p, before[1]) and t == before[2]


BAD = {
    "raises": lambda good: (_ for _ in ()).throw(RuntimeError("boom")),
    "shape": lambda good: np.append(good, 1.0),
    "matrix": lambda good: np.outer(good, good),
    "nan": lambda good: np.where(np.arange(good.size).reshape(good.shape) == 0, np.nan, good),
    "inf": lambda good: np.where(np.arange(good.size).reshape(good.shape) == 0, np.inf, good),
    "none": lambda good: None,
    "text": lambda good: "x",
}
WORDS = {
    "raises": "raised RuntimeError: boom",
    "shape": "returned shape",
    "matrix": "returned shape",
    "nan": "returned NaN",
    "inf": "returned inf",
    "none": "returned shape []",
    "text": "not an array of numbers",
}


def spoiled(fn, how, when):
    """``fn`` that misbehaves as ``how`` where ``when(t)`` says so (``t`` its last time)."""

    def call(*args):
        good = np.asarray(fn(*args), float)
        return BAD[how](good) if when(args[-1]) else good

    return call


@pytest.mark.parametrize("which", ["f", "h", "F_jacobian", "H_jacobian", "Q"])
@pytest.mark.parametrize("how", list(BAD))
@pytest.mark.parametrize("kind", ["ekf", "ukf"])
def test_bad_callable_is_named_and_leaves_the_filter(which, how, kind):
    """A callable that raises or returns a wrong shape, a NaN or an infinity: a
    ParameterError (a SeqsmoothError) naming the callable and the time, the filter as it was;
    in update_many, also the sample's index, the samples before it taken."""
    if kind == "ukf" and which in ("F_jacobian", "H_jacobian"):
        pytest.skip("the unscented filter takes no Jacobians")
    state = {"bad": False}
    good = {
        "f": f_linear,
        "h": h,
        "F_jacobian": F_jacobian,
        "H_jacobian": H_jacobian,
        "Q": lambda a, b: Q,
    }
    kw = {k: spoiled(v, how, lambda t: state["bad"]) if k == which else v for k, v in good.items()}
    if kind == "ekf":
        flt = ss.ExtendedKalmanFilter(X0, P0, **kw)
    else:
        flt = ss.UnscentedKalmanFilter(x0=X0, P0=P0, f=kw["f"], h=kw["h"], Q=kw["Q"])
    rng = np.random.default_rng(1)
    ts, zs = track(np.array([300.0, -4.0, 40.0, 2.0]), 6, rng)
    flt.update(ts[0], zs[0], R)
    before = snapshot(flt)
    state["bad"] = True
    with pytest.raises(ss.ParameterError) as e:
        flt.update(ts[1], zs[1], R)
    assert isinstance(e.value, ss.SeqsmoothError)
    message = str(e.value)
    assert message.startswith(
        f"{which} over t = " if which in ("f", "F_jacobian", "Q") else f"{which} at t = "
    ), message
    assert WORDS[how] in message, message
    # The callable's own exception is the cause; none where it raised nothing.
    if how == "raises":
        assert isinstance(e.value.__cause__, RuntimeError) and str(e.value.__cause__) == "boom"
    else:
        assert e.value.__cause__ is None
    assert unchanged(flt, before)
    # In a batch: sample 2 is the first bad one.
    kw = {k: spoiled(v, how, lambda t: t >= ts[2]) if k == which else v for k, v in good.items()}
    if kind == "ekf":
        flt = ss.ExtendedKalmanFilter(X0, P0, **kw)
    else:
        flt = ss.UnscentedKalmanFilter(x0=X0, P0=P0, f=kw["f"], h=kw["h"], Q=kw["Q"])
    with pytest.raises(ss.ParameterError) as e:
        flt.update_many(ts, zs, R)
    assert e.value.index == 2, str(e.value)
    assert str(e.value).startswith(f"sample 2 of the batch: {which} "), str(e.value)
    assert flt.time == ts[1]


def test_a_bad_constant_q_is_refused():
    with pytest.raises(
        ss.ParameterError,
        match=r"Q with \[1, 0\] = 0 and \[0, 1\] = 1 is invalid: must be symmetric",
    ):
        ss.ExtendedKalmanFilter(X0, P0, f_linear, h, Q=np.triu(np.ones((4, 4))))
    with pytest.raises(ss.ParameterError, match="finite"):
        ss.ExtendedKalmanFilter(X0, P0, f_linear, h, Q=np.full((4, 4), np.nan))
    with pytest.raises(ss.InvalidInputError):
        ss.ExtendedKalmanFilter(X0, P0, f_linear, h, Q=np.eye(3))


def test_ten_thousand_seeded_bad_calls_never_panic():
    """10^4 updates whose callables misbehave at random (each bad way, on any callable): every
    refusal is a SeqsmoothError leaving the filter as it was, every accepted update finite."""
    rng = np.random.default_rng(20261206)
    ways = list(BAD) + ["ok"] * 3
    names = ["f", "h", "F_jacobian", "H_jacobian", "Q"]
    plan = {"which": None, "how": "ok"}

    def chaos(name, fn):
        def call(*args):
            good = np.asarray(fn(*args), float)
            if plan["which"] == name and plan["how"] != "ok" and rng.random() < 0.7:
                return BAD[plan["how"]](good)
            return good

        return call

    good = {
        "f": f_linear,
        "h": h,
        "F_jacobian": F_jacobian,
        "H_jacobian": H_jacobian,
        "Q": lambda a, b: Q,
    }
    kw = {k: chaos(k, v) for k, v in good.items()}
    filters = [
        ss.ExtendedKalmanFilter(X0, P0, **kw),
        ss.ExtendedKalmanFilter(X0, P0, kw["f"], kw["h"], Q=kw["Q"], iterations=3),
        ss.UnscentedKalmanFilter(x0=X0, P0=P0, f=kw["f"], h=kw["h"], Q=kw["Q"]),
    ]
    refused = accepted = 0
    t = 0.0
    for k in range(10_000):
        flt = filters[k % 3]
        plan["which"], plan["how"] = names[rng.integers(5)], ways[rng.integers(len(ways))]
        t += rng.uniform(0.1, 2.0)
        z = np.array([rng.uniform(1.0, 500.0), rng.uniform(-3.2, 3.2)])
        if rng.random() < 0.1:
            z[rng.integers(2)] = np.nan
        before = snapshot(flt)
        try:
            flt.update(max(t, flt.time), z, R)
        except ss.SeqsmoothError:
            refused += 1
            assert unchanged(flt, before)
            continue
        accepted += 1
        assert np.all(np.isfinite(flt.state)) and np.all(np.isfinite(flt.covariance))
    assert refused > 2_000 and accepted > 2_000, (refused, accepted)


@pytest.mark.parametrize("kw", [{"iterations": 0}, {"iterations": 3, "tolerance": 0.0}])
def test_iteration_limits_are_the_librarys(kw):
    with pytest.raises(ss.ParameterError, match="the tolerance must be positive and finite"):
        ss.ExtendedKalmanFilter(X0, P0, f_linear, h, **kw)
