//! Measurement-noise estimation: from differences of the samples (no model needed) and from the
//! residuals of a fit (Reyneke et al. §7.1, eq. 39, App. A.5; Morrison §6.10).
//!
//! ## Differences
//!
//! For white noise of variance `σ²` on a trend, the first difference `y_i − y_{i−1}` has variance
//! `2σ²` plus the square of the trend's increment. Reyneke's eq. 39,
//! `R = Σ_{i=2..N} (y_i − y_{i−1})² / (2N − 2)` ([`reyneke_eq39_variance`]), is therefore biased
//! by any slope (`+ s²/2` for a slope `s` per sample), and `stdd = std(diff y)/√2`
//! ([`reyneke_stdd`], App. A.5), which subtracts the mean difference, by any curvature. The
//! `k`-th difference annihilates every polynomial of degree `< k`, and for white noise
//! `Var(∇^k y) = C(2k,k) σ²` (the weights `(−1)^j C(k,j)` have `Σ C(k,j)² = C(2k,k)`), so
//! `mean((∇^k y)²)/C(2k,k)` ([`difference_variance`]) is unbiased on a trend of degree `< k`.
//! On irregular timestamps the `k`-th divided difference
//! `Σ_j w_j y_j`, `w_j = 1/Π_{i≠j}(t_j − t_i)`, annihilates the same polynomials and has
//! variance `σ² Σ w_j²`, so `d = Σ w_j y_j / √(Σ w_j²)` has variance exactly `σ²`
//! ([`DifferenceNoise`], running or windowed; on even samples it is `∇^k y/√C(2k,k)`).
//! What remains is the trend's `k`-th derivative: `E{d²} = σ² + b²` with, on even steps `Δt`,
//! `b ≈ x^(k) Δt^k / √C(2k,k)`, negligible when `k` exceeds the degree of the local trend. Successive `d` overlap (`k+1` samples each), so the estimate's variance is
//! `2σ⁴/N · C(4k,2k)/C(2k,k)²` (1.5, 1.94, 2.31 × the independent-sample value for `k = 1, 2,
//! 3`) rather than `2σ⁴/N`.
//!
//! An outlier of size `a` at one sample enters `k + 1` successive differences (as `a w_j/√(Σw²)`,
//! in all `a²`), and an isolated glitch of the trend does the same; the screen of
//! [`DifferenceNoise::with_screen`] leaves out a difference beyond `c σ̂` and the `k` after it
//! (which share its samples) and divides the mean of the kept terms by the variance of a unit
//! Gaussian truncated at `±c`, the expectation of a kept term in units of `σ²`.
//!
//! ## Residuals
//!
//! After a least-squares fit of `N_X` parameters to `N_O` samples, the residual sum of squares
//! `e°` has expectation `σ² (N_O − N_X)` (Morrison (6.10.21)), so `σ̂² = e°/(N_O − N_X)`
//! (6.10.24; [`residual_variance`]). Model mismatch inflates it (6.10.25).

use super::chi_squared::two_sided_tail;
use super::welford::Welford;
use super::window::SlidingSum;
use crate::calculus::choose;
use crate::error::{check_finite, Error, Param};
use std::collections::VecDeque;

fn check_values(values: &[f64]) -> Result<(), Error> {
    check_finite("value", values)
}

/// Reyneke's eq. 39 as printed: `R = Σ_{i=2..N} (y_i − y_{i−1})² / (2N − 2)`, the noise variance
/// from first differences of evenly spaced samples. Unbiased on white noise about a constant;
/// a slope `s` per sample adds `s²/2` (`√R = √(1 + 1/8) = 1.061` for `σ = 1`, `s = 0.5`).
/// Needs `N ≥ 2` samples.
///
/// ```
/// use seqsmooth::stats::reyneke_eq39_variance;
/// // a pure ramp: only the slope bias remains, s²/2
/// let y: Vec<f64> = (0..100).map(|n| 0.5 * n as f64).collect();
/// assert!((reyneke_eq39_variance(&y).unwrap() - 0.125).abs() < 1e-12);
/// ```
pub fn reyneke_eq39_variance(values: &[f64]) -> Result<f64, Error> {
    check_values(values)?;
    let n = values.len();
    if n < 2 {
        return Err(Error::TooFewSamples { needed: 2, got: n });
    }
    let s: f64 = values.windows(2).map(|w| (w[1] - w[0]).powi(2)).sum();
    Ok(s / (2 * n - 2) as f64)
}

