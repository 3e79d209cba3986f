//! The adaptive memory of the final degree (Morrison §7.13, §13.9, §14.8): beside the
//! configured discount `θ` it runs fading-memory filters of the shorter memories
//! `θ_j = θ^(4^j)`, `j = 1 … J` ([`AutoConfig::memory_levels`], default 1: `θ⁴`), each with its
//! degree `m + 1` companion, on the same accepted samples, and uses the memory of least
//! estimated mean squared error.
//!
//! The memory trades noise against bias: the position VRF of a fading-memory filter falls as its
//! memory lengthens (about `∝ 1 − θ`, Morrison (13.4.4)), while the bias of an unmodelled
//! `(m+1)`-th derivative grows as `(1 − θ)^−(m+1)` (Morrison (13.9.28); (7.13.5) for the fixed
//! memory). Morrison §7.13 picks the memory where the two balance, and §14.8 answers threshold
//! crossings with "β can be temporarily reduced until the threshold crossings cease … then the
//! memory can again be lengthened". Here each memory's mean squared error of the predicted
//! position, `σ² v_j + b̂_j²` ([`super::bias`]: `b̂_j` from the difference to its companion,
//! counted where it is significant), is estimated before each sample, and the least one is
//! used (a shorter one at once, a longer one a level at a time once it has been the least for
//! [`LENGTHEN_AFTER`] predictions in a row): its prediction is gated, and its state after the
//! sample is reported with its honest covariance. While memory 0 is in use and its bias is not
//! significant, its `σ² v_0` is the least (the VRF falls as the memory lengthens), so the
//! shorter memories are not compared (they keep running); compared again, their calibrations
//! start from memory 0's. Only with
//! [`MisfitResponse::Restart`](super::MisfitResponse::Restart) (the flag-only response keeps
//! the memory). Memory `j = 0` is the configured one (expanding until the switch, then
//! fading); the shorter memories are fading from the first sample (exact discounted least
//! squares, on the exact engine always); a restart rebuilds them all from the onset
//! ([`Memories::rebuild`]). The expanding → fading switch of memory 0 is here too (Morrison
//! §13.8, (13.8.8); Reyneke et al. §7.2, Table 1): the rule's sample index for the discount per
//! sample so far, re-evaluated at each sample until the switch.
//!
//! **The ladder's step** ([`MEMORY_RATIO`]): each shorter memory is about a quarter of the one
//! above (`θ → θ⁴`, so `1 − θ → (1 − θ)(1 + θ + θ² + θ³) ≈ 4(1 − θ)`): it divides the bias of
//! the unmodelled `(m+1)`-th derivative by `(1 + θ + θ² + θ³)^(m+1)` (≈ 51 at `θ = 0.95`,
//! `m = 2`; `→ 4^(m+1) = 64` as `θ → 1`; the bias grows as `(1 − θ)^−(m+1)`, Morrison
//! (13.9.28)) and multiplies the VRF by about 4 (`∝ 1 − θ`, Morrison (13.4.4)). The default
//! single rung `θ⁴` does not reach as deep as the halving ladder `θ², θ⁴, θ⁸` it replaced: its
//! shortest memory went from `θ⁸` to `θ⁴`, and at `m = 2` the deepest bias reduction from
//! ≈ 512× to ≈ 64× (as `θ → 1`; ≈ 305× to ≈ 51× at `θ = 0.95`). A manoeuvre's bias is either small against the noise in the long memory,
//! which is then chosen, or reduced by the short one, and what is left of it is carried by the
//! reported error `σ² V + b̂ b̂ᵀ` ([`super::bias`]): coverage does not rest on the bias being
//! removed, nor on §7.13's balance being met exactly (it may fall between two rungs, where a
//! coarser ladder raises the mean squared error of the memory chosen).
//! Each rung costs one exact filter update at every sample (its companion's) and two
//! positions at every comparison.
//!
//! **One factor per memory.** On the exact engine a memory's degree-`m` filter is not updated
//! itself but taken from its degree `m + 1` companion's leading block
//! ([`FadingMemory::follow_leading`], [`ExpandingMemory::follow_leading`]): in the engine's
//! basis `(1, u, …, u^(m+1))` of re-centred time, whose centre and unit follow the samples'
//! times alone, the degree-`m` design is the companion's first `m + 1` columns, so the same
//! discounted least squares (Morrison (13.2.1), (14.3.11)-(14.3.13)) has the leading block of
//! the companion's information factor, of its true covariance's middle factor and of `Qᵀz` for
//! its own (Morrison (10.2.42)-(10.2.44): the rotations act column by column), and the
//! companion's residual plus the square of its last `Qᵀz` entry for its residual. The two agree
//! to rounding (`leading_tests.rs`: within 3·10⁻⁹ of their σ at degree 8 on long irregular
//! runs). Memory 0's filters follow at every sample; a shorter memory's only when it is in use
//! or compared ([`Memories::choose`]), its companion running at every sample. Measured on the Monte Carlo of manoeuvring tracks and
//! landing.csv (ACCURACY.md), the single rung `θ⁴` covers the truth better than the halving
//! ladder `θ², θ⁴, θ⁸` did (fewer rungs, fewer noisy choices of a memory too short) with half
//! the filters.

