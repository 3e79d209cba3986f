//! The fixed-memory polynomial filter (Morrison 1969, ch. 7; Lear 1977): the least-squares
//! polynomial of degree `m` through the last `L+1` samples, its weights, covariance, bias,
//! trend removal, streaming filters and whole-series smoothing.
//!
//! ## Conventions
//!
//! - `L` (`span`) is the memory length: the window holds `L+1` samples (`window = L+1`).
//!   On the window axis `r`, `r = 0` is the oldest sample and `r = L` the newest (Morrison
//!   Fig. 7.1); `h` is the lead in sampling intervals after the newest sample (`r = L+h`):
//!   `h = 0` current estimate, `h = 1` one-step prediction, `h = -L/2` centre, any real `h`.
//! - Weight matrices multiply `Y_(n) = (y_n, y_{n-1}, …, y_{n-L})`, **newest first** (7.2.1):
//!   column `k` of [`weights`] multiplies `y_{n-k}`.
//! - Functions named without `unscaled` speak Morrison's scaled state `z_i = τ^i x^(i)/i!`;
//!   the `unscaled` ones, the filters and [`smooth`] speak derivatives `x^(i)` in the caller's
//!   time units (`X = D(τ) Z`).
//! - The analytic functions are generic over [`crate::scalar::Scalar`]: exact with
//!   [`crate::scalar::Rational`], stable in `f64` (every discrete Legendre value and
//!   derivative comes from the three-term recursion (A1.1)).
//!
//! | item | what | source |
//! |---|---|---|
//! | [`weights`], [`weights_unscaled`] | `W(h) = Φ(h) 𝒮 G C B`, `D(τ) W(h)` | (7.4.9)-(7.4.16) |
//! | [`covariance`], [`covariance_unscaled`], [`correlated_covariance`] | `W Wᵀ`, `D W Wᵀ D`, `W R Wᵀ` | (7.5.4), (7.5.22)-(7.5.28) |
//! | [`vrf_limit`] | `λ_ij(m, ρ)`: Tables 7.2 (`ρ = 1`) and 7.3 (`ρ = 1/2`) | (7.6.11)-(7.6.12), §7.8 |
//! | [`Design::min_span_for_sigma`], [`tau_for_derivative_sigma`] | design for a target 1σ | (7.6.1)-(7.6.5) |
//! | [`bias`], [`dominant_bias`], [`end_point_bias_bound`] | systematic errors | (7.10.17)-(7.10.18), (7.12.14), (7.13.5)-(7.13.10) |
//! | [`Design::balance_span`] | bias against random error | §7.13 |
//! | [`smooth_detrended`], [`Detrended`] | trend removal | §7.14 |
//! | [`FixedMemory`], [`FixedEngine`] | streaming filter: direct, sliding, irregular, adaptive | §7.1, §9.5 |
//! | [`smooth`], [`smooth_into`], [`smooth_with_sigma_into`] | whole-series centred smoothing (savgol `mode="interp"`), the sliding engine, with 1σ | (7.4.16), `h = -L/2`, (7.5.26)-(7.5.28) |
//! | [`CentredSmoother`], [`SmoothSigma`] | the same smoothing as a stream (memory bounded by the window): the one engine of [`smooth`] | (7.4.16), §7.5 |
//! | window moments `μ_j = Σ y(x) p_j(x)`, `β = C μ`, `T(r)` | the even-spacing fit (private `even`) | (7.4.5), (7.4.10), (7.4.15), (7.5.21) |
//! | sliding moments, shift matrix, refreshes | `O(m²)` per sample (private `sliding`) | (A1.1), §9.5 |
//! | QR fit of the window | irregular timestamps (private `irregular`) | §6.5 |
//!
//! ## The sliding engine
//!
//! [`FixedEngine::Sliding`], the sliding phase of [`FixedEngine::Adaptive`] and [`smooth`] on
//! evenly spaced samples share one engine. It keeps the window's moments
//! `μ_j = Σ_{x=0..L} y(x) p_j(x)` in the discrete Legendre basis (`β_j = μ_j/c_j²` are the
//! coefficients of the fit). When the window slides by one sample the oldest sample leaves, the
//! newest enters, and every retained sample moves from position `x` to `x-1`: with the exact
//! shift matrix `p_j(x-1) = Σ_l M_jl p_l(x)`, `μ' = M (μ − y_old 𝟙) + y_new (p_j(L))_j`
//! (`p_j(0) = 1`, `p_j(L) = (-1)^j`): `O(m²)` per sample, independent of `L`.
//!
//! Alone this recursion is unstable (Morrison §9.5, (9.5.3)-(9.5.10)): `M` is unipotent, so its
//! homogeneous part never forgets — every rounding error persists, and an error injected `k`
//! samples ago has since been shifted `k` samples, i.e. extrapolated beyond the window it
//! belonged to, where a degree-`m` error polynomial grows like `p_m` outside `[0, L]`.
//!
//! So the engine also runs `q` staggered **exact refresh accumulators**: each collects
//! `Σ y p_j(x)` over the `L+1` samples of one future window as they arrive, each sample added
//! directly at its final position `x` — an ordinary sum, no shift — and when its window is
//! complete it replaces `μ`. The accumulators are offset by `⌈(L+1)/q⌉` samples, so `μ` is
//! replaced by an exact sum every `⌈(L+1)/q⌉` samples: no error is ever carried through more
//! than `⌈(L+1)/q⌉` shifts, and the error stays bounded however long the run. The cost is
//! `O(m²) + O(q·m)` per sample with no latency spike (a refresh is not a recomputation over the
//! window), and the first window's moments come from an accumulator, so the first estimate is
//! an exact sum too. The refresh period is a fraction `1/q` of the window because a carried
//! error is amplified by the growth of `p_m` over the extrapolated distance, which at one full
//! window is `~|P_m(3)|` (`~10⁶` at `m = 10`); the default `q = 2^⌊(m-1)/2⌋` (1 for `m ≤ 2`, 2 for
//! `m ≤ 4`, 4 for `m ≤ 6`, 8 for `m ≤ 8`, 16 for `m ≤ 10`, …, at most `L+1`; settable with
//! [`FixedMemory::with_refreshes`]) keeps that factor near 10. [`smooth`] reports every
//! derivative up to `m` relative to its own scale and takes `4q` accumulators from `m = 3` on.
//!
//! Windows barely longer than the degree (`L ≈ m ≥ 16`) are ill-conditioned for every engine
//! (the discrete Legendre values themselves lose digits there). Measured accuracy of the
//! engines and of the analytic functions: see ACCURACY.md.
//!
//! ```
//! use seqsmooth::polynomial::fixed::{FixedEngine, FixedMemory};
//! use seqsmooth::PolynomialFilter;
//! let mut f = FixedMemory::new(2, 101, FixedEngine::Sliding).unwrap().with_noise_sigma(0.1).unwrap();
//! for n in 0..1000 {
//!     let t = 0.01 * n as f64;
//!     f.update(t, 1.0 + 2.0 * t - 3.0 * t * t).unwrap();
//! }
//! let s = f.estimate().unwrap();              // at t = 9.99
//! assert!((s.derivatives[1] - (2.0 - 6.0 * 9.99)).abs() < 1e-8);
//! assert!((s.derivatives[2] + 6.0).abs() < 1e-6);
//! let centre = f.estimate_at(9.49).unwrap(); // centre of the window: smallest variance
//! assert!(centre.std_devs().unwrap()[0] < s.std_devs().unwrap()[0]);
//! ```

