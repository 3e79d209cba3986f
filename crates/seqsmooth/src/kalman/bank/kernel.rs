//! The arithmetic of a [`KalmanBank`](super::KalmanBank)'s fixed-size path on `L` series at
//! once (structure of arrays: every matrix entry an array `[f64; L]`, one number a series,
//! no dependency between the lanes, so that the compiler vectorises across them), and the
//! same code at `L = 1` for one series ([`super::fixed::FixedSeries`]): the prediction
//! `Φ S Φᵀ + Q` (Morrison (12.2.16), (15.4.11)) and the update with `K` components present
//! (gain (12.2.17) through `V = M S Mᵀ + R = L D Lᵀ`, estimate (12.2.18), Joseph's covariance
//! (12.3.7)), each sum in the order of the filter's `carry` and `correct_kernel`.
//!
//! A lane's numbers are a function of that lane's inputs alone, by the same operations in the
//! same order whatever `L` (Rust does not contract `a * b + c` into a fused multiply-add), so
//! a series gives the same numbers bit for bit in a lane of any width.

// The loops index by position on purpose: each sum in the filter kernels' order, over arrays
// whose sizes are constants (the loops unroll; the innermost, over the lanes, vectorises).
#![allow(clippy::needless_range_loop)]

/// `N` entries, each `L` lanes.
pub(super) type Column<const N: usize, const L: usize> = [[f64; L]; N];

/// `N × N`, column-major (`m[j][i]` row `i`, column `j`), each entry `L` lanes.
pub(super) type Square<const N: usize, const L: usize> = [[[f64; L]; N]; N];

/// `X_{k|k−1} = Φ X` (each entry's sum over the columns of `Φ` in order).
#[inline(always)]
pub(super) fn propagate<const N: usize, const L: usize>(
    phi: &Square<N, L>,
    x: &Column<N, L>,
) -> Column<N, L> {
    let mut xp = [[0.0; L]; N];
    for i in 0..N {
        for e in 0..L {
            xp[i][e] = phi[0][i][e] * x[0][e];
        }
    }
    for j in 1..N {
        for i in 0..N {
            for e in 0..L {
                xp[i][e] += phi[j][i][e] * x[j][e];
            }
        }
    }
    xp
}

/// `Φ S Φᵀ + Q`, symmetrized (the filter's `carry`): `A = S Φᵀ`, then `Aᵀ Φᵀ`, each entry
/// summed over the columns of `Φ` in order, then `(out + Q)` symmetrized in one pass.
#[inline(always)]
pub(super) fn carry<const N: usize, const L: usize>(
    phi: &Square<N, L>,
    s: &Square<N, L>,
    q: Option<&Square<N, L>>,
) -> Square<N, L> {
    let mut a = [[[0.0; L]; N]; N];
    for i in 0..N {
        for l in 0..N {
            for row in 0..N {
                for e in 0..L {
                    a[i][row][e] += s[l][row][e] * phi[l][i][e];
                }
            }
        }
    }
    // (S Φᵀ)ᵀ column l, row r is a[r][l].
    let mut out = [[[0.0; L]; N]; N];
    for j in 0..N {
        for l in 0..N {
            for row in 0..N {
                for e in 0..L {
                    out[j][row][e] += a[row][l][e] * phi[l][j][e];
                }
            }
        }
    }
    match q {
        Some(q) => {
            for j in 0..N {
                for e in 0..L {
                    out[j][j][e] += q[j][j][e];
                }
                for i in j + 1..N {
                    for e in 0..L {
                        let v = ((out[j][i][e] + q[j][i][e]) + (out[i][j][e] + q[i][j][e])) * 0.5;
                        out[j][i][e] = v;
                        out[i][j][e] = v;
                    }
                }
            }
        }
        None => {
            for j in 0..N {
                for i in j + 1..N {
                    for e in 0..L {
                        let v = (out[j][i][e] + out[i][j][e]) * 0.5;
                        out[j][i][e] = v;
                        out[i][j][e] = v;
                    }
                }
            }
        }
    }
    out
}

