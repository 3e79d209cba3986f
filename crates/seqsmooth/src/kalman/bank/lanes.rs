//! A [`KalmanBank`]'s filter on `L` series at a time: the fixed-size path's arithmetic
//! ([`super::kernel`], Morrison (12.2.15)-(12.2.19), (15.4.10)-(15.4.11), Joseph's covariance
//! (12.3.7)) in structure of arrays, each lane a series of the task's, each with its own step
//! length (its own `Φ` and `Q`) and its own missing rows (a lane with every component missing
//! takes the prediction alone: a select, not a branch), refilled with the task's next series
//! when its series ends.
//!
//! What a lane does not take, [`FixedSeries`] (the same kernels at one lane) takes for that
//! step, from the lane's estimate and remembered step: a row with some components missing and
//! others present, a row the checks refuse, any step whose numbers a check would stop (not
//! finite, `V` not positive definite, an NIS too large to vouch for its log-likelihood) — that
//! step again, so its error is the one-series path's. When the task has no more series for a
//! free lane, the series still in lanes finish on [`FixedSeries`] too. A series' numbers are
//! the same on either path bit for bit (the same operations in the same order; each series
//! starts with no step length remembered), so they do not depend on its neighbours, on the
//! task, or on the split of the series into batches.
//!
//! The common step — every lane holding a series whose next row has every component present
//! and finite, at a later time, with a step length whose `Φ` and `Q` the lane has, and no
//! check stopping its numbers — takes a straight path (`Lanes::steady`: the same kernels on
//! the same inputs, without the per-lane choices, the checks one sum per lane); any other step
//! goes through `Lanes::advance`, from the same state.
//!
//! The lanes are compiled for x86-64 with AVX2 (four lanes an instruction, no fused
//! multiply-add: the same roundings) and taken where the processor has it.

// The loops index by position on purpose: entry by entry, lane by lane (the innermost, over
// the lanes, vectorises).
#![allow(clippy::needless_range_loop)]

mod steady;

use super::fixed::FixedSeries;
use super::kernel::{self, lane_of, set_lane, Column, Square};
use super::series::{check_row, Forward};
use super::{KalmanBank, Panel, RowsMut};
use crate::error::Error;
use crate::model::dynamics::Dynamics;
use crate::model::observation::Observation;
use crate::numeric::sigma::std_dev;
use nalgebra::{DMatrix, DVector};
use std::ops::Range;

/// The series advanced together (`f64` lanes).
pub(super) const LANES: usize = 4;

/// Whether the lanes run here: an x86-64 processor with AVX2 (four `f64` an instruction);
/// elsewhere the bank takes the one-series path, the same numbers.
pub(super) fn available() -> bool {
    std::arch::is_x86_feature_detected!("avx2")
}

/// The series a lane holds: its index, its next row and its end.
#[derive(Clone, Copy, Default)]
struct Held {
    series: usize,
    row: usize,
    end: usize,
}

/// `L` series' filters of a bank with `N` states and `K` components, in structure of arrays.
pub(super) struct Lanes<'a, D: Dynamics, const N: usize, const K: usize, const L: usize> {
    /// The one-series path (the same kernels at one lane).
    one: FixedSeries<'a, D, N>,
    bank: &'a KalmanBank<D>,
    /// The rows of `M` (`K`, every component).
    mt: [[f64; N]; K],
    /// `R` (`r[b][a]`).
    r: [[f64; K]; K],
    x: Column<N, L>,
    s: Square<N, L>,
    time: [f64; L],
    /// A time-invariant model's last step length (NaN: none), `Φ` and `Q` of it; otherwise
    /// the last step's.
    step: [f64; L],
    phi: Square<N, L>,
    q: Square<N, L>,
    held: [Option<Held>; L],
    dx: DVector<f64>,
    dxo: DVector<f64>,
    dphi: DMatrix<f64>,
    dq: DMatrix<f64>,
}

