"""The library's coordinated turn as Python callables (`CoordinatedTurn`): its `f` against the
matrix exponential of the known-rate model (scipy's `expm`), its `F_jacobian` against central
differences of `f`, its `Q` against constant velocity's at rate 0; and the extended and
unscented Kalman filters over it on a turning target seen in range and bearing."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm

import seqsmooth as ss
from seqsmooth.errors import InvalidInputError, ParameterError


def a_matrix(w):
    a = np.zeros((6, 6))
    a[0, 3] = a[1, 4] = a[2, 5] = 1.0
    a[3, 4], a[4, 3] = -w, w
    return a


X = np.array([1e3, -2e3, 5e2, -150.0, 130.0, 2.0])


@pytest.mark.parametrize("w", [0.0, 1e-9, 0.03, -0.4, 2.5])
@pytest.mark.parametrize("step", [0.013, 0.7, 4.1, -2.2])
def test_known_rate_is_the_matrix_exponential(w, step):
    m = ss.CoordinatedTurn(0.5, turn_rate=w)
    assert m.dim == 6 and m.turn_rate == w
    phi = expm(a_matrix(w) * step)
    got = m.F_jacobian(X, 10.0, 10.0 + step)
    assert np.abs(got - phi).max() <= 1e-12 * np.abs(phi).max()
    assert np.allclose(m.f(X, 10.0, 10.0 + step), phi @ X, rtol=0, atol=1e-9)


@pytest.mark.parametrize("w", [0.0, 1e-7, 0.05, -1.3])
def test_estimated_rate_jacobian_is_the_derivative_of_f(w):
    m = ss.CoordinatedTurn(0.5, turn_rate_noise=1e-5)
    x = np.append(X, w)
    step = 1.7
    phi = m.F_jacobian(x, 0.0, step)
    for c in range(7):
        h = 1e-4 if c == 6 else 1e-2 * max(abs(x[c]), 1.0)
        up, down = x.copy(), x.copy()
        up[c] += h
        down[c] -= h
        d = (m.f(up, 0.0, step) - m.f(down, 0.0, step)) / (2 * h)
        assert np.allclose(d, phi[:, c], rtol=1e-6, atol=1e-6 * np.abs(phi[:, c]).max()), c


def test_q_at_rate_zero_is_constant_velocitys():
    q, step = 0.8, 2.5
    cv = np.kron([[step**3 / 3, step**2 / 2], [step**2 / 2, step]], np.eye(3)) * q
    got = ss.CoordinatedTurn(q, turn_rate=0.0).Q(1.0, 1.0 + step)
    assert np.allclose(got, cv, rtol=1e-15, atol=0)
    est = ss.CoordinatedTurn(q, turn_rate_noise=1e-4).Q(1.0, 1.0 + step)
    assert np.allclose(est[:6, :6], cv, rtol=1e-15, atol=0) and est[6, 6] == pytest.approx(2.5e-4)


def test_bad_settings_and_states_are_refused():
    with pytest.raises(ParameterError, match="turn rate"):
        ss.CoordinatedTurn(1.0, turn_rate=float("nan"))
    with pytest.raises(ParameterError, match="turn_rate_noise"):
        ss.CoordinatedTurn(1.0, turn_rate=0.1, turn_rate_noise=1e-4)
    with pytest.raises(ParameterError):
        ss.CoordinatedTurn(-1.0)
    with pytest.raises(ParameterError, match="state of length 6 is invalid"):
        ss.CoordinatedTurn(1.0).f(X, 0.0, 1.0)  # six values for seven states
    with pytest.raises(InvalidInputError):
        ss.CoordinatedTurn(1.0).f(np.ones((2, 7)), 0.0, 1.0)


def h(x, t=0.0):
    """Range and bearing of (x, y) from the origin."""
    return np.array([np.hypot(x[0], x[1]), np.arctan2(x[1], x[0])])


def test_extended_and_unscented_filters_follow_a_turn():
    """A target turning at 0.05 rad/s, seen in range (σ 5 m) and bearing (σ 2 mrad) on irregular
    steps: both filters over the library's model end within 3σ of the truth, the turn rate
    found, and agree with each other within their σ."""
    rng = np.random.default_rng(5)
    model = ss.CoordinatedTurn(0.1, turn_rate_noise=1e-6)
    truth = np.array([5e3, 2e3, 0.0, -100.0, 60.0, 0.0, 0.05])
    x0 = truth + rng.standard_normal(7) * [50, 50, 1, 5, 5, 0.1, 0.0]
    x0[6] = 0.0
    P0 = np.diag([2500.0, 2500.0, 1.0, 25.0, 25.0, 0.01, 0.01])
    R = np.diag([25.0, 4e-6])
    ekf = ss.ExtendedKalmanFilter(
        x0, P0, model.f, lambda x, t: h(x), Q=model.Q, F_jacobian=model.F_jacobian, angles=[1]
    )
    ukf = ss.UnscentedKalmanFilter(
        x0=x0, P0=P0, f=model.f, h=lambda x, t: h(x), Q=model.Q, angles=[1]
    )
    t = 0.0
    for _ in range(80):
        step = rng.uniform(0.5, 1.5)
        truth = model.f(truth, t, t + step)
        t += step
        z = h(truth) + rng.standard_normal(2) * [5.0, 2e-3]
        ekf.update(t, z, R)
        ukf.update(t, z, R)
    for f in (ekf, ukf):
        sigma = np.sqrt(np.diag(f.covariance))
        assert (np.abs(f.state - truth) <= 3 * sigma).all(), (f.state - truth) / sigma
        assert abs(f.state[6] - 0.05) < 0.005
    sigma = np.sqrt(np.diag(ekf.covariance))
    assert (np.abs(ekf.state - ukf.state) <= sigma).all()
