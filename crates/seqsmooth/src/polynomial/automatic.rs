//! The automatic polynomial filter: a fading-memory filter that starts itself, settles its
//! degree, estimates its noise, rejects outliers and says when its model no longer fits
//! (Morrison §13.8, §14.8; Reyneke et al. §7.2-7.4).
//!
//! Per sample `(t, y)` ([`AutomaticFilter::update`]):
//!
//! 1. **Prediction and innovation.** The active filter predicts `ŷ(t)` with its own covariance;
//!    the innovation `ν = y − ŷ(t)` has variance `σ_ε² = σ²(1 + v)`, `v` the 1-step prediction's
//!    position VRF (Morrison (14.8.4)); `σ` is the given noise or its running estimate.
//! 2. **Outlier gate** ([`OutlierRule`]): Morrison's `|ν| > k σ_ε` (default `k = 3`, false-alarm
//!    rate `P(|Z| > 3) = 0.27%`), or Reyneke's `|ν| > k σ (1 + √(2/N))` (§7.4). A rejected sample
//!    does not touch the state — the estimate is the prediction across it — and is flagged
//!    [`AutoOutput::outlier`]. A run of [`AutoConfig::max_consecutive_rejections`] rejections is
//!    taken for a manoeuvre, not outliers: the run is applied after all (in order), and the
//!    misfit flag goes up. The gate is active only at the final degree, once `σ` is known and the
//!    prediction VRF `v ≤` [`AutoConfig::gate_max_vrf`] (default 1: the prediction is at least
//!    as good as a sample; Reyneke's rule, which ignores `v`, needs this to keep its false-alarm
//!    rate down, see [`REYNEKE_DEFAULT_K`]).
//! 3. **Misfit** ([`crate::stats::InnovationChiSquared`], Morrison §14.8): the normalised squared
//!    innovations `ν²/σ_ε²` of accepted samples, summed over a sliding window of `K` samples, are
//!    `χ²_K` while the model fits; [`AutoOutput::misfit`] is up while the sum exceeds its
//!    `(1-α)` quantile (defaults `K = 10`, `α = 0.01`). The response ([`MisfitResponse`],
//!    Morrison: "β can be temporarily reduced until the threshold crossings cease"): by default
//!    the final-degree memory is restarted from the samples since the estimated onset when the
//!    same window sum passes the stricter `(1-10⁻⁴)` quantile, and grows back through the
//!    expanding start; or the flag is only raised ([`MisfitResponse::Flag`]), and the memory
//!    carries the manoeuvre's bias until it fades (about two memory lengths).
//! 4. **Update** of every filter the automatic filter runs, with the accepted sample:
//!    - **Quick-settling degree ladder** (Reyneke §7.3): expanding-memory filters of degrees
//!      `d₀ … m` (default `d₀ = 0`) run in tandem from the first sample; the active degree `d`
//!      steps up to `d+1` once the candidate's current position VRF is at most
//!      [`AutoConfig::settle_vrf`] (default ½) and its top derivative has changed by less than its
//!      own 1σ at each of the last [`AutoConfig::settle_stable`] updates (default 3); it steps up
//!      at once when the active degree's misfit flag goes up (the lower degree does not fit). The
//!      misfit window restarts at each step.
//!    - **Expanding → fading memory** (Morrison §13.8; Reyneke §7.2, Table 1): at the final
//!      degree `m` the expanding-memory filter is used until the sample index chosen by the
//!      [`SwitchRule`] (default [`SwitchRule::Position`], `n = ⌊c_0m/(1-θ)⌋`), and the
//!      fading-memory filter from then on. The rules count samples, so with
//!      [`DiscountMode::PerTime`] they use the discount per sample `θ^ζ̄`, `ζ̄` the mean step so far
//!      in units of `τ`, re-evaluated at each sample until the switch — as the gain engine of
//!      [`FadingMemory`] does. Indices count *accepted* samples. With the default
//!      [`Engine::Exact`] the fading-memory filter is exact discounted least squares over all
//!      accepted samples (weights `θ^((t_n−t_k)/τ)`), run in tandem from the first sample, so
//!      there is no start-up transient; the expanding start is used because its variance is the
//!      lower one until the crossover.
//! 5. **Noise** ([`NoiseSource`]): a given `σ`, or (default) the running estimate from the
//!    normalised `(m+1)`-th divided differences of the accepted samples
//!    ([`crate::stats::DifferenceNoise`]): unbiased for white noise about any polynomial of
//!    degree `≤ m` on any timestamps; biased upward by the trend's `(m+1)`-th derivative
//!    (`E{d²} = σ² + b²`, `b ≈ x^(m+1) Δt^(m+1)/√C(2m+2,m+1)` — negligible unless the samples
//!    are sparse on the manoeuvre's time scale) and by outliers that pass the gate (each
//!    contributes `a²/N` to `σ̂²` for an outlier of size `a`; before the gate is active all samples
//!    pass). The gate truncates the noise of the samples it passes (for `k = 3`, `σ̂` would be
//!    1.4% low); each gated sample enters with its expected truncated variance
//!    `σ²(c(a) + v)/(1 + v)`, `c(a)` the variance of a unit Gaussian cut at `±a = ±g/σ_ε`, which
//!    removes that bias. Alternatively the innovations of the final-degree filter
//!    ([`NoiseSource::Innovations`]): `σ̂² = mean(ν²/(1+v))`, corrected for the gate's truncation;
//!    without gating and before the switch it equals the expanding-memory fit's residual
//!    variance `e°/(N−m−1)` (Morrison (6.10.24)) exactly, but every unmodelled manoeuvre inflates
//!    it (by the squared bias of the predictions).
//!
//! Every filter inside tracks its covariance for unit noise (the VRF); the reported covariance
//! is `σ²` times it, with the given or the estimated `σ`.
//!
//! ```
//! use seqsmooth::polynomial::automatic::{AutomaticFilter, AutoConfig};
//! let mut config = AutoConfig::new(1, 0.9, 1.0);
//! config.noise_sigma = Some(0.1);
//! let mut f = AutomaticFilter::new(config).unwrap();
//! let mut flagged = Vec::new();
//! for n in 0..200 {
//!     let t = n as f64;
//!     let noise = 0.1 * (((n * 37 + 11) % 17) as f64 / 8.0 - 1.0); // a bounded "noise"
//!     let y = 2.0 + 0.5 * t + noise + if n == 120 { 5.0 } else { 0.0 };
//!     let out = f.update(t, y).unwrap();
//!     if out.outlier { flagged.push(n); }
//! }
//! assert_eq!(flagged, vec![120]);                 // the 50σ spike, and nothing else
//! assert_eq!(f.switched_at(), Some(32));          // Morrison (13.8.8): m = 1, θ = 0.9 → 32
//! let s = f.estimate().unwrap();
//! assert!((s.derivatives[1] - 0.5).abs() < 0.01);
//! ```