mod bias;
mod centred;
mod covariance;
mod design;
mod even;
mod filter;
mod irregular;
mod ring;
mod sliding;
mod smooth;
mod trend;
mod weights;
mod window_vrf;

pub use bias::{bias, dominant_bias, end_point_bias_bound};
pub use centred::{CentredSmoother, SmoothSigma, SmoothedRow};
pub use covariance::{
    check_lead_steps, correlated_covariance, covariance, covariance_unscaled, vrf_limit,
    MAX_LEAD_STEPS,
};
pub use design::{tau_for_derivative_sigma, Balance, Design};
pub use filter::{FixedEngine, FixedMemory};
pub use smooth::{even_times, smooth, smooth_into, smooth_with_sigma_into};
pub use trend::{smooth_detrended, Detrended, Nominal};
pub use weights::{weights, weights_unscaled};
pub use window_vrf::{fixed_memory_vrf_limit, window_covariance};

use crate::error::{Error, Param};
use crate::scalar::{Rational, Scalar};

/// Steps of evenly spaced samples must agree with the first step to this relative tolerance.
pub(crate) const EVEN_STEP_TOLERANCE: f64 = 1e-9;

/// The even-spacing rule: `step` equals `first` to within a relative [`EVEN_STEP_TOLERANCE`],
/// plus the rounding of the timestamps themselves: each of the four times involved is within
/// half an ulp of its nominal value, so the two steps can differ by `2 ulp ≤ 2ε|t|` with `|t|`
/// the largest time (`t_scale`). Millisecond samples stamped in Unix seconds (`t ≈ 1.7e9`,
/// resolution `2.4e-7`) thus count as evenly spaced.
pub(crate) fn steps_agree(step: f64, first: f64, t_scale: f64) -> bool {
    crate::numeric::steps::same_step_within(
        step,
        first,
        t_scale,
        1.0,
        EVEN_STEP_TOLERANCE,
        2.0 * f64::EPSILON,
    )
}

