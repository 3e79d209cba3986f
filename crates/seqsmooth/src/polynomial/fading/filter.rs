//! [`FadingMemory`]: the fading-memory polynomial filter (Morrison ch. 13).

use super::switch::SwitchRule;
use crate::error::Error;
use crate::model::PolynomialState;
use crate::polynomial::engine::{
    impl_polynomial_filter, EngineState, ExactEngine, FadingGains, GainEngine,
};
use crate::polynomial::filter::PolynomialFilter;
use crate::polynomial::options::{
    check_engine_degree, check_not_started, check_tau, check_theta, Discount, DiscountMode, Engine,
};
use crate::polynomial::prior::{check_no_prior, Prior};

/// Fading-memory polynomial filter of degree `m` and discount `θ` per `τ` (Morrison ch. 13;
/// Reyneke §6.5-6.6): the polynomial minimising `Σ_k θ^((t_n-t_k)/τ) (y_k - p(t_k))²`.
///
/// ```
/// use seqsmooth::{Engine, FadingMemory, PolynomialFilter};
/// let mut f = FadingMemory::new(1, 0.9, 1.0, Engine::Gain).unwrap();
/// for n in 0..500 {
///     f.update(n as f64, 2.0 + 0.5 * n as f64).unwrap();
/// }
/// let s = f.estimate().unwrap();
/// assert!((s.derivatives[0] - 251.5).abs() < 1e-9 && (s.derivatives[1] - 0.5).abs() < 1e-12);
/// ```
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub struct FadingMemory {
    m: usize,
    theta: f64,
    tau: f64,
    mode: DiscountMode,
    rule: SwitchRule,
    sigma: Option<f64>,
    prior: Option<Prior>,
    core: EngineState,
}

// Field by field, `clone_from` too (the automatic filter's review keeps copies of it).
field_clone!(FadingMemory {
    m,
    theta,
    tau,
    mode,
    rule,
    sigma,
    prior,
    core
});

impl FadingMemory {
    /// Becomes the degree-`m` filter of `upper`'s samples (`upper` of degree `m + 1`, the same
    /// settings) from `upper`'s leading block, instead of updating with them itself: the same
    /// least squares up to rounding (the exact engine's `ExactEngine::leading_into`, crate
    /// private). `false` (and `self` untouched: update it with the sample instead) unless
    /// both run the exact engine with matching settings and no prior.
    pub(crate) fn follow_leading(&mut self, upper: &FadingMemory) -> bool {
        self.m + 1 == upper.m
            && self.theta == upper.theta
            && self.tau == upper.tau
            && self.mode == upper.mode
            && self.sigma.is_some() == upper.sigma.is_some()
            && self.prior.is_none()
            && upper.prior.is_none()
            && upper.core.leading_into(&mut self.core)
    }
}

impl FadingMemory {
    /// The position at `t` and its variance, without allocating (the automatic filter's
    /// per-sample choices); `None` when [`PolynomialFilter::estimate_at`] has no covariance
    /// or is `None`.
    pub(crate) fn position_at(&self, t: f64) -> Option<(f64, f64)> {
        self.core.position_at(self.m, t)
    }

    /// The derivatives at `t` and their variances into `x` and `var` (`m + 1` each), without
    /// allocating on the exact engine; false when [`PolynomialFilter::estimate_at`] has no
    /// covariance or is `None`.
    pub(crate) fn variances_at(&self, t: f64, x: &mut [f64], var: &mut [f64]) -> bool {
        self.core.variances_at(self.m, t, x, var)
    }

    /// The estimate's derivatives at `t` and its covariance's diagonal into `x` and `var`
    /// (`m + 1` each), the numbers of [`PolynomialFilter::estimate_at`] bit for bit, without
    /// allocating on the exact engine; false where that path does not answer (the caller takes
    /// the estimate).
    pub(crate) fn estimate_diagonal_at(&self, t: f64, x: &mut [f64], var: &mut [f64]) -> bool {
        self.core.estimate_diagonal_at(self.m, t, x, var)
    }

