//! Fixed-interval smoothing (Rauch, Tung and Striebel 1965; beyond Morrison's book): after a
//! forward pass of the [`KalmanFilter`] (plain or extended) over all the measurements, a
//! backward pass gives at every measurement time the estimate from all of them,
//!
//! `C_k = S_{k|k} Φ(t_{k+1}, t_k)ᵀ S_{k+1|k}⁻¹`,
//! `X_{k|N} = X_{k|k} + C_k (X_{k+1|N} − X_{k+1|k})`,
//! `S_{k|N} = S_{k|k} + C_k (S_{k+1|N} − S_{k+1|k}) C_kᵀ`,
//!
//! on any times (`Φ` and `Q` of the actual step; for the extended filter `Φ` is the
//! linearisation along the forward trajectory). `S_{k+1|k}⁻¹` is applied by its square-root-free
//! Cholesky factors `L D Lᵀ`. For linear models without driving noise the result at every time is the batch
//! minimum-variance estimate from the prior and all the measurements (tested against
//! [`crate::estimate::gauss_newton`]).

use super::backward::{map_into, smooth_fixed, smooth_into};
use super::filter::KalmanFilter;
use super::fixed_lag::{
    not_finite, not_positive_definite, step, time_before, FixedLagSmoother, Map, Row,
};
use crate::error::Error;
use crate::linalg::dense::all_finite;
use crate::model::dynamics::Dynamics;
use crate::model::measurement::Measurement;
use crate::model::observation::Observation;
use nalgebra::{DMatrix, DVector};

/// The smoothed estimate at one measurement's time.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Smoothed {
    /// The measurement's time.
    pub time: f64,
    /// `X_{k|N}`.
    pub state: DVector<f64>,
    /// `S_{k|N}`.
    pub covariance: DMatrix<f64>,
    /// The forward filter's `X_{k|k}`.
    pub filtered_state: DVector<f64>,
    /// The forward filter's `S_{k|k}`.
    pub filtered_covariance: DMatrix<f64>,
    /// The forward update's normalised innovation squared (`None` where every component was
    /// missing).
    pub nis: Option<f64>,
}

/// Runs `filter` over `measurements` (in time order) and smooths back: one [`Smoothed`] per
/// measurement.
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::model::measurement::NoiseCovariance;
/// use seqsmooth::model::measurement::Measurement;
/// use seqsmooth::kalman::{smoother, KalmanFilter};
/// use seqsmooth::model::dynamics::PolynomialDynamics;
/// use seqsmooth::model::observation::LinearObservation;
/// // A constant with a vague prior: every smoothed value is the mean of all the samples.
/// let f = KalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
///     DVector::zeros(1), DMatrix::from_element(1, 1, 1e12), 0.0).unwrap();
/// let rows: Vec<Measurement> = [1.0, 2.0, 6.0].iter().enumerate()
///     .map(|(k, &y)| Measurement { time: k as f64, values: vec![Some(y)], noise: NoiseCovariance::Identity })
///     .collect();
/// let s = smoother::smooth(f, &rows).unwrap();
/// assert!((s[0].state[0] - 3.0).abs() < 1e-9 && (s[0].filtered_state[0] - 1.0).abs() < 1e-9);
/// ```
pub fn smooth<D: Dynamics + Clone, O: Observation + Clone>(
    filter: KalmanFilter<D, O>,
    measurements: &[Measurement],
) -> Result<Vec<Smoothed>, Error> {
    Smoother::new(filter).smooth(measurements)
}

