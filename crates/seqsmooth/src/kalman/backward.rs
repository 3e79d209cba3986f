//! The Rauch–Tung–Striebel backward step's arithmetic (Rauch, Tung and Striebel 1965; beyond
//! Morrison's book) on column-major slices, with the state dimension a compile-time constant
//! for `n ≤ 9` (`unrolled_sizes!`) and nothing allocated for those sizes: the step as an
//! affine map ([`map_into`]),
//!
//! `C = S_{k|k} Φᵀ S_{k+1|k}⁻¹`, `a = X_{k|k} − C X_{k+1|k}`, `D = S_{k|k} − C Φ S_{k|k}`,
//!
//! with `S_{k+1|k}⁻¹` applied by its square-root-free Cholesky factors `L D Lᵀ` (never inverted), and the map
//! applied to a later estimate ([`apply_into`]): `X = a + C X'`, `S = D + C S' Cᵀ`; or the
//! whole-interval step at once in the textbook form ([`smooth_into`]). The smoothers of
//! [`super::smoother`] and [`super::fixed_lag`] make every backward step here.

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
        unrolled_sizes!(n, N => {
                let mut scratch = [0.0; 2 * N * N + 2 * N];
                let scratch = &mut scratch[..];
                map_kernel(Fixed::<N>, (x, s), (phi, x_pred, s_pred), scratch, a, d, c)
            },
            _ => false)
    } else {
        let mut scratch = vec![0.0; 2 * n * n + 2 * n];
        let scratch = &mut scratch[..];
        map_kernel(Any(n), (x, s), (phi, x_pred, s_pred), scratch, a, d, c)
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
        unrolled_sizes!(n, N => {
                let mut scratch = [0.0; N * N];
                apply_kernel(Fixed::<N>, (a, d, c), (x, s), &mut scratch, x_out, s_out)
            },
            _ => ())
    } else {
        let mut scratch = vec![0.0; n * n];
        apply_kernel(Any(n), (a, d, c), (x, s), &mut scratch, x_out, s_out);
    }
}

/// One whole-interval backward step in the textbook form: from `(x, s)` (`X_{k|k}`,
/// `S_{k|k}`), the prediction out of it `(Φ, X_{k+1|k}, S_{k+1|k})` and the later smoothed
/// estimate `(x_next, s_next)` (`X_{k+1|N}`, `S_{k+1|N}`), `X_{k|N} = x + C (x_next − X_{k+1|k})`
/// and `S_{k|N} = s + C (s_next − S_{k+1|k}) Cᵀ` (symmetrized) into `x_out`, `s_out`, with `C`
/// by [`gain_kernel`] into `c`: the map's numbers ([`map_into`] then [`apply_into`]) to rounding,
/// at about three quarters of its arithmetic. `false` when `S_{k+1|k}` is not positive definite.
pub(crate) fn smooth_into(
    n: usize,
    (x, s): (&[f64], &[f64]),
    (phi, x_pred, s_pred): (&[f64], &[f64], &[f64]),
    (x_next, s_next): (&[f64], &[f64]),
    (x_out, s_out, c): (&mut [f64], &mut [f64], &mut [f64]),
) -> bool {
    let estimates = ((x, s), (x_next, s_next));
    if n <= MAX {
        unrolled_sizes!(n, N => {
                let mut scratch = [0.0; 2 * N * N + 2 * N];
                let scratch = &mut scratch[..];
                smooth_kernel(Fixed::<N>, estimates, (phi, x_pred, s_pred), scratch, (x_out, s_out, c))
            },
            _ => false)
    } else {
        let mut scratch = vec![0.0; 2 * n * n + 2 * n];
        let scratch = &mut scratch[..];
        smooth_kernel(
            Any(n),
            estimates,
            (phi, x_pred, s_pred),
            scratch,
            (x_out, s_out, c),
        )
    }
}

/// [`smooth_into`] for `n` states.
#[inline(always)]
#[allow(clippy::type_complexity)]
fn smooth_kernel<S: Size>(
    n: S,
    ((x, s), (x_next, s_next)): ((&[f64], &[f64]), (&[f64], &[f64])),
    (phi, x_pred, s_pred): (&[f64], &[f64], &[f64]),
    scratch: &mut [f64],
    (x_out, s_out, c): (&mut [f64], &mut [f64], &mut [f64]),
) -> bool {
    if !gain_kernel(n, s, (phi, s_pred), &mut *scratch, c) {
        return false;
    }
    let n = n.get();
    let nn = n * n;
    let (e, rest) = scratch.split_at_mut(nn);
    let (w, rest) = rest.split_at_mut(nn);
    let dx = &mut rest[..n];
    let (c, x, s, x_pred, s_pred) = (&c[..nn], &x[..n], &s[..nn], &x_pred[..n], &s_pred[..nn]);
    let (x_next, s_next) = (&x_next[..n], &s_next[..nn]);
    let (x_out, s_out) = (&mut x_out[..n], &mut s_out[..nn]);
    for i in 0..n {
        dx[i] = x_next[i] - x_pred[i];
    }
    x_out.copy_from_slice(x);
    for m in 0..n {
        let (v, cm) = (dx[m], &c[m * n..(m + 1) * n]);
        for i in 0..n {
            x_out[i] += cm[i] * v;
        }
    }
    for i in 0..nn {
        e[i] = s_next[i] - s_pred[i];
    }
    // W = C E, then s + W Cᵀ.
    w.fill(0.0);
    for j in 0..n {
        for m in 0..n {
            let (v, cm) = (e[m + j * n], &c[m * n..(m + 1) * n]);
            for i in 0..n {
                w[i + j * n] += cm[i] * v;
            }
        }
    }
    s_out.copy_from_slice(s);
    for m in 0..n {
        let wm = &w[m * n..(m + 1) * n];
        for j in 0..n {
            let v = c[j + m * n];
            for i in 0..n {
                s_out[i + j * n] += wm[i] * v;
            }
        }
    }
    symmetrize(n, s_out);
    true
}

