//! Systematic errors of the fixed-memory filter (Morrison §7.10-7.13): the bias for a truth of
//! any degree, the dominant-term form, the end-point bound, and the bias/variance balance.

use super::weights::weights_unscaled;
use super::{check_finite, check_span, check_tau_scalar, span_scalar};
use crate::basis::DiscreteLegendre;
use crate::calculus::{choose, falling_factorial, stirling2, Polynomial};
use crate::error::Error;
use crate::scalar::Scalar;

/// `g_ij` of the inverse relation `r^(i) = L^(i) Σ_{j=0..i} g_ij p_j(r)` (Morrison (7.12.8)-(7.12.9),
/// (A1.25)): `g_ij = (-1)^j ((2j+1)/(2i+1)) C(2i+1, i-j) / C(2i, i)`.
fn g<T: Scalar>(i: usize, j: usize) -> T {
    let v = T::ratio(2 * j as i64 + 1, 2 * i as i64 + 1) * choose::<T>(2 * i + 1, i - j)
        / choose::<T>(2 * i, i);
    if j.is_multiple_of(2) {
        v
    } else {
        -v
    }
}

/// Systematic error (bias = truth − estimate, Morrison (7.10.1)) of the fixed-memory filter of
/// degree `m` and span `L` for error-free samples of a polynomial truth
/// `π(t) = Σ_k a_k t^k` (`truth = [a_0, a_1, …]`, `t` in the caller's time units measured from
/// the **oldest** sample of the window, samples `τ` apart). Returns the unscaled bias of
/// `x, x', …, x^(m)` at `h` sampling intervals after the newest sample.
///
/// By the power-series route (7.12.6), (7.12.13), (7.12.14) and (7.10.18):
/// `λ_i = Σ_k a_k τ^k S2(k, i)`, `γ̃_j = Σ_{i≥j} λ_i L^(i) g_ij`,
/// `b_i = τ^(-i) Σ_{j=m+1..d} γ̃_j dⁱp_j/drⁱ |_(r=L+h)`. Exact in `T = Rational`. The discrete
/// Legendre expansion needs `d ≤ L`; for a truth of higher degree the bias is computed as
/// `Π(L+h) − W(h, τ) Ỹ` (7.10.1) directly.
///
/// ```
/// use seqsmooth::polynomial::fixed::bias;
/// use seqsmooth::scalar::Rational;
/// let q = |n: i64| Rational::from_integer(n.into());
/// // Ex 7.25 (T7-20): m = 1, π = t², τ = 1: b*(L) = L(L-1)/6; at L = 7: 7, and b*(L/2) = -L(L+2)/12
/// let b = bias(1, 7, q(0), q(1), &[q(0), q(0), q(1)]).unwrap();
/// assert_eq!(b[0], q(7));
/// let c = bias(1, 7, Rational::new((-7).into(), 2.into()), q(1), &[q(0), q(0), q(1)]).unwrap();
/// assert_eq!(c[0], Rational::new((-21).into(), 4.into()));
/// ```
pub fn bias<T: Scalar>(m: usize, span: u64, h: T, tau: T, truth: &[T]) -> Result<Vec<T>, Error> {
    check_span(m, span)?;
    check_finite("lead h", &h)?;
    check_tau_scalar(&tau)?;
    for a in truth {
        check_finite("truth coefficient", a)?;
    }
    let d = truth.len().saturating_sub(1);
    if truth.len() <= m + 1 {
        return Ok(vec![T::zero(); m + 1]);
    }
    let l = span_scalar::<T>(span);
    if d as u64 > span {
        return bias_direct(m, span, h, tau, truth);
    }
    // (7.12.6): λ_i = Σ_{k≥i} a_k τ^k S2(k, i)
    let s2 = stirling2::<T>(d);
    let lam: Vec<T> = (0..=d)
        .map(|i| {
            (i..=d).fold(T::zero(), |acc, k| {
                acc + truth[k].clone() * tau.powi_u(k) * s2[(k, i)].clone()
            })
        })
        .collect();
    // (7.12.13): γ̃_j = Σ_{i≥j} λ_i L^(i) g_ij
    let gamma: Vec<T> = (0..=d)
        .map(|j| {
            (j..=d).fold(T::zero(), |acc, i| {
                acc + lam[i].clone() * falling_factorial(l.clone(), i) * g::<T>(i, j)
            })
        })
        .collect();
    // (7.10.18)
    let basis = DiscreteLegendre::new(l.clone());
    let dp = basis.derivatives_by_recursion(d, m, &(l + h));
    Ok((0..=m)
        .map(|i| {
            let s = (m + 1..=d).fold(T::zero(), |acc, j| {
                acc + gamma[j].clone() * dp[(j, i)].clone()
            });
            s / tau.powi_u(i)
        })
        .collect())
}

