//! Which filter gives the output ([`Phase`]), and the expanding → fading-memory switch of the
//! final degree (Morrison §13.8, (13.8.8); Reyneke et al. §7.2, Table 1): the rule's sample
//! index for the discount per sample so far, re-evaluated at each sample until the switch.

use super::filter::AutomaticFilter;
use crate::error::Error;
use crate::polynomial::fading::switch::memory_length_constant;
use crate::polynomial::vrf::{expanding_vrf, fading_vrf, EstimateForm};
use crate::polynomial::{DiscountMode, PolynomialFilter, SwitchRule};

/// Which filter produced an output.
///
/// ```
/// use seqsmooth::polynomial::automatic::{AutomaticFilter, Phase};
/// let mut f = AutomaticFilter::with_defaults(1, 0.8, 1.0).unwrap().with_noise_sigma(1.0).unwrap();
/// let phases: Vec<Phase> = (0..30).map(|n| f.update(n as f64, 2.0 * n as f64).unwrap().phase).collect();
/// assert_eq!(phases[0], Phase::Settling);            // degree 0 first
/// assert_eq!(phases[29], Phase::Fading);             // switched at ⌊3.2/0.2⌋ = 16
/// assert_eq!(f.switched_at(), Some(16));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// A lower degree of the quick-settling ladder (expanding memory).
    Settling,
    /// The final degree, expanding memory (before the switch).
    Expanding,
    /// The final degree, fading memory.
    Fading,
}

/// The constant `c` of a rule that switches at `n = ⌊c/(1-θ)⌋` (Morrison Table 13.4; Reyneke
/// Table 1), as [`SwitchRule::switch_index`] computes it; `None` for the exact crossover and an
/// explicit sample. Cached by the filter: the rule is evaluated at every sample until the switch.
pub(super) fn switch_constant(rule: SwitchRule, m: usize) -> Option<f64> {
    match rule {
        SwitchRule::Position => Some(memory_length_constant(0, m)),
        SwitchRule::ColumnMean => {
            Some((0..=m).map(|i| memory_length_constant(i, m)).sum::<f64>() / (m + 1) as f64)
        }
        SwitchRule::Derivative(i) => Some(memory_length_constant(i, m)),
        SwitchRule::ExactCrossover | SwitchRule::AtSample(_) => None,
    }
}

/// The switch index `⌊c/(1-θ_s)⌋` of a constant rule for the discount per sample `θ_s`, with the
/// 1e-9 allowance for the rounding of `c/(1-θ_s)` that [`SwitchRule::switch_index`] uses
/// (saturating at `u64::MAX`).
fn constant_rule_index(c: f64, theta_s: f64) -> u64 {
    let v = (c / (1.0 - theta_s) + 1e-9).floor();
    if v >= u64::MAX as f64 {
        u64::MAX
    } else {
        v as u64
    }
}

impl AutomaticFilter {
    /// The discount per sample the switch rules use: `θ` per update, or `θ^ζ̄` with `ζ̄` the mean
    /// step of the current memory so far (including `t`) in units of `τ`.
    pub(super) fn theta_per_sample(&self, t: f64) -> f64 {
        let n = self.fading.samples();
        let th = match (self.cfg.discount, self.memory_t_first) {
            (DiscountMode::PerTime, Some(t0)) if n > 0 => {
                let zeta = (t - t0) / (n as f64 * self.cfg.tau);
                self.cfg.theta.powf(zeta)
            }
            _ => self.cfg.theta,
        };
        th.clamp(1e-300, 1.0 - 1e-15)
    }

    /// Evaluates the expanding → fading switch for the next sample of the current memory, at
    /// time `t`: the rule's index for the per-sample discount so far, exactly as
    /// [`SwitchRule::switch_index`] (and the gain engine) computes it.
    pub(super) fn switch_due(&self, t: f64) -> Result<bool, Error> {
        if self.switched {
            return Ok(false);
        }
        let m = self.cfg.degree;
        let n = self.fading.samples();
        if n <= m as u64 {
            return Ok(false);
        }
        let theta_s = self.theta_per_sample(t);
        let index = match (self.cfg.switch_rule, self.switch_constant) {
            (SwitchRule::AtSample(k), _) => k,
            (_, Some(c)) => constant_rule_index(c, theta_s),
            _ => {
                // Exact crossover: the expanding-memory current position VRF reaches the
                // fading-memory one.
                let h0 = expanding_vrf::<f64>(m, n, EstimateForm::Current)?[(0, 0)];
                let target = fading_vrf(m, theta_s, EstimateForm::Current)?[(0, 0)];
                return Ok(h0 <= target * (1.0 + 1e-12));
            }
        };
        Ok(n >= index.max(m as u64 + 1))
    }
}

#[cfg(test)]
mod tests {
    use super::constant_rule_index;
    use crate::polynomial::fading::switch::memory_length_constant;
    use crate::polynomial::SwitchRule;

    /// The cached computation gives SwitchRule::switch_index's index for every constant rule.
    #[test]
    fn constant_rule_index_matches_switch_index() {
        for m in 0..=4 {
            for theta in [0.5, 0.8, 0.9, 0.93, 0.99] {
                let c = memory_length_constant(0, m);
                let want = SwitchRule::Position.switch_index(m, theta).unwrap();
                assert_eq!(constant_rule_index(c, theta).max(m as u64 + 1), want);
            }
        }
        assert_eq!(constant_rule_index(3.2, 1.0 - 1e-300), u64::MAX);
    }
}
