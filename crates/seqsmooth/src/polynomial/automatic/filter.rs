//! [`AutomaticFilter`]: the update's state ([`super::state`]: the parts that own the filters,
//! the noise estimate, the gate's run, the misfit tests) and the review of each sample's
//! final outlier decision ([`super::review`]), composed; its public interface.

use super::config::AutoConfig;
#[cfg(doc)]
use super::misfit::MisfitResponse;
use super::output::AutoOutput;
#[cfg(doc)]
use super::output::Withheld;
use super::phase::Phase;
use super::review::Review;
use super::state::State;
use crate::error::Error;
use crate::model::PolynomialState;
use crate::polynomial::filter::PolynomialFilter;

/// The automatic polynomial filter (see the [module docs](crate::polynomial::automatic)).
/// Configured like the other filters: [`new`](Self::new) with the required
/// degree, `θ` and `τ`, then `with_*` builders, each checked. It implements
/// [`PolynomialFilter`]; the per-sample flags are in [`last_output`](Self::last_output).
///
/// ```
/// use seqsmooth::polynomial::automatic::{AutomaticFilter, Phase};
/// let mut f = AutomaticFilter::new(2, 0.9, 1.0).unwrap(); // σ estimated
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
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct AutomaticFilter {
    /// Everything an update changes (what the review goes back to).
    pub(super) state: State,
    /// The samples waiting for their final outlier decision ([`super::review`]).
    pub(super) review: Review<State>,
    /// The output of the newest update.
    pub(super) last_output: Option<AutoOutput>,
}

impl AutomaticFilter {
    /// The settings.
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// let f = AutomaticFilter::new(2, 0.9, 0.5).unwrap();
    /// assert_eq!((f.config().degree, f.config().theta, f.config().tau), (2, 0.9, 0.5));
    /// ```
    pub fn config(&self) -> &AutoConfig {
        self.state.config()
    }

    /// The final degree `m`.
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// assert_eq!(AutomaticFilter::new(3, 0.9, 1.0).unwrap().degree(), 3);
    /// ```
    pub fn degree(&self) -> usize {
        self.state.config().degree
    }

    /// The active degree (below `m` while the ladder settles).
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// assert_eq!(AutomaticFilter::new(3, 0.9, 1.0).unwrap().active_degree(), 0);
    /// ```
    pub fn active_degree(&self) -> usize {
        self.state.active_degree()
    }

    /// Which filter is active.
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::{AutomaticFilter, Phase};
    /// let f = AutomaticFilter::new(1, 0.9, 1.0).unwrap().with_start_degree(1).unwrap();
    /// assert_eq!(f.phase(), Phase::Expanding);
    /// ```
    pub fn phase(&self) -> Phase {
        self.state.phase()
    }

    /// Accepted samples (those that updated the state).
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// let mut f = AutomaticFilter::new(0, 0.9, 1.0).unwrap().with_noise_sigma(0.1).unwrap();
    /// for n in 0..40 {
    ///     f.update(n as f64, if n == 30 { 100.0 } else { 1.0 }).unwrap();
    /// }
    /// assert_eq!((f.samples(), f.rejected()), (39, 1)); // the spike at n = 30 was rejected
    /// ```
    pub fn samples(&self) -> u64 {
        self.state.accepted()
    }

    /// Samples rejected as outliers (not counting runs later applied as manoeuvres); see
    /// [`samples`](Self::samples).
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// let mut f = AutomaticFilter::new(0, 0.9, 1.0).unwrap().with_noise_sigma(0.1).unwrap();
    /// for n in 0..40 { f.update(n as f64, if n == 30 { 100.0 } else { 1.0 }).unwrap(); }
    /// assert_eq!(f.rejected(), 1);
    /// ```
    pub fn rejected(&self) -> u64 {
        self.state.rejected()
    }

    /// Restarts of the final-degree memory ([`MisfitResponse::Restart`]); see the example there.
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// assert_eq!(AutomaticFilter::new(1, 0.9, 1.0).unwrap().restarts(), 0);
    /// ```
    pub fn restarts(&self) -> u64 {
        self.state.restarts()
    }

    /// The index (in accepted samples) of the newest sample when the latest restart happened;
    /// see [`MisfitResponse::Restart`].
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// assert_eq!(AutomaticFilter::new(1, 0.9, 1.0).unwrap().last_restart(), None);
    /// ```
    pub fn last_restart(&self) -> Option<u64> {
        self.state.last_restart()
    }

    /// The time of the newest sample seen (accepted or rejected).
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// let mut f = AutomaticFilter::new(1, 0.9, 1.0).unwrap();
    /// assert_eq!(f.last_time(), None);
    /// f.update(2.5, 1.0).unwrap();
    /// assert_eq!(f.last_time(), Some(2.5));
    /// ```
    pub fn last_time(&self) -> Option<f64> {
        self.state.last_time()
    }

