//! The smoothers of a [`KalmanBank`](super::KalmanBank)'s series (Rauch, Tung and Striebel
//! 1965; beyond Morrison's book): the backward step of [`crate::kalman::fixed_lag`],
//!
//! `C_k = S_{k|k} Φᵀ S_{k+1|k}⁻¹`, `X_{k|N} = X_{k|k} + C_k (X_{k+1|N} − X_{k+1|k})`,
//! `S_{k|N} = S_{k|k} + C_k (S_{k+1|N} − S_{k+1|k}) C_kᵀ`,
//!
//! the library's own (`step`, `Map::then`), applied from the last row back over the whole
//! series (fixed interval), or over the last `L` rows (fixed lag).

use super::super::fixed_lag::{step, Map, Row};
use super::series::SeriesFilter;
use super::{Panel, RowsMut};
use crate::error::Error;
use crate::model::dynamics::Dynamics;
use nalgebra::{DMatrix, DVector};
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
/// estimate and the prediction into it), then the backward recursion from the last row.
pub(super) fn rts_series<D: Dynamics>(
    f: &mut SeriesFilter<'_, D>,
    panel: &Panel<'_>,
    s: usize,
    mut out: RowsMut<'_>,
) -> Result<(), Error> {
    let mut rows: Vec<Row> = Vec::new();
    let mut predictions: Vec<(DMatrix<f64>, DVector<f64>, DMatrix<f64>)> = Vec::new();
    f.each_row(panel, s, |f, _, nis| {
        let (phi, x, s) = f.prediction();
        predictions.push((phi.clone(), x.clone(), s.clone()));
        rows.push(filtered(f, nis));
        Ok(())
    })?;
    let Some(last) = rows.last() else {
        return Ok(());
    };
    let mut point = Map::point(&last.state, &last.covariance);
    emit(&mut out, rows.len() - 1, &point, last.nis);
    for k in (0..rows.len() - 1).rev() {
        let (phi, x, s) = &predictions[k + 1];
        let map = step(&rows[k], (phi, x, s), k + 1)?;
        point = map.then(&point).finite(k)?;
        emit(&mut out, k, &point, rows[k].nis);
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
