//! The unscented Rauch–Tung–Striebel smoother (Särkkä 2008, "Unscented Rauch–Tung–Striebel
//! smoother", IEEE TAC 53(3), Algorithm / (10)-(11) with additive noise): after a forward pass
//! of the [`UnscentedKalmanFilter`] over all the measurements, a backward pass gives at every
//! measurement time the estimate from all of them,
//!
//! `G_k = D_{k+1} S̄_{k+1}⁻¹`,
//! `x_{k|N} = x_{k|k} + G_k (x_{k+1|N} − x̄_{k+1})`,
//! `S_{k|N} = S_{k|k} + G_k (S_{k+1|N} − S̄_{k+1}) G_kᵀ`,
//!
//! where `x̄_{k+1}`, `S̄_{k+1}` are the forward pass's prediction to `t_{k+1}` and
//! `D_{k+1} = Σ W^(c) (𝒳_i − x_{k|k})(𝒴_i − x̄_{k+1})ᵀ` its cross-covariance (Särkkä (10)),
//! all kept from the forward pass ([`super::unscented::Prediction`]): the measurements are not
//! read again and the dynamics not run again. `S̄_{k+1}⁻¹` is applied by its Cholesky factor.
//! For a linear model it is the Kalman filter's RTS smoother ([`super::smoother`]).
//!
//! Memory: the forward pass's estimates and predictions of every measurement are kept until
//! the backward pass, `O(N n²)` for `N` measurements — the result needs all of them.

use super::unscented::{Prediction, UnscentedKalmanFilter};
use crate::error::{Error, Param};
use crate::model::dynamics::Dynamics;
use crate::model::measurement::Measurement;
use crate::model::observation::Observation;
use nalgebra::{Cholesky, DMatrix, DVector};

/// The smoothed estimate at one measurement's time, with the forward pass's numbers.
#[derive(Clone, Debug, PartialEq)]
pub struct UnscentedSmoothed {
    /// The measurement's time.
    pub time: f64,
    /// `x_{k|N}`.
    pub state: DVector<f64>,
    /// `S_{k|N}`.
    pub covariance: DMatrix<f64>,
    /// The forward filter's `x_{k|k}`.
    pub filtered_state: DVector<f64>,
    /// The forward filter's `S_{k|k}`.
    pub filtered_covariance: DMatrix<f64>,
    /// The forward filter's prediction `x̄_k` to this time.
    pub predicted_state: DVector<f64>,
    /// Its covariance `S̄_k`.
    pub predicted_covariance: DMatrix<f64>,
    /// The smoother gain `G_k` (`None` at the last measurement).
    pub gain: Option<DMatrix<f64>>,
    /// The forward update's normalised innovation squared (`None` where every component was
    /// missing).
    pub nis: Option<f64>,
}

/// Runs `filter` over `measurements` (in time order) and smooths back: one
/// [`UnscentedSmoothed`] per measurement. An error names its measurement
/// ([`Error::InBatch`]).
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::kalman::unscented_smoother::smooth_unscented;
/// use seqsmooth::kalman::UnscentedKalmanFilter;
/// use seqsmooth::model::dynamics::PolynomialDynamics;
/// use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
/// use seqsmooth::model::observation::LinearObservation;
/// // A constant with a vague prior: every smoothed value is the mean of all the samples.
/// let f = UnscentedKalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
///     DVector::zeros(1), DMatrix::from_element(1, 1, 1e12), 0.0).unwrap();
/// let rows: Vec<Measurement> = [1.0, 2.0, 6.0].iter().enumerate()
///     .map(|(k, &y)| Measurement { time: k as f64, values: vec![Some(y)], noise: NoiseCovariance::Identity })
///     .collect();
/// let s = smooth_unscented(f, &rows).unwrap();
/// assert!((s[0].state[0] - 3.0).abs() < 1e-9 && (s[0].filtered_state[0] - 1.0).abs() < 1e-9);
/// ```
pub fn smooth_unscented<D: Dynamics, O: Observation>(
    filter: UnscentedKalmanFilter<D, O>,
    measurements: &[Measurement],
) -> Result<Vec<UnscentedSmoothed>, Error> {
    let mut smoother = UnscentedSmoother::new(filter);
    for (index, m) in measurements.iter().enumerate() {
        smoother.push(m).map_err(|source| Error::InBatch {
            index,
            source: Box::new(source),
        })?;
    }
    smoother.finish()
}

/// One forward step kept for the backward pass.
#[derive(Clone, Debug)]
pub(super) struct Forward {
    pub(super) prediction: Prediction,
    pub(super) state: DVector<f64>,
    pub(super) covariance: DMatrix<f64>,
    pub(super) nis: Option<f64>,
}

/// The forward pass of `filter` over `m`, not before `previous` (the last step's time): the
/// prediction and the update, kept for the backward pass. On an error the filter is unchanged.
pub(super) fn forward<D: Dynamics, O: Observation>(
    filter: &mut UnscentedKalmanFilter<D, O>,
    m: &Measurement,
    previous: Option<&Forward>,
) -> Result<Forward, Error> {
    if let Some(last) = previous {
        if m.time < last.prediction.time {
            return Err(Error::InvalidParameter {
                name: Param::SampleTime,
                value: m.time.to_string(),
                reason: format!(
                    "is before the previous measurement's time {}",
                    last.prediction.time
                ),
            });
        }
    }
    let (prediction, innovation) = filter.step(m)?;
    Ok(Forward {
        prediction,
        state: filter.state().clone(),
        covariance: filter.covariance().clone(),
        nis: innovation.map(|i| i.nis),
    })
}