/// Reyneke's `stdd` (App. A.5): `σ = std(diff(y))/√2`, with Matlab's `std` (mean removed,
/// `1/(N−2)` normalisation over the `N−1` differences). Immune to a constant slope, biased by
/// curvature: a trend `c n²` adds about `(2cN)²/24` to `σ̂²` (the differences `2cn` spread
/// over `N` samples; `σ̂ = 1.290` for `σ = 1`, `c = 10⁻³`, `N = 2000`). Needs `N ≥ 3`.
///
/// ```
/// use seqsmooth::stats::reyneke_stdd;
/// let y: Vec<f64> = (0..50).map(|n| 3.0 + 0.5 * n as f64).collect();
/// assert!(reyneke_stdd(&y).unwrap() < 1e-12); // slope removed
/// ```
pub fn reyneke_stdd(values: &[f64]) -> Result<f64, Error> {
    check_values(values)?;
    let n = values.len();
    if n < 3 {
        return Err(Error::TooFewSamples { needed: 3, got: n });
    }
    let mut w = Welford::new();
    for d in values.windows(2) {
        w.push(d[1] - d[0])?;
    }
    Ok((w.sample_variance().unwrap_or(0.0) / 2.0).sqrt())
}

/// Reyneke's `stddw` (App. A.5): [`reyneke_stdd`] over a centred moving window of `window`
/// samples, `[i − ⌊w/2⌋, i − ⌊w/2⌋ + w)` clipped to the data, for every sample `i` (the paper
/// uses `w = 20`). Windows with fewer than 3 samples give 0, as the Matlab code does for a
/// single sample.
///
/// ```
/// use seqsmooth::stats::reyneke_stddw;
/// let y: Vec<f64> = (0..30).map(|n| if n % 2 == 0 { 1.0 } else { -1.0 }).collect();
/// let s = reyneke_stddw(&y, 20).unwrap();
/// assert_eq!(s.len(), 30);
/// assert!(s.iter().all(|v| *v > 1.4 && *v < 1.5)); // alternating ±1: √2 · (a little over 1)
/// ```
pub fn reyneke_stddw(values: &[f64], window: usize) -> Result<Vec<f64>, Error> {
    check_values(values)?;
    if window == 0 {
        return Err(Error::InvalidParameter {
            name: Param::Window,
            value: window.to_string(),
            reason: "must be at least 1 sample".into(),
        });
    }
    let n = values.len() as i64;
    let w = window as i64;
    Ok((0..n)
        .map(|i| {
            let lo = (i - w / 2).max(0);
            let hi = (i - w / 2 + w).min(n);
            let slice = &values[lo as usize..hi.max(lo) as usize];
            if slice.len() < 3 {
                0.0
            } else {
                reyneke_stdd(slice).unwrap_or(0.0)
            }
        })
        .collect())
}

/// The bias-free difference estimator of the noise variance on evenly spaced samples:
/// `σ̂² = mean((∇^k y)²) / C(2k,k)` over the `N − k` differences of order `k ≥ 1`. Unbiased for
/// white noise on any polynomial trend of degree `< k` (the weights `(−1)^j C(k,j)` annihilate
/// it and have `Σ C(k,j)² = C(2k,k)`). Needs
/// `N ≥ k + 1`.
///
/// ```
/// use seqsmooth::stats::difference_variance;
/// // a quadratic trend is annihilated by the third difference
/// let y: Vec<f64> = (0..40).map(|n| 1.0 + 2.0 * n as f64 - 0.3 * (n * n) as f64).collect();
/// assert!(difference_variance(&y, 3).unwrap() < 1e-20);
/// ```
pub fn difference_variance(values: &[f64], order: usize) -> Result<f64, Error> {
    check_order(order)?;
    check_values(values)?;
    let n = values.len();
    if n < order + 1 {
        return Err(Error::TooFewSamples {
            needed: order + 1,
            got: n,
        });
    }
    let mut d = values.to_vec();
    for _ in 0..order {
        for i in 0..d.len() - 1 {
            d[i] = d[i + 1] - d[i];
        }
        d.pop();
    }
    let c: f64 = choose(2 * order, order);
    Ok(d.iter().map(|v| v * v).sum::<f64>() / (d.len() as f64 * c))
}

