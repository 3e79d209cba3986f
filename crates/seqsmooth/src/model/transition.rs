//! Transition matrices of the polynomial model: Morrison's scaled `Φ(h)` (4.2.15) and
//! Reyneke's `Ψ(ζ)` (eq. 7), which is also Morrison's unscaled `Φ_X(ζ)` (4.2.5).

use crate::calculus::{choose, factorial};
use crate::scalar::Scalar;
use nalgebra::DMatrix;

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
            psi_term(j - i, &zeta)
        }
    })
}

/// `[Ψ(ζ)]_{i, i+k} = ζ^k/k!`, the one formula of every `Ψ` entry (also
/// [`super::dynamics::PolynomialDynamics`]'s, filled in place).
pub(crate) fn psi_term<T: Scalar>(k: usize, zeta: &T) -> T {
    zeta.powi_u(k) / factorial::<T>(k)
}
