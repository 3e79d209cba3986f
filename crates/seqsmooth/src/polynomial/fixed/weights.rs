//! The weight matrix `W(h)` of the fixed-memory filter (Morrison §7.3-7.4).

use super::{check_finite, check_materialised, check_span, span_scalar};
use crate::basis::DiscreteLegendre;
use crate::calculus::factorial;
use crate::error::Error;
use crate::linalg::mul;
use crate::model::scaling;
use crate::scalar::Scalar;
use nalgebra::DMatrix;

/// The Taylor matrix of the discrete Legendre polynomials at any point `r` of the window axis:
/// `[T(r)]_ij = (1/i!) dⁱp_j(r)/drⁱ`, `0 ≤ i, j ≤ m` (Morrison (7.4.4) at `r = L`, where
/// `T(L) = P = 𝒮 G` (7.4.15), and `T(L+h) = Φ(h) P` (7.5.21)), by the three-term recursion
/// (A1.1), which has none of the cancellation of the explicit sums. Requires `m ≤ L`.
pub(crate) fn taylor_at<T: Scalar>(m: usize, basis: &DiscreteLegendre<T>, r: &T) -> DMatrix<T> {
    let d = basis.derivatives_by_recursion(m, m, r);
    let facts: Vec<T> = (0..=m).map(factorial::<T>).collect();
    DMatrix::from_fn(m + 1, m + 1, |i, j| d[(j, i)].clone() / facts[i].clone())
}

/// `p_0(x) … p_m(x)` by the recursion (A1.1) (order 0).
pub(crate) fn legendre_values<T: Scalar>(m: usize, basis: &DiscreteLegendre<T>, x: &T) -> Vec<T> {
    let d = basis.derivatives_by_recursion(m, 0, x);
    (0..=m).map(|j| d[(j, 0)].clone()).collect()
}

/// `1/c(j, L)²` for `j = 0..=m` (the diagonal of `C`, (7.4.5), (3.2.30)).
pub(crate) fn inverse_norms<T: Scalar>(m: usize, basis: &DiscreteLegendre<T>) -> Vec<T> {
    (0..=m).map(|j| T::one() / basis.norm_sq(j)).collect()
}

/// The fixed-memory weight matrix `W(h)` for Morrison's scaled state (7.4.9)-(7.4.16):
/// `Z*_{n+h,n} = W(h) Y_(n)`, `W(h) = Φ(h) 𝒮 G C B`, an `(m+1) × (L+1)` matrix whose column `k`
/// multiplies `y_{n-k}` (`k = 0` the newest sample, `k = L` the oldest) and whose row `i` gives
/// `z_i = τ^i x^(i)/i!` at `h` sampling intervals after the newest sample (`h` real: `0` current
/// estimate, `1` one-step prediction, `-L/2` centre of the window, any other lead or lag).
///
/// Computed as `W(h) = T(L+h) C B` with `[T(r)]_ij = (1/i!) dⁱp_j(r)/drⁱ` (since
/// `Φ(h) 𝒮 G = T(L+h)`, (7.4.15), (7.5.21)), `C = diag(1/c_j²)` and `[B]_jk = p_j(L-k)` (7.4.6),
/// every Legendre value and derivative from the three-term recursion (A1.1). With
/// `T = Rational` the result is exact (and equals the book's product `Φ(h) 𝒮 G C B` entry for
/// entry); in `f64` it is stable, whereas the book's product with the explicit sums
/// `Σ_ν C(j,ν) C(j+ν,ν) x^(ν)/L^(ν)` and the shift `Φ(h)` loses digits through cancellation
/// (measured accuracy: see ACCURACY.md). Cost `O(L m²)`.
///
/// Errors: `m > MAX_DEGREE`, `L < m` (fewer samples than coefficients), `L ≥ 2³²`,
/// non-finite `h`.
///
/// ```
/// use seqsmooth::polynomial::fixed::weights;
/// use seqsmooth::scalar::Rational;
/// // Morrison (7.4.17): m = 1, L = 4, h = 1: W(1) = (1/10)[[8,5,2,-1,-4],[2,1,0,-1,-2]]
/// let w = weights(1, 4, Rational::from_integer(1.into())).unwrap();
/// assert_eq!(w[(0, 0)], Rational::new(8.into(), 10.into()));
/// assert_eq!(w[(1, 4)], Rational::new((-2).into(), 10.into()));
/// let wf = weights(1, 4, 1.0_f64).unwrap();
/// assert!((wf[(0, 1)] - 0.5).abs() < 1e-15);
/// ```
pub fn weights<T: Scalar>(m: usize, span: u64, h: T) -> Result<DMatrix<T>, Error> {
    check_span(m, span)?;
    check_materialised(span)?;
    check_finite("lead h", &h)?;
    let l = span_scalar::<T>(span);
    let basis = DiscreteLegendre::new(l.clone());
    let t = taylor_at(m, &basis, &(l.clone() + h));
    let inv = inverse_norms(m, &basis);
    let tc = DMatrix::from_fn(m + 1, m + 1, |i, j| t[(i, j)].clone() * inv[j].clone());
    let n = span as usize + 1;
    let mut b = DMatrix::from_element(m + 1, n, T::zero());
    for k in 0..n {
        let x = l.clone() - T::from_i64(k as i64);
        for (j, v) in legendre_values(m, &basis, &x).into_iter().enumerate() {
            b[(j, k)] = v;
        }
    }
    Ok(mul(&tc, &b))
}

/// The unscaled weight matrix `W(h, τ) = D(τ) W(h)` (Morrison (7.4.11)-(7.4.12)): row `i` gives
/// the `i`-th derivative `x^(i)` in the caller's time units for samples `τ` apart.
///
/// ```
/// use seqsmooth::polynomial::fixed::weights_unscaled;
/// // T7-04: m = 1, L = 4, one-step prediction, τ = 0.5: x' = (2y_n + y_{n-1} - y_{n-3} - 2y_{n-4})/(10τ)
/// let w = weights_unscaled(1, 4, 1.0, 0.5).unwrap();
/// assert!((w[(1, 0)] - 0.4).abs() < 1e-15 && (w[(1, 4)] + 0.4).abs() < 1e-15);
/// ```
pub fn weights_unscaled<T: Scalar>(m: usize, span: u64, h: T, tau: T) -> Result<DMatrix<T>, Error> {
    super::check_tau_scalar(&tau)?;
    let w = weights(m, span, h)?;
    Ok(mul(&scaling(m, tau), &w))
}
