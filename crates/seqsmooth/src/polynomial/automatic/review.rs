//! Review: each sample's final outlier decision, made once `L` accepted samples after it are in
//! ([`AutoConfig::review_window`], default `m + 4`), by interpolation as well as prediction.
//!
//! The gate judges a sample against the 1-step prediction, whose mean square `σ_ε²` is large
//! where the filter must use a short memory (a manoeuvre): there the gate is off
//! ([`AutoConfig::gate_max_vrf`]) and outliers pass. Once samples on both sides are in, the
//! sample is judged again against a least-squares polynomial of degree `m + 1` through the `L`
//! nearest accepted samples before it and the `L` after (Morrison ch. 7: a fixed-memory fit
//! evaluated inside its window, where its VRF is least; one degree up so that a manoeuvre's
//! `(m+1)`-th derivative is modelled, Morrison (7.13.5)). The sample is left out of the fit
//! (its deleted residual), so an outlier does not pull the fit towards itself.
//!
//! | step | rule | source |
//! |---|---|---|
//! | gate decides at once | where the gate's `σ_ε` is at most `√(c σ²(1 + v_p))` of the fit through every neighbour, the gate's verdict stands and the steps below are skipped (dropping neighbours only raises `v_p`) | Morrison §7.13 |
//! | neighbours not caught yet | the fit drops up to two of its samples whose studentised residual `\|r_j\|/(σ√(1 − h_j))` exceeds `k`, the largest first (where the gate does not decide at once) | Morrison (6.10.24) |
//! | fit's bias at `t` | `b² = max(0, Δ² − σ²(v₊ − v_p))`, `Δ` against the fit one degree up on the same samples (not fitted where the gate decides whatever `b²` is) | Morrison (7.13.5), §13.9 |
//! | residuals not white | `c = max(1, Σ RSS/σ² / Σ(n − p))` over the last 20 windows ([`Calibration`]; a window the gate decides at once enters with every neighbour) | Morrison §14.8 |
//! | verdict | reject when `\|y − p(t)\| > k √(c σ²(1 + v_p) + b²)` (`k` the gate's multiplier) | Morrison §14.8 |
//! | judge | the gate's verdict stands where its `σ_ε` was at most the interpolation's root mean square (a long memory that fits), the interpolation's otherwise | Morrison §7.13 |
//!
//! Near the start the window takes more samples after; at the end of a series
//! ([`AutomaticFilter::finish`](super::AutomaticFilter::finish)) more before.
//!
//! When the verdict differs from the gate's, the filter goes back to its state before the
//! sample and takes the samples since again (the gate judging them anew): from then on the
//! state is what it would have been had the decision been made at the time. Each decision is
//! reported once, in the output of the update that made it ([`AutoOutput::decided`]); with
//! `L = 0` a decision is the gate's, final once a later sample is accepted (a run of rejections
//! applied as a manoeuvre's onset is not rejected). The measured rates are in ACCURACY.md.

use super::config::{AutoConfig, MAX_REVIEW_WINDOW};
use super::output::AutoOutput;
use super::window_fit::WindowFit;
use crate::error::Error;
use std::collections::VecDeque;

/// The most samples waiting for their decision after an update; beyond it the oldest keeps the
/// gate's (a long run of rejections with [`AutoConfig::max_consecutive_rejections`] off). An
/// update thus makes at most 64 decisions.
pub(super) const MAX_UNDECIDED: usize = 63;

/// One sample in eight keeps the update's state before it: going back restores the nearest kept
/// state at or before the sample and replays the kept samples from there (at most seven more
/// before it), so the review holds one or two copies of the state rather than one per sample
/// waiting.
const SNAPSHOT_EVERY: usize = 8;

/// Kept states no longer needed that the review holds for their buffers (the next kept state
/// is copied into one: no allocation).
const SPARE_STATES: usize = 2;

/// What the review goes back to and replays: the state one update changes (the filter without
/// its review, [`super::state::State`]).
pub(super) trait Replay: Clone {
    /// One sample through the gate and the filters; `force` overrides the gate's verdict (a
    /// decision taken again: a forced rejection is final, not part of a run).
    fn step(&mut self, t: f64, y: f64, force: Option<bool>) -> Result<AutoOutput, Error>;
    /// The noise `σ` in use.
    fn noise_sigma(&self) -> Option<f64>;
    /// The noise estimate is still the start-up one (the review waits for it).
    fn noise_is_early(&self) -> bool;
    /// Forgets the current run of rejections (the samples before a replay's sample are
    /// decided: none of them is part of a run).
    fn end_run(&mut self);
}

