//! The polynomial filters of any degree on evenly spaced or irregular timestamps (Morrison
//! ch. 7, 9, 13-15; Reyneke et al. §6-7): expanding, fading and fixed memory, the automatic
//! filter, and banks of them.
//!
//! ## Concepts
//!
//! | concept | module | source |
//! |---|---|---|
//! | what every filter does: [`PolynomialFilter`]; batch checks | `filter` | — |
//! | engines, discounting, largest degree, the parameters' ranges: [`Engine`], [`DiscountMode`], [`MAX_DEGREE`], [`GAIN_MAX_DEGREE`], [`check_degree`], [`check_theta`], [`check_tau`] | `options` | — |
//! | the default interval `τ` of a fading memory: [`tau::default_tau`], the median time step | [`tau`] | Morrison (13.2.1); Reyneke §6.5 |
//! | current / predictor form of gains and VRFs: [`form::GainForm`], [`form::EstimateForm`], [`form::unscale`] | [`form`] | Morrison (9.7.4), (13.6.22) |
//! | expanding memory: [`ExpandingMemory`], gains, VRF | [`expanding`] | Morrison ch. 9, Tables 9.1-9.2; Reyneke §6.3-6.4 |
//! | fading memory: [`FadingMemory`], gains, VRF, the switch [`SwitchRule`] | [`fading`] | Morrison ch. 13, Tables 13.1-13.4, §13.8; Reyneke §6.5-6.6, Table 1 |
//! | the exact and gain engines | `engine` | Morrison §9.6, Tables 9.1/13.1; Reyneke §6 |
//! | fixed memory and whole-series smoothing | [`fixed`] | Morrison ch. 7, §9.5 |
//! | the automatic filter: [`AutomaticFilter`] | [`automatic`] | Morrison §13.8, §14.8; Reyneke §7 |
//! | many channels at once | [`bank`], [`stream`] | — |
//! | any filter from one description: [`spec::FilterSpec`], [`spec::AnyFilter`] | [`spec`] | — |
//! | a batch to output rows, and what an undetermined or refused row holds: [`spec::AnyFilter::run_rows`] | [`rows`] | — |
//!
//! ## Engines
//!
//! The expanding- and fading-memory filters run on one of two [`Engine`]s:
//!
//! - [`Engine::Exact`] — recursive least squares with the polynomial model on arbitrary
//!   timestamps, `O(m²)` per sample, equal to the batch fit over all samples so far (expanding
//!   memory: equal weights; fading memory: weights `θ^((t_n - t_k)/τ)`, or `θ^(n-k)` with
//!   [`DiscountMode::PerUpdate`]). It is the polynomial instance of the square-root information
//!   filter of [`crate::recursive`], in a centred, scaled monomial basis. Determined from the
//!   `(m+1)`-th sample on. Its accuracy is limited by that basis at high degree (the tests
//!   assert 1e-9 relative to degree 12, 1e-6 to 16, 1e-3 to [`MAX_DEGREE`]).
//! - [`Engine::Gain`] — the fixed-gain recursion of Morrison's Tables 9.1/13.1 in Reyneke's
//!   variable-step form: predict by `Φ(ζ)`, `ζ = Δt/τ`, correct with gains `h_k/ζ̄^k` scaled for
//!   the typical step `ζ̄` of the memory (fading: `θ_eff = θ^ζ̄`). `O(m)` per sample after the
//!   prediction. Exact least squares on evenly spaced samples for any step (there `ζ̄ = ζ`); an
//!   approximation on irregular timestamps. It starts from the exact interpolating polynomial of
//!   the first `m+1` samples (the state the recursion reaches from any start at `n = m`,
//!   Morrison §9.6) and carries its state in compensated arithmetic.
//!
//! On irregular timestamps: with moderate jitter the gain engine is within a few percent of
//! exact least squares, and for fading memory on average on every schedule up to degree 3. The
//! expanding-memory gain engine is **not** usable on strongly irregular sampling (Poisson
//! arrivals, bursts at degree ≥ 2): its early errors, from gains scheduled for even spacing,
//! are large and die out only as `1/n`. Use [`Engine::Exact`] (the default) there. Measured
//! accuracy of both engines: see ACCURACY.md.
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
//! first order in the block's mean-step deviation; degrees ≤ 5; built for new gains only in a
//! batch of at least `512·(m+1)²` samples), and the expanding-memory state on an even grid is
//! the least-squares fit through every sample, so a run of blocks is one least-squares update
//! in the grids' discrete orthogonal polynomials (degrees ≤ 4; degree 0, the running mean, on
//! any steps). Both take each block's samples on the grid of its mean step: the timestamps' own
//! rounding (a few units in the last place of `t`), which the per-sample recursion follows, is
//! the difference between the two paths. The steady recursion is stable (its eigenvalues are
//! all `θ`), so plain arithmetic is enough there; the compensated state matters in the
//! start-up, where the gains are large. The exact engine and the fixed-memory filter give the
//! same numbers through either call. Measured agreement of the paths: see ACCURACY.md;
//! throughput: see BENCHMARKS.md.
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
pub mod form;
pub mod merge;
mod options;
pub mod prior;
pub mod rows;
pub mod spec;
pub mod stream;
pub mod tau;

pub use automatic::{AutoConfig, AutoOutput, AutomaticFilter};
pub use expanding::ExpandingMemory;
pub use fading::{FadingMemory, SwitchRule};
pub use filter::PolynomialFilter;
pub use options::{
    check_degree, check_derivative, check_lead, check_model, check_tau, check_theta, check_theta_of,
};
pub use options::{DiscountMode, Engine, GAIN_MAX_DEGREE, GAIN_MAX_VALUE, MAX_DEGREE};
