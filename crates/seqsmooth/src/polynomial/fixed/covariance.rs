//! Random errors of the fixed-memory filter (Morrison §7.5-7.8): exact covariances for any
//! window and lead, the asymptotic variance-reduction constants of Tables 7.2 and 7.3, and the
//! design helpers of §7.6.

use super::weights::{inverse_norms, taylor_at};
use super::{check_finite, check_span, check_tau_scalar, span_scalar};
use crate::basis::DiscreteLegendre;
use crate::calculus::Polynomial;
use crate::error::{Error, Param};
use crate::linalg::{congruence, mul};
use crate::model::scaling;
use crate::scalar::Scalar;
use nalgebra::DMatrix;

/// The largest lead `|h|` in samples a front end's table takes ([`covariance`] at a lead
/// given as a number): the size of the exact rational such a lead makes in the tables.
pub const MAX_LEAD_STEPS: f64 = 1e300;

/// The range of a lead `h` in samples given for a table: finite, `|h| < MAX_LEAD_STEPS`.
/// (In doubles the matrix's entries, of order `h^(2m)`, may still leave the double range well
/// inside it; the exact tables hold them.)
///
/// ```
/// use seqsmooth::polynomial::fixed::check_lead_steps;
/// assert!(check_lead_steps(-2.5).is_ok());
/// assert!(check_lead_steps(1e300).is_err() && check_lead_steps(f64::NAN).is_err());
/// ```
pub fn check_lead_steps(h: f64) -> Result<(), Error> {
    if !(h.is_finite() && h.abs() < MAX_LEAD_STEPS) {
        return Err(Error::InvalidParameter {
            name: Param::Lead,
            value: h.to_string(),
            reason: format!("must be a finite number of samples, |H| < {MAX_LEAD_STEPS:e}"),
        });
    }
    Ok(())
}

/// Scaled covariance of the fixed-memory estimate per unit input variance,
/// `S*_{n+h,n}/σ² = W(h) W(h)ᵀ = Q(L+h) Q(L+h)ᵀ` with `[Q(r)]_ij = (1/i!) dⁱφ_j(r)/drⁱ`
/// (Morrison (7.5.22)-(7.5.23), (7.5.26)), for white errors of equal variance.
///
/// This is the same matrix as [`super::window_covariance`]
/// (`Φ(h) 𝒮 G C Gᵀ 𝒮ᵀ Φ(h)ᵀ`, equal entry for entry in exact arithmetic; tested), evaluated as
/// `T(L+h) C T(L+h)ᵀ` with the Legendre derivatives from the recursion (A1.1), so that `f64`
/// keeps full accuracy also for `h < 0` (the centre, retrodiction), where the shift `Φ(h)`
/// cancels. Cost `O(m²)`, independent of `L`.
///
/// ```
/// use seqsmooth::polynomial::fixed::covariance;
/// use seqsmooth::scalar::Rational;
/// // (7.5.16), m = 1, L = 4, h = 0: [[2(2L+1), 6], [6, 12/L]] / ((L+2)(L+1)) = [[3/5, 1/5], [1/5, 1/10]]
/// let s = covariance(1, 4, Rational::from_integer(0.into())).unwrap();
/// assert_eq!(s[(0, 0)], Rational::new(3.into(), 5.into()));
/// assert_eq!(s[(1, 1)], Rational::new(1.into(), 10.into()));
/// // In f64 a lead so far out that the variance overflows is refused, exactly it is not.
/// assert!(covariance(2, 9, 1e200_f64).is_err());
/// assert!(covariance(2, 9, Rational::from_integer(10.into()).pow(200)).is_ok());
/// ```
pub fn covariance<T: Scalar>(m: usize, span: u64, h: T) -> Result<DMatrix<T>, Error> {
    check_span(m, span)?;
    check_finite("lead h", &h)?;
    let lead = h.to_f64();
    let l = span_scalar::<T>(span);
    let basis = DiscreteLegendre::new(l.clone());
    let t = taylor_at(m, &basis, &(l + h));
    let inv = inverse_norms(m, &basis);
    let c = DMatrix::from_fn(m + 1, m + 1, |i, j| {
        if i == j {
            inv[i].clone()
        } else {
            T::zero()
        }
    });
    let s = congruence(&t, &c);
    // A lead far beyond the window (|H| of 1e200 samples) overflows `f64`: refused, never
    // written as ∞ or NaN (the exact field has no such limit).
    if let Some(k) = s.iter().position(|v| !v.is_number()) {
        let (i, j) = (k % (m + 1), k / (m + 1));
        return Err(Error::EstimateOutOfRange {
            what: format!("covariance of d{i}, d{j} at the lead {lead:e}"),
        });
    }
    Ok(s)
}

/// Covariance of the unscaled derivatives per unit input variance,
/// `S_X/σ² = D(τ) W(h) W(h)ᵀ D(τ)` with `D(τ) = diag(k!/τ^k)` (Morrison (7.5.27)-(7.5.28)).
/// The diagonal holds the variance-reduction factors of `x, x', …, x^(m)`.
///
/// ```
/// use seqsmooth::polynomial::fixed::covariance_unscaled;
/// // (9.7.8) with n -> L: m = 1, L = 10, 1-step: Var(x') = 12/(τ² (L+2)(L+1)L)
/// let s = covariance_unscaled(1, 10, 1.0, 0.5).unwrap();
/// assert!((s[(1, 1)] - 12.0 / (0.25 * 12.0 * 11.0 * 10.0)).abs() < 1e-15);
/// ```
pub fn covariance_unscaled<T: Scalar>(
    m: usize,
    span: u64,
    h: T,
    tau: T,
) -> Result<DMatrix<T>, Error> {
    check_tau_scalar(&tau)?;
    let s = covariance(m, span, h)?;
    Ok(congruence(&scaling(m, tau), &s))
}

