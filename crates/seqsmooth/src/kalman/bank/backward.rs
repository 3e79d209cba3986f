//! The Rauch–Tung–Striebel backward step of a bank's series on flat column-major slices, in
//! place: the library's whole-interval step ([`crate::kalman::backward`]'s `smooth_into`, the
//! size a compile-time constant for `n ≤ 9`, nothing allocated), the one [`super::super::smoother`]'s
//! `smooth_flat` makes,
//!
//! `C = S_{k|k} Φᵀ S_{k+1|k}⁻¹`, `X_{k|N} = X_{k|k} + C (X_{k+1|N} − X_{k+1|k})`,
//! `S_{k|N} = S_{k|k} + C (S_{k+1|N} − S_{k+1|k}) Cᵀ` (its lower triangle, mirrored),
//!
//! with the errors named by the series' row.

use crate::error::Error;
use crate::kalman::backward::smooth_into;
use crate::kalman::fixed_lag::not_positive_definite;

/// Scratch of the backward step for `n` states.
pub(super) struct Backward {
    n: usize,
    x: Vec<f64>,
    s: Vec<f64>,
    c: Vec<f64>,
}

impl Backward {
    pub(super) fn new(n: usize) -> Self {
        Self {
            n,
            x: vec![0.0; n],
            s: vec![0.0; n * n],
            c: vec![0.0; n * n],
        }
    }

    /// The smoothed `(x, s)` at step `k` in place of the filtered `(x, s)` there, from the
    /// prediction into step `k + 1` (`phi`, `x_pred`, `s_pred`) and its smoothed estimate
    /// (`x_next`, `s_next`); an error names `index` (step `k + 1`).
    pub(super) fn step(
        &mut self,
        (x, s): (&mut [f64], &mut [f64]),
        (phi, x_pred, s_pred): (&[f64], &[f64], &[f64]),
        (x_next, s_next): (&[f64], &[f64]),
        index: usize,
    ) -> Result<(), Error> {
        let n = self.n;
        let (x, s) = (&mut x[..n], &mut s[..n * n]);
        let ok = smooth_into(
            n,
            (&*x, &*s),
            (phi, x_pred, s_pred),
            (x_next, s_next),
            (&mut self.x, &mut self.s, &mut self.c),
        );
        if !ok {
            return Err(not_positive_definite(s_pred, n, index));
        }
        x.copy_from_slice(&self.x);
        s.copy_from_slice(&self.s);
        if let Some(&value) = x.iter().chain(s.iter()).find(|v| !v.is_finite()) {
            return Err(Error::InBatch {
                index: index - 1,
                source: Box::new(Error::NonFinite {
                    what: "smoothed state or covariance entry",
                    value,
                }),
            });
        }
        Ok(())
    }
}
