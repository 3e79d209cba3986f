//! When the model no longer fits (Morrison §14.8, (14.8.5)): the response to a misfit of the
//! innovation chi-squared test, and the restart of the final-degree memory from the estimated
//! onset of the manoeuvre (a CUSUM change point).

use super::build::{unit_expanding, unit_fading, upper_pair};
use super::filter::AutomaticFilter;
use super::memory::shorter_memories;
use crate::error::{Error, Param};
use crate::polynomial::filter::PolynomialFilter;

/// What the filter does when its innovations say the model no longer fits (Morrison §14.8).
///
/// ```
/// use seqsmooth::polynomial::automatic::MisfitResponse;
/// assert_eq!(MisfitResponse::default(), MisfitResponse::Restart { alpha: 1e-4 });
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MisfitResponse {
    /// Raise [`AutoOutput::misfit`](super::AutoOutput::misfit) only: the memory keeps the
    /// unmodelled manoeuvre until it fades (about two memory lengths `c_0m/(1-θ)` for the bias
    /// to fall below 1% of its peak).
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::{AutomaticFilter, MisfitResponse};
    /// let mut f = AutomaticFilter::new(1, 0.95, 1.0).unwrap()
    ///     .with_noise_sigma(0.1).unwrap()
    ///     .with_misfit_response(MisfitResponse::Flag).unwrap();
    /// let mut flagged = false;
    /// for n in 0..300 {
    ///     let t = n as f64;
    ///     let y = 0.5 * t + if t > 200.0 { 0.05 * (t - 200.0).powi(2) } else { 0.0 };
    ///     let out = f.update(t, y).unwrap();
    ///     flagged |= out.misfit;
    ///     assert!(!out.restart);
    /// }
    /// assert!(flagged && f.restarts() == 0);
    /// ```
    Flag,
    /// Also restart the final-degree memory when the same window sum exceeds the `(1-alpha)`
    /// quantile of `χ²_K` (a stricter test than the flag's), or a run of rejections is taken for
    /// a manoeuvre: the filters are rebuilt from the samples since the estimated onset (the
    /// suffix of the window with the largest CUSUM `Σ(ν²/σ_ε² − 3)`, at least `m+1` samples) and
    /// grow back through the expanding-memory start and the switch. Morrison's response — "β can
    /// be temporarily reduced until the threshold crossings cease … then the memory can again be
    /// lengthened" — in its limit `θ → 0`, then back to `θ`. The default, with `alpha = 10⁻⁴`
    /// (on a fitting model about one false restart per 10⁴ samples).
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::{AutomaticFilter, MisfitResponse};
    /// let f = AutomaticFilter::new(1, 0.95, 1.0).unwrap().with_noise_sigma(0.1).unwrap();
    /// assert_eq!(f.config().misfit_response, MisfitResponse::Restart { alpha: 1e-4 });
    /// let mut f = f;
    /// let mut first_restart = None;
    /// for n in 0..300 {
    ///     let t = n as f64;
    ///     let noise = 0.1 * (((n * 37 + 11) % 17) as f64 / 8.0 - 1.0);
    ///     // a ramp that turns into a parabola at t = 200 (unmodelled by degree 1)
    ///     let y = 0.5 * t + if t > 200.0 { 0.05 * (t - 200.0).powi(2) } else { 0.0 } + noise;
    ///     if f.update(t, y).unwrap().restart { first_restart.get_or_insert(n); }
    /// }
    /// let n = first_restart.unwrap();
    /// assert!(n > 200 && n <= 210);
    /// ```
    Restart {
        /// Per-sample false-alarm rate `∈ (0,1)` of the restart test.
        alpha: f64,
    },
}

impl Default for MisfitResponse {
    fn default() -> Self {
        MisfitResponse::Restart { alpha: 1e-4 }
    }
}

impl MisfitResponse {
    pub(super) fn validate(&self) -> Result<(), Error> {
        if let MisfitResponse::Restart { alpha } = *self {
            if !(alpha > 0.0 && alpha < 1.0) {
                return Err(Error::InvalidParameter {
                    name: Param::RestartSignificance,
                    value: alpha.to_string(),
                    reason: "must lie strictly between 0 and 1".into(),
                });
            }
        }
        Ok(())
    }
}