use super::switching::{memory_length_constant, SwitchRule};
use super::vrf::{expanding_vrf, fading_vrf, EstimateForm};
use super::{DiscountMode, Engine, ExpandingMemory, FadingMemory, PolynomialFilter, MAX_DEGREE};
use crate::error::Error;
use crate::model::PolynomialState;
use crate::stats::{two_sided_tail, ChiSquaredOutcome, DifferenceNoise, InnovationChiSquared};
use std::collections::VecDeque;

/// Morrison's gate multiplier: `|ν| > 3 σ_ε` (Reyneke §7.4 citing Morrison).
pub const MORRISON_K: f64 = 3.0;

/// The default multiplier for Reyneke's rule `|ν| > k σ (1 + √(2/N))`. As printed (`k = 1`) the
/// rule rejects 10-30% of good samples (others.md §4.7: 0.10 at `N = 5` to 0.25 at `N = 100`).
/// With `k = 3` and the gate active only where the prediction VRF is at most 1 (the default
/// [`AutoConfig::gate_max_vrf`]), the per-sample
/// false-alarm rate on Gaussian noise is at most 0.21% at degree 0 and 1, 0.35% at 2, 0.64% at
/// 3, 0.91% at 4 (worst case over every sample count of the expanding start and every θ of the
/// fading memory; 1.13% at degree 5 — use the innovation gate there). Asserted in
/// `tests/automatic.rs`.
pub const REYNEKE_DEFAULT_K: f64 = 3.0;

/// The largest 1-step prediction VRF at which the outlier gate is applied.
pub const GATE_MAX_VRF: f64 = 1.0;

/// Noise terms needed before an estimated `σ` is used.
pub const MIN_NOISE_TERMS: usize = 5;

/// How an innovation is judged an outlier.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum OutlierRule {
    /// No gating: every sample updates the filter.
    Off,
    /// Morrison's rule on the innovation: reject when `|ν| > k σ_ε`, `σ_ε² = σ²(1 + v)` with `v`
    /// the filter's own 1-step prediction position VRF. False-alarm rate `P(|Z| > k)` exactly for
    /// Gaussian noise and a fitting model (`k = 3`: 0.27%).
    Innovation {
        /// The multiplier `k > 0` (Morrison: 3).
        k: f64,
    },
    /// Reyneke's rule (§7.4): reject when `|ν| > k σ (1 + √(2/N))`, `N` the memory length (the
    /// sample count while expanding; `c_0m/(1-θ_s)`, the equivalent fixed-memory length, when
    /// fading). Printed with `k = 1`; see [`REYNEKE_DEFAULT_K`].
    Reyneke {
        /// The multiplier `k > 0`.
        k: f64,
    },
}

impl Default for OutlierRule {
    fn default() -> Self {
        OutlierRule::Innovation { k: MORRISON_K }
    }
}

impl OutlierRule {
    /// Morrison's `3σ_ε` gate.
    pub fn morrison() -> Self {
        OutlierRule::Innovation { k: MORRISON_K }
    }

    /// Reyneke's gate with the default multiplier [`REYNEKE_DEFAULT_K`].
    pub fn reyneke() -> Self {
        OutlierRule::Reyneke {
            k: REYNEKE_DEFAULT_K,
        }
    }

    /// The gate half-width for noise `σ`, prediction VRF `v` and memory length `N`, or `None`
    /// for [`OutlierRule::Off`].
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::OutlierRule;
    /// let g = OutlierRule::morrison().threshold(2.0, 0.21, 40.0).unwrap();
    /// assert!((g - 3.0 * 2.0 * 1.1).abs() < 1e-12);
    /// let r = OutlierRule::Reyneke { k: 1.0 }.threshold(2.0, 0.21, 50.0).unwrap();
    /// assert!((r - 2.0 * 1.2).abs() < 1e-12);
    /// ```
    pub fn threshold(&self, sigma: f64, vrf: f64, memory: f64) -> Option<f64> {
        match *self {
            OutlierRule::Off => None,
            OutlierRule::Innovation { k } => Some(k * sigma * (1.0 + vrf).sqrt()),
            OutlierRule::Reyneke { k } => Some(k * sigma * (1.0 + (2.0 / memory).sqrt())),
        }
    }

    /// The per-sample false-alarm rate of the gate on Gaussian innovations of variance
    /// `σ²(1 + v)`: `P(|Z| > threshold/σ_ε)`.
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::OutlierRule;
    /// // Reyneke as printed, N = 100, small VRF: about a quarter of good samples rejected
    /// let p = OutlierRule::Reyneke { k: 1.0 }.false_alarm_rate(0.01, 100.0).unwrap();
    /// assert!((p - 0.25).abs() < 0.01);
    /// ```
    pub fn false_alarm_rate(&self, vrf: f64, memory: f64) -> Option<f64> {
        let g = self.threshold(1.0, vrf, memory)?;
        two_sided_tail(g / (1.0 + vrf).sqrt()).ok()
    }

    fn validate(&self) -> Result<(), Error> {
        match *self {
            OutlierRule::Off => Ok(()),
            OutlierRule::Innovation { k } | OutlierRule::Reyneke { k } => {
                if k.is_finite() && k > 0.0 {
                    Ok(())
                } else {
                    Err(Error::InvalidParameter {
                        name: "outlier gate multiplier",
                        value: k.to_string(),
                        reason: "must be a positive finite number".into(),
                    })
                }
            }
        }
    }
}

