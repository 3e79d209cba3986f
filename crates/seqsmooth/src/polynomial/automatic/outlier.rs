//! The outlier gate (Morrison §14.8, (14.8.4); Reyneke et al. §7.4): when an innovation `ν` is
//! too large for the noise `σ` and the prediction's own variance, the judgement of each sample
//! by the prediction of the memory chosen for it, and the variance of the noise that passes a
//! gate; the current run of rejections, and what it says of the prediction's bias.

use super::config::check_positive;
#[cfg(doc)]
use super::config::AutoConfig;
use super::misfit::Kept;
use crate::error::{Error, Param};
use crate::polynomial::filter::PolynomialFilter;
use crate::stats::two_sided_tail;

/// Morrison's gate multiplier: `|ν| > 3 σ_ε` (Reyneke §7.4 citing Morrison).
///
/// ```
/// use seqsmooth::polynomial::automatic::{OutlierRule, MORRISON_K};
/// assert_eq!(OutlierRule::morrison(), OutlierRule::Innovation { k: MORRISON_K });
/// ```
pub const MORRISON_K: f64 = 3.0;

/// The default multiplier for Reyneke's rule `|ν| > k σ (1 + √(2/N))`. As printed (`k = 1`) the
/// rule rejects 10-30% of good samples (`P(|Z| > 1 + √(2/N))`: 0.10 at `N = 5` to 0.25 at
/// `N = 100`, see [`OutlierRule::false_alarm_rate`]). With `k = 3` and the gate active only where
/// the prediction VRF is at most 1 (the default [`AutoConfig::gate_max_vrf`]), the per-sample
/// false-alarm rate on Gaussian noise stays below 1% up to degree 4 (worst case over the
/// expanding start and every `θ`); above degree 4 use the innovation gate. The rates are
/// asserted in `tests/automatic_noise.rs`; measured accuracy: see ACCURACY.md.
///
/// ```
/// use seqsmooth::polynomial::automatic::{OutlierRule, REYNEKE_DEFAULT_K};
/// assert_eq!(OutlierRule::reyneke(), OutlierRule::Reyneke { k: REYNEKE_DEFAULT_K });
/// ```
pub const REYNEKE_DEFAULT_K: f64 = 3.0;

/// How an innovation is judged an outlier.
///
/// ```
/// use seqsmooth::polynomial::automatic::OutlierRule;
/// assert_eq!(OutlierRule::default(), OutlierRule::morrison());
/// assert_eq!(OutlierRule::Off.threshold(1.0, 0.1, 10.0), None);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
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
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::OutlierRule;
    /// assert_eq!(OutlierRule::morrison(), OutlierRule::Innovation { k: 3.0 });
    /// ```
    pub fn morrison() -> Self {
        OutlierRule::Innovation { k: MORRISON_K }
    }

    /// Reyneke's gate with the default multiplier [`REYNEKE_DEFAULT_K`].
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::OutlierRule;
    /// assert_eq!(OutlierRule::reyneke(), OutlierRule::Reyneke { k: 3.0 });
    /// ```
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

    /// The multiplier `k` of the rule (0 for [`OutlierRule::Off`]).
    pub(super) fn multiplier(&self) -> f64 {
        match *self {
            OutlierRule::Off => 0.0,
            OutlierRule::Innovation { k } | OutlierRule::Reyneke { k } => k,
        }
    }

    pub(super) fn validate(&self) -> Result<(), Error> {
        match *self {
            OutlierRule::Off => Ok(()),
            OutlierRule::Innovation { k } | OutlierRule::Reyneke { k } => {
                check_positive(Param::OutlierGateMultiplier, k)
            }
        }
    }
}

/// What the judgement of one sample found (the prediction by the memory chosen for it, its
/// innovation and honest `σ_ε`, and the gate's verdict; Morrison (14.8.1)-(14.8.4)).
pub(super) struct Judged {
    pub(super) sigma: Option<f64>,
    pub(super) innovation: Option<f64>,
    pub(super) vrf: Option<f64>,
    pub(super) innovation_sigma: Option<f64>,
    pub(super) k2: Option<f64>,
    pub(super) gate: Option<f64>,
    pub(super) rejected: bool,
}

/// The gate half-width for a sample, given the noise `σ`, the prediction's VRF `v`, its
/// estimated bias `b₀` and the memory length `N` (Reyneke's rule): the rule's `g(σ, v, N)`
/// widened to `√(g² + k²b₀²)` (for Morrison's rule `k √(σ²(1 + v) + b₀²)`, `k` times the honest
/// `σ_ε`). Active only at the final degree (`settled`), with `σ` known and the prediction at
/// least as good as [`AutoConfig::gate_max_vrf`] says.
pub(super) fn gate_width(
    rule: &OutlierRule,
    gate_max_vrf: f64,
    settled: bool,
    (sigma, vrf): (Option<f64>, Option<f64>),
    bias: f64,
    memory: impl FnOnce() -> f64,
) -> Option<f64> {
    match (sigma, vrf) {
        (Some(s), Some(v)) if settled && v <= gate_max_vrf => {
            let g = rule.threshold(s, v, memory())?;
            let kb = rule.multiplier() * bias;
            Some((g * g + kb * kb).sqrt())
        }
        _ => None,
    }
}

