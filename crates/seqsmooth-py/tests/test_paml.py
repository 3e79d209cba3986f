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