/// What the filter does when its innovations say the model no longer fits (Morrison §14.8).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MisfitResponse {
    /// Raise [`AutoOutput::misfit`] only: the memory keeps the unmodelled manoeuvre until it
    /// fades (about two memory lengths `c_0m/(1-θ)` for the bias to fall below 1% of its peak).
    Flag,
    /// Also restart the final-degree memory when the same window sum exceeds the `(1-alpha)`
    /// quantile of `χ²_K` (a stricter test than the flag's), or a run of rejections is taken for
    /// a manoeuvre: the filters are rebuilt from the samples since the estimated onset (the
    /// suffix of the window with the largest CUSUM `Σ(ν²/σ_ε² − 3)`, at least `m+1` samples) and
    /// grow back through the expanding-memory start and the switch. Morrison's response — "β can
    /// be temporarily reduced until the threshold crossings cease … then the memory can again be
    /// lengthened" — in its limit `θ → 0`, then back to `θ`. The default, with `alpha = 10⁻⁴`
    /// (on a fitting model about one false restart per 10⁴ samples).
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::{AutoConfig, AutomaticFilter, MisfitResponse};
    /// let mut c = AutoConfig::new(1, 0.95, 1.0);
    /// c.noise_sigma = Some(0.1);
    /// assert_eq!(c.misfit_response, MisfitResponse::Restart { alpha: 1e-4 });
    /// let mut f = AutomaticFilter::new(c).unwrap();
    /// let mut first_restart = None;
    /// for n in 0..300 {
    ///     let t = n as f64;
    ///     let noise = 0.1 * (((n * 37 + 11) % 17) as f64 / 8.0 - 1.0);
    ///     // a ramp that turns into a parabola at t = 200 (unmodelled by degree 1)
    ///     let y = 0.5 * t + if t > 200.0 { 0.05 * (t - 200.0).powi(2) } else { 0.0 } + noise;
    ///     if f.update(t, y).unwrap().restart { first_restart.get_or_insert(n); }
    /// }
    /// let n = first_restart.unwrap();
    /// assert!(n > 200 && n <= 210);
    /// ```
    Restart {
        /// Per-sample false-alarm rate `∈ (0,1)` of the restart test.
        alpha: f64,
    },
}

impl Default for MisfitResponse {
    fn default() -> Self {
        MisfitResponse::Restart { alpha: 1e-4 }
    }
}

/// Where the noise `σ` comes from when it is not given.
///
/// ```
/// use seqsmooth::polynomial::automatic::{AutoConfig, AutomaticFilter, NoiseSource};
/// let mut c = AutoConfig::new(2, 0.95, 1.0);
/// assert_eq!(c.noise_source, NoiseSource::Differences { window: None });
/// c.noise_source = NoiseSource::Innovations { window: Some(200) };
/// let mut f = AutomaticFilter::new(c).unwrap();
/// for n in 0..100 {
///     let t = n as f64;
///     f.update(t, 1.0 + t * t + if n % 2 == 0 { 0.5 } else { -0.5 }).unwrap();
/// }
/// assert!(f.noise_sigma().unwrap() > 0.4); // the ±0.5 pattern, the parabola is modelled
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NoiseSource {
    /// Normalised `(m+1)`-th divided differences of the accepted samples
    /// ([`crate::stats::DifferenceNoise`]), over the last `window` differences or all of them.
    /// Model-free, unbiased on any degree-`m` trend. The default (cumulative).
    Differences {
        /// Sliding window length in differences; `None` for all.
        window: Option<usize>,
    },
    /// Normalised innovations `ν²/(1+v)` of the final-degree filter (expanding, then fading),
    /// over the last `window` accepted samples or all; corrected for the gate's truncation.
    /// Inflated by unmodelled manoeuvres.
    Innovations {
        /// Sliding window length in samples; `None` for all.
        window: Option<usize>,
    },
}

impl Default for NoiseSource {
    fn default() -> Self {
        NoiseSource::Differences { window: None }
    }
}

/// Everything the [`AutomaticFilter`] can be told. Build with [`AutoConfig::new`] and change the
/// public fields; [`AutomaticFilter::new`] validates them.
///
/// ```
/// use seqsmooth::polynomial::automatic::{AutoConfig, AutomaticFilter, OutlierRule};
/// use seqsmooth::polynomial::SwitchRule;
/// let mut c = AutoConfig::new(2, 0.97, 0.1); // degree 2, θ = 0.97 per 0.1 s
/// c.noise_sigma = Some(5.0);
/// c.outliers = OutlierRule::reyneke();
/// c.switch_rule = SwitchRule::ExactCrossover;
/// c.start_degree = 1;
/// let f = AutomaticFilter::new(c).unwrap();
/// assert_eq!((f.degree(), f.active_degree()), (2, 1));
/// ```
#[derive(Clone, Debug, PartialEq)]
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
    /// Outlier gate.
    pub outliers: OutlierRule,
    /// The gate is applied only while the 1-step prediction VRF is at most this (default
    /// [`GATE_MAX_VRF`]).
    pub gate_max_vrf: f64,
    /// A run of this many consecutive rejections is a manoeuvre, applied after all (`0`: never).
    /// Default 3 (three consecutive outliers at a 2% outlier rate: 8·10⁻⁶ per sample).
    pub max_consecutive_rejections: usize,
    /// Innovation chi-squared window `K ≥ 1` (default 10).
    pub misfit_window: usize,
    /// Per-sample false-alarm rate `α ∈ (0,1)` of the misfit test (default 0.01).
    pub misfit_alpha: f64,
    /// What the filter does when the model no longer fits (default: restart at α = 10⁻⁴).
    pub misfit_response: MisfitResponse,
    /// First degree of the quick-settling ladder, `≤ degree` (default 0; `degree` disables it).
    pub start_degree: usize,
    /// The candidate degree takes over once its current position VRF is at most this (default ½).
    pub settle_vrf: f64,
    /// … and its top derivative moved by less than its 1σ at each of this many updates (default 3).
    pub settle_stable: usize,
}

impl AutoConfig {
    /// The defaults for degree `m`, discount `θ` per nominal interval `τ`.
    pub fn new(degree: usize, theta: f64, tau: f64) -> Self {
        Self {
            degree,
            theta,
            tau,
            engine: Engine::Exact,
            discount: DiscountMode::PerTime,
            switch_rule: SwitchRule::Position,
            noise_sigma: None,
            noise_source: NoiseSource::default(),
            outliers: OutlierRule::default(),
            gate_max_vrf: GATE_MAX_VRF,
            max_consecutive_rejections: 3,
            misfit_window: 10,
            misfit_alpha: 0.01,
            misfit_response: MisfitResponse::default(),
            start_degree: 0,
            settle_vrf: 0.5,
            settle_stable: 3,
        }
    }

