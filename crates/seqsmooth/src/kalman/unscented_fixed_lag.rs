//! The unscented fixed-lag smoother (Särkkä 2008, "Unscented Rauch–Tung–Striebel smoother",
//! IEEE TAC 53(3), (10)-(11) with additive noise, over a sliding window): the forward
//! [`UnscentedKalmanFilter`] a measurement at a time, and each measurement's estimate from the
//! `L` measurements after it, `x_{k|k+L}` and `S_{k|k+L}`, given as soon as measurement `k + L`
//! is in — the unscented RTS backward recursion of [`super::unscented_smoother`],
//!
//! `G_j = D_{j+1} S̄_{j+1}⁻¹`,
//! `x_{j|N} = x_{j|j} + G_j (x_{j+1|N} − x̄_{j+1})`,
//! `S_{j|N} = S_{j|j} + G_j (S_{j+1|N} − S̄_{j+1}) G_jᵀ`, `j = N−1, …, k`, `N = k + L`,
//!
//! from the filter's `x_{N|N}`, run over the window of the last `L + 1` forward steps (their
//! filtered estimates, predictions `x̄`, `S̄` and cross-covariances `D`) at each push: `L`
//! gains a measurement, memory `L + 1` steps whatever the input's length. The recursion is the
//! whole-interval smoother's own code, so the estimate is that smoother's over measurements
//! `0..=k+L` read at `k`, bit for bit: `L = 0` gives the filter, `L` at least the number of
//! measurements the whole-interval smoother. The lag counts measurements (not time).

use super::unscented::UnscentedKalmanFilter;
use super::unscented_smoother::{backward, forward, Forward, UnscentedSmoothed};
use crate::error::Error;
use crate::model::dynamics::Dynamics;
use crate::model::measurement::Measurement;
use crate::model::observation::Observation;
use std::collections::VecDeque;

/// The unscented fixed-lag smoother: [`Self::push`] gives the estimate of the measurement
/// `lag` before, from every measurement up to the one pushed; [`Self::finish`] the rest.
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::kalman::unscented_fixed_lag::UnscentedFixedLagSmoother;
/// use seqsmooth::kalman::UnscentedKalmanFilter;
/// use seqsmooth::model::dynamics::PolynomialDynamics;
/// use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
/// use seqsmooth::model::observation::LinearObservation;
/// // A constant with a vague prior, lag 1: each estimate is the mean of the samples so far
/// // and the next one.
/// let f = UnscentedKalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
///     DVector::zeros(1), DMatrix::from_element(1, 1, 1e12), 0.0).unwrap();
/// let mut s = UnscentedFixedLagSmoother::new(f, 1);
/// let mut out = Vec::new();
/// for (k, y) in [1.0, 3.0, 8.0].into_iter().enumerate() {
///     let m = Measurement { time: k as f64, values: vec![Some(y)], noise: NoiseCovariance::Identity };
///     out.extend(s.push(&m).unwrap());
/// }
/// assert_eq!(out.len(), 2); // the first two, each with one measurement after it
/// assert!((out[0].state[0] - 2.0).abs() < 1e-9 && (out[1].state[0] - 4.0).abs() < 1e-9);
/// out.extend(s.finish().unwrap()); // the last: the filter's
/// assert!((out[2].state[0] - 4.0).abs() < 1e-9);
/// ```
#[derive(Clone, Debug)]
pub struct UnscentedFixedLagSmoother<D: Dynamics, O: Observation> {
    filter: UnscentedKalmanFilter<D, O>,
    lag: usize,
    /// The forward steps not yet given, at most `lag + 1` (after a push that gives one, `lag`).
    steps: VecDeque<Forward>,
    /// The measurements pushed.
    pushed: usize,
}

impl<D: Dynamics + Clone, O: Observation + Clone> UnscentedFixedLagSmoother<D, O> {
    /// A smoother of lag `lag` measurements whose forward pass starts as `filter`.
    pub fn new(filter: UnscentedKalmanFilter<D, O>, lag: usize) -> Self {
        Self {
            filter,
            lag,
            steps: VecDeque::with_capacity(lag.saturating_add(1).min(1 << 12)),
            pushed: 0,
        }
    }

    /// The lag, in measurements.
    pub fn lag(&self) -> usize {
        self.lag
    }

    /// The forward filter so far.
    pub fn filter(&self) -> &UnscentedKalmanFilter<D, O> {
        &self.filter
    }

    /// The measurements pushed so far.
    pub fn pushed(&self) -> usize {
        self.pushed
    }

    /// The measurements held (pushed, not yet given): at most `lag`.
    pub fn held(&self) -> usize {
        self.steps.len()
    }

    /// The forward pass over `m` (not before the previous measurement), and the smoothed
    /// estimate of the measurement `lag` before it, if there is one: the backward recursion
    /// over the window from `m`'s filtered estimate. An error of the forward pass is the
    /// filter's; one of the backward pass is [`Error::InBatch`] naming the measurement
    /// (counted from the first pushed). On an error the smoother is unchanged.
    pub fn push(&mut self, m: &Measurement) -> Result<Option<UnscentedSmoothed>, Error> {
        let before = self.filter.clone();
        let step = forward(&mut self.filter, m, self.steps.back())?;
        self.steps.push_back(step);
        if self.steps.len() <= self.lag {
            self.pushed += 1;
            return Ok(None);
        }
        let first = self.pushed - self.lag;
        match backward(self.steps.make_contiguous(), first, |k| k == 0) {
            Ok(mut given) => {
                self.pushed += 1;
                self.steps.pop_front();
                Ok(given.pop())
            }
            Err(e) => {
                self.steps.pop_back();
                self.filter = before;
                Err(e)
            }
        }
    }

    /// The measurements held, each smoothed by every measurement pushed (the backward
    /// recursion from the last), in order. An error names its measurement ([`Error::InBatch`],
    /// counted from the first pushed).
    pub fn finish(mut self) -> Result<Vec<UnscentedSmoothed>, Error> {
        let first = self.pushed - self.steps.len();
        backward(self.steps.make_contiguous(), first, |_| true)
    }
}