/// A sample of the review: the gate's verdict so far (or the final decision), and for one in
/// [`SNAPSHOT_EVERY`] the state `S` before the sample.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
struct Entry<S> {
    t: f64,
    y: f64,
    rejected: bool,
    /// The final decision is made (`rejected` is it).
    decided: bool,
    /// The root mean square `σ_ε` of the innovation the gate judged, when the gate was on.
    gate_rms: Option<f64>,
    before: Option<Box<S>>,
}

/// The samples waiting for their decision, oldest first, after the decided ones still needed
/// for the state the first of them keeps; and the newest accepted samples decided. `L`, `k` and
/// the fit's degree `m + 1` are the configuration's.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub(super) struct Review<S> {
    entries: VecDeque<Entry<S>>,
    /// Kept states no longer needed, whose buffers the next one reuses ([`Review::snapshot`]).
    spare: Vec<Box<S>>,
    accepted: VecDeque<(f64, f64)>,
    scratch: Scratch,
    window: usize,
    k: f64,
    degree: usize,
}

/// The windows' residuals about their fits over the last [`CALIBRATION_WINDOWS`] decisions, in
/// units of `σ²`: `Σ RSS/σ² / Σ (n − p)` estimates the residual variance the fits see, which is
/// 1 (a little less after the drops) for white noise of the `σ` in use and more where the
/// residuals are not white about a polynomial of the degree over the window (a trend it does
/// not follow, coloured noise): the deleted residual is then judged against `σ²` times that
/// factor, not called an outlier (Morrison §14.8: the innovations' mean square against its
/// predicted value).
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub(super) struct Calibration {
    windows: VecDeque<(f64, usize)>,
}

/// How many of the newest windows [`Calibration`] pools.
const CALIBRATION_WINDOWS: usize = 20;

impl Calibration {
    fn push(&mut self, rss: f64, spare: usize) {
        if rss.is_finite() && spare > 0 {
            self.windows.push_back((rss, spare));
            if self.windows.len() > CALIBRATION_WINDOWS {
                self.windows.pop_front();
            }
        }
    }

    /// `max(1, Σ RSS/σ² / Σ (n − p))`.
    fn factor(&self) -> f64 {
        let (rss, spare) = self
            .windows
            .iter()
            .fold((0.0, 0usize), |(r, s), &(rss, n)| (r + rss, s + n));
        if spare == 0 {
            1.0
        } else {
            (rss / spare as f64).max(1.0)
        }
    }
}

impl<S: Replay> Review<S> {
    /// The review of `cfg`'s filter, before the first sample.
    pub(super) fn new(cfg: &AutoConfig) -> Self {
        Self {
            entries: VecDeque::new(),
            spare: Vec::new(),
            accepted: VecDeque::new(),
            scratch: Scratch::default(),
            window: cfg.review_window,
            k: cfg.outliers.multiplier(),
            degree: cfg.degree + 1,
        }
    }

    /// Takes the newest sample with the gate's verdict in `out` and the state before it (kept
    /// for one sample in [`SNAPSHOT_EVERY`]); the `out.reinstated` newest rejections waiting
    /// before it were applied after all.
    fn push(&mut self, t: f64, y: f64, out: &AutoOutput, before: Option<Box<S>>) {
        self.reinstate(out.reinstated);
        self.entries.push_back(Entry {
            t,
            y,
            rejected: out.outlier,
            decided: false,
            gate_rms: gate_rms(out),
            before,
        });
    }

    /// Whether the next sample keeps the state before it: one in [`SNAPSHOT_EVERY`], and the
    /// first one waiting (the state is taken only then, not at every sample).
    pub(super) fn keeps_next(&self) -> bool {
        self.entries
            .iter()
            .rev()
            .take(SNAPSHOT_EVERY - 1)
            .all(|e| e.before.is_none())
    }

