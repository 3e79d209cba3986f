//! One series of a [`KalmanBank`] with the state size `N ≤ 9` and at most
//! [`MAX_COMPONENTS`] observed components: the Kalman filter's prediction and update (Morrison
//! (12.2.15)-(12.2.19), driving noise (15.4.10)-(15.4.11), Joseph's covariance (12.3.7)) with
//! the series' state, covariance, prediction and every scratch in arrays on the stack, the
//! sizes compile-time constants (`N`, and `K` the components present), plain loops that
//! unroll, nothing allocated per step.
//!
//! The arithmetic is [`super::kernel`]'s at one lane (the lane path, [`super::lanes`], runs
//! the same code on `L` series at once), which is the general path's
//! ([`SeriesFilter`](super::series::SeriesFilter), the filter's `carry` and `correct_kernel`)
//! operation for operation, each sum in the same order:
//! `Φ S Φᵀ + Q` as `(S Φᵀ)ᵀ Φᵀ`; `U = S Mᵀ`, `V = M U + R = L D Lᵀ`, `H = U V⁻¹`,
//! `NIS = Σ z_c² / D_c` with `z = L⁻¹ ν`, `X = X_{k|k−1} + H ν`, Joseph's `S` with `I − H M`
//! applied from each side; the general kernels skip the zero entries of `Φ` and `M`, which
//! adds nothing to a finite sum, so the numbers are meant to be the general path's (a zero's
//! sign aside); what the tests hold them to is one [`KalmanFilter`](crate::kalman::KalmanFilter)
//! per series within 1e-12 relative (`tests/kalman_bank.rs`, both sides of the size cut-off),
//! not bit for bit. The same mathematics as `kalman::correct`'s kernels, written again on
//! stack arrays in lanes: one kernel over slices for both is the open step.
//! What differs is the layout: no work buffers on the heap, no matrix `M` per step, and
//! `ln det V` (for the log-likelihood's finiteness) only when the pivots cannot vouch for it.

// The loops index by position on purpose: each sum in the general kernels' order, over
// arrays whose sizes are constants (the loops unroll).
#![allow(clippy::needless_range_loop)]

use super::super::correct::finite;
use super::kernel::{self, one, only};
use super::series::{check_row, Forward};
use super::{KalmanBank, RowsMut};
use crate::error::{Error, Param};
use crate::linalg::dense::{all_finite, log_det};
use crate::model::dynamics::Dynamics;
use crate::model::observation::Observation;
use crate::numeric::sigma::std_dev;
use nalgebra::{DMatrix, DVector};
use std::f64::consts::TAU;

/// The most observed components the fixed-size path takes (more: the general path).
pub(super) const MAX_COMPONENTS: usize = 3;

/// A series' filter with `N` states on the stack: its estimate `(x, s)` at `time` and, after
/// a step, the step's prediction (`phi`, `xp`, `sp`).
pub(super) struct FixedSeries<'a, D: Dynamics, const N: usize> {
    bank: &'a KalmanBank<D>,
    p: usize,
    /// `M` by rows: `m[c][l] = M(c, l)`.
    m: [[f64; N]; MAX_COMPONENTS],
    /// `R`, `p × p`, column-major.
    r: &'a [f64],
    pub(super) x0: [f64; N],
    pub(super) s0: [[f64; N]; N],
    pub(super) x: [f64; N],
    /// Column-major: `s[j][i] = S(i, j)`.
    pub(super) s: [[f64; N]; N],
    pub(super) time: f64,
    phi: [[f64; N]; N],
    xp: [f64; N],
    sp: [[f64; N]; N],
    /// For a time-invariant model, the last step's length and its `Φ` and `Q` (NaN: none).
    pub(super) invariant: bool,
    pub(super) step: f64,
    pub(super) phi_step: [[f64; N]; N],
    pub(super) q_step: [[f64; N]; N],
    /// The model's buffers for a new step length.
    dx: DVector<f64>,
    dxo: DVector<f64>,
    dphi: DMatrix<f64>,
    dq: DMatrix<f64>,
}

/// `n × n` column-major from a slice.
fn square<const N: usize>(from: &[f64]) -> [[f64; N]; N] {
    let mut out = [[0.0; N]; N];
    out.as_flattened_mut().copy_from_slice(&from[..N * N]);
    out
}

fn identity<const N: usize>() -> [[f64; N]; N] {
    let mut out = [[0.0; N]; N];
    for (i, column) in out.iter_mut().enumerate() {
        column[i] = 1.0;
    }
    out
}

