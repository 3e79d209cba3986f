"""`BayesFilter` against numpy's least-squares polynomial fit, the exact expanding- and
fading-memory filters, the Kalman filter from the same prior, and its refusals."""

from __future__ import annotations

import numpy as np
import pytest

import seqsmooth as ss
from seqsmooth.errors import InvalidInputError, ParameterError, SeqsmoothError

SIGMA = 0.3


def series(rng, n, degree, start=1.7e9):
    t = start + np.cumsum(rng.uniform(0.5, 1.5, n))
    x = (t - t[0]) / n
    y = sum((k + 1.0) * (-x) ** k for k in range(degree + 1)) + SIGMA * rng.standard_normal(n)
    return t, y


def lstsq_derivatives(t, y, degree):
    """The least-squares polynomial of the samples (numpy, in a scaled variable), and its
    derivatives at the last time."""
    p = np.polynomial.Polynomial.fit(t - t[-1], y, degree)
    return np.array([p.deriv(k)(0.0) for k in range(degree + 1)])


@pytest.mark.parametrize("degree", [0, 1, 2, 3, 5, 8])
def test_equals_the_least_squares_fit(rng, degree):
    t, y = series(rng, 200, degree)
    f = ss.BayesFilter(degree)
    states, cov = f.update_many(t, y, SIGMA**2)
    # Determined from sample m + 1 on, unless its variance inflation is above the library's
    # limit (degree 8 at its first samples): NaN rows only before the first estimate.
    first = int(np.argmax(np.isfinite(states[:, 0])))
    assert degree <= first <= degree + 3
    assert np.isnan(states[:first]).all() and np.isfinite(states[first:]).all()
    for k in [first, first + 7, 60, 199]:
        want = lstsq_derivatives(t[: k + 1], y[: k + 1], degree)
        sigma = np.sqrt(np.diag(cov[k]))
        assert np.all(np.abs(states[k] - want) <= 1e-6 * sigma), (k, states[k] - want, sigma)
    assert f.is_determined and np.array_equal(f.state, states[-1])


@pytest.mark.parametrize("degree", [1, 3, 8])
def test_equals_the_exact_expanding_and_fading_filters(rng, degree):
    """The exact polynomial engine is this recursion: the same estimates and σ."""
    t, y = series(rng, 300, degree)
    states, cov = ss.BayesFilter(degree).update_many(t, y, SIGMA**2)
    e = ss.ExpandingMemory(degree=degree, engine="exact", sigma=SIGMA)
    d, s = e.update_many(t, y, return_sigma=True)
    sig = np.sqrt(np.diagonal(cov, 0, 1, 2))
    ok = slice(degree + 1, None)
    assert np.all(np.abs(states[ok] - d[ok]) <= 1e-7 * sig[ok])
    assert np.allclose(sig[ok], s[ok], rtol=1e-8, atol=0)
    theta, tau = 0.9, 2.0
    states, cov = ss.BayesFilter(degree, theta=theta, tau=tau).update_many(t, y, SIGMA**2)
    fm = ss.FadingMemory(degree=degree, theta=theta, tau=tau, engine="exact", sigma=SIGMA)
    d, s = fm.update_many(t, y, return_sigma=True)
    sig = np.sqrt(np.diagonal(cov, 0, 1, 2))
    assert np.all(np.abs(states[ok] - d[ok]) <= 1e-7 * sig[ok])
    assert np.allclose(sig[ok], s[ok], rtol=1e-8, atol=0)


def test_with_a_prior_equals_the_kalman_filter(rng):
    """Two axes, a 3 × 4 observation (both positions and their sum), missing components: the
    information form and the covariance form of the same estimate."""
    n = 80
    t = np.cumsum(rng.uniform(0.5, 1.5, n))
    m = np.array([[1.0, 0, 0, 0], [0, 1.0, 0, 0], [1.0, 1.0, 0, 0]])
    z = np.column_stack([2 + 0.5 * t, -1 + 0.2 * t, 1 + 0.7 * t]) + rng.standard_normal((n, 3))
    z[rng.random((n, 3)) < 0.1] = np.nan
    x0, p0 = np.array([1.0, 0.0, 0.3, 0.1]), np.diag([4.0, 4.0, 1.0, 1.0])
    r = np.array([1.0, 2.0, 0.5])
    kw = {"degree": 1, "axes": 2, "observation": m}
    bx, bp = ss.BayesFilter(**kw, x0=x0, P0=p0).update_many(t, z, r)
    kx, kp, _ = ss.KalmanFilter(**kw, x0=x0, P0=p0).update_many(t, z, r)
    assert np.abs(bx - kx).max() <= 1e-9 * np.abs(kx).max()
    assert np.abs(bp - kp).max() <= 1e-9 * np.abs(kp).max()
    # Fading memory per update from the same prior: the fading Kalman filter's true covariance.
    bx, bp = ss.BayesFilter(**kw, x0=x0, P0=p0, theta_per_update=0.8).update_many(t, z, r)
    kx, kp, _ = ss.KalmanFilter(**kw, x0=x0, P0=p0, theta_per_update=0.8).update_many(t, z, r)
    assert np.abs(bx - kx).max() <= 1e-9 * np.abs(kx).max()
    assert np.abs(bp - kp).max() <= 1e-9 * np.abs(kp).max()


def test_one_at_a_time_equals_many(rng):
    t, y = series(rng, 50, 2)
    a = ss.BayesFilter(2)
    states, _ = a.update_many(t, y, 1.0)
    b = ss.BayesFilter(2)
    for k in range(len(t)):
        b.update(t[k], y[k], 1.0)
        if k < 2:
            assert b.state is None and b.covariance is None
        else:
            assert np.array_equal(b.state, states[k])


def test_refusals_name_the_sample(rng):
    t, y = series(rng, 40, 1)
    for where, bad in [("t", np.nan), ("t", -1.0), ("y", np.inf)]:
        tt, yy = t.copy(), y.copy()
        (tt if where == "t" else yy)[17] = bad
        f = ss.BayesFilter(1)
        with pytest.raises(InvalidInputError) as e:
            f.update_many(tt, yy, 1.0)
        assert e.value.index == 17, where
        assert f.time == t[16]
    with pytest.raises(SeqsmoothError):
        ss.BayesFilter(1).update_many(t, y, 0.0)  # a perfect observation is refused
    with pytest.raises(InvalidInputError):
        ss.BayesFilter(1).update_many(t, y[:-1], 1.0)


@pytest.mark.parametrize(
    "kw",
    [
        {"degree": 1, "theta": 0.0, "tau": 1.0},
        {"degree": 1, "theta_per_update": 1.5},
        {"degree": 1, "theta_per_update": 1.0},
        {"degree": 1, "theta": 0.9, "tau": 0.0},
        {"degree": 1, "theta": 0.9},
        {"degree": 1, "beta": 0.9},
        {"degree": 1, "theta": 0.9, "tau": 1.0, "theta_per_update": 0.9},
        {"degree": 1, "x0": [0.0, 0.0]},
        {"degree": 1, "axes": 0},
        {"degree": 99},
        {"degree": 1, "x0": [0.0, 0.0], "P0": [[1.0, 2.0], [2.0, 1.0]]},
    ],
)
def test_bad_settings(kw):
    with pytest.raises((ParameterError, InvalidInputError)):
        ss.BayesFilter(**kw)