    /// The output of the newest [`update`](Self::update) (also when it came through
    /// [`PolynomialFilter`]): the estimate and the per-sample flags (outlier, misfit, noise `σ`
    /// in use, phase). `None` before the first sample.
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::{AutomaticFilter, Phase};
    /// use seqsmooth::PolynomialFilter;
    /// let mut f = AutomaticFilter::new(1, 0.9, 1.0).unwrap().with_noise_sigma(0.1).unwrap();
    /// assert!(f.last_output().is_none());
    /// let times: Vec<f64> = (0..60).map(f64::from).collect();
    /// let values: Vec<f64> = times.iter().map(|t| if *t == 50.0 { 9.0 } else { 0.5 * t }).collect();
    /// f.update_many(&times[..51], &values[..51]).unwrap(); // through the trait
    /// let out = f.last_output().unwrap();
    /// assert!(out.outlier && out.time == 50.0 && out.phase == Phase::Fading);
    /// assert_eq!(out.noise_sigma, Some(0.1));
    /// ```
    pub fn last_output(&self) -> Option<&AutoOutput> {
        self.last_output.as_ref()
    }

    /// The 0-based index, in accepted samples since the first, of the first sample the
    /// fading-memory filter produced the output for (the latest switch, after a restart);
    /// `None` before the switch. See [`Phase`].
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// let mut f = AutomaticFilter::new(1, 0.9, 1.0).unwrap().with_noise_sigma(1.0).unwrap();
    /// for n in 0..40 { f.update(n as f64, n as f64).unwrap(); }
    /// assert_eq!(f.switched_at(), Some(32)); // Morrison (13.8.8)
    /// ```
    pub fn switched_at(&self) -> Option<u64> {
        self.state.switched_at()
    }

    /// The noise `σ` in use: the given one, or the running estimate once it has
    /// [`MIN_NOISE_TERMS`](super::MIN_NOISE_TERMS) terms.
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// assert_eq!(AutomaticFilter::new(1, 0.9, 1.0).unwrap().noise_sigma(), None);
    /// ```
    pub fn noise_sigma(&self) -> Option<f64> {
        self.state.noise_sigma()
    }

    /// True while the innovation chi-squared window exceeds its threshold (see
    /// [`MisfitResponse::Flag`]).
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// assert!(!AutomaticFilter::new(1, 0.9, 1.0).unwrap().is_misfit());
    /// ```
    pub fn is_misfit(&self) -> bool {
        self.state.is_misfit()
    }

    /// The estimate at any time `t` from the active filter (a prediction after the newest
    /// accepted sample), with the covariance `σ²·VRF + b bᵀ` when `σ` is available: the noise's
    /// and the estimated bias `b` of the active degree (see the [module docs](super)).
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// let mut f = AutomaticFilter::new(1, 0.9, 1.0).unwrap().with_start_degree(1).unwrap();
    /// f.update(0.0, 1.0).unwrap();
    /// f.update(1.0, 3.0).unwrap();
    /// assert!(f.estimate_at(2.0).is_none()); // σ not known yet: no estimate without it
    /// let mut f = f.clone().with_noise_sigma(0.1);
    /// assert!(f.is_err()); // the settings are fixed once started
    /// let mut f = AutomaticFilter::new(1, 0.9, 1.0).unwrap().with_start_degree(1).unwrap();
    /// let mut f = f.with_noise_sigma(0.1).unwrap();
    /// f.update(0.0, 1.0).unwrap();
    /// f.update(1.0, 3.0).unwrap();
    /// assert!((f.estimate_at(2.0).unwrap().derivatives[0] - 5.0).abs() < 1e-12);
    /// ```
    pub fn estimate_at(&self, t: f64) -> Option<PolynomialState> {
        self.try_estimate_at(t).ok()
    }

    /// The estimate at `t`, or why there is none
    /// ([`PolynomialFilter::try_estimate_at`]): the active filter's reason, or a number of the
    /// honest covariance beyond the double range ([`Error::EstimateOutOfRange`]).
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// use seqsmooth::Error;
    /// let mut f = AutomaticFilter::new(1, 0.9, 1.0).unwrap().with_start_degree(1).unwrap();
    /// let mut f = f.with_noise_sigma(1e150).unwrap();
    /// assert!(matches!(f.try_estimate_at(0.0), Err(Error::TooFewSamples { .. })));
    /// f.update(0.0, 1.0).unwrap();
    /// f.update(1.0, 2.0).unwrap();
    /// assert!(f.try_estimate().is_ok());
    /// // a line from two samples, 1e6 steps ahead: variance ≈ 1e12·σ² = 1e312
    /// let e = f.try_estimate_at(1e6).unwrap_err();
    /// assert!(matches!(e, Error::EstimateOutOfRange { ref what } if what == "variance of d0"), "{e}");
    /// assert!(f.estimate_at(1e6).is_none());
    /// ```
    pub fn try_estimate_at(&self, t: f64) -> Result<PolynomialState, Error> {
        self.state.try_estimate_at(t)
    }

