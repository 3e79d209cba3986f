//! Where the automatic filter's noise `σ` comes from: given, the normalised `(m+1)`-th divided
//! differences of the accepted samples (Reyneke et al. §7.1; [`DifferenceNoise`]), or the
//! normalised innovations of the final-degree filter (Morrison (14.8.4), (6.10.24)), each
//! corrected for the truncation of the outlier gate.

use crate::error::Error;
use crate::stats::noise::truncated_variance;
use crate::stats::DifferenceNoise;
use std::collections::VecDeque;

/// Noise terms needed before an estimated `σ` is used.
///
/// ```
/// use seqsmooth::polynomial::automatic::{AutomaticFilter, MIN_NOISE_TERMS};
/// let mut f = AutomaticFilter::new(0, 0.9, 1.0).unwrap(); // σ from differences
/// for n in 0..=MIN_NOISE_TERMS {
///     assert!(f.noise_sigma().is_none());
///     f.update(n as f64, if n % 2 == 0 { 1.0 } else { -1.0 }).unwrap();
/// }
/// assert!(f.noise_sigma().is_some()); // 6 samples: MIN_NOISE_TERMS first differences
/// ```
pub const MIN_NOISE_TERMS: usize = 5;

/// Where the noise `σ` comes from when it is not given.
///
/// ```
/// use seqsmooth::polynomial::automatic::{AutomaticFilter, NoiseSource};
/// let f = AutomaticFilter::new(2, 0.95, 1.0).unwrap();
/// assert_eq!(f.config().noise_source, NoiseSource::Differences { window: None });
/// let mut f = f.with_noise_source(NoiseSource::Innovations { window: Some(200) }).unwrap();
/// for n in 0..100 {
///     let t = n as f64;
///     f.update(t, 1.0 + t * t + if n % 2 == 0 { 0.5 } else { -0.5 }).unwrap();
/// }
/// assert!(f.noise_sigma().unwrap() > 0.4); // the ±0.5 pattern, the parabola is modelled
/// ```
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum NoiseSource {
    /// Normalised `(m+1)`-th divided differences of the accepted samples
    /// ([`crate::stats::DifferenceNoise`]), over the last `window` differences or all of them.
    /// Model-free, unbiased on any degree-`m` trend. The default (cumulative).
    Differences {
        /// Sliding window length in differences; `None` for all.
        window: Option<usize>,
    },
    /// Normalised innovations `ν²/(1+v)` of the final-degree filter (expanding, then fading),
    /// over the last `window` accepted samples or all; corrected for the gate's truncation.
    /// Inflated by unmodelled manoeuvres.
    Innovations {
        /// Sliding window length in samples; `None` for all.
        window: Option<usize>,
    },
}

impl Default for NoiseSource {
    fn default() -> Self {
        NoiseSource::Differences { window: None }
    }
}

impl NoiseSource {
    /// The window length, `None` for all terms.
    pub(super) fn window(&self) -> Option<usize> {
        match *self {
            NoiseSource::Differences { window } | NoiseSource::Innovations { window } => window,
        }
    }
}

/// A running mean over the last `window` values (or all of them), re-summed every `4·window`
/// pushes so that the rounding of the sliding sum does not accumulate.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub(super) struct WindowedMean {
    window: Option<usize>,
    values: VecDeque<f64>,
    sum: f64,
    count: usize,
    pushes: usize,
}

// Field by field, `clone_from` too (the review's kept copies reuse their buffers).
field_clone!(WindowedMean {
    window,
    values,
    sum,
    count,
    pushes
});

impl WindowedMean {
    fn new(window: Option<usize>) -> Self {
        Self {
            window,
            values: VecDeque::new(),
            sum: 0.0,
            count: 0,
            pushes: 0,
        }
    }

    fn push(&mut self, x: f64) {
        self.sum += x;
        match self.window {
            None => self.count += 1,
            Some(w) => {
                self.values.push_back(x);
                if self.values.len() > w {
                    let old = self.values.pop_front().unwrap_or(0.0);
                    self.sum -= old;
                }
                self.count = self.values.len();
                self.pushes += 1;
                if self.pushes >= 4 * w {
                    self.sum = self.values.iter().sum();
                    self.pushes = 0;
                }
                self.sum = self.sum.max(0.0);
            }
        }
    }

    fn mean(&self) -> Option<f64> {
        (self.count > 0).then(|| self.sum / self.count as f64)
    }
}

