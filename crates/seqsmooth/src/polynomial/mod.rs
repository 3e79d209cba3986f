//! The expanding- and fading-memory polynomial filters of any degree, on evenly spaced or
//! irregular timestamps (Morrison ch. 9, 13; Reyneke et al. §6).
//!
//! Each filter runs on one of two [`Engine`]s:
//!
//! - [`Engine::Exact`] — recursive least squares with the polynomial model on arbitrary
//!   timestamps, `O(m²)` per sample, equal to the batch fit over all samples so far (expanding
//!   memory: equal weights; fading memory: weights `θ^((t_n - t_k)/τ)`, or `θ^(n-k)` with
//!   [`DiscountMode::PerUpdate`]). It is the polynomial instance of the square-root information
//!   filter of [`crate::recursive`], in a centred, scaled monomial basis (see
//!   `exact_engine` docs for why). Determined from the `(m+1)`-th sample on.
//! - [`Engine::Gain`] — the fixed-gain recursion of Morrison's Tables 9.1/13.1 in Reyneke's
//!   variable-step form: predict by `Φ(ζ)`, `ζ = Δt/τ`, correct with gains `h_k/ζ^k`. `O(m)` per
//!   sample after the prediction. Exact least squares on evenly spaced samples for any step; an
//!   approximation on irregular timestamps (its deviation is tabled in the crate docs).
//!
//! The gain-engine fading-memory filter starts as an expanding-memory filter and switches to the
//! constant gains at the sample chosen by its [`SwitchRule`] (Morrison §13.8).
//!
//! ```
//! use seqsmooth::{Engine, ExpandingMemory};
//! let mut f = ExpandingMemory::new(2, Engine::Exact).unwrap();
//! for (t, y) in [(0.0, 1.0), (0.5, 1.75), (1.7, 5.59), (2.0, 7.0)] {
//!     f.update(t, y).unwrap();
//! }
//! let s = f.estimate().unwrap(); // y = 1 + t + t² exactly: x = 7, x' = 5, x'' = 2
//! assert!((s.derivatives[0] - 7.0).abs() < 1e-12);
//! assert!((s.derivatives[1] - 5.0).abs() < 1e-12);
//! assert!((s.derivatives[2] - 2.0).abs() < 1e-12);
//! ```

mod exact_engine;
mod gain_engine;
pub mod gains;
pub mod switching;
pub mod vrf;

use crate::error::Error;
use crate::model::PolynomialState;
use exact_engine::{Discount, ExactEngine};
use gain_engine::{FadingGains, GainEngine};
pub use switching::SwitchRule;

/// The largest degree the filters accept. The exact engine's accuracy against an independent
/// batch QR fit is measured in the tests up to this degree.
pub const MAX_DEGREE: usize = 24;

/// Which computation a filter uses (see the [module docs](self)).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Engine {
    /// Recursive least squares, exact on any timestamps.
    #[default]
    Exact,
    /// Fixed-gain recursion, exact on evenly spaced samples.
    Gain,
}

/// How a fading-memory filter discounts old samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum DiscountMode {
    /// By `θ` per `τ` of elapsed time: weight `θ^((t_n - t_k)/τ)` (`θ_eff = θ^ζ` per update).
    #[default]
    PerTime,
    /// By `θ` per sample whatever the spacing: weight `θ^(n-k)`.
    PerUpdate,
}

#[derive(Clone, Debug)]
enum Core {
    Exact(ExactEngine),
    Gain(GainEngine),
}

impl Core {
    fn samples(&self) -> u64 {
        match self {
            Core::Exact(e) => e.samples(),
            Core::Gain(g) => g.samples(),
        }
    }

    fn last_time(&self) -> f64 {
        match self {
            Core::Exact(e) => e.last_time(),
            Core::Gain(g) => g.last_time(),
        }
    }

    fn update(&mut self, t: f64, y: f64) -> Result<(), Error> {
        if !t.is_finite() {
            return Err(Error::NonFinite {
                what: "time",
                value: t,
            });
        }
        if !y.is_finite() {
            return Err(Error::NonFinite {
                what: "value",
                value: y,
            });
        }
        if self.samples() > 0 {
            let previous = self.last_time();
            if t <= previous {
                return Err(Error::TimeNotIncreasing { time: t, previous });
            }
        }
        match self {
            Core::Exact(e) => e.update(t, y),
            Core::Gain(g) => g.update(t, y),
        }
        Ok(())
    }

    fn estimate_at(&self, m: usize, t: f64) -> Option<PolynomialState> {
        if self.samples() <= m as u64 || !t.is_finite() {
            return None;
        }
        let (derivatives, covariance) = match self {
            Core::Exact(e) => e.estimate_at(t)?,
            Core::Gain(g) => g.estimate_at(t),
        };
        Some(PolynomialState {
            time: t,
            derivatives,
            covariance,
        })
    }