/// The unscented RTS smoother a measurement at a time: the forward pass as the measurements
/// come ([`Self::push`]), the backward pass at the end ([`Self::finish`]).
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::kalman::unscented_smoother::UnscentedSmoother;
/// use seqsmooth::kalman::UnscentedKalmanFilter;
/// use seqsmooth::model::dynamics::PolynomialDynamics;
/// use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
/// use seqsmooth::model::observation::LinearObservation;
/// let f = UnscentedKalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
///     DVector::zeros(1), DMatrix::from_element(1, 1, 1e6), 0.0).unwrap();
/// let mut s = UnscentedSmoother::new(f);
/// for (k, y) in [1.0, 3.0].into_iter().enumerate() {
///     s.push(&Measurement { time: k as f64, values: vec![Some(y)], noise: NoiseCovariance::Identity }).unwrap();
/// }
/// let out = s.finish().unwrap();
/// assert!((out[0].state[0] - 2.0).abs() < 1e-5); // the mean of both
/// ```
#[derive(Clone, Debug)]
pub struct UnscentedSmoother<D: Dynamics, O: Observation> {
    filter: UnscentedKalmanFilter<D, O>,
    steps: Vec<Forward>,
}

impl<D: Dynamics, O: Observation> UnscentedSmoother<D, O> {
    /// A smoother whose forward pass starts as `filter`.
    pub fn new(filter: UnscentedKalmanFilter<D, O>) -> Self {
        Self {
            filter,
            steps: Vec::new(),
        }
    }

    /// The forward filter so far.
    pub fn filter(&self) -> &UnscentedKalmanFilter<D, O> {
        &self.filter
    }

    /// The forward pass over `m` (not before the previous measurement): the prediction and
    /// the update; the update's NIS (`None` where every component is missing). On an error
    /// the smoother is unchanged.
    pub fn push(&mut self, m: &Measurement) -> Result<Option<f64>, Error> {
        let step = forward(&mut self.filter, m, self.steps.last())?;
        let nis = step.nis;
        self.steps.push(step);
        Ok(nis)
    }

    /// The backward pass: every measurement's smoothed estimate, in order. An error names its
    /// measurement ([`Error::InBatch`], counted from the first pushed): a predicted covariance
    /// that is not positive definite, or a smoothed number that is not finite.
    pub fn finish(self) -> Result<Vec<UnscentedSmoothed>, Error> {
        backward(&self.steps, 0, |_| true)
    }
}

/// The backward pass over `steps` (consecutive forward steps, the first measurement `first`
/// counted from the first pushed), from the last one's filtered estimate: the smoothed
/// estimates of the steps at the positions `keep` accepts, in order. An error names its
/// measurement ([`Error::InBatch`]): a predicted covariance that is not positive definite, or
/// a smoothed number that is not finite.
pub(super) fn backward(
    steps: &[Forward],
    first: usize,
    keep: impl Fn(usize) -> bool,
) -> Result<Vec<UnscentedSmoothed>, Error> {
    let mut out: Vec<UnscentedSmoothed> = Vec::new();
    let mut next: Option<(&Forward, DVector<f64>, DMatrix<f64>)> = None;
    for (k, step) in steps.iter().enumerate().rev() {
        let index = first + k;
        let (state, covariance, gain) = match &next {
            None => (step.state.clone(), step.covariance.clone(), None),
            Some((after, smoothed_x, smoothed_s)) => {
                let p = &after.prediction;
                let Some(factor) = Cholesky::new(p.covariance.clone()) else {
                    return Err(Error::InBatch {
                        index: index + 1,
                        source: Box::new(Error::InvalidParameter {
                            name: Param::PredictedCovariance,
                            value: format!("at t = {}", p.time),
                            reason: "is not positive definite: no smoother gain".into(),
                        }),
                    });
                };
                // G = D S̄⁻¹ = (S̄⁻¹ Dᵀ)ᵀ.
                let gain = factor.solve(&p.cross.transpose()).transpose();
                let x = &step.state + &gain * (smoothed_x - &p.state);
                let s = &step.covariance + &gain * (smoothed_s - &p.covariance) * gain.transpose();
                let s = (&s + s.transpose()) * 0.5;
                (x, s, Some(gain))
            }
        };
        if let Some(&value) = state
            .iter()
            .chain(covariance.iter())
            .find(|v| !v.is_finite())
        {
            return Err(Error::InBatch {
                index,
                source: Box::new(Error::NonFinite {
                    what: "smoothed state or covariance entry",
                    value,
                }),
            });
        }
        if keep(k) {
            out.push(UnscentedSmoothed {
                time: step.prediction.time,
                state: state.clone(),
                covariance: covariance.clone(),
                filtered_state: step.state.clone(),
                filtered_covariance: step.covariance.clone(),
                predicted_state: step.prediction.state.clone(),
                predicted_covariance: step.prediction.covariance.clone(),
                gain,
                nis: step.nis,
            });
        }
        next = Some((step, state, covariance));
    }
    out.reverse();
    Ok(out)
}
