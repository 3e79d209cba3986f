//! Systematic errors of the fixed-memory filter (Morrison §7.10-7.13): the bias for a truth of
//! any degree, the dominant-term form, the end-point bound, and the bias/variance balance.

use super::covariance::{unscaled_variance, MAX_SEARCH_SPAN};
use super::weights::weights_unscaled;
use super::{check_finite, check_span, check_tau_scalar, span_scalar, Lead};
use crate::basis::DiscreteLegendre;
use crate::calculus::{choose, falling_factorial, stirling2, Polynomial};
use crate::error::Error;
use crate::scalar::Scalar;

/// `g_ij` of the inverse relation `r^(i) = L^(i) Σ_{j=0..i} g_ij p_j(r)` (Morrison (7.12.8)-(7.12.9),
/// (A1.25)): `g_ij = (-1)^j ((2j+1)/(2i+1)) C(2i+1, i-j) / C(2i, i)`.
fn g<T: Scalar>(i: usize, j: usize) -> T {
    let v = T::ratio(2 * j as i64 + 1, 2 * i as i64 + 1) * choose::<T>(2 * i + 1, i - j)
        / choose::<T>(2 * i, i);
    if j % 2 == 0 {
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
    let gamma = if (m + 1) % 2 == 0 { gamma } else { -gamma };
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

/// The result of [`balance_span`]: the span and, at it, the random and systematic errors of the
/// value at the lead.
///
/// ```
/// use seqsmooth::polynomial::fixed::{balance_span, Lead};
/// let b = balance_span(2, 0.5, 1e-6, 1.0, Lead::Steps(0.0), 1.0).unwrap();
/// assert!(b.bias <= b.random_sigma && b.span > 2);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Balance {
    /// The memory span `L` (window of `L+1` samples).
    pub span: u64,
    /// 1σ random error of the value at the lead for this span.
    pub random_sigma: f64,
    /// Magnitude of the dominant-term bias of the value at the lead for this span.
    pub bias: f64,
}

/// Balances systematic against random error (Morrison §7.13, (7.13.8)-(7.13.10)): the largest
/// span `L` for which the dominant-term bias of the value at `lead`,
/// `|a_{m+1}| τ^(m+1) L^(m+1) |p_{m+1}(L+h)| / C(2m+2, m+1)`, is at most `ratio` times its random
/// 1σ error `σ_ν √VRF(L)` (exact VRF; the book balances at `ratio = 1`, Ex 9.19b uses 0.1).
/// The bias grows and the random error falls with `L` at the end point, for predictions and at
/// the centre; the search doubles `L` and then bisects. At the centre the dominant bias vanishes
/// for even `m` (`p_{m+1}(L/2) = 0`), so there is nothing to balance: an error.
///
/// ```
/// use seqsmooth::polynomial::fixed::{balance_span, Lead};
/// // Ex 7.26 (T7-23): m = 1, σ_ν = 200 ft, R'' = 32 ft/s² (a2 = 16), τ = 1 s, end point: L = 7
/// // (L = 7: σ 129.1, bias 112.0; L = 8: σ 122.9 < bias 149.3)
/// let b = balance_span(1, 200.0, 16.0, 1.0, Lead::Steps(0.0), 1.0).unwrap();
/// assert_eq!(b.span, 7);
/// ```
pub fn balance_span(
    m: usize,
    sigma_nu: f64,
    a_next: f64,
    tau: f64,
    lead: Lead,
    ratio: f64,
) -> Result<Balance, Error> {
    crate::polynomial::options::check_degree(m)?;
    crate::polynomial::options::check_tau(tau)?;
    lead.check()?;
    for (name, v) in [
        ("noise sigma", sigma_nu),
        ("a_next", a_next.abs()),
        ("ratio", ratio),
    ] {
        if !(v.is_finite() && v > 0.0) {
            return Err(Error::InvalidParameter {
                name,
                value: v.to_string(),
                reason: "must be a non-zero finite number (positive for sigma and ratio)".into(),
            });
        }
    }
    if matches!(lead, Lead::Centre) && m % 2 == 0 {
        return Err(Error::InvalidParameter {
            name: "lead",
            value: "centre".into(),
            reason: format!(
                "the dominant bias p_{}(L/2) vanishes at the centre for even degree {m}",
                m + 1
            ),
        });
    }
    let eval = |l: u64| -> Result<Balance, Error> {
        let h = lead.steps(l);
        let var = unscaled_variance(m, l, lead, 0, tau)?;
        let b = dominant_bias::<f64>(m, l, h, tau, a_next)?[0].abs();
        Ok(Balance {
            span: l,
            random_sigma: sigma_nu * var.sqrt(),
            bias: b,
        })
    };
    let ok = |b: &Balance| b.bias <= ratio * b.random_sigma;
    let first = eval(m as u64)?;
    if !ok(&first) {
        return Err(Error::InvalidParameter {
            name: "a_next",
            value: a_next.to_string(),
            reason: format!(
                "even the shortest window (L = {m}) has bias {} above {ratio} × σ = {}",
                first.bias,
                ratio * first.random_sigma
            ),
        });
    }
    let mut lo = first;
    let mut hi = (m as u64).max(1) * 2;
    loop {
        let b = eval(hi)?;
        if !ok(&b) {
            break;
        }
        lo = b;
        hi *= 2;
        if hi > MAX_SEARCH_SPAN {
            return Err(Error::InvalidParameter {
                name: "a_next",
                value: a_next.to_string(),
                reason: "the bias stays below the random error up to 2^40 samples".into(),
            });
        }
    }
    while hi - lo.span > 1 {
        let mid = lo.span + (hi - lo.span) / 2;
        let b = eval(mid)?;
        if ok(&b) {
            lo = b;
        } else {
            hi = mid;
        }
    }
    Ok(lo)
}
