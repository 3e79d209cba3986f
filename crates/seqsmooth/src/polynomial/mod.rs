//! The expanding- and fading-memory polynomial filters of any degree, on evenly spaced or
//! irregular timestamps (Morrison ch. 9, 13; Reyneke et al. §6).
//!
//! Each filter runs on one of two [`Engine`]s:
//!
//! - [`Engine::Exact`] — recursive least squares with the polynomial model on arbitrary
//!   timestamps, `O(m²)` per sample, equal to the batch fit over all samples so far (expanding
//!   memory: equal weights; fading memory: weights `θ^((t_n - t_k)/τ)`, or `θ^(n-k)` with
//!   [`DiscountMode::PerUpdate`]). It is the polynomial instance of the square-root information
//!   filter of [`crate::recursive`], in a centred, scaled monomial basis (see
//!   `exact_engine` docs for why). Determined from the `(m+1)`-th sample on.
//! - [`Engine::Gain`] — the fixed-gain recursion of Morrison's Tables 9.1/13.1 in Reyneke's
//!   variable-step form: predict by `Φ(ζ)`, `ζ = Δt/τ`, correct with gains `h_k/ζ̄^k` scaled for
//!   the typical step `ζ̄` of the memory (fading: `θ_eff = θ^ζ̄`). `O(m)` per sample after the
//!   prediction. Exact least squares on evenly spaced samples for any step (there `ζ̄ = ζ`); an
//!   approximation on irregular timestamps. It starts from the exact interpolating polynomial of
//!   the first `m+1` samples and carries its state in compensated arithmetic (see
//!   `gain_engine` for why, with measurements).
//!
//! ## Accuracy (measured; `tests/engines.rs`)
//!
//! Relative error per derivative against batch QR (Legendre basis) or exact rational least
//! squares, worst over each run, degrees 0-8: the exact engine ≤ 5e-11 on even, jittered and
//! Poisson timestamps, expanding and fading (≤ 1e-11 over a 10⁵-sample run at degree 8). On
//! 2 000 irregular samples (expanding / fading): 3.5e-12 / 5.3e-12 at degree 12, 7.3e-10 /
//! 1.4e-9 at 14, 1.5e-9 / 1.8e-10 at 16, 1.2e-7 / 2.4e-7 at 20, 8.5e-6 / 3.3e-5 at 24 — the
//! centred monomial basis is what limits it (asserted bounds: 1e-9 to degree 12, 1e-6
//! to 16, 1e-3 to [`MAX_DEGREE`]). The gain engine on even samples: ≤ 5e-11 (expanding, 200
//! samples), ≤ 5e-10 over 10⁵ samples at degree 8, ≤ 5e-12 for fading memory once the switch
//! transient `θ^n·poly(n)` has decayed.
//!
//! ## The gain engine on irregular timestamps
//!
//! Measured by `cargo run --release -p seqsmooth --example gain_engine_deviation`: 200 Monte
//! Carlo runs per row of a degree-`m` polynomial truth plus unit white noise, nominal step 1
//! (expanding: 100 samples, scored from sample `4(m+1)`; fading: θ = 0.9 per τ = 1, 400
//! samples, scored from sample 200). "MSE ratio" is the gain engine's mean squared error
//! against the truth over the exact engine's; the last columns give the largest gain−exact
//! difference in units of the exact estimate's own 1σ. Jitter ±p% perturbs each step
//! uniformly; "random" draws exponential steps (a Poisson process); "bursts and gaps" draws
//! steps from {0.5, 1, 1, 1, 2, 3} × U(0.8, 1.2).
//!
//! | memory | schedule | m | MSE ratio x | MSE ratio x' | max abs(gain−exact)/σ x | max abs(gain−exact)/σ x' |
//! |---|---|---|---|---|---|---|
//! | expanding | even | 1 | 1.000 | 1.000 | 3.58e-14 | 2.56e-14 |
//! | expanding | even | 2 | 1.000 | 1.000 | 3.02e-14 | 1.71e-14 |
//! | expanding | even | 3 | 1.000 | 1.000 | 1.54e-14 | 1.64e-14 |
//! | expanding | even | 4 | 1.000 | 1.000 | 4.40e-14 | 8.07e-14 |
//! | expanding | jitter 20% | 1 | 0.999 | 0.994 | 1.66e-1 | 2.61e-1 |
//! | expanding | jitter 20% | 2 | 0.998 | 0.991 | 2.07e-1 | 2.85e-1 |
//! | expanding | jitter 20% | 3 | 1.004 | 1.012 | 4.31e-1 | 7.78e-1 |
//! | expanding | jitter 20% | 4 | 1.009 | 1.012 | 4.25e-1 | 5.87e-1 |
//! | expanding | jitter 50% | 1 | 1.001 | 1.008 | 4.23e-1 | 9.04e-1 |
//! | expanding | jitter 50% | 2 | 1.006 | 1.019 | 7.96e-1 | 1.26e0 |
//! | expanding | jitter 50% | 3 | 1.028 | 1.089 | 1.21e0 | 2.05e0 |
//! | expanding | jitter 50% | 4 | 1.053 | 1.137 | 2.31e0 | 3.55e0 |
//! | expanding | random (exponential) | 1 | 2.579 | 7.629 | 1.63e1 | 3.76e1 |
//! | expanding | random (exponential) | 2 | 135.059 | 670.423 | 2.35e2 | 3.59e2 |
//! | expanding | random (exponential) | 3 | 262829882.145 | 881303136.471 | 6.08e5 | 7.54e5 |
//! | expanding | random (exponential) | 4 | 174839869553.543 | 871248753400.558 | 1.38e7 | 2.28e7 |
//! | expanding | bursts and gaps | 1 | 1.058 | 1.106 | 1.14e0 | 1.63e0 |
//! | expanding | bursts and gaps | 2 | 1.547 | 3.388 | 1.21e1 | 1.93e1 |
//! | expanding | bursts and gaps | 3 | 1.821 | 4.818 | 1.37e1 | 2.45e1 |
//! | expanding | bursts and gaps | 4 | 54.869 | 312.332 | 2.34e2 | 3.39e2 |
//! | fading θ=0.9 | even | 1 | 1.000 | 1.000 | 3.32e-7 | 8.06e-7 |
//! | fading θ=0.9 | even | 2 | 1.000 | 1.000 | 1.60e-5 | 3.88e-5 |
//! | fading θ=0.9 | even | 3 | 1.000 | 1.000 | 4.92e-4 | 1.20e-3 |
//! | fading θ=0.9 | even | 4 | 1.000 | 1.000 | 4.15e-3 | 1.03e-2 |
//! | fading θ=0.9 | jitter 20% | 1 | 1.000 | 1.000 | 1.31e-1 | 1.53e-1 |
//! | fading θ=0.9 | jitter 20% | 2 | 1.000 | 1.001 | 1.49e-1 | 1.52e-1 |
//! | fading θ=0.9 | jitter 20% | 3 | 1.000 | 1.001 | 1.77e-1 | 1.70e-1 |
//! | fading θ=0.9 | jitter 20% | 4 | 1.000 | 1.000 | 2.55e-1 | 2.32e-1 |
//! | fading θ=0.9 | jitter 50% | 1 | 0.997 | 0.999 | 3.13e-1 | 3.91e-1 |
//! | fading θ=0.9 | jitter 50% | 2 | 0.999 | 1.001 | 3.73e-1 | 3.76e-1 |
//! | fading θ=0.9 | jitter 50% | 3 | 0.999 | 1.005 | 4.87e-1 | 4.46e-1 |
//! | fading θ=0.9 | jitter 50% | 4 | 0.999 | 1.005 | 6.59e-1 | 6.41e-1 |
//! | fading θ=0.9 | random (exponential) | 1 | 0.955 | 0.981 | 1.31e0 | 1.21e0 |
//! | fading θ=0.9 | random (exponential) | 2 | 0.975 | 1.011 | 1.50e0 | 1.94e0 |
//! | fading θ=0.9 | random (exponential) | 3 | 0.987 | 1.051 | 1.71e0 | 2.54e0 |
//! | fading θ=0.9 | random (exponential) | 4 | 1.267 | 2.155 | 3.17e1 | 6.25e1 |
//! | fading θ=0.9 | bursts and gaps | 1 | 0.972 | 0.987 | 5.80e-1 | 9.68e-1 |
//! | fading θ=0.9 | bursts and gaps | 2 | 0.983 | 1.002 | 9.89e-1 | 9.93e-1 |
//! | fading θ=0.9 | bursts and gaps | 3 | 0.983 | 1.012 | 1.22e0 | 1.18e0 |
//! | fading θ=0.9 | bursts and gaps | 4 | 1.004 | 1.048 | 1.42e0 | 1.51e0 |
//!
//! Reading: on even samples the engines agree (the fading rows show the switch transient still
//! present at sample 200 for m ≥ 3). With moderate jitter the gain engine is within a few
//! percent of exact least squares; for fading memory this holds on average on every schedule
//! up to degree 3 (single samples on Poisson arrivals can stray by tens of σ: see the test
//! `gain_engine_stays_close_to_least_squares_on_irregular_schedules`). The expanding-memory gain engine is **not** usable on strongly irregular
//! sampling (Poisson arrivals, bursts at degree ≥ 2): its early errors, from gains scheduled
//! for even spacing, are large and die out only as `1/n`. Use [`Engine::Exact`] (the default)
//! there.
//!
//! The gain-engine fading-memory filter starts as an expanding-memory filter and switches to the
//! constant gains at the sample chosen by its [`SwitchRule`] (Morrison §13.8).
//!
//! ## Batches
//!
//! [`PolynomialFilter::update_many`] takes a slice of times and one of values. The expanding-
//! and fading-memory filters check the whole batch in one branch-free pass, then run their
//! engine without per-sample checks. Once the gain engine's fading gains are in force (and no
//! covariance is tracked), runs of steps equal to the typical step — up to `1e-12` relative
//! plus the rounding of the timestamps, so `t = k·0.1` counts as even — go through a steady
//! kernel: `Z ← Φ(ζ) Z + K (y − [Φ(ζ) Z]₀)` in plain `f64` with the state in registers,
//! regrouped as `Z' = M(ζ) Z₁.. + K d` with `d = y − z₀` so that one sample's dependency chain is
//! a multiplication and two additions (degrees ≤ 8; higher degrees take the per-sample path).
//!
//! Without per-sample outputs (`update_many`), whole blocks of 64 such steps go faster still:
//! the steady fading recursion is linear and time-invariant, so a block is one map
//! `Z ← Āᴮ Z + Σ_j Ā^(B−1−j) K y_j` (`Ā = (I − K e₀ᵀ) Φ(ζ̄)`, tabulated in double words, to
//! first order in the block's mean-step deviation; degrees ≤ 5), and the expanding-memory
//! state on an even grid is the least-squares fit through every sample, so a run of blocks is
//! one least-squares update in the grids' discrete orthogonal polynomials
//! (degrees ≤ 4; degree 0, the running mean, on any steps). Both take each block's samples on
//! the grid of its mean step: the timestamps' own rounding (a few units in the last place of
//! `t`), which the per-sample recursion follows, is the difference between the two paths.
//! Throughput is in BENCHMARKS.md (degree 2, 10⁶ samples: fading ≈ 4·10⁸, expanding
//! ≈ 7·10⁸ samples/s, against ≈ 2·10⁷ per sample).
//!
//! The steady recursion is stable (its eigenvalues are all `θ`), so plain arithmetic is enough
//! there; the compensated state matters in the start-up, where the gains are large. Measured
//! (`cargo test -p seqsmooth --release --test batch plain -- --nocapture`): 60 000 samples at
//! `t = k·0.1`, `τ = 0.1`, a sine of amplitude 100 plus a trend and unit noise, one batch of
//! 20 000 then batches of 101 (a block map and 37 recursion steps each; a block map is built for
//! new gains only in a batch of at least `512·(m+1)²` samples, its cost being that of the
//! recursion over 2 000 to 30 000 samples); the largest
//! difference from the compensated per-sample path over the second half of the run, relative
//! to the largest `|x^(k)|` there, worst over `k`:
//!
//! | m | θ = 0.5 | θ = 0.9 | θ = 0.99 | θ = 0.999 |
//! |---:|---:|---:|---:|---:|
//! | 0 | 1.6e-16 | 4.9e-16 | 9.9e-16 | 2.2e-15 |
//! | 1 | 1.8e-13 | 8.7e-14 | 2.4e-14 | 1.6e-13 |
//! | 2 | 1.7e-13 | 7.6e-13 | 4.7e-14 | 2.9e-14 |
//! | 3 | 1.9e-13 | 7.7e-13 | 7.5e-14 | 5.8e-14 |
//! | 4 | 1.9e-13 | 8.1e-13 | 4.2e-13 | 2.1e-14 |
//! | 5 | 1.4e-13 | 7.7e-13 | 8.1e-13 | 4.8e-14 |
//! | 6 | 1.1e-13 | 5.9e-13 | 1.5e-12 | 8.5e-14 |
//! | 7 | 1.1e-13 | 5.2e-13 | 3.6e-12 | 8.8e-14 |
//! | 8 | 1.1e-13 | 5.6e-13 | 4.8e-12 | 7.2e-14 |
//!
//! (asserted: 1e-11). The exact engine and the fixed-memory filter give the same numbers
//! through either call.
//!
//! ```
//! use seqsmooth::{Engine, ExpandingMemory, PolynomialFilter};
//! let mut f = ExpandingMemory::new(2, Engine::Exact).unwrap();
//! for (t, y) in [(0.0, 1.0), (0.5, 1.75), (1.7, 5.59), (2.0, 7.0)] {
//!     f.update(t, y).unwrap();
//! }
//! let s = f.estimate().unwrap(); // y = 1 + t + t² exactly: x = 7, x' = 5, x'' = 2
//! assert!((s.derivatives[0] - 7.0).abs() < 1e-12);
//! assert!((s.derivatives[1] - 5.0).abs() < 1e-12);
//! assert!((s.derivatives[2] - 2.0).abs() < 1e-12);
//! ```

