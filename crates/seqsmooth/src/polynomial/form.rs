//! Which estimate a gain vector or a variance-reduction matrix belongs to (current or 1-step
//! prediction), shared by the expanding- and fading-memory formulas, and the conversion of a
//! scaled covariance to unscaled derivatives.

use crate::model::{phi, scaling};
use crate::scalar::Scalar;
use nalgebra::DMatrix;

/// Which recursion the gain vector belongs to.
///
/// ```
/// use seqsmooth::polynomial::gains::{expanding_gains, GainForm};
/// let h: Vec<f64> = expanding_gains(1, 3, GainForm::Current);
/// let p: Vec<f64> = expanding_gains(1, 3, GainForm::Predictor);
/// assert_eq!(h, vec![0.7, 0.3]);                      // Morrison T9-01
/// assert!((p[0] - 1.0).abs() < 1e-15 && (p[1] - 0.3).abs() < 1e-15); // Φ(1) H
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum GainForm {
    /// `Z*_{n,n} = Z*_{n,n-1} + H ε_n` (current estimate; Tables 9.1, 13.1 gains).
    #[default]
    Current,
    /// `Z*_{n+1,n} = Φ(1) Z*_{n,n-1} + Φ(1) H ε_n` (1-step predictor; gain `Φ(1) H`).
    Predictor,
}

pub(crate) fn apply_form<T: Scalar>(m: usize, h: Vec<T>, form: GainForm) -> Vec<T> {
    match form {
        GainForm::Current => h,
        GainForm::Predictor => {
            let p = phi(m, T::one());
            (0..=m)
                .map(|i| (i..=m).fold(T::zero(), |acc, j| acc + p[(i, j)].clone() * h[j].clone()))
                .collect()
        }
    }
}

/// Which estimate a variance-reduction matrix describes.
///
/// ```
/// use seqsmooth::polynomial::vrf::{expanding_vrf, EstimateForm};
/// let cur = expanding_vrf::<f64>(0, 3, EstimateForm::Current).unwrap();
/// let pred = expanding_vrf::<f64>(0, 3, EstimateForm::Predictor).unwrap();
/// assert!((cur[(0, 0)] - 0.25).abs() < 1e-15 && (pred[(0, 0)] - 0.25).abs() < 1e-15); // the mean of 4
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum EstimateForm {
    /// `Z*_{n,n}`: valid at the newest sample.
    #[default]
    Current,
    /// `Z*_{n+1,n}`: the 1-step prediction.
    Predictor,
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