/// Every measurement's smoothed and filtered estimates ([`smooth_flat`]) in flat buffers:
/// measurement `k`'s state is `states[k n..(k + 1) n]` and its covariance
/// `covariances[k n²..(k + 1) n²]` (column-major; symmetric, so row-major too), `n` the
/// [`Self::dimension`]; likewise the filtered ones.
#[derive(Clone, Debug, PartialEq)]
pub struct SmoothedRun {
    /// The state dimension `n`.
    pub dimension: usize,
    /// The measurements' times.
    pub times: Vec<f64>,
    /// `X_{k|N}`, `n` a measurement.
    pub states: Vec<f64>,
    /// `S_{k|N}`, `n²` a measurement.
    pub covariances: Vec<f64>,
    /// The forward filter's `X_{k|k}`.
    pub filtered_states: Vec<f64>,
    /// The forward filter's `S_{k|k}`.
    pub filtered_covariances: Vec<f64>,
    /// The forward update's NIS (`None` where every component was missing).
    pub nis: Vec<Option<f64>>,
    /// The smoother gains `C_k = S_{k|k} Φᵀ S_{k+1|k}⁻¹`, `n²` a measurement (column-major;
    /// the last measurement's zero): the backward step's own.
    pub gains: Vec<f64>,
    /// The forward pass's predictions, kept for the backward pass (and their buffers for the
    /// next run, [`smooth_flat_into`]): `Φ` at each measurement, `X_{k+1|k}` and `S_{k+1|k}`
    /// at `k`.
    phi: Vec<f64>,
    x_pred: Vec<f64>,
    s_pred: Vec<f64>,
}

impl SmoothedRun {
    /// Empty buffers, for [`smooth_flat_into`] to fill.
    ///
    /// ```
    /// use seqsmooth::kalman::smoother::SmoothedRun;
    /// assert!(SmoothedRun::new().times.is_empty());
    /// ```
    pub fn new() -> Self {
        Self {
            dimension: 0,
            times: Vec::new(),
            states: Vec::new(),
            covariances: Vec::new(),
            filtered_states: Vec::new(),
            filtered_covariances: Vec::new(),
            nis: Vec::new(),
            gains: Vec::new(),
            phi: Vec::new(),
            x_pred: Vec::new(),
            s_pred: Vec::new(),
        }
    }
}

impl SmoothedRun {
    /// The predicted covariance `S_{k+1|k}` out of measurement `k` (column-major, `n²`), the
    /// one the gain `C_k` weighs; `None` for the last measurement (nothing follows it).
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
    /// use seqsmooth::kalman::{smoother, KalmanFilter};
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// // A constant (Φ = 1, no driving noise) seen twice with unit variance from a vague prior.
    /// let f = KalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
    ///     DVector::zeros(1), DMatrix::from_element(1, 1, 1e12), 0.0).unwrap();
    /// let rows: Vec<Measurement> = [1.0, 2.0].iter().enumerate()
    ///     .map(|(k, &y)| Measurement { time: k as f64, values: vec![Some(y)], noise: NoiseCovariance::Identity })
    ///     .collect();
    /// let run = smoother::smooth_flat(f, &rows).unwrap();
    /// let p = run.predicted_covariance(0).unwrap()[0];
    /// assert!((p - 1.0).abs() < 1e-9); // S_{1|0} = S_{0|0} = 1 (no driving noise)
    /// assert!((run.gains[0] - 1.0).abs() < 1e-9); // C_0 = S_{0|0} S_{1|0}⁻¹ = 1
    /// assert_eq!(run.gains[1], 0.0); // the last
    /// assert!(run.predicted_covariance(1).is_none());
    /// ```
    pub fn predicted_covariance(&self, k: usize) -> Option<&[f64]> {
        let nn = self.dimension * self.dimension;
        self.s_pred.get(k * nn..(k + 1) * nn)
    }
}

impl Default for SmoothedRun {
    fn default() -> Self {
        Self::new()
    }
}

