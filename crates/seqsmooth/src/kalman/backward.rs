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
/// and `S_{k|N} = s + C (s_next − S_{k+1|k}) Cᵀ` (its lower triangle, mirrored) into `x_out`,
/// `s_out`, with `C` by [`gain_kernel`] into `c`: the map's numbers ([`map_into`] then
/// [`apply_into`]) to rounding, at about three quarters of its arithmetic. `false` when `S_{k+1|k}` is not positive definite.
pub(crate) fn smooth_into(
    n: usize,
    (x, s): (&[f64], &[f64]),
    (phi, x_pred, s_pred): (&[f64], &[f64], &[f64]),
    (x_next, s_next): (&[f64], &[f64]),
    (x_out, s_out, c): (&mut [f64], &mut [f64], &mut [f64]),
) -> bool {
    let estimates = ((x, s), (x_next, s_next));
    if n <= MAX {
        unrolled_sizes!(n, N => smooth_fixed::<N>(estimates, (phi, x_pred, s_pred), (x_out, s_out, c)),
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

/// [`smooth_into`] for `N ≤ 9` states on the stack, a matrix as an array of its columns (or
/// rows): [`smooth_kernel`]'s operations entry for entry in the same order (its numbers), laid
/// out so that each step is a sum of whole columns kept in registers. `P = Φ S` by rows (the
/// rows of `S` are its columns: it is symmetric) skipping `Φ`'s zeros; `Cᵀ = L⁻ᵀ D⁻¹ L⁻¹ P` on
/// all of `P`'s columns at once, its rows (the columns of `C`) as they come; then `x + C dx`,
/// `W = C E` and the lower triangle of `s + W Cᵀ`, mirrored.
#[inline(always)]
#[allow(clippy::type_complexity)]
pub(crate) fn smooth_fixed<const N: usize>(
    ((x, s), (x_next, s_next)): ((&[f64], &[f64]), (&[f64], &[f64])),
    (phi, x_pred, s_pred): (&[f64], &[f64], &[f64]),
    (x_out, s_out, c): (&mut [f64], &mut [f64], &mut [f64]),
) -> bool {
    let nn = N * N;
    let (s, phi, s_pred, s_next) = (&s[..nn], &phi[..nn], &s_pred[..nn], &s_next[..nn]);
    let column = |a: &[f64], j: usize| -> [f64; N] { std::array::from_fn(|i| a[i + j * N]) };
    let s_rows: [[f64; N]; N] = std::array::from_fn(|m| std::array::from_fn(|j| s[m + j * N]));
    // Rows of P = Φ S, each entry's terms in the order of Φ's columns, Φ's zeros skipped.
    let mut y = [[0.0; N]; N];
    for m in 0..N {
        for (i, row) in y.iter_mut().enumerate() {
            let v = phi[i + m * N];
            if v != 0.0 {
                for j in 0..N {
                    row[j] += v * s_rows[m][j];
                }
            }
        }
    }
    // S_{k+1|k} = L D Lᵀ as `gain_kernel` makes it: `l[m][i]` = L_{im} (i > m) and
    // `l[i][m]` = L_{im} D_m; `inverse` = 1/D.
    let mut l = [[0.0; N]; N];
    let mut inverse = [0.0; N];
    for j in 0..N {
        let mut pivot = s_pred[j + j * N];
        for (lm, ljm) in l.iter().zip(&l[j]).take(j) {
            pivot -= lm[j] * ljm;
        }
        if pivot.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return false;
        }
        inverse[j] = 1.0 / pivot;
        for i in j + 1..N {
            let mut v = s_pred[i + j * N];
            for (lm, ljm) in l.iter().zip(&l[j]).take(j) {
                v -= lm[i] * ljm;
            }
            l[i][j] = v;
            l[j][i] = v * inverse[j];
        }
    }
    // Cᵀ = S_{k+1|k}⁻¹ P on every column of P at once: L Y = P, Y / D, Lᵀ Z = Y; row i of Z
    // is column i of C.
    for m in 0..N {
        let ym = y[m];
        for i in m + 1..N {
            let lim = l[m][i];
            for j in 0..N {
                y[i][j] -= lim * ym[j];
            }
        }
    }
    for (row, &d) in y.iter_mut().zip(&inverse) {
        for v in row.iter_mut() {
            *v *= d;
        }
    }
    for i in (0..N).rev() {
        let mut v = y[i];
        for m in i + 1..N {
            let lmi = l[i][m];
            for j in 0..N {
                v[j] -= lmi * y[m][j];
            }
        }
        y[i] = v;
    }
    let c_columns = y;
    // X = x + C (x_next − X_{k+1|k}), by columns of C.
    let mut xo: [f64; N] = std::array::from_fn(|i| x[i]);
    for m in 0..N {
        let v = x_next[m] - x_pred[m];
        for i in 0..N {
            xo[i] += c_columns[m][i] * v;
        }
    }
    // W = C E (E = s_next − S_{k+1|k}), a column at a time.
    let mut w = [[0.0; N]; N];
    for (j, wj) in w.iter_mut().enumerate() {
        for m in 0..N {
            let e = s_next[m + j * N] - s_pred[m + j * N];
            for i in 0..N {
                wj[i] += c_columns[m][i] * e;
            }
        }
    }
    // S = s + W Cᵀ, column j from row j on, then mirrored.
    for j in 0..N {
        let mut out = column(s, j);
        for m in 0..N {
            let v = c_columns[m][j];
            for i in 0..N {
                out[i] += w[m][i] * v;
            }
        }
        for i in j..N {
            s_out[i + j * N] = out[i];
            s_out[j + i * N] = out[i];
        }
    }
    x_out[..N].copy_from_slice(&xo);
    for (m, cm) in c_columns.iter().enumerate() {
        c[m * N..(m + 1) * N].copy_from_slice(cm);
    }
    true
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
    // s + W Cᵀ is symmetric: its lower triangle, each entry's terms in the order of `C`'s
    // columns, mirrored (half the products of the full square and its symmetrization).
    s_out.copy_from_slice(s);
    for m in 0..n {
        let wm = &w[m * n..(m + 1) * n];
        for j in 0..n {
            let v = c[j + m * n];
            for i in j..n {
                s_out[i + j * n] += wm[i] * v;
            }
        }
    }
    for j in 0..n {
        for i in j + 1..n {
            s_out[j + i * n] = s_out[i + j * n];
        }
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    /// A random symmetric positive definite `n × n`, column-major.
    fn spd(rng: &mut StdRng, n: usize) -> Vec<f64> {
        let g: Vec<f64> = (0..n * n).map(|_| rng.gen_range(-1.0..1.0)).collect();
        let mut out = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                let dot: f64 = (0..n).map(|k| g[i + k * n] * g[j + k * n]).sum();
                out[i + j * n] = dot + if i == j { 0.5 } else { 0.0 };
            }
        }
        out
    }

    fn case<const N: usize>(rng: &mut StdRng) {
        let n = N;
        let (s, s_pred, s_next) = (spd(rng, n), spd(rng, n), spd(rng, n));
        // Φ upper triangular with zeros, as the polynomial model's.
        let phi: Vec<f64> = (0..n * n)
            .map(|e| {
                let (i, j) = (e % n, e / n);
                if i > j || rng.gen_bool(0.3) {
                    0.0
                } else {
                    rng.gen_range(-2.0..2.0)
                }
            })
            .collect();
        let v =
            |rng: &mut StdRng| -> Vec<f64> { (0..n).map(|_| rng.gen_range(-5.0..5.0)).collect() };
        let (x, x_pred, x_next) = (v(rng), v(rng), v(rng));
        let estimates = ((&x[..], &s[..]), (&x_next[..], &s_next[..]));
        let prediction = (&phi[..], &x_pred[..], &s_pred[..]);
        let (mut xa, mut sa, mut ca) = (vec![0.0; n], vec![0.0; n * n], vec![0.0; n * n]);
        let (mut xb, mut sb, mut cb) = (vec![0.0; n], vec![0.0; n * n], vec![0.0; n * n]);
        let a = smooth_fixed::<N>(estimates, prediction, (&mut xa, &mut sa, &mut ca));
        let mut scratch = vec![0.0; 2 * n * n + 2 * n];
        let b = smooth_kernel(
            Any(n),
            estimates,
            prediction,
            &mut scratch,
            (&mut xb, &mut sb, &mut cb),
        );
        assert_eq!((a, &xa, &sa, &ca), (b, &xb, &sb, &cb), "n = {n}");
        assert!(a);
    }

    /// The fixed-size step is the general kernel's arithmetic: equal bit for bit on random
    /// steps of every unrolled size.
    #[test]
    fn the_fixed_step_is_the_kernels() {
        let mut rng = StdRng::seed_from_u64(6);
        for _ in 0..50 {
            case::<1>(&mut rng);
            case::<2>(&mut rng);
            case::<3>(&mut rng);
            case::<4>(&mut rng);
            case::<5>(&mut rng);
            case::<6>(&mut rng);
            case::<7>(&mut rng);
            case::<8>(&mut rng);
            case::<9>(&mut rng);
        }
    }
}
