//! The invariants of numbers read back ([`crate::persist`]): finite, of the expected shape, a
//! covariance symmetric and positive semi-definite. Each check says why in words, naming what
//! it checked and where.

use nalgebra::{DMatrix, DVector};

/// `Ok` if every number of `xs` is finite, else why (naming `what` and the index).
pub(crate) fn finite(xs: &[f64], what: &str) -> Result<(), String> {
    match xs.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) => Err(format!("{what} [{i}] = {} is not finite", xs[i])),
    }
}

/// `Ok` if `v` has `n` finite numbers.
pub(crate) fn vector(v: &DVector<f64>, n: usize, what: &str) -> Result<(), String> {
    if v.len() != n {
        return Err(format!("{what} has {} numbers, {n} expected", v.len()));
    }
    finite(v.as_slice(), what)
}

/// `Ok` if `m` is `rows × cols` and finite.
pub(crate) fn matrix(m: &DMatrix<f64>, rows: usize, cols: usize, what: &str) -> Result<(), String> {
    if m.shape() != (rows, cols) {
        return Err(format!(
            "{what} is {}×{}, {rows}×{cols} expected",
            m.nrows(),
            m.ncols()
        ));
    }
    finite(m.as_slice(), what)
}

/// `Ok` if `m` is an `n × n` finite covariance: symmetric and positive semi-definite, each to
/// 1e-9 of its largest entry (a filter's covariance is kept so to rounding).
pub(crate) fn covariance(m: &DMatrix<f64>, n: usize, what: &str) -> Result<(), String> {
    matrix(m, n, n, what)?;
    let scale = m.amax().max(f64::MIN_POSITIVE);
    let tol = 1e-9 * scale;
    for i in 0..n {
        for j in 0..i {
            if (m[(i, j)] - m[(j, i)]).abs() > tol {
                return Err(format!("{what} is not symmetric at ({i}, {j})"));
            }
        }
    }
    let shifted = (m + m.transpose()) * 0.5 + DMatrix::identity(n, n) * tol;
    if shifted.cholesky().is_none() {
        return Err(format!("{what} is not positive semi-definite"));
    }
    Ok(())
}
