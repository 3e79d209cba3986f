//! The polynomial process model: state conventions, scaling and transition matrices
//! (Morrison ch. 4; Reyneke et al. §4).
//!
//! For a degree-`m` process `x(t)` three state vectors appear in the sources:
//!
//! | name | components `k = 0..m` | transition over `h` steps of `τ` |
//! |---|---|---|
//! | unscaled `X` | `x^(k)(t)` (the public API) | `Φ_X(hτ)`, `[Φ_X(ζ)]_ij = ζ^(j-i)/(j-i)!` (4.2.5) |
//! | Morrison's scaled `Z` | `z_k = τ^k x^(k)/k!` | [`phi`]: `[Φ(h)]_ij = C(j,i) h^(j-i)` (4.2.15) |
//! | Reyneke's `Ψ` state | `d_k = τ^k x^(k) = k! z_k` | [`psi`]: `[Ψ(ζ)]_ij = ζ^(j-i)/(j-i)!` (eq. 7) |
//!
//! `X = D(τ) Z` with `D(τ) = diag(k!/τ^k)` ([`scaling`], (4.2.18)). Gains convert as
//! `Γ_Ψ[k] = k! Γ_Φ[k]` (derivative index `k`; see ../shared/spec/others.md §4.5).

use crate::calculus::{choose, factorial};
use crate::scalar::Scalar;
use nalgebra::{DMatrix, DVector};

/// Morrison's scaled transition matrix `[Φ(h)]_ij = C(j,i) h^(j-i)` for `j ≥ i` (4.2.15):
/// `Z(t + hτ) = Φ(h) Z(t)`. Upper-triangular Pascal matrix; `Φ(h)Φ(k) = Φ(h+k)`.
///
/// ```
/// use seqsmooth::model::phi;
/// let p = phi(2, 1.0_f64);
/// assert_eq!(p.row(0).iter().copied().collect::<Vec<_>>(), vec![1.0, 1.0, 1.0]); // (4.2.17)
/// assert_eq!(p[(1, 2)], 2.0);
/// ```
pub fn phi<T: Scalar>(m: usize, h: T) -> DMatrix<T> {
    DMatrix::from_fn(m + 1, m + 1, |i, j| {
        if j < i {
            T::zero()
        } else {
            choose::<T>(j, i) * h.powi_u(j - i)
        }
    })
}

/// Reyneke's transition matrix `[Ψ(ζ)]_ij = ζ^(j-i)/(j-i)!` for `j ≥ i` (Reyneke eq. 7), which is
/// also Morrison's unscaled `Φ_X(ζ)` (4.2.5) when `ζ` is in time units.
///
/// ```
/// use seqsmooth::model::psi;
/// let p = psi(2, 2.0_f64);
/// assert_eq!(p[(0, 2)], 2.0); // ζ²/2!
/// ```
pub fn psi<T: Scalar>(m: usize, zeta: T) -> DMatrix<T> {
    DMatrix::from_fn(m + 1, m + 1, |i, j| {
        if j < i {
            T::zero()
        } else {
            zeta.powi_u(j - i) / factorial::<T>(j - i)
        }
    })
}

/// The scaling matrix `D(τ) = diag(k!/τ^k)` with `X = D(τ) Z` (Morrison (4.2.18)-(4.2.19)).
///
/// ```
/// use seqsmooth::model::scaling;
/// let d = scaling(2, 0.5_f64);
/// assert_eq!(d[(2, 2)], 8.0); // 2!/0.5²
/// ```
pub fn scaling<T: Scalar>(m: usize, tau: T) -> DMatrix<T> {
    DMatrix::from_fn(m + 1, m + 1, |i, j| {
        if i == j {
            factorial::<T>(i) / tau.powi_u(i)
        } else {
            T::zero()
        }
    })
}

/// In-place Taylor shift `z ← Φ(h) z` in `O(m²)` operations: if `z` holds the coefficients of
/// `f(u) = Σ z_k u^k`, afterwards it holds those of `f(u + h)` (repeated synthetic division).
///
/// ```
/// use seqsmooth::model::shift_scaled;
/// let mut z = [1.0, 2.0, 3.0];      // 1 + 2u + 3u²
/// shift_scaled(&mut z, 1.0);        // 6 + 8u + 3u²
/// assert_eq!(z, [6.0, 8.0, 3.0]);
/// ```
pub fn shift_scaled(z: &mut [f64], h: f64) {
    if z.len() < 2 || h == 0.0 {
        return;
    }
    // Fixed lengths unroll completely (the same operations in the same order).
    match z.len() {
        2 => shift_fixed::<2>(z, h),
        3 => shift_fixed::<3>(z, h),
        4 => shift_fixed::<4>(z, h),
        5 => shift_fixed::<5>(z, h),
        6 => shift_fixed::<6>(z, h),
        _ => shift_any(z, h),
    }
}

#[inline(always)]
fn shift_fixed<const N: usize>(z: &mut [f64], h: f64) {
    shift_any(&mut z[..N], h);
}

/// [`shift_scaled`] for a length known at compile time (unrolled where it is inlined; the
/// same operations in the same order).
#[inline(always)]
pub(crate) fn shift_scaled_array<const N: usize>(z: &mut [f64; N], h: f64) {
    if N >= 2 && h != 0.0 {
        shift_any(z, h);
    }
}

