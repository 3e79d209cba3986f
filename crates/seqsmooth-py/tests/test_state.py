"""Settable state and covariance on every Kalman-family class (checked by the library: a
``ParameterError`` naming the state or ``P``, the filter unchanged), the priors of
``FadingMemory`` and ``ExpandingMemory`` against numpy's QR solve of the weighted
least-squares problem with the prior as pseudo-observations, and ``BayesFilter``'s driving
noise ``q`` against ``KalmanFilter`` with the same ``q``."""

from __future__ import annotations

import math

import numpy as np
import pytest

import seqsmooth as ss
from seqsmooth.errors import InvalidInputError, ParameterError

X0 = np.array([1.0, 2.0])
P0 = np.array([[4.0, 1.0], [1.0, 2.0]])


def cv(x, t0, t1):
    return np.array([x[0] + (t1 - t0) * x[1], x[1]])


def first(x, t):
    return np.array([x[0]])


def filters():
    """One of each Kalman-family class on the constant-velocity model, at ``X0``, ``P0``."""
    return {
        "KalmanFilter": ss.KalmanFilter(1, X0, P0, q=0.1),
        "LinearKalmanFilter": ss.LinearKalmanFilter(
            X0, P0, F=[[1.0, 1.0], [0.0, 1.0]], H=[[1.0, 0.0]], Q=np.eye(2) * 0.01, R=[[1.0]]
        ),
        "BayesFilter": ss.BayesFilter(1, x0=X0, P0=P0, q=0.1),
        "UnscentedKalmanFilter": ss.UnscentedKalmanFilter(1, X0, P0, q=0.1),
        "ExtendedKalmanFilter": ss.ExtendedKalmanFilter(X0, P0, f=cv, h=first, Q=np.eye(2) * 0.01),
    }


BAD = {
    "indefinite": np.array([[1.0, 2.0], [2.0, 1.0]]),
    "not symmetric": np.array([[1.0, 0.5], [0.0, 1.0]]),
    "NaN": np.array([[1.0, 0.0], [0.0, np.nan]]),
    "infinite": np.array([[np.inf, 0.0], [0.0, 1.0]]),
}