use super::bias::position_bias;
use super::config::{AutoConfig, MAX_MEMORY_LEVELS};
use super::misfit::{Kept, MisfitResponse};
use crate::error::Error;
use crate::polynomial::expanding::vrf::expanding_vrf;
use crate::polynomial::expanding::ExpandingMemory;
use crate::polynomial::fading::switch::memory_length_constant;
#[cfg(doc)]
use crate::polynomial::fading::switch::SwitchRule;
use crate::polynomial::fading::vrf::fading_vrf;
use crate::polynomial::fading::FadingMemory;
use crate::polynomial::filter::PolynomialFilter;
use crate::polynomial::form::EstimateForm;
use crate::polynomial::options::{DiscountMode, Engine, GAIN_MAX_DEGREE, MAX_DEGREE};
use std::sync::Arc;

/// A memory's position at the prediction's time and its companion's, each `(x, v)` with its
/// unit variance `v` (`None`: not determined).
pub(super) type Positions = (Option<(f64, f64)>, Option<(f64, f64)>);

/// A shorter memory never discounts by less than this per `τ` (a memory of well under one
/// sample says nothing more): a rung with `θ^(4^j) < 10⁻³` is dropped with those below it
/// ([`AutoConfig::memory_levels`]).
const MIN_THETA: f64 = 1e-3;

/// For the choice a memory's bias counts only where `Δ` exceeds this many of its noise standard
/// deviations (a false shortening on a fitting model at `P(|Z| > 2.5) = 1.2%` of the
/// predictions; with `SD(Δ) = σ√(V_{m+1} − V_m)` the memory shortens once its bias is a few
/// times the noise of the estimate, near Morrison §7.13's balance).
const CHOICE_SIGNIFICANCE: f64 = 2.5;

/// The calibration of [`Memories::calibrate`] averages over about this many samples.
const CALIBRATION_MEMORY: u64 = 20;

/// Samples a memory's calibration needs before it widens the reported error.
const CALIBRATION_MIN: u64 = 5;

/// A longer memory is taken once it has had the least estimated error for this many
/// predictions in a row.
pub(super) const LENGTHEN_AFTER: usize = 10;

/// An expanding-memory filter of degree `m` tracking its covariance for unit noise (its VRF).
pub(super) fn unit_expanding(m: usize, engine: Engine) -> Result<ExpandingMemory, Error> {
    ExpandingMemory::new(m, engine)?.with_noise_sigma(1.0)
}

/// The fading-memory filter of degree `m` with the settings of `cfg` on the given engine and
/// discount `θ` per `τ`, tracking its VRF.
fn unit_fading_on(
    cfg: &AutoConfig,
    m: usize,
    engine: Engine,
    theta: f64,
) -> Result<FadingMemory, Error> {
    FadingMemory::new(m, theta, cfg.tau, engine)?
        .with_discount_mode(cfg.discount)?
        .with_switch_rule(cfg.switch_rule)?
        .with_noise_sigma(1.0)
}

/// The degree `m + 1` of the companions and their engine, when `m + 1` is a supported degree;
/// the exact engine where the configured gain engine stops ([`GAIN_MAX_DEGREE`]): they only
/// measure the bias.
fn upper_degree(cfg: &AutoConfig) -> Option<(usize, Engine)> {
    let u = cfg.degree + 1;
    if u > MAX_DEGREE {
        return None;
    }
    let engine = if cfg.engine == Engine::Gain && u > GAIN_MAX_DEGREE {
        Engine::Exact
    } else {
        cfg.engine
    };
    Some((u, engine))
}

/// The degree `m + 1` companions (expanding, fading) of the final degree (see
/// [`upper_degree`]).
type UpperPair = (Option<ExpandingMemory>, Option<FadingMemory>);

