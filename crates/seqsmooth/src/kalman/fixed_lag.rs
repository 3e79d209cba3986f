//! Fixed-lag smoothing (Rauch, Tung and Striebel 1965; beyond Morrison's book): the forward
//! [`KalmanFilter`] a measurement at a time, and each measurement's estimate from the `L`
//! measurements after it, `X_{k|k+L}` and `S_{k|k+L}`, given as soon as measurement `k + L` is
//! in — the Rauch–Tung–Striebel backward recursion of [`super::smoother`] over the last `L + 1`
//! measurements,
//!
//! `C_j = S_{j|j} Φ(t_{j+1}, t_j)ᵀ S_{j+1|j}⁻¹`,
//! `X_{j|N} = X_{j|j} + C_j (X_{j+1|N} − X_{j+1|j})`,
//! `S_{j|N} = S_{j|j} + C_j (S_{j+1|N} − S_{j+1|j}) C_jᵀ`, `j = N−1, …, k`, `N = k + L`,
//!
//! from `X_{N|N}`, the filter's. Each step is an affine map of the later estimate,
//! `T_j: (X, S) ↦ (a_j + C_j X, D_j + C_j S C_jᵀ)` with `a_j = X_{j|j} − C_j X_{j+1|j}` and
//! `D_j = S_{j|j} − C_j S_{j+1|j} C_jᵀ` (positive semidefinite: the covariance of `x_j` given
//! `x_{j+1}` and the measurements to `j`), and maps compose into maps:
//! `T ∘ T' = (a + C a', D + C D' Cᵀ, C C')`. So `X_{k|k+L}` is the composition
//! `T_k ∘ … ∘ T_{k+L−1}` applied to the filter's estimate at `k + L`, and the window of the last
//! `L` maps slides by one each measurement: its composition is kept by the two-stack method of
//! sliding-window aggregation (no inverse is needed, each map is composed about three times),
//! so a measurement costs the filter's update and a few 6×6 products whatever `L`. The
//! whole-interval smoother ([`super::Smoother`], this with an unbounded lag) and
//! [`FixedLagSmoother::finish`] apply the same maps one at a time from the last estimate: the
//! backward recursion above, one code. The estimate is the whole-interval smoother's over
//! measurements `0..=k+L` read at `k`, to rounding: `L = 0` gives the filter, `L` at least the
//! number of measurements the whole-interval smoother. The lag counts measurements (not
//! time): memory is `L + 1` measurements' filtered estimates and maps, whatever the input's
//! length.

use super::backward;
use super::filter::KalmanFilter;
use super::smoother::Smoothed;
use crate::error::{Error, Param};
use crate::model::dynamics::Dynamics;
use crate::model::measurement::Measurement;
use crate::model::observation::Observation;
use nalgebra::{DMatrix, DVector};
use std::collections::VecDeque;

/// One measurement's filtered estimate, until it is given.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub(super) struct Row {
    pub(super) time: f64,
    /// `X_{k|k}`, `S_{k|k}`.
    pub(super) state: DVector<f64>,
    pub(super) covariance: DMatrix<f64>,
    /// The update's NIS (`None` where every component was missing).
    pub(super) nis: Option<f64>,
}

/// `(X, S) ↦ (a + C X, D + C S Cᵀ)`: a backward step, a composition of them, or (`c` `None`)
/// the constant `(a, D)`, an estimate.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub(super) struct Map {
    pub(super) a: DVector<f64>,
    pub(super) d: DMatrix<f64>,
    pub(super) c: Option<DMatrix<f64>>,
}

impl Map {
    /// The estimate `(x, s)` as a constant map.
    pub(super) fn point(x: &DVector<f64>, s: &DMatrix<f64>) -> Self {
        Self {
            a: x.clone(),
            d: s.clone(),
            c: None,
        }
    }