impl<'a, D: Dynamics, const N: usize, const K: usize, const L: usize> Lanes<'a, D, N, K, L> {
    /// The lanes of `bank` (`N` states, `K` components, `K ≤` [`super::fixed::MAX_COMPONENTS`]).
    pub(super) fn new(bank: &'a KalmanBank<D>, r: &'a [f64]) -> Self {
        debug_assert!(bank.dynamics.dimension() == N && bank.observation.components() == K);
        let one = FixedSeries::<D, N>::new(bank, r);
        let h = bank.observation.matrix();
        let mt = std::array::from_fn(|c| std::array::from_fn(|l| h[(c, l)]));
        let rr = std::array::from_fn(|b| std::array::from_fn(|a| r[a + b * K]));
        let x0 = one.x;
        let s0 = one.s;
        let mut lanes = Self {
            one,
            bank,
            mt,
            r: rr,
            x: [[0.0; L]; N],
            s: [[[0.0; L]; N]; N],
            time: [0.0; L],
            step: [f64::NAN; L],
            phi: [[[0.0; L]; N]; N],
            q: [[[0.0; L]; N]; N],
            held: [None; L],
            dx: DVector::zeros(N),
            dxo: DVector::zeros(N),
            dphi: DMatrix::zeros(N, N),
            dq: DMatrix::zeros(N, N),
        };
        for e in 0..L {
            lanes.set(e, &x0, &s0);
        }
        lanes
    }

    /// Lane `e`'s estimate from `(x, s)`.
    fn set(&mut self, e: usize, x: &[f64; N], s: &[[f64; N]; N]) {
        for i in 0..N {
            self.x[i][e] = x[i];
        }
        set_lane(&mut self.s, e, s);
    }

    /// The filter over the series `range` of `panel` into `out` (the rows from `base`): the
    /// first failing series and its error. Compiled for AVX2 (four lanes an instruction):
    /// only where the processor has it ([`available`]).
    pub(super) fn filter(
        &mut self,
        panel: &Panel<'_>,
        range: Range<usize>,
        out: &mut RowsMut<'_>,
        base: usize,
    ) -> Option<(usize, Error)> {
        assert!(available(), "the lanes need AVX2");
        // SAFETY: the processor has AVX2 (checked above), the one feature it enables.
        unsafe { self.filter_avx2(panel, range, out, base) }
    }

    /// [`Self::filter`] with AVX2.
    #[target_feature(enable = "avx2")]
    fn filter_avx2(
        &mut self,
        panel: &Panel<'_>,
        range: Range<usize>,
        out: &mut RowsMut<'_>,
        base: usize,
    ) -> Option<(usize, Error)> {
        self.filter_lanes(panel, range, out, base)
    }

    /// [`Self::filter`]'s body.
    #[inline(always)]
    fn filter_lanes(
        &mut self,
        panel: &Panel<'_>,
        range: Range<usize>,
        out: &mut RowsMut<'_>,
        base: usize,
    ) -> Option<(usize, Error)> {
        let mut failure: Option<(usize, Error)> = None;
        let mut fail = |s: usize, e: Error| {
            if failure.as_ref().is_none_or(|(f, _)| s < *f) {
                failure = Some((s, e));
            }
        };
        let mut next = range.start;
        loop {
            for e in 0..L {
                while self.held[e].is_none() && next < range.end {
                    let s = next;
                    next += 1;
                    let (a, b) = (panel.offsets[s], panel.offsets[s + 1]);
                    if a < b {
                        let (x0, s0) = (self.one.x0, self.one.s0);
                        self.set(e, &x0, &s0);
                        self.time[e] = panel.times[a];
                        self.step[e] = f64::NAN;
                        self.held[e] = Some(Held {
                            series: s,
                            row: a,
                            end: b,
                        });
                    }
                }
            }
            let count = self.held.iter().flatten().count();
            if count < L {
                // No series left for the free lanes: the others finish one at a time.
                for e in 0..L {
                    if let Some(held) = self.held[e].take() {
                        self.hand_over(e);
                        if let Err(err) = self.alone(panel, held, held.end, out, base) {
                            fail(held.series, err);
                        }
                    }
                }
                return failure;
            }
            // Every lane holds a series: the steps before the first of them ends.
            let run = self
                .held
                .iter()
                .flatten()
                .map(|h| h.end - h.row)
                .min()
                .unwrap_or(0);
            for _ in 0..run {
                if self.steady(panel, out, base, None) {
                    continue;
                }
                let mut failed = false;
                for (e, err) in self.advance(panel, out, base, None).into_iter().enumerate() {
                    if let Some(err) = err {
                        let held = self.held[e].take().expect("a failing lane holds a series");
                        fail(held.series, err);
                        failed = true;
                    }
                }
                if failed {
                    break;
                }
            }
        }
    }

