//! The Rauch–Tung–Striebel backward step's arithmetic (Rauch, Tung and Striebel 1965; beyond
//! Morrison's book) on column-major slices, with the state dimension a compile-time constant
//! for `n ≤ 9` (`unrolled_sizes!`) and nothing allocated for those sizes: the step as an
//! affine map ([`map_into`]),
//!
//! `C = S_{k|k} Φᵀ S_{k+1|k}⁻¹`, `a = X_{k|k} − C X_{k+1|k}`, `D = S_{k|k} − C Φ S_{k|k}`,
//!
//! with `S_{k+1|k}⁻¹` applied by its Cholesky factor `L Lᵀ` (never inverted), and the map
//! applied to a later estimate ([`apply_into`]): `X = a + C X'`, `S = D + C S' Cᵀ`. The
//! smoothers of [`super::smoother`] and [`super::fixed_lag`] make every backward step here.

use crate::numeric::unrolled::{unrolled_sizes, Any, Fixed, Size};

/// The backward map from `(x, s)` (`X_{k|k}`, `S_{k|k}`) and the prediction out of it,
/// `(Φ(t_{k+1}, t_k), X_{k+1|k}, S_{k+1|k})`, into `a` (`n`), `d` and `c` (`n × n`); `false`
/// when `S_{k+1|k}` is not positive definite (nothing else checked: the caller checks that
/// the results are finite).
pub(crate) fn map_into(
    n: usize,
    (x, s): (&[f64], &[f64]),
    (phi, x_pred, s_pred): (&[f64], &[f64], &[f64]),
    a: &mut [f64],
    d: &mut [f64],
    c: &mut [f64],
) -> bool {
    if n <= MAX {
        let mut scratch = [0.0; 2 * MAX * MAX + MAX];
        unrolled_sizes!(n, N => map_kernel(Fixed::<N>, (x, s), (phi, x_pred, s_pred), &mut scratch, a, d, c),
            _ => false)
    } else {
        let mut scratch = vec![0.0; 2 * n * n + n];
        map_kernel(Any(n), (x, s), (phi, x_pred, s_pred), &mut scratch, a, d, c)
    }
}

/// The map `(a, d, c)` applied to `(x, s)` into `x_out`, `s_out`: `a + C x`, `D + (C S) Cᵀ`
/// (symmetrized), each sum in the order of the columns of `C`.
pub(crate) fn apply_into(
    n: usize,
    (a, d, c): (&[f64], &[f64], &[f64]),
    (x, s): (&[f64], &[f64]),
    x_out: &mut [f64],
    s_out: &mut [f64],
) {
    if n <= MAX {
        let mut scratch = [0.0; MAX * MAX];
        unrolled_sizes!(n, N => apply_kernel(Fixed::<N>, (a, d, c), (x, s), &mut scratch, x_out, s_out),
            _ => ())
    } else {
        let mut scratch = vec![0.0; n * n];
        apply_kernel(Any(n), (a, d, c), (x, s), &mut scratch, x_out, s_out);
    }
}

/// The largest dimension with its kernels unrolled and its scratch on the stack.
const MAX: usize = crate::numeric::unrolled::UNROLLED_MAX_SIZE;