fn upper_pair(cfg: &AutoConfig) -> Result<UpperPair, Error> {
    let Some((u, engine)) = upper_degree(cfg) else {
        return Ok((None, None));
    };
    Ok((
        Some(unit_expanding(u, engine)?),
        Some(unit_fading_on(cfg, u, engine, cfg.theta)?),
    ))
}

/// A filter whose degree-`m` estimate can be taken from its degree `m + 1` companion's
/// leading block ([`FadingMemory::follow_leading`], [`ExpandingMemory::follow_leading`]).
trait FollowLeading: PolynomialFilter {
    fn follow(&mut self, upper: &Self) -> bool;
}

impl FollowLeading for FadingMemory {
    fn follow(&mut self, upper: &Self) -> bool {
        self.follow_leading(upper)
    }
}

impl FollowLeading for ExpandingMemory {
    fn follow(&mut self, upper: &Self) -> bool {
        self.follow_leading(upper)
    }
}

/// Applies a sample to a degree-`m` filter and its degree `m + 1` companion (if any): the
/// companion updated, then the filter taken from the companion's leading block (on the exact
/// engine the degree-`m` discounted least squares is the first `m + 1` columns of the
/// degree-`m + 1` one, so one factor serves both), or updated itself where that does not
/// apply (the gain engine, no companion).
fn update_pair<F: FollowLeading>(
    lower: &mut F,
    upper: Option<&mut F>,
    t: f64,
    y: f64,
) -> Result<(), Error> {
    if let Some(upper) = upper {
        upper.update(t, y)?;
        if lower.follow(upper) {
            return Ok(());
        }
    }
    lower.update(t, y)
}

/// Each shorter memory discounts by this power of the one above: `θ_j = θ^(4^j)` per `τ` (the
/// module docs: a memory a quarter as long per rung).
const MEMORY_RATIO: i32 = 4;

/// A shorter memory of the final degree: the degree-`m` fading-memory filter of discount
/// `θ^(4^j)` per `τ` and its degree `m + 1` companion.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
struct Shorter {
    fading: FadingMemory,
    upper: FadingMemory,
    /// `fading` lags `upper` by samples not yet taken from its leading block
    /// ([`Memories::sync`]: only the memories compared or in use need their own filter; a
    /// state saved before this flag has none lagging).
    #[serde(default)]
    stale: bool,
}

// Field by field, `clone_from` too (the review's kept copies reuse their buffers).
field_clone! { Shorter { fading, upper, stale } }

impl Shorter {
    /// Brings `fading` up to `upper`'s samples from `upper`'s leading block
    /// ([`FadingMemory::follow_leading`]; both run the exact engine with one discount, as
    /// [`shorter_memories`] builds them).
    fn sync(&mut self) {
        if self.stale {
            let synced = self.fading.follow_leading(&self.upper);
            // Every pair is built matching (`shorter_memories`) and checked on restore.
            debug_assert!(synced, "a shorter memory's filters do not match");
            self.stale = !synced;
        }
    }
}

/// The shorter memories of `cfg` (none when `m + 1` is not a supported degree: without the
/// companion there is no bias estimate to choose by), on the exact engine whatever the
/// configured one: exact discounted least squares from the first sample, whose short memories
/// the gain engine's step-by-step gains would follow less accurately on irregular steps.
fn shorter_memories(cfg: &AutoConfig) -> Result<Vec<Shorter>, Error> {
    let Some((u, _)) = upper_degree(cfg) else {
        return Ok(Vec::new());
    };
    let mut out = Vec::new();
    let mut theta = cfg.theta;
    for _ in 0..cfg.memory_levels {
        theta = theta.powi(MEMORY_RATIO);
        if theta < MIN_THETA {
            break;
        }
        out.push(Shorter {
            fading: unit_fading_on(cfg, cfg.degree, Engine::Exact, theta)?,
            upper: unit_fading_on(cfg, u, Engine::Exact, theta)?,
            stale: false,
        });
    }
    Ok(out)
}

/// The final degree's filters before their first sample, built once (a restart starts from
/// copies of them: no settings checked again, no allocation to build them).
#[derive(Debug, serde::Serialize, serde::Deserialize)]
struct Fresh {
    expanding: ExpandingMemory,
    fading: FadingMemory,
    upper: UpperPair,
    shorter: Vec<Shorter>,
}

