//! Independent cross-checks of the fixed-memory covariance: Morrison's product form over the
//! end differences of the discrete Legendre polynomials, and the long-window limit `κ(m)` from
//! the inverse Hilbert matrix (Tables 7.2 / 9.3).

use crate::basis::DiscreteLegendre;
use crate::calculus::falling_factorial;
use crate::linalg::{congruence, inverse_exact, mul};
use crate::model::phi;
use crate::scalar::{Rational, Scalar};
use nalgebra::DMatrix;

/// Morrison's product form of the fixed-memory covariance, kept as an independent cross-check
/// of [`super::covariance`] (which the filters use: it keeps full `f64` accuracy also for
/// `h < 0`, where `Φ(h)` here cancels — 5.4e-13 at the centre, `m = 8`, `L = 1000`).
///
/// Scaled covariance (per unit input variance) of the least-squares degree-`m` fit over the
/// `L+1` equally spaced samples `r = 0..L`, evaluated at `r = L + h` (any real lead `h`):
/// `W(h) Wᵀ = Φ(h) 𝒮 G C Gᵀ 𝒮ᵀ Φ(h)ᵀ` with `C = diag(1/c(j,L)²)` (Morrison (7.4.16), (7.5.x),
/// using `B Bᵀ = diag(c_j²)`). Requires `m ≤ L`.
///
/// For `h ≥ 0` every term of the sums has the same sign, so the `f64` evaluation loses no
/// digits to cancellation — as long as the intermediate factorial powers stay in range:
/// `L^(m)` and `c(m,L)² ~ L^(2m+1)/(2m+1)` must not overflow `f64`, which limits the `f64`
/// path to roughly `L^(2m+1) < 1e300` (e.g. `m = 20`, `L ≲ 1e7`). Use `T = Rational` beyond.
///
/// ```
/// use seqsmooth::polynomial::fixed::window_covariance;
/// // m = 1, L = 4, h = 0 (Morrison (7.3.27)): W(0)W(0)ᵀ = [[0.6, 0.2], [0.2, 0.1]]
/// let s = window_covariance(1, 4, 0.0_f64);
/// assert!((s[(0, 0)] - 0.6).abs() < 1e-15 && (s[(0, 1)] - 0.2).abs() < 1e-15);
/// ```
pub fn window_covariance<T: Scalar>(m: usize, span: u64, h: T) -> DMatrix<T> {
    let b = DiscreteLegendre::new(T::from_rational(&Rational::from_integer(span.into())));
    let q = mul(
        &mul(&phi(m, h), &crate::calculus::link_matrix::<T>(m)),
        &b.end_differences(m),
    );
    let c = DMatrix::from_fn(m + 1, m + 1, |i, j| {
        if i == j {
            T::one() / b.norm_sq(j)
        } else {
            T::zero()
        }
    });
    congruence(&q, &c)
}

/// Morrison's Table 7.2 / 9.3 matrix `κ(m)`: the covariance of a least-squares fit over a long
/// window evaluated at its newest end, `[S]_ij ≈ σ² κ_ij / (L^(i+j+1) τ^(i+j))` for the unscaled
/// derivatives; exactly `κ = V H⁻¹ Vᵀ` with the Hilbert matrix `H_jk = 1/(j+k+1)` and
/// `V_ij = j^(i)` (the derivatives of `s^j` at `s = 1`).
///
/// ```
/// use seqsmooth::polynomial::fixed::fixed_memory_vrf_limit;
/// use seqsmooth::scalar::Rational;
/// let k = fixed_memory_vrf_limit(3);
/// assert_eq!(k[(3, 3)], Rational::from_integer(100800.into())); // Table 9.3, m = 3
/// ```
pub fn fixed_memory_vrf_limit(m: usize) -> DMatrix<Rational> {
    let h = DMatrix::from_fn(m + 1, m + 1, |j, k| {
        Rational::from_i64(1) / Rational::from_i64((j + k + 1) as i64)
    });
    let hi = inverse_exact(&h).expect("Hilbert matrices are nonsingular");
    let v = DMatrix::from_fn(m + 1, m + 1, |i, j| {
        falling_factorial(Rational::from_i64(j as i64), i)
    });
    congruence(&v, &hi)
}
