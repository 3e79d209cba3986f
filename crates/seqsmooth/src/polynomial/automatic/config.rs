//! [`AutoConfig`]: every setting of the [`AutomaticFilter`](super::AutomaticFilter), with its
//! default and its check. The filter is configured by its builders
//! ([`AutomaticFilter::new`](super::AutomaticFilter::new) and the `with_*`
//! methods); [`AutomaticFilter::config`](super::AutomaticFilter::config) reads the settings back.

use super::misfit::MisfitResponse;
use super::noise::NoiseSource;
use super::outlier::OutlierRule;
use crate::error::{Error, Param};
use crate::polynomial::fading::switch::SwitchRule;
use crate::polynomial::options::{check_engine_degree, check_tau, check_theta};
use crate::polynomial::options::{DiscountMode, Engine};

/// The largest 1-step prediction VRF at which the outlier gate is applied (the default of
/// [`AutoConfig::gate_max_vrf`]: the prediction is at least as good as a sample).
///
/// ```
/// use seqsmooth::polynomial::automatic::{AutomaticFilter, GATE_MAX_VRF};
/// let f = AutomaticFilter::new(1, 0.9, 1.0).unwrap();
/// assert_eq!(f.config().gate_max_vrf, GATE_MAX_VRF);
/// ```
pub const GATE_MAX_VRF: f64 = 1.0;

/// The most shorter memories [`AutoConfig::memory_levels`] may ask for (the shortest would
/// discount by `θ^(4^8) = θ^65536`; a rung below `10⁻³` is dropped, so all 8 are built only for
/// `θ ≥ 0.999895`). It was 16 before 2026-12-07 (the ladder `θ^(2^j)` of then):
/// `with_memory_levels(9..=16)` is now refused, as is a state saved with such a setting.
///
/// ```
/// use seqsmooth::polynomial::automatic::{AutomaticFilter, MAX_MEMORY_LEVELS};
/// let f = AutomaticFilter::new(1, 0.9, 1.0).unwrap();
/// assert!(f.clone().with_memory_levels(MAX_MEMORY_LEVELS).is_ok());
/// assert!(f.with_memory_levels(MAX_MEMORY_LEVELS + 1).is_err());
/// ```
pub const MAX_MEMORY_LEVELS: usize = 8;

/// The largest [`AutoConfig::review_window`].
///
/// ```
/// use seqsmooth::polynomial::automatic::{AutomaticFilter, MAX_REVIEW_WINDOW};
/// let f = AutomaticFilter::new(2, 0.9, 1.0).unwrap();
/// assert!(f.clone().with_review_window(MAX_REVIEW_WINDOW).is_ok());
/// assert!(f.with_review_window(MAX_REVIEW_WINDOW + 1).is_err());
/// ```
pub const MAX_REVIEW_WINDOW: usize = 31;