/// The largest difference order the estimators accept: enough for a trend of the filters'
/// largest degree (`MAX_DEGREE + 1`, checked where the filters define it).
///
/// ```
/// use seqsmooth::stats::{DifferenceNoise, MAX_DIFFERENCE_ORDER};
/// assert!(DifferenceNoise::new(MAX_DIFFERENCE_ORDER, None).is_ok());
/// assert!(DifferenceNoise::new(MAX_DIFFERENCE_ORDER + 1, None).is_err());
/// ```
pub const MAX_DIFFERENCE_ORDER: usize = 25;

fn check_order(order: usize) -> Result<(), Error> {
    if order == 0 || order > MAX_DIFFERENCE_ORDER {
        return Err(Error::InvalidParameter {
            name: Param::DifferenceOrder,
            value: order.to_string(),
            reason: format!("must be between 1 and {MAX_DIFFERENCE_ORDER}"),
        });
    }
    Ok(())
}

/// The noise variance from the residuals of a least-squares fit: `σ̂² = e°/(N_O − N_X)`
/// (Morrison (6.10.24)), `e°` the residual sum of squares of `N_O` samples fitted with `N_X`
/// parameters. Requires `N_O > N_X` and a finite `e° ≥ 0`.
///
/// ```
/// use seqsmooth::stats::residual_variance;
/// assert_eq!(residual_variance(12.0, 10, 2).unwrap(), 1.5);
/// assert!(residual_variance(1.0, 3, 3).is_err());
/// ```
pub fn residual_variance(
    residual_sq: f64,
    observations: usize,
    parameters: usize,
) -> Result<f64, Error> {
    if !(residual_sq.is_finite() && residual_sq >= 0.0) {
        return Err(Error::InvalidParameter {
            name: Param::ResidualSumOfSquares,
            value: residual_sq.to_string(),
            reason: "must be a non-negative finite number".into(),
        });
    }
    if observations <= parameters {
        return Err(Error::TooFewSamples {
            needed: parameters + 1,
            got: observations,
        });
    }
    Ok(residual_sq / (observations - parameters) as f64)
}

/// The normalised `k`-th divided difference of `k+1` samples with distinct times:
/// `Σ w_j y_j / √(Σ w_j²)`, `w_j = 1/Π_{i≠j}(t_j − t_i)` — zero on any polynomial of degree
/// `< k`, variance `σ²` on white noise. Times are rescaled to the span first (the ratio is
/// scale-invariant), so no under- or overflow.
///
/// ```
/// use seqsmooth::stats::normalised_divided_difference;
/// // even steps, k = 1: (y1 − y0)/√2
/// let d = normalised_divided_difference(&[0.0, 1.0], &[1.0, 3.0]).unwrap();
/// assert!((d - 2.0 / 2f64.sqrt()).abs() < 1e-15);
/// // irregular steps: a quadratic is annihilated by the third divided difference
/// let t = [0.0, 0.3, 1.7, 2.0];
/// let y: Vec<f64> = t.iter().map(|t| 5.0 - t + 2.0 * t * t).collect();
/// assert!(normalised_divided_difference(&t, &y).unwrap().abs() < 1e-12);
/// ```
pub fn normalised_divided_difference(times: &[f64], values: &[f64]) -> Result<f64, Error> {
    if times.len() != values.len() || times.len() < 2 {
        return Err(Error::InvalidParameter {
            name: Param::InputLengths,
            value: format!("{} times, {} values", times.len(), values.len()),
            reason: "need the same number (at least 2) of times and values".into(),
        });
    }
    check_finite("time", times)?;
    check_values(values)?;
    for w in times.windows(2) {
        if w[1] <= w[0] {
            return Err(Error::TimeNotIncreasing {
                time: w[1],
                previous: w[0],
            });
        }
    }
    Ok(divided_difference_unchecked(times, values))
}