    fn validate(&self) -> Result<(), Error> {
        if self.degree > MAX_DEGREE {
            return Err(Error::DegreeOutOfRange {
                degree: self.degree,
                max: MAX_DEGREE,
            });
        }
        if !(self.theta > 0.0 && self.theta < 1.0) {
            return Err(Error::ThetaOutOfRange { theta: self.theta });
        }
        if !(self.tau.is_finite() && self.tau > 0.0) {
            return Err(Error::TauOutOfRange { tau: self.tau });
        }
        if let Some(s) = self.noise_sigma {
            if !(s.is_finite() && s > 0.0) {
                return Err(Error::InvalidParameter {
                    name: "noise sigma",
                    value: s.to_string(),
                    reason: "must be a positive finite number".into(),
                });
            }
        }
        let window = match self.noise_source {
            NoiseSource::Differences { window } | NoiseSource::Innovations { window } => window,
        };
        if window == Some(0) {
            return Err(Error::InvalidParameter {
                name: "noise window",
                value: "0".into(),
                reason: "must be at least 1".into(),
            });
        }
        self.outliers.validate()?;
        if self.gate_max_vrf.is_nan() || self.gate_max_vrf <= 0.0 {
            return Err(Error::InvalidParameter {
                name: "gate VRF limit",
                value: self.gate_max_vrf.to_string(),
                reason: "must be positive (infinity: always gate)".into(),
            });
        }
        if let MisfitResponse::Restart { alpha } = self.misfit_response {
            if !(alpha > 0.0 && alpha < 1.0) {
                return Err(Error::InvalidParameter {
                    name: "restart significance",
                    value: alpha.to_string(),
                    reason: "must lie strictly between 0 and 1".into(),
                });
            }
        }
        self.switch_rule.switch_index(self.degree, self.theta)?;
        if self.start_degree > self.degree {
            return Err(Error::InvalidParameter {
                name: "start degree",
                value: self.start_degree.to_string(),
                reason: format!("must be at most the degree {}", self.degree),
            });
        }
        if !(self.settle_vrf.is_finite() && self.settle_vrf > 0.0) {
            return Err(Error::InvalidParameter {
                name: "settle VRF",
                value: self.settle_vrf.to_string(),
                reason: "must be a positive finite number".into(),
            });
        }
        // The misfit window and α are checked by InnovationChiSquared::new.
        Ok(())
    }
}

/// Which filter produced an output.
///
/// ```
/// use seqsmooth::polynomial::automatic::{AutoConfig, AutomaticFilter, Phase};
/// let mut c = AutoConfig::new(1, 0.8, 1.0);
/// c.noise_sigma = Some(1.0);
/// let mut f = AutomaticFilter::new(c).unwrap();
/// let phases: Vec<Phase> = (0..30).map(|n| f.update(n as f64, 2.0 * n as f64).unwrap().phase).collect();
/// assert_eq!(phases[0], Phase::Settling);            // degree 0 first
/// assert_eq!(phases[29], Phase::Fading);             // switched at ⌊3.2/0.2⌋ = 16
/// assert_eq!(f.switched_at(), Some(16));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// A lower degree of the quick-settling ladder (expanding memory).
    Settling,
    /// The final degree, expanding memory (before the switch).
    Expanding,
    /// The final degree, fading memory.
    Fading,
}

/// The result of one [`AutomaticFilter::update`].
///
/// ```
/// use seqsmooth::polynomial::automatic::{AutoConfig, AutomaticFilter};
/// let mut c = AutoConfig::new(1, 0.9, 1.0);
/// c.noise_sigma = Some(0.5);
/// let mut f = AutomaticFilter::new(c).unwrap();
/// let mut out = None;
/// for n in 0..50 {
///     out = Some(f.update(n as f64, 1.0 + 0.1 * n as f64).unwrap());
/// }
/// let out = out.unwrap();
/// let x = out.derivatives().unwrap();                 // [x, x']
/// let sd = out.std_devs().unwrap();                   // their 1σ from σ = 0.5
/// assert!((x[1] - 0.1).abs() < 1e-9 && sd[0] < 0.5);
/// assert_eq!(out.noise_sigma, Some(0.5));
/// assert!(!out.outlier && !out.misfit);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct AutoOutput {
    /// The sample's time.
    pub time: f64,
    /// The estimate at `time`: derivatives `x … x^(d)` of the active degree `d`, with their
    /// covariance when `σ` is known or estimated. After a rejected sample, the prediction
    /// across it. `None` until the active filter is determined.
    pub estimate: Option<PolynomialState>,
    /// The active degree `d` (the final degree once settled).
    pub degree: usize,
    /// Which filter is active.
    pub phase: Phase,
    /// The noise `σ` used (given, or the running estimate once it has enough terms).
    pub noise_sigma: Option<f64>,
    /// `ν = y − ŷ(t)` against the active filter's prediction (before this sample).
    pub innovation: Option<f64>,
    /// `σ_ε = σ √(1 + v)`, the innovation's standard deviation.
    pub innovation_sigma: Option<f64>,
    /// The gate half-width applied, when the gate was active.
    pub gate: Option<f64>,
    /// The sample was rejected: the state was not updated.
    pub outlier: bool,
    /// The innovation chi-squared test says the model no longer fits (or a run of rejections
    /// was just taken for a manoeuvre).
    pub misfit: bool,
    /// A run of consecutive rejections was taken for a manoeuvre and applied at this sample.
    pub manoeuvre: bool,
    /// The final-degree memory was restarted at this sample ([`MisfitResponse::Restart`]).
    pub restart: bool,
    /// The chi-squared window after this sample (when the sample entered it).
    pub chi_squared: Option<ChiSquaredOutcome>,
}

impl AutoOutput {
    /// The estimated derivatives `x, x', …` (active degree), when determined.
    pub fn derivatives(&self) -> Option<&[f64]> {
        self.estimate.as_ref().map(|s| s.derivatives.as_slice())
    }