    /// Lane `e`'s estimate and remembered step into the one-series path.
    fn hand_over(&mut self, e: usize) {
        let one = &mut self.one;
        one.x = std::array::from_fn(|i| self.x[i][e]);
        one.s = lane_of(&self.s, e);
        one.time = self.time[e];
        one.step = self.step[e];
        one.phi_step = lane_of(&self.phi, e);
        one.q_step = lane_of(&self.q, e);
    }

    /// The one-series path's estimate and remembered step into lane `e`.
    fn take_back(&mut self, e: usize) {
        let (x, s) = (self.one.x, self.one.s);
        self.set(e, &x, &s);
        self.time[e] = self.one.time;
        self.step[e] = self.one.step;
        set_lane(&mut self.phi, e, &self.one.phi_step);
        set_lane(&mut self.q, e, &self.one.q_step);
    }

    /// The rows of `held` before `until` on the one-series path (handed over), into `out`.
    fn alone(
        &mut self,
        panel: &Panel<'_>,
        held: Held,
        until: usize,
        out: &mut RowsMut<'_>,
        base: usize,
    ) -> Result<Option<f64>, Error> {
        let mut last = None;
        for row in held.row..until {
            let z = &panel.values[row * K..(row + 1) * K];
            let nis = self
                .one
                .step(panel.times[row], z)
                .map_err(|source| Error::InBatch {
                    index: row - panel.offsets[held.series],
                    source: Box::new(source),
                })?;
            self.one.write(out, row - base, nis);
            last = nis;
        }
        Ok(last)
    }

