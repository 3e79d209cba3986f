//! One series of a [`KalmanBank`]: the Kalman filter's prediction and update (Morrison
//! (12.2.15)-(12.2.19), driving noise (15.4.10)-(15.4.11), Joseph's covariance (12.3.7)) on the
//! filter's own work buffers and kernels ([`carry`], [`correct_kernel`]), in the filter's
//! order, so that every number is [`KalmanFilter`](crate::kalman::KalmanFilter)'s.

use super::super::correct::{carry, correct_kernel, finite, Work};
use super::{KalmanBank, Panel, RowsMut};
use crate::error::{Error, Param};
use crate::model::dynamics::Dynamics;
use crate::model::observation::Observation;
use crate::numeric::unrolled::{unrolled_sizes, Any, Fixed};
use nalgebra::{DMatrix, DVector};
use std::f64::consts::TAU;

/// A series' filter: its estimate `(x, s)` at `time`, and the work buffers, which after
/// [`SeriesFilter::step`] hold the step's prediction (`phi`, `x`, `s`).
pub(crate) struct SeriesFilter<'a, D: Dynamics> {
    bank: &'a KalmanBank<D>,
    /// `R`, `p × p` column-major.
    r: &'a [f64],
    w: Work,
    x: DVector<f64>,
    s: DMatrix<f64>,
    time: f64,
    /// For a time-invariant model, the last step's length and its `Φ` and `Q` (NaN: none).
    invariant: bool,
    step: f64,
    phi: DMatrix<f64>,
    q: DMatrix<f64>,
}

impl<'a, D: Dynamics> SeriesFilter<'a, D> {
    /// A filter of `bank` (not started).
    pub(super) fn new(bank: &'a KalmanBank<D>, r: &'a [f64]) -> Self {
        let (n, p) = (bank.dynamics.dimension(), bank.observation.components());
        Self {
            bank,
            r,
            w: Work::new(n, p),
            x: bank.state.clone(),
            s: bank.covariance.clone(),
            time: f64::NAN,
            invariant: bank.dynamics.is_time_invariant()
                && bank.noise.as_ref().is_none_or(|q| q.is_time_invariant()),
            step: f64::NAN,
            phi: DMatrix::zeros(n, n),
            q: DMatrix::zeros(n, n),
        }
    }

    /// The prediction to `t` and the update with `z` ([`Forward::step`]).
    fn step_general(&mut self, t: f64, z: &[f64]) -> Result<Option<f64>, Error> {
        check_row(self.time, t, z)?;
        self.predict(t)?;
        let w = &mut self.w;
        w.present.clear();
        w.values.clear();
        for (c, &v) in z.iter().enumerate() {
            if !v.is_nan() {
                w.present.push(c);
                w.values.push(v);
            }
        }
        let k = w.present.len();
        if k == 0 {
            self.x.copy_from(&w.x);
            self.s.copy_from(&w.s);
            self.time = t;
            return Ok(None);
        }
        let nis = self.correct(t)?;
        std::mem::swap(&mut self.x, &mut self.w.x_out);
        std::mem::swap(&mut self.s, &mut self.w.s_out);
        self.time = t;
        Ok(Some(nis))
    }

