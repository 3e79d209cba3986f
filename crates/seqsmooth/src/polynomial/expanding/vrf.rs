//! The expanding-memory variance-reduction matrix (Morrison (9.7.2)-(9.7.4), Table 9.2): the
//! fixed-memory covariance of a window of `n+1` samples.

use crate::error::Error;
use crate::polynomial::form::EstimateForm;
use crate::scalar::Scalar;
use nalgebra::DMatrix;

/// Expanding-memory variance-reduction matrix at the 0-based index `n` of the newest sample
/// (`n+1` samples): Morrison §9.7, (9.7.1)-(9.7.4), Table 9.2 (the EMP at `n` is the fixed-memory
/// fit with `L = n`, so this is [`crate::polynomial::fixed::covariance`] at lead 0 or 1). Defined for `n ≥ m`.
///
/// ```
/// use seqsmooth::polynomial::expanding::vrf::expanding_vrf;
/// use seqsmooth::polynomial::form::EstimateForm;
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
    crate::polynomial::fixed::covariance(m, n, h)
}