    /// `self ∘ inner`: `(a + C a', D + C D' Cᵀ, C C')` (`D` kept exactly symmetric); a constant
    /// `self` is itself, and a constant `inner` gives a constant (the backward step applied).
    pub(super) fn then(&self, inner: &Map) -> Map {
        let Some(c) = &self.c else {
            return self.clone();
        };
        let n = self.a.len();
        let cs = c.as_slice();
        let (mut a, mut d) = (DVector::zeros(n), DMatrix::zeros(n, n));
        backward::apply_into(
            n,
            (self.a.as_slice(), self.d.as_slice(), cs),
            (inner.a.as_slice(), inner.d.as_slice()),
            a.as_mut_slice(),
            d.as_mut_slice(),
        );
        let c = inner.c.as_ref().map(|ci| {
            let mut out = DMatrix::zeros(n, n);
            mul_into(n, cs, ci.as_slice(), out.as_mut_slice());
            out
        });
        Map { a, d, c }
    }

    /// An error naming measurement `index` if the map holds a number that is not finite.
    pub(super) fn finite(self, index: usize) -> Result<Self, Error> {
        match self.a.iter().chain(self.d.iter()).find(|v| !v.is_finite()) {
            Some(&value) => Err(Error::InBatch {
                index,
                source: Box::new(not_finite(value)),
            }),
            None => Ok(self),
        }
    }
}

/// `y += alpha x`.
fn axpy(alpha: f64, x: &[f64], y: &mut [f64]) {
    for (y, x) in y.iter_mut().zip(x) {
        *y += alpha * x;
    }
}

/// `out = A B`, column-major `n × n` slices (loops over contiguous columns: for 6×6 far
/// cheaper than a general product's packing and allocation).
fn mul_into(n: usize, a: &[f64], b: &[f64], out: &mut [f64]) {
    out.fill(0.0);
    for (j, oj) in out.chunks_exact_mut(n).enumerate() {
        for r in 0..n {
            axpy(b[r + j * n], &a[r * n..(r + 1) * n], oj);
        }
    }
}

/// The backward step `T_k` from measurement `k + 1` to `k` ([`backward::map_into`]):
/// `C = S_{k|k} Φᵀ S_{k+1|k}⁻¹` by the `L D Lᵀ` factors of `S_{k+1|k}`,
/// `a = X_{k|k} − C X_{k+1|k}`, `D = S_{k|k} − C Φ S_{k|k}` (that is,
/// `S_{k|k} − C S_{k+1|k} Cᵀ`); an error names measurement `index` (`k + 1`).
pub(super) fn step(
    row: &Row,
    (phi, x_pred, s_pred): (&DMatrix<f64>, &DVector<f64>, &DMatrix<f64>),
    index: usize,
) -> Result<Map, Error> {
    let n = row.state.len();
    let (mut a, mut d, mut c) = (
        DVector::zeros(n),
        DMatrix::zeros(n, n),
        DMatrix::zeros(n, n),
    );
    let made = backward::map_into(
        n,
        (row.state.as_slice(), row.covariance.as_slice()),
        (phi.as_slice(), x_pred.as_slice(), s_pred.as_slice()),
        a.as_mut_slice(),
        d.as_mut_slice(),
        c.as_mut_slice(),
    );
    if !made {
        return Err(not_positive_definite(s_pred.as_slice(), n, index));
    }
    Map { a, d, c: Some(c) }.finite(index)
}

/// The error of a smoothed estimate's entry `value` that is not finite.
pub(super) fn not_finite(value: f64) -> Error {
    Error::NonFinite {
        what: "smoothed state or covariance entry",
        value,
    }
}

/// The error of a measurement at `time`, before the previous one's `previous`.
pub(super) fn time_before(time: f64, previous: f64) -> Error {
    Error::InvalidParameter {
        name: Param::Time,
        value: time.to_string(),
        reason: format!("is before the previous measurement's {previous}"),
    }
}

/// The error of a backward step whose `S_{k+1|k}` (`n × n`) is not positive definite, naming
/// measurement `index`.
pub(crate) fn not_positive_definite(s_pred: &[f64], n: usize, index: usize) -> Error {
    Error::InBatch {
        index,
        source: Box::new(Error::InvalidParameter {
            name: Param::PredictedCovariance,
            value: format!("{:?}", DMatrix::from_column_slice(n, n, s_pred)),
            reason: "is not positive definite, so the smoother cannot weigh the later \
                     measurements (add driving noise, or avoid perfect observations)"
                .into(),
        }),
    }
}