#[inline(always)]
fn shift_any(z: &mut [f64], h: f64) {
    let n = z.len();
    for i in 0..n - 1 {
        for k in (i..n - 1).rev() {
            z[k] += h * z[k + 1];
        }
    }
}

/// Converts Morrison's scaled state `Z` (unit `τ`) to unscaled derivatives `X = D(τ) Z`.
///
/// ```
/// use seqsmooth::model::scaled_to_derivatives;
/// assert_eq!(scaled_to_derivatives(&[1.0, 2.0, 3.0], 2.0), vec![1.0, 1.0, 1.5]);
/// ```
pub fn scaled_to_derivatives(z: &[f64], tau: f64) -> Vec<f64> {
    let mut f = 1.0;
    let mut tk = 1.0;
    z.iter()
        .enumerate()
        .map(|(k, &v)| {
            if k > 0 {
                f *= k as f64;
                tk *= tau;
            }
            v * f / tk
        })
        .collect()
}

/// Converts unscaled derivatives `X` to Morrison's scaled state `Z = D(τ)⁻¹ X`.
///
/// ```
/// use seqsmooth::model::derivatives_to_scaled;
/// assert_eq!(derivatives_to_scaled(&[1.0, 1.0, 1.5], 2.0), vec![1.0, 2.0, 3.0]);
/// ```
pub fn derivatives_to_scaled(x: &[f64], tau: f64) -> Vec<f64> {
    let mut f = 1.0;
    let mut tk = 1.0;
    x.iter()
        .enumerate()
        .map(|(k, &v)| {
            if k > 0 {
                f *= k as f64;
                tk *= tau;
            }
            v * tk / f
        })
        .collect()
}

/// A polynomial state: the value and derivatives `x^(0..=m)` of the estimated process at `time`,
/// in the caller's time units, with the covariance of their errors when known.
///
/// ```
/// use seqsmooth::model::PolynomialState;
/// let s = PolynomialState::new(0.0, vec![1.0, 2.0, 2.0]); // 1 + 2t + t²
/// let p = s.at(1.0);
/// assert_eq!(p.derivatives, vec![4.0, 4.0, 2.0]);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct PolynomialState {
    /// The instant the state is valid at.
    pub time: f64,
    /// `x, x', x'', …, x^(m)` at `time`.
    pub derivatives: Vec<f64>,
    /// Covariance of the errors of `derivatives` (unscaled), when known.
    pub covariance: Option<DMatrix<f64>>,
}

impl PolynomialState {
    /// A state without covariance.
    pub fn new(time: f64, derivatives: Vec<f64>) -> Self {
        Self {
            time,
            derivatives,
            covariance: None,
        }
    }

    /// Degree `m` of the polynomial model.
    pub fn degree(&self) -> usize {
        self.derivatives.len().saturating_sub(1)
    }

    /// 1σ of each derivative, when the covariance is known.
    pub fn std_devs(&self) -> Option<Vec<f64>> {
        self.covariance
            .as_ref()
            .map(|c| (0..c.nrows()).map(|i| c[(i, i)].max(0.0).sqrt()).collect())
    }

    /// The same trajectory propagated to `time` (prediction for a later time, retrodiction for an
    /// earlier one): `X(t+ζ) = Φ_X(ζ) X(t)`, `S(t+ζ) = Φ_X S Φ_Xᵀ` (Morrison (5.5.21)-(5.5.22)).
    pub fn at(&self, time: f64) -> PolynomialState {
        let zeta = time - self.time;
        let m = self.degree();
        let transition = psi(m, zeta);
        let x = &transition * DVector::from_column_slice(&self.derivatives);
        let covariance = self
            .covariance
            .as_ref()
            .map(|c| &transition * c * transition.transpose());
        PolynomialState {
            time,
            derivatives: x.iter().copied().collect(),
            covariance,
        }
    }
}

/// Error-free sum: `a + b = s + e` exactly (Knuth's TwoSum).
#[inline]
pub(crate) fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    (s, e)
}

/// [`shift_scaled`] in compensated (double-word) arithmetic: the state is `hi + lo` per
/// component, each product's and sum's rounding error is carried in `lo` (TwoSum and an FMA
/// for the product error; Graillat–Langlois–Louvet's compensated Horner scheme). The result is
/// as accurate as if computed in twice the working precision, which matters because the Taylor
/// coefficients of a polynomial about the end of its data interval are an ill-conditioned
/// representation (cancellation of order `(1+√2)^(2m)` at degree `m`).
///
/// ```
/// use seqsmooth::model::shift_scaled_compensated;
/// let mut hi = [1.0, 2.0, 3.0];
/// let mut lo = [0.0; 3];
/// shift_scaled_compensated(&mut hi, &mut lo, 1.0);
/// assert_eq!(hi, [6.0, 8.0, 3.0]);
/// ```
pub fn shift_scaled_compensated(hi: &mut [f64], lo: &mut [f64], h: f64) {
    let n = hi.len();
    if n < 2 || h == 0.0 {
        return;
    }
    for i in 0..n - 1 {
        for k in (i..n - 1).rev() {
            let p = h * hi[k + 1];
            let pe = h.mul_add(hi[k + 1], -p);
            let (s, se) = two_sum(hi[k], p);
            lo[k] += h * lo[k + 1] + pe + se;
            hi[k] = s;
        }
    }
    for k in 0..n {
        let (s, e) = two_sum(hi[k], lo[k]);
        hi[k] = s;
        lo[k] = e;
    }
}