impl<'a, D: Dynamics, const N: usize> FixedSeries<'a, D, N> {
    /// A filter of `bank` (not started); `N` is the bank's state size and it has at most
    /// [`MAX_COMPONENTS`] components.
    pub(super) fn new(bank: &'a KalmanBank<D>, r: &'a [f64]) -> Self {
        let p = bank.observation.components();
        debug_assert!(bank.dynamics.dimension() == N && p <= MAX_COMPONENTS);
        let mut m = [[0.0; N]; MAX_COMPONENTS];
        let h = bank.observation.matrix();
        for (c, row) in m.iter_mut().enumerate().take(p) {
            for (l, v) in row.iter_mut().enumerate() {
                *v = h[(c, l)];
            }
        }
        let mut x0 = [0.0; N];
        x0.copy_from_slice(bank.state.as_slice());
        let s0 = square(bank.covariance.as_slice());
        Self {
            bank,
            p,
            m,
            r,
            x0,
            s0,
            x: x0,
            s: s0,
            time: f64::NAN,
            phi: identity(),
            xp: x0,
            sp: s0,
            invariant: bank.dynamics.is_time_invariant()
                && bank.noise.as_ref().is_none_or(|q| q.is_time_invariant()),
            step: f64::NAN,
            phi_step: identity(),
            q_step: [[0.0; N]; N],
            dx: DVector::zeros(N),
            dxo: DVector::zeros(N),
            dphi: DMatrix::zeros(N, N),
            dq: DMatrix::zeros(N, N),
        }
    }

    /// `X_{k|k−1}`, `S_{k|k−1}` and `Φ` (the general path's `predict`).
    #[inline(always)]
    fn predict(&mut self, t: f64) -> Result<(), Error> {
        if t == self.time {
            self.xp = self.x;
            self.sp = self.s;
            self.phi = identity();
            return Ok(());
        }
        let bank = self.bank;
        let dt = t - self.time;
        let noise = bank.noise.is_some();
        if self.invariant && dt == self.step {
            self.phi = self.phi_step;
            self.xp = kernel::propagate(&one(&self.phi_step), &self.x.map(|v| [v])).map(|v| v[0]);
            if let Some(&value) = self.xp.iter().find(|v| !v.is_finite()) {
                return Err(Error::NonFinite {
                    what: "propagated state entry",
                    value,
                });
            }
        } else {
            self.dx.as_mut_slice().copy_from_slice(&self.x);
            bank.dynamics
                .propagate_into(&self.dx, self.time, t, &mut self.dxo, &mut self.dphi)?;
            self.xp.copy_from_slice(self.dxo.as_slice());
            self.phi = square(self.dphi.as_slice());
            if let Some(q) = &bank.noise {
                q.covariance_into(self.time, t, &mut self.dq)?;
            }
            if self.invariant {
                self.phi_step = self.phi;
                if noise {
                    self.q_step = square(self.dq.as_slice());
                }
                self.step = dt;
            }
        }
        let q = if !noise {
            None
        } else if self.invariant {
            Some(self.q_step)
        } else {
            Some(square(self.dq.as_slice()))
        };
        self.sp = only(&kernel::carry(
            &one(&self.phi),
            &one(&self.s),
            q.as_ref().map(one).as_ref(),
        ));
        if all_finite(self.sp.as_flattened()) {
            Ok(())
        } else {
            finite(self.sp.as_flattened(), "predicted covariance")
        }
    }