    /// The estimate at the newest accepted sample.
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// let mut f = AutomaticFilter::new(1, 0.9, 1.0).unwrap().with_noise_sigma(0.5).unwrap();
    /// assert!(f.estimate().is_none());
    /// f.update(0.0, 1.0).unwrap();
    /// assert_eq!(f.estimate().unwrap().derivatives, vec![1.0]);
    /// ```
    pub fn estimate(&self) -> Option<PolynomialState> {
        self.try_estimate().ok()
    }

    /// The estimate at the newest accepted sample, or why there is none
    /// ([`try_estimate_at`](Self::try_estimate_at)).
    pub fn try_estimate(&self) -> Result<PolynomialState, Error> {
        self.state.try_estimate()
    }

    /// Decides every sample still waiting for its final outlier decision (the end of a series;
    /// see [`AutoOutput::decided`]), with the samples there are: the review's window takes more
    /// samples before. Returns the decisions, oldest first; they follow the ones reported so
    /// far, in sample order. A decision that differs from the gate's takes the samples since
    /// again, so the estimate may change. Later samples may still follow.
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::{final_outliers, AutomaticFilter};
    /// let mut f = AutomaticFilter::new(1, 0.9, 1.0).unwrap().with_noise_sigma(0.1).unwrap();
    /// let mut outs = Vec::new();
    /// for n in 0..40 {
    ///     let y = 0.5 * n as f64 + if n == 38 { 3.0 } else { 0.0 };
    ///     outs.push(f.update(n as f64, y).unwrap());
    /// }
    /// let reported: usize = outs.iter().map(|o| o.decided.len()).sum();
    /// let tail = f.finish();
    /// assert_eq!(reported + tail.len(), 40);         // one decision per sample
    /// let flags = final_outliers(&outs, &tail);
    /// assert_eq!(flags.iter().filter(|&&r| r).count(), 1);
    /// assert!(flags[38]);
    /// ```
    pub fn finish(&mut self) -> Vec<bool> {
        self.review
            .decide_all(&mut self.state, self.last_output.as_mut())
    }

    /// Processes the sample `y` at time `t` (finite, strictly after the previous sample's time,
    /// rejected or not) and returns (and keeps, see [`last_output`](Self::last_output)) what it
    /// did. On error nothing changes.
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// use seqsmooth::Error;
    /// let mut f = AutomaticFilter::new(1, 0.9, 1.0).unwrap();
    /// f.update(0.0, 1.0).unwrap();
    /// assert!(matches!(f.update(0.0, 2.0), Err(Error::TimeNotIncreasing { .. })));
    /// assert!(matches!(f.update(1.0, f64::NAN), Err(Error::NonFinite { .. })));
    /// assert_eq!(f.samples(), 1);
    /// ```
    pub fn update(&mut self, t: f64, y: f64) -> Result<AutoOutput, Error> {
        self.update_kept(t, y)?;
        Ok(self.last_output.clone().expect("kept by the update"))
    }

    /// [`update`](Self::update) keeping the output in [`last_output`](Self::last_output) only
    /// (the trait's update: no copy of it).
    fn update_kept(&mut self, t: f64, y: f64) -> Result<(), Error> {
        crate::error::check_sample(t, y, self.state.last_time())?;
        // With the input checked, the steps below cannot fail on the data; should an internal
        // step still fail, go back to the state before the sample so that an error never
        // leaves a half update ([`Review::recover`]). The state before one sample in eight is
        // kept: what its review may go back to.
        let before = self.review.snapshot(&self.state);
        match self.state.step(t, y, None) {
            Ok(out) => {
                // The previous output's decisions vector, its allocation reused.
                let buffer = (self.last_output.as_mut())
                    .map_or_else(Vec::new, |o| std::mem::take(&mut o.decided));
                let out = (self.review).review(&mut self.state, (t, y), out, before, buffer);
                self.last_output = Some(out);
                Ok(())
            }
            Err(e) => {
                self.review.recover(&mut self.state, before);
                Err(e)
            }
        }
    }

    /// [`update`](Self::update) for the row runner (`AnyFilter::run_rows`, the rows of
    /// `seqsmooth filter` and of the Python package): the newest output keeps, in place of its
    /// estimate, what the rows write of it ([`reported`](Self::reported): derivatives, 1σ,
    /// `b₀`, the same numbers), where the filters give it without allocating; the caller
    /// calls [`complete_output`](Self::complete_output) before anyone else reads
    /// [`last_output`](Self::last_output).
    pub(crate) fn update_row(&mut self, t: f64, y: f64) -> Result<(), Error> {
        self.state.set_rows(true);
        let result = self.update_kept(t, y);
        self.state.set_rows(false);
        result
    }