/// The largest dimension with its kernels unrolled and its scratch on the stack.
const MAX: usize = crate::numeric::unrolled::UNROLLED_MAX_SIZE;

/// The smoother gain `C = S Φᵀ S_{k+1|k}⁻¹` into `c` and `P = Φ S` into `scratch`'s first
/// `n²` (the rest: `L` below its diagonal and `L D` above, a column, `1/D`: `2n² + 2n` in all);
/// `false` when `S_{k+1|k}` is not positive definite.
#[inline(always)]
fn gain_kernel<S: Size>(
    n: S,
    s: &[f64],
    (phi, s_pred): (&[f64], &[f64]),
    scratch: &mut [f64],
    c: &mut [f64],
) -> bool {
    let n = n.get();
    let (nn, s, phi, s_pred) = (n * n, &s[..n * n], &phi[..n * n], &s_pred[..n * n]);
    let (p, rest) = scratch.split_at_mut(nn);
    let (l, rest) = rest.split_at_mut(nn);
    let (column, inverse) = rest.split_at_mut(n);
    let (inverse, c) = (&mut inverse[..n], &mut c[..nn]);
    // P = Φ S, each entry's terms in the order of Φ's columns, those of Φ's zeros skipped
    // (adding 0 · s would change nothing for a finite s; the polynomial model's Φ is mostly
    // zeros): one test per entry of Φ, its row of S then an axpy into P's row.
    p.fill(0.0);
    for m in 0..n {
        for i in 0..n {
            let v = phi[i + m * n];
            if v != 0.0 {
                for j in 0..n {
                    p[i + j * n] += v * s[m + j * n];
                }
            }
        }
    }
    // S_{k+1|k} = L D Lᵀ (L unit lower, column-major, below its diagonal; `inverse` holds
    // 1/D: the square-root-free Cholesky factorisation, no square root in the chain). Below the
    // diagonal, the entries l_{im} D_m are kept in the upper triangle as they are formed.
    for j in 0..n {
        let mut pivot = s_pred[j + j * n];
        for m in 0..j {
            pivot -= l[j + m * n] * l[m + j * n];
        }
        if pivot.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return false;
        }
        inverse[j] = 1.0 / pivot;
        for i in j + 1..n {
            let mut v = s_pred[i + j * n];
            for m in 0..j {
                v -= l[i + m * n] * l[m + j * n];
            }
            l[j + i * n] = v;
            l[i + j * n] = v * inverse[j];
        }
    }
    // Cᵀ = S_{k+1|k}⁻¹ P, a column at a time: L y = P_j (by columns of L), y / D, then
    // Lᵀ z = y (by its rows, L's columns); row j of C is z.
    for j in 0..n {
        column.copy_from_slice(&p[j * n..(j + 1) * n]);
        for m in 0..n {
            let (ym, lm) = (column[m], &l[m * n..(m + 1) * n]);
            for i in m + 1..n {
                column[i] -= lm[i] * ym;
            }
        }
        for m in 0..n {
            column[m] *= inverse[m];
        }
        for i in (0..n).rev() {
            let li = &l[i * n..(i + 1) * n];
            let mut v = column[i];
            for m in i + 1..n {
                v -= li[m] * column[m];
            }
            column[i] = v;
        }
        for i in 0..n {
            c[j + i * n] = column[i];
        }
    }
    true
}

/// [`map_into`] for `n` states: [`gain_kernel`], then `D = S − C P` (symmetrized) and
/// `a = x − C X_{k+1|k}`, by columns of `C`.
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
    if !gain_kernel(n, s, (phi, s_pred), &mut *scratch, c) {
        return false;
    }
    let n = n.get();
    let nn = n * n;
    let (p, s, c) = (&scratch[..nn], &s[..nn], &c[..nn]);
    let (a, d) = (&mut a[..n], &mut d[..nn]);
    d.copy_from_slice(s);
    for j in 0..n {
        let dj = &mut d[j * n..(j + 1) * n];
        for m in 0..n {
            let (v, cm) = (p[m + j * n], &c[m * n..(m + 1) * n]);
            for i in 0..n {
                dj[i] -= cm[i] * v;
            }
        }
    }
    symmetrize(n, d);
    a.copy_from_slice(&x[..n]);
    for m in 0..n {
        let (v, cm) = (x_pred[m], &c[m * n..(m + 1) * n]);
        for i in 0..n {
            a[i] -= cm[i] * v;
        }
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