pub mod automatic;
pub mod bank;
mod exact_engine;
mod expanding_block;
pub mod fixed;
mod gain_engine;
pub mod gains;
pub mod stream;
pub mod switching;
pub mod vrf;

use crate::error::Error;
use crate::model::PolynomialState;
pub use automatic::{AutoConfig, AutoOutput, AutomaticFilter};
use exact_engine::{Discount, ExactEngine};
use gain_engine::{FadingGains, GainEngine};
pub use switching::SwitchRule;

/// The largest degree the filters accept. The exact engine's accuracy against an independent
/// batch QR fit is measured in the tests up to this degree.
pub const MAX_DEGREE: usize = 24;

/// Which computation a filter uses (see the [module docs](self)).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Engine {
    /// Recursive least squares, exact on any timestamps.
    #[default]
    Exact,
    /// Fixed-gain recursion, exact on evenly spaced samples.
    Gain,
}

/// How a fading-memory filter discounts old samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum DiscountMode {
    /// By `θ` per `τ` of elapsed time: weight `θ^((t_n - t_k)/τ)` (`θ_eff = θ^ζ` per update).
    #[default]
    PerTime,
    /// By `θ` per sample whatever the spacing: weight `θ^(n-k)`.
    PerUpdate,
}

#[derive(Clone, Debug)]
enum Core {
    Exact(ExactEngine),
    Gain(GainEngine),
}

