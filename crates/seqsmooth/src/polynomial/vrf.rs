//! Variance-reduction (normalised covariance) matrices of the polynomial filters, any degree.
//!
//! All matrices are for Morrison's scaled state `Z` and white errors of unit variance: the
//! covariance of the estimate is `σ² · VRF`, and for unscaled derivatives
//! `S_X = σ² D(τ) VRF D(τ)` with `D(τ) = diag(k!/τ^k)` ([`unscale`]).

use crate::basis::{DiscreteLaguerre, DiscreteLegendre};
use crate::calculus::{choose, falling_factorial};
use crate::error::Error;
use crate::linalg::{congruence, inverse_exact, mul};
use crate::model::{phi, scaling};
use crate::scalar::{Rational, Scalar};
use nalgebra::DMatrix;

/// Which estimate a variance-reduction matrix describes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum EstimateForm {
    /// `Z*_{n,n}`: valid at the newest sample.
    #[default]
    Current,
    /// `Z*_{n+1,n}`: the 1-step prediction.
    Predictor,
}

/// Morrison's product form of the fixed-memory covariance, kept as an independent cross-check
/// of [`super::fixed::covariance`] (which the filters use: it keeps full `f64` accuracy also for
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
/// use seqsmooth::polynomial::vrf::window_covariance;
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

/// Expanding-memory variance-reduction matrix at the 0-based index `n` of the newest sample
/// (`n+1` samples): Morrison §9.7, (9.7.1)-(9.7.4), Table 9.2 (the EMP at `n` is the fixed-memory
/// fit with `L = n`, so this is [`super::fixed::covariance`] at lead 0 or 1). Defined for `n ≥ m`.
///
/// ```
/// use seqsmooth::polynomial::vrf::{expanding_vrf, EstimateForm};
/// let s = expanding_vrf::<f64>(1, 1, EstimateForm::Predictor).unwrap();
/// assert!((s[(0, 0)] - 5.0).abs() < 1e-14 && (s[(0, 1)] - 3.0).abs() < 1e-14); // T9-08
/// ```
pub fn expanding_vrf<T: Scalar>(m: usize, n: u64, form: EstimateForm) -> Result<DMatrix<T>, Error> {
    if (n as usize) < m {
        return Err(Error::TooFewSamples {
            needed: m + 1,
            got: n as usize + 1,
        });
    }
    let h = match form {
        EstimateForm::Current => T::zero(),
        EstimateForm::Predictor => T::one(),
    };
    super::fixed::covariance(m, n, h)
}

/// Fading-memory variance-reduction matrix in the steady state, `S = F(r) A F(r)ᵀ` (Morrison
/// (13.6.15)-(13.6.20)) with `[F(r)]_ij = ((-1)^i/i!) dⁱp_j(r; θ)/drⁱ` and
/// `[A]_lk = C(l+k, l)(1-θ)/(1+θ)^(l+k+1)`; `r = 0` for the current estimate, `r = -1` for the
/// 1-step prediction. All terms are non-negative, so `f64` evaluation is accurate for all `θ`.
///
/// ```
/// use seqsmooth::polynomial::vrf::{fading_vrf, EstimateForm};
/// let s = fading_vrf(1, 0.9_f64, EstimateForm::Predictor).unwrap();
/// assert!((s[(0, 0)] - 0.137192010).abs() < 1e-9); // (13.7.1)
/// ```
pub fn fading_vrf<T: Scalar>(m: usize, theta: T, form: EstimateForm) -> Result<DMatrix<T>, Error> {
    if !(theta > T::zero() && theta < T::one()) {
        return Err(Error::ThetaOutOfRange {
            theta: theta.to_f64(),
        });
    }
    let r = match form {
        EstimateForm::Current => T::zero(),
        EstimateForm::Predictor => -T::one(),
    };
    let basis = DiscreteLaguerre::new(theta.clone());
    let polys: Vec<_> = (0..=m).map(|j| basis.polynomial(j)).collect();
    let f = DMatrix::from_fn(m + 1, m + 1, |i, j| {
        let v = polys[j].taylor_coefficient(i, &r);
        if i % 2 == 0 {
            v
        } else {
            -v
        }
    });
    let om = T::one() - theta.clone();
    let op = T::one() + theta;
    let a = DMatrix::from_fn(m + 1, m + 1, |l, k| {
        choose::<T>(l + k, l) * om.clone() / op.powi_u(l + k + 1)
    });
    Ok(congruence(&f, &a))
}

/// Converts a scaled covariance to unscaled derivatives: `D(τ) S D(τ)` (Morrison (9.7.4),
/// (13.6.22)).
///
/// ```
/// use seqsmooth::polynomial::vrf::unscale;
/// use nalgebra::DMatrix;
/// let s = unscale(&DMatrix::from_element(2, 2, 1.0), 0.5);
/// assert_eq!(s[(1, 1)], 4.0);
/// ```
pub fn unscale(s: &DMatrix<f64>, tau: f64) -> DMatrix<f64> {
    let d = scaling(s.nrows() - 1, tau);
    &d * s * &d
}

/// Morrison's Table 13.3 matrix `λ(m)`: the fading-memory covariance near `θ = 1`,
/// `[S]_ij ≈ σ² λ_ij (1-θ)^(i+j+1) / τ^(i+j)` for the unscaled derivatives, exactly
/// `λ = G B Gᵀ` with `[G]_ij = C(j,i)`, `[B]_ij = C(i+j,i)/2^(i+j+1)` (Ex. 13.15).
///
/// ```
/// use seqsmooth::polynomial::vrf::fading_vrf_limit;
/// use seqsmooth::scalar::parse_rational;
/// let l = fading_vrf_limit(2);
/// assert_eq!(l[(0, 0)], parse_rational("33/16").unwrap());
/// assert_eq!(l[(1, 2)], parse_rational("9/16").unwrap());
/// ```
pub fn fading_vrf_limit(m: usize) -> DMatrix<Rational> {
    let g = DMatrix::from_fn(m + 1, m + 1, |i, j| choose::<Rational>(j, i));
    let b = DMatrix::from_fn(m + 1, m + 1, |i, j| {
        choose::<Rational>(i + j, i) / Rational::from_i64(2).powi_u(i + j + 1)
    });
    congruence(&g, &b)
}

/// Morrison's Table 7.2 / 9.3 matrix `κ(m)`: the covariance of a least-squares fit over a long
/// window evaluated at its newest end, `[S]_ij ≈ σ² κ_ij / (L^(i+j+1) τ^(i+j))` for the unscaled
/// derivatives; exactly `κ = V H⁻¹ Vᵀ` with the Hilbert matrix `H_jk = 1/(j+k+1)` and
/// `V_ij = j^(i)` (the derivatives of `s^j` at `s = 1`).
///
/// ```
/// use seqsmooth::polynomial::vrf::fixed_memory_vrf_limit;
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
