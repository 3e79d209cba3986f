//! # seqsmooth
//!
//! Sequential smoothing and prediction: polynomial filters that turn streams of noisy,
//! timestamped measurements into smoothed estimates, derivatives and predictions with honest
//! error statistics (Morrison, *Introduction to Sequential Smoothing and Prediction*, 1969;
//! Reyneke, Morrison, Kourie, de Ridder, 2012).
//!
//! ## Conventions (fixed here, once)
//!
//! - **Degree** `m`; the state has `m+1` components indexed by **derivative order**
//!   `k = 0..m` (`0` = the value itself).
//! - The **public API speaks unscaled derivatives in the caller's time units**:
//!   [`PolynomialState::derivatives`] is `(x, x', x'', …, x^(m))` at
//!   [`PolynomialState::time`].
//! - Internally and in the printed tables, Morrison's **scaled state** `Z` has
//!   `z_k = τ^k x^(k) / k!` (4.2.14); `X = D(τ) Z` with `D(τ) = diag(k!/τ^k)` (4.2.18). Gains
//!   ([`polynomial::expanding::gains`], [`polynomial::fading::gains`]) and variance-reduction
//!   matrices ([`polynomial::expanding::vrf`], [`polynomial::fading::vrf`]) are given for `Z`
//!   (Tables 9.1, 9.2, 13.1-13.3), and converted at the boundary ([`model`]).
//! - **Transition matrices**: Morrison's `Φ(h)` acts on `Z` with `h` in samples,
//!   `[Φ(h)]_ij = C(j,i) h^(j-i)` ([`model::phi`]); Reyneke's `Ψ(ζ)` acts on `d_k = τ^k x^(k)`,
//!   `[Ψ(ζ)]_ij = ζ^(j-i)/(j-i)!` ([`model::psi`]), which is also the unscaled `Φ_X`. Gains
//!   relate by `Γ_Ψ[k] = k! Γ_Φ[k]`.
//! - **Sample index** `n` is 0-based: after the sample with index `n` the filter has seen `n+1`
//!   samples (Morrison ch. 9: "in all cases n starts at zero").
//! - **Fading memory**: one type, [`discount::Discount`], for every filter that forgets
//!   (polynomial, Bayes, Kalman): `θ ∈ (0,1)` per span `τ` of time, a sample of age `Δt`
//!   weighing `θ^(Δt/τ)` ([`discount::Discount::PerTime`]), or `θ` per later sample
//!   ([`discount::Discount::PerUpdate`]).
//! - **Right or refused**: every number of an estimate is finite. Where there is none,
//!   [`PolynomialFilter::try_estimate_at`] says why: too few samples, a fit singular in doubles
//!   (with what to change), or a derivative or variance beyond the double range in the caller's
//!   units ([`Error::EstimateOutOfRange`]); `estimate_at` is `None` exactly then, and the rows
//!   of `update_many_into` hold NaN ("no estimate") there, never an infinity.
//!
//! ## Modules
//!
//! - [`calculus`]: factorials, binomials, Stirling and link matrices, polynomials.
//! - [`basis`]: discrete Legendre and Laguerre polynomials, classical Legendre.
//! - [`model`]: state scaling, `Φ` and `Ψ`, propagation ([`PolynomialState::at`]).
//! - [`estimate`]: batch least squares (QR): polynomial fits, the minimum-variance estimate of
//!   any linear model, Gauss–Newton differential correction (§8.5-8.7, ch. 11), the sliding
//!   fit of each measurement's window, curve fits with their Cramér–Rao bound.
//! - [`polynomial`]: the polynomial filters, one module per concept (table in its docs):
//!   - [`polynomial::expanding`]: [`ExpandingMemory`], its gains and VRF (Morrison ch. 9);
//!   - [`polynomial::fading`]: [`FadingMemory`], its gains, VRF and the expanding → fading
//!     switch (Morrison ch. 13);
//!   - the exact and gain engines both run on (`polynomial::engine`, internal);
//!   - [`polynomial::fixed`]: [`FixedMemory`] and whole-series smoothing (Morrison ch. 7);
//!   - [`polynomial::automatic`]: the automatic filter (start-up, outliers, noise, misfit,
//!     degree settling; Morrison §13.8, §14.8; Reyneke et al. §7);
//!   - [`polynomial::bank`], [`polynomial::stream`]: many channels at once;
//!   - [`polynomial::tau`]: the default `τ` of a fading memory (the median time step);
//!   - every filter implements [`PolynomialFilter`], configured as `Type::new(required)?`
//!     (the automatic filter: `AutomaticFilter::new(m, θ, τ)`) then `.with_x(v)?` builders.
//! - [`kalman`]: recursive filters over any dynamic and observation model (Morrison chs. 10,
//!   12, 14, 15): the Bayes filter in information form, the Kalman filter (extended, iterated,
//!   driving noise, fading memory), the Rauch–Tung–Striebel and fixed-lag smoothers.
//! - [`track`]: the radar tracking application over them: a radar's rows to a track
//!   ([`track::RadarTracker`]: start-up fit, sliding fit, Kalman filter or fixed-lag
//!   smoother) with its innovation monitor (§14.8).
//! - [`paml`]: polynomial samples and the PAML estimate (Villien & Ostertag 2009).
//! - [`stats`]: chi-squared tests, noise estimation, residual calibration, NIS/NEES.
//! - [`recursive`]: the square-root information (Bayes) recursion the exact engines run on.
//! - [`scalar`]: the `f64` / exact-rational abstraction every formula is generic over.
//! - [`linalg`]: the small dense linear algebra the formulas share.
//! - [`error`]: the one error type, [`Error`], of every fallible call.
//! - [`discount`]: the discount of every fading memory, [`discount::Discount`].
//! - [`persist`]: the one saved form of every filter (copy, save and resume bit for bit).
//! - `numeric`: the numerical building blocks of the engines (double-word arithmetic, the
//!   step tolerance).
//!
//! Measured accuracy: see ACCURACY.md; speed: BENCHMARKS.md.
//!
//! ```
//! use seqsmooth::{Engine, FadingMemory, PolynomialFilter};
//! // degree-2 fading-memory filter, θ = 0.9 per second, noise σ = 0.1
//! let mut f = FadingMemory::new(2, 0.9, 1.0, Engine::Exact).unwrap().with_noise_sigma(0.1).unwrap();
//! for k in 0..50 {
//!     let t = k as f64 * 1.0 + 0.1 * ((k * 7 % 5) as f64); // irregular times
//!     f.update(t, 3.0 + 2.0 * t).unwrap();
//! }
//! let s = f.estimate().unwrap();
//! assert!((s.derivatives[1] - 2.0).abs() < 1e-9);        // exact on a polynomial
//! assert!(s.std_devs().unwrap()[0] < 0.1);                // smoothed below the noise
//! ```
#![warn(missing_docs)]

// Before the modules: `field_clone!` is in scope in every one of them.
#[macro_use]
mod field_clone;

pub mod basis;
pub mod calculus;
pub mod discount;
pub mod error;
pub mod estimate;
pub mod kalman;
pub mod linalg;
pub mod model;
pub mod numeric;
pub mod paml;
pub mod persist;
pub mod polynomial;
pub mod recursive;
pub mod scalar;
pub mod stats;
pub mod track;

pub use error::{Error, Param};

/// The README's Rust example, compiled and run as a doctest.
#[cfg(doctest)]
#[doc = include_str!("../../../README.md")]
pub struct ReadmeDoctests;
pub use model::PolynomialState;
pub use polynomial::fixed::{FixedEngine, FixedMemory};
pub use polynomial::{DiscountMode, Engine, ExpandingMemory, FadingMemory, PolynomialFilter};
