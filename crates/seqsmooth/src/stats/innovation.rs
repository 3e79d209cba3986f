//! Detection of systematic errors from the innovations (Morrison §14.8).
//!
//! The innovation `ν_n = y_n − x*_{n,n−1}` (the sample minus the filter's 1-step prediction) is
//! zero-mean when the model fits (14.8.1)-(14.8.2), with variance
//! `σ_ε² = σ² + S*_{n,n−1}[0,0] = σ²(1 + v)`, `v` the prediction's position VRF (14.8.4). So
//! `k_n² = ν_n²/σ_ε²` is `χ²_1` (14.8.5), and for independent innovations the sum over a sliding
//! window of `K` samples is `χ²_K`. Isolated large `k²` are rare events; *repeated* ones — a large
//! window sum — mean bias (Morrison: "if it is exceeded repeatedly, then a bias error can be
//! assumed to have developed"). [`InnovationChiSquared`] flags when the window sum exceeds the
//! `(1-α)` quantile of `χ²_K` (with fewer than `K` samples so far, of `χ²_count`).
//!
//! Independence: the innovations of expanding-memory least squares are exactly independent
//! (they are the recursive residuals); those of a fading-memory filter are weakly correlated
//! (each shares the filter's memory), so the window sum has mean `K` but a slightly wider spread
//! than `χ²_K` and the realised false-alarm rate can exceed `α` somewhat (measured in
//! `tests/innovation.rs`).

use super::chi_squared::chi_squared_quantile;
use super::window::SlidingSum;
use crate::error::Error;

/// One step of the windowed innovation test.
///
/// ```
/// use seqsmooth::stats::InnovationChiSquared;
/// let mut test = InnovationChiSquared::new(3, 0.05).unwrap();
/// let o = test.push(2.0, 4.0).unwrap(); // k² = 2²/4 = 1
/// assert_eq!((o.normalised, o.statistic, o.dof), (1.0, 1.0, 1));
/// assert!(!o.misfit && o.threshold > 3.8);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChiSquaredOutcome {
    /// The normalised squared innovation `k² = ν²/σ_ε²` just added.
    pub normalised: f64,
    /// The window sum `Σ k²` over the last `dof` samples.
    pub statistic: f64,
    /// Samples in the window (the degrees of freedom).
    pub dof: usize,
    /// The `(1-α)` quantile of `χ²_dof`.
    pub threshold: f64,
    /// `statistic > threshold`: the model no longer fits.
    pub misfit: bool,
}

/// Sliding-window chi-squared test of the normalised innovations (Morrison (14.8.4)-(14.8.5)).
///
/// ```
/// use seqsmooth::stats::InnovationChiSquared;
/// let mut test = InnovationChiSquared::new(10, 0.01).unwrap();
/// // innovations of unit variance: well inside
/// for nu in [0.3, -1.1, 0.8, 0.1, -0.4, 1.5, -0.9, 0.2, 0.6, -1.0] {
///     assert!(!test.push(nu, 1.0).unwrap().misfit);
/// }
/// // a growing bias: the window sum crosses the 99% point of χ²_10 (23.21)
/// let mut fired = None;
/// for k in 1..=10 {
///     if test.push(0.8 * k as f64, 1.0).unwrap().misfit { fired.get_or_insert(k); }
/// }
/// assert_eq!(fired, Some(4));
/// ```
#[derive(Clone, Debug)]
pub struct InnovationChiSquared {
    window: usize,
    alpha: f64,
    /// `thresholds[d-1]` = `(1-α)` quantile of `χ²_d`, `d = 1..=window`.
    thresholds: Vec<f64>,
    /// The window sum of `k²`.
    recent: SlidingSum,
}