/// The predicted observation `G = M X_{k|k−1}` of the `K` rows `mt` of `M` (each a sum over
/// the states in order, from −0 as [`Iterator::sum`]).
#[inline(always)]
pub(super) fn observe<const N: usize, const K: usize, const L: usize>(
    mt: &[[f64; N]; K],
    xp: &Column<N, L>,
) -> [[f64; L]; K] {
    let mut g = [[-0.0; L]; K];
    for c in 0..K {
        for l in 0..N {
            for e in 0..L {
                g[c][e] += mt[c][l] * xp[l][e];
            }
        }
    }
    g
}

/// An update of `L` lanes: the estimate, the NIS, and what its checks need.
pub(super) struct Corrected<const N: usize, const K: usize, const L: usize> {
    /// `X_{k|k}`.
    pub(super) x: Column<N, L>,
    /// `S_{k|k}` (Joseph's form, symmetrized).
    pub(super) s: Square<N, L>,
    /// `Σ z_c² / D_c`, `z = L⁻¹ ν`.
    pub(super) nis: [f64; L],
    /// `V`, symmetrized (for an error's message).
    pub(super) v: [[[f64; L]; K]; K],
    /// `L D Lᵀ` of `V` (`lv[j][i]`: row `i`, column `j`; `D` on the diagonal).
    pub(super) lv: [[[f64; L]; K]; K],
    /// Every pivot `D_c > 0`.
    pub(super) positive: [bool; L],
}