    /// The state before the next sample when it keeps it ([`keeps_next`](Self::keeps_next)):
    /// a copy of `state`, into the buffers of a kept state no longer needed when there is one.
    pub(super) fn snapshot(&mut self, state: &S) -> Option<Box<S>> {
        if !self.keeps_next() {
            return None;
        }
        Some(copy_into(&mut self.spare, state))
    }

    /// The newest `n` rejected samples waiting (a run just applied) are not rejected.
    fn reinstate(&mut self, n: usize) {
        reinstate(self.entries.iter_mut(), n);
    }

    /// The first sample waiting for its decision.
    fn first_undecided(&self) -> Option<usize> {
        self.entries.iter().position(|e| !e.decided)
    }

    /// Drops the decided samples before the last kept state at or before the first sample
    /// waiting (all of them when none waits): the first entry always keeps the state before it.
    fn trim(&mut self) {
        let end = match self.first_undecided() {
            Some(f) => (0..=f)
                .rev()
                .find(|&j| self.entries[j].before.is_some())
                .unwrap_or(0),
            None => self.entries.len(),
        };
        for e in self.entries.drain(..end) {
            if let Some(kept) = e.before {
                if self.spare.len() < SPARE_STATES {
                    self.spare.push(kept);
                }
            }
        }
    }
}

/// The newest `n` of `entries` rejected and waiting are not rejected (a run just applied).
/// The gate did not pass them: it judged them against a model the run says no longer fits
/// (Morrison §14.8), so its verdict does not stand for them; the interpolation decides.
fn reinstate<'a, S: 'a>(entries: impl DoubleEndedIterator<Item = &'a mut Entry<S>>, n: usize) {
    for e in entries.rev().filter(|e| !e.decided && e.rejected).take(n) {
        e.rejected = false;
        e.gate_rms = None;
    }
}

/// `σ_ε` of the innovation the gate judged in `out`, when the gate was on and passed it (a
/// sample that ends a run of rejections, applied as a manoeuvre, was not passed: see
/// [`reinstate`]).
fn gate_rms(out: &AutoOutput) -> Option<f64> {
    out.gate
        .and(out.innovation_sigma)
        .filter(|_| !out.manoeuvre)
}

