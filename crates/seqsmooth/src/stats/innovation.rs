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
use crate::error::{Error, Param};

/// One step of the windowed innovation test.
///
/// ```
/// use seqsmooth::stats::InnovationChiSquared;
/// let mut test = InnovationChiSquared::new(3, 0.05).unwrap();
/// let o = test.push(2.0, 4.0).unwrap(); // k² = 2²/4 = 1
/// assert_eq!((o.normalised, o.statistic, o.dof), (1.0, 1.0, 1));
/// assert!(!o.misfit && o.threshold > 3.8);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ChiSquaredOutcome {
    /// The normalised squared innovation `k² = ν²/σ_ε²` just added.
    pub normalised: f64,
    /// The window sum `Σ k²` over the last `K` updates.
    pub statistic: f64,
    /// The window's degrees of freedom (its samples, for scalar innovations).
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
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub struct InnovationChiSquared {
    window: usize,
    alpha: f64,
    /// `thresholds[d-1]` = `(1-α)` quantile of `χ²_d`, `d = 1..=window`.
    thresholds: Vec<f64>,
    /// The window sum of `k²`.
    recent: SlidingSum,
    /// The degrees of freedom of each update in the window (1 for a scalar innovation, `p` for
    /// the NIS of `p` components), and their sum.
    dofs: std::collections::VecDeque<usize>,
    dof_total: usize,
}

// Field by field, `clone_from` too (the automatic filter's review keeps copies of it).
field_clone!(InnovationChiSquared {
    window,
    alpha,
    thresholds,
    recent,
    dofs,
    dof_total
});

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
                name: Param::ChiSquaredWindow,
                value: window.to_string(),
                reason: "must be at least 1 sample".into(),
            });
        }
        if !(alpha > 0.0 && alpha < 1.0) {
            return Err(Error::InvalidParameter {
                name: Param::ChiSquaredSignificance,
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
            dofs: std::collections::VecDeque::with_capacity(window),
            dof_total: 0,
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
                name: Param::InnovationVariance,
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
                name: Param::NormalisedInnovationSquared,
                value: k2.to_string(),
                reason: "must be a non-negative finite number".into(),
            });
        }
        self.push_dof(k2, 1)
    }

    /// Adds the normalised innovation squared of a `components`-vector innovation,
    /// `NIS = νᵀ V⁻¹ ν` (χ² with `components` degrees of freedom when the model holds, (14.8.5)
    /// with `T_n = V`): the window holds the last `K` updates and its sum is tested against
    /// `χ²` with their summed degrees of freedom. For the Kalman filter with a correct model
    /// the innovations are independent, so the rate of false alarms per update is `α`.
    ///
    /// ```
    /// use seqsmooth::stats::InnovationChiSquared;
    /// let mut test = InnovationChiSquared::new(2, 0.01).unwrap();
    /// test.push_nis(2.0, 3).unwrap();
    /// let o = test.push_nis(4.0, 3).unwrap();
    /// assert_eq!((o.statistic, o.dof), (6.0, 6));
    /// assert!((o.threshold - 16.812).abs() < 1e-3); // 99% point of χ²₆
    /// assert!(test.push_nis(1.0, 0).is_err());
    /// ```
    pub fn push_nis(&mut self, nis: f64, components: usize) -> Result<ChiSquaredOutcome, Error> {
        if components == 0 {
            return Err(Error::InvalidParameter {
                name: Param::InnovationComponents,
                value: "0".into(),
                reason: "an update has at least one component".into(),
            });
        }
        if !(nis.is_finite() && nis >= 0.0) {
            return Err(Error::InvalidParameter {
                name: Param::NormalisedInnovationSquared,
                value: nis.to_string(),
                reason: "must be a non-negative finite number".into(),
            });
        }
        self.push_dof(nis, components)
    }

    fn push_dof(&mut self, k2: f64, dof: usize) -> Result<ChiSquaredOutcome, Error> {
        if self.dofs.len() == self.window {
            self.dof_total -= self.dofs.pop_front().unwrap_or(0);
        }
        self.dofs.push_back(dof);
        self.dof_total += dof;
        self.recent.push(k2);
        let threshold = self.threshold()?;
        Ok(ChiSquaredOutcome {
            normalised: k2,
            statistic: self.recent.sum(),
            dof: self.dof_total,
            threshold,
            misfit: self.dof_total > 0 && self.recent.sum() > threshold,
        })
    }

    /// The `(1-α)` quantile of `χ²` with the window's degrees of freedom (from the table up to
    /// `K`, the scalar case).
    fn threshold(&self) -> Result<f64, Error> {
        match self.dof_total {
            0 => Ok(f64::INFINITY),
            d if d <= self.window => Ok(self.thresholds[d - 1]),
            d => chi_squared_quantile(d as f64, 1.0 - self.alpha),
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

    /// Updates currently in the window.
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
        self.dof_total > 0
            && self
                .threshold()
                .is_ok_and(|threshold| self.recent.sum() > threshold)
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
        self.dofs.clear();
        self.dof_total = 0;
    }
}