/// The correction of the prediction `(xp, sp)` with the residuals `nu` of the `K` present
/// components (`mt`: their rows of `M`; `r`: `R` on them, `r[b][a]`): the filter's
/// `correct_kernel` (no fading), each sum in its order. `U = S Mᵀ`, `V = M U + R = L D Lᵀ`,
/// `H = U V⁻¹`, `X = X_{k|k−1} + H ν`, Joseph's `S` with `I − H M` applied from each side:
/// `X = S − H Uᵀ`, `Y = X Mᵀ`, `S = (X − Y Hᵀ) + (H R) Hᵀ`, symmetrized; the products by `M`
/// skip its zeros, as the filter's kernels do.
#[inline(always)]
pub(super) fn correct<const N: usize, const K: usize, const L: usize>(
    mt: &[[f64; N]; K],
    r: &[[f64; K]; K],
    xp: &Column<N, L>,
    sp: &Square<N, L>,
    nu: &[[f64; L]; K],
) -> Corrected<N, K, L> {
    let s = sp;
    // U = S Mᵀ (`u[c]` its column c).
    // The zeros of `M` skipped (the same in every lane; adding `0 · s` changes no finite
    // sum but a zero's sign).
    let mut u = [[[0.0; L]; N]; K];
    for c in 0..K {
        for l in 0..N {
            let scale = mt[c][l];
            if scale == 0.0 {
                continue;
            }
            for row in 0..N {
                for e in 0..L {
                    u[c][row][e] += s[l][row][e] * scale;
                }
            }
        }
    }
    // V = M U + R, symmetrized, and its L D Lᵀ.
    let mut v = [[[0.0; L]; K]; K];
    for b in 0..K {
        for a in 0..K {
            let mut msm = [0.0; L];
            for l in 0..N {
                if mt[a][l] == 0.0 {
                    continue;
                }
                for e in 0..L {
                    msm[e] += mt[a][l] * u[b][l][e];
                }
            }
            for e in 0..L {
                v[b][a][e] = msm[e] + r[b][a] * 1.0;
            }
        }
    }
    for j in 0..K {
        for i in j + 1..K {
            for e in 0..L {
                let value = (v[j][i][e] + v[i][j][e]) * 0.5;
                v[j][i][e] = value;
                v[i][j][e] = value;
            }
        }
    }
    let mut lv = v;
    let mut positive = [true; L];
    for j in 0..K {
        for c in 0..j {
            for e in 0..L {
                let scale = lv[c][j][e] * lv[c][c][e];
                for i in j..K {
                    lv[j][i][e] -= lv[c][i][e] * scale;
                }
            }
        }
        for e in 0..L {
            let d = lv[j][j][e];
            positive[e] &= d > 0.0;
            for i in j + 1..K {
                lv[j][i][e] /= d;
            }
        }
    }
    // H = U V⁻¹: G Lᵀ = U (forwards), over the pivots, then H L = G (backwards).
    let mut h = u;
    for c in 0..K {
        for d in 0..c {
            for i in 0..N {
                for e in 0..L {
                    h[c][i][e] -= lv[d][c][e] * h[d][i][e];
                }
            }
        }
    }
    for c in 0..K {
        for i in 0..N {
            for e in 0..L {
                h[c][i][e] /= lv[c][c][e];
            }
        }
    }
    for c in (0..K).rev() {
        for d in c + 1..K {
            for i in 0..N {
                for e in 0..L {
                    h[c][i][e] -= lv[c][d][e] * h[d][i][e];
                }
            }
        }
    }
    // NIS = Σ z_c² / D_c, z = L⁻¹ ν.
    let mut z = [[0.0; L]; K];
    let mut nis = [0.0; L];
    for c in 0..K {
        let mut acc = nu[c];
        for d in 0..c {
            for e in 0..L {
                acc[e] -= lv[d][c][e] * z[d][e];
            }
        }
        z[c] = acc;
        for e in 0..L {
            nis[e] += acc[e] * acc[e] / lv[c][c][e];
        }
    }
    let mut x_out = [[0.0; L]; N];
    for i in 0..N {
        let mut acc = [0.0; L];
        for c in 0..K {
            for e in 0..L {
                acc[e] += h[c][i][e] * nu[c][e];
            }
        }
        for e in 0..L {
            x_out[i][e] = acc[e] + xp[i][e];
        }
    }
    // Joseph's form (12.3.7), I − H M applied from each side (the filter's `joseph`).
    let mut x = [[[0.0; L]; N]; N];
    for j in 0..N {
        for i in 0..N {
            let mut acc = [0.0; L];
            for c in 0..K {
                for e in 0..L {
                    acc[e] += h[c][i][e] * u[c][j][e];
                }
            }
            for e in 0..L {
                x[j][i][e] = s[j][i][e] - acc[e];
            }
        }
    }
    let mut y = [[[0.0; L]; N]; K];
    for c in 0..K {
        for l in 0..N {
            let scale = mt[c][l];
            if scale == 0.0 {
                continue;
            }
            for row in 0..N {
                for e in 0..L {
                    y[c][row][e] += x[l][row][e] * scale;
                }
            }
        }
    }
    let mut hr = [[[0.0; L]; N]; K];
    for d in 0..K {
        for i in 0..N {
            for c in 0..K {
                for e in 0..L {
                    hr[d][i][e] += h[c][i][e] * r[d][c];
                }
            }
        }
    }
    let mut s_out = [[[0.0; L]; N]; N];
    for j in 0..N {
        for i in 0..N {
            let (mut yh, mut rh) = ([0.0; L], [0.0; L]);
            for c in 0..K {
                for e in 0..L {
                    yh[e] += y[c][i][e] * h[c][j][e];
                }
            }
            for d in 0..K {
                for e in 0..L {
                    rh[e] += hr[d][i][e] * h[d][j][e];
                }
            }
            for e in 0..L {
                s_out[j][i][e] = (x[j][i][e] - yh[e]) + rh[e];
            }
        }
    }
    for j in 0..N {
        for i in j + 1..N {
            for e in 0..L {
                let value = (s_out[j][i][e] + s_out[i][j][e]) * 0.5;
                s_out[j][i][e] = value;
                s_out[i][j][e] = value;
            }
        }
    }
    Corrected {
        x: x_out,
        s: s_out,
        nis,
        v,
        lv,
        positive,
    }
}

/// Lane `e` of `m`, `N × N` column-major.
#[inline(always)]
pub(super) fn lane_of<const N: usize, const L: usize>(m: &Square<N, L>, e: usize) -> [[f64; N]; N] {
    m.map(|column| column.map(|v| v[e]))
}

/// `from` into lane `e` of `m`.
#[inline(always)]
pub(super) fn set_lane<const N: usize, const L: usize>(
    m: &mut Square<N, L>,
    e: usize,
    from: &[[f64; N]; N],
) {
    for (column, f) in m.iter_mut().zip(from) {
        for (v, &value) in column.iter_mut().zip(f) {
            v[e] = value;
        }
    }
}

/// A matrix as one lane.
#[inline(always)]
pub(super) fn one<const N: usize>(m: &[[f64; N]; N]) -> Square<N, 1> {
    m.map(|column| column.map(|v| [v]))
}

/// One lane as a matrix.
#[inline(always)]
pub(super) fn only<const N: usize>(m: &Square<N, 1>) -> [[f64; N]; N] {
    m.map(|column| column.map(|v| v[0]))
}

