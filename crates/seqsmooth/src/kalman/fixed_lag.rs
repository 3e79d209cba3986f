//! Fixed-lag smoothing (Rauch, Tung and Striebel 1965; beyond Morrison's book): the forward
//! [`KalmanFilter`] a measurement at a time, and each measurement's estimate from the `L`
//! measurements after it, `X_{k|k+L}` and `S_{k|k+L}`, given as soon as measurement `k + L` is
//! in — the Rauch–Tung–Striebel backward recursion of [`super::smoother`] run over the last
//! `L + 1` measurements only,
//!
//! `C_j = S_{j|j} Φ(t_{j+1}, t_j)ᵀ S_{j+1|j}⁻¹`,
//! `X_{j|k+L} = X_{j|j} + C_j (X_{j+1|k+L} − X_{j+1|j})`,
//! `S_{j|k+L} = S_{j|j} + C_j (S_{j+1|k+L} − S_{j+1|j}) C_jᵀ`, `j = k+L−1, …, k`,
//!
//! from `X_{k+L|k+L}`, the filter's. The lag counts measurements (not time): memory is `L + 1`
//! measurements' filtered and predicted states, covariances and transitions, whatever the
//! input's length. Each gain `C_j` is formed once (when measurement `j + 1` is in) and kept, so
//! a measurement costs the filter's update and `L` backward steps of two matrix products. The
//! estimate is exactly the whole-interval smoother's run over measurements `0..=k+L`, read at
//! `k`: `L = 0` gives the filter, `L` at least the number of measurements gives the
//! whole-interval smoother ([`super::Smoother`] is this with an unbounded lag). At
//! [`FixedLagSmoother::finish`] the last `L` measurements get the whole-interval smoother's
//! estimates (the backward pass from the last).

use super::filter::KalmanFilter;
use super::smoother::Smoothed;
use crate::error::Error;
use crate::estimate::gauss_newton::Measurement;
use crate::model::dynamics::Dynamics;
use crate::model::observation::Observation;
use nalgebra::{Cholesky, DMatrix, DVector};
use std::collections::VecDeque;

/// One measurement's forward pass.
#[derive(Clone, Debug)]
struct Row {
    time: f64,
    /// `Φ` from the previous measurement to this one, `X_{k|k−1}` and `S_{k|k−1}`.
    transition: DMatrix<f64>,
    predicted_state: DVector<f64>,
    predicted_covariance: DMatrix<f64>,
    /// `X_{k|k}`, `S_{k|k}`.
    state: DVector<f64>,
    covariance: DMatrix<f64>,
    /// The update's NIS (`None` where every component was missing).
    nis: Option<f64>,
    /// `C_kᵀ`, once the next measurement is in and it has been formed.
    gain: Option<DMatrix<f64>>,
}

/// The fixed-lag smoother: [`FixedLagSmoother::push`] gives the estimate of the measurement
/// `lag` before, from every measurement up to the one pushed; [`FixedLagSmoother::finish`] the
/// rest.
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::estimate::batch::NoiseCovariance;
/// use seqsmooth::estimate::gauss_newton::Measurement;
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
#[derive(Clone, Debug)]
pub struct FixedLagSmoother<D: Dynamics, O: Observation> {
    filter: KalmanFilter<D, O>,
    lag: usize,
    /// The measurements not yet given, at most `lag + 1` (after a push that gives one, `lag`).
    rows: VecDeque<Row>,
    /// The measurements pushed.
    pushed: usize,
    /// The last measurement's time.
    last_time: Option<f64>,
}

impl<D: Dynamics + Clone, O: Observation + Clone> FixedLagSmoother<D, O> {
    /// A smoother of lag `lag` measurements whose forward pass starts as `filter`.
    pub fn new(filter: KalmanFilter<D, O>, lag: usize) -> Self {
        Self {
            filter,
            lag,
            rows: VecDeque::with_capacity(lag.saturating_add(1).min(1 << 12)),
            pushed: 0,
            last_time: None,
        }
    }

    /// The lag, in measurements.
    pub fn lag(&self) -> usize {
        self.lag
    }

    /// The forward filter so far.
    pub fn filter(&self) -> &KalmanFilter<D, O> {
        &self.filter
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
        self.rows.back().and_then(|r| r.nis)
    }

