//! The statistics the automatic filter steers by: chi-squared helpers, the windowed innovation
//! test for systematic errors, measurement-noise estimators and a running variance.
//!
//! - [`chi_squared_cdf`], [`chi_squared_sf`], [`chi_squared_quantile`], [`ChiSquaredTest`]:
//!   Morrison §5.6 (a quadratic form of a Gaussian vector in its inverse covariance is
//!   chi-squared, (5.6.12)); [`normal_quantile`], [`two_sided_tail`], [`two_sided_threshold`]
//!   for `k`-sigma gates.
//! - [`InnovationChiSquared`]: Morrison §14.8 — the normalised innovations `ν_n²/σ_ε²`,
//!   `σ_ε² = σ²(1 + VRF of the 1-step prediction)` (14.8.4)-(14.8.5), summed over a sliding window
//!   of `K` samples and compared with the `(1-α)` quantile of `χ²_K`; repeated crossings mean
//!   the model no longer fits.
//! - Noise: Reyneke's eq. 39 as printed ([`reyneke_eq39_variance`]) and `stdd`/`stddw`
//!   (App. A.5), both biased by a trend; the bias-free `k`-th difference estimator
//!   ([`difference_variance`], and [`DifferenceNoise`] on irregular timestamps, running or
//!   windowed); residual-based [`residual_variance`] (Morrison (6.10.24)).
//! - Reyneke et al.'s §7.1 goodness of fit ([`goodness_of_fit()`], [`reyneke_gof_limit`]) and its
//!   reading as Morrison's χ² test of a window's residuals ([`gof_mean`], [`gof_threshold`],
//!   [`gof_false_alarm_rate`]).
//! - [`Welford`]: running mean and variance.
//! - [`consistency`]: NEES against a known truth and the chi-squared interval of the mean NEES
//!   or NIS over many runs (a filter's run-time consistency check).
//!
//! ```
//! use seqsmooth::stats::{difference_variance, reyneke_eq39_variance};
//! // a steep ramp with a ±1 alternating pattern (variance-1 "noise")
//! let y: Vec<f64> = (0..1000).map(|n| 0.5 * n as f64 + if n % 2 == 0 { 1.0 } else { -1.0 }).collect();
//! let biased = reyneke_eq39_variance(&y).unwrap();
//! let clean = difference_variance(&y, 2).unwrap();
//! assert!(biased > 2.0);                 // slope bias on top of the pattern
//! assert!((clean - 16.0 / 6.0).abs() < 0.01); // ∇²(±1) = ±4: 16/C(4,2), no slope term
//! ```

pub mod chi_squared;
pub mod consistency;
pub mod goodness_of_fit;
pub mod innovation;
pub mod noise;
pub mod welford;
mod window;

pub use chi_squared::{
    chi_squared_cdf, chi_squared_quantile, chi_squared_sf, normal_quantile, two_sided_tail,
    two_sided_threshold, ChiSquaredTest,
};
pub use goodness_of_fit::{
    gof_false_alarm_rate, gof_mean, gof_threshold, goodness_of_fit, reyneke_gof_limit,
};
pub use innovation::{ChiSquaredOutcome, InnovationChiSquared};
pub use noise::{
    difference_variance, normalised_divided_difference, residual_variance, reyneke_eq39_variance,
    reyneke_stdd, reyneke_stddw, DifferenceNoise, MAX_DIFFERENCE_ORDER,
};
pub use welford::Welford;
