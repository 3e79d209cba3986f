//! The adaptive memory of the final degree (Morrison §7.13, §13.9, §14.8): beside the
//! configured discount `θ` it runs fading-memory filters of the shorter memories
//! `θ_j = θ^(2^j)`, `j = 1 … J` ([`AutoConfig::memory_levels`]), each with its degree `m + 1`
//! companion, on the same accepted samples, and uses the memory of least estimated mean squared
//! error.
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
//! sample is reported with its honest covariance. Only with
//! [`MisfitResponse::Restart`](super::MisfitResponse::Restart) (the flag-only response keeps
//! the memory). Halving the memory (`θ → θ²`, so
//! `1 − θ → ≈ 2(1 − θ)`) divides the bias by `≈ 2^(m+1)` and about doubles the VRF. Memory
//! `j = 0` is the configured one (expanding until the switch, then fading); the shorter memories
//! are fading from the first sample (exact discounted least squares, on the exact engine always); a
//! restart rebuilds them all from the onset.

use super::bias::position_bias;
use super::build::{unit_fading_on, upper_degree};
use super::filter::AutomaticFilter;
use super::misfit::MisfitResponse;
#[cfg(doc)]
use super::AutoConfig;
use super::AutoConfig as Config;
use super::MAX_MEMORY_LEVELS;
use crate::error::Error;
use crate::polynomial::fading::FadingMemory;
use crate::polynomial::filter::PolynomialFilter;
use crate::polynomial::options::Engine;

/// A memory's position at the prediction's time and its companion's, each `(x, v)` with its
/// unit variance `v` (`None`: not determined).
pub(super) type Positions = (Option<(f64, f64)>, Option<(f64, f64)>);

/// A shorter memory never discounts by less than this per `τ` (a memory of well under one
/// sample says nothing more).
const MIN_THETA: f64 = 1e-3;

/// For the choice a memory's bias counts only where `Δ` exceeds this many of its noise standard
/// deviations (a false shortening on a fitting model at `P(|Z| > 2.5) = 1.2%` of the
/// predictions; with `SD(Δ) = σ√(V_{m+1} − V_m)` the memory shortens once its bias is a few
/// times the noise of the estimate, near Morrison §7.13's balance).
const CHOICE_SIGNIFICANCE: f64 = 2.5;

/// The calibration of [`AutomaticFilter::calibrate`] averages over about this many samples.
const CALIBRATION_MEMORY: u64 = 20;

/// Samples a memory's calibration needs before it widens the reported error.
const CALIBRATION_MIN: u64 = 5;

/// A longer memory is taken once it has had the least estimated error for this many
/// predictions in a row.
pub(super) const LENGTHEN_AFTER: usize = 10;

/// A shorter memory of the final degree: the degree-`m` fading-memory filter of discount
/// `θ^(2^j)` per `τ` and its degree `m + 1` companion.
#[derive(Clone, Debug)]
pub(super) struct Shorter {
    pub(super) fading: FadingMemory,
    pub(super) upper: FadingMemory,
}

/// The shorter memories of `cfg` (none when `m + 1` is not a supported degree: without the
/// companion there is no bias estimate to choose by), on the exact engine whatever the
/// configured one: exact discounted least squares from the first sample, whose short memories
/// the gain engine's step-by-step gains would follow less accurately on irregular steps.
pub(super) fn shorter_memories(cfg: &Config) -> Result<Vec<Shorter>, Error> {
    let Some((u, _)) = upper_degree(cfg) else {
        return Ok(Vec::new());
    };
    let mut out = Vec::new();
    let mut theta = cfg.theta;
    for _ in 0..cfg.memory_levels {
        theta *= theta;
        if theta < MIN_THETA {
            break;
        }
        out.push(Shorter {
            fading: unit_fading_on(cfg, cfg.degree, Engine::Exact, theta)?,
            upper: unit_fading_on(cfg, u, Engine::Exact, theta)?,
        });
    }
    Ok(out)
}

impl AutomaticFilter {
    /// The final-degree filter of memory `j` (0: the configured `θ`, expanding until the switch).
    pub(super) fn memory_filter(&self, j: usize) -> &dyn PolynomialFilter {
        match (j, &self.expanding, self.switched) {
            (0, Some(e), false) => e,
            (0, _, _) => &self.fading,
            _ => &self.shorter[j - 1].fading,
        }
    }

    /// The position at `t` and its unit variance from memory `j`'s filter, without allocating.
    pub(super) fn memory_position(&self, j: usize, t: f64) -> Option<(f64, f64)> {
        match (j, &self.expanding, self.switched) {
            (0, Some(e), false) => e.position_at(t),
            (0, _, _) => self.fading.position_at(t),
            _ => self.shorter[j - 1].fading.position_at(t),
        }
    }

    /// The position at `t` and its unit variance from memory `j`'s companion.
    pub(super) fn memory_companion_position(&self, j: usize, t: f64) -> Option<(f64, f64)> {
        if j > 0 {
            return self.shorter[j - 1].upper.position_at(t);
        }
        match (&self.upper_expanding, &self.upper_fading, self.switched) {
            (Some(e), _, false) => e.position_at(t),
            (_, Some(f), _) => f.position_at(t),
            _ => None,
        }
    }

    /// The degree `m + 1` companion of memory `j`.
    pub(super) fn memory_companion(&self, j: usize) -> Option<&dyn PolynomialFilter> {
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
    /// ladder settles or without `σ`. Returns, when it compared the memories, the chosen one's
    /// position at `t` and its companion's (each with its unit variance, as
    /// [`memory_position`](Self::memory_position) and
    /// [`memory_companion_position`](Self::memory_companion_position) give them): the
    /// prediction's, computed once.
    pub(super) fn choose_memory(&mut self, t: f64) -> Option<Positions> {
        let Some(sigma) = self.noise_sigma() else {
            self.memory = 0;
            return None;
        };
        let responds = matches!(self.cfg.misfit_response, MisfitResponse::Restart { .. });
        if self.active < self.cfg.degree || self.shorter.is_empty() || !responds {
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
            let Some(est) = self.memory_position(j, t) else {
                continue;
            };
            let upper = self.memory_companion_position(j, t);
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
    /// once it has [`CALIBRATION_MIN`] of them, while the final degree is active; 1 otherwise.
    /// The honest covariance `σ² V + b̂ b̂ᵀ` is an estimate; where the memory's own innovations
    /// say its predictions err more than it, the reported error is widened by the same ratio
    /// (the gate is not: it keeps its false-alarm rate by the noise model alone).
    pub(super) fn calibration_factor(&self) -> f64 {
        if self.active < self.cfg.degree {
            return 1.0;
        }
        match self.calibration.get(self.memory) {
            Some(&(mean, n)) if n >= CALIBRATION_MIN && mean.is_finite() => mean.max(1.0),
            _ => 1.0,
        }
    }

    /// The index `j` of the memory in use: the final degree's discount is `θ^(2^j)` per `τ`
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
        self.memory
    }
}