    fn track_covariance(&mut self, sigma: f64) -> Result<(), Error> {
        if !(sigma.is_finite() && sigma > 0.0) {
            return Err(Error::InvalidParameter {
                name: "noise sigma",
                value: sigma.to_string(),
                reason: "must be a positive finite number".into(),
            });
        }
        match self {
            Core::Exact(e) => e.track_covariance(sigma),
            Core::Gain(g) => g.track_covariance(sigma),
        }
        Ok(())
    }
}

fn check_degree(m: usize) -> Result<(), Error> {
    if m > MAX_DEGREE {
        return Err(Error::DegreeOutOfRange {
            degree: m,
            max: MAX_DEGREE,
        });
    }
    Ok(())
}

fn check_tau(tau: f64) -> Result<(), Error> {
    if !(tau.is_finite() && tau > 0.0) {
        return Err(Error::TauOutOfRange { tau });
    }
    Ok(())
}

fn check_theta(theta: f64) -> Result<(), Error> {
    if !(theta > 0.0 && theta < 1.0) {
        return Err(Error::ThetaOutOfRange { theta });
    }
    Ok(())
}

/// Expanding-memory polynomial filter of degree `m` (Morrison ch. 9; Reyneke §6.3-6.4): the
/// least-squares polynomial through all samples so far, with its derivatives, predictions and
/// (given the noise σ) covariance. Self-starting: determined from the `(m+1)`-th sample.
///
/// ```
/// use seqsmooth::{Engine, ExpandingMemory};
/// let mut f = ExpandingMemory::new(1, Engine::Gain).unwrap();
/// for (n, y) in [1.0, 3.0, 2.0, 5.0, 4.0].iter().enumerate() {
///     f.update(n as f64, *y).unwrap();
/// }
/// // Morrison T9-02: Z*_{4,4} = (23/5, 4/5)
/// let s = f.estimate().unwrap();
/// assert!((s.derivatives[0] - 4.6).abs() < 1e-12 && (s.derivatives[1] - 0.8).abs() < 1e-12);
/// // the 1-step prediction Z*_{5,4} = (27/5, 4/5)
/// assert!((f.estimate_at(5.0).unwrap().derivatives[0] - 5.4).abs() < 1e-12);
/// ```
#[derive(Clone, Debug)]
pub struct ExpandingMemory {
    m: usize,
    core: Core,
}

impl ExpandingMemory {
    /// A filter of degree `m` on the given engine.
    pub fn new(m: usize, engine: Engine) -> Result<Self, Error> {
        check_degree(m)?;
        let core = match engine {
            Engine::Exact => Core::Exact(ExactEngine::new(m, None)),
            // The gain engine's output does not depend on τ for expanding memory; τ = 1.
            Engine::Gain => Core::Gain(GainEngine::new(m, 1.0, None)),
        };
        Ok(Self { m, core })
    }

    /// Tracks the covariance of the estimate for white measurement noise of standard deviation
    /// `sigma`: exact for the engine's estimator on any timestamps.
    pub fn with_noise_sigma(mut self, sigma: f64) -> Result<Self, Error> {
        self.core.track_covariance(sigma)?;
        Ok(self)
    }

    /// Degree `m`.
    pub fn degree(&self) -> usize {
        self.m
    }

    /// Number of samples processed.
    pub fn samples(&self) -> u64 {
        self.core.samples()
    }

    /// True once the estimate is determined (`m+1` samples).
    pub fn is_determined(&self) -> bool {
        self.samples() > self.m as u64
    }

    /// Processes the sample `y` at time `t` (strictly after the previous one, finite).
    pub fn update(&mut self, t: f64, y: f64) -> Result<(), Error> {
        self.core.update(t, y)
    }

    /// The current estimate `X*_{n,n}`, valid at the newest sample's time.
    pub fn estimate(&self) -> Option<PolynomialState> {
        self.core.estimate_at(self.m, self.core.last_time())
    }

    /// The estimate valid at any time `t` from the samples so far: a prediction for `t` after
    /// the newest sample, a retrodiction before it.
    pub fn estimate_at(&self, t: f64) -> Option<PolynomialState> {
        self.core.estimate_at(self.m, t)
    }
}

/// Fading-memory polynomial filter of degree `m` and discount `θ` per `τ` (Morrison ch. 13;
/// Reyneke §6.5-6.6): the polynomial minimising `Σ_k θ^((t_n-t_k)/τ) (y_k - p(t_k))²`.
///
/// ```
/// use seqsmooth::{Engine, FadingMemory};
/// let mut f = FadingMemory::new(1, 0.9, 1.0, Engine::Gain).unwrap();
/// for n in 0..500 {
///     f.update(n as f64, 2.0 + 0.5 * n as f64).unwrap();
/// }
/// let s = f.estimate().unwrap();
/// assert!((s.derivatives[0] - 251.5).abs() < 1e-9 && (s.derivatives[1] - 0.5).abs() < 1e-12);
/// ```
#[derive(Clone, Debug)]
pub struct FadingMemory {
    m: usize,
    theta: f64,
    tau: f64,
    mode: DiscountMode,
    rule: SwitchRule,
    sigma: Option<f64>,
    core: Core,
}

