//! The quick-settling degree ladder (Reyneke et al. §7.3): expanding-memory filters of degrees
//! `d₀ … m` run in tandem from the first sample, and the active degree steps up once the next
//! one is ready — its current position VRF at most [`AutoConfig::settle_vrf`] and its top
//! derivative stable within its own 1σ for [`AutoConfig::settle_stable`] updates — or at once
//! when the active degree's misfit flag goes up.

use super::filter::AutomaticFilter;
#[cfg(doc)]
use super::AutoConfig;

impl AutomaticFilter {
    /// Steps the active degree up while the next degree is ready (see the module docs).
    pub(super) fn settle(&mut self) {
        let m = self.cfg.degree;
        while self.active < m {
            let c = self.active + 1;
            let Some(cand) = self.filter(c) else { break };
            let Some(est) = cand.estimate() else { break };
            let Some(cov) = est.covariance.as_ref() else {
                break;
            };
            let vrf = cov[(0, 0)];
            // Stability of the candidate's top derivative against its own 1σ.
            let top = est.derivatives[c];
            let stable_now = match (self.prev_top, self.noise_sigma()) {
                (Some(prev), Some(s)) => (top - prev).abs() <= s * cov[(c, c)].max(0.0).sqrt(),
                _ => false,
            };
            self.stable_runs = if stable_now { self.stable_runs + 1 } else { 0 };
            self.prev_top = Some(top);
            let misfit = self.chi.is_misfit() && vrf <= 1.0;
            let ready = vrf <= self.cfg.settle_vrf && self.stable_runs >= self.cfg.settle_stable;
            if !(ready || misfit) {
                break;
            }
            self.ladder[self.active] = None;
            self.active = c;
            self.chi.reset();
            if let Some(r) = &mut self.restart_test {
                r.reset();
            }
            self.stable_runs = 0;
            self.prev_top = None;
        }
    }
}