@pytest.mark.parametrize("name", list(filters()))
def test_state_and_covariance_are_settable(name):
    f = filters()[name]
    x, p = np.array([-3.0, 0.5]), np.array([[2.0, 0.3], [0.3, 1.0]])
    f.state = x
    f.covariance = p
    np.testing.assert_allclose(f.state, x, rtol=1e-14)
    np.testing.assert_allclose(f.covariance, p, rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(f.std_devs, np.sqrt(np.diag(p)), rtol=1e-14)


@pytest.mark.parametrize("name", list(filters()))
@pytest.mark.parametrize("bad", list(BAD))
def test_a_bad_covariance_is_refused_naming_p_the_filter_unchanged(name, bad):
    f = filters()[name]
    before = (f.state.copy(), f.covariance.copy())
    with pytest.raises(ParameterError, match=r"\bP\b") as e:
        f.covariance = BAD[bad]
    assert "must be" in str(e.value)
    np.testing.assert_array_equal(f.state, before[0])
    np.testing.assert_array_equal(f.covariance, before[1])


@pytest.mark.parametrize("name", list(filters()))
def test_a_bad_state_is_refused_naming_it_the_filter_unchanged(name):
    f = filters()[name]
    before = (f.state.copy(), f.covariance.copy())
    for bad in ([np.nan, 0.0], [1.0, 2.0, 3.0]):
        with pytest.raises(ParameterError, match="state"):
            f.state = bad
    with pytest.raises(ParameterError, match="P of shape 3x3 is invalid: must be 2x2"):
        f.covariance = np.eye(3)
    np.testing.assert_array_equal(f.state, before[0])
    np.testing.assert_array_equal(f.covariance, before[1])


def test_a_singular_covariance_is_taken_where_the_form_allows_it():
    singular = np.ones((2, 2))
    for name in ("KalmanFilter", "LinearKalmanFilter", "ExtendedKalmanFilter"):
        f = filters()[name]
        f.covariance = singular
        np.testing.assert_array_equal(f.covariance, singular)
    # The sigma points and the information form need it positive definite.
    for name in ("UnscentedKalmanFilter", "BayesFilter"):
        with pytest.raises(ParameterError, match="positive definite"):
            filters()[name].covariance = singular


def test_a_set_estimate_continues_as_a_filter_started_there(rng):
    t = np.cumsum(rng.uniform(0.2, 1.0, 30))
    z = 0.5 * t + rng.standard_normal(30)
    x, p = np.array([0.2, 0.4]), np.array([[3.0, 0.5], [0.5, 1.0]])
    for make in (
        lambda x0, p0: ss.KalmanFilter(1, x0, p0, q=0.05),
        lambda x0, p0: ss.UnscentedKalmanFilter(1, x0, p0, q=0.05),
        lambda x0, p0: ss.ExtendedKalmanFilter(x0, p0, f=cv, h=first, Q=np.eye(2) * 0.01),
    ):
        moved = make(X0, P0)
        moved.state, moved.covariance = x, p
        fresh = make(x, p)
        a = moved.update_many(t, z, 1.0)
        b = fresh.update_many(t, z, 1.0)
        for u, v in zip(a, b, strict=True):
            np.testing.assert_array_equal(u, v)


def test_the_bayes_filter_sets_its_estimate_before_it_is_determined():
    f = ss.BayesFilter(1)
    with pytest.raises(ss.errors.NotDeterminedError, match="set_estimate"):
        f.state = X0
    f.set_estimate(X0, P0)
    np.testing.assert_allclose(f.covariance, P0, rtol=1e-14)
    with pytest.raises(ParameterError, match=r"\bP\b"):
        f.set_estimate(X0, BAD["indefinite"])
    np.testing.assert_allclose(f.state, X0, rtol=1e-14)


@pytest.mark.parametrize(("degree", "axes"), [(0, 1), (1, 1), (1, 2), (2, 3)])
def test_bayes_with_q_is_the_kalman_filter_with_q(rng, degree, axes):
    n = (degree + 1) * axes
    g = rng.standard_normal((n, n))
    p0 = g @ g.T + np.eye(n)
    x0 = rng.standard_normal(n)
    q = 0.7
    t = np.cumsum(rng.uniform(0.05, 1.5, 80))
    z = rng.standard_normal((80, axes)) * 3.0
    z[rng.random((80, axes)) < 0.15] = np.nan  # missing components
    k = ss.KalmanFilter(degree, x0, p0, axes=axes, q=q).update_many(t, z, 0.4)
    b = ss.BayesFilter(degree, axes=axes, x0=x0, P0=p0, q=q).update_many(t, z, 0.4)
    sd = np.sqrt(np.einsum("kii->ki", k[1]))
    assert np.max(np.abs(b[0] - k[0]) / sd) < 1e-12
    scale = sd[:, :, None] * sd[:, None, :]
    assert np.max(np.abs(b[1] - k[1]) / scale) < 1e-12


def test_bayes_q_with_fading_memory_is_refused():
    with pytest.raises(ParameterError, match="fading"):
        ss.BayesFilter(1, theta=0.9, tau=1.0, q=1.0)
    with pytest.raises(ParameterError, match="q"):
        ss.BayesFilter(1, q=-1.0)


def wls(t, y, sigma, t0, x0, p0, w0=1.0, w=None):
    """The derivatives at ``t[-1]`` by numpy's QR solve of the whitened, weighted rows: the
    samples (noise ``sigma``, weights ``w``) and the prior ``x0``, ``p0`` at ``t0`` (weight
    ``w0``) as ``len(x0)`` pseudo-observations; and the estimator's covariance (the sandwich
    ``M AᵀW²A M`` with ``M = (AᵀWA)⁻¹``)."""
    m = len(x0) - 1
    w = np.ones(len(t)) if w is None else w
    fact = np.array([math.factorial(j) for j in range(m + 1)], dtype=float)
    rows = ((t[:, None] - t[-1]) ** np.arange(m + 1)) / fact / sigma
    # x(t0) = Φ(t0 - t_n) x(t_n): the k-th derivative's Taylor row.
    h = t0 - t[-1]
    phi = np.array(
        [
            [h ** (j - i) / math.factorial(j - i) if j >= i else 0.0 for j in range(m + 1)]
            for i in range(m + 1)
        ]
    )
    li = np.linalg.inv(np.linalg.cholesky(p0))
    a = np.vstack([li @ phi, rows])
    b = np.concatenate([li @ x0, y / sigma])
    weights = np.concatenate([np.full(m + 1, w0), w])
    q, r = np.linalg.qr(np.sqrt(weights)[:, None] * a)
    x = np.linalg.solve(r, q.T @ (np.sqrt(weights) * b))
    mm = np.linalg.inv(r.T @ r)
    cov = mm @ (a.T * weights**2) @ a @ mm
    return x, cov


@pytest.mark.parametrize("degree", [0, 1, 2, 3])
@pytest.mark.parametrize("fading", [None, "per time", "per update"])
def test_a_prior_is_the_weighted_least_squares_fit(rng, degree, fading):
    sigma, theta, tau = 0.6, 0.85, 2.0
    n = degree + 1
    g = rng.standard_normal((n, n))
    p0 = g @ g.T + 0.5 * np.eye(n)
    x0 = rng.standard_normal(n)
    t0 = 10.0
    t = t0 + np.cumsum(rng.uniform(0.1, 1.2, 25))
    t[0] = t0  # the first sample may be at the prior's time
    y = x0[0] + rng.standard_normal(25)
    prior = {"sigma": sigma, "x0": x0, "P0": p0, "t0": t0}
    if fading == "per time":
        f = ss.FadingMemory(degree, theta=theta, tau=tau, **prior)
    elif fading == "per update":
        f = ss.FadingMemory(degree, theta_per_update=theta, **prior)
    else:
        f = ss.ExpandingMemory(degree, **prior)
    d, s = f.update_many(t, y, return_sigma=True)
    for k in range(len(t)):
        tk = t[: k + 1]
        if fading == "per time":
            weights, w0 = theta ** ((tk[-1] - tk) / tau), theta ** ((tk[-1] - t0) / tau)
        elif fading == "per update":
            # The prior, then each sample: discounted once per sample after it.
            weights, w0 = theta ** np.arange(k, -1, -1.0), theta ** (k + 1)
        else:
            weights, w0 = None, 1.0
        x, cov = wls(tk, y[: k + 1], sigma, t0, x0, p0, w0, weights)
        sd = np.sqrt(np.diag(cov))
        assert np.max(np.abs(d[k] - x) / sd) < 1e-10
        np.testing.assert_allclose(s[k], sd, rtol=1e-10)


@pytest.mark.parametrize("kind", ["expanding", "fading"])
def test_a_vague_prior_tends_to_no_prior(rng, kind):
    t = np.cumsum(rng.uniform(0.2, 0.8, 60))
    y = 1.0 + 0.3 * t + 0.5 * rng.standard_normal(60)

    def run(**prior):
        if kind == "expanding":
            f = ss.ExpandingMemory(1, sigma=0.5, **prior)
        else:
            f = ss.FadingMemory(1, theta=0.9, sigma=0.5, **prior)
        f.update_many(t, y)
        return f.estimate().derivatives

    plain = run()
    gaps = [
        np.max(np.abs(run(x0=[0.0, 0.0], P0=scale, t0=t[0]) - plain) / np.abs(plain))
        for scale in (1e4, 1e8)
    ]
    assert 0 < gaps[1] < gaps[0] * 1e-3 and gaps[1] < 1e-7


def test_a_prior_is_refused_where_it_cannot_be_held():
    with pytest.raises(ParameterError, match="gain engine"):
        ss.ExpandingMemory(1, engine="gain", sigma=1.0, x0=[0.0, 0.0], P0=1.0)
    with pytest.raises(ParameterError, match="sigma"):
        ss.FadingMemory(1, theta=0.9, x0=[0.0, 0.0], P0=1.0)
    with pytest.raises(ParameterError, match="go together"):
        ss.ExpandingMemory(1, sigma=1.0, x0=[0.0, 0.0])
    with pytest.raises(ParameterError, match="prior covariance"):
        ss.ExpandingMemory(1, sigma=1.0, x0=[0.0, 0.0], P0=[[1.0, 2.0], [2.0, 1.0]])
    with pytest.raises(ParameterError, match="prior"):
        ss.ExpandingMemory(2, sigma=1.0, x0=[0.0, 0.0], P0=1.0)
    f = ss.ExpandingMemory(1, sigma=1.0, x0=[0.0, 0.0], P0=1.0, t0=5.0)
    assert f.is_determined and f.samples == 0
    assert f.estimate_at(5.0).derivatives.tolist() == [0.0, 0.0]
    with pytest.raises(InvalidInputError, match="previous time 5"):
        f.update(4.0, 1.0)


def test_ten_thousand_random_bad_estimates_are_refused_or_taken_never_a_panic():
    """10⁴ seeded random states and covariances (NaN, infinities, wrong shapes, asymmetric,
    indefinite, singular, huge, tiny) set on every class: each is taken (and then reads back
    as set) or refused with a ``SeqsmoothError`` leaving the filter as it was."""
    rng = np.random.default_rng(2026)
    specials = [np.nan, np.inf, -np.inf, 0.0, -1.0, 1e300, 1e-300]
    made = filters()
    taken = refused = 0
    for k in range(10_000):
        name = list(made)[k % len(made)]
        f = made[name]
        before = (f.state.copy(), f.covariance.copy())
        shape = rng.choice([1, 2, 2, 2, 3])
        value = rng.standard_normal((shape, shape) if rng.random() < 0.7 else (shape,))
        if rng.random() < 0.5:
            value.flat[rng.integers(value.size)] = rng.choice(specials)
        if value.ndim == 2 and rng.random() < 0.5:
            with np.errstate(over="ignore", invalid="ignore"):
                value = value @ value.T  # symmetric, often positive definite
        attribute = "covariance" if value.ndim == 2 or rng.random() < 0.3 else "state"
        try:
            setattr(f, attribute, value)
        except ss.SeqsmoothError:
            refused += 1
            np.testing.assert_array_equal(f.state, before[0])
            np.testing.assert_array_equal(f.covariance, before[1])
        else:
            taken += 1
            got = getattr(f, attribute)
            assert np.isfinite(got).all()
    print(f"{taken} taken, {refused} refused")
    assert taken > 500 and refused > 5000, (taken, refused)
