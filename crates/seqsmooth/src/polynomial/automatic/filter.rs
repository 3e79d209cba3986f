//! [`AutomaticFilter`]: the filters it runs, its builders, and one update — prediction,
//! innovation, gate, acceptance — delegating the gate ([`super::outlier`]), the noise estimate
//! ([`super::noise`]), the restart ([`super::misfit`]), the degree ladder ([`super::settle`]) and
//! the switch ([`super::phase`]) to their modules.

use super::config::AutoConfig;
use super::memory::Shorter;
use super::misfit::Kept;
#[cfg(doc)]
use super::misfit::MisfitResponse;
use super::noise::NoiseState;
use super::outlier::Judged;
use super::output::{AutoOutput, Withheld};
use super::phase::Phase;
use super::review::Review;
use crate::error::Error;
use crate::model::PolynomialState;
use crate::polynomial::expanding::ExpandingMemory;
use crate::polynomial::fading::FadingMemory;
use crate::polynomial::filter::PolynomialFilter;
use crate::stats::{ChiSquaredOutcome, InnovationChiSquared};
use std::collections::VecDeque;

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
#[derive(Clone, Debug)]
pub struct AutomaticFilter {
    pub(super) cfg: AutoConfig,
    /// Expanding-memory filters of the ladder, indexed by degree `< m` (`None` once passed).
    pub(super) ladder: Vec<Option<ExpandingMemory>>,
    /// The final-degree expanding-memory filter of the current memory, until the switch.
    pub(super) expanding: Option<ExpandingMemory>,
    /// The final-degree fading-memory filter of the current memory.
    pub(super) fading: FadingMemory,
    /// Degree `m + 1` companions of `expanding` and `fading` on the same samples (for the bias
    /// of the final degree; `None` at `m = MAX_DEGREE`, the expanding one after the switch).
    pub(super) upper_expanding: Option<ExpandingMemory>,
    pub(super) upper_fading: Option<FadingMemory>,
    /// The shorter memories `θ^(2^j)`, `j = 1 … J`, of the final degree ([`super::memory`]).
    pub(super) shorter: Vec<Shorter>,
    /// The memory in use (0: the configured `θ`).
    pub(super) memory: usize,
    /// Predictions in a row for which a longer memory had the least estimated error.
    pub(super) longer_runs: usize,
    /// Each memory's prediction of the newest sample and its honest mean square.
    pub(super) predictions: Vec<Option<(f64, f64)>>,
    /// Each memory's running mean of `ν²/σ_ε²` and its count ([`super::memory`]).
    pub(super) calibration: Vec<(f64, u64)>,
    pub(super) active: usize,
    /// Global index (accepted samples) of the latest expanding → fading switch.
    pub(super) switched_at: Option<u64>,
    /// The current memory has switched to fading.
    pub(super) switched: bool,
    /// Time of the first sample of the current final-degree memory.
    pub(super) memory_t_first: Option<f64>,
    /// `c` of a constant switch rule (`n_s = ⌊c/(1-θ)⌋`), and `c_0m` for Reyneke's `N`.
    pub(super) switch_constant: Option<f64>,
    pub(super) memory_constant: f64,
    pub(super) accepted: u64,
    pub(super) rejected: u64,
    pub(super) restarts: u64,
    pub(super) last_restart: Option<u64>,
    pub(super) last_time: Option<f64>,
    pub(super) noise: NoiseState,
    pub(super) chi: InnovationChiSquared,
    pub(super) restart_test: Option<InnovationChiSquared>,
    /// The newest accepted samples (for a restart).
    pub(super) recent: VecDeque<Kept>,
    /// The current run of rejected samples.
    pub(super) pending: Vec<Kept>,
    /// Consecutive updates the candidate's top derivative stayed within its 1σ.
    pub(super) stable_runs: usize,
    pub(super) prev_top: Option<f64>,
    /// The output of the newest update.
    pub(super) last_output: Option<AutoOutput>,
    /// The innovations' mean square excess over their noise-only variance in the misfit
    /// window, `max(0, mean(k²) − 1)·σ²(1 + v)` (value units²), at the newest sample.
    pub(super) excess: f64,
    /// The samples waiting for their final outlier decision ([`super::review`]).
    pub(super) review: Review,
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
        &self.cfg
    }

    /// The final degree `m`.
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// assert_eq!(AutomaticFilter::new(3, 0.9, 1.0).unwrap().degree(), 3);
    /// ```
    pub fn degree(&self) -> usize {
        self.cfg.degree
    }

    /// The active degree (below `m` while the ladder settles).
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// assert_eq!(AutomaticFilter::new(3, 0.9, 1.0).unwrap().active_degree(), 0);
    /// ```
    pub fn active_degree(&self) -> usize {
        self.active
    }

    /// Which filter is active.
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::{AutomaticFilter, Phase};
    /// let f = AutomaticFilter::new(1, 0.9, 1.0).unwrap().with_start_degree(1).unwrap();
    /// assert_eq!(f.phase(), Phase::Expanding);
    /// ```
    pub fn phase(&self) -> Phase {
        if self.active < self.cfg.degree {
            Phase::Settling
        } else if !self.switched && self.memory == 0 {
            Phase::Expanding
        } else {
            Phase::Fading
        }
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
        self.accepted
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
        self.rejected
    }

    /// Restarts of the final-degree memory ([`MisfitResponse::Restart`]); see the example there.
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// assert_eq!(AutomaticFilter::new(1, 0.9, 1.0).unwrap().restarts(), 0);
    /// ```
    pub fn restarts(&self) -> u64 {
        self.restarts
    }

    /// The index (in accepted samples) of the newest sample when the latest restart happened;
    /// see [`MisfitResponse::Restart`].
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// assert_eq!(AutomaticFilter::new(1, 0.9, 1.0).unwrap().last_restart(), None);
    /// ```
    pub fn last_restart(&self) -> Option<u64> {
        self.last_restart
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
        self.last_time
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
        self.switched_at
    }

    /// The noise `σ` in use: the given one, or the running estimate once it has
    /// [`MIN_NOISE_TERMS`](super::MIN_NOISE_TERMS) terms.
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// assert_eq!(AutomaticFilter::new(1, 0.9, 1.0).unwrap().noise_sigma(), None);
    /// ```
    pub fn noise_sigma(&self) -> Option<f64> {
        self.noise.sigma()
    }

    /// True while the innovation chi-squared window exceeds its threshold (see
    /// [`MisfitResponse::Flag`]).
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// assert!(!AutomaticFilter::new(1, 0.9, 1.0).unwrap().is_misfit());
    /// ```
    pub fn is_misfit(&self) -> bool {
        self.chi.is_misfit()
    }

    pub(super) fn final_filter(&self) -> &dyn PolynomialFilter {
        self.memory_filter(self.memory)
    }

    pub(super) fn filter(&self, degree: usize) -> Option<&dyn PolynomialFilter> {
        if degree < self.cfg.degree {
            self.ladder[degree]
                .as_ref()
                .map(|f| f as &dyn PolynomialFilter)
        } else {
            Some(self.final_filter())
        }
    }

    pub(super) fn active_filter(&self) -> &dyn PolynomialFilter {
        self.filter(self.active)
            .unwrap_or_else(|| self.final_filter())
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
        let s = self.active_filter().try_estimate_at(t)?;
        self.check_sigma()?;
        self.honest(s).0.checked()
    }

    /// No estimate without its σ: [`Error::NotDetermined`] naming [`Withheld::NoiseUnknown`]'s
    /// reason while `σ` is neither given nor estimated yet.
    fn check_sigma(&self) -> Result<(), Error> {
        match self.noise_sigma() {
            Some(_) => Ok(()),
            None => Err(Error::NotDetermined {
                samples: self.accepted,
                why: format!(
                    "{}: the estimate is given with its σ, after {} samples",
                    Withheld::NoiseUnknown.reason(),
                    Withheld::noise_samples(self.cfg.degree)
                ),
            }),
        }
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
        let s = self.active_filter().try_estimate()?;
        self.check_sigma()?;
        self.honest(s).0.checked()
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
        self.decide_all()
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
        crate::error::check_sample(t, y, self.last_time)?;
        // With the input checked, the steps below cannot fail on the data; should an internal
        // step still fail, go back to the state before the sample so that an error never
        // leaves a half update ([`Self::recover`]). The state before one sample in eight is
        // kept: what its review may go back to.
        let before = self.review.keeps_next().then(|| self.snapshot());
        match self.step(t, y, None) {
            Ok(out) => {
                self.last_output = Some(self.review(t, y, out, before));
                Ok(())
            }
            Err(e) => {
                self.recover(before);
                Err(e)
            }
        }
    }

    /// One sample through the gate and the filters; `force` overrides the gate's verdict (a
    /// review's decision, taken again: a forced rejection is final, not part of a run).
    pub(super) fn step(
        &mut self,
        t: f64,
        y: f64,
        force: Option<bool>,
    ) -> Result<AutoOutput, Error> {
        self.last_time = Some(t);
        let m = self.cfg.degree;
        if self.switch_due(t)? {
            self.switched = true;
            self.switched_at = Some(self.accepted);
            self.expanding = None;
            self.upper_expanding = None;
        }
        let Judged {
            sigma,
            innovation,
            vrf,
            innovation_sigma,
            k2,
            gate,
            rejected,
        } = self.judge(t, y);
        let rejected = force.unwrap_or(rejected);
        let mut manoeuvre = false;
        let mut restart = false;
        let mut chi_out = None;
        let mut reinstated = 0;
        if rejected && force.is_some() {
            self.pending.clear();
            self.rejected += 1;
        } else if rejected {
            self.pending.push(Kept { t, y, k2 });
            let limit = self.cfg.max_consecutive_rejections;
            if limit > 0 && (self.pending.len() >= limit || self.same_side_run()) {
                // A run of rejections: the model, not the samples, is wrong. Apply the run.
                manoeuvre = true;
                let run = std::mem::take(&mut self.pending);
                // The earlier members of the run were counted as rejections; they are not.
                reinstated = run.len() - 1;
                self.rejected -= reinstated as u64;
                for p in run {
                    chi_out = self.accept(p, None, true, false)?.or(chi_out);
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
            // The innovation noise estimate sees the samples the noise-only gate g₀ (the rule
            // without the bias) passes, with its truncation in units of σ√(1 + v); a sample
            // accepted only because the gate includes the estimated bias is left out of it. The
            // difference estimate sees every accepted sample, with the truncation of the gate
            // that passed it (its noise e is cut at [−g − b, g − b], near side at least
            // √(k² − 1)/k of g₀), and screens outliers itself.
            let noise_gate = if self.noise.wants_innovations() {
                self.gate(sigma, vrf, 0.0, t)
            } else {
                gate
            };
            let truncation = match (noise_gate, sigma, vrf) {
                (Some(g), Some(s), Some(v)) if s > 0.0 => Some((g / (s * (1.0 + v).sqrt()), v)),
                _ => None,
            };
            let beyond_noise = match (noise_gate, innovation) {
                (Some(g), Some(nu)) => nu.abs() > g,
                _ => false,
            };
            chi_out = self.accept(Kept { t, y, k2 }, truncation, false, beyond_noise)?;
            self.calibrate(y);
            if self.active == m && self.restart_test.as_ref().is_some_and(|r| r.is_misfit()) {
                self.restart()?;
                restart = true;
            }
        }
        let outlier = rejected && !manoeuvre;
        let raw = if outlier {
            self.active_filter().estimate_at(t)
        } else {
            self.active_filter().estimate()
        };
        // Right or refused: no estimate without its σ, and an estimate with a number beyond
        // the double range is none (`try_estimate_at` names it); `withheld` says which.
        let (estimate, bias, withheld) = match (raw, self.noise_sigma()) {
            (_, None) => (None, None, Some(Withheld::NoiseUnknown)),
            (None, _) => (None, None, Some(Withheld::NotDetermined)),
            (Some(raw), Some(_)) => {
                let (s, b) = self.honest(raw);
                match s.checked() {
                    Ok(s) => (Some(s), b.filter(|b| b.iter().all(|v| v.is_finite())), None),
                    Err(_) => (None, None, Some(Withheld::OutOfRange)),
                }
            }
        };
        Ok(AutoOutput {
            time: t,
            estimate,
            withheld,
            degree: self.active,
            phase: self.phase(),
            noise_sigma: self.noise_sigma(),
            innovation,
            innovation_sigma,
            gate,
            bias,
            outlier,
            misfit: manoeuvre || restart || self.chi.is_misfit(),
            manoeuvre,
            reinstated,
            restart,
            chi_squared: chi_out,
            decided: Vec::new(),
        })
    }

    /// Applies an accepted sample to every filter, the noise estimate and the misfit window;
    /// then lets the ladder step up. `truncation` is `(a, v)`, the gate half-width in units of
    /// `σ_ε` and the prediction VRF, when the gate was active (the noise estimates correct for
    /// the truncation); `manoeuvre` marks a run of rejections applied after all (left out of the
    /// innovation noise estimate); `unseen` leaves the sample out of every noise estimate.
    fn accept(
        &mut self,
        sample: Kept,
        truncation: Option<(f64, f64)>,
        manoeuvre: bool,
        unseen: bool,
    ) -> Result<Option<ChiSquaredOutcome>, Error> {
        let Kept { t, y, k2 } = sample;
        // The final-degree filter's own normalised innovation ν²/(1+v), whatever degree is
        // active (for the innovation noise estimate).
        let innovation = if self.noise.wants_innovations() {
            self.memory_filter(0).estimate_at(t).and_then(|p| {
                let v = p.covariance.as_ref()?[(0, 0)].max(0.0);
                let nu = y - p.derivatives[0];
                Some(nu * nu / (1.0 + v))
            })
        } else {
            None
        };
        if !unseen {
            self.noise.push(t, y, innovation, truncation, manoeuvre)?;
        }
        for f in self.ladder.iter_mut().flatten() {
            f.update(t, y)?;
        }
        if let Some(f) = &mut self.expanding {
            f.update(t, y)?;
        }
        self.fading.update(t, y)?;
        if let Some(f) = &mut self.upper_expanding {
            f.update(t, y)?;
        }
        if let Some(f) = &mut self.upper_fading {
            f.update(t, y)?;
        }
        for s in &mut self.shorter {
            s.fading.update(t, y)?;
            s.upper.update(t, y)?;
        }
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
        self.active_filter().is_determined() && self.noise_sigma().is_some()
    }
}