/// A rejected sample is a marginal crossing (evidence of bias when the next sample crosses on
/// the same side) up to this many gate widths.
const MARGINAL: f64 = 1.25;

/// The current run of rejected samples (the gate's, not yet applied as a manoeuvre), and the
/// count of rejections.
#[derive(Debug, Default, serde::Serialize, serde::Deserialize)]
pub(super) struct Run {
    pending: Vec<Kept>,
    rejected: u64,
}

// Field by field, `clone_from` too (the review's kept copies reuse their buffers).
field_clone!(Run { pending, rejected });

impl Run {
    /// Samples rejected so far (not counting runs applied as manoeuvres).
    pub(super) fn rejected(&self) -> u64 {
        self.rejected
    }

    /// A final rejection (a review's decision): not part of a run.
    pub(super) fn reject_final(&mut self) {
        self.pending.clear();
        self.rejected += 1;
    }

    /// The gate rejected `sample`: it joins the run (counted by [`count`](Self::count) unless
    /// the run is taken for a manoeuvre).
    pub(super) fn push(&mut self, sample: Kept) {
        self.pending.push(sample);
    }

    /// Counts the newest sample of the run as a rejection.
    pub(super) fn count(&mut self) {
        self.rejected += 1;
    }

    /// Samples in the run.
    pub(super) fn len(&self) -> usize {
        self.pending.len()
    }

    /// The run is a manoeuvre: its samples, to be applied after all, of which all but the
    /// newest had been counted as rejections (they are not).
    pub(super) fn take(&mut self) -> Vec<Kept> {
        let run = std::mem::take(&mut self.pending);
        self.rejected -= run.len().saturating_sub(1) as u64;
        run
    }

    /// An accepted sample ends the run.
    pub(super) fn clear(&mut self) {
        self.pending.clear();
    }

    /// The prediction's position bias `b₀` raised by the current run: a rejected sample on the
    /// same side as the innovation `ν` and within [`MARGINAL`] gate widths
    /// (`|r| ≤ 1.25 k√(σ²(1+v) + b₀²)`, a marginal crossing, not a jump) is taken as evidence of
    /// bias (Morrison §14.8: repeated crossings mean bias), `b₀² ≥ r² − σ²(1+v)` with `r` its
    /// residual against `active`'s prediction and `v` that prediction's VRF; `k` the gate's
    /// multiplier.
    pub(super) fn with_pending(
        &self,
        active: &dyn PolynomialFilter,
        k: f64,
        b0: f64,
        nu: Option<f64>,
        sigma: Option<f64>,
    ) -> f64 {
        let (Some(nu), Some(s)) = (nu, sigma) else {
            return b0;
        };
        let mut b2 = b0 * b0;
        for p in &self.pending {
            let Some(pred) = active.estimate_at(p.t) else {
                continue;
            };
            let v = pred.covariance.as_ref().map_or(0.0, |c| c[(0, 0)].max(0.0));
            let r = p.y - pred.derivatives[0];
            let noise = s * s * (1.0 + v);
            let marginal = r.abs() <= MARGINAL * k * (noise + b0 * b0).sqrt();
            if marginal && r.signum() == nu.signum() && r * r - noise > b2 {
                b2 = r * r - noise;
            }
        }
        if b2.is_finite() {
            b2.sqrt().copysign(b0)
        } else {
            b0
        }
    }

    /// True when the run ends with `n =` [`AutoConfig::same_side_rejections`] `≥ 2` samples
    /// all on the same side of `active`'s prediction (Morrison §14.8: repeated crossings on one
    /// side mean bias, not outliers; two outliers in a row on one side at an outlier rate `p`
    /// happen at `p²/2` per sample).
    pub(super) fn same_side(&self, active: &dyn PolynomialFilter, n: usize) -> bool {
        if n < 2 || self.pending.len() < n {
            return false;
        }
        let mut side = 0.0;
        for p in &self.pending[self.pending.len() - n..] {
            let Some(pred) = active.estimate_at(p.t) else {
                return false;
            };
            let r = (p.y - pred.derivatives[0]).signum();
            if side != 0.0 && r != side {
                return false;
            }
            side = r;
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use crate::stats::noise::truncated_variance;

    /// Against the variance of the truncated density by Simpson's rule,
    /// `∫ z² φ(z) dz / ∫ φ(z) dz` over `[−a, a]`, and the limits.
    #[test]
    fn truncated_variance_matches_the_integral() {
        for a in [0.5, 1.0, 2.0, 3.0, 4.5] {
            let n = 20_000;
            let h = 2.0 * a / n as f64;
            let (mut m0, mut m2) = (0.0, 0.0);
            for k in 0..=n {
                let z = -a + k as f64 * h;
                let w = if k == 0 || k == n {
                    1.0
                } else if k % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                let phi = (-0.5 * z * z).exp();
                m0 += w * phi;
                m2 += w * z * z * phi;
            }
            let want = m2 / m0;
            let got = truncated_variance(a);
            assert!((got - want).abs() < 1e-9, "a = {a}: {got} against {want}");
        }
        assert_eq!(truncated_variance(f64::INFINITY), 1.0);
        assert!((truncated_variance(8.0) - 1.0).abs() < 1e-12);
    }
}