    /// `X_{k|k−1}`, `S_{k|k−1}` and `Φ` into the work buffers (the filter's `predict_work`).
    fn predict(&mut self, t: f64) -> Result<(), Error> {
        let w = &mut self.w;
        let n = self.x.len();
        if t == self.time {
            w.x.copy_from(&self.x);
            w.s.copy_from(&self.s);
            w.phi.fill_with_identity();
            return Ok(());
        }
        let bank = self.bank;
        let dt = t - self.time;
        if self.invariant && dt == self.step {
            // Φ and Q of the same step length again: X_{k|k−1} = Φ X (each entry's sum over
            // the columns in order).
            w.phi.copy_from(&self.phi);
            w.q.copy_from(&self.q);
            let (f, x, xp) = (self.phi.as_slice(), self.x.as_slice(), w.x.as_mut_slice());
            for i in 0..n {
                xp[i] = f[i] * x[0];
            }
            for j in 1..n {
                for i in 0..n {
                    xp[i] += f[i + j * n] * x[j];
                }
            }
            if let Some(&value) = xp.iter().find(|v| !v.is_finite()) {
                return Err(Error::NonFinite {
                    what: "propagated state entry",
                    value,
                });
            }
        } else {
            bank.dynamics
                .propagate_into(&self.x, self.time, t, &mut w.x, &mut w.phi)?;
            if let Some(noise) = &bank.noise {
                noise.covariance_into(self.time, t, &mut w.q)?;
            }
            if self.invariant {
                self.phi.copy_from(&w.phi);
                self.q.copy_from(&w.q);
                self.step = dt;
            }
        }
        let q = bank.noise.as_ref().map(|_| w.q.as_slice());
        let (phi, from, to) = (w.phi.as_slice(), self.s.as_slice(), w.s.as_mut_slice());
        let finite_out = unrolled_sizes!(n, N => carry(Fixed::<N>, phi, from, q, &mut w.square, to),
            n => carry(Any(n), phi, from, q, &mut w.square, to));
        if finite_out {
            Ok(())
        } else {
            finite(to, "predicted covariance")
        }
    }

    /// The correction of the prediction in the work buffers with the present components (the
    /// filter's `correct`, linear observation, no fading): the NIS.
    fn correct(&mut self, t: f64) -> Result<f64, Error> {
        let n = self.x.len();
        let p = self.bank.observation.components();
        let w = &mut self.w;
        self.bank
            .observation
            .predict_into(&w.x, t, &mut w.g, &mut w.m_all)?;
        let k = w.present.len();
        for (c, (&a, &y)) in w.present.iter().zip(&w.values).enumerate() {
            let m_all = w.m_all.as_slice();
            for (l, mt) in w.mt[c * n..(c + 1) * n].iter_mut().enumerate() {
                *mt = m_all[a + l * p];
            }
            w.nu[c] = self.bank.observation.residual(a, y, w.g[a]);
        }
        for (j, &b) in w.present.iter().enumerate() {
            for (i, &a) in w.present.iter().enumerate() {
                w.r[i + j * k] = self.r[a + b * p];
            }
        }
        let (nis, log_det, finite_out) = unrolled_sizes!(n, N => match k {
                1 => correct_kernel(Fixed::<N>, Fixed::<1>, 1.0, false, w),
                2 => correct_kernel(Fixed::<N>, Fixed::<2>, 1.0, false, w),
                3 => correct_kernel(Fixed::<N>, Fixed::<3>, 1.0, false, w),
                4 => correct_kernel(Fixed::<N>, Fixed::<4>, 1.0, false, w),
                k => correct_kernel(Fixed::<N>, Any(k), 1.0, false, w),
            },
            n => correct_kernel(Any(n), Any(k), 1.0, false, w))?;
        let log_likelihood = -0.5 * (nis + log_det + k as f64 * TAU.ln());
        if !finite_out {
            finite(w.s_out.as_slice(), "updated covariance")?;
            finite(w.x_out.as_slice(), "updated state entry")?;
        }
        if !(nis.is_finite() && log_likelihood.is_finite()) {
            return Err(Error::EstimateOutOfRange {
                what: "normalised innovation squared".into(),
            });
        }
        Ok(nis)
    }
}

/// A series' filter, fixed-size ([`super::fixed::FixedSeries`]) or general ([`SeriesFilter`]):
/// what the bank's passes need of it.
pub(super) trait Forward {
    /// The observed components `p`.
    fn components(&self) -> usize;

    /// Starts a series at `time` from the bank's prior.
    fn start(&mut self, time: f64);

    /// Starts a series at `time` from the estimate `(x, s)` (`s` column-major).
    fn resume(&mut self, x: &[f64], s: &[f64], time: f64);

    /// The estimate's time.
    fn time(&self) -> f64;

    /// The estimate `(X, S)`, `S` column-major.
    fn estimate(&self) -> (&[f64], &[f64]);

    /// The prediction of the last step: `Φ(t_k, t_{k−1})` (the identity for no step),
    /// `X_{k|k−1}`, `S_{k|k−1}`, column-major.
    fn prediction(&self) -> (&[f64], &[f64], &[f64]);