/// [`FixedEngine::Adaptive`]'s stricter rule: the even-spacing engine runs only while every
/// step equals the first to a relative [`ADAPTIVE_STEP_TOLERANCE`], with no allowance for the
/// timestamps' rounding. Its fit (on the mean step) is then the least-squares fit of the actual
/// times to about 1e-9 at any time origin: at Unix times the timestamps' own rounding (`2ε|t|`,
/// a relative 4.8e-5 of a 10 ms step at 1.7e9 s) already exceeds the tolerance, so such samples
/// go to the QR engine, which fits the times as they are.
pub(crate) fn steps_equal(step: f64, first: f64) -> bool {
    (step - first).abs() <= ADAPTIVE_STEP_TOLERANCE * first.abs()
}

/// The relative step tolerance of [`steps_equal`].
pub(crate) const ADAPTIVE_STEP_TOLERANCE: f64 = 1e-12;

/// Where in (or beyond) the window an estimate is wanted, for the design helpers.
///
/// ```
/// use seqsmooth::polynomial::fixed::Lead;
/// assert_eq!(Lead::Centre.steps(10), -5.0);
/// assert_eq!(Lead::Steps(1.0).steps(10), 1.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Lead {
    /// `h` sampling intervals after the newest sample: `0` current estimate, `1` one-step
    /// prediction, negative a retrodiction.
    Steps(f64),
    /// The centre of the window, `h = -L/2`.
    Centre,
}

impl Lead {
    /// The lead `h` in sampling intervals for the span `L`.
    pub fn steps(&self, span: u64) -> f64 {
        match self {
            Lead::Steps(h) => *h,
            Lead::Centre => -(span as f64) / 2.0,
        }
    }

    fn check(&self) -> Result<(), Error> {
        match self {
            Lead::Steps(h) if !h.is_finite() => Err(Error::NonFinite {
                what: "lead h",
                value: *h,
            }),
            _ => Ok(()),
        }
    }
}

/// `L` in the field `T`.
fn span_scalar<T: Scalar>(span: u64) -> T {
    T::from_rational(&Rational::from_integer(span.into()))
}

/// Degree within range and at least `m+1` samples (`L ≥ m`).
fn check_span(m: usize, span: u64) -> Result<(), Error> {
    crate::polynomial::options::check_degree(m)?;
    if span < m as u64 {
        return Err(Error::TooFewSamples {
            needed: m + 1,
            got: span as usize + 1,
        });
    }
    Ok(())
}

/// The longest window the functions that store or materialise a whole window accept
/// ([`weights`], [`FixedMemory`]): 2³² samples.
pub(crate) const MAX_WINDOW: u64 = 1 << 32;

/// A window of `span + 1` samples that can be materialised.
fn check_materialised(span: u64) -> Result<(), Error> {
    if span >= MAX_WINDOW {
        return Err(Error::InvalidParameter {
            name: Param::Span,
            value: span.to_string(),
            reason: format!("windows of more than {MAX_WINDOW} samples are not materialised"),
        });
    }
    Ok(())
}

/// A fixed memory's window (Morrison's `L + 1` samples, ch. 7): the degree within range and
/// `m+1 ≤ window ≤ MAX_WINDOW` (every front end's check).
///
/// ```
/// use seqsmooth::polynomial::fixed::check_window;
/// assert!(check_window(2, 3).is_ok() && check_window(2, 2).is_err());
/// ```
pub fn check_window(m: usize, window: usize) -> Result<(), Error> {
    crate::polynomial::options::check_degree(m)?;
    if window as u64 > MAX_WINDOW {
        return Err(Error::InvalidParameter {
            name: Param::Window,
            value: window.to_string(),
            reason: format!("at most {MAX_WINDOW} samples"),
        });
    }
    if window < m + 1 {
        return Err(Error::InvalidParameter {
            name: Param::Window,
            value: window.to_string(),
            reason: format!(
                "a degree-{m} fit needs a window of at least {} samples",
                m + 1
            ),
        });
    }
    Ok(())
}

fn check_finite<T: Scalar>(what: &'static str, v: &T) -> Result<(), Error> {
    let f = v.to_f64();
    if !f.is_finite() {
        return Err(Error::NonFinite { what, value: f });
    }
    Ok(())
}

fn check_tau_scalar<T: Scalar>(tau: &T) -> Result<(), Error> {
    let f = tau.to_f64();
    if !(f.is_finite() && *tau > T::zero()) {
        return Err(Error::TauOutOfRange { tau: f });
    }
    Ok(())
}