impl Core {
    fn samples(&self) -> u64 {
        match self {
            Core::Exact(e) => e.samples(),
            Core::Gain(g) => g.samples(),
        }
    }

    fn last_time(&self) -> f64 {
        match self {
            Core::Exact(e) => e.last_time(),
            Core::Gain(g) => g.last_time(),
        }
    }

    fn update(&mut self, t: f64, y: f64) -> Result<(), Error> {
        let previous = (self.samples() > 0).then(|| self.last_time());
        crate::error::check_sample(t, y, previous)?;
        match self {
            Core::Exact(e) => e.update(t, y),
            Core::Gain(g) => g.update(t, y),
        }
        Ok(())
    }

    fn update_many(
        &mut self,
        m: usize,
        times: &[f64],
        values: &[f64],
        estimates: Option<&mut [f64]>,
    ) -> Result<(), Error> {
        check_batch_lengths(times, values)?;
        if let Some(out) = &estimates {
            check_estimates_length(times, m, out)?;
        }
        let previous = (self.samples() > 0).then(|| self.last_time());
        let valid = first_invalid(times, values, previous);
        let (ts, ys) = (&times[..valid], &values[..valid]);
        match (&mut *self, estimates) {
            (Core::Exact(e), None) => ts.iter().zip(ys).for_each(|(&t, &y)| e.update(t, y)),
            (Core::Exact(e), Some(out)) => {
                for ((&t, &y), row) in ts.iter().zip(ys).zip(out.chunks_exact_mut(m + 1)) {
                    e.update(t, y);
                    if !e.derivatives_into(t, row) {
                        row.fill(f64::NAN);
                    }
                }
            }
            (Core::Gain(g), None) => g.update_many(ts, ys),
            (Core::Gain(g), Some(out)) => g.update_many_into(ts, ys, &mut out[..valid * (m + 1)]),
        }
        if valid < times.len() {
            let previous = (self.samples() > 0).then(|| self.last_time());
            if let Err(e) = crate::error::check_sample(times[valid], values[valid], previous) {
                return Err(Error::InBatch {
                    index: valid,
                    source: Box::new(e),
                });
            }
        }
        Ok(())
    }