    /// 1σ of each derivative, when determined and `σ` is available.
    pub fn std_devs(&self) -> Option<Vec<f64>> {
        self.estimate.as_ref().and_then(|s| s.std_devs())
    }
}

#[derive(Clone, Debug)]
struct WindowedMean {
    window: Option<usize>,
    values: VecDeque<f64>,
    sum: f64,
    count: usize,
    pushes: usize,
}

impl WindowedMean {
    fn new(window: Option<usize>) -> Self {
        Self {
            window,
            values: VecDeque::new(),
            sum: 0.0,
            count: 0,
            pushes: 0,
        }
    }

    fn push(&mut self, x: f64) {
        self.sum += x;
        match self.window {
            None => self.count += 1,
            Some(w) => {
                self.values.push_back(x);
                if self.values.len() > w {
                    let old = self.values.pop_front().unwrap_or(0.0);
                    self.sum -= old;
                }
                self.count = self.values.len();
                self.pushes += 1;
                if self.pushes >= 4 * w {
                    self.sum = self.values.iter().sum();
                    self.pushes = 0;
                }
                self.sum = self.sum.max(0.0);
            }
        }
    }

    fn mean(&self) -> Option<f64> {
        (self.count > 0).then(|| self.sum / self.count as f64)
    }
}

#[derive(Clone, Debug)]
enum NoiseState {
    Known(f64),
    Differences(DifferenceNoise),
    Innovations(WindowedMean),
}

/// A sample kept for a restart or a run of rejections, with `ν²/σ_ε²` against the active
/// filter's prediction when it arrived.
#[derive(Clone, Copy, Debug)]
struct Kept {
    t: f64,
    y: f64,
    k2: Option<f64>,
}

/// The automatic polynomial filter (see the [module docs](self)).
///
/// ```
/// use seqsmooth::polynomial::automatic::{AutomaticFilter, Phase};
/// let mut f = AutomaticFilter::with_defaults(2, 0.9, 1.0).unwrap(); // σ estimated
/// for n in 0..200 {
///     let t = n as f64 * 1.1;
///     let noise = 0.2 * (((n * 37 + 11) % 17) as f64 / 8.0 - 1.0);
///     f.update(t, 3.0 - t + 0.01 * t * t + noise).unwrap();
/// }
/// assert_eq!((f.active_degree(), f.phase()), (2, Phase::Fading));
/// assert_eq!(f.samples() + f.rejected(), 200);
/// assert!(f.noise_sigma().unwrap() > 0.05 && f.noise_sigma().unwrap() < 0.2);
/// let p = f.estimate_at(f.last_time().unwrap() + 1.0).unwrap(); // 1-step prediction
/// assert_eq!(p.derivatives.len(), 3);
/// assert!(!f.is_misfit() && f.restarts() == 0 && f.last_restart().is_none());
/// ```
#[derive(Clone, Debug)]
pub struct AutomaticFilter {
    cfg: AutoConfig,
    /// Expanding-memory filters of the ladder, indexed by degree `< m` (`None` once passed).
    ladder: Vec<Option<ExpandingMemory>>,
    /// The final-degree expanding-memory filter of the current memory, until the switch.
    expanding: Option<ExpandingMemory>,
    /// The final-degree fading-memory filter of the current memory.
    fading: FadingMemory,
    active: usize,
    /// Global index (accepted samples) of the latest expanding → fading switch.
    switched_at: Option<u64>,
    /// The current memory has switched to fading.
    switched: bool,
    /// Time of the first sample of the current final-degree memory.
    memory_t_first: Option<f64>,
    /// `c` of a constant switch rule (`n_s = ⌊c/(1-θ)⌋`), and `c_0m` for Reyneke's `N`.
    switch_constant: Option<f64>,
    memory_constant: f64,
    accepted: u64,
    rejected: u64,
    restarts: u64,
    last_restart: Option<u64>,
    last_time: Option<f64>,
    noise: NoiseState,
    chi: InnovationChiSquared,
    restart_test: Option<InnovationChiSquared>,
    /// The newest accepted samples (for a restart).
    recent: VecDeque<Kept>,
    /// The current run of rejected samples.
    pending: Vec<Kept>,
    /// Consecutive updates the candidate's top derivative stayed within its 1σ.
    stable_runs: usize,
    prev_top: Option<f64>,
}

fn unit_expanding(m: usize, engine: Engine) -> Result<ExpandingMemory, Error> {
    ExpandingMemory::new(m, engine)?.with_noise_sigma(1.0)
}

fn unit_fading(cfg: &AutoConfig) -> Result<FadingMemory, Error> {
    FadingMemory::new(cfg.degree, cfg.theta, cfg.tau, cfg.engine)?
        .with_discount_mode(cfg.discount)?
        .with_switch_rule(cfg.switch_rule)?
        .with_noise_sigma(1.0)
}

/// The variance of a unit Gaussian truncated to `|Z| ≤ a`: `1 − 2aφ(a)/(1 − 2Q(a))`.
fn truncated_variance(a: f64) -> f64 {
    if !a.is_finite() {
        return 1.0;
    }
    let phi = (-0.5 * a * a).exp() / (2.0 * std::f64::consts::PI).sqrt();
    let inside = 1.0 - two_sided_tail(a).unwrap_or(0.0);
    if inside <= 0.0 {
        return 1.0;
    }
    (1.0 - 2.0 * a * phi / inside).max(1e-3)
}

