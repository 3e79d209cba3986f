//! The outlier gate (Morrison §14.8, (14.8.4); Reyneke et al. §7.4): when an innovation `ν` is
//! too large for the noise `σ` and the prediction's own variance, the judgement of each sample
//! by the prediction of the memory chosen for it, and the variance of the noise that passes a
//! gate.

use super::config::check_positive;
use super::filter::AutomaticFilter;
#[cfg(doc)]
use super::AutoConfig;
use crate::error::{Error, Param};
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
#[derive(Clone, Copy, Debug, PartialEq)]
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

/// What [`AutomaticFilter::judge`] found for one sample.
pub(super) struct Judged {
    pub(super) sigma: Option<f64>,
    pub(super) innovation: Option<f64>,
    pub(super) vrf: Option<f64>,
    pub(super) innovation_sigma: Option<f64>,
    pub(super) k2: Option<f64>,
    pub(super) gate: Option<f64>,
    pub(super) rejected: bool,
}

impl AutomaticFilter {
    /// The prediction of the sample `(t, y)` by the memory of least estimated error, its
    /// innovation and honest `σ_ε`, and the gate's verdict (Morrison (14.8.1)-(14.8.4)).
    pub(super) fn judge(&mut self, t: f64, y: f64) -> Judged {
        let chosen = self.choose_memory(t);
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
            (Some(s), Some(v)) => self.innovation_excess(s * s * (1.0 + v)),
            _ => 0.0,
        };
        // The prediction's estimated bias: the honest innovation variance σ²(1 + v) + b₀².
        let bias0 = match (prediction, sigma) {
            (Some(p), Some(s)) => self.position_bias_of(p, chosen.map(|c| c.1), t, s),
            _ => 0.0,
        };
        let bias0 = self.with_pending(bias0, innovation, sigma);
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

    /// The gate half-width for the sample at `t`, given the noise `σ`, the prediction's VRF
    /// `v` and its estimated bias `b₀`: the rule's `g(σ, v, N)` widened to `√(g² + k²b₀²)`
    /// (for Morrison's rule `k √(σ²(1 + v) + b₀²)`, `k` times the honest `σ_ε`). Active only at
    /// the final degree, with `σ` known and the prediction at least as good as
    /// [`AutoConfig::gate_max_vrf`] says.
    pub(super) fn gate(
        &self,
        sigma: Option<f64>,
        vrf: Option<f64>,
        bias: f64,
        t: f64,
    ) -> Option<f64> {
        match (sigma, vrf) {
            (Some(s), Some(v)) if self.active == self.cfg.degree && v <= self.cfg.gate_max_vrf => {
                let g = self.cfg.outliers.threshold(s, v, self.memory_length(t))?;
                let kb = self.cfg.outliers.multiplier() * bias;
                Some((g * g + kb * kb).sqrt())
            }
            _ => None,
        }
    }

    /// Reyneke's memory length `N` at `t`: `c_0m/(1-θ_s)` once faded, else the active filter's
    /// sample count.
    fn memory_length(&self, t: f64) -> f64 {
        if self.active == self.cfg.degree && (self.switched || self.memory > 0) {
            // The memory in use discounts by θ^(2^j) per sample.
            let theta = self.theta_per_sample(t).powi(1 << self.memory);
            self.memory_constant / (1.0 - theta)
        } else {
            self.active_filter().samples().max(1) as f64
        }
    }
}

pub(super) use crate::stats::noise::truncated_variance;

#[cfg(test)]
mod tests {
    use super::truncated_variance;

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