/// [`smooth`]'s numbers in flat buffers, with nothing allocated per measurement: the forward
/// pass runs the filter and keeps each step's prediction `Φ`, `X_{k+1|k}`, `S_{k+1|k}`; the
/// backward pass is the textbook recursion of the module's doc from the last estimate
/// (`backward::smooth_into`, `S_{k+1|k}⁻¹` by its `L D Lᵀ` factors), the
/// measurement-at-a-time [`Smoother`]'s numbers (its maps) to rounding, at about three quarters
/// of its arithmetic. Errors as [`Smoother::smooth`]'s (the first in the order that smoother
/// meets them).
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
/// use seqsmooth::kalman::{smoother, KalmanFilter};
/// use seqsmooth::model::dynamics::PolynomialDynamics;
/// use seqsmooth::model::observation::LinearObservation;
/// let f = KalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
///     DVector::zeros(1), DMatrix::from_element(1, 1, 1e12), 0.0).unwrap();
/// let rows: Vec<Measurement> = [1.0, 2.0, 6.0].iter().enumerate()
///     .map(|(k, &y)| Measurement { time: k as f64, values: vec![Some(y)], noise: NoiseCovariance::Identity })
///     .collect();
/// let run = smoother::smooth_flat(f, &rows).unwrap();
/// assert!(run.states.iter().all(|x| (x - 3.0).abs() < 1e-9)); // the mean, everywhere
/// ```
pub fn smooth_flat<D: Dynamics + Clone, O: Observation + Clone>(
    filter: KalmanFilter<D, O>,
    measurements: &[Measurement],
) -> Result<SmoothedRun, Error> {
    let mut run = SmoothedRun::new();
    smooth_flat_into(filter, measurements, &mut run)?;
    Ok(run)
}

/// [`smooth_flat`] into `run`, its buffers reused (cleared first; their capacity kept, so a
/// run no longer than the last allocates nothing): the smoother of many series in turn.
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
/// use seqsmooth::kalman::smoother::{smooth_flat, smooth_flat_into, SmoothedRun};
/// use seqsmooth::kalman::KalmanFilter;
/// use seqsmooth::model::dynamics::PolynomialDynamics;
/// use seqsmooth::model::observation::LinearObservation;
/// let f = KalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
///     DVector::zeros(1), DMatrix::from_element(1, 1, 1e12), 0.0).unwrap();
/// let rows: Vec<Measurement> = [1.0, 2.0, 6.0].iter().enumerate()
///     .map(|(k, &y)| Measurement { time: k as f64, values: vec![Some(y)], noise: NoiseCovariance::Identity })
///     .collect();
/// let mut run = SmoothedRun::new();
/// for _ in 0..2 {
///     smooth_flat_into(f.clone(), &rows, &mut run).unwrap();
/// }
/// assert_eq!(run, smooth_flat(f, &rows).unwrap());
/// ```
pub fn smooth_flat_into<D: Dynamics + Clone, O: Observation + Clone>(
    mut filter: KalmanFilter<D, O>,
    measurements: &[Measurement],
    run: &mut SmoothedRun,
) -> Result<(), Error> {
    let (n, count) = (filter.state().len(), measurements.len());
    let nn = n * n;
    run.dimension = n;
    // The smoothed states, covariances and gains are written whole by the backward pass (their
    // lengths set there, without filling them first), so they are not cleared here.
    for v in [
        &mut run.times,
        &mut run.filtered_states,
        &mut run.filtered_covariances,
        &mut run.phi,
        &mut run.x_pred,
        &mut run.s_pred,
    ] {
        v.clear();
    }
    run.nis.clear();
    // The prediction into measurement k + 1, at k: Φ, X_{k+1|k}, S_{k+1|k}.
    let steps = count.saturating_sub(1);
    let (mut phi, mut x_pred, mut s_pred) = (
        std::mem::take(&mut run.phi),
        std::mem::take(&mut run.x_pred),
        std::mem::take(&mut run.s_pred),
    );
    phi.reserve(count * nn);
    x_pred.reserve(steps * n);
    s_pred.reserve(steps * nn);
    run.filtered_states.reserve(count * n);
    run.filtered_covariances.reserve(count * nn);
    let kept = (&mut phi, &mut x_pred, &mut s_pred);
    // The common sizes at compile time (the copies then inline, the slicing checked once):
    // the same operations in the same order, so the same numbers.
    let result = match n {
        1 => passes::<_, _, 1>(&mut filter, measurements, run, kept),
        2 => passes::<_, _, 2>(&mut filter, measurements, run, kept),
        3 => passes::<_, _, 3>(&mut filter, measurements, run, kept),
        4 => passes::<_, _, 4>(&mut filter, measurements, run, kept),
        6 => passes::<_, _, 6>(&mut filter, measurements, run, kept),
        _ => passes::<_, _, 0>(&mut filter, measurements, run, kept),
    };
    (run.phi, run.x_pred, run.s_pred) = (phi, x_pred, s_pred);
    if result.is_err() {
        for v in [&mut run.states, &mut run.covariances, &mut run.gains] {
            v.clear();
        }
    }
    result
}

