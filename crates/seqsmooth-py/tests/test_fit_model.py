"""fit_model: the library's Gauss–Newton differential correction (Morrison §8.5-8.7) of the
user's model over a window, against scipy.optimize.least_squares on the same weighted problem
(the state within 1e-8 relative) and the covariance against (Jᵀ R⁻¹ J)⁻¹ with the analytic J
at the solution; a nonlinear transition (a decay of unknown rate) and a nonlinear observation
(range and bearing, the bearing's residual wrapped) through dxdt; and its refusals."""

import math

import numpy as np
import pytest
from scipy.optimize import least_squares

import seqsmooth as ss


def rel(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300)


def decay(x, t0, t1):
    return np.array([x[0] * math.exp(-x[1] * (t1 - t0)), x[1]])


def test_decay_of_unknown_rate_against_least_squares():
    """x = (a, k) at the last time, z = a(t) observed with σ = 0.02: fit_model's state equals
    least_squares' (tight tolerances, analytic J) within 1e-8 relative, its covariance
    (Jᵀ R⁻¹ J)⁻¹ at that solution within 1e-7, chi-squared its residual sum."""
    rng = np.random.default_rng(8)
    t = np.sort(rng.uniform(0.0, 5.0, size=30))
    sigma = 0.02
    z = 3.0 * np.exp(-0.4 * t) + rng.normal(0, sigma, size=t.size)
    te = t[-1]

    def residuals(x):
        return (z - x[0] * np.exp(-x[1] * (t - te))) / sigma

    def jac(x):
        e = np.exp(-x[1] * (t - te))
        return -np.column_stack([e, -x[0] * (t - te) * e]) / sigma

    ref = least_squares(residuals, [0.2, 0.1], jac=jac, xtol=1e-15, ftol=1e-15, gtol=1e-15)
    fit = ss.fit_model([0.2, 0.1], t, z, sigma**2, f=decay, h=lambda x, t: x[:1])
    assert fit["epoch"] == te
    assert rel(fit["state"], ref.x) < 1e-8, rel(fit["state"], ref.x)
    J = jac(ref.x)
    assert rel(fit["covariance"], np.linalg.inv(J.T @ J)) < 1e-7
    assert fit["chi_squared"] == pytest.approx(np.sum(residuals(ref.x) ** 2), rel=1e-9)
    assert fit["degrees_of_freedom"] == 28 and 1 <= fit["iterations"] <= 20


def cv(x, t):
    return np.array([x[1], 0.0, x[3], 0.0])


def range_bearing(x, t):
    return np.array([math.hypot(x[0], x[2]), math.atan2(x[2], x[0])])


def test_range_and_bearing_through_dxdt_against_least_squares():
    """A constant-velocity target (x, vx, y, vy) as dxdt, seen in range and bearing (the
    bearing an angle near ±π, its residual wrapped), fitted at the centre epoch: the state
    within 1e-8 of least_squares', the covariance within 1e-7 of (Jᵀ R⁻¹ J)⁻¹."""
    rng = np.random.default_rng(9)
    t = np.sort(rng.uniform(0.0, 20.0, size=25))
    truth = np.array([-500.0, 3.0, 5.0, -1.0])
    sig = np.array([2.0, 2e-3])
    pos = truth[[0, 2]] + np.outer(t, truth[[1, 3]])
    z = np.column_stack([np.hypot(pos[:, 0], pos[:, 1]), np.arctan2(pos[:, 1], pos[:, 0])])
    z += rng.normal(0, 1, size=z.shape) * sig
    z[:, 1] = (z[:, 1] + math.pi) % (2 * math.pi) - math.pi
    te = t.mean()

    def states(x):
        dt = t - te
        return np.column_stack([x[0] + x[1] * dt, x[2] + x[3] * dt])

    def residuals(x):
        p = states(x)
        r = z[:, 0] - np.hypot(p[:, 0], p[:, 1])
        b = z[:, 1] - np.arctan2(p[:, 1], p[:, 0])
        b = (b + math.pi) % (2 * math.pi) - math.pi
        return np.concatenate([r / sig[0], b / sig[1]])

    def jac(x):
        p = states(x)
        dt = t - te
        r2 = p[:, 0] ** 2 + p[:, 1] ** 2
        r = np.sqrt(r2)
        dr = np.column_stack([p[:, 0] / r, p[:, 0] / r * dt, p[:, 1] / r, p[:, 1] / r * dt])
        db = np.column_stack([-p[:, 1] / r2, -p[:, 1] / r2 * dt, p[:, 0] / r2, p[:, 0] / r2 * dt])
        return -np.vstack([dr / sig[0], db / sig[1]])

    x0 = [-480.0, 0.0, 0.0, 0.0]
    ref = least_squares(residuals, x0, jac=jac, xtol=1e-15, ftol=1e-15, gtol=1e-15)
    fit = ss.fit_model(x0, t, z, sig**2, dxdt=cv, h=range_bearing, angles=[1], epoch="centre")
    assert fit["epoch"] == pytest.approx(te, rel=1e-15)
    assert rel(fit["state"], ref.x) < 1e-8, rel(fit["state"], ref.x)
    J = jac(ref.x)
    assert rel(fit["covariance"], np.linalg.inv(J.T @ J)) < 1e-7
    assert fit["chi_squared"] == pytest.approx(np.sum(residuals(ref.x) ** 2), rel=1e-8)


def test_refusals():
    t = np.arange(5.0)
    z = 2.0 * t
    h = lambda x, t: x[:1]  # noqa: E731
    f = lambda x, t0, t1: np.array([x[0] + x[1] * (t1 - t0), x[1]])  # noqa: E731
    fit = ss.fit_model([0.0, 0.0], t, z, 1.0, f=f, h=h, epoch=0.0)
    assert fit["state"] == pytest.approx([0.0, 2.0], abs=1e-9)
    with pytest.raises(ss.ParameterError, match="max_iterations|max-iterations|iterations"):
        ss.fit_model([0.0, 0.0], t, z, 1.0, f=f, h=h, max_iterations=0)
    with pytest.raises(ss.ParameterError, match="epoch"):
        ss.fit_model([0.0, 0.0], t, z, 1.0, f=f, h=h, epoch="middle")
    with pytest.raises(ss.ParameterError, match="f .* or dxdt"):
        ss.fit_model([0.0, 0.0], t, z, 1.0, h=h)

    def boom(x, t):
        if t > 2.5:
            raise RuntimeError("boom")
        return x[:1]

    with pytest.raises(ss.ParameterError, match="h at t = 3") as e:
        ss.fit_model([0.0, 0.0], t, z, 1.0, f=f, h=boom, epoch=0.0)
    assert isinstance(e.value.__cause__, RuntimeError)
    with pytest.raises(ss.SeqsmoothError):
        ss.fit_model([0.0, 0.0], t, z[:3], 1.0, f=f, h=h)
    with pytest.raises(ss.SeqsmoothError):
        ss.fit_model([0.0, 0.0], [], [], 1.0, f=f, h=h)
    with pytest.raises(ss.SeqsmoothError):
        ss.fit_model([0.0, 0.0], t, np.where(t == 2, np.inf, z), 1.0, f=f, h=h)