impl Fresh {
    fn new(cfg: &AutoConfig) -> Result<Self, Error> {
        Ok(Self {
            expanding: unit_expanding(cfg.degree, cfg.engine)?,
            fading: unit_fading_on(cfg, cfg.degree, cfg.engine, cfg.theta)?,
            upper: upper_pair(cfg)?,
            shorter: shorter_memories(cfg)?,
        })
    }
}

/// The final degree's memories (see the module docs): memory 0 (expanding until the switch,
/// then fading) and the shorter ones, each with its degree `m + 1` companion; which one is in
/// use, and each one's calibration.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub(super) struct Memories {
    /// The final-degree expanding-memory filter of the current memory, until the switch.
    expanding: Option<ExpandingMemory>,
    /// The final-degree fading-memory filter of the current memory.
    fading: FadingMemory,
    /// Degree `m + 1` companions of `expanding` and `fading` on the same samples (for the bias
    /// of the final degree; `None` at `m = MAX_DEGREE`, the expanding one after the switch).
    upper_expanding: Option<ExpandingMemory>,
    upper_fading: Option<FadingMemory>,
    /// The shorter memories `θ^(4^j)`, `j = 1 … J`, of the final degree.
    shorter: Vec<Shorter>,
    /// The memory in use (0: the configured `θ`).
    memory: usize,
    /// Predictions in a row for which a longer memory had the least estimated error.
    longer_runs: usize,
    /// The shorter memories were compared at the latest prediction (see [`Memories::choose`]).
    compared: bool,
    /// Each memory's prediction of the newest sample and its honest mean square.
    predictions: Vec<Option<(f64, f64)>>,
    /// Each memory's running mean of `ν²/σ_ε²` and its count ([`Memories::calibrate`]).
    calibration: Vec<(f64, u64)>,
    /// Global index (accepted samples) of the latest expanding → fading switch.
    switched_at: Option<u64>,
    /// The current memory 0 has switched to fading.
    switched: bool,
    /// Time of the first sample of the current memories.
    t_first: Option<f64>,
    /// `c` of a constant switch rule (`n_s = ⌊c/(1-θ)⌋`), and `c_0m` for Reyneke's `N`.
    switch_constant: Option<f64>,
    memory_constant: f64,
    /// The filters before their first sample (shared by every copy of the state).
    fresh: Arc<Fresh>,
}

// Field by field, `clone_from` too (the review's kept copies reuse their buffers).
field_clone! {
    Memories {
        expanding, fading, upper_expanding, upper_fading, shorter, memory, longer_runs, compared,
        predictions, calibration, switched_at, switched, t_first, switch_constant, memory_constant,
        fresh,
    }
}

impl Memories {
    /// The memories of `cfg`'s final degree, before the first sample.
    pub(super) fn new(cfg: &AutoConfig) -> Result<Self, Error> {
        let m = cfg.degree;
        let fresh = Arc::new(Fresh::new(cfg)?);
        let (upper_expanding, upper_fading) = fresh.upper.clone();
        Ok(Self {
            expanding: Some(fresh.expanding.clone()),
            fading: fresh.fading.clone(),
            upper_expanding,
            upper_fading,
            shorter: fresh.shorter.clone(),
            memory: 0,
            longer_runs: 0,
            compared: true,
            predictions: Vec::new(),
            calibration: Vec::new(),
            switched_at: None,
            switched: false,
            t_first: None,
            switch_constant: cfg.switch_rule.asymptotic_constant(m),
            memory_constant: memory_length_constant(0, m),
            fresh,
        })
    }

    /// The memories rebuilt from the `kept` samples (a restart, [`MisfitResponse::Restart`]):
    /// memory 0 expanding again, the calibration cleared.
    pub(super) fn rebuild(&mut self, kept: &[Kept]) -> Result<(), Error> {
        // Into the filters' own places (`clone_from`: the shorter memories' vector keeps its
        // allocation); the samples cannot fail on filters built from checked settings, and the
        // state is the caller's to restore should they (`Review::recover`).
        let fresh = &self.fresh;
        match &mut self.expanding {
            Some(e) => e.clone_from(&fresh.expanding),
            None => self.expanding = Some(fresh.expanding.clone()),
        }
        self.fading.clone_from(&fresh.fading);
        self.upper_expanding.clone_from(&fresh.upper.0);
        self.upper_fading.clone_from(&fresh.upper.1);
        self.shorter.clone_from(&fresh.shorter);
        let expanding = self.expanding.as_mut().expect("set above");
        for k in kept {
            for s in &mut self.shorter {
                s.upper.update(k.t, k.y)?;
                s.stale = true;
            }
            update_pair(expanding, self.upper_expanding.as_mut(), k.t, k.y)?;
            update_pair(&mut self.fading, self.upper_fading.as_mut(), k.t, k.y)?;
        }
        self.memory = 0;
        self.longer_runs = 0;
        self.calibration.clear();
        self.switched = false;
        self.t_first = kept.first().map(|k| k.t);
        Ok(())
    }