/// The final verdict on `(t, y)` (`true`: an outlier) from the samples around it and the
/// gate's: the interpolation's, judged against the root mean square of its deleted residual
/// `√(c σ²(1 + v_p) + b²)`, where that is below the gate's `σ_ε` (`gate_rms`, `None` when the
/// gate was off), else the gate's; the gate's (`None`) too when the fit cannot say (too few
/// samples, or numbers beyond the double range). `gate` is the gate's verdict and the `σ_ε` it
/// judged against (`None` when the gate was off). The fit one degree up (for `b²`) is left out
/// where `σ_ε ≤ √(c σ²(1 + v_p))` (the root mean square is at least that, so the gate decides
/// whatever `b²` is), and where the gate passed the sample and `|y − p(t)| ≤ k √(c σ²(1 + v_p))`
/// (a larger `b²` only widens the interpolation's bound: it passes the sample too, or leaves
/// the decision to the gate, which passed it). Where the fit through every neighbour already
/// leaves the decision to the gate, no neighbour is dropped (dropping only raises `v_p`).
pub(super) fn interpolation_verdict(
    around: &[(f64, f64)],
    (t, y): (f64, f64),
    degree: usize,
    sigma: f64,
    k: f64,
    (gate, gate_rms): (bool, Option<f64>),
    scratch: &mut Scratch,
) -> Option<bool> {
    let Scratch {
        fit,
        up,
        calibration,
        ts,
        ys,
        ..
    } = scratch;
    let mut n = around.len().min(WINDOW);
    ts.clear();
    ys.clear();
    ts.extend(around[..n].iter().map(|s| s.0));
    ys.extend(around[..n].iter().map(|s| s.1));
    if !fit.fit(&ts[..n], &ys[..n], degree) {
        return None;
    }
    // The calibration's factor of the earlier windows (this window enters it only below).
    let scale = calibration.factor();
    // The gate decides where its σ_ε is at most the interpolation's noise-only root mean square
    // (below). Dropping neighbours only raises the fit's VRF at `t` (less information), so
    // where the fit through every neighbour already says so, the neighbours are not studied:
    // the window's residuals enter the calibration as they are.
    if let Some(g) = gate_rms {
        let (_, v) = fit.value_and_vrf_at(t)?;
        let rms_noise = (sigma * sigma * scale * (1.0 + v.max(0.0))).sqrt();
        if g <= rms_noise {
            calibration.push(fit.residual_sq() / (sigma * sigma), n - (degree + 1));
            return None;
        }
    }
    for _ in 0..2 {
        if n < degree + 4 {
            break;
        }
        let worst = fit.worst_residual(sigma * sigma)?;
        if worst.0 <= k * k {
            break;
        }
        ts.copy_within(worst.1 + 1..n, worst.1);
        ys.copy_within(worst.1 + 1..n, worst.1);
        n -= 1;
        if !fit.fit(&ts[..n], &ys[..n], degree) {
            return None;
        }
    }
    let (p, v) = fit.value_and_vrf_at(t)?;
    let v = v.max(0.0);
    let spare = n - (degree + 1);
    let var = sigma * sigma * scale;
    calibration.push(fit.residual_sq() / (sigma * sigma), spare);
    // The judge of the smaller mean square: the gate's prediction where the memory is long
    // and fits (the root mean square below is at least √(var(1 + v))), the interpolation
    // where it is short.
    let rms_noise = (var * (1.0 + v)).sqrt();
    if gate_rms.is_some_and(|g| g <= rms_noise) {
        return None;
    }
    let r = y - p;
    if !gate && r.abs() <= k * rms_noise {
        return None;
    }
    // The fit's bias at t, from one degree up on the same samples (nested least squares:
    // E{Δ²} = b² + σ²(v₊ − v), as for the filter's own bias).
    let up = (n >= degree + 3 && up.fit(&ts[..n], &ys[..n], degree + 1))
        .then(|| up.value_and_vrf_at(t))
        .flatten();
    let b2 = match up {
        Some((pu, vu)) => {
            let d = p - pu;
            (d * d - sigma * sigma * (vu.max(0.0) - v).max(0.0)).max(0.0)
        }
        None => 0.0,
    };
    let rms = (var * (1.0 + v) + b2).sqrt();
    let decides = r.is_finite() && rms.is_finite() && gate_rms.is_none_or(|g| g > rms);
    decides.then_some(r.abs() > k * rms)
}

/// The most samples of a review window: `L` on each side.
const WINDOW: usize = 2 * MAX_REVIEW_WINDOW;

/// What the review's fits keep between samples: the calibration, the two fits refitted in
/// place, and the window's samples (no allocation, nothing to clear, per sample).
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub(super) struct Scratch {
    /// The fits, refitted at each use ([`WindowFit`]): not saved.
    #[serde(skip)]
    fit: WindowFit,
    #[serde(skip)]
    up: WindowFit,
    calibration: Calibration,
    /// The window's times and values, the fit's (neighbours dropped in place).
    ts: Vec<f64>,
    ys: Vec<f64>,
    /// The accepted samples after the sample decided, and the window around it.
    after: Vec<(f64, f64)>,
    around: Vec<(f64, f64)>,
    /// The verdicts a decision going back replaces, put back if it fails
    /// ([`Review::take_again`]): not saved.
    #[serde(skip)]
    undo: Vec<(bool, Option<f64>)>,
}

impl<S: Replay> Review<S> {
    /// After an internal step failed on the newest sample (not yet in the review): `state`
    /// back to `before`, the state before it, or when that was not kept, to the newest state
    /// the review keeps, replaying the samples since with their decisions so far (the gate
    /// judging the undecided ones anew, as it did).
    pub(super) fn recover(&self, state: &mut S, before: Option<Box<S>>) {
        if let Some(s) = before {
            *state = *s;
            return;
        }
        let Some(start) = self.entries.iter().rposition(|e| e.before.is_some()) else {
            return;
        };
        *state = self.entries[start]
            .before
            .as_deref()
            .expect("found")
            .clone();
        for e in self.entries.range(start..) {
            let force = e.decided.then_some(e.rejected);
            // The same samples from the same state: it cannot fail where it did not.
            let _ = state.step(e.t, e.y, force);
        }
    }