/// The noise estimate an [`AutomaticFilter`](super::AutomaticFilter) keeps.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub(super) enum NoiseState {
    Known(f64),
    Differences(DifferenceNoise, Box<Early>),
    Innovations(WindowedMean),
}

// `clone_from` into the same source reuses its buffers (the review's kept copies).
impl Clone for NoiseState {
    fn clone(&self) -> Self {
        match self {
            NoiseState::Known(s) => NoiseState::Known(*s),
            NoiseState::Differences(d, e) => NoiseState::Differences(d.clone(), e.clone()),
            NoiseState::Innovations(w) => NoiseState::Innovations(w.clone()),
        }
    }

    fn clone_from(&mut self, source: &Self) {
        match (self, source) {
            (NoiseState::Differences(d, e), NoiseState::Differences(ds, es)) => {
                d.clone_from(ds);
                e.as_mut().clone_from(es);
            }
            (NoiseState::Innovations(w), NoiseState::Innovations(ws)) => w.clone_from(ws),
            (to, from) => *to = from.clone(),
        }
    }
}

/// The accepted samples whose differences the start-up estimate screens at once ([`Early`]).
pub(super) const EARLY_SAMPLES: usize = 40;

/// The mean of `χ²₁` below its 80% quantile (the trimmed reference of [`Early`]).
const CHI2_1_TRIMMED_MEAN: f64 = 0.437_724_6;

/// The difference estimate over the first [`EARLY_SAMPLES`] accepted samples, screened against
/// a reference from all of them at once. The running estimate screens each difference against
/// the differences before it, so an outlier among the first few samples — before there is a
/// reference — enters up to `m + 2` of its first terms and inflates `σ̂` (an 8σ outlier in
/// the first 5 terms of third differences: `σ̂ ≈ 3.7σ`), and with it every gate and every review
/// of the start-up, which then pass it. Here every early difference is screened at `|d| > c σ̂₀`
/// (and the `m + 1` after it, which share its samples), `σ̂₀²` the mean of the smallest 80% of
/// the early squared differences over its Gaussian value (robust while under a fifth of the
/// terms are an outlier's), the kept ones divided by the truncated variance. Once the review
/// rejects the outlier, the filter takes the samples again without it, and the running estimate
/// is clean too.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub(super) struct Early {
    /// The screen `c` ([`AutoConfig::noise_screen`](super::AutoConfig::noise_screen)).
    screen: f64,
    /// `(t, y, variance factor)` of the first accepted samples, until [`EARLY_SAMPLES`].
    samples: Vec<(f64, f64, f64)>,
    /// The estimate from them, once it has [`MIN_NOISE_TERMS`] terms.
    sigma: Option<f64>,
    done: bool,
}

// Field by field, `clone_from` too (the review's kept copies reuse their buffers).
field_clone!(Early {
    screen,
    samples,
    sigma,
    done
});

impl Early {
    fn new(screen: f64) -> Self {
        Self {
            screen,
            samples: Vec::new(),
            sigma: None,
            done: false,
        }
    }

    /// Adds an accepted sample; recomputes the early estimate of differences of order `k`.
    fn push(&mut self, t: f64, y: f64, factor: f64, k: usize) -> Result<(), Error> {
        let c = self.screen;
        if self.done {
            return Ok(());
        }
        self.samples.push((t, y, factor));
        if self.samples.len() > EARLY_SAMPLES {
            self.done = true;
            self.samples = Vec::new();
            self.sigma = None;
            return Ok(());
        }
        // Each squared difference over its expected value: an estimator of one term.
        let mut probe = DifferenceNoise::new(k, Some(1))?;
        let mut terms = Vec::with_capacity(self.samples.len());
        for &(t, y, f) in &self.samples {
            probe.push_with_variance_factor(t, y, f)?;
            if let Some(v) = probe.variance() {
                terms.push(v);
            }
        }
        if terms.len() < MIN_NOISE_TERMS {
            return Ok(());
        }
        let mut sorted = terms.clone();
        sorted.sort_by(f64::total_cmp);
        let kept = ((sorted.len() * 4) / 5).max(3);
        let reference = sorted[..kept].iter().sum::<f64>() / kept as f64 / CHI2_1_TRIMMED_MEAN;
        let (mut sum, mut n, mut holdoff) = (0.0, 0usize, 0usize);
        for d2 in terms {
            if holdoff > 0 {
                holdoff -= 1;
            } else if c.is_finite() && d2 > c * c * reference {
                holdoff = k;
            } else {
                sum += d2;
                n += 1;
            }
        }
        let truncation = if c.is_finite() {
            truncated_variance(c)
        } else {
            1.0
        };
        self.sigma = (n > 0 && sum > 0.0).then(|| (sum / n as f64 / truncation).sqrt());
        Ok(())
    }
}

