//! The expanding-memory variance-reduction matrix (Morrison (9.7.2)-(9.7.4), Table 9.2): the
//! fixed-memory covariance of a window of `n+1` samples.

use crate::error::{Error, Param};
use crate::polynomial::form::EstimateForm;
use crate::scalar::Scalar;
use nalgebra::DMatrix;

/// The range of the newest sample's 0-based index `n` of an expanding-memory
/// variance-reduction matrix at degree `m`: `n ≥ m`, the `m + 1` samples a degree-`m` fit needs
/// (every front end's check, and [`expanding_vrf`]'s).
///
/// ```
/// use seqsmooth::polynomial::expanding::vrf::check_index;
/// assert!(check_index(3, 3).is_ok() && check_index(3, 2).is_err());
/// ```
pub fn check_index(m: usize, n: u64) -> Result<(), Error> {
    if n < m as u64 {
        return Err(Error::InvalidParameter {
            name: Param::NewestIndex,
            value: n.to_string(),
            reason: format!(
                "too small for degree {m}: the expanding-memory variance-reduction matrix needs \
                 n >= {m} (at least {} samples)",
                m + 1
            ),
        });
    }
    Ok(())
}

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
    check_index(m, n)?;
    let h = match form {
        EstimateForm::Current => T::zero(),
        EstimateForm::Predictor => T::one(),
    };
    crate::polynomial::fixed::covariance(m, n, h)
}
