//! The automatic polynomial filter: a fading-memory filter that starts itself, settles its
//! degree, estimates its noise, rejects outliers and says when its model no longer fits
//! (Morrison §13.8, §14.8; Reyneke et al. §7.2-7.4).
//!
//! Per sample `(t, y)` ([`AutomaticFilter::update`]):
//!
//! 1. **Prediction and innovation.** The active filter predicts `ŷ(t)` with its own covariance;
//!    the innovation `ν = y − ŷ(t)` has noise variance `σ²(1 + v)`, `v` the 1-step prediction's
//!    position VRF (Morrison (14.8.4)); `σ` is the given noise or its running estimate. Its
//!    mean square is `σ_ε² = σ²(1 + v) + b₀²` with `b₀` the prediction's estimated bias (see
//!    *Honest covariance* below).
//! 2. **Outlier gate** ([`OutlierRule`]): Morrison's `|ν| > k σ_ε` (default `k = 3`, false-alarm
//!    rate `P(|Z| > 3) = 0.27%`), or Reyneke's `|ν| > k σ (1 + √(2/N))` (§7.4). A rejected sample
//!    does not touch the state — the estimate is the prediction across it — and is flagged
//!    [`AutoOutput::outlier`]. A run of [`AutoConfig::max_consecutive_rejections`] rejections
//!    (default 3), or of [`AutoConfig::same_side_rejections`] (default: off) all on the same side of
//!    the prediction (Morrison §14.8: repeated crossings on one side mean bias), is
//!    taken for a manoeuvre, not outliers: the run is applied after all (in order), the
//!    misfit flag goes up, and the output says how many earlier samples it reinstated
//!    ([`AutoOutput::reinstated`]). The gate's verdict is provisional: the final decision is
//!    the review's (step 6), and `seqsmooth filter` writes it. The gate is active only at the final degree, once `σ` is known and the
//!    prediction VRF `v ≤` [`AutoConfig::gate_max_vrf`] (default 1: the prediction is at least
//!    as good as a sample; Reyneke's rule, which ignores `v`, needs this to keep its false-alarm
//!    rate down, see [`REYNEKE_DEFAULT_K`]).
//! 3. **Misfit** ([`crate::stats::InnovationChiSquared`], Morrison §14.8): the normalised squared
//!    innovations `ν²/σ_ε²` of accepted samples, summed over a sliding window of `K` samples, are
//!    `χ²_K` while the model fits; [`AutoOutput::misfit`] is up while the sum exceeds its
//!    `(1-α)` quantile (defaults `K = 10`, `α = 0.01`). The response ([`MisfitResponse`],
//!    Morrison: "β can be temporarily reduced until the threshold crossings cease"): by default
//!    the final-degree memory is restarted from the samples since the estimated onset when the
//!    same window sum passes the stricter `(1-10⁻⁴)` quantile, and grows back through the
//!    expanding start; or the flag is only raised ([`MisfitResponse::Flag`]), and the memory
//!    carries the manoeuvre's bias until it fades (about two memory lengths).
//! 4. **Update** of every filter the automatic filter runs, with the accepted sample:
//!    - **Quick-settling degree ladder** (Reyneke §7.3): expanding-memory filters of degrees
//!      `d₀ … m` (default `d₀ = 0`) run in tandem from the first sample; the active degree `d`
//!      steps up to `d+1` once the candidate's current position VRF is at most
//!      [`AutoConfig::settle_vrf`] (default ½) and its top derivative has changed by less than its
//!      own 1σ at each of the last [`AutoConfig::settle_stable`] updates (default 3); it steps up
//!      at once when the active degree's misfit flag goes up (the lower degree does not fit). The
//!      misfit window restarts at each step.
//!    - **Expanding → fading memory** (Morrison §13.8; Reyneke §7.2, Table 1): at the final
//!      degree `m` the expanding-memory filter is used until the sample index chosen by the
//!      [`SwitchRule`] (default [`SwitchRule::Position`], `n = ⌊c_0m/(1-θ)⌋`), and the
//!      fading-memory filter from then on. The rules count samples, so with
//!      [`DiscountMode::PerTime`] they use the discount per sample `θ^ζ̄`, `ζ̄` the mean step so far
//!      in units of `τ`, re-evaluated at each sample until the switch — as the gain engine of
//!      [`FadingMemory`] does. Indices count *accepted* samples. With the default
//!      [`Engine::Exact`] the fading-memory filter is exact discounted least squares over all
//!      accepted samples (weights `θ^((t_n−t_k)/τ)`), run in tandem from the first sample, so
//!      there is no start-up transient; the expanding start is used because its variance is the
//!      lower one until the crossover.
//!    - **Adaptive memory** (Morrison §7.13, §14.8; [`AutoConfig::memory_levels`], default 1):
//!      beside `θ` the final degree runs fading-memory filters of the shorter memories
//!      `θ⁴, θ¹⁶, …` (by default `θ⁴` alone: a memory about a quarter as long, whose bias of an
//!      unmodelled `(m+1)`-th derivative is `(1+θ+θ²+θ³)^−(m+1)` of `θ`'s, Morrison (13.9.28):
//!      ≈ 1/51 at `θ = 0.95`, `m = 2`, tending to `4^−(m+1)` as `θ → 1`) with their
//!      degree-`(m+1)` companions. Before each prediction the memory of
//!      least estimated mean squared error `σ² v_j + b̂_j²` is chosen (bias counted where `|Δ|`
//!      exceeds 2.5 of its noise standard deviations): the VRF falls as the memory lengthens,
//!      the bias of the unmodelled `(m+1)`-th derivative grows as `(1−θ)^−(m+1)` (Morrison
//!      (13.9.28)), and §7.13 balances the two. A shorter memory is taken at once, a longer one
//!      a level at a time after 10 predictions in a row ("β can be temporarily reduced until
//!      the threshold crossings cease … then the memory can again be lengthened", §14.8). Only
//!      with [`MisfitResponse::Restart`]; a restart rebuilds every memory.
//! 5. **Noise** ([`NoiseSource`]): a given `σ`, or (default) the running estimate from the
//!    normalised `(m+1)`-th divided differences of the accepted samples
//!    ([`crate::stats::DifferenceNoise`]): unbiased for white noise about any polynomial of
//!    degree `≤ m` on any timestamps; biased upward by the trend's `(m+1)`-th derivative
//!    (`E{d²} = σ² + b²`, `b ≈ x^(m+1) Δt^(m+1)/√C(2m+2,m+1)` — negligible unless the samples
//!    are sparse on the manoeuvre's time scale). Outliers the gate passes (before it is active
//!    every sample passes) and isolated glitches of the trend are screened
//!    ([`AutoConfig::noise_screen`], default `c = 3`): a difference beyond `c σ̂` and the `m + 1`
//!    after it, which share its samples, are left out, and the kept terms are divided by the
//!    variance of a unit Gaussian truncated at `±c` ([`crate::stats::DifferenceNoise::with_screen`]).
//!    The gate truncates the noise of the samples it passes (for `k = 3`, `σ̂` would be 1.4% low);
//!    each gated sample enters with its expected truncated variance `σ²(c(a) + v)/(1 + v)`,
//!    `c(a)` the variance of a unit Gaussian cut at `±a = ±g/(σ√(1 + v))`, `g` the gate that
//!    passed it (with a bias `b` the cut is `[−g − b, g − b]`, `g = k√(σ²(1+v) + b²)`, whose
//!    near side is never nearer than `√(k² − 1)·σ√(1 + v)`, 0.94 of the symmetric one), which
//!    removes that bias. Alternatively the innovations of the final-degree filter
//!    ([`NoiseSource::Innovations`]): `σ̂² = mean(ν²/(1+v))`, corrected for the gate's truncation;
//!    without gating and before the switch it equals the expanding-memory fit's residual
//!    variance `e°/(N−m−1)` (Morrison (6.10.24)) exactly, but every unmodelled manoeuvre inflates
//!    it (by the squared bias of the predictions).
//!
//! 6. **Review** (the final outlier decision; [`AutoConfig::review_window`] `L`, default
//!    `m + 4`): once `L` accepted samples after a sample are in, it is judged again, against a
//!    least-squares polynomial of degree `m + 1` through the `L` nearest accepted samples on
//!    each side (its deleted residual: Morrison ch. 7, a fit evaluated inside its window, where
//!    its VRF is least), with up to two of those neighbours dropped when their studentised
//!    residual exceeds `k`, the fit's own bias estimated one degree up, and the variance scaled
//!    by the windows' residual mean square where the residuals are not white (Morrison §14.8).
//!    The judge of the smaller mean square decides: the gate where its `σ_ε` is the smaller (a
//!    long memory that fits), the interpolation otherwise (a short memory, where the gate is
//!    off or wide). Where the verdict differs from the gate's, the filter goes back to its
//!    state before the sample and takes the samples since again. Each decision is reported
//!    once, in sample order ([`AutoOutput::decided`]); [`AutomaticFilter::finish`] decides the
//!    rest at the end of a series; [`final_outliers`] collects them. `L = 0`: the gate's
//!    decisions, final once a later sample is accepted.
//!
//! Every filter inside tracks its covariance for unit noise (the VRF).
//!
//! ## Honest covariance
//!
//! The reported covariance is the mean squared error matrix of the estimate, not the noise's
//! covariance alone: `σ² V_d + b bᵀ` ([`AutoOutput::bias`] holds `b`, or `None` when it is not
//! estimated). The bias of a degree-`d` estimate on a trend it does not model is dominated by
//! the `(d+1)`-th term (Morrison (7.13.5), §13.9, (13.9.10), (13.9.28)); a degree-`(d+1)`
//! filter on the same memory (the next rung of the ladder, or the final degree's `m + 1`
//! companion, expanding then fading) removes it, and the nested least-squares difference
//! `Δ = x_d − x_{d+1}` has `E{Δ_i²} = b_i² + σ²(V_{d+1} − V_d)_ii` (the added term is
//! uncorrelated with `x_d`), so `b_i = sign(Δ_i) √max(0, Δ_i² − σ²(V_{d+1} − V_d)_ii)`. For the
//! position, while the misfit test is up, `b₀²` is at least the innovations' mean square excess
//! over their noise variance in the misfit window, `(mean(ν²/σ²(1+v)) − 1)·σ²(1+v)` (Morrison
//! §14.8), and at least the excess `r² − σ²(1+v)` of a sample just rejected within 1.25 gate
//! widths on the same side as `ν` (repeated crossings mean bias, Morrison §14.8). This covers
//! a start-up at a low degree of the ladder, a degree still settling and a
//! manoeuvre the memory does not follow (Morrison §7.13: the total error is the random error
//! and the bias together). The gate judges `ν` against the same honest `σ_ε`; the misfit test
//! keeps judging the model, against the noise-only variance. At the final degree the reported
//! covariance is then multiplied by `max(1, mean(ν²/σ_ε²))`, the memory's own normalised
//! innovations over about the last 20 accepted samples (each clipped at 16): Morrison §14.8's
//! check that the innovations' mean square equals its predicted value, applied where the
//! estimated bias falls short; the gate is not widened by it. Measured coverage: see
//! ACCURACY.md.
//!
//! ## Configuration and use
//!
//! Like the other filters: [`AutomaticFilter::new`] with the required degree `m`,
//! discount `θ` and interval `τ`, then checked `with_*` builders ([`AutomaticFilter::with_noise_sigma`],
//! [`AutomaticFilter::with_outlier_rule`], …; the settings are read back as an [`AutoConfig`]).
//! It implements [`PolynomialFilter`](crate::PolynomialFilter), so it can stand wherever another
//! filter does; each sample's flags are in [`AutomaticFilter::last_output`] (or returned by its
//! own [`AutomaticFilter::update`]).
//!
//! | concept | module | source |
//! |---|---|---|
//! | settings and their checks: [`AutoConfig`], [`GATE_MAX_VRF`] | `config` | — |
//! | building: [`AutomaticFilter::new`], the `with_*` builders, the filters a configuration runs | `build` | — |
//! | the filters it runs, one update, acceptance: [`AutomaticFilter`] | `filter` | Morrison (14.8.1)-(14.8.4) |
//! | what each sample did: [`AutoOutput`]; the final decisions, [`final_outliers`] | `output` | — |
//! | the final outlier decision by interpolation, going back: [`MAX_REVIEW_WINDOW`] | `review` | Morrison ch. 7, (6.10.24), (7.13.5), §14.8 |
//! | the review's window fit: the normal equations in the Legendre basis of the window | `window_fit` | Morrison ch. 7, §6.5 |
//! | outlier gate: [`OutlierRule`], [`MORRISON_K`], [`REYNEKE_DEFAULT_K`]; each sample's prediction, innovation and verdict; truncated variance | `outlier` | Morrison §14.8, (14.8.1)-(14.8.4); Reyneke §7.4 |
//! | noise `σ`: [`NoiseSource`], [`MIN_NOISE_TERMS`] | `noise` | Reyneke §7.1; Morrison (6.10.24), (14.8.4); [`crate::stats::DifferenceNoise`] |
//! | misfit and restart: [`MisfitResponse`], CUSUM onset | `misfit` | Morrison §14.8, (14.8.5); [`crate::stats::InnovationChiSquared`] |
//! | degree settling (the ladder) | `settle` | Reyneke §7.3 |
//! | bias of the active degree, honest covariance | `bias` | Morrison (7.13.5), §13.9, (13.9.28), §14.8 |
//! | adaptive memory: [`AutomaticFilter::memory`], [`MAX_MEMORY_LEVELS`] | `memory` | Morrison §7.13, (13.9.28), §14.8 |
//! | expanding → fading switch: [`Phase`] | `phase` | Morrison §13.8, (13.8.8), Table 13.4; Reyneke §7.2, Table 1 |
//!
//! ```
//! use seqsmooth::polynomial::automatic::AutomaticFilter;
//! let mut f = AutomaticFilter::new(1, 0.9, 1.0).unwrap().with_noise_sigma(0.1).unwrap();
//! let mut flagged = Vec::new();
//! for n in 0..200 {
//!     let t = n as f64;
//!     let noise = 0.1 * (((n * 37 + 11) % 17) as f64 / 8.0 - 1.0); // a bounded "noise"
//!     let y = 2.0 + 0.5 * t + noise + if n == 120 { 5.0 } else { 0.0 };
//!     let out = f.update(t, y).unwrap();
//!     if out.outlier { flagged.push(n); }
//! }
//! assert_eq!(flagged, vec![120]);                 // the 50σ spike, and nothing else
//! assert_eq!(f.switched_at(), Some(32));          // Morrison (13.8.8): m = 1, θ = 0.9 → 32
//! let s = f.estimate().unwrap();
//! assert!((s.derivatives[1] - 0.5).abs() < 0.01);
//! ```

#[cfg(doc)]
use crate::polynomial::fading::switch::SwitchRule;
#[cfg(doc)]
use crate::polynomial::fading::FadingMemory;
#[cfg(doc)]
use crate::polynomial::options::{DiscountMode, Engine};

mod bias;
mod build;
mod config;
mod filter;
mod memory;
mod misfit;
mod noise;
mod outlier;
mod output;
mod phase;
mod review;
mod settle;
mod state;
mod window_fit;

#[cfg(test)]
mod leading_tests;
#[cfg(test)]
mod rows_tests;

pub use config::{AutoConfig, GATE_MAX_VRF, MAX_MEMORY_LEVELS, MAX_REVIEW_WINDOW};
pub use filter::AutomaticFilter;
pub use misfit::MisfitResponse;
pub use noise::{NoiseSource, MIN_NOISE_TERMS};
pub use outlier::{OutlierRule, MORRISON_K, REYNEKE_DEFAULT_K};
pub use output::{final_outliers, AutoOutput, Withheld};
pub use phase::Phase;
