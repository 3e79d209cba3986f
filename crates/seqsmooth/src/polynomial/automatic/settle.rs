//! The quick-settling degree ladder (Reyneke et al. §7.3): expanding-memory filters of degrees
//! `d₀ … m` run in tandem from the first sample, and the active degree steps up once the next
//! one is ready — its current position VRF at most [`AutoConfig::settle_vrf`] and its top
//! derivative stable within its own 1σ for [`AutoConfig::settle_stable`] updates — or at once
//! when the active degree's misfit flag goes up.

use super::config::AutoConfig;
use super::memory::unit_expanding;
use super::misfit::Misfit;
use crate::error::Error;
use crate::polynomial::expanding::ExpandingMemory;
use crate::polynomial::filter::PolynomialFilter;

/// The ladder's filters below the final degree and the active degree.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub(super) struct Ladder {
    /// Expanding-memory filters indexed by degree `< m` (`None` once passed or below `d₀`).
    filters: Vec<Option<ExpandingMemory>>,
    /// The active degree (`m`: settled).
    active: usize,
    /// The final degree `m`.
    degree: usize,
    /// Consecutive updates the candidate's top derivative stayed within its 1σ.
    stable_runs: usize,
    prev_top: Option<f64>,
}

// Field by field, `clone_from` too (the review's kept copies reuse their buffers).
field_clone!(Ladder {
    filters,
    active,
    degree,
    stable_runs,
    prev_top
});

impl Ladder {
    /// The ladder of `cfg`: degrees [`AutoConfig::start_degree`] to `m − 1` below the final one.
    pub(super) fn new(cfg: &AutoConfig) -> Result<Self, Error> {
        let filters = (0..cfg.degree)
            .map(|d| {
                if d >= cfg.start_degree {
                    unit_expanding(d, cfg.engine).map(Some)
                } else {
                    Ok(None)
                }
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            filters,
            active: cfg.start_degree,
            degree: cfg.degree,
            stable_runs: 0,
            prev_top: None,
        })
    }

    /// The active degree.
    pub(super) fn active(&self) -> usize {
        self.active
    }

    /// The final degree is active.
    pub(super) fn settled(&self) -> bool {
        self.active == self.degree
    }

    /// The ladder's filter of degree `d < m` (`None` once passed).
    pub(super) fn filter(&self, d: usize) -> Option<&ExpandingMemory> {
        self.filters.get(d)?.as_ref()
    }

    /// Applies an accepted sample to the ladder's filters.
    pub(super) fn update(&mut self, t: f64, y: f64) -> Result<(), Error> {
        for f in self.filters.iter_mut().flatten() {
            f.update(t, y)?;
        }
        Ok(())
    }

    /// Steps the active degree up while the next degree is ready (see the module docs);
    /// `last` is the final degree's filter in use, `sigma` the noise, and `misfit` the tests,
    /// which start again at each step.
    pub(super) fn settle(
        &mut self,
        cfg: &AutoConfig,
        last: &dyn PolynomialFilter,
        sigma: Option<f64>,
        misfit: &mut Misfit,
    ) {
        let m = self.degree;
        while self.active < m {
            let c = self.active + 1;
            let cand: &dyn PolynomialFilter = if c < m {
                match &self.filters[c] {
                    Some(f) => f,
                    None => break,
                }
            } else {
                last
            };
            let Some(est) = cand.estimate() else { break };
            let Some(cov) = est.covariance.as_ref() else {
                break;
            };
            let vrf = cov[(0, 0)];
            // Stability of the candidate's top derivative against its own 1σ.
            let top = est.derivatives[c];
            let stable_now = match (self.prev_top, sigma) {
                (Some(prev), Some(s)) => (top - prev).abs() <= s * cov[(c, c)].max(0.0).sqrt(),
                _ => false,
            };
            self.stable_runs = if stable_now { self.stable_runs + 1 } else { 0 };
            self.prev_top = Some(top);
            let misfit_now = misfit.is_misfit() && vrf <= 1.0;
            let ready = vrf <= cfg.settle_vrf && self.stable_runs >= cfg.settle_stable;
            if !(ready || misfit_now) {
                break;
            }
            self.filters[self.active] = None;
            self.active = c;
            if self.settled() {
                // Every filter below the final degree is passed: none is kept (nor copied with
                // the state).
                self.filters = Vec::new();
            }
            misfit.reset();
            self.stable_runs = 0;
            self.prev_top = None;
        }
    }
}

impl Ladder {
    /// A restored ladder's invariants ([`crate::persist`]): each filter of its degree, the
    /// active degree at most the final one.
    pub(super) fn check_saved(&self, m: usize) -> Result<(), String> {
        // Settled, the passed filters are dropped (none kept).
        let settled_empty = self.active == m && self.filters.is_empty();
        if self.degree != m || self.active > m || (self.filters.len() != m && !settled_empty) {
            return Err("degree ladder is not of the filter's degree".into());
        }
        for (d, f) in self.filters.iter().enumerate() {
            if let Some(f) = f {
                if f.degree() != d {
                    return Err(format!(
                        "degree ladder's filter {d} is of degree {}",
                        f.degree()
                    ));
                }
                f.check_saved()?;
            }
        }
        Ok(())
    }
}