/// A sample kept for a restart or a run of rejections, with `ν²/σ_ε²` against the active
/// filter's prediction when it arrived.
#[derive(Clone, Copy, Debug)]
pub(super) struct Kept {
    pub(super) t: f64,
    pub(super) y: f64,
    pub(super) k2: Option<f64>,
}

/// The estimated onset of a misfit among the `recent` samples: the start of the suffix of the
/// last `window` samples that maximises the CUSUM `Σ (k² − 3)` (a change-point estimate), moved
/// back if needed so that at least `m + 1` samples remain. A term of a fitting model lowers the
/// sum with probability `P(χ²_1 < 3) = 92%`, so the suffix rarely reaches back before the onset;
/// ties keep the later start.
fn misfit_onset(recent: &[Kept], window: usize, m: usize) -> usize {
    let len = recent.len();
    let window = window.min(len);
    let mut best = (0.0, len);
    let mut sum = 0.0;
    for j in (len - window..len).rev() {
        if let Some(k2) = recent[j].k2 {
            sum += k2 - 3.0;
            if sum > best.0 {
                best = (sum, j);
            }
        }
    }
    best.1.min(len.saturating_sub(m + 1))
}

impl AutomaticFilter {
    /// Restarts the final-degree memory from the samples since the estimated onset of the
    /// misfit ([`misfit_onset`]), with at least `m + 1` samples (so the state stays determined).
    pub(super) fn restart(&mut self) -> Result<(), Error> {
        let m = self.cfg.degree;
        let recent: Vec<Kept> = self.recent.iter().copied().collect();
        // m + 2 samples at least: the degree m + 1 companion is determined (its bias estimate).
        let start = misfit_onset(&recent, self.cfg.misfit_window, m + 1);
        let kept = &recent[start..];
        let mut expanding = unit_expanding(m, self.cfg.engine)?;
        let mut fading = unit_fading(&self.cfg, m)?;
        let (mut upper_expanding, mut upper_fading) = upper_pair(&self.cfg)?;
        let mut shorter = shorter_memories(&self.cfg)?;
        for k in kept {
            for s in &mut shorter {
                s.fading.update(k.t, k.y)?;
                s.upper.update(k.t, k.y)?;
            }
            expanding.update(k.t, k.y)?;
            fading.update(k.t, k.y)?;
            if let Some(f) = &mut upper_expanding {
                f.update(k.t, k.y)?;
            }
            if let Some(f) = &mut upper_fading {
                f.update(k.t, k.y)?;
            }
        }
        self.expanding = Some(expanding);
        self.fading = fading;
        self.upper_expanding = upper_expanding;
        self.upper_fading = upper_fading;
        self.shorter = shorter;
        self.memory = 0;
        self.longer_runs = 0;
        self.calibration.clear();
        self.switched = false;
        self.memory_t_first = kept.first().map(|k| k.t);
        self.chi.reset();
        if let Some(r) = &mut self.restart_test {
            r.reset();
        }
        // The kept samples' innovations belong to the old memory.
        self.recent = kept.iter().map(|k| Kept { k2: None, ..*k }).collect();
        self.restarts += 1;
        self.last_restart = Some(self.accepted.saturating_sub(1));
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::{misfit_onset, Kept};

    fn kept(k2: &[f64]) -> Vec<Kept> {
        k2.iter()
            .enumerate()
            .map(|(j, &k2)| Kept {
                t: j as f64,
                y: 0.0,
                k2: Some(k2),
            })
            .collect()
    }

    /// The onset is where the large terms begin; at least m + 1 samples are kept.
    #[test]
    fn onset_is_the_start_of_the_large_terms() {
        let r = kept(&[1.0, 0.5, 1.0, 9.0, 16.0, 25.0]);
        assert_eq!(misfit_onset(&r, 6, 1), 3);
        assert_eq!(misfit_onset(&r, 6, 4), 1); // 5 samples kept
                                               // nothing above 3: no suffix raises the sum, keep the last m + 1
        let quiet = kept(&[1.0, 1.0, 1.0, 1.0]);
        assert_eq!(misfit_onset(&quiet, 4, 1), 2);
    }
}
