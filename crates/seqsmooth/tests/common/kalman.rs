//! Shared by the Bayes and Kalman filter tests.

use nalgebra::DMatrix;

/// The largest `|A_ij − B_ij| / sqrt(B_ii B_jj)`: a covariance difference in units of its
/// standard deviations (`B` positive definite).
pub fn cov_err(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    let mut worst: f64 = 0.0;
    for i in 0..b.nrows() {
        for j in 0..b.ncols() {
            let scale = (b[(i, i)] * b[(j, j)]).sqrt();
            worst = worst.max((a[(i, j)] - b[(i, j)]).abs() / scale);
        }
    }
    worst
}
