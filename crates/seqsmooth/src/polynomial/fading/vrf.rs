//! The fading-memory variance-reduction matrices (Morrison (13.6.4), Tables 13.2-13.3).

use crate::basis::DiscreteLaguerre;
use crate::calculus::choose;
use crate::error::Error;
use crate::linalg::congruence;
use crate::polynomial::form::EstimateForm;
use crate::scalar::{Rational, Scalar};
use nalgebra::DMatrix;

/// Fading-memory variance-reduction matrix in the steady state, `S = F(r) A F(r)ᵀ` (Morrison
/// (13.6.15)-(13.6.20)) with `[F(r)]_ij = ((-1)^i/i!) dⁱp_j(r; θ)/drⁱ` and
/// `[A]_lk = C(l+k, l)(1-θ)/(1+θ)^(l+k+1)`; `r = 0` for the current estimate, `r = -1` for the
/// 1-step prediction. All terms are non-negative, so `f64` evaluation is accurate for all `θ`.
///
/// ```
/// use seqsmooth::polynomial::fading::vrf::fading_vrf;
/// use seqsmooth::polynomial::form::EstimateForm;
/// let s = fading_vrf(1, 0.9_f64, EstimateForm::Predictor).unwrap();
/// assert!((s[(0, 0)] - 0.137192010).abs() < 1e-9); // (13.7.1)
/// ```
pub fn fading_vrf<T: Scalar>(m: usize, theta: T, form: EstimateForm) -> Result<DMatrix<T>, Error> {
    crate::polynomial::options::check_theta_of(&theta)?;
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

/// Morrison's Table 13.3 matrix `λ(m)`: the fading-memory covariance near `θ = 1`,
/// `[S]_ij ≈ σ² λ_ij (1-θ)^(i+j+1) / τ^(i+j)` for the unscaled derivatives, exactly
/// `λ = G B Gᵀ` with `[G]_ij = C(j,i)`, `[B]_ij = C(i+j,i)/2^(i+j+1)` (Ex. 13.15).
///
/// ```
/// use seqsmooth::polynomial::fading::vrf::fading_vrf_limit;
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
