//! When the model no longer fits (Morrison §14.8, (14.8.5)): the response to a misfit of the
//! innovation chi-squared test, and the restart of the final-degree memory from the estimated
//! onset of the manoeuvre (a CUSUM change point).

use crate::error::{Error, Param};
use crate::stats::{ChiSquaredOutcome, InnovationChiSquared};
use std::collections::VecDeque;

/// What the filter does when its innovations say the model no longer fits (Morrison §14.8).
///
/// ```
/// use seqsmooth::polynomial::automatic::MisfitResponse;
/// assert_eq!(MisfitResponse::default(), MisfitResponse::Restart { alpha: 1e-4 });
/// ```
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
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
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
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

/// The misfit tests and what a restart needs (Morrison §14.8): the innovation chi-squared
/// window of the flag, the stricter one of the restart ([`MisfitResponse::Restart`]), the
/// newest accepted samples, and the restarts so far.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub(super) struct Misfit {
    chi: InnovationChiSquared,
    restart_test: Option<InnovationChiSquared>,
    /// The newest accepted samples (for a restart), at most `keep`.
    recent: VecDeque<Kept>,
    keep: usize,
    /// The misfit window `K` (the onset is looked for in its last `K` samples).
    window: usize,
    restarts: u64,
    last_restart: Option<u64>,
}

// Field by field, `clone_from` too (the review's kept copies reuse their buffers).
field_clone!(Misfit {
    chi,
    restart_test,
    recent,
    keep,
    window,
    restarts,
    last_restart
});

impl Misfit {
    /// The tests of window `window` and false-alarm rate `alpha`, the restart's per
    /// `response`, keeping the newest `keep` accepted samples.
    pub(super) fn new(
        window: usize,
        alpha: f64,
        response: MisfitResponse,
        keep: usize,
    ) -> Result<Self, Error> {
        let chi = InnovationChiSquared::new(window, alpha)?;
        let restart_test = match response {
            MisfitResponse::Flag => None,
            MisfitResponse::Restart { alpha } => Some(InnovationChiSquared::new(window, alpha)?),
        };
        Ok(Self {
            chi,
            restart_test,
            recent: VecDeque::new(),
            keep,
            window,
            restarts: 0,
            last_restart: None,
        })
    }

    /// Keeps an accepted sample and adds its `ν²/σ_ε²` (when it has one) to both tests; the
    /// flag's window after it.
    pub(super) fn push(&mut self, sample: Kept) -> Result<Option<ChiSquaredOutcome>, Error> {
        self.recent.push_back(sample);
        while self.recent.len() > self.keep {
            self.recent.pop_front();
        }
        match sample.k2 {
            Some(k2) => {
                if let Some(r) = &mut self.restart_test {
                    r.push_normalised(k2)?;
                }
                Ok(Some(self.chi.push_normalised(k2)?))
            }
            None => Ok(None),
        }
    }

    /// The flag's test says the model no longer fits.
    pub(super) fn is_misfit(&self) -> bool {
        self.chi.is_misfit()
    }

    /// The flag's window (for the innovations' excess).
    pub(super) fn chi(&self) -> &InnovationChiSquared {
        &self.chi
    }

    /// The response restarts the memory ([`MisfitResponse::Restart`]).
    pub(super) fn restarts_memory(&self) -> bool {
        self.restart_test.is_some()
    }

    /// The restart's test says the memory must restart.
    pub(super) fn restart_due(&self) -> bool {
        self.restart_test.as_ref().is_some_and(|r| r.is_misfit())
    }

    /// Both windows start again (a new degree or memory).
    pub(super) fn reset(&mut self) {
        self.chi.reset();
        if let Some(r) = &mut self.restart_test {
            r.reset();
        }
    }

    /// The samples since the estimated onset of the misfit ([`misfit_onset`]), at least
    /// `m + 2` of them (so that the degree `m + 1` companion is determined: its bias estimate).
    pub(super) fn since_onset(&self, m: usize) -> Vec<Kept> {
        let recent: Vec<Kept> = self.recent.iter().copied().collect();
        let start = misfit_onset(&recent, self.window, m + 1);
        recent[start..].to_vec()
    }

    /// The memory restarted from `kept` ([`since_onset`](Self::since_onset)) when `accepted`
    /// samples were in: the windows start again, and the kept samples' innovations, which
    /// belong to the old memory, are forgotten.
    pub(super) fn restarted(&mut self, kept: &[Kept], accepted: u64) {
        self.reset();
        self.recent = kept.iter().map(|k| Kept { k2: None, ..*k }).collect();
        self.restarts += 1;
        self.last_restart = Some(accepted.saturating_sub(1));
    }

    /// Restarts so far.
    pub(super) fn restarts(&self) -> u64 {
        self.restarts
    }

    /// The index (in accepted samples) of the newest sample at the latest restart.
    pub(super) fn last_restart(&self) -> Option<u64> {
        self.last_restart
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