impl AutomaticFilter {
    /// A filter with the given configuration (validated: typed errors for a degree, `θ`, `τ`,
    /// `σ`, window, significance, multiplier or ladder setting out of range).
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::{AutoConfig, AutomaticFilter};
    /// use seqsmooth::Error;
    /// assert!(matches!(
    ///     AutomaticFilter::new(AutoConfig::new(2, 1.5, 1.0)),
    ///     Err(Error::ThetaOutOfRange { .. })
    /// ));
    /// let mut c = AutoConfig::new(2, 0.9, 1.0);
    /// c.misfit_window = 0;
    /// assert!(AutomaticFilter::new(c).is_err());
    /// ```
    pub fn new(config: AutoConfig) -> Result<Self, Error> {
        config.validate()?;
        let chi = InnovationChiSquared::new(config.misfit_window, config.misfit_alpha)?;
        let restart_test = match config.misfit_response {
            MisfitResponse::Flag => None,
            MisfitResponse::Restart { alpha } => {
                Some(InnovationChiSquared::new(config.misfit_window, alpha)?)
            }
        };
        let m = config.degree;
        let ladder = (0..m)
            .map(|d| {
                if d >= config.start_degree {
                    unit_expanding(d, config.engine).map(Some)
                } else {
                    Ok(None)
                }
            })
            .collect::<Result<Vec<_>, _>>()?;
        let expanding = Some(unit_expanding(m, config.engine)?);
        let fading = unit_fading(&config)?;
        let noise = match (config.noise_sigma, config.noise_source) {
            (Some(s), _) => NoiseState::Known(s),
            (None, NoiseSource::Differences { window }) => {
                NoiseState::Differences(DifferenceNoise::new(m + 1, window)?)
            }
            (None, NoiseSource::Innovations { window }) => {
                NoiseState::Innovations(WindowedMean::new(window))
            }
        };
        // The constant of the switch rule, as SwitchRule::switch_index computes it (cached:
        // the rules are evaluated at every sample until the switch).
        let switch_constant = match config.switch_rule {
            SwitchRule::Position => Some(memory_length_constant(0, m)),
            SwitchRule::ColumnMean => {
                Some((0..=m).map(|i| memory_length_constant(i, m)).sum::<f64>() / (m + 1) as f64)
            }
            SwitchRule::Derivative(i) => Some(memory_length_constant(i, m)),
            SwitchRule::ExactCrossover | SwitchRule::AtSample(_) => None,
        };
        Ok(Self {
            active: config.start_degree,
            memory_constant: memory_length_constant(0, m),
            switch_constant,
            cfg: config,
            ladder,
            expanding,
            fading,
            switched_at: None,
            switched: false,
            memory_t_first: None,
            accepted: 0,
            rejected: 0,
            restarts: 0,
            last_restart: None,
            last_time: None,
            noise,
            chi,
            restart_test,
            recent: VecDeque::new(),
            pending: Vec::new(),
            stable_runs: 0,
            prev_top: None,
        })
    }

    /// A filter of final degree `m`, discount `θ` per `τ`, with every other setting at its
    /// default ([`AutoConfig::new`]).
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// let mut f = AutomaticFilter::with_defaults(2, 0.95, 0.5).unwrap();
    /// let out = f.update(0.0, 1.0).unwrap();
    /// assert_eq!(out.degree, 0);                       // the ladder starts at degree 0
    /// assert_eq!(out.derivatives(), Some(&[1.0][..]));
    /// assert!(out.noise_sigma.is_none());               // not estimated yet
    /// ```
    pub fn with_defaults(m: usize, theta: f64, tau: f64) -> Result<Self, Error> {
        Self::new(AutoConfig::new(m, theta, tau))
    }

    /// The configuration.
    pub fn config(&self) -> &AutoConfig {
        &self.cfg
    }

    /// The final degree `m`.
    pub fn degree(&self) -> usize {
        self.cfg.degree
    }

    /// The active degree (below `m` while the ladder settles).
    pub fn active_degree(&self) -> usize {
        self.active
    }

    /// Which filter is active.
    pub fn phase(&self) -> Phase {
        if self.active < self.cfg.degree {
            Phase::Settling
        } else if !self.switched {
            Phase::Expanding
        } else {
            Phase::Fading
        }
    }

    /// Accepted samples (those that updated the state).
    pub fn samples(&self) -> u64 {
        self.accepted
    }

    /// Samples rejected as outliers (not counting runs later applied as manoeuvres).
    pub fn rejected(&self) -> u64 {
        self.rejected
    }

    /// Restarts of the final-degree memory ([`MisfitResponse::Restart`]).
    pub fn restarts(&self) -> u64 {
        self.restarts
    }

    /// The index (in accepted samples) of the newest sample when the latest restart happened.
    pub fn last_restart(&self) -> Option<u64> {
        self.last_restart
    }

    /// The time of the newest sample seen (accepted or rejected).
    pub fn last_time(&self) -> Option<f64> {
        self.last_time
    }

    /// The 0-based index, in accepted samples since the first, of the first sample the
    /// fading-memory filter produced the output for (the latest switch, after a restart);
    /// `None` before the switch.
    pub fn switched_at(&self) -> Option<u64> {
        self.switched_at
    }

    /// The noise `σ` in use: the given one, or the running estimate once it has
    /// [`MIN_NOISE_TERMS`] terms.
    pub fn noise_sigma(&self) -> Option<f64> {
        match &self.noise {
            NoiseState::Known(s) => Some(*s),
            NoiseState::Differences(d) => {
                if d.len() >= MIN_NOISE_TERMS {
                    d.sigma()
                } else {
                    None
                }
            }
            NoiseState::Innovations(w) => {
                if w.count >= MIN_NOISE_TERMS {
                    w.mean().map(f64::sqrt)
                } else {
                    None
                }
            }
        }
    }

    /// True while the innovation chi-squared window exceeds its threshold.
    pub fn is_misfit(&self) -> bool {
        self.chi.is_misfit()
    }

    fn final_filter(&self) -> &dyn PolynomialFilter {
        match (&self.expanding, self.switched) {
            (Some(e), false) => e,
            _ => &self.fading,
        }
    }

    fn filter(&self, degree: usize) -> Option<&dyn PolynomialFilter> {
        if degree < self.cfg.degree {
            self.ladder[degree]
                .as_ref()
                .map(|f| f as &dyn PolynomialFilter)
        } else {
            Some(self.final_filter())
        }
    }

    fn active_filter(&self) -> &dyn PolynomialFilter {
        self.filter(self.active)
            .unwrap_or_else(|| self.final_filter())
    }

    fn scale(&self, state: PolynomialState) -> PolynomialState {
        let sigma = self.noise_sigma();
        PolynomialState {
            covariance: match (state.covariance, sigma) {
                (Some(c), Some(s)) => Some(c * (s * s)),
                _ => None,
            },
            ..state
        }
    }

    /// The estimate at any time `t` from the active filter (a prediction after the newest
    /// accepted sample), with covariance `σ²·VRF` when `σ` is available.
    pub fn estimate_at(&self, t: f64) -> Option<PolynomialState> {
        self.active_filter().estimate_at(t).map(|s| self.scale(s))
    }