impl NoiseState {
    /// The state for a given `σ`, or an estimator of the source for degree `m`; the difference
    /// estimator with the screen `c` ([`DifferenceNoise::with_screen`]).
    pub(super) fn new(
        sigma: Option<f64>,
        source: NoiseSource,
        m: usize,
        screen: f64,
    ) -> Result<Self, Error> {
        Ok(match (sigma, source) {
            (Some(s), _) => NoiseState::Known(s),
            (None, NoiseSource::Differences { window }) => {
                let d = DifferenceNoise::new(m + 1, window)?.with_screen(screen)?;
                NoiseState::Differences(d, Box::new(Early::new(screen)))
            }
            (None, NoiseSource::Innovations { window }) => {
                NoiseState::Innovations(WindowedMean::new(window))
            }
        })
    }

    /// True while the difference estimate is the start-up one ([`Early`]): the review waits
    /// for the first [`EARLY_SAMPLES`] accepted samples before it decides, so that one or two
    /// outliers among the first samples are judged against a `σ̂` screened of them.
    pub(super) fn is_early(&self) -> bool {
        matches!(self, NoiseState::Differences(_, e) if !e.done)
    }

    /// True when the estimate is built from the final-degree filter's innovations (the caller
    /// then supplies them to [`push`](Self::push)).
    pub(super) fn wants_innovations(&self) -> bool {
        matches!(self, NoiseState::Innovations(_))
    }

    /// `σ`: the given one, or the running estimate once it has [`MIN_NOISE_TERMS`] terms.
    pub(super) fn sigma(&self) -> Option<f64> {
        match self {
            NoiseState::Known(s) => Some(*s),
            NoiseState::Differences(_, e) if !e.done => e.sigma,
            NoiseState::Differences(d, _) => d.sigma(),
            NoiseState::Innovations(w) => {
                if w.count >= MIN_NOISE_TERMS {
                    w.mean().map(f64::sqrt)
                } else {
                    None
                }
            }
        }
    }

    /// Adds an accepted sample `(t, y)`. `innovation` is the final-degree filter's normalised
    /// squared innovation `ν²/(1+v)` (used by the innovation estimate); `truncation` is `(a, v)`,
    /// the gate half-width in units of `σ_ε` and the prediction VRF, when the gate was active;
    /// `manoeuvre` marks a run of rejections applied after all (left out of the innovation
    /// estimate).
    pub(super) fn push(
        &mut self,
        t: f64,
        y: f64,
        innovation: Option<f64>,
        truncation: Option<(f64, f64)>,
        manoeuvre: bool,
    ) -> Result<(), Error> {
        match self {
            NoiseState::Known(_) => {}
            NoiseState::Innovations(w) => {
                // Samples the gate could have cut are divided by the truncated variance.
                if let (Some(term), false) = (innovation, manoeuvre) {
                    w.push(term / truncation.map_or(1.0, |(a, _)| truncated_variance(a)));
                }
            }
            NoiseState::Differences(d, early) => {
                // A gated sample's own noise e has E{e² | |ν| ≤ aσ_ε} = σ²(c(a) + v)/(1 + v),
                // with c(a) the truncated unit variance (e = ν/(1+v) + an independent part).
                let factor =
                    truncation.map_or(1.0, |(a, v)| (truncated_variance(a) + v) / (1.0 + v));
                d.push_with_variance_factor(t, y, factor)?;
                early.push(t, y, factor, d.order())?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::WindowedMean;

    /// The sliding mean against a direct mean over the last `w` values, across the re-summing.
    #[test]
    fn windowed_mean_equals_the_mean_of_the_window() {
        let xs: Vec<f64> = (0..50).map(|k| ((k * 13 % 7) as f64) * 0.25).collect();
        let mut w = WindowedMean::new(Some(4));
        let mut all = WindowedMean::new(None);
        for (k, &x) in xs.iter().enumerate() {
            w.push(x);
            all.push(x);
            let lo = (k + 1).saturating_sub(4);
            let want = xs[lo..=k].iter().sum::<f64>() / (k + 1 - lo) as f64;
            assert!((w.mean().unwrap() - want).abs() < 1e-12);
            let want_all = xs[..=k].iter().sum::<f64>() / (k + 1) as f64;
            assert!((all.mean().unwrap() - want_all).abs() < 1e-12);
        }
    }
}
