//! Recursive filters over any dynamic and observation model (Morrison chs. 10, 12, 14, 15):
//! the Bayes filter in information form, and the Kalman filter, extended and iterated for
//! nonlinear models, with driving noise or fading memory, and its smoother.
//!
//! - [`bank`]: [`KalmanBank`](bank::KalmanBank), one linear model over many series, each
//!   with its own times and missing components, in structure of arrays on the rayon pool:
//!   the filter, the RTS and fixed-lag smoothers, and a streaming form.
//! - [`bayes`]: [`BayesFilter`], the Bayes filter (ch. 10) in square-root information form, the
//!   recursion of the exact polynomial engine over any linear model; it starts from nothing;
//!   with fading memory (ch. 14, [`Discount`]) it reports its true covariance.
//! - [`filter`]: [`KalmanFilter`], prediction, Joseph-form update, the iterated update, the
//!   generalized fading memory of ch. 14 ([`Discount`]), innovation statistics; its arithmetic
//!   on preallocated buffers (the covariance's prediction, one correction) in `correct`.
//! - [`discrete`]: [`LinearKalmanFilter`], the filter on a discrete-time linear model given by
//!   its matrices `F`, `H`, `Q`, `R`, `B u` (constant or one per step), its batch and smoothers;
//!   its batch with constant matrices at small sizes in `discrete_fixed` (the same numbers).
//! - [`smoother`]: the Rauch–Tung–Striebel fixed-interval smoother over a forward run, or
//!   over a forward pass already made ([`rts`]: gains and predicted covariances too).
//! - [`fixed_lag`]: the same smoother with a fixed lag: each measurement's estimate from the
//!   `L` after it, in memory bounded by `L`.
//! - [`steady`]: the fading filter's steady state (§14.7).
//! - [`sigma_points`]: the scaled unscented transform (Julier, Uhlmann; Wan, van der Merwe):
//!   the sigma points of a mean and covariance, their weights, and the weighted moments.
//! - [`unscented`]: [`UnscentedKalmanFilter`], the unscented Kalman filter over any
//!   [`Dynamics`](crate::model::dynamics::Dynamics) and
//!   [`Observation`](crate::model::observation::Observation), its predictions kept with their
//!   cross-covariances; [`unscented_smoother`], the unscented RTS smoother (Särkkä 2008) over
//!   them; [`unscented_fixed_lag`], the same with a fixed lag, in memory bounded by it.
//! - [`noise`]: the driving-noise covariance `Q` over a step (15.2.23), in closed form for the
//!   polynomial model ([`noise::WhiteNoiseDerivative`]), or given per step ([`noise::MatrixNoise`]).
//!
//! The radar tracking application over these filters is [`crate::track`].

mod backward;
pub mod bank;
pub mod bayes;
mod correct;
pub mod discrete;
mod discrete_fixed;
pub mod filter;
pub mod fixed_lag;
pub mod noise;
pub mod saved_noise;
pub mod sigma_points;
pub mod smoother;
pub mod steady;
pub mod unscented;
pub mod unscented_fixed_lag;
pub mod unscented_smoother;

pub use crate::discount::Discount;
pub use bayes::BayesFilter;
pub use discrete::LinearKalmanFilter;
pub use filter::{Innovation, KalmanFilter};
pub use fixed_lag::FixedLagSmoother;
pub use smoother::{rts, smooth, RtsStep, Smoothed, Smoother};
pub use unscented::UnscentedKalmanFilter;
pub use unscented_fixed_lag::UnscentedFixedLagSmoother;
pub use unscented_smoother::{smooth_unscented, UnscentedSmoother};