/// The Rauch–Tung–Striebel backward step of `L` lanes (the whole-interval step of
/// `kalman::backward`'s `smooth_into`, each sum in its order, every term of `Φ S` added):
/// `C = S Φᵀ S_{k+1|k}⁻¹` through `S_{k+1|k} = L D Lᵀ`, `X_{k|N} = x + C (x_next − X_{k+1|k})`,
/// `S_{k|N} = s + C (s_next − S_{k+1|k}) Cᵀ` (symmetrized); per lane whether every pivot
/// `D_j > 0`.
#[allow(clippy::type_complexity)]
#[inline(always)]
pub(super) fn smooth<const N: usize, const L: usize>(
    (x, s): (&Column<N, L>, &Square<N, L>),
    (phi, x_pred, s_pred): (&Square<N, L>, &Column<N, L>, &Square<N, L>),
    (x_next, s_next): (&Column<N, L>, &Square<N, L>),
) -> (Column<N, L>, Square<N, L>, [bool; L]) {
    // P = Φ S, each entry's terms in the order of Φ's columns.
    let mut p = [[[0.0; L]; N]; N];
    for m in 0..N {
        for i in 0..N {
            for j in 0..N {
                for e in 0..L {
                    p[j][i][e] += phi[m][i][e] * s[j][m][e];
                }
            }
        }
    }
    // S_{k+1|k} = L D Lᵀ: `l[m][j]` (j > m) L's entries, `l[j][m]` L D's, `inverse` 1/D.
    let mut l = [[[0.0; L]; N]; N];
    let mut inverse = [[0.0; L]; N];
    let mut positive = [true; L];
    for j in 0..N {
        for e in 0..L {
            let mut pivot = s_pred[j][j][e];
            for m in 0..j {
                pivot -= l[m][j][e] * l[j][m][e];
            }
            positive[e] &= pivot > 0.0;
            inverse[j][e] = 1.0 / pivot;
        }
        for i in j + 1..N {
            for e in 0..L {
                let mut v = s_pred[j][i][e];
                for m in 0..j {
                    v -= l[m][i][e] * l[j][m][e];
                }
                l[i][j][e] = v;
                l[j][i][e] = v * inverse[j][e];
            }
        }
    }
    // Cᵀ = S_{k+1|k}⁻¹ P, a column at a time; row j of C is the solution (`c[i][j]`).
    let mut c = [[[0.0; L]; N]; N];
    for j in 0..N {
        let mut column = p[j];
        for m in 0..N {
            for i in m + 1..N {
                for e in 0..L {
                    column[i][e] -= l[m][i][e] * column[m][e];
                }
            }
        }
        for m in 0..N {
            for e in 0..L {
                column[m][e] *= inverse[m][e];
            }
        }
        for i in (0..N).rev() {
            for e in 0..L {
                let mut v = column[i][e];
                for m in i + 1..N {
                    v -= l[i][m][e] * column[m][e];
                }
                column[i][e] = v;
            }
        }
        for i in 0..N {
            c[i][j] = column[i];
        }
    }
    let mut x_out = *x;
    for m in 0..N {
        for i in 0..N {
            for e in 0..L {
                x_out[i][e] += c[m][i][e] * (x_next[m][e] - x_pred[m][e]);
            }
        }
    }
    // W = C E (E = s_next − S_{k+1|k}), then s + W Cᵀ.
    let mut w = [[[0.0; L]; N]; N];
    for j in 0..N {
        for m in 0..N {
            for i in 0..N {
                for e in 0..L {
                    w[j][i][e] += c[m][i][e] * (s_next[j][m][e] - s_pred[j][m][e]);
                }
            }
        }
    }
    let mut s_out = *s;
    for m in 0..N {
        for j in 0..N {
            for i in 0..N {
                for e in 0..L {
                    s_out[j][i][e] += w[m][i][e] * c[m][j][e];
                }
            }
        }
    }
    for j in 0..N {
        for i in 0..j {
            for e in 0..L {
                let v = 0.5 * (s_out[j][i][e] + s_out[i][j][e]);
                s_out[j][i][e] = v;
                s_out[i][j][e] = v;
            }
        }
    }
    (x_out, s_out, positive)
}