/// The maps of the window, oldest first, in two stacks (sliding-window aggregation): `front`
/// with the oldest last, each with the composition of it and every newer map of `front`;
/// `back` in order, with the composition of all of them (kept only for a bounded lag).
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
struct Window {
    front: Vec<(Map, Map)>,
    back: Vec<Map>,
    back_all: Option<Map>,
}

impl Window {
    /// The composition of every map of the window applied to `point`.
    fn apply(&self, point: &Map) -> Map {
        let inner = match &self.back_all {
            Some(b) => b.then(point),
            None => point.clone(),
        };
        match self.front.last() {
            Some((_, all)) => all.then(&inner),
            None => inner,
        }
    }

    /// Removes the oldest map (after moving `back` onto `front` if `front` is empty).
    fn pop(&mut self) {
        if self.front.is_empty() {
            let mut all: Option<Map> = None;
            for m in std::mem::take(&mut self.back).into_iter().rev() {
                let composed = match &all {
                    Some(a) => m.then(a),
                    None => m.clone(),
                };
                all = Some(composed.clone());
                self.front.push((m, composed));
            }
            self.back_all = None;
        }
        self.front.pop();
    }

    /// The maps, oldest first.
    fn maps(&self) -> impl Iterator<Item = &Map> {
        self.front.iter().rev().map(|(m, _)| m).chain(&self.back)
    }
}

/// The fixed-lag smoother: [`FixedLagSmoother::push`] gives the estimate of the measurement
/// `lag` before, from every measurement up to the one pushed; [`FixedLagSmoother::finish`] the
/// rest.
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::model::measurement::NoiseCovariance;
/// use seqsmooth::model::measurement::Measurement;
/// use seqsmooth::kalman::fixed_lag::FixedLagSmoother;
/// use seqsmooth::kalman::KalmanFilter;
/// use seqsmooth::model::dynamics::PolynomialDynamics;
/// use seqsmooth::model::observation::LinearObservation;
/// // A constant with a vague prior, lag 1: each estimate is the mean of the samples so far
/// // and the next one.
/// let f = KalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
///     DVector::zeros(1), DMatrix::from_element(1, 1, 1e12), 0.0).unwrap();
/// let mut s = FixedLagSmoother::new(f, 1);
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
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct FixedLagSmoother<D: Dynamics, O: Observation> {
    filter: KalmanFilter<D, O>,
    lag: usize,
    /// The measurements not yet given, at most `lag + 1` (after a push that gives one, `lag`).
    rows: VecDeque<Row>,
    /// The backward steps between them (one fewer).
    window: Window,
    /// The measurements pushed.
    pushed: usize,
    /// The last measurement's time and NIS.
    last: Option<(f64, Option<f64>)>,
    /// The iterated update's tolerance and most iterations (§12.5), where the forward pass
    /// iterates.
    iterated: Option<(f64, usize)>,
}

impl<D: Dynamics + Clone, O: Observation + Clone> FixedLagSmoother<D, O> {
    /// A smoother of lag `lag` measurements whose forward pass starts as `filter`.
    pub fn new(filter: KalmanFilter<D, O>, lag: usize) -> Self {
        Self {
            filter,
            lag,
            rows: VecDeque::with_capacity(lag.saturating_add(1).min(1 << 12)),
            window: Window::default(),
            pushed: 0,
            last: None,
            iterated: None,
        }
    }

