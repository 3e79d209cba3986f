//! [`State`]: everything one update of the automatic filter changes — the parts, each owning
//! its own state (the degree ladder [`Ladder`], the final degree's memories [`Memories`], the
//! noise estimate [`NoiseState`], the misfit tests [`Misfit`], the run of rejections [`Run`]) —
//! and the update itself: prediction, innovation, gate, acceptance (Morrison §14.8), and the
//! estimate with its honest covariance ([`super::bias`]). The review ([`super::review`]) keeps
//! copies of it to go back to.

use super::bias::{self, at_least, difference_bias, innovation_excess, position_bias};
use super::config::AutoConfig;
use super::memory::Memories;
use super::misfit::{Kept, Misfit};
use super::noise::NoiseState;
use super::outlier::{gate_width, Judged, Run};
use super::output::{AutoOutput, Reported, Withheld};
use super::phase::Phase;
use super::review::Replay;
use super::settle::Ladder;
use crate::error::Error;
use crate::model::PolynomialState;
use crate::numeric::sigma::std_dev;
use crate::polynomial::filter::PolynomialFilter;
use crate::polynomial::options::MAX_DEGREE;
use crate::stats::ChiSquaredOutcome;

/// The automatic filter's state without its review (what a review's decision goes back to).
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub(super) struct State {
    cfg: AutoConfig,
    ladder: Ladder,
    memories: Memories,
    noise: NoiseState,
    misfit: Misfit,
    run: Run,
    accepted: u64,
    last_time: Option<f64>,
    /// The innovations' mean square excess over their noise-only variance in the misfit
    /// window, `max(0, mean(k²) − 1)·σ²(1 + v)` (value units²), at the newest sample.
    excess: f64,
    /// The row runner's path ([`Rows`]): not saved, not copied.
    #[serde(skip)]
    rows: Rows,
}

/// The row runner's path (`AutomaticFilter::update_row`): while `on`, an update reports its
/// estimate as [`Reported`] (derivatives, 1σ, `b₀`: what the rows write) instead of the
/// [`AutoOutput::estimate`] with its covariance matrix, where the filters answer without
/// allocating; the output then has neither an estimate nor a reason why not, and
/// [`State::report`] gives the full one on request (the state unchanged since). A copy of the
/// state (the review's kept states, its replays) starts with the path off and nothing
/// reported: the row runner sets it again before each update.
#[derive(Debug, Default)]
struct Rows {
    on: bool,
    /// The newest update reported `reported` (else it is stale).
    valid: bool,
    reported: Reported,
}

impl Clone for Rows {
    fn clone(&self) -> Self {
        Self::default()
    }
    fn clone_from(&mut self, _: &Self) {
        *self = Self::default();
    }
}

// Field by field, `clone_from` too: a kept copy of the state (the review's) is taken again
// into the buffers it has.
field_clone!(State {
    cfg,
    ladder,
    memories,
    noise,
    misfit,
    run,
    accepted,
    last_time,
    excess,
    rows
});

impl State {
    /// The state of a checked configuration before the first sample.
    pub(super) fn new(cfg: AutoConfig) -> Result<Self, Error> {
        let m = cfg.degree;
        let keep = cfg.misfit_window.max(2 * (m + 1));
        let misfit = Misfit::new(
            cfg.misfit_window,
            cfg.misfit_alpha,
            cfg.misfit_response,
            keep,
        )?;
        let ladder = Ladder::new(&cfg)?;
        let memories = Memories::new(&cfg)?;
        let noise = NoiseState::new(cfg.noise_sigma, cfg.noise_source, m, cfg.noise_screen)?;
        Ok(Self {
            cfg,
            ladder,
            memories,
            noise,
            misfit,
            run: Run::default(),
            accepted: 0,
            last_time: None,
            excess: 0.0,
            rows: Rows::default(),
        })
    }

    pub(super) fn config(&self) -> &AutoConfig {
        &self.cfg
    }

    pub(super) fn active_degree(&self) -> usize {
        self.ladder.active()
    }

    pub(super) fn accepted(&self) -> u64 {
        self.accepted
    }

    pub(super) fn rejected(&self) -> u64 {
        self.run.rejected()
    }

    pub(super) fn restarts(&self) -> u64 {
        self.misfit.restarts()
    }

    pub(super) fn last_restart(&self) -> Option<u64> {
        self.misfit.last_restart()
    }

    pub(super) fn last_time(&self) -> Option<f64> {
        self.last_time
    }

    pub(super) fn switched_at(&self) -> Option<u64> {
        self.memories.switched_at()
    }

