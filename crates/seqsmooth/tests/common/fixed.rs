//! Shared by the fixed-memory tests.

use super::rational::*;
use nalgebra::DMatrix;
use num_traits::Signed;

pub fn rows(r: &[Vec<Q>]) -> DMatrix<Q> {
    DMatrix::from_fn(r.len(), r[0].len(), |i, j| r[i][j].clone())
}

/// The leads used throughout: current, one-step, centre, a fractional lead, a retrodiction
/// before the window.
pub fn leads(l: i64) -> Vec<Q> {
    vec![z(0), z(1), fr(-l, 2), fr(5, 2), z(-l - 3)]
}

/// Relative error of derivative vectors with floors `scale / step^i` (the data scale carried to
/// each derivative's units).
pub fn rel_to_scale(got: &[f64], want: &[f64], scale: f64, step: f64) -> f64 {
    got.iter()
        .zip(want)
        .enumerate()
        .map(|(i, (a, b))| (a - b).abs() / (b.abs().max(scale / step.powi(i as i32))))
        .fold(0.0, f64::max)
}