    /// A step of every lane that holds a series (the others stay as they are): into `out`
    /// its rows (the filter), or into `keep` the step (the smoother's forward pass): each
    /// lane's error.
    #[inline(always)]
    fn advance(
        &mut self,
        panel: &Panel<'_>,
        out: &mut RowsMut<'_>,
        base: usize,
        mut keep: Option<&mut Step<N, L>>,
    ) -> [Option<Error>; L] {
        let bank = self.bank;
        let noise = bank.noise.as_ref();
        let invariant = self.one.invariant;
        let held = self.held;
        let mut t = self.time;
        let mut z = [[0.0; L]; K];
        // Per lane: no step (the same time), a step taken alone, components present, a
        // new `Φ` (from the model: its `X_{k|k−1}` too).
        let (mut same, mut alone, mut present, mut new) =
            ([false; L], [false; L], [false; L], [false; L]);
        let mut xp_new = [[0.0; L]; N];
        for e in 0..L {
            let Some(Held { row, .. }) = held[e] else {
                same[e] = true;
                continue;
            };
            let (te, values) = (panel.times[row], &panel.values[row * K..(row + 1) * K]);
            t[e] = te;
            let k = values.iter().filter(|v| !v.is_nan()).count();
            if (k != 0 && k != K) || check_row(self.time[e], te, values).is_err() {
                alone[e] = true;
                continue;
            }
            present[e] = k == K;
            if present[e] {
                for c in 0..K {
                    z[c][e] = values[c];
                }
            }
            let dt = te - self.time[e];
            if te == self.time[e] {
                same[e] = true;
            } else if !(invariant && dt == self.step[e]) {
                // A step length the lane has not the `Φ` of: the model's, as the one-series
                // path takes it.
                self.dx
                    .as_mut_slice()
                    .copy_from_slice(&std::array::from_fn::<f64, N, _>(|i| self.x[i][e]));
                let propagated = bank.dynamics.propagate_into(
                    &self.dx,
                    self.time[e],
                    te,
                    &mut self.dxo,
                    &mut self.dphi,
                );
                let covariance = match (propagated, noise) {
                    (Err(_), _) => Err(()),
                    (Ok(()), Some(q)) => q
                        .covariance_into(self.time[e], te, &mut self.dq)
                        .map_err(|_| ()),
                    (Ok(()), None) => Ok(()),
                };
                if covariance.is_err() {
                    alone[e] = true;
                    continue;
                }
                new[e] = true;
                for i in 0..N {
                    xp_new[i][e] = self.dxo[i];
                    for j in 0..N {
                        self.phi[j][i][e] = self.dphi[(i, j)];
                        if noise.is_some() {
                            self.q[j][i][e] = self.dq[(i, j)];
                        }
                    }
                }
                if invariant {
                    self.step[e] = dt;
                }
            }
        }
        // The prediction of every lane, then each lane's own: the same time, the estimate; a
        // new `Φ`, the model's `X_{k|k−1}`.
        let mut xp = kernel::propagate(&self.phi, &self.x);
        let mut sp = kernel::carry(&self.phi, &self.s, noise.map(|_| &self.q));
        for i in 0..N {
            for e in 0..L {
                xp[i][e] = if same[e] {
                    self.x[i][e]
                } else if new[e] {
                    xp_new[i][e]
                } else {
                    xp[i][e]
                };
            }
            for j in 0..N {
                for e in 0..L {
                    sp[j][i][e] = if same[e] {
                        self.s[j][i][e]
                    } else {
                        sp[j][i][e]
                    };
                }
            }
        }
        // The update with every component of the lanes that have them.
        let g = kernel::observe(&self.mt, &xp);
        let mut nu = [[0.0; L]; K];
        for c in 0..K {
            for e in 0..L {
                nu[c][e] = if present[e] { z[c][e] - g[c][e] } else { 0.0 };
            }
        }
        let up = kernel::correct(&self.mt, &self.r, &xp, &sp, &nu);
        // A lane whose numbers a check would stop takes the step alone.
        let mut fine = [true; L];
        for e in 0..L {
            let mut ok = xp.iter().fold(true, |ok, v| ok & v[e].is_finite());
            ok &= sp
                .as_flattened()
                .iter()
                .fold(true, |ok, v| ok & v[e].is_finite());
            if present[e] {
                ok &= g.iter().fold(true, |ok, v| ok & v[e].is_finite());
                ok &= up.positive[e] & (up.nis[e] < 1e300) & up.nis[e].is_finite();
                ok &= up.lv.iter().enumerate().all(|(c, v)| v[c][e].is_finite());
                ok &= up.x.iter().fold(true, |ok, v| ok & v[e].is_finite());
                ok &=
                    up.s.as_flattened()
                        .iter()
                        .fold(true, |ok, v| ok & v[e].is_finite());
            }
            fine[e] = ok;
            alone[e] |= !ok;
        }
        for i in 0..N {
            for e in 0..L {
                self.x[i][e] = if alone[e] {
                    self.x[i][e]
                } else if present[e] {
                    up.x[i][e]
                } else {
                    xp[i][e]
                };
            }
            for j in 0..N {
                for e in 0..L {
                    self.s[j][i][e] = if alone[e] {
                        self.s[j][i][e]
                    } else if present[e] {
                        up.s[j][i][e]
                    } else {
                        sp[j][i][e]
                    };
                }
            }
        }
        if let Some(keep) = keep.as_deref_mut() {
            for j in 0..N {
                for i in 0..N {
                    for e in 0..L {
                        let unit = if i == j { 1.0 } else { 0.0 };
                        keep.phi[j][i][e] = if same[e] { unit } else { self.phi[j][i][e] };
                    }
                }
            }
            (keep.xp, keep.sp, keep.x, keep.s) = (xp, sp, self.x, self.s);
            for e in 0..L {
                keep.nis[e] = present[e].then_some(up.nis[e]);
            }
        }
        let sigma: [[f64; L]; N] =
            std::array::from_fn(|i| std::array::from_fn(|e| std_dev(self.s[i][i][e])));
        let mut errors = [const { None }; L];
        for e in 0..L {
            let Some(held) = held[e] else {
                continue;
            };
            let row = held.row;
            let r = row - base;
            if alone[e] {
                if new[e] && !fine[e] {
                    // The step's `Φ` is the model's again on the one-series path.
                    self.step[e] = f64::NAN;
                }
                self.hand_over(e);
                match self.alone(panel, held, row + 1, out, base) {
                    Ok(nis) => {
                        self.take_back(e);
                        if let Some(keep) = keep.as_deref_mut() {
                            keep.take(e, &self.one, nis);
                        }
                    }
                    Err(err) => {
                        errors[e] = Some(err);
                        continue;
                    }
                }
            } else {
                self.time[e] = t[e];
                if keep.is_none() {
                    for i in 0..N {
                        out.state[r * N + i] = self.x[i][e];
                        out.sigma[r * N + i] = sigma[i][e];
                    }
                    out.put_nis(r, present[e].then_some(up.nis[e]));
                }
            }
            let h = self.held[e].as_mut().expect("every lane holds");
            h.row += 1;
            if h.row == h.end {
                self.held[e] = None;
            }
        }
        errors
    }
}