    fn estimate_at(&self, m: usize, t: f64) -> Option<PolynomialState> {
        if self.samples() <= m as u64 || !t.is_finite() {
            return None;
        }
        let (derivatives, covariance) = match self {
            Core::Exact(e) => e.estimate_at(t)?,
            Core::Gain(g) => g.estimate_at(t),
        };
        Some(PolynomialState {
            time: t,
            derivatives,
            covariance,
        })
    }

    fn track_covariance(&mut self, sigma: f64) -> Result<(), Error> {
        if !(sigma.is_finite() && sigma > 0.0) {
            return Err(Error::InvalidParameter {
                name: "noise sigma",
                value: sigma.to_string(),
                reason: "must be a positive finite number".into(),
            });
        }
        match self {
            Core::Exact(e) => e.track_covariance(sigma),
            Core::Gain(g) => g.track_covariance(sigma),
        }
        Ok(())
    }
}

fn check_degree(m: usize) -> Result<(), Error> {
    if m > MAX_DEGREE {
        return Err(Error::DegreeOutOfRange {
            degree: m,
            max: MAX_DEGREE,
        });
    }
    Ok(())
}

fn check_tau(tau: f64) -> Result<(), Error> {
    if !(tau.is_finite() && tau > 0.0) {
        return Err(Error::TauOutOfRange { tau });
    }
    Ok(())
}