    /// The estimate at the newest accepted sample.
    pub fn estimate(&self) -> Option<PolynomialState> {
        self.active_filter().estimate().map(|s| self.scale(s))
    }

    /// The discount per sample the switch rules use: `θ` per update, or `θ^ζ̄` with `ζ̄` the mean
    /// step of the current memory so far (including `t`) in units of `τ`.
    fn theta_per_sample(&self, t: f64) -> f64 {
        let n = self.fading.samples();
        let th = match (self.cfg.discount, self.memory_t_first) {
            (DiscountMode::PerTime, Some(t0)) if n > 0 => {
                let zeta = (t - t0) / (n as f64 * self.cfg.tau);
                self.cfg.theta.powf(zeta)
            }
            _ => self.cfg.theta,
        };
        th.clamp(1e-300, 1.0 - 1e-15)
    }

    fn memory_length(&self, t: f64) -> f64 {
        if self.active == self.cfg.degree && self.switched {
            self.memory_constant / (1.0 - self.theta_per_sample(t))
        } else {
            self.active_filter().samples().max(1) as f64
        }
    }

    /// Evaluates the expanding → fading switch for the next sample of the current memory, at
    /// time `t`: the rule's index for the per-sample discount so far, exactly as
    /// [`SwitchRule::switch_index`] (and the gain engine) computes it.
    fn switch_due(&self, t: f64) -> Result<bool, Error> {
        if self.switched {
            return Ok(false);
        }
        let m = self.cfg.degree;
        let n = self.fading.samples();
        if n <= m as u64 {
            return Ok(false);
        }
        let theta_s = self.theta_per_sample(t);
        let index = match (self.cfg.switch_rule, self.switch_constant) {
            (SwitchRule::AtSample(k), _) => k,
            (_, Some(c)) => {
                let v = (c / (1.0 - theta_s) + 1e-9).floor();
                if v >= u64::MAX as f64 {
                    u64::MAX
                } else {
                    v as u64
                }
            }
            _ => {
                // Exact crossover: the expanding-memory current position VRF reaches the
                // fading-memory one.
                let h0 = expanding_vrf::<f64>(m, n, EstimateForm::Current)?[(0, 0)];
                let target = fading_vrf(m, theta_s, EstimateForm::Current)?[(0, 0)];
                return Ok(h0 <= target * (1.0 + 1e-12));
            }
        };
        Ok(n >= index.max(m as u64 + 1))
    }

    /// Processes the sample `y` at time `t` (finite, strictly after the previous sample's time,
    /// rejected or not). On error nothing changes.
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::{AutoConfig, AutomaticFilter};
    /// use seqsmooth::Error;
    /// let mut f = AutomaticFilter::new(AutoConfig::new(1, 0.9, 1.0)).unwrap();
    /// f.update(0.0, 1.0).unwrap();
    /// assert!(matches!(f.update(0.0, 2.0), Err(Error::TimeNotIncreasing { .. })));
    /// assert!(matches!(f.update(1.0, f64::NAN), Err(Error::NonFinite { .. })));
    /// assert_eq!(f.samples(), 1);
    /// ```
    pub fn update(&mut self, t: f64, y: f64) -> Result<AutoOutput, Error> {
        crate::error::check_sample(t, y, self.last_time)?;
        // With the input checked, the steps below cannot fail on the data; should an internal
        // step still fail, restore the state so that an error never leaves a half update.
        let backup = self.clone();
        match self.step(t, y) {
            Ok(out) => Ok(out),
            Err(e) => {
                *self = backup;
                Err(e)
            }
        }
    }

    fn step(&mut self, t: f64, y: f64) -> Result<AutoOutput, Error> {
        self.last_time = Some(t);
        let m = self.cfg.degree;
        if self.switch_due(t)? {
            self.switched = true;
            self.switched_at = Some(self.accepted);
            self.expanding = None;
        }
        let sigma = self.noise_sigma();
        let prediction = self.active_filter().estimate_at(t);
        let (innovation, vrf) = match &prediction {
            Some(p) => (
                Some(y - p.derivatives[0]),
                p.covariance.as_ref().map(|c| c[(0, 0)].max(0.0)),
            ),
            None => (None, None),
        };
        let innovation_sigma = match (sigma, vrf) {
            (Some(s), Some(v)) => Some(s * (1.0 + v).sqrt()),
            _ => None,
        };
        let k2 = match (innovation, innovation_sigma) {
            (Some(nu), Some(se)) if se > 0.0 => Some((nu / se).powi(2)),
            _ => None,
        };
        // The gate: final degree, σ known, prediction at least as good as a sample.
        let gate = match (sigma, vrf) {
            (Some(s), Some(v)) if self.active == m && v <= self.cfg.gate_max_vrf => {
                self.cfg.outliers.threshold(s, v, self.memory_length(t))
            }
            _ => None,
        };
        let rejected = match (gate, innovation) {
            (Some(g), Some(nu)) => nu.abs() > g,
            _ => false,
        };
        let mut manoeuvre = false;
        let mut restart = false;
        let mut chi_out = None;
        if rejected {
            self.pending.push(Kept { t, y, k2 });
            let limit = self.cfg.max_consecutive_rejections;
            if limit > 0 && self.pending.len() >= limit {
                // A run of rejections: the model, not the samples, is wrong. Apply the run.
                manoeuvre = true;
                let run = std::mem::take(&mut self.pending);
                // The earlier members of the run were counted as rejections; they are not.
                self.rejected -= (run.len() - 1) as u64;
                for p in run {
                    chi_out = self.accept(p, None, true)?.or(chi_out);
                }
                if self.restart_test.is_some() && self.active == m {
                    self.restart()?;
                    restart = true;
                }
            } else {
                self.rejected += 1;
            }
        } else {
            self.pending.clear();
            let truncation = match (gate, innovation_sigma, vrf) {
                (Some(g), Some(se), Some(v)) if se > 0.0 => Some((g / se, v)),
                _ => None,
            };
            chi_out = self.accept(Kept { t, y, k2 }, truncation, false)?;
            if self.active == m && self.restart_test.as_ref().is_some_and(|r| r.is_misfit()) {
                self.restart()?;
                restart = true;
            }
        }
        let outlier = rejected && !manoeuvre;
        let estimate = if outlier {
            self.estimate_at(t)
        } else {
            self.estimate()
        };
        Ok(AutoOutput {
            time: t,
            estimate,
            degree: self.active,
            phase: self.phase(),
            noise_sigma: self.noise_sigma(),
            innovation,
            innovation_sigma,
            gate,
            outlier,
            misfit: manoeuvre || restart || self.chi.is_misfit(),
            manoeuvre,
            restart,
            chi_squared: chi_out,
        })
    }