fn divided_difference_unchecked(times: &[f64], values: &[f64]) -> f64 {
    divided_difference_with_factors(times, values, &[]).0
}

/// The normalised divided difference and its variance in units of `σ²` when sample `j` has
/// variance `f_j σ²` (`factors` empty: all 1).
fn divided_difference_with_factors(times: &[f64], values: &[f64], factors: &[f64]) -> (f64, f64) {
    let k = times.len();
    let span = times[k - 1] - times[0];
    let mut num = 0.0;
    let mut norm = 0.0;
    // Weights relative to the span; the common factor span^(-k+1) cancels in the ratio. Scale
    // them by the largest to keep the sums in range. On the stack up to the largest order.
    let mut stack = [0.0; MAX_DIFFERENCE_ORDER + 1];
    let mut heap = Vec::new();
    let w: &mut [f64] = if k <= stack.len() {
        &mut stack[..k]
    } else {
        heap.resize(k, 0.0);
        &mut heap
    };
    for j in 0..k {
        let mut p = 1.0;
        for i in 0..k {
            if i != j {
                p *= (times[j] - times[i]) / span;
            }
        }
        w[j] = 1.0 / p;
    }
    let big = w.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let mut weighted = 0.0;
    for j in 0..k {
        let wj = w[j] / big;
        num += wj * values[j];
        norm += wj * wj;
        weighted += wj * wj * factors.get(j).copied().unwrap_or(1.0);
    }
    (num / norm.sqrt(), weighted / norm)
}

/// Running noise estimator from normalised divided differences of order `k` on any timestamps
/// (see the [module docs](self)): unbiased for white noise about any polynomial of degree `< k`.
/// Cumulative, or over the last `window` differences.
///
/// ```
/// use seqsmooth::stats::DifferenceNoise;
/// let mut est = DifferenceNoise::new(2, None).unwrap();
/// // a ramp plus an alternating ±0.1 "noise", on irregular times
/// for n in 0..200 {
///     let t = n as f64 + 0.3 * ((n * 7 % 5) as f64) / 5.0;
///     let y = 4.0 + 3.0 * t + if n % 2 == 0 { 0.1 } else { -0.1 };
///     est.push(t, y).unwrap();
/// }
/// let s = est.sigma().unwrap();
/// assert!(s > 0.1 && s < 0.2); // the ramp is gone; the rest is the ±0.1 pattern
/// ```
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub struct DifferenceNoise {
    order: usize,
    times: VecDeque<f64>,
    values: VecDeque<f64>,
    factors: VecDeque<f64>,
    /// The sum of the normalised squared differences `d²`.
    squares: SlidingSum,
    /// The screen `c` (`|d| > c σ̂` leaves a difference out), if any.
    screen: Option<f64>,
    /// The variance of a unit Gaussian truncated at the screen (1 without one), computed once.
    kept: f64,
    /// Differences still to leave out after a screened one (they share its samples).
    holdoff: usize,
    /// The first [`SCREEN_REFERENCE_TERMS`] squared differences (for the startup reference).
    early: Vec<f64>,
    /// Differences left out by the screen (the screened ones and those that share their samples).
    left_out: u64,
}

// Field by field, `clone_from` too (the automatic filter's review keeps copies of it).
field_clone!(DifferenceNoise {
    order,
    times,
    values,
    factors,
    squares,
    screen,
    kept,
    holdoff,
    early,
    left_out
});

/// Until the screened estimate has this many terms, the screen's reference is the mean of the
/// smallest 80% of the squared differences seen so far, over its value for Gaussian terms
/// (robust to an early outlier), and the screen 1.5 times as wide.
const SCREEN_REFERENCE_TERMS: usize = 20;

/// The mean of `χ²₁` below its 80% quantile `a² = Φ⁻¹(0.9)²`: `(0.8 − 2aφ(a))/0.8`.
const CHI2_1_TRIMMED_MEAN: f64 = 0.437_724_6;