/// Covariance `W R Wᵀ` of the estimate `W Y` for errors of covariance `R` (Morrison (7.5.4)):
/// `w` is any weight matrix ([`weights`](super::weights()) or
/// [`weights_unscaled`](super::weights_unscaled()), `(m+1) × (L+1)`)
/// and `r` the `(L+1) × (L+1)` covariance of `Y_(n) = (y_n, …, y_{n-L})`, newest first.
///
/// ```
/// use seqsmooth::polynomial::fixed::{correlated_covariance, weights};
/// use seqsmooth::scalar::Rational;
/// use nalgebra::DMatrix;
/// // Ex 7.10 (T7-11): R = tridiag(1, 2, 1), W = W(0), m = 1, L = 4: S = [[46/25, 14/25], [14/25, 7/25]]
/// let q = |n: i64| Rational::from_integer(n.into());
/// let r = DMatrix::from_fn(5, 5, |i, j| match i.abs_diff(j) { 0 => q(2), 1 => q(1), _ => q(0) });
/// let s = correlated_covariance(&weights(1, 4, q(0)).unwrap(), &r).unwrap();
/// assert_eq!(s[(0, 0)], Rational::new(46.into(), 25.into()));
/// ```
pub fn correlated_covariance<T: Scalar>(
    w: &DMatrix<T>,
    r: &DMatrix<T>,
) -> Result<DMatrix<T>, Error> {
    if r.nrows() != w.ncols() || r.ncols() != w.ncols() {
        return Err(Error::InvalidParameter {
            name: Param::ErrorCovarianceR,
            value: format!("{} x {}", r.nrows(), r.ncols()),
            reason: format!(
                "must be {n} x {n} to match a weight matrix over {n} samples",
                n = w.ncols()
            ),
        });
    }
    Ok(mul(&mul(w, r), &w.transpose()))
}

/// The classical Legendre polynomials `P_0 … P_m` (Bonnet's recursion), exact in `T`.
fn classical_legendre<T: Scalar>(m: usize) -> Vec<Polynomial<T>> {
    let mut p = vec![Polynomial::constant(T::one())];
    if m >= 1 {
        p.push(Polynomial::new(vec![T::zero(), T::one()]));
    }
    for k in 1..m {
        let x_pk = Polynomial::new(vec![T::zero(), T::one()]).mul(&p[k]);
        let a = x_pk.scale(&T::ratio(2 * k as i64 + 1, k as i64 + 1));
        let b = p[k - 1].scale(&T::ratio(-(k as i64), k as i64 + 1));
        p.push(a.add(&b));
    }
    p
}

/// The asymptotic (long-window) variance-reduction constants `λ_ij(m, ρ)` of the fixed-memory
/// filter evaluated at the fraction `ρ = r/L` of the window (`ρ = 1` the newest sample, `ρ = 1/2`
/// the centre): `[S_X]_ij ≈ σ² λ_ij / (τ^(i+j) L^(i+j+1))` (Morrison (7.6.11)-(7.6.12)), with
/// the exact generating formula (continuous limit `φ_k ≈ √((2k+1)/L) P_k(1-2ρ)`, Ex 7.22)
/// `λ_ij(ρ) = (-2)^(i+j) Σ_{k=0..m} (2k+1) P_k^(i)(x) P_k^(j)(x)`, `x = 1 - 2ρ`.
/// `ρ = 1` gives Table 7.2 (also valid for the one-step prediction; equal to
/// [`super::fixed_memory_vrf_limit`]), `ρ = 1/2` Table 7.3.
///
/// ```
/// use seqsmooth::polynomial::fixed::vrf_limit;
/// use seqsmooth::scalar::Rational;
/// let half = Rational::new(1.into(), 2.into());
/// let centre = vrf_limit(4, half).unwrap();
/// assert_eq!(centre[(2, 2)], Rational::from_integer(8820.into())); // Table 7.3 (not 720: (7.8.5))
/// assert_eq!(vrf_limit(2, 1.0_f64).unwrap()[(0, 0)], 9.0);         // Table 7.2
/// ```
pub fn vrf_limit<T: Scalar>(m: usize, rho: T) -> Result<DMatrix<T>, Error> {
    crate::polynomial::options::check_degree(m)?;
    check_finite("window fraction rho", &rho)?;
    let x = T::one() - T::from_i64(2) * rho;
    let p = classical_legendre::<T>(m);
    // d[k][i] = P_k^(i)(x)
    let d: Vec<Vec<T>> = p
        .iter()
        .map(|pk| (0..=m).map(|i| pk.derivative(i).eval(&x)).collect())
        .collect();
    Ok(DMatrix::from_fn(m + 1, m + 1, |i, j| {
        let s = (0..=m).fold(T::zero(), |acc, k| {
            acc + T::from_i64(2 * k as i64 + 1) * d[k][i].clone() * d[k][j].clone()
        });
        T::from_i64(-2).powi_u(i + j) * s
    }))
}
