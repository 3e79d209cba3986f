//! The radar tracks of the extended Kalman filter bench (`benches/kalman.rs`) and of the peer
//! comparison (`examples/peers.rs`, which writes them for `scripts/peers.py`'s filterpy
//! `ExtendedKalmanFilter`), so both time the same data. Included by path next to
//! `common/radar.rs` (`#[path = ...] mod radar; #[path = ...] mod kalman_tracks;`), whose
//! simulated windows it reuses.
//!
//! Track `w` is window `w` of [`radar::windows`] (a constant-velocity target, 60 measurements of
//! range, azimuth and elevation at steps `U(0.5, 1.5)` s, σ 10 m and 1 mrad): the filter starts
//! at the first measurement's time from that measurement alone, the position converted to
//! Cartesian with its first-order covariance (`Radar::to_cartesian`, Morrison (8.5.6)), the
//! velocity 0 with σ [`SIGMA_VELOCITY`] on each axis, and updates with the other 59. The
//! driving noise is white acceleration of spectral density [`Q`] on each axis
//! (`WhiteNoiseDerivative::new(1, 3, Q)`).

use crate::radar;
use nalgebra::{DMatrix, DVector, Matrix3};
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::kalman::KalmanFilter;
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::measurement::Measurement;
use seqsmooth::model::radar::Radar;

/// The driving noise's spectral density on each axis, m²/s³.
pub const Q: f64 = 1.0;
/// The prior's σ of each velocity component, m/s (the simulated speeds are 100-300 m/s).
pub const SIGMA_VELOCITY: f64 = 300.0;

/// One track: the prior at the first measurement's time and the measurements after it.
pub struct Track {
    /// The time of the prior (the first measurement's).
    pub time: f64,
    /// The prior state `(x, y, z, vx, vy, vz)`.
    pub state: DVector<f64>,
    /// The prior covariance.
    pub covariance: DMatrix<f64>,
    /// The measurements the filter updates with.
    pub measurements: Vec<Measurement>,
}

/// The first `count` tracks of `seed`.
pub fn tracks(seed: u64, count: usize) -> Vec<Track> {
    let (_, radar) = radar::models();
    let r = Matrix3::from_diagonal(
        &[
            radar::SIGMA_RANGE.powi(2),
            radar::SIGMA_ANGLE.powi(2),
            radar::SIGMA_ANGLE.powi(2),
        ]
        .into(),
    );
    radar::windows(seed, count)
        .iter()
        .map(|w| {
            let first = radar.to_cartesian(w.measured[0], &r).expect("a valid pass");
            let mut covariance = DMatrix::from_diagonal_element(6, 6, SIGMA_VELOCITY.powi(2));
            covariance
                .view_mut((0, 0), (3, 3))
                .copy_from(&first.covariance);
            let mut state = DVector::zeros(6);
            state.rows_mut(0, 3).copy_from(&first.position);
            Track {
                time: w.times[0],
                state,
                covariance,
                measurements: w.measurements().split_off(1),
            }
        })
        .collect()
}

impl Track {
    /// The extended Kalman filter at the prior: `PolynomialDynamics::new(1, 3)`, the radar at
    /// the origin, white-noise acceleration `Q`.
    pub fn filter(&self) -> KalmanFilter<PolynomialDynamics, Radar> {
        let (dynamics, radar) = radar::models();
        KalmanFilter::new(
            dynamics,
            radar,
            self.state.clone(),
            self.covariance.clone(),
            self.time,
        )
        .expect("a valid prior")
        .with_process_noise(WhiteNoiseDerivative::new(1, 3, Q).expect("q >= 0"))
        .expect("6 states")
    }
}