    /// Applies an accepted sample to every memory and companion.
    pub(super) fn update(&mut self, t: f64, y: f64) -> Result<(), Error> {
        if let Some(f) = &mut self.expanding {
            update_pair(f, self.upper_expanding.as_mut(), t, y)?;
        } else if let Some(f) = &mut self.upper_expanding {
            f.update(t, y)?;
        }
        update_pair(&mut self.fading, self.upper_fading.as_mut(), t, y)?;
        // A shorter memory's own filter only where it is in use; the others' when compared.
        for (j, s) in self.shorter.iter_mut().enumerate() {
            s.upper.update(t, y)?;
            s.stale = true;
            if j + 1 == self.memory {
                s.sync();
            }
        }
        if self.t_first.is_none() {
            self.t_first = Some(t);
        }
        Ok(())
    }

    /// The index `j` of the memory in use.
    pub(super) fn in_use(&self) -> usize {
        self.memory
    }

    /// Memory 0 has switched to fading.
    pub(super) fn switched(&self) -> bool {
        self.switched
    }

    /// The index (in accepted samples) of the latest switch.
    pub(super) fn switched_at(&self) -> Option<u64> {
        self.switched_at
    }

    /// The final-degree filter of memory `j` (0: the configured `θ`, expanding until the switch).
    pub(super) fn filter(&self, j: usize) -> &dyn PolynomialFilter {
        match (j, &self.expanding, self.switched) {
            (0, Some(e), false) => e,
            (0, _, _) => &self.fading,
            _ => &self.shorter[j - 1].fading,
        }
    }

    /// The position at `t` and its unit variance from memory `j`'s filter, without allocating.
    pub(super) fn position(&self, j: usize, t: f64) -> Option<(f64, f64)> {
        match (j, &self.expanding, self.switched) {
            (0, Some(e), false) => e.position_at(t),
            (0, _, _) => self.fading.position_at(t),
            _ => self.shorter[j - 1].fading.position_at(t),
        }
    }

    /// The derivatives at `t` of memory `j`'s filter and their variances into `x` and `var`
    /// (false when it is not determined or has no such path).
    pub(super) fn variances(&self, j: usize, t: f64, x: &mut [f64], var: &mut [f64]) -> bool {
        match (j, &self.expanding, self.switched) {
            (0, Some(e), false) => e.variances_at(t, x, var),
            (0, _, _) => self.fading.variances_at(t, x, var),
            (j, _, _) => self.shorter[j - 1].fading.variances_at(t, x, var),
        }
    }

    /// Memory `j`'s estimate at `t`, its derivatives into `x` and its covariance's diagonal
    /// into `var`: the numbers of its [`PolynomialFilter::estimate_at`] bit for bit, without
    /// allocating (false where that path does not answer: the caller takes the estimate).
    pub(super) fn estimate_diagonal(
        &self,
        j: usize,
        t: f64,
        x: &mut [f64],
        var: &mut [f64],
    ) -> bool {
        match (j, &self.expanding, self.switched) {
            (0, Some(e), false) => e.estimate_diagonal_at(t, x, var),
            (0, _, _) => self.fading.estimate_diagonal_at(t, x, var),
            (j, _, _) => self.shorter[j - 1].fading.estimate_diagonal_at(t, x, var),
        }
    }

    /// The position at `t` and its unit variance from memory `j`'s companion.
    pub(super) fn companion_position(&self, j: usize, t: f64) -> Option<(f64, f64)> {
        if j > 0 {
            return self.shorter[j - 1].upper.position_at(t);
        }
        match (&self.upper_expanding, &self.upper_fading, self.switched) {
            (Some(e), _, false) => e.position_at(t),
            (_, Some(f), _) => f.position_at(t),
            _ => None,
        }
    }

