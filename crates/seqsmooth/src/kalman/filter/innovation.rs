//! What one update of the Kalman filter saw: its innovation `ν = Y − G(X_{n,n−1})`, the
//! innovation's covariance `V = M S_{n,n−1} Mᵀ + R`, the gain, the normalised innovation squared
//! (χ² with as many degrees of freedom as components when the model holds, Morrison §14.8) and
//! the Gaussian log-likelihood.

use nalgebra::{DMatrix, DVector};

/// What one update saw: the innovation and its statistics.
#[derive(Clone, Debug, PartialEq)]
pub struct Innovation {
    /// The components used (the present ones), in the observation's order.
    pub components: Vec<usize>,
    /// `ν = Y − G(X_{n,n−1})` on those components (an angle's wrapped).
    pub innovation: DVector<f64>,
    /// `V = M S_{n,n−1} Mᵀ + R`.
    pub covariance: DMatrix<f64>,
    /// The gain `H = S_{n,n−1} Mᵀ V⁻¹`, states × components.
    pub gain: DMatrix<f64>,
    /// `νᵀ V⁻¹ ν`.
    pub nis: f64,
    /// `−(NIS + ln det V + p ln 2π)/2`.
    pub log_likelihood: f64,
}

/// What one update saw, in numbers only: an [`Innovation`] without its vectors and matrices,
/// what [`super::KalmanFilter::update_stats`] returns.
///
/// ```
/// use seqsmooth::kalman::filter::InnovationStats;
/// let s = InnovationStats { components: 1, nis: 0.5, log_likelihood: -1.0 };
/// assert_eq!(s, s.clone());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InnovationStats {
    /// The number of components used (the present ones).
    pub components: usize,
    /// `νᵀ V⁻¹ ν`.
    pub nis: f64,
    /// `−(NIS + ln det V + p ln 2π)/2`.
    pub log_likelihood: f64,
}