    /// A filter of degree `m`, discount `θ ∈ (0,1)` per span `τ > 0` of time
    /// ([`Discount::PerTime`]; [`Self::from_discount`] takes either meaning).
    ///
    /// ```
    /// use seqsmooth::{Engine, Error, FadingMemory, PolynomialFilter};
    /// let f = FadingMemory::new(1, 0.9, 0.5, Engine::Gain).unwrap();
    /// assert_eq!((f.degree(), f.theta(), f.tau()), (1, 0.9, 0.5));
    /// assert!(matches!(FadingMemory::new(1, 1.0, 1.0, Engine::Gain), Err(Error::ThetaOutOfRange { .. })));
    /// assert!(matches!(FadingMemory::new(1, 0.9, 0.0, Engine::Gain), Err(Error::TauOutOfRange { .. })));
    /// ```
    pub fn new(m: usize, theta: f64, tau: f64, engine: Engine) -> Result<Self, Error> {
        check_engine_degree(m, engine)?;
        check_theta(theta)?;
        check_tau(tau)?;
        let mode = DiscountMode::default();
        let rule = SwitchRule::default();
        let core = match engine {
            Engine::Exact => {
                EngineState::Exact(ExactEngine::new(m, Some(Discount::PerTime { theta, tau })))
            }
            Engine::Gain => EngineState::Gain(GainEngine::new(
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
            prior: None,
            core,
        })
    }

    /// A filter of degree `m` with `discount`, either meaning ([`Discount`]): the one type the
    /// fading Bayes and Kalman filters take too, so that the same discount is the same
    /// estimator (`θ` per update runs the engines in units of `τ = 1`).
    ///
    /// ```
    /// use seqsmooth::discount::Discount;
    /// use seqsmooth::{Engine, FadingMemory, PolynomialFilter};
    /// let d = Discount::per_time(0.9, 0.5).unwrap();
    /// let f = FadingMemory::from_discount(1, d, Engine::Exact).unwrap();
    /// assert_eq!((f.theta(), f.tau(), f.discount()), (0.9, 0.5, d));
    /// let g = FadingMemory::from_discount(1, Discount::PerUpdate { theta: 0.9 }, Engine::Gain).unwrap();
    /// assert_eq!(g.discount(), Discount::PerUpdate { theta: 0.9 });
    /// assert!(FadingMemory::from_discount(1, Discount::PerUpdate { theta: 1.0 }, Engine::Gain).is_err());
    /// ```
    pub fn from_discount(m: usize, discount: Discount, engine: Engine) -> Result<Self, Error> {
        let d = discount.checked()?;
        let f = Self::new(m, d.theta(), d.tau().unwrap_or(1.0), engine)?;
        match d.mode() {
            DiscountMode::PerTime => Ok(f),
            DiscountMode::PerUpdate => f.with_discount_mode(DiscountMode::PerUpdate),
        }
    }

    /// The discount, with its meaning.
    pub fn discount(&self) -> Discount {
        match self.mode {
            DiscountMode::PerTime => Discount::PerTime {
                theta: self.theta,
                tau: self.tau,
            },
            DiscountMode::PerUpdate => Discount::PerUpdate { theta: self.theta },
        }
    }

    fn rebuild(&mut self) -> Result<(), Error> {
        check_not_started(self.core.samples() > 0, "the discount mode and switch rule")?;
        match &mut self.core {
            EngineState::Exact(_) => {
                self.core = EngineState::Exact(ExactEngine::new(self.m, Some(self.discount())));
            }
            EngineState::Gain(_) => {
                self.core = EngineState::Gain(GainEngine::new(
                    self.m,
                    self.tau,
                    Some(FadingGains::new(self.m, self.theta, self.mode, self.rule)),
                ));
            }
        }
        if let Some(sigma) = self.sigma {
            self.core.track_covariance(sigma)?;
        }
        if let Some(prior) = &self.prior {
            self.core.set_prior(self.m, prior)?;
        }
        Ok(())
    }

    /// Chooses how old samples are discounted (default [`DiscountMode::PerTime`]). Must be set
    /// before the first sample.
    ///
    /// ```
    /// use seqsmooth::{DiscountMode, Engine, FadingMemory, PolynomialFilter};
    /// let f = FadingMemory::new(1, 0.9, 1.0, Engine::Exact).unwrap();
    /// let mut g = f.with_discount_mode(DiscountMode::PerUpdate).unwrap();
    /// g.update(0.0, 1.0).unwrap();
    /// assert!(g.with_discount_mode(DiscountMode::PerTime).is_err()); // after the first sample
    /// ```
    pub fn with_discount_mode(mut self, mode: DiscountMode) -> Result<Self, Error> {
        self.mode = mode;
        self.rebuild()?;
        Ok(self)
    }

    /// Chooses when the gain engine switches from its expanding-memory start to the fading
    /// gains (default [`SwitchRule::Position`]). Must be set before the first sample. The exact
    /// engine needs no start-up and ignores the rule.
    ///
    /// ```
    /// use seqsmooth::{Engine, FadingMemory, PolynomialFilter};
    /// use seqsmooth::polynomial::SwitchRule;
    /// let mut f = FadingMemory::new(1, 0.9, 1.0, Engine::Gain).unwrap()
    ///     .with_switch_rule(SwitchRule::AtSample(10)).unwrap();
    /// for n in 0..20 { f.update(n as f64, n as f64).unwrap(); }
    /// assert_eq!(f.switched_at(), Some(10));
    /// ```
    pub fn with_switch_rule(mut self, rule: SwitchRule) -> Result<Self, Error> {
        rule.switch_index(self.m, self.theta)?;
        self.rule = rule;
        self.rebuild()?;
        Ok(self)
    }

    /// Tracks the covariance of the estimate for white measurement noise of standard deviation
    /// `sigma` (exact for the engine's estimator, including the start-up).
    ///
    /// ```
    /// use seqsmooth::{Engine, FadingMemory, PolynomialFilter};
    /// let mut f = FadingMemory::new(0, 0.5, 1.0, Engine::Exact).unwrap().with_noise_sigma(1.0).unwrap();
    /// for n in 0..200 { f.update(n as f64, 1.0).unwrap(); }
    /// let var = f.estimate().unwrap().covariance.unwrap()[(0, 0)];
    /// assert!((var - 1.0 / 3.0).abs() < 1e-12); // (1−θ)/(1+θ)
    /// ```
    pub fn with_noise_sigma(mut self, sigma: f64) -> Result<Self, Error> {
        check_no_prior(self.prior.as_ref())?;
        self.core.track_covariance(sigma)?;
        self.sigma = Some(sigma);
        Ok(self)
    }

    /// Starts from `prior` ([`Prior`]: the derivatives at `t₀` and their covariance) instead
    /// of from no information: the fading-memory Bayes filter ((14.4.26)-(14.4.32)), the
    /// prior discounted like a sample at `t₀`; the first sample may be at `t₀`. Needs the
    /// exact engine and the noise σ ([`Self::with_noise_sigma`], first: it weighs the prior
    /// against the samples), before any sample.
    ///
    /// ```
    /// use nalgebra::DMatrix;
    /// use seqsmooth::polynomial::prior::Prior;
    /// use seqsmooth::{Engine, FadingMemory, PolynomialFilter};
    /// let prior = Prior::new(0.0, vec![1.0, 0.5], DMatrix::identity(2, 2)).unwrap();
    /// let mut f = FadingMemory::new(1, 0.9, 1.0, Engine::Exact).unwrap()
    ///     .with_noise_sigma(1.0).unwrap()
    ///     .with_prior(&prior).unwrap();
    /// let s = f.estimate_at(0.0).unwrap(); // determined before any sample: the prior
    /// assert!((s.derivatives[0] - 1.0).abs() < 1e-14 && (s.derivatives[1] - 0.5).abs() < 1e-14);
    /// f.update(1.0, 1.5).unwrap(); // one sample, on the prior's line: still on it
    /// assert!((f.estimate().unwrap().derivatives[0] - 1.5).abs() < 1e-14);
    /// assert!(FadingMemory::new(1, 0.9, 1.0, Engine::Gain).unwrap()
    ///     .with_noise_sigma(1.0).unwrap().with_prior(&prior).is_err()); // fixed gains: no prior
    /// ```
    pub fn with_prior(mut self, prior: &Prior) -> Result<Self, Error> {
        self.core.set_prior(self.m, prior)?;
        self.prior = Some(prior.clone());
        Ok(self)
    }

    /// `θ`.
    ///
    /// ```
    /// use seqsmooth::{Engine, FadingMemory};
    /// assert_eq!(FadingMemory::new(1, 0.9, 1.0, Engine::Exact).unwrap().theta(), 0.9);
    /// ```
    pub fn theta(&self) -> f64 {
        self.theta
    }

    /// `τ`.
    ///
    /// ```
    /// use seqsmooth::{Engine, FadingMemory};
    /// assert_eq!(FadingMemory::new(1, 0.9, 0.25, Engine::Exact).unwrap().tau(), 0.25);
    /// ```
    pub fn tau(&self) -> f64 {
        self.tau
    }

    /// The 0-based index of the first sample the gain engine processed with the fading-memory
    /// gains: `None` before the switch and on the exact engine (which needs no start-up).
    ///
    /// ```
    /// use seqsmooth::{Engine, FadingMemory, PolynomialFilter};
    /// let mut f = FadingMemory::new(1, 0.9, 1.0, Engine::Gain).unwrap();
    /// for n in 0..40 { f.update(n as f64, 0.0).unwrap(); }
    /// assert_eq!(f.switched_at(), Some(32)); // Morrison (13.8.8)
    /// ```
    pub fn switched_at(&self) -> Option<u64> {
        match &self.core {
            EngineState::Gain(g) => g.switched_at(),
            EngineState::Exact(_) => None,
        }
    }
}

impl_polynomial_filter!(FadingMemory);

impl FadingMemory {
    /// The invariants of a restored filter ([`crate::persist`]): θ and τ in range, the engine
    /// of the filter's degree.
    pub(crate) fn check_saved(&self) -> Result<(), String> {
        if !(self.theta > 0.0 && self.theta < 1.0 && self.tau.is_finite() && self.tau > 0.0) {
            return Err(format!(
                "θ {} or τ {} is out of range",
                self.theta, self.tau
            ));
        }
        self.core.check_saved(self.m)
    }
}