/// [`smooth_flat_into`]'s forward and backward passes into `run`, the predictions kept in
/// `phi`, `x_pred`, `s_pred`; `N` the state's dimension when it is known at compile time
/// (it is then `filter`'s), else 0.
fn passes<D: Dynamics + Clone, O: Observation + Clone, const N: usize>(
    filter: &mut KalmanFilter<D, O>,
    measurements: &[Measurement],
    run: &mut SmoothedRun,
    (phi, x_pred, s_pred): (&mut Vec<f64>, &mut Vec<f64>, &mut Vec<f64>),
) -> Result<(), Error> {
    let (n, count) = (filter.state().len(), measurements.len());
    debug_assert!(N == 0 || N == n);
    let n = if N == 0 { n } else { N };
    let nn = n * n;
    for (index, m) in measurements.iter().enumerate() {
        let mut forward = |filter: &mut KalmanFilter<D, O>| {
            if let Some(&previous) = run.times.last() {
                if m.time.is_finite() && m.time < previous {
                    return Err(time_before(m.time, previous));
                }
            }
            // One update (its prediction and correction), the prediction then read from
            // the filter's work buffers: the same numbers as predicting and updating apart.
            let stepped = m.time != filter.time();
            let stats = match filter.update_stats_keeping_prediction(m) {
                Ok(stats) => stats,
                // [`Smoother`] predicts before it reads the measurement: a row whose
                // prediction fails too gives that error, as there (the filter is unchanged).
                Err(e) => {
                    return Err(filter
                        .clone()
                        .predict_with_transition(m.time)
                        .err()
                        .unwrap_or(e))
                }
            };
            if stepped {
                phi.extend_from_slice(&filter.last_transition().as_slice()[..nn]);
            } else {
                phi.extend((0..nn).map(|e| f64::from(u8::from(e % (n + 1) == 0))));
            }
            if index > 0 {
                let (x, s) = match stats {
                    Some(_) => filter.last_prediction(),
                    None => (filter.state(), filter.covariance()),
                };
                x_pred.extend_from_slice(&x.as_slice()[..n]);
                s_pred.extend_from_slice(&s.as_slice()[..nn]);
            }
            Ok(stats.map(|s| s.nis))
        };
        let nis = match forward(filter) {
            Ok(nis) => nis,
            Err(e) => {
                let run = (run.filtered(), &phi[..], &x_pred[..], &s_pred[..]);
                return Err(first_map_error(run, index).unwrap_or(in_batch(index, e)));
            }
        };
        run.times.push(m.time);
        run.filtered_states
            .extend_from_slice(&filter.state().as_slice()[..n]);
        run.filtered_covariances
            .extend_from_slice(&filter.covariance().as_slice()[..nn]);
        run.nis.push(nis);
    }
    // Every entry below is written (the last estimate copied, the last gain zero, the others
    // by the backward steps): the lengths are set without filling the buffers first.
    run.states.resize(count * n, 0.0);
    run.covariances.resize(count * nn, 0.0);
    run.gains.resize(count * nn, 0.0);
    if count == 0 {
        return Ok(());
    }
    let last = count - 1;
    run.gains[last * nn..].fill(0.0);
    run.states[last * n..].copy_from_slice(&run.filtered_states[last * n..]);
    run.covariances[last * nn..].copy_from_slice(&run.filtered_covariances[last * nn..]);
    let kept = (&phi[..], &x_pred[..], &s_pred[..]);
    if N != 0 {
        return backward_fixed::<N>(run, kept);
    }
    for k in (0..last).rev() {
        let prediction = (
            &phi[(k + 1) * nn..(k + 2) * nn],
            &x_pred[k * n..(k + 1) * n],
            &s_pred[k * nn..(k + 1) * nn],
        );
        let filtered = (
            &run.filtered_states[k * n..(k + 1) * n],
            &run.filtered_covariances[k * nn..(k + 1) * nn],
        );
        let (states, later) = run.states.split_at_mut((k + 1) * n);
        let (covariances, later_s) = run.covariances.split_at_mut((k + 1) * nn);
        let (x, s) = (&mut states[k * n..], &mut covariances[k * nn..]);
        let next = (&later[..n], &later_s[..nn]);
        let c = &mut run.gains[k * nn..(k + 1) * nn];
        let made = smooth_into(n, filtered, prediction, next, (&mut *x, &mut *s, c));
        if !(made && all_finite(x) && all_finite(s)) {
            let filtered = Filtered {
                dimension: n,
                states: &run.filtered_states,
                covariances: &run.filtered_covariances,
            };
            return Err(step_error(filtered, kept, k, (x, s)));
        }
    }
    Ok(())
}

