//! [`ExpandingMemory`]: the expanding-memory polynomial filter (Morrison ch. 9).

use crate::error::Error;
use crate::model::PolynomialState;
use crate::polynomial::engine::{impl_polynomial_filter, EngineState, ExactEngine, GainEngine};
use crate::polynomial::filter::PolynomialFilter;
use crate::polynomial::options::{check_engine_degree, Engine};
use crate::polynomial::prior::{check_no_prior, Prior};

/// Expanding-memory polynomial filter of degree `m` (Morrison ch. 9; Reyneke §6.3-6.4): the
/// least-squares polynomial through all samples so far, with its derivatives, predictions and
/// (given the noise σ) covariance. Self-starting: determined from the `(m+1)`-th sample.
///
/// ```
/// use seqsmooth::{Engine, ExpandingMemory, PolynomialFilter};
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
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub struct ExpandingMemory {
    m: usize,
    prior: bool,
    core: EngineState,
}

// Field by field, `clone_from` too (the automatic filter's review keeps copies of it).
field_clone!(ExpandingMemory { m, prior, core });

impl ExpandingMemory {
    /// Becomes the degree-`m` filter of `upper`'s samples (`upper` of degree `m + 1`, the same
    /// settings) from `upper`'s leading block, instead of updating with them itself: the same
    /// least squares up to rounding (the exact engine's `ExactEngine::leading_into`, crate
    /// private). `false` (and `self` untouched: update it with the sample instead) unless
    /// both run the exact engine with matching settings and no prior.
    pub(crate) fn follow_leading(&mut self, upper: &ExpandingMemory) -> bool {
        self.m + 1 == upper.m
            && !self.prior
            && !upper.prior
            && upper.core.leading_into(&mut self.core)
    }
}

impl ExpandingMemory {
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

    /// A filter of degree `m` on the given engine.
    ///
    /// ```
    /// use seqsmooth::{Engine, Error, ExpandingMemory, PolynomialFilter};
    /// let f = ExpandingMemory::new(2, Engine::Exact).unwrap();
    /// assert_eq!((f.degree(), f.samples()), (2, 0));
    /// assert!(matches!(ExpandingMemory::new(99, Engine::Exact), Err(Error::DegreeOutOfRange { .. })));
    /// ```
    pub fn new(m: usize, engine: Engine) -> Result<Self, Error> {
        check_engine_degree(m, engine)?;
        let core = match engine {
            Engine::Exact => EngineState::Exact(ExactEngine::new(m, None)),
            // The gain engine's output does not depend on τ for expanding memory; τ = 1.
            Engine::Gain => EngineState::Gain(GainEngine::new(m, 1.0, None)),
        };
        Ok(Self {
            m,
            prior: false,
            core,
        })
    }

    /// Tracks the covariance of the estimate for white measurement noise of standard deviation
    /// `sigma`: exact for the engine's estimator on any timestamps.
    ///
    /// ```
    /// use seqsmooth::{Engine, ExpandingMemory, PolynomialFilter};
    /// let mut f = ExpandingMemory::new(0, Engine::Exact).unwrap().with_noise_sigma(2.0).unwrap();
    /// for n in 0..4 { f.update(n as f64, 1.0).unwrap(); }
    /// let var = f.estimate().unwrap().covariance.unwrap()[(0, 0)];
    /// assert!((var - 1.0).abs() < 1e-12); // σ²/4
    /// ```
    pub fn with_noise_sigma(mut self, sigma: f64) -> Result<Self, Error> {
        check_no_prior(self.prior.then_some(&()))?;
        self.core.track_covariance(sigma)?;
        Ok(self)
    }

    /// Starts from `prior` ([`Prior`]: the derivatives at `t₀` and their covariance) instead
    /// of from no information: the Bayes filter (Morrison ch. 10, (10.3.8) with
    /// `(S_{1,0})⁻¹ = P⁻¹`), whose estimate is the least-squares fit with the prior as `m + 1`
    /// more observations; the first sample may be at `t₀`. Needs the exact engine and the
    /// noise σ ([`Self::with_noise_sigma`], first: it weighs the prior against the samples),
    /// before any sample.
    ///
    /// ```
    /// use nalgebra::DMatrix;
    /// use seqsmooth::polynomial::prior::Prior;
    /// use seqsmooth::{Engine, ExpandingMemory, PolynomialFilter};
    /// // A constant known to variance 1, one sample of variance 1: their mean.
    /// let prior = Prior::new(0.0, vec![2.0], DMatrix::identity(1, 1)).unwrap();
    /// let mut f = ExpandingMemory::new(0, Engine::Exact).unwrap()
    ///     .with_noise_sigma(1.0).unwrap()
    ///     .with_prior(&prior).unwrap();
    /// f.update(0.0, 4.0).unwrap();
    /// let s = f.estimate().unwrap();
    /// assert!((s.derivatives[0] - 3.0).abs() < 1e-14);
    /// assert!((s.covariance.unwrap()[(0, 0)] - 0.5).abs() < 1e-14);
    /// ```
    pub fn with_prior(mut self, prior: &Prior) -> Result<Self, Error> {
        self.core.set_prior(self.m, prior)?;
        self.prior = true;
        Ok(self)
    }
}

impl_polynomial_filter!(ExpandingMemory);

impl ExpandingMemory {
    /// The invariants of a restored filter ([`crate::persist`]).
    pub(crate) fn check_saved(&self) -> Result<(), String> {
        self.core.check_saved(self.m)
    }
}