    /// [`variances`](Self::variances) of memory `j`'s companion.
    pub(super) fn companion_variances(
        &self,
        j: usize,
        t: f64,
        x: &mut [f64],
        var: &mut [f64],
    ) -> bool {
        if j > 0 {
            return self.shorter[j - 1].upper.variances_at(t, x, var);
        }
        match (&self.upper_expanding, &self.upper_fading, self.switched) {
            (Some(e), _, false) => e.variances_at(t, x, var),
            (_, Some(f), _) => f.variances_at(t, x, var),
            _ => false,
        }
    }

    /// The degree `m + 1` companion of memory `j`.
    pub(super) fn companion(&self, j: usize) -> Option<&dyn PolynomialFilter> {
        if j > 0 {
            return Some(&self.shorter[j - 1].upper);
        }
        match (&self.upper_expanding, &self.upper_fading, self.switched) {
            (Some(e), _, false) => Some(e as &dyn PolynomialFilter),
            (_, Some(f), _) => Some(f as &dyn PolynomialFilter),
            _ => None,
        }
    }

    /// Chooses the memory for the prediction at `t`: the one of least estimated mean squared
    /// error of the position, `σ² V_j + b̂_j²`, at once when it is shorter than the memory in
    /// use; a longer one only one level at a time, once it has been the least for
    /// [`LENGTHEN_AFTER`] predictions in a row (Morrison §14.8: the memory is lengthened again
    /// once the crossings cease; a single low `b̂` is not evidence enough). Memory 0 while the
    /// ladder settles (`settled` false), without `σ` or with the flag-only response; memory 0,
    /// without comparing the shorter ones, while it is in use and its bias not significant
    /// (its VRF is the least, Morrison (13.4.4)). Returns,
    /// when it compared the memories, the chosen one's position at `t` and its companion's
    /// (each with its unit variance, as [`position`](Self::position) and
    /// [`companion_position`](Self::companion_position) give them): the prediction's, computed
    /// once.
    pub(super) fn choose(
        &mut self,
        cfg: &AutoConfig,
        t: f64,
        sigma: Option<f64>,
        settled: bool,
    ) -> Option<Positions> {
        let Some(sigma) = sigma else {
            self.memory = 0;
            return None;
        };
        let responds = matches!(cfg.misfit_response, MisfitResponse::Restart { .. });
        if !settled || self.shorter.is_empty() || !responds {
            self.memory = 0;
            return None;
        }
        let s2 = sigma * sigma;
        let mut best = (f64::INFINITY, self.memory);
        self.predictions.clear();
        self.predictions.resize(self.shorter.len() + 1, None);
        let mut positions = [(None, None); MAX_MEMORY_LEVELS + 1];
        let memories = self.shorter.len() + 1;
        for (j, slot) in positions.iter_mut().enumerate().take(memories) {
            if j > 0 {
                self.shorter[j - 1].sync();
            }
            let Some(est) = self.position(j, t) else {
                continue;
            };
            let upper = self.companion_position(j, t);
            *slot = (Some(est), upper);
            let (b0, honest) = match upper {
                Some(u) => (
                    position_bias(est, u, sigma, CHOICE_SIGNIFICANCE),
                    position_bias(est, u, sigma, 1.0),
                ),
                // Memory 0 without its companion yet: its noise only; a shorter one: not yet.
                None if j == 0 => (0.0, 0.0),
                None => continue,
            };
            let (x, v) = (est.0, est.1.max(0.0));
            self.predictions[j] = Some((x, s2 * (1.0 + v) + honest * honest));
            let mse = s2 * v + b0 * b0;
            if mse.is_finite() && mse < best.0 {
                best = (mse, j);
            }
            if j == 0 && self.memory == 0 && b0 == 0.0 && mse.is_finite() {
                // Memory 0 in use without a significant bias: its `σ² V₀` is the least (a
                // shorter memory's VRF is larger, Morrison (13.4.4), and its `b̂²` is not
                // negative), so the shorter memories are not compared.
                self.compared = false;
                self.longer_runs = 0;
                return Some(positions[0]);
            }
        }
        if !self.compared {
            // Compared again after a pause: their calibrations restart from memory 0's, the
            // memory in use through the pause (its innovations' mean square against its
            // predicted value, Morrison §14.8, stands for theirs).
            if let Some(&first) = self.calibration.first() {
                for c in self.calibration.iter_mut().skip(1) {
                    *c = first;
                }
            }
            self.compared = true;
        }
        let j = best.1;
        if j >= self.memory {
            self.memory = j;
            self.longer_runs = 0;
        } else {
            self.longer_runs += 1;
            if self.longer_runs >= LENGTHEN_AFTER {
                self.memory -= 1;
                self.longer_runs = 0;
            }
        }
        Some(positions[self.memory])
    }