    /// The prediction to `t` and the update with `z` (`p` values, NaN missing): the update's
    /// NIS, `None` when every component is missing (the prediction alone). `t` not before the
    /// estimate's time. On an error the estimate is unchanged.
    fn step(&mut self, t: f64, z: &[f64]) -> Result<Option<f64>, Error>;

    /// Row `r` of `out` from the estimate and `nis`.
    #[inline(always)]
    fn write(&self, out: &mut RowsMut<'_>, r: usize, nis: Option<f64>) {
        let (x, s) = self.estimate();
        out.set(r, x, s, nis);
    }

    /// The filter over series `s` of `panel` into `out`.
    fn filter_series(
        &mut self,
        panel: &Panel<'_>,
        s: usize,
        mut out: RowsMut<'_>,
    ) -> Result<(), Error>
    where
        Self: Sized,
    {
        self.each_row(panel, s, |f, r, nis| {
            f.write(&mut out, r, nis);
            Ok(())
        })
    }

    /// Each row of series `s` of `panel` through [`Self::step`] from the prior at the series'
    /// first time, then `after(self, row within the series, NIS)`; an error names the row
    /// ([`Error::InBatch`]).
    fn each_row(
        &mut self,
        panel: &Panel<'_>,
        s: usize,
        mut after: impl FnMut(&mut Self, usize, Option<f64>) -> Result<(), Error>,
    ) -> Result<(), Error>
    where
        Self: Sized,
    {
        let (a, b) = (panel.offsets[s], panel.offsets[s + 1]);
        let p = self.components();
        if a == b {
            return Ok(());
        }
        self.start(panel.times[a]);
        for (r, row) in (a..b).enumerate() {
            let in_row = |source| Error::InBatch {
                index: r,
                source: Box::new(source),
            };
            let nis = self
                .step(panel.times[row], &panel.values[row * p..(row + 1) * p])
                .map_err(in_row)?;
            after(self, r, nis).map_err(|e| match e {
                e @ Error::InBatch { .. } => e,
                e => in_row(e),
            })?;
        }
        Ok(())
    }
}

impl<D: Dynamics> Forward for SeriesFilter<'_, D> {
    fn components(&self) -> usize {
        self.bank.observation.components()
    }

    fn start(&mut self, time: f64) {
        self.x.copy_from(&self.bank.state);
        self.s.copy_from(&self.bank.covariance);
        self.time = time;
        // Each series' numbers its own: no step length remembered from the one before.
        self.step = f64::NAN;
    }

    fn resume(&mut self, x: &[f64], s: &[f64], time: f64) {
        self.x.as_mut_slice().copy_from_slice(x);
        self.s.as_mut_slice().copy_from_slice(s);
        self.time = time;
    }

    fn time(&self) -> f64 {
        self.time
    }

    fn estimate(&self) -> (&[f64], &[f64]) {
        (self.x.as_slice(), self.s.as_slice())
    }

    fn prediction(&self) -> (&[f64], &[f64], &[f64]) {
        (
            self.w.phi.as_slice(),
            self.w.x.as_slice(),
            self.w.s.as_slice(),
        )
    }

    fn step(&mut self, t: f64, z: &[f64]) -> Result<Option<f64>, Error> {
        self.step_general(t, z)
    }
}

/// A series' row at `t` with values `z` after one at `previous` (NaN: none): a finite time,
/// not before the previous row's, and no infinite value (NaN is a missing component).
#[inline(always)]
pub(super) fn check_row(previous: f64, t: f64, z: &[f64]) -> Result<(), Error> {
    if !t.is_finite() {
        return Err(Error::NonFinite {
            what: "time",
            value: t,
        });
    }
    if t < previous {
        return Err(Error::InvalidParameter {
            name: Param::Time,
            value: t.to_string(),
            reason: format!("is before the previous row's {previous}"),
        });
    }
    if let Some(&value) = z.iter().find(|v| v.is_infinite()) {
        return Err(Error::NonFinite {
            what: "measurement value",
            value,
        });
    }
    Ok(())
}
