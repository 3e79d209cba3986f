//! Recursive filters over any dynamic and observation model (Morrison chs. 12 and 15): the
//! Kalman filter, extended for nonlinear models, with or without driving noise.
//!
//! - [`filter`]: [`KalmanFilter`], prediction, Joseph-form update, innovation statistics.
//! - [`noise`]: the driving-noise covariance `Q` over a step (15.2.23), in closed form for the
//!   polynomial model ([`noise::WhiteNoiseDerivative`]).

pub mod filter;
pub mod noise;

pub use filter::{Innovation, KalmanFilter};