    /// Takes the newest sample into the review (its output `out` from `state`, and the state
    /// before it when [`keeps_next`](Self::keeps_next)) and makes every decision it can;
    /// returns the newest sample's output (taken again when a decision went back) with the
    /// decisions (in `buffer`'s allocation: the previous output's, reused).
    pub(super) fn review(
        &mut self,
        state: &mut S,
        (t, y): (f64, f64),
        mut out: AutoOutput,
        before: Option<Box<S>>,
        buffer: Vec<bool>,
    ) -> AutoOutput {
        self.push(t, y, &out, before);
        let (decided, newest) = self.decide(state, false, buffer);
        if let Some(newest) = newest {
            out = newest;
        }
        out.decided = decided;
        out
    }

    /// Decides every sample still waiting, with the samples there are (at the end of a
    /// series: the window takes more samples before); the decisions, oldest first. `last`, the
    /// newest output, becomes the newest sample's output taken again if a decision went back
    /// (keeping its decisions).
    pub(super) fn decide_all(&mut self, state: &mut S, last: Option<&mut AutoOutput>) -> Vec<bool> {
        let (decided, newest) = self.decide(state, true, Vec::new());
        if let (Some(newest), Some(last)) = (newest, last) {
            let keep = std::mem::take(&mut last.decided);
            *last = newest;
            last.decided = keep;
        }
        decided
    }

    /// The oldest waiting samples' decisions, in order, and the newest sample's output if a
    /// decision went back and took the samples again.
    fn decide(
        &mut self,
        state: &mut S,
        finishing: bool,
        mut decided: Vec<bool>,
    ) -> (Vec<bool>, Option<AutoOutput>) {
        let (l, k, degree) = (self.window, self.k, self.degree);
        decided.clear();
        let mut newest = None;
        while let Some(f) = self.first_undecided() {
            let overflow = self.entries.len() - f > MAX_UNDECIDED;
            if l > 0 && !finishing && !overflow && self.entries.len() - f - 1 < l {
                // Fewer than `L` samples after it, accepted or not: not ready (below).
                break;
            }
            let front = &self.entries[f];
            // The accepted samples after it (at most 2L), in the scratch's buffer.
            let mut after = std::mem::take(&mut self.scratch.after);
            after.clear();
            let later = self.entries.iter().skip(f + 1).filter(|u| !u.rejected);
            after.extend(later.take(2 * l.max(1)).map(|u| (u.t, u.y)));
            let (before_wanted, ready) = if l == 0 {
                (0, !front.rejected || !after.is_empty() || finishing)
            } else if finishing {
                (2 * l - after.len().min(l), true)
            } else {
                // At start-up the noise estimate waits for its first samples (see
                // `NoiseState::is_early`).
                let before = self.accepted.len().min(l);
                let enough = after.len() >= l && after.len() >= 2 * l - before;
                (before, enough && !state.noise_is_early())
            };
            if !ready && !overflow {
                self.scratch.after = after;
                break;
            }
            let (gate, gate_rms, sample) = (front.rejected, front.gate_rms, (front.t, front.y));
            let verdict = match (l, state.noise_sigma(), overflow) {
                (1.., Some(sigma), false) if k > 0.0 && sigma > 0.0 => {
                    let before = self.accepted.len().min(before_wanted);
                    let mut around = std::mem::take(&mut self.scratch.around);
                    around.clear();
                    let accepted = &self.accepted;
                    let earlier = accepted.iter().skip(accepted.len() - before);
                    around.extend(earlier.chain(after.iter().take(2 * l - before)));
                    let verdict = (around.len() >= degree + 2)
                        .then(|| {
                            let c = &mut self.scratch;
                            interpolation_verdict(
                                &around,
                                sample,
                                degree,
                                sigma,
                                k,
                                (gate, gate_rms),
                                c,
                            )
                        })
                        .flatten()
                        .unwrap_or(gate);
                    self.scratch.around = around;
                    verdict
                }
                _ => gate,
            };
            self.scratch.after = after;
            if verdict != gate {
                if let Ok(out) = self.take_again(state, f, verdict) {
                    newest = Some(out);
                }
            }
            // Going back failed (it cannot on checked samples): the gate's verdict stands.
            let entry = &mut self.entries[f];
            entry.decided = true;
            let rejected = entry.rejected;
            if !rejected {
                self.accepted.push_back(sample);
                while self.accepted.len() > 2 * l.max(1) {
                    self.accepted.pop_front();
                }
            }
            decided.push(rejected);
            self.trim();
        }
        (decided, newest)
    }