/// The one-series smoother of a series (by its index) into its rows.
pub(super) type Alone<'f, D, const N: usize> =
    dyn FnMut(&mut FixedSeries<'_, D, N>, usize, RowsMut<'_>) -> Result<(), Error> + 'f;

/// A step of `L` lanes kept for the backward pass: the prediction into it (`Φ`, the identity
/// for no step; `X_{k|k−1}`, `S_{k|k−1}`), the filtered estimate and the update's NIS.
#[derive(Clone, Copy)]
pub(super) struct Step<const N: usize, const L: usize> {
    phi: Square<N, L>,
    xp: Column<N, L>,
    sp: Square<N, L>,
    x: Column<N, L>,
    s: Square<N, L>,
    nis: [Option<f64>; L],
}

impl<const N: usize, const L: usize> Step<N, L> {
    /// Lane `e` from the one-series path's last step.
    fn take<D: Dynamics>(&mut self, e: usize, one: &FixedSeries<'_, D, N>, nis: Option<f64>) {
        let (phi, xp, sp) = one.prediction();
        let (x, s) = one.estimate();
        for i in 0..N {
            self.xp[i][e] = xp[i];
            self.x[i][e] = x[i];
            for j in 0..N {
                self.phi[j][i][e] = phi[i + j * N];
                self.sp[j][i][e] = sp[i + j * N];
                self.s[j][i][e] = s[i + j * N];
            }
        }
        self.nis[e] = nis;
    }
}