fn check_theta(theta: f64) -> Result<(), Error> {
    if !(theta > 0.0 && theta < 1.0) {
        return Err(Error::ThetaOutOfRange { theta });
    }
    Ok(())
}

/// What every polynomial filter does: take timestamped samples, give estimates. Implemented by
/// [`ExpandingMemory`] and [`FadingMemory`], so callers can hold either behind one type.
///
/// ```
/// use seqsmooth::{Engine, ExpandingMemory, FadingMemory, PolynomialFilter};
/// let mut filters: Vec<Box<dyn PolynomialFilter>> = vec![
///     Box::new(ExpandingMemory::new(1, Engine::Exact).unwrap()),
///     Box::new(FadingMemory::new(1, 0.8, 1.0, Engine::Gain).unwrap()),
/// ];
/// for f in filters.iter_mut() {
///     for k in 0..20 {
///         f.update(k as f64, 3.0 * k as f64).unwrap();
///     }
///     assert!((f.estimate().unwrap().derivatives[1] - 3.0).abs() < 1e-12);
/// }
/// ```
pub trait PolynomialFilter: std::fmt::Debug + Send {
    /// Degree `m`.
    fn degree(&self) -> usize;
    /// Number of samples processed.
    fn samples(&self) -> u64;
    /// Processes the sample `y` at time `t` (finite, strictly after the previous time). A
    /// rejected sample leaves the filter unchanged.
    fn update(&mut self, t: f64, y: f64) -> Result<(), Error>;
    /// The estimate valid at any time `t` from the samples so far (a prediction after the
    /// newest sample, a retrodiction before it); `None` until the estimate is determined
    /// (`m+1` samples for the expanding- and fading-memory filters, a full window for the
    /// fixed-memory filter).
    fn estimate_at(&self, t: f64) -> Option<PolynomialState>;
    /// The time of the newest sample.
    fn last_time(&self) -> Option<f64>;
    /// The current estimate, valid at the newest sample's time.
    fn estimate(&self) -> Option<PolynomialState> {
        self.estimate_at(self.last_time()?)
    }
    /// True once the estimate is determined (`m+1` samples).
    fn is_determined(&self) -> bool {
        self.samples() > self.degree() as u64
    }
    /// Processes the samples `(times[i], values[i])` in order, with the same result as
    /// [`update`](Self::update) on each. The expanding- and fading-memory filters check the
    /// whole batch in one pass and run a tight loop (see BENCHMARKS.md for the speed-up). On
    /// the first invalid sample it returns [`Error::InBatch`] with the sample's index: the
    /// samples before it are processed, it and the rest are not.
    ///
    /// ```
    /// use seqsmooth::{Engine, Error, FadingMemory, PolynomialFilter};
    /// let mut f = FadingMemory::new(1, 0.9, 1.0, Engine::Gain).unwrap();
    /// let t: Vec<f64> = (0..100).map(f64::from).collect();
    /// let y: Vec<f64> = t.iter().map(|t| 3.0 + 0.5 * t).collect();
    /// f.update_many(&t, &y).unwrap();
    /// let s = f.estimate().unwrap();
    /// assert!((s.derivatives[0] - 52.5).abs() < 1e-9 && (s.derivatives[1] - 0.5).abs() < 1e-9);
    /// // a time that goes backwards is reported with its index; the samples before it count
    /// let err = f.update_many(&[100.0, 99.0], &[53.0, 52.5]).unwrap_err();
    /// assert!(matches!(err, Error::InBatch { index: 1, .. }));
    /// assert_eq!(f.samples(), 101);
    /// ```
    fn update_many(&mut self, times: &[f64], values: &[f64]) -> Result<(), Error> {
        check_batch_lengths(times, values)?;
        for (index, (&t, &y)) in times.iter().zip(values).enumerate() {
            self.update(t, y).map_err(|e| Error::InBatch {
                index,
                source: Box::new(e),
            })?;
        }
        Ok(())
    }
    /// [`update_many`](Self::update_many) that also writes the estimate after each sample:
    /// `estimates[i·(m+1) + k]` is the `k`-th derivative at `times[i]` from the samples up to
    /// and including sample `i` (NaN while undetermined). `estimates.len()` must be
    /// `times.len()·(m+1)`. On an invalid sample the rows before it are written, the rest are
    /// left as they were. The gain engine writes from its batch kernels (no allocation per
    /// sample); the rows equal [`estimate`](Self::estimate)'s up to a rounding of the last
    /// conversion `k!/τ^k`.
    ///
    /// ```
    /// use seqsmooth::{Engine, ExpandingMemory, PolynomialFilter};
    /// let mut f = ExpandingMemory::new(1, Engine::Gain).unwrap();
    /// let t = [0.0, 1.0, 2.0, 3.0];
    /// let y = [1.0, 3.0, 5.0, 7.0]; // y = 1 + 2t
    /// let mut est = [0.0; 8];
    /// f.update_many_into(&t, &y, &mut est).unwrap();
    /// assert!(est[0].is_nan()); // one sample does not determine a line
    /// assert!((est[6] - 7.0).abs() < 1e-12 && (est[7] - 2.0).abs() < 1e-12);
    /// ```
    fn update_many_into(
        &mut self,
        times: &[f64],
        values: &[f64],
        estimates: &mut [f64],
    ) -> Result<(), Error> {
        check_batch_lengths(times, values)?;
        let w = self.degree() + 1;
        check_estimates_length(times, self.degree(), estimates)?;
        for (index, ((&t, &y), row)) in times
            .iter()
            .zip(values)
            .zip(estimates.chunks_exact_mut(w))
            .enumerate()
        {
            self.update(t, y).map_err(|e| Error::InBatch {
                index,
                source: Box::new(e),
            })?;
            match self.estimate() {
                Some(s) => row.copy_from_slice(&s.derivatives),
                None => row.fill(f64::NAN),
            }
        }
        Ok(())
    }
}

