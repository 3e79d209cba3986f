//! Recursive filters over any dynamic and observation model (Morrison chs. 12 and 15): the
//! Kalman filter, extended for nonlinear models, with or without driving noise.
//!
//! - [`filter`]: [`KalmanFilter`], prediction, Joseph-form update, the iterated update, the
//!   generalized fading memory of ch. 14 ([`Discount`]), innovation statistics.
//! - [`smoother`]: the Rauch–Tung–Striebel fixed-interval smoother over a forward run.
//! - [`noise`]: the driving-noise covariance `Q` over a step (15.2.23), in closed form for the
//!   polynomial model ([`noise::WhiteNoiseDerivative`]).

pub mod filter;
pub mod noise;
pub mod smoother;

pub use filter::{Discount, Innovation, KalmanFilter};
pub use smoother::{smooth, Smoothed};