    pub(super) fn memory(&self) -> usize {
        self.memories.in_use()
    }

    pub(super) fn noise_sigma(&self) -> Option<f64> {
        self.noise.sigma()
    }

    pub(super) fn is_misfit(&self) -> bool {
        self.misfit.is_misfit()
    }

    /// Which filter is active.
    pub(super) fn phase(&self) -> Phase {
        if !self.ladder.settled() {
            Phase::Settling
        } else if !self.memories.switched() && self.memories.in_use() == 0 {
            Phase::Expanding
        } else {
            Phase::Fading
        }
    }

    fn final_filter(&self) -> &dyn PolynomialFilter {
        self.memories.filter(self.memories.in_use())
    }

    fn filter(&self, degree: usize) -> Option<&dyn PolynomialFilter> {
        if degree < self.cfg.degree {
            self.ladder
                .filter(degree)
                .map(|f| f as &dyn PolynomialFilter)
        } else {
            Some(self.final_filter())
        }
    }

    pub(super) fn active_filter(&self) -> &dyn PolynomialFilter {
        self.filter(self.ladder.active())
            .unwrap_or_else(|| self.final_filter())
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

    /// The honest estimate at `t` from the active filter, or why there is none.
    pub(super) fn try_estimate_at(&self, t: f64) -> Result<PolynomialState, Error> {
        let s = self.active_filter().try_estimate_at(t)?;
        self.check_sigma()?;
        self.honest(s).0.checked()
    }

    /// The honest estimate at the newest accepted sample, or why there is none.
    pub(super) fn try_estimate(&self) -> Result<PolynomialState, Error> {
        let s = self.active_filter().try_estimate()?;
        self.check_sigma()?;
        self.honest(s).0.checked()
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
        self.rows.valid = false;
        self.memories.switch_if_due(&self.cfg, t, self.accepted)?;
        let judged = self.judge(t, y);
        let (sigma, innovation, vrf) = (judged.sigma, judged.innovation, judged.vrf);
        let (k2, gate) = (judged.k2, judged.gate);
        let rejected = force.unwrap_or(judged.rejected);
        let mut manoeuvre = false;
        let mut restart = false;
        let mut chi_out = None;
        let mut reinstated = 0;
        if rejected && force.is_some() {
            self.run.reject_final();
        } else if rejected {
            self.run.push(Kept { t, y, k2 });
            let limit = self.cfg.max_consecutive_rejections;
            let same_side = self.cfg.same_side_rejections;
            if limit > 0
                && (self.run.len() >= limit || self.run.same_side(self.active_filter(), same_side))
            {
                // A run of rejections: the model, not the samples, is wrong. Apply the run;
                // its earlier members were counted as rejections; they are not.
                manoeuvre = true;
                let run = self.run.take();
                reinstated = run.len() - 1;
                for p in run {
                    chi_out = self.accept(p, None, true, false)?.or(chi_out);
                }
                if self.misfit.restarts_memory() && self.ladder.settled() {
                    self.restart()?;
                    restart = true;
                }
            } else {
                self.run.count();
            }
        } else {
            self.run.clear();
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
            self.memories.calibrate(y);
            if self.ladder.settled() && self.misfit.restart_due() {
                self.restart()?;
                restart = true;
            }
        }
        let outlier = rejected && !manoeuvre;
        let (estimate, bias, withheld) = if self.rows.on && self.report_row(outlier, t) {
            (None, None, None)
        } else {
            self.report(outlier, t)
        };
        Ok(AutoOutput {
            time: t,
            estimate,
            withheld,
            degree: self.ladder.active(),
            phase: self.phase(),
            noise_sigma: self.noise_sigma(),
            innovation,
            innovation_sigma: judged.innovation_sigma,
            gate,
            bias,
            outlier,
            misfit: manoeuvre || restart || self.misfit.is_misfit(),
            manoeuvre,
            reinstated,
            restart,
            chi_squared: chi_out,
            decided: Vec::new(),
        })
    }

    /// The reported estimate at `t` after the newest update (`outlier`: that sample was
    /// rejected, the estimate is the prediction across it), its bias and why there is none:
    /// the honest estimate ([`honest`](Self::honest)) of the active filter. Right or refused:
    /// no estimate without its σ, and an estimate with a number beyond the double range is
    /// none (`try_estimate_at` names it); `withheld` says which.
    pub(super) fn report(
        &self,
        outlier: bool,
        t: f64,
    ) -> (Option<PolynomialState>, Option<Vec<f64>>, Option<Withheld>) {
        let raw = if outlier {
            self.active_filter().estimate_at(t)
        } else {
            self.active_filter().estimate()
        };
        match (raw, self.noise_sigma()) {
            (_, None) => (None, None, Some(Withheld::NoiseUnknown)),
            (None, _) => (None, None, Some(Withheld::NotDetermined)),
            (Some(raw), Some(_)) => {
                let (s, b) = self.honest(raw);
                match s.checked() {
                    Ok(s) => (Some(s), b.filter(|b| b.iter().all(|v| v.is_finite())), None),
                    Err(_) => (None, None, Some(Withheld::OutOfRange)),
                }
            }
        }
    }

    /// [`report`](Self::report) as the rows need it, into `self.rows.reported`: the
    /// derivatives and the diagonal of the honest covariance `factor·(σ² V + b bᵀ)`, each
    /// number by the same operations in the same order as there (the active filter's and its
    /// companion's [`variances`](Memories::estimate_diagonal) without allocating, the bias of
    /// [`bias_of`](Self::bias_of), the diagonal of [`bias::honest`]). False (nothing
    /// reported) where that path does not answer or cannot tell the estimate within the
    /// double range from the diagonal: no `σ` yet, a filter not determined or on the gain
    /// engine, no companion, a number that is not finite or an honest variance above `1e300`
    /// (below it every entry `|C_ij| ≤ √(C_ii C_jj)` is finite); the caller takes
    /// [`report`](Self::report) then.
    fn report_row(&mut self, outlier: bool, t: f64) -> bool {
        const P: usize = MAX_DEGREE + 1;
        const LIMIT: f64 = 1e300;
        let Some(sigma) = self.noise_sigma() else {
            return false;
        };
        let active = self.active_filter();
        let p = active.degree() + 1;
        // `estimate()` is the estimate at the newest sample's time.
        let at = if outlier { Some(t) } else { active.last_time() };
        // Written in place: the derivatives into the row's own cells.
        let mut r = Reported::default();
        let (x, mut v) = (&mut r.derivatives, [0.0; P]);
        let (mut xu, mut vu) = ([0.0; P], [0.0; P]);
        let answered = at.is_some_and(|at| {
            self.active_diagonal(at, x, &mut v) && self.companion_variances(at, &mut xu, &mut vu)
        });
        // A derivative beyond the double range: the estimate is refused as not determined
        // (`try_estimate_at`), which the full path says.
        if !answered || !x[..p].iter().all(|x| x.is_finite()) {
            return false;
        }
        let mut b = [0.0; P];
        for i in 0..p {
            b[i] = position_bias((x[i], v[i]), (xu[i], vu[i]), sigma, bias::SIGNIFICANCE);
        }
        b[0] = at_least(b[0], self.excess.sqrt());
        let factor = self.memories.calibration_factor(self.ladder.settled());
        let s2 = sigma * sigma;
        for i in 0..p {
            let h = (v[i] * s2 + b[i] * b[i]) * factor;
            if h.is_nan() || h.abs() > LIMIT {
                return false;
            }
            r.std_devs[i] = std_dev(h);
        }
        if b[..p].iter().all(|b| b.is_finite()) {
            r.bias0 = b[0];
        }
        r.len = p;
        self.rows.reported = r;
        self.rows.valid = true;
        true
    }

    /// The row runner's path on or off for the next update ([`Rows`]).
    pub(super) fn set_rows(&mut self, on: bool) {
        self.rows.on = on;
    }

    /// What the newest update reported on the row runner's path ([`Rows`]), if it did.
    pub(super) fn reported(&self) -> Option<&Reported> {
        self.rows.valid.then_some(&self.rows.reported)
    }

    /// The active filter's estimate at `t`, its derivatives into `x` and its covariance's
    /// diagonal into `var`, the numbers of its `estimate_at` bit for bit, without allocating;
    /// false where that path does not answer.
    fn active_diagonal(&self, t: f64, x: &mut [f64], var: &mut [f64]) -> bool {
        let d = self.ladder.active();
        match self.ladder.filter(d).filter(|_| d < self.cfg.degree) {
            Some(f) => f.estimate_diagonal_at(t, x, var),
            None => (self.memories).estimate_diagonal(self.memories.in_use(), t, x, var),
        }
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
        let Kept { t, y, .. } = sample;
        // The final-degree filter's own normalised innovation ν²/(1+v), whatever degree is
        // active (for the innovation noise estimate).
        let innovation = if self.noise.wants_innovations() {
            self.memories.filter(0).estimate_at(t).and_then(|p| {
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
        self.ladder.update(t, y)?;
        self.memories.update(t, y)?;
        self.accepted += 1;
        let chi_out = self.misfit.push(sample)?;
        let last = self.memories.filter(self.memories.in_use());
        self.ladder
            .settle(&self.cfg, last, self.noise.sigma(), &mut self.misfit);
        Ok(chi_out)
    }

    /// Restarts the final-degree memories from the samples since the estimated onset of the
    /// misfit ([`Misfit::since_onset`]).
    fn restart(&mut self) -> Result<(), Error> {
        let kept = self.misfit.since_onset(self.cfg.degree);
        self.memories.rebuild(&kept)?;
        self.misfit.restarted(&kept, self.accepted);
        Ok(())
    }

    /// The prediction of the sample `(t, y)` by the memory of least estimated error, its
    /// innovation and honest `σ_ε`, and the gate's verdict (Morrison (14.8.1)-(14.8.4)).
    fn judge(&mut self, t: f64, y: f64) -> Judged {
        let settled = self.ladder.settled();
        let chosen = self
            .memories
            .choose(&self.cfg, t, self.noise.sigma(), settled);
        let sigma = self.noise_sigma();
        let prediction = match chosen {
            Some((position, _)) => position,
            None => self.active_position(t),
        };
        let (innovation, vrf) = match prediction {
            Some((x, v)) => (Some(y - x), Some(v.max(0.0))),
            None => (None, None),
        };
        self.excess = match (sigma, vrf) {
            (Some(s), Some(v)) => innovation_excess(self.misfit.chi(), s * s * (1.0 + v)),
            _ => 0.0,
        };
        // The prediction's estimated bias: the honest innovation variance σ²(1 + v) + b₀².
        let bias0 = match (prediction, sigma) {
            (Some(p), Some(s)) => self.position_bias_of(p, chosen.map(|c| c.1), t, s),
            _ => 0.0,
        };
        let k = self.cfg.outliers.multiplier();
        let bias0 = self
            .run
            .with_pending(self.active_filter(), k, bias0, innovation, sigma);
        let innovation_sigma = match (sigma, vrf) {
            (Some(s), Some(v)) => Some((s * s * (1.0 + v) + bias0 * bias0).sqrt()),
            _ => None,
        };
        // The misfit test judges the model: the innovation against its noise-only variance.
        let k2 = match (innovation, sigma, vrf) {
            (Some(nu), Some(s), Some(v)) if s > 0.0 => Some(nu * nu / (s * s * (1.0 + v))),
            _ => None,
        };
        let gate = self.gate(sigma, vrf, bias0, t);
        let rejected = match (gate, innovation) {
            (Some(g), Some(nu)) => nu.abs() > g,
            _ => false,
        };
        Judged {
            sigma,
            innovation,
            vrf,
            innovation_sigma,
            k2,
            gate,
            rejected,
        }
    }

    /// The gate half-width for the sample at `t` ([`gate_width`]).
    fn gate(&self, sigma: Option<f64>, vrf: Option<f64>, bias: f64, t: f64) -> Option<f64> {
        let settled = self.ladder.settled();
        gate_width(
            &self.cfg.outliers,
            self.cfg.gate_max_vrf,
            settled,
            (sigma, vrf),
            bias,
            || self.memory_length(t),
        )
    }

    /// Reyneke's memory length `N` at `t`: `c_0m/(1-θ_s)` once faded, else the active filter's
    /// sample count.
    fn memory_length(&self, t: f64) -> f64 {
        let faded = if self.ladder.settled() {
            self.memories.faded_length(&self.cfg, t)
        } else {
            None
        };
        faded.unwrap_or_else(|| self.active_filter().samples().max(1) as f64)
    }

    /// The active filter's position at `t` and its unit variance, without allocating.
    fn active_position(&self, t: f64) -> Option<(f64, f64)> {
        if self.ladder.settled() {
            self.memories.position(self.memories.in_use(), t)
        } else {
            self.ladder.filter(self.ladder.active())?.position_at(t)
        }
    }

    /// The filter of the active degree plus one on the active filter's memory: the next rung of
    /// the ladder, or the companion of the final degree's memory in use.
    fn companion(&self) -> Option<&dyn PolynomialFilter> {
        if self.ladder.settled() {
            self.memories.companion(self.memories.in_use())
        } else {
            self.filter(self.ladder.active() + 1)
        }
    }

    /// The position at `t` of the active filter's companion ([`companion`](Self::companion)).
    fn companion_position(&self, t: f64) -> Option<(f64, f64)> {
        let j = self.memories.in_use();
        let c = self.ladder.active() + 1;
        if self.ladder.settled() {
            self.memories.companion_position(j, t)
        } else if c < self.cfg.degree {
            self.ladder.filter(c)?.position_at(t)
        } else {
            self.memories.position(j, t)
        }
    }

    /// The derivatives at `t` of the active filter's companion ([`companion`](Self::companion))
    /// and their variances into `x` and `var`, without allocating on the exact engine; false
    /// when it is not determined (or has no such path: the caller takes its estimate).
    fn companion_variances(&self, t: f64, x: &mut [f64], var: &mut [f64]) -> bool {
        let j = self.memories.in_use();
        let c = self.ladder.active() + 1;
        if self.ladder.settled() {
            self.memories.companion_variances(j, t, x, var)
        } else if c < self.cfg.degree {
            self.ladder
                .filter(c)
                .is_some_and(|f| f.variances_at(t, x, var))
        } else {
            self.memories.variances(j, t, x, var)
        }
    }

    /// The position bias `b₀` of the active filter's position `(x, v)` at `t` (the first entry
    /// of [`bias_of`](Self::bias_of), without allocating): 0 while the companion is not
    /// determined. `companion`: the companion's position at `t` when already computed (the
    /// memory choice's).
    fn position_bias_of(
        &self,
        position: (f64, f64),
        companion: Option<Option<(f64, f64)>>,
        t: f64,
        sigma: f64,
    ) -> f64 {
        let upper = companion.unwrap_or_else(|| self.companion_position(t));
        let Some(upper) = upper else {
            return 0.0;
        };
        let b = position_bias(position, upper, sigma, bias::SIGNIFICANCE);
        at_least(b, self.excess.sqrt())
    }

    /// The estimated bias `b` (one entry per derivative of `raw`) of the active filter's unit
    /// noise state `raw` at its time, for noise `σ` ([`difference_bias`]), the position's
    /// raised to the innovations' excess. `None` when the companion is not determined.
    fn bias_of(&self, raw: &PolynomialState, sigma: f64) -> Option<Vec<f64>> {
        let mut xu = [0.0; MAX_DEGREE + 2];
        let mut vu = [0.0; MAX_DEGREE + 2];
        let mut b = if self.companion_variances(raw.time, &mut xu, &mut vu) {
            let vd = raw.covariance.as_ref()?;
            let upper = (0..raw.derivatives.len()).map(|i| (xu[i], vu[i]));
            raw.derivatives
                .iter()
                .enumerate()
                .zip(upper)
                .map(|((i, &x), u)| position_bias((x, vd[(i, i)]), u, sigma, bias::SIGNIFICANCE))
                .collect()
        } else {
            let upper = self.companion()?.estimate_at(raw.time)?;
            difference_bias(raw, &upper, sigma)?
        };
        b[0] = at_least(b[0], self.excess.sqrt());
        Some(b)
    }

    /// The reported state of a unit noise state `raw` of the active filter: covariance
    /// `σ² V + b bᵀ` with the bias of [`bias_of`](Self::bias_of) (widened by the memory's
    /// calibration), and that bias; without `σ` no covariance and no bias.
    fn honest(&self, raw: PolynomialState) -> (PolynomialState, Option<Vec<f64>>) {
        let Some(sigma) = self.noise_sigma() else {
            return (
                PolynomialState {
                    covariance: None,
                    ..raw
                },
                None,
            );
        };
        let bias = self.bias_of(&raw, sigma);
        let factor = self.memories.calibration_factor(self.ladder.settled());
        let mut raw = raw;
        bias::honest(&mut raw, sigma, bias.as_deref(), factor);
        (raw, bias)
    }
}

impl Replay for State {
    fn step(&mut self, t: f64, y: f64, force: Option<bool>) -> Result<AutoOutput, Error> {
        State::step(self, t, y, force)
    }
    fn noise_sigma(&self) -> Option<f64> {
        self.noise.sigma()
    }
    fn noise_is_early(&self) -> bool {
        self.noise.is_early()
    }
    fn end_run(&mut self) {
        self.run.clear();
    }
}

impl State {
    /// A restored state's invariants ([`crate::persist`]): every setting in range (the
    /// builders' checks), the ladder and the memories valid and of the degree.
    pub(super) fn check_saved(&self) -> Result<(), String> {
        let m = self.cfg.degree;
        if m > MAX_DEGREE {
            return Err(format!("degree {m} is out of range"));
        }
        self.cfg
            .validate()
            .map_err(|e| format!("a setting out of range: {e}"))?;
        self.ladder.check_saved(m)?;
        self.memories.check_saved(m)
    }
}