    /// Goes back to the nearest state kept at or before the sample `f` waiting, replays the
    /// decided samples from there with their decisions, `f` with the decision `rejected`, and
    /// the samples after it (the gate judging them anew). Returns the newest sample's output;
    /// on an error `state` and the review are as before the call. No state is copied but the
    /// kept ones the replay takes again, each into the buffers of a spare one: the state
    /// before the call is moved aside, not copied, and the verdicts and kept states the
    /// replay replaces are put back only on an error.
    fn take_again(&mut self, state: &mut S, f: usize, rejected: bool) -> Result<AutoOutput, Error> {
        let start = (0..=f)
            .rev()
            .find(|&j| self.entries[j].before.is_some())
            .expect("the first entry keeps its state");
        let mut undo = std::mem::take(&mut self.scratch.undo);
        undo.clear();
        undo.extend(
            self.entries
                .range(start..)
                .map(|e| (e.rejected, e.gate_rms)),
        );
        let mut replaced = Vec::new();
        let kept = self.entries[start].before.as_deref().expect("found");
        let mut current = copy_into(&mut self.spare, kept);
        std::mem::swap(state, &mut current);
        // Every sample before `f` is decided: none of them is part of a run.
        state.end_run();
        let mut result = Err(None);
        for j in start..self.entries.len() {
            if j > start && self.entries[j].before.is_some() {
                let copy = copy_into(&mut self.spare, state);
                let old = self.entries[j].before.replace(copy).expect("kept");
                replaced.push((j, old));
            }
            let (t, y) = (self.entries[j].t, self.entries[j].y);
            let force = match j.cmp(&f) {
                std::cmp::Ordering::Less => Some(self.entries[j].rejected),
                std::cmp::Ordering::Equal => Some(rejected),
                std::cmp::Ordering::Greater => None,
            };
            let o = match state.step(t, y, force) {
                Ok(o) => o,
                Err(e) => {
                    result = Err(Some(e));
                    break;
                }
            };
            if j == f {
                self.entries[j].rejected = rejected;
                self.entries[j].gate_rms = None;
            } else if j > f {
                reinstate(self.entries.range_mut(f + 1..j), o.reinstated);
                self.entries[j].rejected = o.outlier;
                self.entries[j].gate_rms = gate_rms(&o);
            }
            result = Ok(o);
        }
        match result {
            Ok(out) => {
                self.keep_spare(current);
                for (_, old) in replaced {
                    self.keep_spare(old);
                }
                self.scratch.undo = undo;
                Ok(out)
            }
            Err(e) => {
                std::mem::swap(state, &mut current);
                for (entry, &(rejected, gate_rms)) in self.entries.range_mut(start..).zip(&undo) {
                    entry.rejected = rejected;
                    entry.gate_rms = gate_rms;
                }
                for (j, old) in replaced {
                    self.entries[j].before = Some(old);
                }
                self.scratch.undo = undo;
                Err(e.expect("the sample f was taken"))
            }
        }
    }

    /// Holds a kept state no longer needed for its buffers, up to [`SPARE_STATES`].
    fn keep_spare(&mut self, kept: Box<S>) {
        if self.spare.len() < SPARE_STATES {
            self.spare.push(kept);
        }
    }
}

/// A copy of `state`, into the buffers of a spare kept state when there is one.
fn copy_into<S: Clone>(spare: &mut Vec<Box<S>>, state: &S) -> Box<S> {
    match spare.pop() {
        Some(mut kept) => {
            kept.as_mut().clone_from(state);
            kept
        }
        None => Box::new(state.clone()),
    }
}

impl<S> Review<S> {
    /// A restored review's invariants ([`crate::persist`]): every kept state by `check`.
    pub(super) fn check_saved(
        &self,
        check: impl Fn(&S) -> Result<(), String>,
    ) -> Result<(), String> {
        self.entries
            .iter()
            .filter_map(|e| e.before.as_deref())
            .try_for_each(check)
    }
}
