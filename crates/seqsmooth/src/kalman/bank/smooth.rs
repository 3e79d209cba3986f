//! The smoothers of a [`KalmanBank`](super::KalmanBank)'s series (Rauch, Tung and Striebel
//! 1965; beyond Morrison's book): the backward step of [`crate::kalman::fixed_lag`],
//!
//! `C_k = S_{k|k} Φᵀ S_{k+1|k}⁻¹`, `X_{k|N} = X_{k|k} + C_k (X_{k+1|N} − X_{k+1|k})`,
//! `S_{k|N} = S_{k|k} + C_k (S_{k+1|N} − S_{k+1|k}) C_kᵀ`,
//!
//! over the whole series from its last row (fixed interval: [`Backward`], in place on flat
//! arrays, the size a compile-time constant), or over the last `L` rows (fixed lag: the
//! library's own `step` and `Map::then`).

use super::super::fixed_lag::{step, Map, Row};
use super::backward::Backward;
use super::series::Forward;
use super::{Panel, RowsMut};
use crate::error::Error;
use nalgebra::{DMatrix, DVector};
use std::collections::VecDeque;

/// The filtered estimate of the row just updated.
fn filtered<F: Forward>(f: &F, nis: Option<f64>) -> Row {
    let (x, s) = f.estimate();
    let n = x.len();
    Row {
        time: f.time(),
        state: DVector::from_column_slice(x),
        covariance: DMatrix::from_column_slice(n, n, s),
        nis,
    }
}

/// A row's smoothed estimate `point` into `out`.
fn emit(out: &mut RowsMut<'_>, r: usize, point: &Map, nis: Option<f64>) {
    out.set(r, point.a.as_slice(), point.d.as_slice(), nis);
}

/// A series' forward pass kept for its backward pass, flat: each row's filtered estimate and
/// the prediction into it. Reused from series to series (its memory that of the longest).
#[derive(Default)]
pub(super) struct Kept {
    xs: Vec<f64>,
    ss: Vec<f64>,
    phis: Vec<f64>,
    xps: Vec<f64>,
    sps: Vec<f64>,
    nis: Vec<Option<f64>>,
}

/// The fixed-interval smoother over series `s`: the forward pass kept (each row's filtered
/// estimate and the prediction into it, flat, in `kept`), then the backward recursion from
/// the last row ([`Backward`], in place).
pub(super) fn rts_series<F: Forward>(
    f: &mut F,
    kept: &mut Kept,
    panel: &Panel<'_>,
    s: usize,
    mut out: RowsMut<'_>,
) -> Result<(), Error> {
    let Kept {
        xs,
        ss,
        phis,
        xps,
        sps,
        nis,
    } = kept;
    for v in [&mut *xs, &mut *ss, &mut *phis, &mut *xps, &mut *sps] {
        v.clear();
    }
    nis.clear();
    f.each_row(panel, s, |f, _, v| {
        let (phi, x, s) = f.prediction();
        phis.extend_from_slice(phi);
        xps.extend_from_slice(x);
        sps.extend_from_slice(s);
        let (x, s) = f.estimate();
        xs.extend_from_slice(x);
        ss.extend_from_slice(s);
        nis.push(v);
        Ok(())
    })?;
    let rows = nis.len();
    if rows == 0 {
        return Ok(());
    }
    let n = xs.len() / rows;
    let nn = n * n;
    let last = rows - 1;
    out.set(last, &xs[last * n..], &ss[last * nn..], nis[last]);
    let mut back = Backward::new(n);
    for k in (0..last).rev() {
        let (x, x_next) = xs.split_at_mut((k + 1) * n);
        let (sk, s_next) = ss.split_at_mut((k + 1) * nn);
        let next = k + 1;
        back.step(
            (&mut x[k * n..], &mut sk[k * nn..]),
            (
                &phis[next * nn..(next + 1) * nn],
                &xps[next * n..(next + 1) * n],
                &sps[next * nn..(next + 1) * nn],
            ),
            (&x_next[..n], &s_next[..nn]),
            next,
        )?;
        out.set(k, &x[k * n..], &sk[k * nn..], nis[k]);
    }
    Ok(())
}

/// The fixed-lag smoother over series `s`: each row's estimate from the `lag` rows after it
/// (the backward recursion over them, from the newest), given as soon as they are in, from
/// the last `lag + 1` rows and the `lag` backward steps between them; the last `lag` rows of
/// the series from all of its rows.
pub(super) fn fixed_lag_series<F: Forward>(
    f: &mut F,
    panel: &Panel<'_>,
    s: usize,
    lag: usize,
    mut out: RowsMut<'_>,
) -> Result<(), Error> {
    // The rows not yet given (with their index in the series) and the steps between them.
    let mut rows: VecDeque<(usize, Row)> = VecDeque::new();
    let mut maps: VecDeque<Map> = VecDeque::new();
    f.each_row(panel, s, |f, r, nis| {
        let row = filtered(f, nis);
        if let Some((_, previous)) = rows.back() {
            let (phi, x, s) = f.prediction();
            let n = x.len();
            let prediction = (
                &DMatrix::from_column_slice(n, n, phi),
                &DVector::from_column_slice(x),
                &DMatrix::from_column_slice(n, n, s),
            );
            maps.push_back(step(previous, prediction, r)?);
        }
        rows.push_back((r, row));
        if rows.len() > lag {
            let (first, point) = back_over(&rows, &maps)?;
            let (r0, oldest) = rows.pop_front().expect("a row is held");
            debug_assert_eq!(first, r0);
            emit(&mut out, r0, &point, oldest.nis);
            maps.pop_front();
        }
        Ok(())
    })?;
    // The rows still held, each from every row of the series.
    let Some((_, last)) = rows.back() else {
        return Ok(());
    };
    let mut point = Map::point(&last.state, &last.covariance);
    for (i, (r, row)) in rows.iter().enumerate().rev() {
        if i + 1 < rows.len() {
            point = maps[i].then(&point).finite(*r)?;
        }
        emit(&mut out, *r, &point, row.nis);
    }
    Ok(())
}

/// The oldest held row's estimate from the newest's, by the backward steps between them; its
/// index in the series.
fn back_over(rows: &VecDeque<(usize, Row)>, maps: &VecDeque<Map>) -> Result<(usize, Map), Error> {
    let (_, newest) = rows.back().expect("a row is held");
    let mut point = Map::point(&newest.state, &newest.covariance);
    for (i, map) in maps.iter().enumerate().rev() {
        point = map.then(&point).finite(rows[i].0)?;
    }
    Ok((rows[0].0, point))
}