    /// Bytes held per measurement for a state of `n` components: a bound of the smoother's
    /// memory is `(lag + 1)` times this (plus the filter's).
    pub fn bytes_per_measurement(n: usize) -> usize {
        // Four n×n matrices and two n-vectors of f64, with their allocations' headers.
        std::mem::size_of::<Row>() + 8 * (4 * n * n + 2 * n) + 6 * 16
    }

    /// The forward pass over `m` (not before the previous measurement), and the smoothed
    /// estimate of the measurement `lag` before it, if there is one. An error of the forward
    /// pass is the update's; one of the backward pass is [`Error::InBatch`] naming the
    /// measurement (counted from the first pushed). On an error the smoother is unchanged.
    pub fn push(&mut self, m: &Measurement) -> Result<Option<Smoothed>, Error> {
        if let Some(previous) = self.last_time {
            if m.time.is_finite() && m.time < previous {
                return Err(Error::InvalidParameter {
                    name: "time",
                    value: m.time.to_string(),
                    reason: format!("is before the previous measurement's {previous}"),
                });
            }
        }
        let before = self.filter.clone();
        let step = |filter: &mut KalmanFilter<D, O>| {
            let phi = filter.predict_with_transition(m.time)?;
            let predicted = (phi, filter.state().clone(), filter.covariance().clone());
            Ok::<_, Error>((predicted, filter.update(m)?.map(|i| i.nis)))
        };
        let ((transition, predicted_state, predicted_covariance), nis) =
            match step(&mut self.filter) {
                Ok(v) => v,
                Err(e) => {
                    self.filter = before;
                    return Err(e);
                }
            };
        self.rows.push_back(Row {
            time: m.time,
            transition,
            predicted_state,
            predicted_covariance,
            state: self.filter.state().clone(),
            covariance: self.filter.covariance().clone(),
            nis,
            gain: None,
        });
        if self.rows.len() <= self.lag {
            self.pushed += 1;
            self.last_time = Some(m.time);
            return Ok(None);
        }
        let first = self.pushed + 1 - self.rows.len();
        let mut out = None;
        let backward = backward(&mut self.rows, first, |k, x, s| {
            if k == 0 {
                out = Some((x.clone(), s.clone()));
            }
        });
        if let Err(e) = backward {
            // Undo: the filter, the row, and the gain formed against it.
            self.filter = before;
            self.rows.pop_back();
            if let Some(last) = self.rows.back_mut() {
                last.gain = None;
            }
            return Err(e);
        }
        self.pushed += 1;
        self.last_time = Some(m.time);
        let row = self.rows.pop_front().expect("a row was pushed");
        let (state, covariance) = out.expect("the backward pass reaches the first row");
        Ok(Some(smoothed(row, state, covariance)))
    }

    /// The measurements held, each smoothed by every measurement pushed (the backward pass from
    /// the last), in order. An error names its measurement ([`Error::InBatch`], counted from
    /// the first pushed).
    pub fn finish(self) -> Result<Vec<Smoothed>, Error> {
        let mut rows = self.rows;
        let first = self.pushed - rows.len();
        let mut out = vec![None; rows.len()];
        backward(&mut rows, first, |k, x, s| {
            out[k] = Some((x.clone(), s.clone()));
        })?;
        Ok(rows
            .into_iter()
            .zip(out)
            .map(|(row, o)| {
                let (state, covariance) = o.expect("the backward pass reaches every row");
                smoothed(row, state, covariance)
            })
            .collect())
    }
}

/// A row's [`Smoothed`], with its smoothed `state` and `covariance`.
fn smoothed(row: Row, state: DVector<f64>, covariance: DMatrix<f64>) -> Smoothed {
    Smoothed {
        time: row.time,
        state,
        covariance,
        filtered_state: row.state,
        filtered_covariance: row.covariance,
        nis: row.nis,
    }
}