    /// Applies an accepted sample to every filter, the noise estimate and the misfit window;
    /// then lets the ladder step up. `truncation` is `(a, v)`, the gate half-width in units of
    /// `σ_ε` and the prediction VRF, when the gate was active (the noise estimates correct for
    /// the truncation); `manoeuvre` marks a run of rejections applied after all (left out of the
    /// innovation noise estimate).
    fn accept(
        &mut self,
        sample: Kept,
        truncation: Option<(f64, f64)>,
        manoeuvre: bool,
    ) -> Result<Option<ChiSquaredOutcome>, Error> {
        let Kept { t, y, k2 } = sample;
        if let NoiseState::Innovations(_) = self.noise {
            // The final-degree filter's own innovation, whatever degree is active.
            let term = self.final_filter().estimate_at(t).and_then(|p| {
                let v = p.covariance.as_ref()?[(0, 0)].max(0.0);
                let nu = y - p.derivatives[0];
                Some(nu * nu / (1.0 + v))
            });
            // Samples the gate could have cut are divided by the truncated variance.
            if let (Some(term), NoiseState::Innovations(w)) = (term, &mut self.noise) {
                if !manoeuvre {
                    w.push(term / truncation.map_or(1.0, |(a, _)| truncated_variance(a)));
                }
            }
        }
        if let NoiseState::Differences(d) = &mut self.noise {
            // A gated sample's own noise e has E{e² | |ν| ≤ aσ_ε} = σ²(c(a) + v)/(1 + v), with
            // c(a) the truncated unit variance (e = ν/(1+v) + an independent part).
            let factor = truncation.map_or(1.0, |(a, v)| (truncated_variance(a) + v) / (1.0 + v));
            d.push_with_variance_factor(t, y, factor)?;
        }
        for f in self.ladder.iter_mut().flatten() {
            f.update(t, y)?;
        }
        if let Some(f) = &mut self.expanding {
            f.update(t, y)?;
        }
        self.fading.update(t, y)?;
        if self.memory_t_first.is_none() {
            self.memory_t_first = Some(t);
        }
        self.accepted += 1;
        self.recent.push_back(sample);
        let keep = self.cfg.misfit_window.max(2 * (self.cfg.degree + 1));
        while self.recent.len() > keep {
            self.recent.pop_front();
        }
        let chi_out = match k2 {
            Some(k2) => {
                if let Some(r) = &mut self.restart_test {
                    r.push_normalised(k2)?;
                }
                Some(self.chi.push_normalised(k2)?)
            }
            None => None,
        };
        self.settle();
        Ok(chi_out)
    }

    /// Restarts the final-degree memory from the samples since the estimated onset of the
    /// misfit: the suffix of the misfit window with the largest CUSUM `Σ (ν²/σ_ε² − 3)` (a
    /// change-point estimate), with at least `m + 1` samples (so the state stays determined).
    fn restart(&mut self) -> Result<(), Error> {
        let m = self.cfg.degree;
        let len = self.recent.len();
        let window = self.cfg.misfit_window.min(len);
        // CUSUM change point: the suffix maximising Σ (k² − 3). A term of a fitting model
        // lowers the sum with probability P(χ²_1 < 3) = 92%, so the suffix rarely reaches back
        // before the onset; ties keep the later start.
        let mut best = (0.0, len);
        let mut sum = 0.0;
        for j in (len - window..len).rev() {
            if let Some(k2) = self.recent[j].k2 {
                sum += k2 - 3.0;
                if sum > best.0 {
                    best = (sum, j);
                }
            }
        }
        let start = best.1.min(len.saturating_sub(m + 1));
        let kept: Vec<Kept> = self.recent.iter().skip(start).copied().collect();
        let mut expanding = unit_expanding(m, self.cfg.engine)?;
        let mut fading = unit_fading(&self.cfg)?;
        for k in &kept {
            expanding.update(k.t, k.y)?;
            fading.update(k.t, k.y)?;
        }
        self.expanding = Some(expanding);
        self.fading = fading;
        self.switched = false;
        self.memory_t_first = kept.first().map(|k| k.t);
        self.chi.reset();
        if let Some(r) = &mut self.restart_test {
            r.reset();
        }
        // The kept samples' innovations belong to the old memory.
        self.recent = kept.into_iter().map(|k| Kept { k2: None, ..k }).collect();
        self.restarts += 1;
        self.last_restart = Some(self.accepted.saturating_sub(1));
        Ok(())
    }

    /// The quick-settling ladder (Reyneke §7.3): step up while the next degree is ready.
    fn settle(&mut self) {
        let m = self.cfg.degree;
        while self.active < m {
            let c = self.active + 1;
            let Some(cand) = self.filter(c) else { break };
            let Some(est) = cand.estimate() else { break };
            let Some(cov) = est.covariance.as_ref() else {
                break;
            };
            let vrf = cov[(0, 0)];
            // Stability of the candidate's top derivative against its own 1σ.
            let top = est.derivatives[c];
            let stable_now = match (self.prev_top, self.noise_sigma()) {
                (Some(prev), Some(s)) => (top - prev).abs() <= s * cov[(c, c)].max(0.0).sqrt(),
                _ => false,
            };
            self.stable_runs = if stable_now { self.stable_runs + 1 } else { 0 };
            self.prev_top = Some(top);
            let misfit = self.chi.is_misfit() && vrf <= 1.0;
            let ready = vrf <= self.cfg.settle_vrf && self.stable_runs >= self.cfg.settle_stable;
            if !(ready || misfit) {
                break;
            }
            self.ladder[self.active] = None;
            self.active = c;
            self.chi.reset();
            if let Some(r) = &mut self.restart_test {
                r.reset();
            }
            self.stable_runs = 0;
            self.prev_top = None;
        }
    }
}
