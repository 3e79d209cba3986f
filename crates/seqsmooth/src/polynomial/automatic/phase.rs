//! Which filter gives the output ([`Phase`]), and the expanding → fading-memory switch of the
//! final degree (Morrison §13.8, (13.8.8); Reyneke et al. §7.2, Table 1): the rule's sample
//! index for the discount per sample so far, re-evaluated at each sample until the switch.

use super::filter::AutomaticFilter;
use crate::error::Error;
use crate::polynomial::expanding::vrf::expanding_vrf;
#[cfg(doc)]
use crate::polynomial::fading::switch::SwitchRule;
use crate::polynomial::fading::vrf::fading_vrf;
use crate::polynomial::filter::PolynomialFilter;
use crate::polynomial::form::EstimateForm;
use crate::polynomial::options::DiscountMode;

/// Which filter produced an output.
///
/// ```
/// use seqsmooth::polynomial::automatic::{AutomaticFilter, Phase};
/// let mut f = AutomaticFilter::new(1, 0.8, 1.0).unwrap().with_noise_sigma(1.0).unwrap();
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
    /// The final degree, fading memory (the configured `θ` after the switch, or a shorter
    /// memory `θ^(2^j)`, see [`AutomaticFilter::memory`](super::AutomaticFilter::memory)).
    Fading,
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
        // The exact crossover: the expanding-memory current position VRF reaches the
        // fading-memory one.
        self.cfg
            .switch_rule
            .switches(m, n, theta_s, self.switch_constant, || {
                Ok((
                    expanding_vrf::<f64>(m, n, EstimateForm::Current)?[(0, 0)],
                    fading_vrf(m, theta_s, EstimateForm::Current)?[(0, 0)],
                ))
            })
    }
}