/// `Π(L+h) − W(h, τ) Ỹ` (7.10.1), for a truth of any degree.
fn bias_direct<T: Scalar>(m: usize, span: u64, h: T, tau: T, truth: &[T]) -> Result<Vec<T>, Error> {
    let p = Polynomial::new(truth.to_vec());
    let l = span_scalar::<T>(span);
    let w = weights_unscaled(m, span, h.clone(), tau.clone())?;
    let at = (l.clone() + h) * tau.clone();
    Ok((0..=m)
        .map(|i| {
            let truth_i = p.taylor_coefficient(i, &at) * crate::calculus::factorial::<T>(i);
            let est = (0..=span as usize).fold(T::zero(), |acc, k| {
                let y = p.eval(&((l.clone() - T::from_i64(k as i64)) * tau.clone()));
                acc + w[(i, k)].clone() * y
            });
            truth_i - est
        })
        .collect())
}

/// The dominant-term bias for a truth whose first neglected power-series coefficient is
/// `a_next = a_{m+1}` (exact when the truth has degree `m+1`): Morrison (7.13.5)-(7.13.6),
/// `D^i b* = τ^(-i) (-1)^(m+1) a_{m+1} τ^(m+1) L^(m+1) / C(2m+2, m+1) · dⁱp_{m+1}/drⁱ |_(r=L+h)`
/// (the book's "to within sign" is `(-1)^(m+1)`). Unscaled derivatives `0..=m` at lead `h`.
///
/// ```
/// use seqsmooth::polynomial::fixed::dominant_bias;
/// // (7.13.7), m = 1: b*(r) = a2 τ² L(L-1)/6 p2(r); end point (r = L): a2 τ² L(L-1)/6
/// let b = dominant_bias(1, 10, 0.0, 1.0, 16.0).unwrap();
/// assert!((b[0] - 16.0 * 90.0 / 6.0).abs() < 1e-9);
/// ```
pub fn dominant_bias<T: Scalar>(
    m: usize,
    span: u64,
    h: T,
    tau: T,
    a_next: T,
) -> Result<Vec<T>, Error> {
    check_span(m, span)?;
    check_finite("lead h", &h)?;
    check_tau_scalar(&tau)?;
    check_finite("a_next", &a_next)?;
    if span <= m as u64 {
        // p_{m+1} does not exist on m+1 points; the bias is the interpolation error.
        let mut truth = vec![T::zero(); m + 2];
        truth[m + 1] = a_next;
        return bias_direct(m, span, h, tau, &truth);
    }
    let l = span_scalar::<T>(span);
    let gamma = a_next * tau.powi_u(m + 1) * falling_factorial(l.clone(), m + 1)
        / choose::<T>(2 * m + 2, m + 1);
    let gamma = if (m + 1).is_multiple_of(2) {
        gamma
    } else {
        -gamma
    };
    let basis = DiscreteLegendre::new(l.clone());
    let dp = basis.derivatives_by_recursion(m + 1, m, &(l + h));
    Ok((0..=m)
        .map(|i| gamma.clone() * dp[(m + 1, i)].clone() / tau.powi_u(i))
        .collect())
}

/// Bound on the end-point bias (Morrison (7.13.9)-(7.13.10)):
/// `|b*(L)| ≤ |a_{m+1}|_max τ^(m+1) L^(m+1) / C(2m+2, m+1)`.
///
/// ```
/// use seqsmooth::polynomial::fixed::end_point_bias_bound;
/// // Ex 7.26 (T7-23): m = 1, |R''/2| = 16 ft/s², τ = 1 s, L = 10: 16·10·9/6 = 240 ft
/// assert_eq!(end_point_bias_bound(1, 10, 1.0, 16.0).unwrap(), 240.0);
/// ```
pub fn end_point_bias_bound<T: Scalar>(m: usize, span: u64, tau: T, a_max: T) -> Result<T, Error> {
    check_span(m, span)?;
    check_tau_scalar(&tau)?;
    check_finite("a_max", &a_max)?;
    let l = span_scalar::<T>(span);
    Ok(
        a_max.abs_val() * tau.powi_u(m + 1) * falling_factorial(l, m + 1)
            / choose::<T>(2 * m + 2, m + 1),
    )
}