    /// Adds the accepted sample `y` to each memory's calibration: the running mean (over about
    /// [`CALIBRATION_MEMORY`] samples) of `ν_j²/σ_ε,j²`, its squared innovation over the
    /// predicted mean square `σ²(1 + v_j) + b̂_j²` (clipped at 16, so that an outlier the gate
    /// passed counts as a 4σ innovation). Morrison §14.8: the normalised innovations have mean 1
    /// while the predictions' honest variance is right.
    pub(super) fn calibrate(&mut self, y: f64) {
        self.calibration.resize(self.shorter.len() + 1, (1.0, 0));
        for (c, p) in self.calibration.iter_mut().zip(&self.predictions) {
            let Some((pred, var)) = *p else { continue };
            let k2 = ((y - pred).powi(2) / var).min(16.0);
            if k2.is_finite() {
                c.1 += 1;
                c.0 += (k2 - c.0) / (c.1.min(CALIBRATION_MEMORY) as f64);
            }
        }
    }

    /// The factor of the reported mean squared error of the memory in use:
    /// `max(1, mean(ν²/σ_ε²))` over its recent accepted samples ([`calibrate`](Self::calibrate)),
    /// once it has [`CALIBRATION_MIN`] of them, while the final degree is active (`settled`); 1
    /// otherwise. The honest covariance `σ² V + b̂ b̂ᵀ` is an estimate; where the memory's own
    /// innovations say its predictions err more than it, the reported error is widened by the
    /// same ratio (the gate is not: it keeps its false-alarm rate by the noise model alone).
    pub(super) fn calibration_factor(&self, settled: bool) -> f64 {
        if !settled {
            return 1.0;
        }
        match self.calibration.get(self.memory) {
            Some(&(mean, n)) if n >= CALIBRATION_MIN && mean.is_finite() => mean.max(1.0),
            _ => 1.0,
        }
    }

    /// Reyneke's memory length `N = c_0m/(1-θ_s)` of the memory in use at `t`, once it fades
    /// (switched, or a shorter memory); `None` before (the caller counts samples).
    pub(super) fn faded_length(&self, cfg: &AutoConfig, t: f64) -> Option<f64> {
        (self.switched || self.memory > 0).then(|| {
            // The memory in use discounts by θ^(4^j) per sample (the power its own filter's
            // discount is of θ, so that a restored filter keeps its own).
            let power = match self.memory {
                0 => 1,
                j => (self.shorter[j - 1].fading.theta().ln() / cfg.theta.ln()).round() as i32,
            };
            let theta = self.theta_per_sample(cfg, t).powi(power);
            self.memory_constant / (1.0 - theta)
        })
    }

    /// The discount per sample the switch rules use: `θ` per update, or `θ^ζ̄` with `ζ̄` the mean
    /// step of the current memory so far (including `t`) in units of `τ`.
    fn theta_per_sample(&self, cfg: &AutoConfig, t: f64) -> f64 {
        let n = self.fading.samples();
        let th = match (cfg.discount, self.t_first) {
            (DiscountMode::PerTime, Some(t0)) if n > 0 => {
                let zeta = (t - t0) / (n as f64 * cfg.tau);
                cfg.theta.powf(zeta)
            }
            _ => cfg.theta,
        };
        th.clamp(1e-300, 1.0 - 1e-15)
    }

    /// Switches memory 0 from expanding to fading when the rule says so for its next sample at
    /// time `t` (`accepted` samples so far): the rule's index for the per-sample discount so
    /// far, exactly as [`SwitchRule::switch_index`] (and the gain engine) computes it.
    pub(super) fn switch_if_due(
        &mut self,
        cfg: &AutoConfig,
        t: f64,
        accepted: u64,
    ) -> Result<(), Error> {
        if self.switched {
            return Ok(());
        }
        let m = cfg.degree;
        let n = self.fading.samples();
        if n <= m as u64 {
            return Ok(());
        }
        let theta_s = self.theta_per_sample(cfg, t);
        // The exact crossover: the expanding-memory current position VRF reaches the
        // fading-memory one.
        let due = cfg
            .switch_rule
            .switches(m, n, theta_s, self.switch_constant, || {
                Ok((
                    expanding_vrf::<f64>(m, n, EstimateForm::Current)?[(0, 0)],
                    fading_vrf(m, theta_s, EstimateForm::Current)?[(0, 0)],
                ))
            })?;
        if due {
            self.switched = true;
            self.switched_at = Some(accepted);
            self.expanding = None;
            self.upper_expanding = None;
        }
        Ok(())
    }
}

