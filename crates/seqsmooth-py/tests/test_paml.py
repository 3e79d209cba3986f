"""gauss_rule, polynomial_samples and luenberger_gains: Gauss-Legendre against numpy's
leggauss (<= 1e-13), Gauss-Chebyshev against its closed form, the discrete rule's exactness on
the samples' inner product, polynomial samples against numpy's weighted least squares, and
Luenberger's b against the inverse Hilbert matrix in fractions."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

import seqsmooth as ss


@pytest.mark.parametrize("n", [0, 1, 5, 12, 30])
def test_gauss_legendre_and_chebyshev(n):
    x, w = ss.gauss_rule(n)
    xn, wn = np.polynomial.legendre.leggauss(n + 1)
    assert np.max(np.abs(x - xn)) <= 1e-13 and np.max(np.abs(w - wn)) <= 1e-13
    x, w = ss.gauss_rule(n, kind="chebyshev")
    k = np.arange(n + 1)
    want = np.sort(np.cos((2 * k + 1) * np.pi / (2 * (n + 1))))
    assert np.max(np.abs(x - want)) <= 1e-13
    assert np.max(np.abs(w - np.pi / (n + 1))) <= 1e-13
    # on [a, b]: nodes mapped, Legendre weights scaled by the half-width
    x, w = ss.gauss_rule(n, a=2.0, b=6.0)
    assert np.max(np.abs(x - (4.0 + 2.0 * xn))) <= 1e-13
    assert np.max(np.abs(w - 2.0 * wn)) <= 1e-13


def test_the_discrete_rule_is_exact_on_the_samples():
    rng = np.random.default_rng(5)
    t = np.cumsum(rng.uniform(0.5, 1.5, 3000))
    w = rng.uniform(0.1, 10.0, t.size)
    n = 8
    x, lam = ss.gauss_rule(n, t=t, weights=w)
    c, h = (t[0] + t[-1]) / 2, (t[-1] - t[0]) / 2
    for d in range(2 * n + 2):
        coef = np.zeros(d + 1)
        coef[d] = 1.0
        f = np.polynomial.chebyshev.Chebyshev(coef)
        want = np.sum(w * f((t - c) / h))
        got = np.sum(lam * f((x - c) / h))
        assert abs(got - want) <= 1e-12 * np.sum(w * np.abs(f((t - c) / h)))


def test_polynomial_samples_are_the_weighted_fit():
    rng = np.random.default_rng(6)
    t = 1.0 + np.cumsum(rng.uniform(0.5, 1.5, 500)) * 1e-2
    sigma = rng.uniform(0.5, 5.0, t.size)
    y = np.sin(3 * t) + sigma * rng.standard_normal(t.size)
    n = 5
    times, values, variances = ss.polynomial_samples(t, y, sigma, n)
    fit = np.polynomial.Legendre.fit(t, y, n, w=1 / sigma)
    np.testing.assert_allclose(values, fit(times), rtol=0, atol=1e-10)
    # covariance of the fit at the nodes: V (AᵀWA)⁻¹ Vᵀ in the Legendre basis of the span
    c, h = (t[0] + t[-1]) / 2, (t[-1] - t[0]) / 2
    a = np.polynomial.legendre.legvander((t - c) / h, n) / sigma[:, None]
    v = np.polynomial.legendre.legvander((times - c) / h, n)
    cov = v @ np.linalg.inv(a.T @ a) @ v.T
    np.testing.assert_allclose(variances, np.diag(cov), rtol=1e-9)
    corr = cov / np.sqrt(np.outer(np.diag(cov), np.diag(cov)))
    assert np.max(np.abs(corr - np.eye(n + 1))) <= 1e-9
    # one sigma for all
    _, v1, var1 = ss.polynomial_samples(t, y, 2.0, n)
    _, v2, var2 = ss.polynomial_samples(t, y, np.full(t.size, 2.0), n)
    assert np.array_equal(v1, v2) and np.array_equal(var1, var2)


def test_luenberger_gains():
    for n in range(1, 10):
        h = [[Fraction(1, i + j + 1) for j in range(n)] for i in range(n)]
        # b = H⁻¹ 1 by Gauss-Jordan in fractions
        m = [row[:] + [Fraction(1)] for row in h]
        for col in range(n):
            p = m[col][col]
            m[col] = [v / p for v in m[col]]
            for r in range(n):
                if r != col:
                    f = m[r][col]
                    m[r] = [a - f * b for a, b in zip(m[r], m[col])]
        want = [int(row[n]) for row in m]
        assert ss.luenberger_gains(n, exact=True) == want
        assert list(ss.luenberger_gains(n)) == [float(v) for v in want]
    assert sum(ss.luenberger_gains(12, exact=True)) == 144


def test_errors():
    with pytest.raises(ss.TooFewSamplesError):
        ss.gauss_rule(3, t=[0.0, 1.0, 2.0])
    with pytest.raises(ss.InvalidInputError):
        ss.gauss_rule(1, t=[0.0, 1.0, 2.0], weights=[1.0, -1.0, 1.0])
    with pytest.raises(ss.ParameterError):
        ss.gauss_rule(2, kind="hermite")
    with pytest.raises(ss.ParameterError):
        ss.gauss_rule(2, a=1.0, b=1.0)
    with pytest.raises(ss.InvalidInputError):
        ss.polynomial_samples([0.0, 1.0, 2.0], [1.0, np.nan, 2.0], 1.0, 1)
    with pytest.raises(ss.InvalidInputError):
        ss.polynomial_samples([0.0, 1.0, 2.0], [1.0, 2.0, 3.0], [1.0, 0.0, 1.0], 1)
    with pytest.raises(ss.InvalidInputError):
        ss.polynomial_samples([0.0, 1.0, 2.0], [1.0, 2.0], 1.0, 1)
    with pytest.raises(ss.InvalidTypeError):
        ss.polynomial_samples(["a"], [1.0], 1.0, 0)
    with pytest.raises(ss.ParameterError):
        ss.luenberger_gains(0)


def _demo(theta, t):
    return theta[0] * np.exp(theta[1] * t) + theta[2] * t


def _demo_jac(theta, t):
    e = np.exp(theta[1] * t)
    return np.stack([e, theta[0] * t * e, t], axis=1)


def _demo_data(n=400, seed=3):
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 2.0, n)
    sigma = 0.05 * (1.0 + t)
    y = _demo([1.0, 0.8, -0.5], t) + sigma * rng.standard_normal(n)
    return t, y, sigma


@pytest.mark.parametrize("analytic", [True, False])
def test_fit_curve_is_scipys_least_squares(analytic):
    from scipy.optimize import least_squares

    t, y, sigma = _demo_data()
    fit = ss.fit_curve(_demo, t, y, sigma, [0.5, 0.0, 0.0], jac=_demo_jac if analytic else None)
    ref = least_squares(
        lambda p: (_demo(p, t) - y) / sigma,
        [0.5, 0.0, 0.0],
        jac=lambda p: _demo_jac(p, t) / sigma[:, None],
        method="lm",
        xtol=1e-15,
        ftol=1e-15,
        gtol=1e-15,
    )
    j = _demo_jac(ref.x, t) / sigma[:, None]
    cov = np.linalg.inv(j.T @ j)
    sd = np.sqrt(np.diag(cov))
    # both stop on MINPACK's relative-reduction test: scipy here at 1.6e-9 sigma of ours
    tol = 1e-8 if analytic else 1e-6
    assert np.all(np.abs(fit.parameters - ref.x) / sd <= tol)
    assert np.max(np.abs(fit.covariance - cov)) <= tol * np.max(np.abs(cov))
    assert np.allclose(fit.standard_deviations, sd, rtol=tol)
    assert fit.degrees_of_freedom == len(t) - 3
    assert fit.correction <= 1e-9
    assert fit.chi_squared == pytest.approx(2 * ref.cost, rel=1e-10)
    bound = ss.cramer_rao_bound(_demo, ref.x, t, sigma, jac=_demo_jac)
    assert np.max(np.abs(bound - cov)) <= 1e-9 * np.max(np.abs(cov))


def test_paml_fit_on_polynomial_samples_is_the_raw_fit_where_lemma_3_holds():
    # h = a + b t + c² t²: the normal equations are polynomial of degree 4 <= 2n+1 (n = 2).
    rng = np.random.default_rng(8)
    t = np.sort(rng.uniform(0.0, 10.0, 500))
    sigma = 0.05 * (1.0 + 2.0 * t)
    y = 1.0 - 0.4 * t + 0.09 * t * t + sigma * rng.standard_normal(500)

    def h(p, t):
        return p[0] + p[1] * t + p[2] ** 2 * t * t

    raw = ss.fit_curve(h, t, y, sigma, [0.0, 0.0, 1.0])
    tk, vk, var = ss.polynomial_samples(t, y, sigma, 2)
    paml = ss.fit_curve(h, tk, vk, np.sqrt(var), [0.0, 0.0, 1.0])
    sd = raw.standard_deviations
    assert np.all(np.abs(paml.parameters - raw.parameters) / sd <= 1e-6)
    assert np.allclose(paml.covariance, raw.covariance, rtol=1e-7, atol=0)


def test_online_smoother_is_the_batch_polynomial_samples():
    rng = np.random.default_rng(4)
    t = np.cumsum(rng.uniform(0.5, 1.5, 300))
    sigma = 0.1 + 0.01 * t
    s = ss.OnlineSmoother(t, sigma, 4)
    assert (s.size, s.taken) == (300, 0)
    for segment in range(3):
        y = np.sin(0.02 * t + segment) + sigma * rng.standard_normal(300)
        for v in y[:100]:
            s.push(v)
        s.push_all(y[100:])
        assert s.taken == 300
        online = s.polynomial_samples()
        batch = ss.polynomial_samples(t, y, sigma, 4)
        for a, b in zip(online, batch, strict=True):
            np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)
        s.reset()
        assert s.taken == 0
    assert "OnlineSmoother(size=300" in repr(s)


def test_curve_and_smoother_errors():
    t, y, sigma = _demo_data(20)
    with pytest.raises(ss.InvalidTypeError):
        ss.fit_curve("not a function", t, y, sigma, [1.0, 0.0, 0.0])
    with pytest.raises(ss.InvalidInputError):
        ss.fit_curve(_demo, t, y, 0.0, [1.0, 0.0, 0.0])
    with pytest.raises(ss.InvalidInputError):
        ss.fit_curve(_demo, t, np.where(t > 1, np.nan, y), sigma, [1.0, 0.0, 0.0])
    with pytest.raises(ss.TooFewSamplesError):
        ss.fit_curve(_demo, t[:2], y[:2], sigma[:2], [1.0, 0.0, 0.0])
    with pytest.raises(ss.NumericalError):
        # a and a second constant cannot be told apart
        ss.fit_curve(lambda p, t: p[0] + p[1] + t, t, y, sigma, [0.0, 0.0])

    class Boom(RuntimeError):
        pass

    def raises(p, t):
        raise Boom("model failed")

    with pytest.raises(Boom):
        ss.fit_curve(raises, t, y, sigma, [1.0, 0.0, 0.0])
    with pytest.raises(ss.InvalidInputError):
        ss.fit_curve(lambda p, t: np.full(len(t), np.inf), t, y, sigma, [1.0])
    with pytest.raises(ss.ParameterError):
        ss.fit_curve(lambda p, t: np.zeros(3), t, y, sigma, [1.0])
    with pytest.raises(ss.ParameterError):
        ss.fit_curve(_demo, t, y, sigma, [1.0, 0.0, 0.0], jac=lambda p, t: np.zeros((3, 3)))
    s = ss.OnlineSmoother([0.0, 1.0, 2.0], 1.0, 1)
    with pytest.raises(ss.InvalidInputError):
        s.push(np.nan)
    with pytest.raises(ss.TooFewSamplesError):
        s.polynomial_samples()
    s.push_all([1.0, 2.0, 3.0])
    with pytest.raises(ss.InvalidInputError):
        s.push(4.0)
    with pytest.raises(ss.InvalidInputError):
        ss.OnlineSmoother([0.0, 2.0, 1.0], 1.0, 1)
    with pytest.raises(ss.TooFewSamplesError):
        ss.OnlineSmoother([0.0, 1.0], 1.0, 2)