impl InnovationChiSquared {
    /// A test over a window of `window ≥ 1` samples at false-alarm rate `α ∈ (0,1)` per sample.
    ///
    /// ```
    /// use seqsmooth::stats::InnovationChiSquared;
    /// assert!(InnovationChiSquared::new(10, 0.01).is_ok());
    /// assert!(InnovationChiSquared::new(0, 0.01).is_err());
    /// assert!(InnovationChiSquared::new(10, 0.0).is_err());
    /// ```
    pub fn new(window: usize, alpha: f64) -> Result<Self, Error> {
        if window == 0 {
            return Err(Error::InvalidParameter {
                name: "chi-squared window",
                value: window.to_string(),
                reason: "must be at least 1 sample".into(),
            });
        }
        if !(alpha > 0.0 && alpha < 1.0) {
            return Err(Error::InvalidParameter {
                name: "chi-squared significance",
                value: alpha.to_string(),
                reason: "must lie strictly between 0 and 1".into(),
            });
        }
        let thresholds = (1..=window)
            .map(|d| chi_squared_quantile(d as f64, 1.0 - alpha))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            window,
            alpha,
            thresholds,
            recent: SlidingSum::new(Some(window)),
        })
    }

    /// The window length `K`.
    ///
    /// ```
    /// use seqsmooth::stats::InnovationChiSquared;
    /// assert_eq!(InnovationChiSquared::new(10, 0.01).unwrap().window(), 10);
    /// ```
    pub fn window(&self) -> usize {
        self.window
    }

    /// The false-alarm rate `α`.
    ///
    /// ```
    /// use seqsmooth::stats::InnovationChiSquared;
    /// assert_eq!(InnovationChiSquared::new(10, 0.01).unwrap().alpha(), 0.01);
    /// ```
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// Adds the innovation `ν` with its predicted variance `σ_ε² > 0` and tests the window.
    ///
    /// ```
    /// use seqsmooth::stats::InnovationChiSquared;
    /// let mut test = InnovationChiSquared::new(5, 0.01).unwrap();
    /// assert_eq!(test.push(3.0, 9.0).unwrap().normalised, 1.0);
    /// assert!(test.push(1.0, 0.0).is_err()); // the variance must be positive
    /// ```
    pub fn push(&mut self, innovation: f64, variance: f64) -> Result<ChiSquaredOutcome, Error> {
        if !innovation.is_finite() {
            return Err(Error::NonFinite {
                what: "value",
                value: innovation,
            });
        }
        if !(variance.is_finite() && variance > 0.0) {
            return Err(Error::InvalidParameter {
                name: "innovation variance",
                value: variance.to_string(),
                reason: "must be a positive finite number".into(),
            });
        }
        self.push_normalised(innovation * innovation / variance)
    }

    /// Adds an already normalised squared innovation `k² = ν²/σ_ε² ≥ 0`.
    ///
    /// ```
    /// use seqsmooth::stats::InnovationChiSquared;
    /// let mut test = InnovationChiSquared::new(2, 0.01).unwrap();
    /// test.push_normalised(1.0).unwrap();
    /// test.push_normalised(2.0).unwrap();
    /// assert_eq!(test.push_normalised(4.0).unwrap().statistic, 6.0); // the first one left
    /// assert!(test.push_normalised(-1.0).is_err());
    /// ```
    pub fn push_normalised(&mut self, k2: f64) -> Result<ChiSquaredOutcome, Error> {
        if !(k2.is_finite() && k2 >= 0.0) {
            return Err(Error::InvalidParameter {
                name: "normalised squared innovation",
                value: k2.to_string(),
                reason: "must be a non-negative finite number".into(),
            });
        }
        self.recent.push(k2);
        Ok(self.outcome(k2))
    }

    fn outcome(&self, k2: f64) -> ChiSquaredOutcome {
        let dof = self.recent.len();
        let threshold = if dof == 0 {
            f64::INFINITY
        } else {
            self.thresholds[dof - 1]
        };
        ChiSquaredOutcome {
            normalised: k2,
            statistic: self.recent.sum(),
            dof,
            threshold,
            misfit: dof > 0 && self.recent.sum() > threshold,
        }
    }

    /// The current window sum.
    ///
    /// ```
    /// use seqsmooth::stats::InnovationChiSquared;
    /// let mut test = InnovationChiSquared::new(4, 0.01).unwrap();
    /// test.push_normalised(0.5).unwrap();
    /// test.push_normalised(1.5).unwrap();
    /// assert_eq!(test.statistic(), 2.0);
    /// ```
    pub fn statistic(&self) -> f64 {
        self.recent.sum()
    }

    /// Samples currently in the window.
    ///
    /// ```
    /// use seqsmooth::stats::InnovationChiSquared;
    /// let mut test = InnovationChiSquared::new(2, 0.01).unwrap();
    /// for _ in 0..5 { test.push_normalised(1.0).unwrap(); }
    /// assert_eq!(test.len(), 2);
    /// ```
    pub fn len(&self) -> usize {
        self.recent.len()
    }

    /// True when no sample has been added since creation or the last [`reset`](Self::reset).
    ///
    /// ```
    /// use seqsmooth::stats::InnovationChiSquared;
    /// let mut test = InnovationChiSquared::new(2, 0.01).unwrap();
    /// assert!(test.is_empty());
    /// test.push_normalised(1.0).unwrap();
    /// assert!(!test.is_empty());
    /// ```
    pub fn is_empty(&self) -> bool {
        self.recent.is_empty()
    }

    /// True when the current window sum exceeds its threshold.
    ///
    /// ```
    /// use seqsmooth::stats::InnovationChiSquared;
    /// let mut test = InnovationChiSquared::new(3, 0.01).unwrap();
    /// test.push_normalised(1.0).unwrap();
    /// assert!(!test.is_misfit());
    /// test.push_normalised(30.0).unwrap(); // above the 99% point of χ²₂ (9.21)
    /// assert!(test.is_misfit());
    /// ```
    pub fn is_misfit(&self) -> bool {
        let dof = self.recent.len();
        dof > 0 && self.recent.sum() > self.thresholds[dof - 1]
    }

    /// Empties the window (e.g. after the model has been changed).
    ///
    /// ```
    /// use seqsmooth::stats::InnovationChiSquared;
    /// let mut test = InnovationChiSquared::new(3, 0.01).unwrap();
    /// test.push_normalised(30.0).unwrap();
    /// test.reset();
    /// assert!(test.is_empty() && !test.is_misfit() && test.statistic() == 0.0);
    /// ```
    pub fn reset(&mut self) {
        self.recent.clear();
    }
}