    /// With the forward pass's update the iterated one
    /// ([`KalmanFilter::update_iterated`], Morrison §12.5: relinearised about each new estimate
    /// until the change is at most `tolerance` of its σ, at most `max_iterations` times); the
    /// backward pass is the same, on that forward pass's own predictions. Its limits checked
    /// ([`super::filter::check_iteration_limits`]).
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::fixed_lag::FixedLagSmoother;
    /// use seqsmooth::kalman::KalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let f = KalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
    ///     DVector::zeros(1), DMatrix::identity(1, 1), 0.0).unwrap();
    /// assert!(FixedLagSmoother::new(f.clone(), 2).with_iterated_update(1e-9, 5).is_ok());
    /// assert!(FixedLagSmoother::new(f, 2).with_iterated_update(1e-9, 0).is_err());
    /// ```
    pub fn with_iterated_update(
        mut self,
        tolerance: f64,
        max_iterations: usize,
    ) -> Result<Self, Error> {
        super::filter::check_iteration_limits(tolerance, max_iterations)?;
        self.iterated = Some((tolerance, max_iterations));
        Ok(self)
    }

    /// The lag, in measurements.
    pub fn lag(&self) -> usize {
        self.lag
    }

    /// The forward filter so far.
    pub fn filter(&self) -> &KalmanFilter<D, O> {
        &self.filter
    }

    /// The forward filter, to change its driving noise or fading between pushes (an adaptive
    /// filter, as the radar tracker's, Morrison §14.8): each backward step is formed from that
    /// step's own prediction (`Φ`, `X_{k+1|k}`, `S_{k+1|k}` with the driving noise then in
    /// force), so the smoothed estimates stay those of the filter actually run.
    pub fn filter_mut(&mut self) -> &mut KalmanFilter<D, O> {
        &mut self.filter
    }

    /// The measurements pushed so far.
    pub fn pushed(&self) -> usize {
        self.pushed
    }

    /// The measurements held (pushed, not yet given): at most `lag`.
    pub fn held(&self) -> usize {
        self.rows.len()
    }

    /// The last update's NIS (`None` before the first, or where every component was missing).
    pub fn nis(&self) -> Option<f64> {
        self.last.and_then(|l| l.1)
    }

    /// Bytes held per measurement for a state of `n` components: a bound of the smoother's
    /// memory is `lag + 1` times this (plus the filter's).
    pub fn bytes_per_measurement(n: usize) -> usize {
        // A row (an n-vector and an n×n matrix) and two or three maps (an n-vector and two
        // n×n matrices each), with their allocations' headers.
        std::mem::size_of::<Row>()
            + 3 * std::mem::size_of::<Map>()
            + 8 * (n * n + n + 3 * (2 * n * n + n))
            + 10 * 16
    }

    /// The forward pass over `m` (not before the previous measurement), and the smoothed
    /// estimate of the measurement `lag` before it, if there is one. An error of the forward
    /// pass is the update's; one of the backward pass is [`Error::InBatch`] naming the
    /// measurement (counted from the first pushed). On an error the smoother is unchanged.
    pub fn push(&mut self, m: &Measurement) -> Result<Option<Smoothed>, Error> {
        if let Some((previous, _)) = self.last {
            if m.time.is_finite() && m.time < previous {
                return Err(time_before(m.time, previous));
            }
        }
        let before = self.filter.estimate_copy();
        let iterated = self.iterated;
        let step_forward = |filter: &mut KalmanFilter<D, O>| {
            let phi = filter.predict_with_transition(m.time)?;
            let predicted = (phi, filter.state().clone(), filter.covariance().clone());
            let nis = match iterated {
                Some((tolerance, most)) => {
                    filter.update_iterated(m, tolerance, most)?.map(|i| i.nis)
                }
                None => filter.update_stats(m)?.map(|i| i.nis),
            };
            Ok::<_, Error>((predicted, nis))
        };
        let undo = |this: &mut Self, e: Error| {
            this.filter.restore_estimate(before.clone());
            Err(e)
        };
        let ((phi, x_pred, s_pred), nis) = match step_forward(&mut self.filter) {
            Ok(v) => v,
            Err(e) => return undo(self, e),
        };
        let row = Row {
            time: m.time,
            state: self.filter.state().clone(),
            covariance: self.filter.covariance().clone(),
            nis,
        };
        // The step from this measurement back to the previous one, if that is still held.
        let map = match self.rows.back() {
            Some(previous) => match step(previous, (&phi, &x_pred, &s_pred), self.pushed) {
                Ok(map) => Some(map),
                Err(e) => return undo(self, e),
            },
            None => None,
        };
        let bounded = self.lag < usize::MAX;
        let back_all = match (&map, bounded) {
            (Some(map), true) => Some(match &self.window.back_all {
                Some(all) => all.then(map),
                None => map.clone(),
            }),
            _ => self.window.back_all.clone(),
        };
        let given = if self.rows.len() + 1 > self.lag {
            // Measurement `pushed − lag` from the window's maps and this estimate.
            let mut window = std::mem::take(&mut self.window);
            let saved = std::mem::replace(&mut window.back_all, back_all.clone());
            let smoothed = window
                .apply(&Map::point(&row.state, &row.covariance))
                .finite(self.pushed - self.lag);
            window.back_all = saved;
            self.window = window;
            match smoothed {
                Ok(s) => Some(s),
                Err(e) => return undo(self, e),
            }
        } else {
            None
        };
        // Committed from here.
        self.pushed += 1;
        self.last = Some((m.time, nis));
        self.rows.push_back(row);
        if let Some(map) = map {
            self.window.back.push(map);
            self.window.back_all = back_all;
        }
        let Some(s) = given else {
            return Ok(None);
        };
        let oldest = self.rows.pop_front().expect("a row was pushed");
        if self.lag > 0 {
            self.window.pop();
        }
        Ok(Some(smoothed(oldest, s)))
    }