/// The Rauch–Tung–Striebel backward pass over `rows` (the module's recursion; the first row is
/// measurement `first`): from the last row's filtered estimate back to the first, calling
/// `each(k, X_{k|last}, S_{k|last})` for every row, the last first. Forms and keeps the gains it
/// lacks.
fn backward(
    rows: &mut VecDeque<Row>,
    first: usize,
    mut each: impl FnMut(usize, &DVector<f64>, &DMatrix<f64>),
) -> Result<(), Error> {
    let Some(last) = rows.back() else {
        return Ok(());
    };
    let (mut x, mut s) = (last.state.clone(), last.covariance.clone());
    let n = x.len();
    let (mut x_next, mut s_next) = (DVector::zeros(n), DMatrix::zeros(n, n));
    let mut w = DMatrix::zeros(n, n);
    each(rows.len() - 1, &x, &s);
    for k in (0..rows.len() - 1).rev() {
        if rows[k].gain.is_none() {
            let gain = gain(&rows[k], &rows[k + 1], first + k + 1)?;
            rows[k].gain = Some(gain);
        }
        let (row, next) = (&rows[k], &rows[k + 1]);
        let g = row.gain.as_ref().expect("formed above");
        // x, s hold X_{k+1|N}, S_{k+1|N}: their differences from the prediction, then
        // X_{k|N} = X_{k|k} + Gᵀ dx and S_{k|N} = S_{k|k} + Gᵀ (dS G), G = Cᵀ.
        x -= &next.predicted_state;
        s -= &next.predicted_covariance;
        step(
            n,
            g.as_slice(),
            (x.as_slice(), s.as_slice()),
            (row.state.as_slice(), row.covariance.as_slice()),
            w.as_mut_slice(),
            (x_next.as_mut_slice(), s_next.as_mut_slice()),
        );
        if let Some(&value) = x_next
            .iter()
            .chain(s_next.iter())
            .find(|v| !v.is_finite())
        {
            return Err(Error::InBatch {
                index: first + k,
                source: Box::new(Error::NonFinite {
                    what: "smoothed state or covariance entry",
                    value,
                }),
            });
        }
        std::mem::swap(&mut x, &mut x_next);
        std::mem::swap(&mut s, &mut s_next);
        each(k, &x, &s);
    }
    Ok(())
}

/// One backward step on column-major `n × n` slices: from `dx = X_{k+1|N} − X_{k+1|k}` and
/// `dS = S_{k+1|N} − S_{k+1|k}`, `X_{k|N} = X_{k|k} + Gᵀ dx` and `S_{k|N} = S_{k|k} + Gᵀ (dS G)`
/// (its upper triangle, mirrored: exactly symmetric), `G = C_kᵀ`; `w` is scratch. Loops over
/// contiguous columns: a 6-state step is a few hundred multiply-adds, no allocation.
fn step(
    n: usize,
    g: &[f64],
    (dx, ds): (&[f64], &[f64]),
    (xf, sf): (&[f64], &[f64]),
    w: &mut [f64],
    (x, s): (&mut [f64], &mut [f64]),
) {
    fn column(m: &[f64], n: usize, j: usize) -> &[f64] {
        &m[j * n..(j + 1) * n]
    }
    let dot = |a: &[f64], b: &[f64]| -> f64 { a.iter().zip(b).map(|(a, b)| a * b).sum() };
    for i in 0..n {
        x[i] = xf[i] + dot(column(g, n, i), dx);
    }
    // w = dS G, column by column: w_j = Σ_r dS_r G[r, j].
    for j in 0..n {
        let wj = &mut w[j * n..(j + 1) * n];
        wj.fill(0.0);
        for (r, &grj) in column(g, n, j).iter().enumerate() {
            for (wi, di) in wj.iter_mut().zip(column(ds, n, r)) {
                *wi += di * grj;
            }
        }
    }
    for j in 0..n {
        for i in 0..=j {
            let v = sf[j * n + i] + dot(column(g, n, i), column(w, n, j));
            s[j * n + i] = v;
            s[i * n + j] = v;
        }
    }
}

/// `Gᵀ = C_k = S_{k|k} Φᵀ S_{k+1|k}⁻¹` as `G = S_{k+1|k}⁻¹ Φ S_{k|k}` (a Cholesky solve); an
/// error names measurement `index` (the later one).
fn gain(row: &Row, next: &Row, index: usize) -> Result<DMatrix<f64>, Error> {
    let s_pred = &next.predicted_covariance;
    let chol = Cholesky::new(s_pred.clone()).ok_or_else(|| Error::InBatch {
        index,
        source: Box::new(Error::InvalidParameter {
            name: "predicted covariance",
            value: format!("{s_pred:?}"),
            reason: "is not positive definite, so the smoother cannot weigh the later \
                     measurements (add driving noise, or avoid perfect observations)"
                .into(),
        }),
    })?;
    Ok(chol.solve(&(&next.transition * &row.covariance)))
}