/// Checks `estimates.len() = times.len()·(m+1)` for [`PolynomialFilter::update_many_into`].
fn check_estimates_length(times: &[f64], m: usize, estimates: &[f64]) -> Result<(), Error> {
    if estimates.len() != times.len() * (m + 1) {
        return Err(Error::InvalidParameter {
            name: "estimates length",
            value: estimates.len().to_string(),
            reason: format!(
                "{} samples of degree {m} need {} values (one row of m+1 derivatives per sample)",
                times.len(),
                times.len() * (m + 1)
            ),
        });
    }
    Ok(())
}

fn check_batch_lengths(times: &[f64], values: &[f64]) -> Result<(), Error> {
    if times.len() != values.len() {
        return Err(Error::InvalidParameter {
            name: "batch lengths",
            value: format!("{} times, {} values", times.len(), values.len()),
            reason: "a batch needs one time per value".into(),
        });
    }
    Ok(())
}

/// `x` is neither NaN nor infinite: `x − x` is `0` exactly then (`NaN` otherwise); as
/// arithmetic it vectorises better in [`first_invalid`] than `f64::is_finite` (measured:
/// 2.5e9 against 2.0e9 samples/s checked).
#[inline(always)]
#[allow(clippy::eq_op)]
fn finite(x: f64) -> bool {
    x - x == 0.0
}