    /// The measurements held, each smoothed by every measurement pushed (the backward
    /// recursion from the last), in order. An error names its measurement ([`Error::InBatch`],
    /// counted from the first pushed).
    pub fn finish(self) -> Result<Vec<Smoothed>, Error> {
        let first = self.pushed - self.rows.len();
        let Some(last) = self.rows.back() else {
            return Ok(Vec::new());
        };
        let mut point = Map::point(&last.state, &last.covariance);
        let mut out = Vec::with_capacity(self.rows.len());
        out.push(point.clone());
        let maps: Vec<&Map> = self.window.maps().collect();
        for (k, map) in maps.into_iter().enumerate().rev() {
            point = map.then(&point).finite(first + k)?;
            out.push(point.clone());
        }
        Ok(self
            .rows
            .into_iter()
            .zip(out.into_iter().rev())
            .map(|(row, s)| smoothed(row, s))
            .collect())
    }
}

/// A row's [`Smoothed`], with its smoothed estimate (a constant map).
fn smoothed(row: Row, s: Map) -> Smoothed {
    Smoothed {
        time: row.time,
        state: s.a,
        covariance: s.d,
        filtered_state: row.state,
        filtered_covariance: row.covariance,
        nis: row.nis,
    }
}

impl<D: Dynamics, O: Observation> FixedLagSmoother<D, O> {
    /// The dynamic and observation models (a restored smoother's checks).
    pub(crate) fn models(&self) -> (&D, &O) {
        self.filter.models()
    }

    /// A restored smoother's invariants ([`crate::persist`]): its filter's, and the rows it
    /// holds of the filter's dimension.
    pub(crate) fn check_saved(&mut self) -> Result<(), String> {
        self.filter.check_saved()?;
        let n = self.filter.state().len();
        for r in &self.rows {
            crate::linalg::invariant::vector(&r.state, n, "held state")?;
            crate::linalg::invariant::covariance(&r.covariance, n, "held covariance")?;
        }
        let map = |m: &Map| {
            m.a.len() == n
                && m.d.shape() == (n, n)
                && m.c.as_ref().is_none_or(|c| c.shape() == (n, n))
        };
        let w = &self.window;
        if !(w.front.iter().all(|(a, b)| map(a) && map(b))
            && w.back.iter().all(map)
            && w.back_all.as_ref().is_none_or(map))
        {
            return Err(format!("smoother's maps are not {n}-dimensional"));
        }
        Ok(())
    }
}