impl<D: Dynamics, const N: usize, const K: usize, const L: usize> Lanes<'_, D, N, K, L> {
    /// The Rauch–Tung–Striebel smoother over the series `range` of `panel` into `out` (the
    /// rows from `base`), `L` consecutive series at a time (the lanes past the last series
    /// idle): the forward pass of the group kept a step at a time in `steps`, then the
    /// backward recursion ([`kernel::smooth`]) from each series' last row. A series whose
    /// backward step a check would stop goes again, whole, through `alone` (the one-series
    /// smoother), whose error is the one given. The first failing series and its error.
    pub(super) fn smooth(
        &mut self,
        panel: &Panel<'_>,
        range: Range<usize>,
        out: &mut RowsMut<'_>,
        base: usize,
        steps: &mut Vec<Step<N, L>>,
        alone: &mut Alone<'_, D, N>,
    ) -> Option<(usize, Error)> {
        assert!(available(), "the lanes need AVX2");
        // SAFETY: the processor has AVX2 (checked above), the one feature it enables.
        unsafe { self.smooth_avx2(panel, range, out, base, steps, alone) }
    }

    /// [`Self::smooth`] with AVX2.
    #[target_feature(enable = "avx2")]
    fn smooth_avx2(
        &mut self,
        panel: &Panel<'_>,
        range: Range<usize>,
        out: &mut RowsMut<'_>,
        base: usize,
        steps: &mut Vec<Step<N, L>>,
        alone: &mut Alone<'_, D, N>,
    ) -> Option<(usize, Error)> {
        self.smooth_lanes(panel, range, out, base, steps, alone)
    }

    /// [`Self::smooth`]'s body.
    #[inline(always)]
    fn smooth_lanes(
        &mut self,
        panel: &Panel<'_>,
        range: Range<usize>,
        out: &mut RowsMut<'_>,
        base: usize,
        steps: &mut Vec<Step<N, L>>,
        alone: &mut Alone<'_, D, N>,
    ) -> Option<(usize, Error)> {
        let mut failure: Option<(usize, Error)> = None;
        let mut fail = |s: usize, e: Error| {
            if failure.as_ref().is_none_or(|(f, _)| s < *f) {
                failure = Some((s, e));
            }
        };
        for first in range.clone().step_by(L) {
            // The group's series, each from the prior at its first time.
            let mut len = [0; L];
            let mut gone = [true; L];
            for e in 0..L {
                let (x0, s0) = (self.one.x0, self.one.s0);
                self.set(e, &x0, &s0);
                self.step[e] = f64::NAN;
                self.held[e] = None;
                let s = first + e;
                if s < range.end && panel.offsets[s] < panel.offsets[s + 1] {
                    let (a, b) = (panel.offsets[s], panel.offsets[s + 1]);
                    self.time[e] = panel.times[a];
                    self.held[e] = Some(Held {
                        series: s,
                        row: a,
                        end: b,
                    });
                    (len[e], gone[e]) = (b - a, false);
                }
            }
            let rows = len.iter().copied().max().unwrap_or(0);
            steps.clear();
            for _ in 0..rows {
                let mut step = Step {
                    phi: [[[0.0; L]; N]; N],
                    xp: [[0.0; L]; N],
                    sp: [[[0.0; L]; N]; N],
                    x: [[0.0; L]; N],
                    s: [[[0.0; L]; N]; N],
                    nis: [None; L],
                };
                if self.steady(panel, out, base, Some(&mut step)) {
                    steps.push(step);
                    continue;
                }
                let errors = self.advance(panel, out, base, Some(&mut step));
                for (e, err) in errors.into_iter().enumerate() {
                    if let Some(err) = err {
                        fail(first + e, err);
                        (self.held[e], gone[e]) = (None, true);
                    }
                }
                steps.push(step);
            }
            // The backward pass: each lane from its series' last row.
            let (mut x, mut s) = (self.x, self.s);
            for k in (0..rows).rev() {
                let now = &steps[k];
                let (bx, bs, positive) = match steps.get(k + 1) {
                    Some(next) => {
                        kernel::smooth((&now.x, &now.s), (&next.phi, &next.xp, &next.sp), (&x, &s))
                    }
                    None => (now.x, now.s, [true; L]),
                };
                let mut last = [false; L];
                let mut back = [false; L];
                for e in 0..L {
                    if gone[e] || k >= len[e] {
                        continue;
                    }
                    last[e] = k + 1 == len[e];
                    if !last[e] {
                        let fine = positive[e]
                            & bx.iter().fold(true, |ok, v| ok & v[e].is_finite())
                            & bs.as_flattened()
                                .iter()
                                .fold(true, |ok, v| ok & v[e].is_finite());
                        if !fine {
                            gone[e] = true;
                            let series = first + e;
                            let (a, b) = (
                                panel.offsets[series] - base,
                                panel.offsets[series + 1] - base,
                            );
                            let rows = RowsMut {
                                state: &mut out.state[a * N..b * N],
                                sigma: &mut out.sigma[a * N..b * N],
                                nis: &mut out.nis[a..b],
                            };
                            if let Err(err) = alone(&mut self.one, series, rows) {
                                fail(series, err);
                            }
                            continue;
                        }
                        back[e] = true;
                    }
                }
                for i in 0..N {
                    for e in 0..L {
                        x[i][e] = if last[e] {
                            now.x[i][e]
                        } else if back[e] {
                            bx[i][e]
                        } else {
                            x[i][e]
                        };
                    }
                    for j in 0..N {
                        for e in 0..L {
                            s[j][i][e] = if last[e] {
                                now.s[j][i][e]
                            } else if back[e] {
                                bs[j][i][e]
                            } else {
                                s[j][i][e]
                            };
                        }
                    }
                }
                let sigma: [[f64; L]; N] =
                    std::array::from_fn(|i| std::array::from_fn(|e| std_dev(s[i][i][e])));
                for e in 0..L {
                    if last[e] || back[e] {
                        let r = panel.offsets[first + e] + k - base;
                        for i in 0..N {
                            out.state[r * N + i] = x[i][e];
                            out.sigma[r * N + i] = sigma[i][e];
                        }
                        out.put_nis(r, now.nis[e]);
                    }
                }
            }
        }
        failure
    }
}