    /// The correction of the prediction with the present components of `z`: the NIS.
    #[inline(always)]
    fn correct(&mut self, z: &[f64]) -> Result<f64, Error> {
        let p = self.p;
        let g = kernel::observe(&self.m, &self.xp.map(|v| [v])).map(|v| v[0]);
        if let Some(&v) = g[..p].iter().find(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "predicted observation",
                value: v,
            });
        }
        let mut present = [0; MAX_COMPONENTS];
        let mut nu = [0.0; MAX_COMPONENTS];
        let mut k = 0;
        for (a, &y) in z.iter().enumerate() {
            if !y.is_nan() {
                present[k] = a;
                nu[k] = self.bank.observation.residual(a, y, g[a]);
                k += 1;
            }
        }
        match k {
            1 => self.correct_k::<1>(&present, &nu),
            2 => self.correct_k::<2>(&present, &nu),
            _ => self.correct_k::<3>(&present, &nu),
        }
    }

    /// The correction with `K` components present (`present`, their residuals `nu`): the
    /// filter's `correct_kernel` (no fading) on arrays, each sum in its order.
    #[inline(always)]
    fn correct_k<const K: usize>(
        &mut self,
        present: &[usize; MAX_COMPONENTS],
        nu: &[f64; MAX_COMPONENTS],
    ) -> Result<f64, Error> {
        let p = self.p;
        // Mᵀ of the present rows (`mt[c]` row `present[c]` of M) and R on them (`r[b][a]`).
        let mut mt = [[0.0; N]; K];
        let mut r = [[0.0; K]; K];
        for c in 0..K {
            mt[c] = self.m[present[c]];
            for (i, v) in r[c].iter_mut().enumerate() {
                *v = self.r[present[i] + present[c] * p];
            }
        }
        let nu1 = std::array::from_fn(|c| [nu[c]]);
        let out = kernel::correct::<N, K, 1>(&mt, &r, &self.xp.map(|v| [v]), &one(&self.sp), &nu1);
        let lv = out.lv.map(|column| column.map(|v| v[0]));
        if !out.positive[0] {
            let v = out.v.map(|column| column.map(|v| v[0]));
            return Err(Error::InvalidParameter {
                name: Param::InnovationCovariance,
                value: format!("{:?}", DMatrix::from_column_slice(K, K, v.as_flattened())),
                reason: "is not positive definite: the observation adds nothing the filter \
                         can weigh (a perfect observation of a component already known exactly)"
                    .into(),
            });
        }
        let (x_out, s_out, nis) = (out.x.map(|v| v[0]), only(&out.s), out.nis[0]);
        if !(all_finite(&x_out) & all_finite(s_out.as_flattened())) {
            finite(s_out.as_flattened(), "updated covariance")?;
            finite(&x_out, "updated state entry")?;
        }
        // The log-likelihood −(NIS + ln det V + k ln 2π)/2 is finite when the NIS is and the
        // pivots are finite (each |ln D_c| < 746); otherwise computed as the filter does.
        let pivots_finite = (0..K).all(|c| lv[c][c].is_finite());
        if !(nis.is_finite() && pivots_finite && nis < 1e300) {
            let log_likelihood = -0.5 * (nis + log_det(K, lv.as_flattened()) + K as f64 * TAU.ln());
            if !(nis.is_finite() && log_likelihood.is_finite()) {
                return Err(Error::EstimateOutOfRange {
                    what: "normalised innovation squared".into(),
                });
            }
        }
        self.x = x_out;
        self.s = s_out;
        Ok(nis)
    }
}

impl<D: Dynamics, const N: usize> Forward for FixedSeries<'_, D, N> {
    fn components(&self) -> usize {
        self.p
    }

    fn start(&mut self, time: f64) {
        self.x = self.x0;
        self.s = self.s0;
        self.time = time;
        // Each series' numbers its own: no step length remembered from the one before.
        self.step = f64::NAN;
    }

    fn resume(&mut self, x: &[f64], s: &[f64], time: f64) {
        self.x.copy_from_slice(x);
        self.s = square(s);
        self.time = time;
    }

    fn time(&self) -> f64 {
        self.time
    }

    fn estimate(&self) -> (&[f64], &[f64]) {
        (&self.x, self.s.as_flattened())
    }

    fn prediction(&self) -> (&[f64], &[f64], &[f64]) {
        (self.phi.as_flattened(), &self.xp, self.sp.as_flattened())
    }

    #[inline(always)]
    fn write(&self, out: &mut RowsMut<'_>, r: usize, nis: Option<f64>) {
        out.state[r * N..(r + 1) * N].copy_from_slice(&self.x);
        let sigma = &mut out.sigma[r * N..(r + 1) * N];
        for i in 0..N {
            sigma[i] = std_dev(self.s[i][i]);
        }
        out.put_nis(r, nis);
    }

    #[inline(always)]
    fn step(&mut self, t: f64, z: &[f64]) -> Result<Option<f64>, Error> {
        check_row(self.time, t, z)?;
        self.predict(t)?;
        if z.iter().all(|v| v.is_nan()) {
            self.x = self.xp;
            self.s = self.sp;
            self.time = t;
            return Ok(None);
        }
        let nis = self.correct(z)?;
        self.time = t;
        Ok(Some(nis))
    }
}
