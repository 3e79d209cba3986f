"""fixed_lag_smoother(t, z, R, lag) of KalmanFilter, ExtendedKalmanFilter,
ContinuousKalmanFilter and UnscentedKalmanFilter against its definition: with lag L the
estimate of measurement k is the class's own whole-interval smoother (``smooth``) over the
measurements 0..k+L, read at k (checked directly, several L, irregular times, missing
components), a lag of at least the run's length is ``smooth`` itself, the filter is not moved,
and an out-of-order time is refused naming its index. On a linear model at unit steps the
polynomial filter's equals LinearKalmanFilter.fixed_lag_smoother (a second code, the
library's discrete-model smoother). Each state component compared relative to max(|x|, σ),
each covariance entry relative to σ_i σ_j (the oracle's)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import seqsmooth as ss

TOL = 1e-12


def worst(x, p, want_x, want_p):
    """The worst relative difference of (x, p) from (want_x, want_p), stacked per row."""
    s = np.sqrt(np.einsum("...ii->...i", want_p))
    dx = np.abs(x - want_x) / np.maximum(np.abs(want_x), s)
    dp = np.abs(p - want_p) / (s[..., :, None] * s[..., None, :])
    return max(dx.max(), dp.max())


def check(make, t, z, R, lags):
    """make() a fresh filter; its fixed_lag_smoother against smooth over each prefix."""
    n = len(t)
    full = make().smooth(t, z, R)
    for lag in lags:
        f = make()
        before = (f.state.copy(), f.covariance.copy(), f.time)
        xs, ps = f.fixed_lag_smoother(t, z, R, lag)
        after = (f.state, f.covariance, f.time)
        assert np.array_equal(before[0], after[0]) and np.array_equal(before[1], after[1])
        assert before[2] == after[2]
        assert xs.shape == full[0].shape and ps.shape == full[1].shape
        for k in range(n):
            end = min(k + lag, n - 1) + 1
            if end == n:
                wx, wp = full[0][k], full[1][k]
            else:
                sx, sp = make().smooth(t[:end], z[:end], R)
                wx, wp = sx[k], sp[k]
            w = worst(xs[k], ps[k], wx, wp)
            assert w <= TOL, (lag, k, w)
    for lag in (n, 10**9):
        xs, ps = make().fixed_lag_smoother(t, z, R, lag)
        assert worst(xs, ps, full[0], full[1]) <= TOL
    # The smoothing is real: a lag of 3 shrinks a σ below the filter's somewhere.
    filtered = make().update_many(t, z, R)
    xs, ps = make().fixed_lag_smoother(t, z, R, 3)
    assert np.any(
        np.diagonal(ps, axis1=1, axis2=2) < 0.95 * np.diagonal(filtered[1], axis1=1, axis2=2)
    )


def check_refused(make, t, z, R):
    """A time before its predecessor is refused with its index, the filter unchanged."""
    t = t.copy()
    t[6] = t[5] - 0.1
    f = make()
    with pytest.raises(ss.SeqsmoothError) as e:
        f.fixed_lag_smoother(t, z, R, 2)
    assert e.value.index == 6
    assert f.time == make().time


def irregular(rng, count):
    return np.cumsum(rng.uniform(0.3, 1.7, size=count))


def two_axis_problem(seed, count=40):
    rng = np.random.default_rng(seed)
    t = irregular(rng, count)
    z = np.column_stack([3.0 * t + 0.1 * t**2, 20 - 2.0 * t]) + rng.normal(0, 0.5, size=(count, 2))
    z[5, 0] = np.nan
    z[12, :] = np.nan
    z[20, 1] = np.nan
    return t, z


def test_kalman_filter():
    t, z = two_axis_problem(1)

    def make():
        return ss.KalmanFilter(1, [0.0, 20.0, 0.0, 0.0], 100.0, axes=2, q=0.3)

    check(make, t, z, 0.25, [0, 1, 4, 11])
    check_refused(make, t, z, 0.25)


def test_kalman_filter_with_fading_memory():
    t, z = two_axis_problem(2, 30)

    def make():
        return ss.KalmanFilter(1, [0.0, 20.0, 0.0, 0.0], 100.0, axes=2, q=0.1, theta=0.8, tau=2.0)

    check(make, t, z, [0.25, 0.5], [0, 2, 7])


def test_kalman_filter_equals_the_linear_filters_fixed_lag_smoother():
    """Unit steps, constant velocity: Phi and Q (Morrison (15.2.23)) as matrices."""
    rng = np.random.default_rng(3)
    count, q, r = 50, 0.4, 0.3
    t = np.arange(1.0, count + 1)
    z = 0.5 * t + rng.normal(0, math.sqrt(r), size=count)
    z[9] = np.nan
    F = np.array([[1.0, 1.0], [0.0, 1.0]])
    Q = q * np.array([[1 / 3, 1 / 2], [1 / 2, 1.0]])
    for lag in (0, 1, 5, 60):
        xs, ps = ss.KalmanFilter(1, [0.0, 0.0], 10.0, q=q).fixed_lag_smoother(t, z, r, lag)
        lin = ss.LinearKalmanFilter([0.0, 0.0], 10.0, F, [[1.0, 0.0]], Q, r)
        wx, wp = lin.fixed_lag_smoother(z, lag)
        assert worst(xs, ps, wx, wp) <= 1e-10, lag


def ekf_problem(seed, count=24):
    rng = np.random.default_rng(seed)
    t = irregular(rng, count)
    truth = np.array([300.0, -4.0, 40.0, 2.0])
    pos = np.array([[truth[0] + truth[1] * s, truth[2] + truth[3] * s] for s in t])
    z = np.column_stack([np.hypot(pos[:, 0], pos[:, 1]), np.arctan2(pos[:, 1], pos[:, 0])])
    z += rng.normal(0, 1, size=z.shape) * [2.0, 0.01]
    z[4, 1] = np.nan
    z[15, :] = np.nan
    return t, z


def cv(dt):
    return np.array([[1.0, dt, 0, 0], [0, 1.0, 0, 0], [0, 0, 1.0, dt], [0, 0, 0, 1.0]])


def cv_q(dt, q=0.01):
    b = q * np.array([[dt**3 / 3, dt**2 / 2], [dt**2 / 2, dt]])
    out = np.zeros((4, 4))
    out[:2, :2] = b
    out[2:, 2:] = b
    return out


@pytest.mark.parametrize("iterations", [1, 6])
def test_extended_kalman_filter(iterations):
    t, z = ekf_problem(4)
    R = np.diag([4.0, 1e-4])

    def make():
        return ss.ExtendedKalmanFilter(
            [250.0, 0.0, 80.0, 0.0],
            np.diag([400.0, 25.0, 400.0, 25.0]),
            f=lambda x, a, b: cv(b - a) @ x,
            h=lambda x, t: np.array([math.hypot(x[0], x[2]), math.atan2(x[2], x[0])]),
            Q=lambda a, b: cv_q(b - a),
            angles=[1],
            iterations=iterations,
        )

    check(make, t, z, R, [0, 1, 3, 8])
    check_refused(make, t, z, R)


def test_continuous_kalman_filter():
    t, z = two_axis_problem(5, 30)
    model = ss.ContinuousModel.polynomial(1, 0.3, axes=2)
    H = np.eye(2, 4)

    def make():
        return ss.ContinuousKalmanFilter(model, H, 0.25, [0.0, 20.0, 0.0, 0.0], np.eye(4) * 100.0)

    check(make, t, z, None, [0, 2, 9])
    check(make, t, z, [0.25, 0.5], [3])
    check_refused(make, t, z, None)
    # The same model as the polynomial filter's: the same fixed-lag estimates.
    got = make().fixed_lag_smoother(t, z, None, 4)
    want = ss.KalmanFilter(1, [0.0, 20.0, 0.0, 0.0], 100.0, axes=2, q=0.3).fixed_lag_smoother(
        t, z, 0.25, 4
    )
    assert worst(got[0], got[1], want[0], want[1]) <= 1e-10


def test_unscented_kalman_filter_on_a_radar():
    rng = np.random.default_rng(6)
    count = 40
    t = irregular(rng, count)
    p0, v = np.array([8000.0, -6000.0, 3000.0]), np.array([-150.0, 120.0, 10.0])
    pos = p0 + t[:, None] * v
    rng_ = np.linalg.norm(pos, axis=1)
    z = np.column_stack([rng_, np.arctan2(pos[:, 1], pos[:, 0]), np.arcsin(pos[:, 2] / rng_)])
    z += rng.normal(0, 1, size=z.shape) * [5.0, 1e-3, 1e-3]
    z[3, 2] = np.nan
    z[17, :] = np.nan
    R = [25.0, 1e-6, 1e-6]

    def make():
        x0 = np.concatenate([p0, v])
        P0 = np.diag([400.0] * 3 + [100.0] * 3)
        return ss.UnscentedKalmanFilter(1, x0, P0, axes=3, q=0.05, observation="radar")

    check(make, t, z, R, [0, 1, 4, 12])
    check_refused(make, t, z, R)


def test_unscented_kalman_filter_on_a_linear_model_is_the_kalman_filters():
    t, z = two_axis_problem(7)
    x0 = [0.0, 20.0, 0.0, 0.0]
    got = ss.UnscentedKalmanFilter(1, x0, 100.0, axes=2, q=0.3).fixed_lag_smoother(t, z, 0.25, 5)
    want = ss.KalmanFilter(1, x0, 100.0, axes=2, q=0.3).fixed_lag_smoother(t, z, 0.25, 5)
    assert worst(got[0], got[1], want[0], want[1]) <= 1e-9


@pytest.mark.parametrize("kind", ["ekf", "ukf"])
def test_a_raising_callable_is_named_with_its_index(kind):
    """The user's h raises from measurement 5 on: ParameterError with .index 5, the callable's
    exception its cause, the filter not moved."""
    t, z = ekf_problem(8, 20)
    R = np.diag([4.0, 1e-4])

    def h(x, s):
        if s >= t[5]:
            raise RuntimeError("boom")
        return np.array([math.hypot(x[0], x[2]), math.atan2(x[2], x[0])])

    x0, P0 = [250.0, 0.0, 80.0, 0.0], np.diag([400.0, 25.0, 400.0, 25.0])
    if kind == "ekf":
        f = ss.ExtendedKalmanFilter(x0, P0, f=lambda x, a, b: cv(b - a) @ x, h=h, Q=cv_q(1.0))
    else:
        f = ss.UnscentedKalmanFilter(
            x0=x0, P0=P0, f=lambda x, a, b: cv(b - a) @ x, h=h, Q=cv_q(1.0)
        )
    with pytest.raises(ss.ParameterError) as e:
        f.fixed_lag_smoother(t, z, R, 3)
    assert e.value.index == 5, str(e.value)
    assert isinstance(e.value.__cause__, RuntimeError)
    assert f.time == 0.0