impl DifferenceNoise {
    /// An estimator from differences of order `k ≥ 1` (use `k = m + 1` for a degree-`m` trend),
    /// over the last `window ≥ 1` differences, or all of them with `None`.
    ///
    /// ```
    /// use seqsmooth::stats::DifferenceNoise;
    /// assert!(DifferenceNoise::new(3, Some(100)).is_ok());
    /// assert!(DifferenceNoise::new(0, None).is_err());
    /// assert!(DifferenceNoise::new(2, Some(0)).is_err());
    /// ```
    pub fn new(order: usize, window: Option<usize>) -> Result<Self, Error> {
        check_order(order)?;
        if window == Some(0) {
            return Err(Error::InvalidParameter {
                name: Param::Window,
                value: "0".into(),
                reason: "must be at least 1 difference".into(),
            });
        }
        Ok(Self {
            order,
            times: VecDeque::with_capacity(order + 1),
            values: VecDeque::with_capacity(order + 1),
            factors: VecDeque::with_capacity(order + 1),
            squares: SlidingSum::new(window),
            screen: None,
            kept: 1.0,
            holdoff: 0,
            early: Vec::new(),
            left_out: 0,
        })
    }

    /// The same estimator, robust to outliers and to isolated glitches of the trend: a difference
    /// with `|d| > c σ̂` (`σ̂` the estimate before it; while fewer than 20 are in, `|d| > 1.5c σ̂₀`
    /// with `σ̂₀²` the mean of the smallest 80% of the squared differences so far over its
    /// Gaussian value 0.4377) is left out, and so are the
    /// next `k` differences, which share its samples (an outlier of size `a` at one sample enters
    /// `k + 1` successive differences, with weights `w_j/√(Σw²)`). The kept terms of white
    /// Gaussian noise are truncated at `±cσ`, so the estimate divides their mean by the
    /// truncated variance `1 − 2cφ(c)/(1 − 2Q(c))` (0.973 at `c = 3`), which keeps it unbiased
    /// for `σ²`. `c > 0`; infinity: no screen.
    ///
    /// ```
    /// use seqsmooth::stats::DifferenceNoise;
    /// let mut plain = DifferenceNoise::new(2, None).unwrap();
    /// let mut robust = DifferenceNoise::new(2, None).unwrap().with_screen(3.0).unwrap();
    /// for n in 0..400 {
    ///     let noise = if n % 2 == 0 { 0.1 } else { -0.1 };
    ///     let y = 2.0 * n as f64 + noise + if n % 100 == 50 { 20.0 } else { 0.0 }; // 4 spikes
    ///     plain.push(n as f64, y).unwrap();
    ///     robust.push(n as f64, y).unwrap();
    /// }
    /// assert!(plain.sigma().unwrap() > 1.0);   // the spikes dominate
    /// let s = robust.sigma().unwrap();          // the ±0.1 pattern: ∇²(±0.1)/√6 = ±0.163
    /// assert!(s > 0.16 && s < 0.17, "{s}");
    /// assert_eq!(robust.left_out(), 4 * 3);     // each spike and the 2 differences after it
    /// assert!(DifferenceNoise::new(2, None).unwrap().with_screen(0.0).is_err());
    /// ```
    pub fn with_screen(mut self, c: f64) -> Result<Self, Error> {
        if c.is_nan() || c <= 0.0 {
            return Err(Error::InvalidParameter {
                name: Param::NoiseScreen,
                value: c.to_string(),
                reason: "must be positive (infinity: no screen)".into(),
            });
        }
        self.screen = c.is_finite().then_some(c);
        self.kept = self.screen.map_or(1.0, truncated_variance);
        Ok(self)
    }

    /// Differences the screen left out (see [`with_screen`](Self::with_screen)).
    ///
    /// ```
    /// use seqsmooth::stats::DifferenceNoise;
    /// assert_eq!(DifferenceNoise::new(3, None).unwrap().left_out(), 0);
    /// ```
    pub fn left_out(&self) -> u64 {
        self.left_out
    }