/// [`passes`]'s backward steps with the state's dimension `N` known at compile time
/// (`backward::smooth_fixed`, inlined: the same operations as [`smooth_into`], so the same
/// numbers), walking the flat buffers by chunks from the last estimate (written) back to the
/// first, each step reading the one after it as the previous step left it.
#[inline(always)]
fn backward_fixed<const N: usize>(
    run: &mut SmoothedRun,
    (phi, x_pred, s_pred): (&[f64], &[f64], &[f64]),
) -> Result<(), Error> {
    let nn = N * N;
    let filtered = Filtered {
        dimension: N,
        states: &run.filtered_states,
        covariances: &run.filtered_covariances,
    };
    let mut states = run.states.chunks_exact_mut(N).rev();
    let mut covariances = run.covariances.chunks_exact_mut(nn).rev();
    let (Some(x_last), Some(s_last)) = (states.next(), covariances.next()) else {
        return Ok(());
    };
    let (mut x_next, mut s_next): (&[f64], &[f64]) = (x_last, s_last);
    // One iterator a buffer, each walked from its end (a zip of them is not inlined), over
    // the steps out of measurements 0..last: as many as the predictions kept.
    let (steps, steps_nn) = (x_pred.len(), s_pred.len());
    let mut gains = run.gains[..steps_nn].chunks_exact_mut(nn);
    let mut xfs = filtered.states[..steps].chunks_exact(N);
    let mut sfs = filtered.covariances[..steps_nn].chunks_exact(nn);
    let mut phis = phi[nn..].chunks_exact(nn);
    let (mut xps, mut sps) = (x_pred.chunks_exact(N), s_pred.chunks_exact(nn));
    let mut k = steps / N;
    while let (Some(x), Some(s), Some(c), Some(xf), Some(sf), Some(f), Some(xp), Some(sp)) = (
        states.next(),
        covariances.next(),
        gains.next_back(),
        xfs.next_back(),
        sfs.next_back(),
        phis.next_back(),
        xps.next_back(),
        sps.next_back(),
    ) {
        k -= 1;
        let estimates = ((xf, sf), (x_next, s_next));
        let made = smooth_fixed::<N>(estimates, (f, xp, sp), (&mut *x, &mut *s, c));
        if !(made && finite(x, s)) {
            return Err(step_error(filtered, (phi, x_pred, s_pred), k, (x, s)));
        }
        (x_next, s_next) = (x, s);
    }
    Ok(())
}

/// Whether every entry of `x` and `s` is finite: so when their sum is (an infinity or NaN
/// among them makes the sum one); a sum that overflows is checked entry by entry.
#[inline(always)]
fn finite(x: &[f64], s: &[f64]) -> bool {
    let sum = x.iter().chain(s).sum::<f64>();
    sum.is_finite() || (all_finite(x) && all_finite(s))
}

