//! The streaming form of a [`KalmanBank`]: every series' estimate kept in structure of arrays
//! (all states, all covariances, all times), a step of every series at a time. Its memory is
//! `n + n² + 1` numbers a series whatever the number of steps.

use super::fixed::{FixedSeries, MAX_COMPONENTS};
use super::series::{Forward, SeriesFilter};
use super::{BankRows, KalmanBank, RowsMut};
use crate::error::{Error, Param};
use crate::model::dynamics::Dynamics;
use crate::numeric::unrolled::unrolled_sizes;
use rayon::prelude::*;

/// Series per rayon task of a streaming step.
const STREAM_TASK: usize = 1024;

/// Many series' filters of one [`KalmanBank`], fed a row of each at a time.
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::kalman::bank::{BankRows, KalmanBank, Panel};
/// use seqsmooth::model::dynamics::PolynomialDynamics;
/// use seqsmooth::model::observation::LinearObservation;
/// let bank = KalmanBank::new(PolynomialDynamics::new(1, 1), LinearObservation::value_of(2),
///     DMatrix::identity(1, 1), DVector::zeros(2), DMatrix::identity(2, 2) * 100.0).unwrap();
/// let mut stream = bank.clone().stream(2);
/// let mut out = BankRows::default();
/// // Series 0 at times 0 and 1; series 1 only at time 1 (NaN time: no row this step).
/// stream.update(&[0.0, f64::NAN], &[1.0, 0.0], &mut out).unwrap();
/// stream.update(&[1.0, 1.0], &[2.0, 7.0], &mut out).unwrap();
/// // The same as the bank over the whole series.
/// let all = bank.filter(&Panel { offsets: &[0, 2, 3], times: &[0.0, 1.0, 1.0], values: &[1.0, 2.0, 7.0] }).unwrap();
/// assert_eq!(out.row(0), all.row(1));
/// assert_eq!(out.row(1), all.row(2));
/// ```
#[derive(Clone, Debug)]
pub struct BankStream<D: Dynamics> {
    bank: KalmanBank<D>,
    r: Vec<f64>,
    /// `n` a series.
    state: Vec<f64>,
    /// `n²` a series, column-major.
    covariance: Vec<f64>,
    /// A series' time, NaN before its first row.
    time: Vec<f64>,
}

impl<D: Dynamics + Sync> KalmanBank<D> {
    /// A streaming bank of `series` series, each at the prior until its first row.
    pub fn stream(self, series: usize) -> BankStream<D> {
        let r = self.r_entries();
        let state = self.state.as_slice().repeat(series);
        let covariance = self.covariance.as_slice().repeat(series);
        BankStream {
            bank: self,
            r,
            state,
            covariance,
            time: vec![f64::NAN; series],
        }
    }
}

impl<D: Dynamics + Sync> BankStream<D> {
    /// The number of series.
    pub fn series(&self) -> usize {
        self.time.len()
    }

    /// Bytes held a series (its state, covariance and time): the stream's memory is this
    /// times the series, whatever the steps.
    pub fn bytes_per_series(&self) -> usize {
        let n = self.bank.states();
        8 * (n + n * n + 1)
    }

    /// One row of every series: `times[s]` (NaN: no row for series `s` this step) and `p`
    /// values a series (NaN missing). `out` gets one row a series: its estimate, σ and NIS
    /// (`None` for no row, or no component present). Each series' times must not decrease.
    /// A series that fails keeps its estimate; the others are updated; the error names the
    /// first failing series ([`Error::InChannel`], with the others in `also_failed`).
    pub fn update(
        &mut self,
        times: &[f64],
        values: &[f64],
        out: &mut BankRows,
    ) -> Result<(), Error> {
        let (n, p, count) = (self.bank.states(), self.bank.components(), self.series());
        if times.len() != count || values.len() != count * p {
            return Err(Error::InvalidParameter {
                name: Param::RowsLength,
                value: format!("{} times and {} values", times.len(), values.len()),
                reason: format!("must be one time and {p} values for each of {count} series"),
            });
        }
        if out.states != n || out.nis.len() != count {
            *out = BankRows::zeros(count, n);
        }
        let (bank, r) = (&self.bank, &self.r[..]);
        let task = STREAM_TASK;
        let mut failures: Vec<(usize, Error)> = self
            .state
            .par_chunks_mut(task * n)
            .zip(self.covariance.par_chunks_mut(task * n * n))
            .zip(self.time.par_chunks_mut(task))
            .zip(out.state.par_chunks_mut(task * n))
            .zip(out.sigma.par_chunks_mut(task * n))
            .zip(out.nis.par_chunks_mut(task))
            .enumerate()
            .flat_map_iter(|(c, (((((x, cov), time), state), sigma), nis))| {
                let chunk = Chunk {
                    first: c * task,
                    x,
                    cov,
                    time,
                    out: RowsMut { state, sigma, nis },
                };
                if p <= MAX_COMPONENTS {
                    unrolled_sizes!(n, N => chunk.update(&mut FixedSeries::<D, N>::new(bank, r), times, values),
                        _ => chunk.update(&mut SeriesFilter::new(bank, r), times, values))
                } else {
                    chunk.update(&mut SeriesFilter::new(bank, r), times, values)
                }
            })
            .collect();
        if failures.is_empty() {
            return Ok(());
        }
        failures.sort_by_key(|(s, _)| *s);
        let also_failed = failures[1..].iter().map(|(s, _)| *s).collect();
        let (channel, source) = failures.swap_remove(0);
        Err(Error::InChannel {
            channel,
            source: Box::new(source),
            also_failed,
        })
    }

    /// Series `s`'s estimate: its state and covariance (`n × n`, column-major), and its time
    /// (`None` before its first row).
    pub fn estimate(&self, s: usize) -> Option<(&[f64], &[f64], Option<f64>)> {
        let n = self.bank.states();
        let t = *self.time.get(s)?;
        Some((
            &self.state[s * n..(s + 1) * n],
            &self.covariance[s * n * n..(s + 1) * n * n],
            (!t.is_nan()).then_some(t),
        ))
    }
}

/// A streaming step's share of the series: from series `first`, their states, covariances,
/// times and output rows.
struct Chunk<'a> {
    first: usize,
    x: &'a mut [f64],
    cov: &'a mut [f64],
    time: &'a mut [f64],
    out: RowsMut<'a>,
}

impl Chunk<'_> {
    /// Each series' row of `times`, `values` through `f`: the failures.
    fn update<F: Forward>(
        mut self,
        f: &mut F,
        times: &[f64],
        values: &[f64],
    ) -> Vec<(usize, Error)> {
        let p = f.components();
        let n = self.x.len() / self.time.len().max(1);
        let mut failed = Vec::new();
        for (i, t) in self.time.iter_mut().enumerate() {
            let s = self.first + i;
            let (xs, ss) = (
                &mut self.x[i * n..(i + 1) * n],
                &mut self.cov[i * n * n..(i + 1) * n * n],
            );
            let at = times[s];
            if at.is_nan() {
                self.out.set(i, xs, ss, None);
                continue;
            }
            if t.is_nan() {
                f.start(at);
            } else {
                f.resume(xs, ss, *t);
            }
            match f.step(at, &values[s * p..(s + 1) * p]) {
                Ok(nis) => {
                    let (x, s) = f.estimate();
                    xs.copy_from_slice(x);
                    ss.copy_from_slice(s);
                    *t = at;
                    self.out.set(i, xs, ss, nis);
                }
                Err(e) => {
                    self.out.set(i, xs, ss, None);
                    failed.push((s, e));
                }
            }
        }
        failed
    }
}