/// [`map_into`] for `n` states; `scratch` holds `Φ S`, `L` and a column (`2n² + n`).
#[inline(always)]
fn map_kernel<S: Size>(
    n: S,
    (x, s): (&[f64], &[f64]),
    (phi, x_pred, s_pred): (&[f64], &[f64], &[f64]),
    scratch: &mut [f64],
    a: &mut [f64],
    d: &mut [f64],
    c: &mut [f64],
) -> bool {
    let n = n.get();
    let (nn, s, phi, s_pred) = (n * n, &s[..n * n], &phi[..n * n], &s_pred[..n * n]);
    let (p, rest) = scratch.split_at_mut(nn);
    let (l, rest) = rest.split_at_mut(nn);
    let column = &mut rest[..n];
    let (a, d, c) = (&mut a[..n], &mut d[..nn], &mut c[..nn]);
    // P = Φ S, a column at a time (Φ's zeros skipped: adding 0·s changes nothing finite).
    for j in 0..n {
        let pj = &mut p[j * n..(j + 1) * n];
        pj.fill(0.0);
        for m in 0..n {
            let v = s[m + j * n];
            let fm = &phi[m * n..(m + 1) * n];
            for i in 0..n {
                if fm[i] != 0.0 {
                    pj[i] += fm[i] * v;
                }
            }
        }
    }
    // S_{k+1|k} = L Lᵀ (lower, column-major).
    for j in 0..n {
        let mut diagonal = s_pred[j + j * n];
        for m in 0..j {
            diagonal -= l[j + m * n] * l[j + m * n];
        }
        if diagonal.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return false;
        }
        let pivot = diagonal.sqrt();
        l[j + j * n] = pivot;
        for i in j + 1..n {
            let mut v = s_pred[i + j * n];
            for m in 0..j {
                v -= l[i + m * n] * l[j + m * n];
            }
            l[i + j * n] = v / pivot;
        }
    }
    // Cᵀ = S_{k+1|k}⁻¹ P, a column at a time: L y = P_j, then Lᵀ z = y; row j of C is z.
    for j in 0..n {
        for i in 0..n {
            let mut v = p[i + j * n];
            for m in 0..i {
                v -= l[i + m * n] * column[m];
            }
            column[i] = v / l[i + i * n];
        }
        for i in (0..n).rev() {
            let mut v = column[i];
            for m in i + 1..n {
                v -= l[m + i * n] * column[m];
            }
            column[i] = v / l[i + i * n];
        }
        for i in 0..n {
            c[j + i * n] = column[i];
        }
    }
    // D = S − C P (symmetrized), a = x − C X_{k+1|k}.
    for j in 0..n {
        for i in 0..n {
            let mut v = 0.0;
            for m in 0..n {
                v += c[i + m * n] * p[m + j * n];
            }
            d[i + j * n] = s[i + j * n] - v;
        }
    }
    symmetrize(n, d);
    for i in 0..n {
        let mut v = 0.0;
        for m in 0..n {
            v += c[i + m * n] * x_pred[m];
        }
        a[i] = x[i] - v;
    }
    true
}

/// [`apply_into`] for `n` states; `w` (`n²`) holds `C S`.
#[inline(always)]
fn apply_kernel<S: Size>(
    n: S,
    (a, d, c): (&[f64], &[f64], &[f64]),
    (x, s): (&[f64], &[f64]),
    w: &mut [f64],
    x_out: &mut [f64],
    s_out: &mut [f64],
) {
    let n = n.get();
    let nn = n * n;
    let (a, d, c, x, s) = (&a[..n], &d[..nn], &c[..nn], &x[..n], &s[..nn]);
    let (w, x_out, s_out) = (&mut w[..nn], &mut x_out[..n], &mut s_out[..nn]);
    x_out.copy_from_slice(a);
    for (r, &xr) in x.iter().enumerate() {
        let cr = &c[r * n..(r + 1) * n];
        for i in 0..n {
            x_out[i] += xr * cr[i];
        }
    }
    // W = C S, then D + W Cᵀ.
    w.fill(0.0);
    for j in 0..n {
        for r in 0..n {
            let v = s[r + j * n];
            let cr = &c[r * n..(r + 1) * n];
            for i in 0..n {
                w[i + j * n] += v * cr[i];
            }
        }
    }
    s_out.copy_from_slice(d);
    for r in 0..n {
        let wr = &w[r * n..(r + 1) * n];
        for j in 0..n {
            let v = c[j + r * n];
            for i in 0..n {
                s_out[i + j * n] += v * wr[i];
            }
        }
    }
    symmetrize(n, s_out);
}

/// `(M + Mᵀ)/2` in place, `n × n`.
#[inline(always)]
fn symmetrize(n: usize, m: &mut [f64]) {
    for j in 0..n {
        for i in 0..j {
            let v = 0.5 * (m[i + j * n] + m[j + i * n]);
            m[i + j * n] = v;
            m[j + i * n] = v;
        }
    }
}