/// The forward pass's estimates, as [`first_map_error`] reads them.
#[derive(Clone, Copy)]
struct Filtered<'a> {
    dimension: usize,
    states: &'a [f64],
    covariances: &'a [f64],
}

impl SmoothedRun {
    fn filtered(&self) -> Filtered<'_> {
        Filtered {
            dimension: self.dimension,
            states: &self.filtered_states,
            covariances: &self.filtered_covariances,
        }
    }
}

/// The error of the backward step into measurement `k` (its results `x`, `s`), when its map
/// could not be made or an entry is not finite: the first in the measurement-at-a-time
/// smoother's order, a map that cannot be made, from the first; else this estimate's entry.
fn step_error(
    filtered: Filtered<'_>,
    (phi, x_pred, s_pred): (&[f64], &[f64], &[f64]),
    k: usize,
    (x, s): (&[f64], &[f64]),
) -> Error {
    let bad = x.iter().chain(s.iter()).find(|v| !v.is_finite()).copied();
    let found = first_map_error((filtered, phi, x_pred, s_pred), k + 2);
    found.unwrap_or_else(|| in_batch(k, not_finite(bad.unwrap_or(f64::NAN))))
}

/// `e` naming measurement `index`.
fn in_batch(index: usize, e: Error) -> Error {
    Error::InBatch {
        index,
        source: Box::new(e),
    }
}