    /// The newest [`update_row`](Self::update_row)'s reported estimate (`None`: the output
    /// has its full estimate, or none and the reason).
    pub(crate) fn reported(&self) -> Option<&super::output::Reported> {
        let out = self.last_output.as_ref()?;
        (out.estimate.is_none() && out.withheld.is_none())
            .then(|| self.state.reported())
            .flatten()
    }

    /// The newest output with its full estimate and bias where
    /// [`update_row`](Self::update_row) kept only what the rows write: computed now from the
    /// state, unchanged since that update, by the update's own path (the same numbers).
    pub(crate) fn complete_output(&mut self) {
        if let Some(out) = self.last_output.as_mut() {
            if out.estimate.is_none() && out.withheld.is_none() {
                let (estimate, bias, withheld) = self.state.report(out.outlier, out.time);
                (out.estimate, out.bias, out.withheld) = (estimate, bias, withheld);
            }
        }
    }

    /// The index `j` of the memory in use: the final degree's discount is `θ^(4^j)` per `τ`
    /// (0: the configured `θ`; see the [module docs](super) and
    /// [`AutoConfig::memory_levels`]).
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// let mut f = AutomaticFilter::new(1, 0.95, 1.0).unwrap().with_noise_sigma(0.1).unwrap();
    /// let mut shortest = 0;
    /// for n in 0..400 {
    ///     let t = n as f64;
    ///     // a straight line, then a turn (0.02 t² from t = 200) that degree 1 does not model
    ///     let y = 0.5 * t + if t > 200.0 { 0.02 * (t - 200.0).powi(2) } else { 0.0 };
    ///     f.update(t, y).unwrap();
    ///     if n == 199 { assert_eq!(f.memory(), 0); } // the line: the longest memory
    ///     shortest = shortest.max(f.memory());
    /// }
    /// assert!(shortest > 0); // the turn: a shorter memory
    /// ```
    pub fn memory(&self) -> usize {
        self.state.memory()
    }
}

/// The automatic filter through the common trait: the same estimates as its own methods
/// ([`AutomaticFilter::estimate`] is the estimate at the newest *accepted* sample), `samples`
/// counts accepted samples, and the estimates have the active degree's `d+1` derivatives
/// (fewer than `m+1` while the ladder settles). The flags of each sample are in
/// [`AutomaticFilter::last_output`].
///
/// ```
/// use seqsmooth::polynomial::automatic::AutomaticFilter;
/// use seqsmooth::PolynomialFilter;
/// let auto = AutomaticFilter::new(1, 0.9, 1.0).unwrap().with_noise_sigma(0.1).unwrap();
/// let mut f: Box<dyn PolynomialFilter> = Box::new(auto);
/// for n in 0..100 {
///     f.update(n as f64, 2.0 + 0.5 * n as f64).unwrap();
/// }
/// let s = f.estimate().unwrap();
/// assert!((s.derivatives[1] - 0.5).abs() < 1e-9 && f.is_determined() && f.samples() == 100);
/// ```
impl PolynomialFilter for AutomaticFilter {
    fn degree(&self) -> usize {
        AutomaticFilter::degree(self)
    }
    fn samples(&self) -> u64 {
        AutomaticFilter::samples(self)
    }
    fn update(&mut self, t: f64, y: f64) -> Result<(), Error> {
        self.update_kept(t, y)
    }
    fn estimate_at(&self, t: f64) -> Option<PolynomialState> {
        AutomaticFilter::estimate_at(self, t)
    }
    fn try_estimate_at(&self, t: f64) -> Result<PolynomialState, Error> {
        AutomaticFilter::try_estimate_at(self, t)
    }
    fn try_estimate(&self) -> Result<PolynomialState, Error> {
        AutomaticFilter::try_estimate(self)
    }
    fn last_time(&self) -> Option<f64> {
        AutomaticFilter::last_time(self)
    }
    fn estimate(&self) -> Option<PolynomialState> {
        AutomaticFilter::estimate(self)
    }
    /// The active filter is determined and `σ` is known (no estimate without its σ).
    fn is_determined(&self) -> bool {
        self.state.active_filter().is_determined() && self.noise_sigma().is_some()
    }
}

impl AutomaticFilter {
    /// A restored filter's invariants ([`crate::persist`]): its state and every state the
    /// review may go back to.
    pub(crate) fn check_saved(&self) -> Result<(), String> {
        self.state.check_saved()?;
        self.review.check_saved(|s| s.check_saved())
    }
}