    /// The screen's reference variance: the estimate, or while it has fewer than
    /// [`SCREEN_REFERENCE_TERMS`] terms the trimmed mean of the squared differences seen so far
    /// (`None` before 3 are seen).
    fn screen_reference(&self) -> Option<f64> {
        if self.len() >= SCREEN_REFERENCE_TERMS {
            return self.variance();
        }
        if self.early.len() < 3 {
            return None;
        }
        let mut e = self.early.clone();
        e.sort_by(f64::total_cmp);
        // The mean of the smallest 80% (at least 3) over its value for unit Gaussian terms.
        let kept = ((e.len() * 4) / 5).max(3);
        let trimmed = e[..kept].iter().sum::<f64>() / kept as f64;
        Some(trimmed / CHI2_1_TRIMMED_MEAN)
    }

    /// Whether the screen leaves out the new squared difference `d2` (and updates its state).
    fn screened_out(&mut self, d2: f64) -> bool {
        let Some(c) = self.screen else {
            return false;
        };
        if self.holdoff > 0 {
            self.holdoff -= 1;
            self.left_out += 1;
            return true;
        }
        // While the reference is the trimmed mean (which assumes Gaussian terms), only gross
        // outliers: 1.5 times the screen.
        let c = if self.len() >= SCREEN_REFERENCE_TERMS {
            c
        } else {
            1.5 * c
        };
        let reference = self.screen_reference();
        if self.early.len() < SCREEN_REFERENCE_TERMS {
            self.early.push(d2);
        }
        match reference {
            Some(r) if d2 > c * c * r => {
                self.holdoff = self.order;
                self.left_out += 1;
                true
            }
            _ => false,
        }
    }

    /// The difference order `k`.
    ///
    /// ```
    /// use seqsmooth::stats::DifferenceNoise;
    /// assert_eq!(DifferenceNoise::new(3, None).unwrap().order(), 3);
    /// ```
    pub fn order(&self) -> usize {
        self.order
    }

    /// Adds a sample (finite, strictly after the previous time); returns the new normalised
    /// difference once `k+1` samples are in. On error the estimator is unchanged.
    ///
    /// ```
    /// use seqsmooth::stats::DifferenceNoise;
    /// let mut est = DifferenceNoise::new(1, None).unwrap();
    /// assert_eq!(est.push(0.0, 1.0).unwrap(), None);          // k + 1 = 2 samples needed
    /// let d = est.push(2.0, 3.0).unwrap().unwrap();            // (3 − 1)/2, normalised by √(2/4)
    /// assert!((d - 2f64.sqrt()).abs() < 1e-15);
    /// assert!(est.push(1.0, 0.0).is_err());                    // time not increasing
    /// ```
    pub fn push(&mut self, t: f64, y: f64) -> Result<Option<f64>, Error> {
        self.push_with_variance_factor(t, y, 1.0)
    }

