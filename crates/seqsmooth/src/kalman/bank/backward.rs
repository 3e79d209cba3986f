//! The Rauch–Tung–Striebel backward step of a bank's series on flat column-major slices, the
//! state size a compile-time constant for `n ≤ 9` (`unrolled_sizes!`), nothing allocated:
//! the same formulas as [`crate::kalman::fixed_lag`]'s `step` and `Map::then`,
//!
//! `C = S_{k|k} Φᵀ S_{k+1|k}⁻¹` (by the Cholesky factor `S_{k+1|k} = L Lᵀ`: `C = Yᵀ` with
//! `S_{k+1|k} Y = Φ S_{k|k}`), `D = S_{k|k} − C Φ S_{k|k}`, `a = X_{k|k} − C X_{k+1|k}`,
//! `X_{k|N} = a + C X_{k+1|N}`, `S_{k|N} = D + C S_{k+1|N} Cᵀ` (each symmetrised),
//!
//! to rounding (tested against the library's smoother to `10⁻¹²` relative,
//! `tests/kalman_bank.rs`).

use crate::error::{Error, Param};
use crate::numeric::unrolled::{unrolled_sizes, Any, Fixed, Size};

/// Scratch of the backward step for `n` states.
pub(super) struct Backward {
    n: usize,
    p: Vec<f64>,
    l: Vec<f64>,
    c: Vec<f64>,
    cs: Vec<f64>,
}

impl Backward {
    pub(super) fn new(n: usize) -> Self {
        Self {
            n,
            p: vec![0.0; n * n],
            l: vec![0.0; n * n],
            c: vec![0.0; n * n],
            cs: vec![0.0; n * n],
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
        let ok = unrolled_sizes!(n, N => back(Fixed::<N>, self, (x, s), (phi, x_pred, s_pred), (x_next, s_next)),
            n => back(Any(n), self, (x, s), (phi, x_pred, s_pred), (x_next, s_next)));
        if !ok {
            return Err(Error::InBatch {
                index,
                source: Box::new(Error::InvalidParameter {
                    name: Param::PredictedCovariance,
                    value: format!("{s_pred:?}"),
                    reason: "is not positive definite, so the smoother cannot weigh the later \
                             measurements (add driving noise, or avoid perfect observations)"
                        .into(),
                }),
            });
        }
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

/// [`Backward::step`] for `n` states; `false` when `S_{k+1|k}` is not positive definite.
#[inline(always)]
fn back<Z: Size>(
    n: Z,
    w: &mut Backward,
    (x, s): (&mut [f64], &mut [f64]),
    (phi, x_pred, s_pred): (&[f64], &[f64], &[f64]),
    (x_next, s_next): (&[f64], &[f64]),
) -> bool {
    let n = n.get();
    let nn = n * n;
    let (p, l, c, cs) = (
        &mut w.p[..nn],
        &mut w.l[..nn],
        &mut w.c[..nn],
        &mut w.cs[..nn],
    );
    let (s, phi, s_pred, s_next) = (&mut s[..nn], &phi[..nn], &s_pred[..nn], &s_next[..nn]);
    // P = Φ S.
    for j in 0..n {
        for i in 0..n {
            let mut acc = 0.0;
            for k in 0..n {
                acc += phi[i + k * n] * s[k + j * n];
            }
            p[i + j * n] = acc;
        }
    }
    // L Lᵀ = S_pred (lower, column-major).
    for j in 0..n {
        let mut d = s_pred[j + j * n];
        for k in 0..j {
            d -= l[j + k * n] * l[j + k * n];
        }
        if d.is_nan() || d <= 0.0 {
            return false;
        }
        let d = d.sqrt();
        l[j + j * n] = d;
        for i in j + 1..n {
            let mut v = s_pred[i + j * n];
            for k in 0..j {
                v -= l[i + k * n] * l[j + k * n];
            }
            l[i + j * n] = v / d;
        }
    }
    // Y = S_pred⁻¹ P column by column (forward, then backward substitution); C = Yᵀ.
    for j in 0..n {
        let y = &mut cs[j * n..(j + 1) * n];
        for i in 0..n {
            let mut v = p[i + j * n];
            for k in 0..i {
                v -= l[i + k * n] * y[k];
            }
            y[i] = v / l[i + i * n];
        }
        for i in (0..n).rev() {
            let mut v = y[i];
            for k in i + 1..n {
                v -= l[k + i * n] * y[k];
            }
            y[i] = v / l[i + i * n];
        }
        for i in 0..n {
            c[j + i * n] = y[i];
        }
    }
    // X = X_f − C X_pred + C X_next = X_f + C (X_next − X_pred).
    for i in 0..n {
        let mut acc = 0.0;
        for k in 0..n {
            acc += c[i + k * n] * (x_next[k] - x_pred[k]);
        }
        x[i] += acc;
    }
    // S = S_f − C P + C S_next Cᵀ: cs = S_next Cᵀ − P (n × n), then S += C cs.
    for j in 0..n {
        for i in 0..n {
            let mut acc = 0.0;
            for k in 0..n {
                acc += s_next[i + k * n] * c[j + k * n];
            }
            cs[i + j * n] = acc - p[i + j * n];
        }
    }
    for j in 0..n {
        for i in 0..n {
            let mut acc = 0.0;
            for k in 0..n {
                acc += c[i + k * n] * cs[k + j * n];
            }
            s[i + j * n] += acc;
        }
    }
    for j in 0..n {
        for i in 0..j {
            let v = 0.5 * (s[i + j * n] + s[j + i * n]);
            s[i + j * n] = v;
            s[j + i * n] = v;
        }
    }
    true
}