/// The index of the first sample of a batch that [`crate::error::check_sample`] rejects
/// (`times.len()` when all pass): a branch-free pass over blocks, located exactly only when a
/// block fails.
fn first_invalid(times: &[f64], values: &[f64], previous: Option<f64>) -> usize {
    const CHUNK: usize = 256;
    let mut prev = previous.unwrap_or(f64::NEG_INFINITY);
    for (c, (tc, yc)) in times.chunks(CHUNK).zip(values.chunks(CHUNK)).enumerate() {
        // Branch-free over the chunk, so that it vectorises (`t > p` is false for NaN or a time
        // not after the previous one).
        let n = tc.len();
        let mut ok = (tc[0] > prev) & finite(tc[0]) & finite(yc[0]);
        for ((&t, &p), &y) in tc[1..].iter().zip(&tc[..n - 1]).zip(&yc[1..]) {
            ok &= (t > p) & finite(t) & finite(y);
        }
        if !ok {
            let mut p = (c > 0 || previous.is_some()).then_some(prev);
            for (j, (&t, &y)) in tc.iter().zip(yc).enumerate() {
                if crate::error::check_sample(t, y, p).is_err() {
                    return c * CHUNK + j;
                }
                p = Some(t);
            }
        }
        prev = tc[n - 1];
    }
    times.len()
}

macro_rules! impl_polynomial_filter {
    ($ty:ty) => {
        impl PolynomialFilter for $ty {
            fn degree(&self) -> usize {
                self.m
            }
            fn samples(&self) -> u64 {
                self.core.samples()
            }
            fn update(&mut self, t: f64, y: f64) -> Result<(), Error> {
                self.core.update(t, y)
            }
            fn update_many(&mut self, times: &[f64], values: &[f64]) -> Result<(), Error> {
                self.core.update_many(self.m, times, values, None)
            }
            fn update_many_into(
                &mut self,
                times: &[f64],
                values: &[f64],
                estimates: &mut [f64],
            ) -> Result<(), Error> {
                self.core
                    .update_many(self.m, times, values, Some(estimates))
            }
            fn estimate_at(&self, t: f64) -> Option<PolynomialState> {
                self.core.estimate_at(self.m, t)
            }
            fn last_time(&self) -> Option<f64> {
                (self.core.samples() > 0).then(|| self.core.last_time())
            }
        }
    };
}

impl_polynomial_filter!(ExpandingMemory);
impl_polynomial_filter!(FadingMemory);

/// Expanding-memory polynomial filter of degree `m` (Morrison ch. 9; Reyneke §6.3-6.4): the
/// least-squares polynomial through all samples so far, with its derivatives, predictions and
/// (given the noise σ) covariance. Self-starting: determined from the `(m+1)`-th sample.
///
/// ```
/// use seqsmooth::{Engine, ExpandingMemory, PolynomialFilter};
/// let mut f = ExpandingMemory::new(1, Engine::Gain).unwrap();
/// for (n, y) in [1.0, 3.0, 2.0, 5.0, 4.0].iter().enumerate() {
///     f.update(n as f64, *y).unwrap();
/// }
/// // Morrison T9-02: Z*_{4,4} = (23/5, 4/5)
/// let s = f.estimate().unwrap();
/// assert!((s.derivatives[0] - 4.6).abs() < 1e-12 && (s.derivatives[1] - 0.8).abs() < 1e-12);
/// // the 1-step prediction Z*_{5,4} = (27/5, 4/5)
/// assert!((f.estimate_at(5.0).unwrap().derivatives[0] - 5.4).abs() < 1e-12);
/// ```
#[derive(Clone, Debug)]
pub struct ExpandingMemory {
    m: usize,
    core: Core,
}

impl ExpandingMemory {
    /// A filter of degree `m` on the given engine.
    pub fn new(m: usize, engine: Engine) -> Result<Self, Error> {
        check_degree(m)?;
        let core = match engine {
            Engine::Exact => Core::Exact(ExactEngine::new(m, None)),
            // The gain engine's output does not depend on τ for expanding memory; τ = 1.
            Engine::Gain => Core::Gain(GainEngine::new(m, 1.0, None)),
        };
        Ok(Self { m, core })
    }

    /// Tracks the covariance of the estimate for white measurement noise of standard deviation
    /// `sigma`: exact for the engine's estimator on any timestamps.
    pub fn with_noise_sigma(mut self, sigma: f64) -> Result<Self, Error> {
        self.core.track_covariance(sigma)?;
        Ok(self)
    }
}