impl Memories {
    /// Restored memories' invariants ([`crate::persist`]): at most [`MAX_MEMORY_LEVELS`]
    /// shorter memories, every filter valid and of the final degree `m` (the companions
    /// `m + 1`), the memory in use one of them. The shorter memories' discounts are not
    /// checked against the configured ladder: a state saved before 2026-12-07 holds the
    /// ladder `θ², θ⁴, θ⁸` of then, and keeps it.
    pub(super) fn check_saved(&self, m: usize) -> Result<(), String> {
        let degree = |f: &dyn PolynomialFilter, want: usize| {
            if f.degree() == want {
                Ok(())
            } else {
                Err(format!("memory of degree {}, {want} expected", f.degree()))
            }
        };
        if let Some(e) = &self.expanding {
            e.check_saved()?;
            degree(e, m)?;
        }
        self.fading.check_saved()?;
        degree(&self.fading, m)?;
        if let Some(e) = &self.upper_expanding {
            e.check_saved()?;
            degree(e, m + 1)?;
        }
        if let Some(f) = &self.upper_fading {
            f.check_saved()?;
            degree(f, m + 1)?;
        }
        // A restart starts again from the fresh memories.
        for shorter in [&self.shorter, &self.fresh.shorter] {
            if shorter.len() > MAX_MEMORY_LEVELS {
                // `choose` holds the positions of at most `MAX_MEMORY_LEVELS + 1` memories.
                return Err(format!(
                    "{} shorter memories, at most {MAX_MEMORY_LEVELS}",
                    shorter.len()
                ));
            }
            for s in shorter {
                s.fading.check_saved()?;
                s.upper.check_saved()?;
                degree(&s.fading, m)?;
                degree(&s.upper, m + 1)?;
                // `Shorter::sync` takes the filter from its companion's leading block: a pair
                // that does not match (discount, engine, σ, prior) would leave it behind.
                if !s.fading.clone().follow_leading(&s.upper) {
                    return Err(
                        "a shorter memory's filter and its companion differ in discount, \
                         engine or noise"
                            .to_string(),
                    );
                }
            }
        }
        if self.memory > self.shorter.len() {
            return Err(format!(
                "memory in use {} of {}",
                self.memory,
                self.shorter.len()
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The discounts of the shorter memories built for `θ` and `levels`.
    fn ladder(theta: f64, levels: usize) -> Vec<f64> {
        let mut cfg = AutoConfig::new(2, theta, 1.0);
        cfg.memory_levels = levels;
        shorter_memories(&cfg)
            .unwrap()
            .iter()
            .map(|s| {
                assert_eq!(s.fading.theta(), s.upper.theta());
                assert_eq!((s.fading.degree(), s.upper.degree()), (2, 3));
                s.fading.theta()
            })
            .collect()
    }

    #[test]
    fn the_ladder_is_theta_to_the_powers_of_four_down_to_the_cutoff() {
        // θ⁴ and θ¹⁶ at θ = 0.95: 0.81450625 and 0.95¹⁶ = 0.4401266686517657 (from exact rationals).
        let th: f64 = 0.95;
        let l = ladder(th, 2);
        assert_eq!(l.len(), 2);
        assert!((l[0] - 0.814_506_25).abs() < 1e-15, "{l:?}");
        assert!((l[1] - 0.440_126_668_651_765_7).abs() < 1e-15, "{l:?}");
        let t4 = l[0];
        assert_eq!(ladder(th, 1), [t4]);
        assert!(ladder(th, 0).is_empty());
        // A rung below 10⁻³ is dropped: θ⁴ < 10⁻³ for θ < 10^(−3/4) ≈ 0.1778.
        assert!(ladder(0.177, 1).is_empty());
        assert_eq!(ladder(0.18, 1).len(), 1);
        // All MAX_MEMORY_LEVELS rungs only where θ^(4^8) ≥ 10⁻³: θ ≥ 10^(−3/65536) ≈ 0.999895.
        assert_eq!(ladder(0.99990, MAX_MEMORY_LEVELS).len(), MAX_MEMORY_LEVELS);
        assert_eq!(
            ladder(0.99989, MAX_MEMORY_LEVELS).len(),
            MAX_MEMORY_LEVELS - 1
        );
    }
}