/// The first backward map among the steps into measurements `1..before` that cannot be made
/// (`S_{k+1|k}` not positive definite, or a number that is not finite), as the
/// measurement-at-a-time smoother reports it when that measurement is pushed.
fn first_map_error(
    (run, phi, x_pred, s_pred): (Filtered<'_>, &[f64], &[f64], &[f64]),
    before: usize,
) -> Option<Error> {
    let n = run.dimension;
    let nn = n * n;
    let (mut a, mut d, mut c) = (vec![0.0; n], vec![0.0; nn], vec![0.0; nn]);
    let made = x_pred.len() / n.max(1);
    (1..before.min(made + 1)).find_map(|index| {
        let k = index - 1;
        let filtered = (
            &run.states[k * n..index * n],
            &run.covariances[k * nn..index * nn],
        );
        let prediction = (
            &phi[index * nn..(index + 1) * nn],
            &x_pred[k * n..index * n],
            &s_pred[k * nn..index * nn],
        );
        if !map_into(n, filtered, prediction, &mut a, &mut d, &mut c) {
            return Some(in_batch(
                index,
                not_positive_definite(&s_pred[k * nn..index * nn], n, index),
            ));
        }
        let value = a.iter().chain(&d).find(|v| !v.is_finite())?;
        Some(in_batch(index, in_batch(index, not_finite(*value))))
    })
}

/// The smoother a measurement at a time: the forward pass as the measurements come
/// ([`Smoother::push`]), the backward pass at the end ([`Smoother::finish`]). [`smooth`] is
/// this over a slice; it is the [`FixedLagSmoother`] with an unbounded lag (one backward
/// pass, the same code).
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::model::measurement::NoiseCovariance;
/// use seqsmooth::model::measurement::Measurement;
/// use seqsmooth::kalman::smoother::Smoother;
/// use seqsmooth::kalman::KalmanFilter;
/// use seqsmooth::model::dynamics::PolynomialDynamics;
/// use seqsmooth::model::observation::LinearObservation;
/// let f = KalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
///     DVector::from_vec(vec![0.0]), DMatrix::from_element(1, 1, 1e6), 0.0).unwrap();
/// let mut s = Smoother::new(f);
/// for (k, y) in [1.0, 3.0].into_iter().enumerate() {
///     s.push(&Measurement { time: k as f64, values: vec![Some(y)], noise: NoiseCovariance::Identity }).unwrap();
/// }
/// let out = s.finish().unwrap();
/// assert!((out[0].state[0] - 2.0).abs() < 1e-5); // the mean of both
/// ```
#[derive(Clone, Debug)]
pub struct Smoother<D: Dynamics, O: Observation>(FixedLagSmoother<D, O>);

impl<D: Dynamics + Clone, O: Observation + Clone> Smoother<D, O> {
    /// A smoother whose forward pass starts as `filter`.
    pub fn new(filter: KalmanFilter<D, O>) -> Self {
        Self(FixedLagSmoother::new(filter, usize::MAX))
    }

    /// With the forward pass's update the iterated one (Morrison §12.5,
    /// [`FixedLagSmoother::with_iterated_update`]): the iterated extended Kalman filter's
    /// smoother.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::smoother::Smoother;
    /// use seqsmooth::kalman::KalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let f = KalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
    ///     DVector::zeros(1), DMatrix::identity(1, 1), 0.0).unwrap();
    /// assert!(Smoother::new(f).with_iterated_update(0.0, 3).is_err()); // no tolerance
    /// ```
    pub fn with_iterated_update(
        self,
        tolerance: f64,
        max_iterations: usize,
    ) -> Result<Self, Error> {
        Ok(Self(
            self.0.with_iterated_update(tolerance, max_iterations)?,
        ))
    }

    /// The forward filter so far.
    pub fn filter(&self) -> &KalmanFilter<D, O> {
        self.0.filter()
    }

    /// The forward filter, to change its driving noise or fading between pushes (an adaptive
    /// filter): the backward pass uses each step's own prediction, so it stays consistent.
    pub fn filter_mut(&mut self) -> &mut KalmanFilter<D, O> {
        self.0.filter_mut()
    }

    /// The forward pass over `m` (not before the previous measurement): the prediction and
    /// the update; the update's NIS (`None` where every component is missing). On an error
    /// the smoother is unchanged.
    pub fn push(&mut self, m: &Measurement) -> Result<Option<f64>, Error> {
        let given = self.0.push(m)?;
        debug_assert!(
            given.is_none(),
            "an unbounded lag gives nothing before finish"
        );
        Ok(self.0.nis())
    }

    /// [`Self::push`] for each of `measurements` (in time order), then [`Self::finish`]: one
    /// [`Smoothed`] per measurement; an error names its measurement ([`Error::InBatch`]).
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
    /// use seqsmooth::kalman::smoother::Smoother;
    /// use seqsmooth::kalman::KalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let f = KalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
    ///     DVector::zeros(1), DMatrix::from_element(1, 1, 1e12), 0.0).unwrap();
    /// let rows: Vec<Measurement> = [2.0, 4.0].iter().enumerate()
    ///     .map(|(k, &y)| Measurement { time: k as f64, values: vec![Some(y)], noise: NoiseCovariance::Identity })
    ///     .collect();
    /// let s = Smoother::new(f).with_iterated_update(1e-9, 3).unwrap().smooth(&rows).unwrap();
    /// assert!((s[0].state[0] - 3.0).abs() < 1e-9); // linear: the iterated update is the plain one
    /// ```
    pub fn smooth(mut self, measurements: &[Measurement]) -> Result<Vec<Smoothed>, Error> {
        for (index, m) in measurements.iter().enumerate() {
            self.push(m).map_err(|source| Error::InBatch {
                index,
                source: Box::new(source),
            })?;
        }
        self.finish()
    }

    /// The backward pass: every measurement's smoothed estimate, in order. An error names its
    /// measurement ([`Error::InBatch`], counted from the first pushed).
    pub fn finish(self) -> Result<Vec<Smoothed>, Error> {
        self.0.finish()
    }
}

/// One step of [`rts`]: the smoothed estimate, the smoother gain `C_k` into it and the
/// prediction's covariance `S_{k+1|k}` it used (filterpy's `rts_smoother` outputs `x`, `P`,
/// `K`, `Pp`; for the last step `C = 0` and `S_{k+1|k}` is its own filtered covariance, as
/// filterpy gives them).
#[derive(Clone, Debug, PartialEq)]
pub struct RtsStep {
    /// `X_{k|N}`.
    pub state: DVector<f64>,
    /// `S_{k|N}`.
    pub covariance: DMatrix<f64>,
    /// `C_k = S_{k|k} Φᵀ S_{k+1|k}⁻¹`.
    pub gain: DMatrix<f64>,
    /// `S_{k+1|k}`.
    pub predicted_covariance: DMatrix<f64>,
}

/// The Rauch–Tung–Striebel backward pass over a forward pass already run: `filtered[k]` the
/// updated `(X_{k|k}, S_{k|k})`, `predicted[k]` the prediction from step `k` into step `k + 1`,
/// `(Φ(t_{k+1}, t_k), X_{k+1|k}, S_{k+1|k})` (one fewer). The same backward step as the
/// whole-interval and fixed-lag smoothers ([`FixedLagSmoother`]); an error names its step
/// ([`Error::InBatch`]).
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::kalman::smoother::rts;
/// // A constant (Φ = 1, no driving noise) seen twice with unit variance from a vague prior:
/// // both smoothed estimates are the mean, variance 1/2.
/// let one = |v: f64| DMatrix::from_element(1, 1, v);
/// let filtered = [(DVector::from_vec(vec![1.0]), one(1.0)), (DVector::from_vec(vec![2.0]), one(0.5))];
/// let predicted = [(one(1.0), DVector::from_vec(vec![1.0]), one(1.0))];
/// let s = rts(&filtered, &predicted).unwrap();
/// assert_eq!((s[0].state[0], s[0].covariance[(0, 0)], s[0].gain[(0, 0)]), (2.0, 0.5, 1.0));
/// ```
pub fn rts(
    filtered: &[(DVector<f64>, DMatrix<f64>)],
    predicted: &[(DMatrix<f64>, DVector<f64>, DMatrix<f64>)],
) -> Result<Vec<RtsStep>, Error> {
    let Some((x, s)) = filtered.last() else {
        return Ok(Vec::new());
    };
    if predicted.len() + 1 != filtered.len() {
        return Err(Error::InvalidParameter {
            name: crate::error::Param::MatrixLength,
            value: format!("{} predictions", predicted.len()),
            reason: format!("need one fewer than the {} steps", filtered.len()),
        });
    }
    let n = x.len();
    let mut point = Map::point(x, s);
    let mut out = vec![RtsStep {
        state: x.clone(),
        covariance: s.clone(),
        gain: DMatrix::zeros(n, n),
        predicted_covariance: s.clone(),
    }];
    for k in (0..predicted.len()).rev() {
        let (x, s) = &filtered[k];
        let row = Row {
            time: k as f64,
            state: x.clone(),
            covariance: s.clone(),
            nis: None,
        };
        let (phi, x_pred, s_pred) = &predicted[k];
        let map = step(&row, (phi, x_pred, s_pred), k + 1)?;
        point = map.then(&point).finite(k)?;
        out.push(RtsStep {
            state: point.a.clone(),
            covariance: point.d.clone(),
            gain: map.c.expect("a backward step has its gain"),
            predicted_covariance: s_pred.clone(),
        });
    }
    out.reverse();
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::finite;

    /// The finite test by the sum: a sum that overflows is not an entry that is not finite;
    /// an infinity or NaN anywhere is found, whatever the other entries.
    #[test]
    fn finite_by_the_sum_and_by_entry() {
        assert!(finite(&[f64::MAX, f64::MAX], &[f64::MAX; 4]));
        assert!(finite(&[1.0], &[-2.0]));
        for bad in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
            assert!(!finite(&[1.0, bad], &[1.0; 4]));
            assert!(!finite(&[f64::MAX, 0.0], &[1.0, 2.0, 3.0, bad]));
            assert!(!finite(&[f64::MAX, f64::MAX], &[bad, f64::MAX, 0.0, 0.0]));
        }
    }
}
