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
use super::series::SeriesFilter;
use super::{Panel, RowsMut};
use crate::error::Error;
use crate::model::dynamics::Dynamics;
use std::collections::VecDeque;

/// The filtered estimate of the row just updated.
fn filtered<D: Dynamics>(f: &SeriesFilter<'_, D>, nis: Option<f64>) -> Row {
    Row {
        time: f.time,
        state: f.x.clone(),
        covariance: f.s.clone(),
        nis,
    }
}

/// A row's smoothed estimate `point` into `out`.
fn emit(out: &mut RowsMut<'_>, r: usize, point: &Map, nis: Option<f64>) {
    out.set(r, point.a.as_slice(), point.d.as_slice(), nis);
}

/// The fixed-interval smoother over series `s`: the forward pass kept (each row's filtered
/// estimate and the prediction into it, flat), then the backward recursion from the last row
/// ([`Backward`], in place).
pub(super) fn rts_series<D: Dynamics>(
    f: &mut SeriesFilter<'_, D>,
    panel: &Panel<'_>,
    s: usize,
    mut out: RowsMut<'_>,
) -> Result<(), Error> {
    let n = f.x.len();
    let nn = n * n;
    let rows = panel.offsets[s + 1] - panel.offsets[s];
    let (mut xs, mut ss) = (Vec::with_capacity(rows * n), Vec::with_capacity(rows * nn));
    let (mut phis, mut xps, mut sps) = (
        Vec::with_capacity(rows * nn),
        Vec::with_capacity(rows * n),
        Vec::with_capacity(rows * nn),
    );
    let mut nis = Vec::with_capacity(rows);
    f.each_row(panel, s, |f, _, v| {
        let (phi, x, s) = f.prediction();
        phis.extend_from_slice(phi.as_slice());
        xps.extend_from_slice(x.as_slice());
        sps.extend_from_slice(s.as_slice());
        xs.extend_from_slice(f.x.as_slice());
        ss.extend_from_slice(f.s.as_slice());
        nis.push(v);
        Ok(())
    })?;
    if rows == 0 {
        return Ok(());
    }
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
pub(super) fn fixed_lag_series<D: Dynamics>(
    f: &mut SeriesFilter<'_, D>,
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
            maps.push_back(step(previous, f.prediction(), r)?);
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
