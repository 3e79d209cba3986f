//! The oracle of the polynomial-sample tests: a segment's weighted least-squares polynomial
//! by a direct QR solve in the Legendre basis of its span, evaluated at given offsets from the
//! span's centre, with the covariance of those values.

use nalgebra::{DMatrix, DVector};
use seqsmooth::basis::legendre::values as legendre;

/// The degree-`n` fit of `(t, y)` with noise `sigma` (rows `P_i(u_j)/σ_j`,
/// `u = (t − c)/h` on the span), its values at `c + offsets[k]` and their covariance.
pub fn direct_fit(
    t: &[f64],
    y: &[f64],
    sigma: &[f64],
    n: usize,
    offsets: &[f64],
) -> (DVector<f64>, DMatrix<f64>) {
    let (a, b) = (t[0], t[t.len() - 1]);
    let (c, h) = ((a + b) / 2.0, (b - a) / 2.0);
    let design = DMatrix::from_fn(t.len(), n + 1, |j, i| {
        legendre(n, (t[j] - c) / h)[i] / sigma[j]
    });
    let rhs = DVector::from_fn(t.len(), |j, _| y[j] / sigma[j]);
    let (q, r) = design.qr().unpack();
    let coef = r.solve_upper_triangular(&(q.transpose() * rhs)).unwrap();
    let r_inv = r.try_inverse().unwrap();
    let at = DMatrix::from_fn(offsets.len(), n + 1, |k, i| legendre(n, offsets[k] / h)[i]);
    let cov = &at * &r_inv * r_inv.transpose() * at.transpose();
    (&at * coef, cov)
}