impl FadingMemory {
    /// A filter of degree `m`, discount `θ ∈ (0,1)` per nominal interval `τ > 0`.
    pub fn new(m: usize, theta: f64, tau: f64, engine: Engine) -> Result<Self, Error> {
        check_degree(m)?;
        check_theta(theta)?;
        check_tau(tau)?;
        let mode = DiscountMode::default();
        let rule = SwitchRule::default();
        let core = match engine {
            Engine::Exact => Core::Exact(ExactEngine::new(m, Some(Discount { theta, tau, mode }))),
            Engine::Gain => Core::Gain(GainEngine::new(
                m,
                tau,
                Some(FadingGains::new(m, theta, mode, rule)),
            )),
        };
        Ok(Self {
            m,
            theta,
            tau,
            mode,
            rule,
            sigma: None,
            core,
        })
    }

    fn rebuild(&mut self) -> Result<(), Error> {
        if self.core.samples() > 0 {
            return Err(Error::InvalidParameter {
                name: "configuration",
                value: "change after the first sample".into(),
                reason: "set the discount mode and switch rule before the first update".into(),
            });
        }
        match &mut self.core {
            Core::Exact(_) => {
                self.core = Core::Exact(ExactEngine::new(
                    self.m,
                    Some(Discount {
                        theta: self.theta,
                        tau: self.tau,
                        mode: self.mode,
                    }),
                ));
            }
            Core::Gain(_) => {
                self.core = Core::Gain(GainEngine::new(
                    self.m,
                    self.tau,
                    Some(FadingGains::new(self.m, self.theta, self.mode, self.rule)),
                ));
            }
        }
        if let Some(sigma) = self.sigma {
            self.core.track_covariance(sigma)?;
        }
        Ok(())
    }

    /// Chooses how old samples are discounted (default [`DiscountMode::PerTime`]). Must be set
    /// before the first sample.
    pub fn with_discount_mode(mut self, mode: DiscountMode) -> Result<Self, Error> {
        self.mode = mode;
        self.rebuild()?;
        Ok(self)
    }

    /// Chooses when the gain engine switches from its expanding-memory start to the fading
    /// gains (default [`SwitchRule::Position`]). Must be set before the first sample. The exact
    /// engine needs no start-up and ignores the rule.
    pub fn with_switch_rule(mut self, rule: SwitchRule) -> Result<Self, Error> {
        rule.switch_index(self.m, self.theta)?;
        self.rule = rule;
        self.rebuild()?;
        Ok(self)
    }

    /// Tracks the covariance of the estimate for white measurement noise of standard deviation
    /// `sigma` (exact for the engine's estimator, including the start-up).
    pub fn with_noise_sigma(mut self, sigma: f64) -> Result<Self, Error> {
        self.core.track_covariance(sigma)?;
        self.sigma = Some(sigma);
        Ok(self)
    }

    /// Degree `m`.
    pub fn degree(&self) -> usize {
        self.m
    }

    /// `θ`.
    pub fn theta(&self) -> f64 {
        self.theta
    }

    /// `τ`.
    pub fn tau(&self) -> f64 {
        self.tau
    }

    /// The 0-based index of the first sample the gain engine processed with the fading-memory
    /// gains: `None` before the switch and on the exact engine (which needs no start-up).
    pub fn switched_at(&self) -> Option<u64> {
        match &self.core {
            Core::Gain(g) => g.switched_at(),
            Core::Exact(_) => None,
        }
    }

    /// Number of samples processed.
    pub fn samples(&self) -> u64 {
        self.core.samples()
    }

    /// True once the estimate is determined (`m+1` samples).
    pub fn is_determined(&self) -> bool {
        self.samples() > self.m as u64
    }

    /// Processes the sample `y` at time `t` (strictly after the previous one, finite).
    pub fn update(&mut self, t: f64, y: f64) -> Result<(), Error> {
        self.core.update(t, y)
    }

    /// The current estimate, valid at the newest sample's time.
    pub fn estimate(&self) -> Option<PolynomialState> {
        self.core.estimate_at(self.m, self.core.last_time())
    }

    /// The estimate valid at any time `t` from the samples so far.
    pub fn estimate_at(&self, t: f64) -> Option<PolynomialState> {
        self.core.estimate_at(self.m, t)
    }
}