/// Fading-memory polynomial filter of degree `m` and discount `θ` per `τ` (Morrison ch. 13;
/// Reyneke §6.5-6.6): the polynomial minimising `Σ_k θ^((t_n-t_k)/τ) (y_k - p(t_k))²`.
///
/// ```
/// use seqsmooth::{Engine, FadingMemory, PolynomialFilter};
/// let mut f = FadingMemory::new(1, 0.9, 1.0, Engine::Gain).unwrap();
/// for n in 0..500 {
///     f.update(n as f64, 2.0 + 0.5 * n as f64).unwrap();
/// }
/// let s = f.estimate().unwrap();
/// assert!((s.derivatives[0] - 251.5).abs() < 1e-9 && (s.derivatives[1] - 0.5).abs() < 1e-12);
/// ```
#[derive(Clone, Debug)]
pub struct FadingMemory {
    m: usize,
    theta: f64,
    tau: f64,
    mode: DiscountMode,
    rule: SwitchRule,
    sigma: Option<f64>,
    core: Core,
}

impl FadingMemory {
    /// A filter of degree `m`, discount `θ ∈ (0,1)` per nominal interval `τ > 0`.
    pub fn new(m: usize, theta: f64, tau: f64, engine: Engine) -> Result<Self, Error> {
        check_degree(m)?;
        check_theta(theta)?;
        check_tau(tau)?;
        let mode = DiscountMode::default();
        let rule = SwitchRule::default();
        let core = match engine {
            Engine::Exact => Core::Exact(ExactEngine::new(m, Some(Discount { theta, tau, mode }))),
            Engine::Gain => Core::Gain(GainEngine::new(
                m,
                tau,
                Some(FadingGains::new(m, theta, mode, rule)),
            )),
        };
        Ok(Self {
            m,
            theta,
            tau,
            mode,
            rule,
            sigma: None,
            core,
        })
    }

    fn rebuild(&mut self) -> Result<(), Error> {
        if self.core.samples() > 0 {
            return Err(Error::InvalidParameter {
                name: "configuration",
                value: "change after the first sample".into(),
                reason: "set the discount mode and switch rule before the first update".into(),
            });
        }
        match &mut self.core {
            Core::Exact(_) => {
                self.core = Core::Exact(ExactEngine::new(
                    self.m,
                    Some(Discount {
                        theta: self.theta,
                        tau: self.tau,
                        mode: self.mode,
                    }),
                ));
            }
            Core::Gain(_) => {
                self.core = Core::Gain(GainEngine::new(
                    self.m,
                    self.tau,
                    Some(FadingGains::new(self.m, self.theta, self.mode, self.rule)),
                ));
            }
        }
        if let Some(sigma) = self.sigma {
            self.core.track_covariance(sigma)?;
        }
        Ok(())
    }

    /// Chooses how old samples are discounted (default [`DiscountMode::PerTime`]). Must be set
    /// before the first sample.
    pub fn with_discount_mode(mut self, mode: DiscountMode) -> Result<Self, Error> {
        self.mode = mode;
        self.rebuild()?;
        Ok(self)
    }

    /// Chooses when the gain engine switches from its expanding-memory start to the fading
    /// gains (default [`SwitchRule::Position`]). Must be set before the first sample. The exact
    /// engine needs no start-up and ignores the rule.
    pub fn with_switch_rule(mut self, rule: SwitchRule) -> Result<Self, Error> {
        rule.switch_index(self.m, self.theta)?;
        self.rule = rule;
        self.rebuild()?;
        Ok(self)
    }

    /// Tracks the covariance of the estimate for white measurement noise of standard deviation
    /// `sigma` (exact for the engine's estimator, including the start-up).
    pub fn with_noise_sigma(mut self, sigma: f64) -> Result<Self, Error> {
        self.core.track_covariance(sigma)?;
        self.sigma = Some(sigma);
        Ok(self)
    }

    /// `θ`.
    pub fn theta(&self) -> f64 {
        self.theta
    }

    /// `τ`.
    pub fn tau(&self) -> f64 {
        self.tau
    }

    /// The 0-based index of the first sample the gain engine processed with the fading-memory
    /// gains: `None` before the switch and on the exact engine (which needs no start-up).
    pub fn switched_at(&self) -> Option<u64> {
        match &self.core {
            Core::Gain(g) => g.switched_at(),
            Core::Exact(_) => None,
        }
    }
}