/// Every setting of the [`AutomaticFilter`](super::AutomaticFilter), as its builders set them
/// (read with [`AutomaticFilter::config`](super::AutomaticFilter::config)).
///
/// ```
/// use seqsmooth::polynomial::automatic::{AutomaticFilter, OutlierRule};
/// use seqsmooth::polynomial::SwitchRule;
/// let f = AutomaticFilter::new(2, 0.97, 0.1) // degree 2, θ = 0.97 per 0.1 s
///     .unwrap()
///     .with_noise_sigma(5.0)
///     .unwrap()
///     .with_outlier_rule(OutlierRule::reyneke())
///     .unwrap()
///     .with_switch_rule(SwitchRule::ExactCrossover)
///     .unwrap()
///     .with_start_degree(1)
///     .unwrap();
/// assert_eq!((f.degree(), f.active_degree()), (2, 1));
/// let c = f.config();
/// assert_eq!((c.noise_sigma, c.outliers, c.misfit_window), (Some(5.0), OutlierRule::reyneke(), 10));
/// ```
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AutoConfig {
    /// Final degree `m ≤ MAX_DEGREE`.
    pub degree: usize,
    /// Discount `θ ∈ (0,1)` per `tau`.
    pub theta: f64,
    /// Nominal sampling interval `τ > 0` (the time unit of `θ`).
    pub tau: f64,
    /// Engine of every internal filter (default [`Engine::Exact`], right on irregular samples).
    pub engine: Engine,
    /// Discounting by time (default) or by sample.
    pub discount: DiscountMode,
    /// When the final-degree output moves from expanding to fading memory.
    pub switch_rule: SwitchRule,
    /// The measurement noise `σ > 0` if known; `None` to estimate it by `noise_source`.
    pub noise_sigma: Option<f64>,
    /// How `σ` is estimated when not given.
    pub noise_source: NoiseSource,
    /// The difference noise estimate leaves out a difference beyond `noise_screen · σ̂` and the
    /// `m + 1` after it, and corrects for the truncation
    /// ([`crate::stats::DifferenceNoise::with_screen`]): outliers the gate has not seen (before
    /// it is active) and glitches of the trend stay out of `σ̂`. Default 3; infinity: no screen.
    pub noise_screen: f64,
    /// Outlier gate.
    pub outliers: OutlierRule,
    /// The gate is applied only while the 1-step prediction VRF is at most this (default
    /// [`GATE_MAX_VRF`]).
    pub gate_max_vrf: f64,
    /// A run of this many consecutive rejections is a manoeuvre, applied after all (`0`: never).
    /// Default 3 (three consecutive outliers at a 2% outlier rate: 8·10⁻⁶ per sample).
    pub max_consecutive_rejections: usize,
    /// A run of this many consecutive rejections all on the same side of the prediction is a
    /// manoeuvre too (Morrison §14.8: repeated crossings on one side mean bias), applied after
    /// all (two outliers in a row on one side at a 2% outlier rate: 2·10⁻⁴ per sample, so 1% of
    /// the outliers would be taken); default 0: off (0 or 1: only `max_consecutive_rejections`
    /// counts); off too when that is 0.
    pub same_side_rejections: usize,
    /// The accepted samples `L` on each side of a sample by which its final outlier decision is
    /// made, by interpolation ([review](crate::polynomial::automatic), step 6); default `m + 4`; 0: the gate's decision.
    pub review_window: usize,
    /// Innovation chi-squared window `K ≥ 1` (default 10).
    pub misfit_window: usize,
    /// Per-sample false-alarm rate `α ∈ (0,1)` of the misfit test (default 0.01).
    pub misfit_alpha: f64,
    /// What the filter does when the model no longer fits (default: restart at α = 10⁻⁴).
    pub misfit_response: MisfitResponse,
    /// Shorter memories `θ⁴, θ¹⁶, …, θ^(4^J)` the final degree may use (`J`; default 1: `θ⁴`, a
    /// memory about a quarter as long; 0: only `θ`): for each prediction and estimate the memory
    /// of least estimated mean squared error `σ² V + b̂²` (Morrison §7.13, (13.9.28); see
    /// [`AutomaticFilter::memory`](super::AutomaticFilter::memory)). A rung with
    /// `θ^(4^j) < 10⁻³` (a memory of well under one sample) is not built, nor those below it:
    /// at the default 1 there is no shorter memory for `θ < 0.178`, and all
    /// [`MAX_MEMORY_LEVELS`] are built only for `θ ≥ 0.999895`. Before 2026-12-07 the ladder
    /// was `θ², θ⁴, θ⁸` (`θ^(2^j)`, default 3, at most 16): a filter restored from a state saved
    /// before 2026-12-07 keeps the memories it was saved with.
    pub memory_levels: usize,
    /// First degree of the quick-settling ladder, `≤ degree` (default 0; `degree` disables it).
    pub start_degree: usize,
    /// The candidate degree takes over once its current position VRF is at most this (default ½).
    pub settle_vrf: f64,
    /// … and its top derivative moved by less than its 1σ at each of this many updates (default 3).
    pub settle_stable: usize,
}

