//! [`PolynomialState`]: the value and derivatives of an estimate at an instant, with their
//! covariance, and its propagation `X(t+ζ) = Φ_X(ζ) X(t)` (Morrison (5.5.21)-(5.5.22)).

use super::transition::psi;
use crate::error::Error;
use nalgebra::{DMatrix, DVector};

/// A polynomial state: the value and derivatives `x^(0..=m)` of the estimated process at `time`,
/// in the caller's time units, with the covariance of their errors when known.
///
/// ```
/// use seqsmooth::model::PolynomialState;
/// let s = PolynomialState::new(0.0, vec![1.0, 2.0, 2.0]); // 1 + 2t + t²
/// let p = s.at(1.0);
/// assert_eq!(p.derivatives, vec![4.0, 4.0, 2.0]);
/// ```
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
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

    /// The state itself when every number of it (time, derivatives, covariance) is finite;
    /// else [`Error::EstimateOutOfRange`] naming the first that is not.
    ///
    /// ```
    /// use seqsmooth::{Error, PolynomialState};
    /// assert!(PolynomialState::new(0.0, vec![1.0, 2.0]).checked().is_ok());
    /// let e = PolynomialState::new(0.0, vec![1.0, f64::INFINITY]).checked().unwrap_err();
    /// assert!(matches!(e, Error::EstimateOutOfRange { what } if what == "d1"));
    /// ```
    pub fn checked(self) -> Result<Self, Error> {
        let out = |what: String| Err(Error::EstimateOutOfRange { what });
        if !self.time.is_finite() {
            return out("time".into());
        }
        if let Some(k) = self.derivatives.iter().position(|v| !v.is_finite()) {
            return out(format!("d{k}"));
        }
        if let Some(c) = &self.covariance {
            let p = c.nrows();
            if let Some(k) = c.iter().position(|v| !v.is_finite()) {
                let (i, j) = (k % p, k / p);
                return out(if i == j {
                    format!("variance of d{i}")
                } else {
                    format!("covariance of d{}, d{}", i.min(j), i.max(j))
                });
            }
        }
        Ok(self)
    }

    /// Degree `m` of the polynomial model.
    pub fn degree(&self) -> usize {
        self.derivatives.len().saturating_sub(1)
    }

    /// 1σ of each derivative, when the covariance is known.
    pub fn std_devs(&self) -> Option<Vec<f64>> {
        self.covariance.as_ref().map(crate::linalg::std_devs)
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
