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
mod engine;
pub mod expanding;
pub mod fading;
mod filter;
pub mod fixed;
mod options;
pub mod stream;

pub use automatic::{AutoConfig, AutoOutput, AutomaticFilter};
pub use expanding::ExpandingMemory;
pub use fading::{FadingMemory, SwitchRule};
pub use filter::PolynomialFilter;
pub(crate) use options::{check_degree, check_tau};
pub use options::{DiscountMode, Engine, MAX_DEGREE};

/// The gains of both filters (kept at their old path).
pub mod gains {
    pub use super::expanding::gains::{
        expanding_gain_numerators, expanding_gains, ExpandingGainSchedule,
    };
    pub use super::fading::gains::fading_gains;
    pub use super::form::GainForm;
}
/// The variance-reduction matrices (kept at their old path).
pub mod vrf {
    pub use super::expanding::vrf::expanding_vrf;
    pub use super::fading::vrf::{fading_vrf, fading_vrf_limit};
    pub use super::fixed::{fixed_memory_vrf_limit, window_covariance};
    pub use super::form::{unscale, EstimateForm};
}
/// The expanding-to-fading switch (kept at its old path).
pub mod switching {
    pub use super::fading::switch::{memory_length_constant, switch_constant, SwitchRule};
}
mod form;