    /// [`push`](Self::push) for a sample whose noise variance is `f·σ²` with a known factor
    /// `f > 0` — e.g. a sample that passed a gate, whose noise is truncated. Each squared
    /// difference is divided by its expected value in units of `σ²`,
    /// `Σ w_j² f_j / Σ w_j²`, which keeps the estimate unbiased for `σ²`.
    ///
    /// ```
    /// use seqsmooth::stats::DifferenceNoise;
    /// let mut est = DifferenceNoise::new(1, None).unwrap();
    /// est.push_with_variance_factor(0.0, 0.0, 0.5).unwrap();
    /// est.push_with_variance_factor(1.0, 1.0, 0.5).unwrap();
    /// // d² = 1/2 with expected value σ²·(0.5 + 0.5)/2: σ̂² = 1
    /// assert!((est.variance().unwrap() - 1.0).abs() < 1e-15);
    /// ```
    pub fn push_with_variance_factor(
        &mut self,
        t: f64,
        y: f64,
        factor: f64,
    ) -> Result<Option<f64>, Error> {
        if !(factor.is_finite() && factor > 0.0) {
            return Err(Error::InvalidParameter {
                name: Param::VarianceFactor,
                value: factor.to_string(),
                reason: "must be a positive finite number".into(),
            });
        }
        crate::error::check_sample(t, y, self.times.back().copied())?;
        self.times.push_back(t);
        self.values.push_back(y);
        self.factors.push_back(factor);
        if self.times.len() > self.order + 1 {
            self.times.pop_front();
            self.values.pop_front();
            self.factors.pop_front();
        }
        if self.times.len() < self.order + 1 {
            return Ok(None);
        }
        // The windows copied to the stack (`order + 1 ≤ MAX_DIFFERENCE_ORDER + 1` values each):
        // cheaper than rotating the rings in place at every sample.
        let k = self.order + 1;
        let mut window = [[0.0; MAX_DIFFERENCE_ORDER + 1]; 3];
        for (w, ring) in window
            .iter_mut()
            .zip([&self.times, &self.values, &self.factors])
        {
            for (a, &b) in w.iter_mut().zip(ring) {
                *a = b;
            }
        }
        let [times, values, factors] = &window;
        let (d, expected) =
            divided_difference_with_factors(&times[..k], &values[..k], &factors[..k]);
        let d2 = d * d / expected;
        if !self.screened_out(d2) {
            self.squares.push(d2);
        }
        Ok(Some(d))
    }

    /// Differences currently in the estimate.
    ///
    /// ```
    /// use seqsmooth::stats::DifferenceNoise;
    /// let mut est = DifferenceNoise::new(1, Some(2)).unwrap();
    /// for n in 0..5 { est.push(n as f64, 0.0).unwrap(); }
    /// assert_eq!(est.len(), 2); // 4 differences, the window keeps 2
    /// ```
    pub fn len(&self) -> usize {
        self.squares.len()
    }

    /// True before the first difference.
    ///
    /// ```
    /// use seqsmooth::stats::DifferenceNoise;
    /// let mut est = DifferenceNoise::new(1, None).unwrap();
    /// est.push(0.0, 1.0).unwrap();
    /// assert!(est.is_empty());
    /// est.push(1.0, 1.0).unwrap();
    /// assert!(!est.is_empty());
    /// ```
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The variance estimate `mean(d²)` (with a [screen](Self::with_screen), the mean of the kept
    /// terms over their truncated variance), once one difference is in.
    ///
    /// ```
    /// use seqsmooth::stats::DifferenceNoise;
    /// let mut est = DifferenceNoise::new(1, None).unwrap();
    /// for (n, y) in [1.0, -1.0, 1.0].iter().enumerate() { est.push(n as f64, *y).unwrap(); }
    /// assert!((est.variance().unwrap() - 2.0).abs() < 1e-15); // (±2)²/2
    /// ```
    pub fn variance(&self) -> Option<f64> {
        let n = self.len();
        (n > 0).then(|| self.squares.sum() / n as f64 / self.kept)
    }

    /// `√variance`.
    ///
    /// ```
    /// use seqsmooth::stats::DifferenceNoise;
    /// let mut est = DifferenceNoise::new(1, None).unwrap();
    /// for (n, y) in [1.0, -1.0, 1.0].iter().enumerate() { est.push(n as f64, *y).unwrap(); }
    /// assert!((est.sigma().unwrap() - 2f64.sqrt()).abs() < 1e-15);
    /// ```
    pub fn sigma(&self) -> Option<f64> {
        self.variance().map(f64::sqrt)
    }
}

/// The variance of a unit Gaussian truncated to `|Z| ≤ a`: `1 − 2aφ(a)/(1 − 2Q(a))`. The noise
/// of the samples a gate of half-width `a σ_ε` passes has this variance (in units of `σ_ε²`).
pub(crate) fn truncated_variance(a: f64) -> f64 {
    if !a.is_finite() {
        return 1.0;
    }
    let phi = (-0.5 * a * a).exp() / (2.0 * std::f64::consts::PI).sqrt();
    let inside = 1.0 - two_sided_tail(a).unwrap_or(0.0);
    if inside <= 0.0 {
        return 1.0;
    }
    (1.0 - 2.0 * a * phi / inside).max(1e-3)
}
