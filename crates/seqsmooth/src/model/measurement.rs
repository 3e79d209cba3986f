//! A measurement and the covariance of its errors: the types every estimator and filter of the
//! library takes (the batch estimates of ch. 6 and §8.2, Gauss–Newton of ch. 8 and 11, the Bayes
//! and Kalman filters of ch. 10 and 12). `Y_k` with `Cov(N_k) = R_k` (Morrison (6.2.x)).

use crate::error::{Error, Param};
use nalgebra::DMatrix;

/// Whether `sigma` can be a noise standard deviation: above 0 with a normal double square
/// (the variance `σ²`, `1.5e-154 ≲ σ ≲ 1.3e154`); below, the variance is zero or subnormal and
/// weighing by it is meaningless; above, it is infinite. The one rule of every σ the library,
/// the command and the Python package take.
///
/// ```
/// use seqsmooth::model::measurement::is_usable_sigma;
/// assert!(is_usable_sigma(0.5) && is_usable_sigma(1e150));
/// assert!(!is_usable_sigma(0.0) && !is_usable_sigma(1e-160) && !is_usable_sigma(1e160));
/// assert!(!is_usable_sigma(f64::NAN) && !is_usable_sigma(f64::INFINITY));
/// ```
pub fn is_usable_sigma(sigma: f64) -> bool {
    let variance = sigma * sigma;
    sigma > 0.0 && variance.is_finite() && variance >= f64::MIN_POSITIVE
}

/// The covariance `R` of the stacked observation errors.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum NoiseCovariance {
    /// `R = I`.
    Identity,
    /// `R = diag(σ_k²)`, one variance per observation, each positive and finite.
    Variances(Vec<f64>),
    /// A full symmetric positive definite `R`.
    Full(DMatrix<f64>),
}

/// One observation: its time, its components (`None` for a missing one: its row is dropped),
/// and the covariance of its errors (of all components; the missing ones' rows and columns are
/// dropped).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Measurement {
    /// The time `t_k`.
    pub time: f64,
    /// `Y_k`, one entry per component of the observation model.
    pub values: Vec<Option<f64>>,
    /// `R_k`: [`NoiseCovariance::Variances`] (one per component) or [`NoiseCovariance::Full`].
    pub noise: NoiseCovariance,
}

impl Measurement {
    /// The present components (indices into the observation's `p`) and their values, after
    /// the checks every estimator makes: a finite time, `p` values, each present one finite.
    ///
    /// ```
    /// use seqsmooth::model::measurement::NoiseCovariance;
    /// use seqsmooth::model::measurement::Measurement;
    /// let m = Measurement { time: 1.0, values: vec![Some(2.0), None, Some(4.0)], noise: NoiseCovariance::Identity };
    /// assert_eq!(m.present(3).unwrap(), (vec![0, 2], vec![2.0, 4.0]));
    /// assert!(m.present(2).is_err());
    /// ```
    pub fn present(&self, p: usize) -> Result<(Vec<usize>, Vec<f64>), Error> {
        if !self.time.is_finite() {
            return Err(Error::NonFinite {
                what: "time",
                value: self.time,
            });
        }
        if self.values.len() != p {
            return Err(Error::InvalidParameter {
                name: Param::Measurement,
                value: format!("with {} components", self.values.len()),
                reason: format!("the observation model has {p}"),
            });
        }
        let mut present = Vec::with_capacity(p);
        let mut values = Vec::with_capacity(p);
        for (k, v) in self.values.iter().enumerate() {
            if let Some(v) = *v {
                if !v.is_finite() {
                    return Err(Error::NonFinite {
                        what: "measured value",
                        value: v,
                    });
                }
                present.push(k);
                values.push(v);
            }
        }
        Ok((present, values))
    }
}