impl AutoConfig {
    /// The defaults for degree `m`, discount `θ` per nominal interval `τ` (unchecked:
    /// [`AutomaticFilter::new`](super::AutomaticFilter::new) checks them).
    pub(super) fn new(degree: usize, theta: f64, tau: f64) -> Self {
        Self {
            degree,
            theta,
            tau,
            engine: Engine::Exact,
            discount: DiscountMode::PerTime,
            switch_rule: SwitchRule::Position,
            noise_sigma: None,
            noise_source: NoiseSource::default(),
            noise_screen: 3.0,
            outliers: OutlierRule::default(),
            gate_max_vrf: GATE_MAX_VRF,
            max_consecutive_rejections: 3,
            same_side_rejections: 0,
            review_window: (degree + 4).min(MAX_REVIEW_WINDOW),
            misfit_window: 10,
            misfit_alpha: 0.01,
            misfit_response: MisfitResponse::default(),
            memory_levels: 1,
            start_degree: 0,
            settle_vrf: 0.5,
            settle_stable: 3,
        }
    }

    /// Checks every setting: a typed error for the first one out of range (degree, `θ`, `τ`,
    /// `σ`, noise window and screen, gate, restart significance, switch rule, ladder). The misfit window
    /// and `α` are checked by [`crate::stats::InnovationChiSquared::new`].
    pub(super) fn validate(&self) -> Result<(), Error> {
        check_engine_degree(self.degree, self.engine)?;
        check_theta(self.theta)?;
        check_tau(self.tau)?;
        if let Some(s) = self.noise_sigma {
            crate::polynomial::options::check_noise_sigma(s)?;
        }
        if self.noise_source.window() == Some(0) {
            return Err(Error::InvalidParameter {
                name: Param::NoiseWindow,
                value: "0".into(),
                reason: "must be at least 1".into(),
            });
        }
        if self.noise_screen.is_nan() || self.noise_screen <= 0.0 {
            return Err(Error::InvalidParameter {
                name: Param::NoiseScreen,
                value: self.noise_screen.to_string(),
                reason: "must be positive (infinity: no screen)".into(),
            });
        }
        if self.memory_levels > MAX_MEMORY_LEVELS {
            return Err(Error::InvalidParameter {
                name: Param::MemoryLevels,
                value: self.memory_levels.to_string(),
                reason: format!("must be at most {MAX_MEMORY_LEVELS}"),
            });
        }
        self.outliers.validate()?;
        if self.gate_max_vrf.is_nan() || self.gate_max_vrf <= 0.0 {
            return Err(Error::InvalidParameter {
                name: Param::GateVrfLimit,
                value: self.gate_max_vrf.to_string(),
                reason: "must be positive (infinity: always gate)".into(),
            });
        }
        let l = self.review_window;
        if l > MAX_REVIEW_WINDOW || (l > 0 && 2 * l < self.degree + 4) {
            return Err(Error::InvalidParameter {
                name: Param::ReviewWindow,
                value: l.to_string(),
                reason: format!(
                    "must be 0 (no review) or from {} to {MAX_REVIEW_WINDOW} at degree {}: the \
                     degree {} fit through 2L samples needs two to spare",
                    (self.degree + 5) / 2,
                    self.degree,
                    self.degree + 1
                ),
            });
        }
        self.misfit_response.validate()?;
        self.switch_rule.switch_index(self.degree, self.theta)?;
        if self.start_degree > self.degree {
            return Err(Error::InvalidParameter {
                name: Param::StartDegree,
                value: self.start_degree.to_string(),
                reason: format!("must be at most the degree {}", self.degree),
            });
        }
        check_positive(Param::SettleVrf, self.settle_vrf)
    }
}

/// `x` is a positive finite number, or an [`Error::InvalidParameter`] naming it.
pub(super) fn check_positive(name: Param, x: f64) -> Result<(), Error> {
    if x.is_finite() && x > 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidParameter {
            name,
            value: x.to_string(),
            reason: "must be a positive finite number".into(),
        })
    }
}
