//! Advancing an expanding-memory least-squares fit over a run of evenly spaced samples in
//! blocks, for the gain engine's `update_many` (final state only).
//!
//! On an even grid the expanding-memory filter of degree `m` holds, after `N` samples, the
//! least-squares polynomial of degree `m` through all of them (Morrison ch. 9). The residuals of
//! that fit are orthogonal to every polynomial of degree `≤ m` on its grid, so the fit over the
//! old samples plus a run `y_N … y_{N+L-1}` depends on the old samples only through their fit:
//!
//! `p_new = argmin Σ_{u<N} (p_old(u) − p(u))² + Σ_{u=N}^{N+L-1} (y_u − p(u))²`,
//!
//! which is what the recursion `Z ← Φ(1) Z + H(n) (y − [Φ(1) Z]₀)` computes one sample at a time.
//! [`advance_even_fit`] computes it for the whole run at once.
//!
//! ## Method
//!
//! Everything is expressed in the monic discrete orthogonal (Gram) polynomials `Q_j` of a grid
//! of `C` points `v_i = (2i + 1 − C)/C ∈ (−1, 1)`, given by their three-term recurrence
//! `Q_{j+1}(v) = v Q_j(v) − β_j Q_{j−1}(v)`, `β_j = j²(C² − j²)/((4j² − 1) C²)`, with norms
//! `‖Q_j‖² = C β_1 ⋯ β_j`: closed forms, so no Gram matrix of monomials is ever formed or
//! factorised, and the least-squares solve on the union grid is a division by `‖Q_j‖²`. Three
//! kinds of grid are involved: the old samples (`C = N`), each block of new samples (`C = B`),
//! and the union (`C = N + L`, variable `s`).
//!
//! - **Blocks.** A block's moments `μ_j = Σ_i y_i Q^blk_j(v_i)` are `m+1` dot products with
//!   fixed tabulated weights (the only per-sample work; see "Kernel" below). They move to the
//!   union basis by the exact polynomial identity `Q^union_i(δ + α v) = Σ_j E_ij Q^blk_j(v)`
//!   (`s = δ + α v` on the block; `|δ| + α ≤ 1`, so `E` is bounded and the move stable),
//!   `O(m²)` per block, and accumulate in double-word arithmetic. `B = 512`; a tail shorter
//!   than `B` is split into power-of-two blocks, each with its own tables (built once, to
//!   degree 8 for every size 1 … 512: 64 KiB; a degree-4 block reads 8 KiB of them).
//! - **The old samples**, in one of two forms ([`Form`], chosen by the run length `L` against
//!   `n`): *direct* — the old fit's moments `μ_j = c_j ‖Q_j‖²` in the old grid's basis (`c`
//!   from the state by the Taylor recurrence of the `Q_j` at the old newest sample) join the
//!   blocks' through their own `E`, and the new fit is `c_i = μ_i/‖Q_i‖²` — or *residual* —
//!   `z ← Φ(L) z + Δz`, with `Δz` the fit (on the union grid) of `y − p_old` on the run and `0`
//!   on the old samples, whose moments are the blocks' minus `Σ_j G_ij a_j` (`a`: `p_old` in
//!   the union basis; `G`: the run's Gram matrix in the union basis, `E D E^T` with `D` the
//!   run grid's norms). The residual form keeps the state's well-conditioned update `Φ(L) z`
//!   out of the orthogonal-basis round trip, which costs up to `(1+√2)^(2m)`-fold rounding
//!   when the old samples dominate; but it extrapolates `p_old` over the run, so it is used
//!   only while `(m+1)·L ≤ n`.
//! - **Output:** `z_k = f_k (2/M)^k` with `f_k = Σ_i c_i Q_i^(k)(s_newest)/k!` (`M = N+L`).
//!
//! Cost: `m+1` multiply-adds per sample, `O(m²)` per block, `O(m³)` per call.
//!
//! ## Kernel
//!
//! Safe, portable Rust that LLVM vectorises for baseline x86-64 (SSE2): `LANES` independent
//! accumulators per moment over `chunks_exact`, reduced pairwise. For `m ≥ 2` the block's
//! symmetry `Q_j(−v) = (−1)^j Q_j(v)` halves the work: the first half of the block is paired in
//! registers with the mirrored second half, `y_i ± y_{B−1−i}` feed the even/odd moments (the
//! block sum is a separate forward pass first, which also keeps the hardware prefetcher on a
//! forward stream when the data come from DRAM). For `m ≤ 1`, one pass per moment over the
//! L1-resident block is faster. The kernel and lane count per degree are the fastest measured
//! ([`block_moments`]; throughput: see BENCHMARKS.md).
//!
//! ## Accuracy
//!
//! Measured by this module's tests against exact rational least squares (`N ≤ 300`),
//! Householder QR in a Legendre basis (long runs), the gain recursion run exactly and in
//! double-word arithmetic, and polynomial data (where the answer is `Φ(L) z` exactly); the
//! measured errors are in ACCURACY.md. The limit is the conditioning of the state itself:
//! Taylor coefficients about the end of the data are an ill-conditioned representation of the
//! fit (`(1+√2)^(2m)`), felt on the shortest grids (`N = m+2`) and, in the direct form, when a
//! run of a few hundred samples follows `~10³` old ones at high degree.

// The small matrix recurrences below index several arrays by the same subscripts.
#![allow(clippy::needless_range_loop)]

use crate::model::shift_scaled_array;
use crate::numeric::double_word::two_sum;
use crate::numeric::unrolled::{unrolled_sizes, UNROLLED_MAX_SIZE};
use std::sync::OnceLock;

/// The largest degree [`advance_even_fit`] accepts.
pub(crate) const MAX_BLOCK_DEGREE: usize = UNROLLED_MAX_SIZE - 1;

/// `log2` of the block length `B`.
const BLOCK_LOG2: usize = 9;
/// The block length `B`.
const BLOCK: usize = 1 << BLOCK_LOG2;

/// Recurrence coefficient `β_j` of the monic discrete orthogonal polynomials on the grid of
/// `count` points `v_i = (2i + 1 − count)/count`. Non-positive for `j ≥ count` (the
/// polynomials of degree `≥ count` vanish on the grid; the recurrence still defines a basis).
#[inline]
fn beta(j: usize, count: f64) -> f64 {
    let j = j as f64;
    j * j * ((count - j) * (count + j)) / ((4.0 * j * j - 1.0) * count * count)
}

/// `[0, β_1, …, β_{K−1}]` for a grid of `count` points.
#[inline]
fn betas<const K: usize>(count: f64) -> [f64; K] {
    std::array::from_fn(|j| if j == 0 { 0.0 } else { beta(j, count) })
}

/// `T[j][k]`: the Taylor coefficients about `x` of the monic recurrence polynomials `Q_j`,
/// `Q_j(x + t) = Σ_k T[j][k] t^k` (`T[j][j] = 1`).
#[inline]
fn taylor_of_q<const K: usize>(b: &[f64; K], x: f64) -> [[f64; K]; K] {
    let mut t = [[0.0; K]; K];
    t[0][0] = 1.0;
    for j in 0..K - 1 {
        for k in 0..=j + 1 {
            let mut v = x * t[j][k];
            if k > 0 {
                v += t[j][k - 1];
            }
            if j > 0 {
                v -= b[j] * t[j - 1][k];
            }
            t[j + 1][k] = v;
        }
    }
    t
}

/// The coefficients `c` in the monic basis `Q_j` of a grid of `count` points (`v` has step
/// `2/count`) of the polynomial with Taylor coefficients `z_k` in sample steps about the grid
/// point whose Taylor table ([`taylor_of_q`]) is `r`: with `ζ_k = z_k (count/2)^k`,
/// `Σ_k ζ_k t^k = Σ_j c_j Q_j(v + t)`, solved by back substitution (`T[j][j] = 1`).
#[inline(always)]
fn taylor_to_basis<const K: usize>(z: &[f64], count: f64, r: &[[f64; K]; K]) -> [f64; K] {
    let mut zeta = [0.0; K];
    let mut scale = 1.0;
    for k in 0..K {
        zeta[k] = z[k] * scale;
        scale *= 0.5 * count;
    }
    let mut c = [0.0; K];
    for k in (0..K).rev() {
        let mut v = zeta[k];
        for j in k + 1..K {
            v -= c[j] * r[j][k];
        }
        c[k] = v;
    }
    c
}

/// `E[i][j]` with `Q^outer_i(δ + α v) = Σ_j E[i][j] Q^inner_j(v)`: the outer basis restricted to
/// a segment, in the segment's basis (`bo`, `bi` their recurrence coefficients). From
/// `v Q_j = Q_{j+1} + β_j Q_{j−1}` and the outer recurrence.
#[inline]
fn transform<const K: usize>(
    bo: &[f64; K],
    bi: &[f64; K],
    delta: f64,
    alpha: f64,
) -> [[f64; K]; K] {
    let mut e = [[0.0; K]; K];
    e[0][0] = 1.0;
    for i in 0..K - 1 {
        for j in 0..=i + 1 {
            let mut shifted = 0.0;
            if j > 0 {
                shifted += e[i][j - 1];
            }
            if j < i {
                shifted += bi[j + 1] * e[i][j + 1];
            }
            let mut v = delta * e[i][j] + alpha * shifted;
            if i > 0 {
                v -= bo[i] * e[i - 1][j];
            }
            e[i + 1][j] = v;
        }
    }
    e
}

/// Double-word accumulators of the union-basis moments.
struct Moments<const K: usize> {
    hi: [f64; K],
    lo: [f64; K],
}

impl<const K: usize> Moments<K> {
    /// Adds a segment's moments `mu` (in its own basis) through the transform `e`.
    #[inline(always)]
    fn add(&mut self, e: &[[f64; K]; K], mu: &[f64; K]) {
        for i in 0..K {
            let mut t = 0.0;
            for j in 0..=i {
                t += e[i][j] * mu[j];
            }
            let (s, r) = two_sum(self.hi[i], t);
            self.hi[i] = s;
            self.lo[i] += r;
        }
    }
}

/// Weight tables, built once by the recurrence: `weights[p][j]` holds `Q_j(v_i)` on the grid of
/// `2^p` points for `j = 1..=MAX_BLOCK_DEGREE` (`weights[p][0]` is empty: `Q_0 = 1`).
struct Tables {
    weights: Vec<Vec<Vec<f64>>>,
}

fn tables() -> &'static Tables {
    static TABLES: OnceLock<Tables> = OnceLock::new();
    TABLES.get_or_init(|| {
        let weights = (0..=BLOCK_LOG2)
            .map(|p| {
                let count = 1usize << p;
                let cf = count as f64;
                let b = betas::<{ MAX_BLOCK_DEGREE + 1 }>(cf);
                let mut q: Vec<Vec<f64>> = vec![Vec::new(); MAX_BLOCK_DEGREE + 1];
                let v: Vec<f64> = (0..count)
                    .map(|i| (2.0 * i as f64 + 1.0 - cf) / cf)
                    .collect();
                q[1] = v.clone();
                for j in 1..MAX_BLOCK_DEGREE {
                    let next = (0..count)
                        .map(|i| {
                            let prev = if j == 1 { 1.0 } else { q[j - 1][i] };
                            v[i] * q[j][i] - b[j] * prev
                        })
                        .collect();
                    q[j + 1] = next;
                }
                q
            })
            .collect();
        Tables { weights }
    })
}

/// The block moments `μ_j = Σ_i y_i Q_j(v_i)` (`w[j]` the tabulated `Q_j`, `w[0]` unused) of a
/// block of even length, using the symmetry `Q_j(−v) = (−1)^j Q_j(v)` of the grid: each sample
/// `y_i` of the first half is paired in registers with its mirror `y_{C−1−i}`; the even moments
/// take `y_i + y_{C−1−i}`, the odd ones `y_i − y_{C−1−i}`, against the first half of the weights
/// (half the multiplications, additions and weight loads of the direct sums). `μ_0`, the block
/// sum, is a forward pass first: it also brings the block into L1 on a forward stream, which
/// the hardware prefetcher follows (the mirrored loads alone run 5× slower from DRAM). `LANES`
/// independent accumulators per moment, so that the loop vectorises and its additions pipeline.
#[inline(always)]
fn moments_symmetric<const K: usize, const LANES: usize>(y: &[f64], w: &[&[f64]; K]) -> [f64; K] {
    let total = sum::<8>(y);
    let half = y.len() / 2;
    let (lo, hi) = y.split_at(half);
    let body = half - half % LANES;
    let lo_b = &lo[..body];
    let hi_b = &hi[half - body..half];
    let ws: [&[f64]; K] = std::array::from_fn(|j| if j == 0 { lo_b } else { &w[j][..body] });
    let mut acc = [[0.0; LANES]; K];
    for c in 0..body / LANES {
        let o = c * LANES;
        let a: &[f64; LANES] = lo_b[o..o + LANES].try_into().unwrap();
        let r0 = body - o - LANES;
        let b: &[f64; LANES] = hi_b[r0..r0 + LANES].try_into().unwrap();
        let mut even = [0.0; LANES];
        let mut odd = [0.0; LANES];
        for l in 0..LANES {
            let mirror = b[LANES - 1 - l];
            even[l] = a[l] + mirror;
            odd[l] = a[l] - mirror;
        }
        for j in 1..K {
            let wv: &[f64; LANES] = ws[j][o..o + LANES].try_into().unwrap();
            let src = if j % 2 == 0 { &even } else { &odd };
            for l in 0..LANES {
                acc[j][l] += src[l] * wv[l];
            }
        }
    }
    let mut out: [f64; K] = std::array::from_fn(|j| reduce(acc[j]));
    out[0] = total;
    for i in body..half {
        let mirror = hi[half - 1 - i];
        let (even, odd) = (lo[i] + mirror, lo[i] - mirror);
        for j in 1..K {
            out[j] += if j % 2 == 0 { even } else { odd } * w[j][i];
        }
    }
    out
}

/// Pairwise sum of the lane accumulators (`LANES` a power of two).
#[inline(always)]
fn reduce<const LANES: usize>(mut acc: [f64; LANES]) -> f64 {
    let mut width = LANES;
    while width > 1 {
        width /= 2;
        for l in 0..width {
            acc[l] += acc[l + width];
        }
    }
    acc[0]
}

/// `Σ a_i b_i` over equal-length slices with `LANES` independent accumulators (vectorises).
#[inline(always)]
fn dot<const LANES: usize>(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; LANES];
    let ac = a.chunks_exact(LANES);
    let bc = b.chunks_exact(LANES);
    let (ra, rb) = (ac.remainder(), bc.remainder());
    for (x, y) in ac.zip(bc) {
        for l in 0..LANES {
            acc[l] += x[l] * y[l];
        }
    }
    reduce(acc) + ra.iter().zip(rb).map(|(x, y)| x * y).sum::<f64>()
}

/// `Σ a_i` with `LANES` independent accumulators (vectorises).
#[inline(always)]
fn sum<const LANES: usize>(a: &[f64]) -> f64 {
    let mut acc = [0.0; LANES];
    let ac = a.chunks_exact(LANES);
    let ra = ac.remainder();
    for x in ac {
        for l in 0..LANES {
            acc[l] += x[l];
        }
    }
    reduce(acc) + ra.iter().sum::<f64>()
}

/// The block moments as in [`moments_symmetric`], one pass over the (L1-resident) block per
/// moment: faster for degrees 0 and 1, where the pairing costs more than it saves.
#[inline(always)]
fn moments_by_pass<const K: usize, const LANES: usize>(y: &[f64], w: &[&[f64]; K]) -> [f64; K] {
    std::array::from_fn(|j| {
        if j == 0 {
            sum::<LANES>(y)
        } else {
            dot::<LANES>(y, &w[j][..y.len()])
        }
    })
}

/// Advances the expanding-memory least-squares fit of degree `m` over the evenly spaced run
/// `ys` (final state only).
///
/// `z` (`m+1` entries, in/out) is Morrison's scaled state about the newest sample in units of
/// the sample step: with the samples so far at grid positions `u = 0 … n−1`, the fit is
/// `p(u) = Σ_k z_k (u − (n−1))^k`. Afterwards `z` describes, in the same form about the new
/// newest sample `u = n+L−1`, the least-squares fit of degree `m` to `p_old` on the old grid and
/// `ys` on `u = n … n+L−1` — the least-squares fit of all `n+L` samples when `z` was the fit of
/// the first `n` (Morrison ch. 9; the LS-combination identity in the [module docs](self)), and
/// what the gain recursion `Z ← Φ(1) Z + H(n)(y − [Φ(1) Z]₀)` gives sample by sample. Needs
/// `n ≥ m+1` and `m ≤ MAX_BLOCK_DEGREE`; `n + ys.len() < 2⁵³`. An empty run leaves `z` as it is.
/// `m = 0` is the running mean `z₀ ← (n z₀ + Σy)/(n+L)` (for short runs in the form
/// `z₀ + (Σy − L z₀)/(n+L)`), `Σy` a blocked, lane-parallel sum compensated across blocks.
///
/// Accuracy and speed: see the [module docs](self).
pub(crate) fn advance_even_fit(m: usize, n: u64, z: &mut [f64], ys: &[f64]) {
    advance_even_fit_in(m, n, z, ys, Form::choose(m, n, ys.len()));
}

/// How [`advance_even_fit`] combines the old fit with the run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Form {
    /// Refit from the old fit's moments and the run's: `z ← fit(p_old on old, y on new)`.
    /// Accurate while the run carries a fair share of the samples; when it does not, the
    /// conversions of the old state to and from the orthogonal basis cost up to
    /// `(1+√2)^(2m)`-fold rounding (measured: see ACCURACY.md).
    Direct,
    /// Correct the extrapolated old fit: `z ← Φ(L) z + fit(0 on old, y − p_old on new)`. The
    /// correction is small and carries the conversions' rounding only in proportion `L/(n+L)`;
    /// but `p_old` is extrapolated over the run, so it is used only for short runs.
    Residual,
}

impl Form {
    /// Residual while the run is at most `1/(m+1)` of the old samples, direct otherwise (the
    /// crossover measured in this module's tests: the residual form's extrapolation error grows
    /// with the degree).
    fn choose(m: usize, n: u64, len: usize) -> Form {
        if (m as u64 + 1) * len as u64 <= n {
            Form::Residual
        } else {
            Form::Direct
        }
    }
}

/// [`advance_even_fit`] in the given [`Form`].
fn advance_even_fit_in(m: usize, n: u64, z: &mut [f64], ys: &[f64], form: Form) {
    assert!(m <= MAX_BLOCK_DEGREE, "degree {m} above {MAX_BLOCK_DEGREE}");
    assert_eq!(z.len(), m + 1, "state length");
    assert!(
        n > m as u64,
        "the fit of degree {m} needs {} samples, got {n}",
        m + 1
    );
    if ys.is_empty() {
        return;
    }
    unrolled_sizes!(m + 1, K => advance::<K>(n, z, ys, form), _ => unreachable!("degree checked"))
}

/// The block moments of `y` for `K = m+1` components: the kernel ([`moments_symmetric`] or
/// [`moments_by_pass`]) and lane count per size, the fastest measured (see the module docs).
#[inline(always)]
fn block_moments<const K: usize>(y: &[f64], w: &[&[f64]; K]) -> [f64; K] {
    let pairs = y.len() >= 2;
    match K {
        1 => moments_by_pass::<K, 16>(y, w),
        2 => moments_by_pass::<K, 8>(y, w),
        3 | 4 if pairs => moments_symmetric::<K, 4>(y, w),
        3 | 4 => moments_by_pass::<K, 4>(y, w),
        5 | 6 | 8 if pairs => moments_symmetric::<K, 2>(y, w),
        5 | 6 | 8 => moments_by_pass::<K, 2>(y, w),
        _ => moments_by_pass::<K, 8>(y, w),
    }
}

/// [`advance_even_fit`] for `K = m+1` state components.
fn advance<const K: usize>(n: u64, z: &mut [f64], ys: &[f64], form: Form) {
    let nf = n as f64;
    let lf = ys.len() as f64;
    let mf = (n + ys.len() as u64) as f64;
    let bg = betas::<K>(mf);
    let mut norms = [0.0; K]; // ‖Q^union_i‖²
    let mut norm = mf;
    for (i, v) in norms.iter_mut().enumerate() {
        *v = norm;
        if i + 1 < K {
            norm *= bg[i + 1];
        }
    }
    let mut acc = Moments::<K> {
        hi: [0.0; K],
        lo: [0.0; K],
    };

    if form == Form::Direct {
        // The old fit in the old grid's basis: p_old = Σ_k ζ_k (v − v_newest)^k with
        // ζ_k = z_k (n/2)^k (v has step 2/n), and Σ_k ζ_k t^k = Σ_j c_j Q_j(v_newest + t);
        // its moments are μ_j = c_j ‖Q_j‖².
        let bo = betas::<K>(nf);
        let r = taylor_of_q(&bo, (nf - 1.0) / nf);
        let c = taylor_to_basis(z, nf, &r);
        let mut mu = [0.0; K];
        let mut norm = nf;
        for j in 0..K {
            mu[j] = c[j] * norm;
            if j + 1 < K {
                norm *= bo[j + 1];
            }
        }
        acc.add(&transform(&bg, &bo, -lf / mf, nf / mf), &mu);
    }

    // The new samples, block by block.
    let tabs = tables();
    let segment = |y: &[f64], p: usize, u0: f64, acc: &mut Moments<K>| {
        let count = (1usize << p) as f64;
        let w: [&[f64]; K] = std::array::from_fn(|j| &tabs.weights[p][j][..]);
        let mut mu = block_moments::<K>(y, &w);
        for (j, m) in mu.iter_mut().enumerate() {
            if j >= 1usize << p {
                *m = 0.0; // Q_j vanishes on a grid of fewer than j+1 points
            }
        }
        let bb = betas::<K>(count);
        let e = transform(&bg, &bb, (2.0 * u0 + count - mf) / mf, count / mf);
        acc.add(&e, &mu);
    };
    let mut u0 = nf;
    let blocks = ys.chunks_exact(BLOCK);
    let mut rest = blocks.remainder();
    for y in blocks {
        segment(y, BLOCK_LOG2, u0, &mut acc);
        u0 += BLOCK as f64;
    }
    for p in (0..BLOCK_LOG2).rev() {
        let len = 1usize << p;
        if rest.len() >= len {
            let (y, r) = rest.split_at(len);
            segment(y, p, u0, &mut acc);
            u0 += len as f64;
            rest = r;
        }
    }

    // The union basis is orthogonal: coefficients c_i = μ_i/‖Q_i‖², then the Taylor form
    // about the newest, f_k = Σ_i c_i Q_i^(k)(s_newest)/k!, z_k = f_k (2/M)^k.
    let t = taylor_of_q(&bg, (mf - 1.0) / mf);
    let step = 2.0 / mf;
    let mut c = [0.0; K];
    match form {
        Form::Direct => {
            for i in 0..K {
                c[i] = (acc.hi[i] + acc.lo[i]) / norms[i];
            }
            z.fill(0.0);
        }
        Form::Residual => {
            // z ← Φ(L) z (Taylor shift by L steps) …
            let z: &mut [f64; K] = z.try_into().expect("state length checked");
            shift_scaled_array(z, lf);
            // … which is Σ_i a_i Q_i(s_newest + t) with t in units of M/2 steps …
            let a = taylor_to_basis(&z[..], mf, &t);
            // … and whose moments over the run are Σ_j G_ij a_j with the run's Gram matrix
            // G_ij = Σ_run Q_i Q_j = Σ_l E_il E_jl ‖Q^run_l‖² (E: union → run basis).
            let br = betas::<K>(lf);
            let e = transform(&bg, &br, nf / mf, lf / mf);
            let mut nr = [0.0; K];
            let mut norm = lf;
            for (l, v) in nr.iter_mut().enumerate() {
                *v = if l < ys.len() { norm } else { 0.0 };
                if l + 1 < K {
                    norm *= br[l + 1];
                }
            }
            for i in 0..K {
                let mut g = 0.0;
                for j in 0..K {
                    let mut gij = 0.0;
                    for l in 0..=i.min(j) {
                        gij += e[i][l] * e[j][l] * nr[l];
                    }
                    g += gij * a[j];
                }
                c[i] = ((acc.hi[i] - g) + acc.lo[i]) / norms[i];
            }
        }
    }
    let mut scale = 1.0;
    for k in 0..K {
        let mut f = 0.0;
        for i in k..K {
            f += c[i] * t[i][k];
        }
        z[k] += f * scale;
        scale *= step;
    }
}

#[cfg(test)]
mod tests {
    //! Oracles: exact rational least squares (small runs), blocked Householder QR in a Legendre
    //! basis (long runs), and the gain recursion itself, exact or in double-word arithmetic.
    use super::super::testing::scaled_errors;
    use super::*;
    use crate::linalg::inverse_exact;
    use crate::model::{for_each_shift_step, shift_scaled_compensated};
    use crate::numeric::double_word::{two_prod, two_sum};
    use crate::polynomial::gains::{expanding_gains, ExpandingGainSchedule, GainForm};
    use crate::scalar::{rational_from_f64, Rational, Scalar};
    use nalgebra::DMatrix;
    use num_traits::Zero;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    fn max_err(e: &[f64]) -> f64 {
        e.iter().copied().fold(0.0, f64::max)
    }

    /// A trend of degree `deg` over the span `len` (every Taylor coefficient significant), a
    /// sine and Gaussian-ish noise, as `f64` values.
    fn data(len: usize, deg: usize, offset: f64, noise: f64, seed: u64) -> Vec<f64> {
        let mut r = StdRng::seed_from_u64(seed);
        let a: Vec<f64> = (0..=deg).map(|_| r.gen_range(0.5..1.5) * 10.0).collect();
        (0..len)
            .map(|u| {
                let x = u as f64 / len as f64 - 0.3;
                let trend = a.iter().rev().fold(0.0, |acc, c| acc * x + c);
                let e: f64 = (0..4).map(|_| r.gen::<f64>() - 0.5).sum();
                offset + trend + (20.0 * x).sin() + noise * e
            })
            .collect()
    }

    /// Exact least squares of degree `m` through `w` at `u = 0 … N−1`, as Taylor coefficients
    /// about `u = N−1` (the normal equations in `x = u − (N−1)`, solved exactly).
    fn exact_fit(m: usize, w: &[Rational]) -> Vec<Rational> {
        let k = m + 1;
        let last = w.len() as i64 - 1;
        let mut pw = vec![Rational::zero(); 2 * m + 1];
        let mut rhs = vec![Rational::zero(); k];
        for (u, wu) in w.iter().enumerate() {
            let x = Rational::from_i64(u as i64 - last);
            let mut p = Rational::from_i64(1);
            for r in 0..=2 * m {
                if r < k {
                    rhs[r] += wu * &p;
                }
                pw[r] += &p;
                p *= &x;
            }
        }
        let g = DMatrix::from_fn(k, k, |i, j| pw[i + j].clone());
        let gi = inverse_exact(&g).expect("Gram matrix of ≥ m+1 points is regular");
        (0..k)
            .map(|i| (0..k).fold(Rational::zero(), |acc, j| acc + &gi[(i, j)] * &rhs[j]))
            .collect()
    }

    fn to_f64(v: &[Rational]) -> Vec<f64> {
        v.iter().map(|x| x.to_f64()).collect()
    }

    fn rat(x: f64) -> Rational {
        rational_from_f64(x).unwrap()
    }

    /// `p_old(u) = Σ_k z_k (u − (n−1))^k` for `u < n`, exactly.
    fn pseudo_data(z: &[f64], n: usize) -> Vec<Rational> {
        let zr: Vec<Rational> = z.iter().map(|&v| rat(v)).collect();
        (0..n)
            .map(|u| {
                let x = Rational::from_i64(u as i64 - (n as i64 - 1));
                zr.iter()
                    .rev()
                    .fold(Rational::zero(), |acc, c| acc * &x + c)
            })
            .collect()
    }

    /// Against exact rational least squares: the kernel from the rounded old fit vs (a) the
    /// exact combination of that same old fit with the new samples, (b) the exact fit of all
    /// samples (which adds the rounding of the old state).
    #[test]
    fn expanding_block_matches_exact_least_squares() {
        let mut table = Vec::new();
        for m in 0..=MAX_BLOCK_DEGREE {
            let mut worst_a = 0.0f64;
            let mut worst_b = 0.0f64;
            for (ni, &big_n) in [m + 2, 13, 64, 300].iter().enumerate() {
                if big_n < m + 2 {
                    continue;
                }
                let y = data(big_n, m, 3.0, 0.5, 100 * m as u64 + ni as u64);
                let yr: Vec<Rational> = y.iter().map(|&v| rat(v)).collect();
                let all = exact_fit(m, &yr);
                for n in [m + 1, m + 2, big_n / 2, big_n - 1] {
                    if n < m + 1 || n >= big_n {
                        continue;
                    }
                    let mut z = to_f64(&exact_fit(m, &yr[..n]));
                    let mut w = pseudo_data(&z, n);
                    w.extend_from_slice(&yr[n..]);
                    let want_a = to_f64(&exact_fit(m, &w));
                    advance_even_fit(m, n as u64, &mut z, &y[n..]);
                    let span = (big_n - 1) as f64;
                    let ea = max_err(&scaled_errors(&z, &want_a, span));
                    let eb = max_err(&scaled_errors(&z, &to_f64(&all), span));
                    worst_a = worst_a.max(ea);
                    worst_b = worst_b.max(eb);
                    let tol = if m <= 2 {
                        1e-13
                    } else if m <= 4 {
                        1e-12
                    } else {
                        1e-9
                    };
                    assert!(ea < tol, "m {m} N {big_n} n {n}: {ea:e}");
                }
            }
            table.push((m, worst_a, worst_b));
        }
        for (m, a, b) in table {
            println!("exact N≤300 m {m}: vs same old state {a:.1e}, vs fit of all samples {b:.1e}");
        }
    }

    /// Legendre polynomials `P_0 … P_m` at `s`.
    fn legendre(m: usize, s: f64, out: &mut [f64]) {
        out[0] = 1.0;
        if m >= 1 {
            out[1] = s;
        }
        for j in 1..m {
            let jf = j as f64;
            out[j + 1] = ((2.0 * jf + 1.0) * s * out[j] - jf * out[j - 1]) / (jf + 1.0);
        }
    }

    /// Least squares by Householder QR (nalgebra) in the Legendre basis of
    /// `s = (2u + 1 − M)/M` over `u = 0 … M−1` with values `value(u)`, as Taylor coefficients
    /// about `u = M−1` in step units. Tall-skinny QR: the triangular factors of 128-row chunks
    /// are merged pairwise in a binary tree (a stack of levels), so that rounding grows with
    /// the logarithm of the length rather than the length.
    fn qr_fit(m: usize, big_m: usize, value: impl Fn(usize) -> f64) -> Vec<f64> {
        let k = m + 1;
        let chunk = 128;
        let mf = big_m as f64;
        let triangle = |a: DMatrix<f64>| -> DMatrix<f64> {
            let rr = a.qr().r();
            let mut r = DMatrix::<f64>::zeros(k + 1, k + 1);
            let rows = rr.nrows().min(k + 1);
            r.view_mut((0, 0), (rows, k + 1))
                .copy_from(&rr.view((0, 0), (rows, k + 1)));
            r
        };
        let merge = |a: &DMatrix<f64>, b: &DMatrix<f64>| -> DMatrix<f64> {
            let mut s = DMatrix::<f64>::zeros(2 * (k + 1), k + 1);
            s.view_mut((0, 0), (k + 1, k + 1)).copy_from(a);
            s.view_mut((k + 1, 0), (k + 1, k + 1)).copy_from(b);
            triangle(s)
        };
        let mut levels: Vec<Option<DMatrix<f64>>> = Vec::new();
        let mut p = vec![0.0; k];
        let mut u = 0;
        while u < big_m {
            let rows = chunk.min(big_m - u);
            let mut a = DMatrix::<f64>::zeros(rows.max(k + 1), k + 1);
            for i in 0..rows {
                let uu = u + i;
                legendre(m, (2.0 * uu as f64 + 1.0 - mf) / mf, &mut p);
                for j in 0..k {
                    a[(i, j)] = p[j];
                }
                a[(i, k)] = value(uu);
            }
            let mut r = triangle(a);
            let mut level = 0;
            loop {
                if level == levels.len() {
                    levels.push(None);
                }
                match levels[level].take() {
                    Some(other) => {
                        r = merge(&other, &r);
                        level += 1;
                    }
                    None => {
                        levels[level] = Some(r);
                        break;
                    }
                }
            }
            u += rows;
        }
        let r = levels
            .into_iter()
            .flatten()
            .reduce(|a, b| merge(&b, &a))
            .expect("at least one sample");
        // back substitution for the Legendre coefficients
        let mut c = vec![0.0; k];
        for i in (0..k).rev() {
            let mut v = r[(i, k)];
            for j in i + 1..k {
                v -= r[(i, j)] * c[j];
            }
            c[i] = v / r[(i, i)];
        }
        // Taylor coefficients of the P_j about s_new (Bonnet's recurrence on Taylor arrays)
        let x = (mf - 1.0) / mf;
        let mut t = vec![vec![0.0; k]; k];
        t[0][0] = 1.0;
        if k > 1 {
            t[1][0] = x;
            t[1][1] = 1.0;
        }
        for j in 1..k - 1 {
            let jf = j as f64;
            for d in 0..=j + 1 {
                let xs = x * t[j][d] + if d > 0 { t[j][d - 1] } else { 0.0 };
                t[j + 1][d] = ((2.0 * jf + 1.0) * xs - jf * t[j - 1][d]) / (jf + 1.0);
            }
        }
        let step = 2.0 / mf;
        (0..k)
            .map(|d| (d..k).map(|j| c[j] * t[j][d]).sum::<f64>() * step.powi(d as i32))
            .collect()
    }

    /// `p_old(u)` in `f64` (Horner in `u − (n−1)`).
    fn eval_old(z: &[f64], n: usize, u: usize) -> f64 {
        let x = u as f64 - (n as f64 - 1.0);
        z.iter().rev().fold(0.0, |acc, c| acc * x + c)
    }

    fn long_run_errors(m: usize, big_n: usize, splits: &[usize], seed: u64) -> f64 {
        let y = data(big_n, m, 3.0, 1.0, seed);
        let mut worst = 0.0f64;
        for &n in splits {
            let z0 = qr_fit(m, n, |u| y[u]);
            let want = qr_fit(m, big_n, |u| if u < n { eval_old(&z0, n, u) } else { y[u] });
            let mut z = z0.clone();
            advance_even_fit(m, n as u64, &mut z, &y[n..]);
            let e = scaled_errors(&z, &want, (big_n - 1) as f64);
            worst = worst.max(max_err(&e));
        }
        worst
    }

    /// Against blocked QR over 10⁶ samples, with old runs of a few, a third and most samples.
    #[test]
    fn expanding_block_matches_qr_on_long_runs() {
        let big_n = 1_000_000;
        for m in 0..=MAX_BLOCK_DEGREE {
            let splits = [m + 1, 333_333, 999_000, big_n - 7, big_n - 1];
            let e = long_run_errors(m, big_n, &splits, 7 + m as u64);
            println!("QR N=1e6 m {m}: {e:.1e}");
            let tol = match m {
                0..=2 => 1e-13,
                3..=4 => 1e-12,
                _ => 1e-9,
            };
            assert!(e < tol, "m {m}: {e:e}");
        }
    }

    /// The same at 10⁷ samples (slow: run with `--ignored`).
    #[test]
    #[ignore]
    fn expanding_block_matches_qr_on_ten_million() {
        for m in 0..=MAX_BLOCK_DEGREE {
            let e = long_run_errors(m, 10_000_000, &[m + 1, 4_000_000], 11 + m as u64);
            println!("QR N=1e7 m {m}: {e:.1e}");
        }
    }

    /// The gain recursion `z ← Φ(1) z; e = y − z₀; z_k += h_k(n) e` in exact rationals.
    fn exact_recursion(m: usize, n0: usize, z: &[f64], ys: &[f64]) -> Vec<f64> {
        let k = m + 1;
        let mut zr: Vec<Rational> = z.iter().map(|&v| rat(v)).collect();
        for (i, &y) in ys.iter().enumerate() {
            for_each_shift_step(k, |b| {
                let t = zr[b + 1].clone();
                zr[b] += t;
            });
            let e = rat(y) - &zr[0];
            let h = expanding_gains::<Rational>(m, (n0 + i) as u64, GainForm::Current);
            for (zk, hk) in zr.iter_mut().zip(&h) {
                *zk += hk * &e;
            }
        }
        to_f64(&zr)
    }

    /// The same recursion in double-word arithmetic (`f64` gains, accurate to a few ulps).
    fn compensated_recursion(m: usize, n0: usize, z: &[f64], ys: &[f64]) -> Vec<f64> {
        let k = m + 1;
        let mut hi = z.to_vec();
        let mut lo = vec![0.0; k];
        let sched = ExpandingGainSchedule::new(m);
        let mut h = vec![0.0; k];
        for (i, &y) in ys.iter().enumerate() {
            shift_scaled_compensated(&mut hi, &mut lo, 1.0);
            let (e, ee) = two_sum(y, -hi[0]);
            let (e, ee) = two_sum(e, ee - lo[0]);
            sched.gains((n0 + i) as u64, &mut h);
            for j in 0..k {
                let (p, pe) = two_prod(h[j], e);
                let pe = pe + h[j] * ee;
                let (s, se) = two_sum(hi[j], p);
                let (s, t) = two_sum(s, lo[j] + se + pe);
                hi[j] = s;
                lo[j] = t;
            }
        }
        hi.iter().zip(&lo).map(|(a, b)| a + b).collect()
    }

    /// Against the gain recursion: exactly over 200 samples, in double-word arithmetic over
    /// 10⁵, from the same state; and one call against many calls of uneven lengths.
    #[test]
    fn expanding_block_matches_gain_recursion() {
        for m in 0..=4 {
            let tol = if m <= 2 { 1e-13 } else { 1e-12 };
            // exact, 200 samples
            let y = data(200, m, -2.0, 0.3, 40 + m as u64);
            let yr: Vec<Rational> = y.iter().map(|&v| rat(v)).collect();
            let n0 = m + 1;
            let z0 = to_f64(&exact_fit(m, &yr[..n0]));
            let want = exact_recursion(m, n0, &z0, &y[n0..]);
            let mut z = z0.clone();
            advance_even_fit(m, n0 as u64, &mut z, &y[n0..]);
            let e1 = max_err(&scaled_errors(&z, &want, 199.0));
            // double-word, 10⁵ samples, from the rounded exact fit of the first 1000
            let big = 100_000;
            let y = data(big, m, 5.0, 1.0, 50 + m as u64);
            let yr: Vec<Rational> = y[..1000].iter().map(|&v| rat(v)).collect();
            let z0 = to_f64(&exact_fit(m, &yr));
            let want = compensated_recursion(m, 1000, &z0, &y[1000..]);
            let mut z = z0.clone();
            advance_even_fit(m, 1000, &mut z, &y[1000..]);
            let e2 = max_err(&scaled_errors(&z, &want, (big - 1) as f64));
            // many calls of uneven lengths (1 … 1500) against one call
            let mut zs = z0.clone();
            let (mut at, mut len) = (1000, 1);
            while at < big {
                let end = (at + len).min(big);
                advance_even_fit(m, at as u64, &mut zs, &y[at..end]);
                at = end;
                len = (len * 7 + 3) % 1501 + 1;
            }
            let e3 = max_err(&scaled_errors(&zs, &z, (big - 1) as f64));
            println!(
                "recursion m {m}: exact N=200 {e1:.1e}, double-word N=1e5 {e2:.1e}, pieces vs one call {e3:.1e}"
            );
            assert!(
                e1 < tol && e2 < tol && e3 < 10.0 * tol,
                "m {m}: {e1:e} {e2:e} {e3:e}"
            );
        }
    }

    /// Both forms against QR over 2·10⁵ samples, for runs from 1 % to 100 times the old
    /// samples: the chosen form is accurate throughout; the residual form degrades once the
    /// run outgrows the old samples (it extrapolates the old fit over the run).
    #[test]
    fn expanding_block_forms_across_run_lengths() {
        let big_n = 200_000;
        for m in 0..=MAX_BLOCK_DEGREE {
            let y = data(big_n, m, 3.0, 1.0, 99 + m as u64);
            let mut line = format!("forms m {m} (L/n: chosen direct residual):");
            for ratio in [0.01, 0.1, 0.2, 0.3, 1.0, 3.0, 10.0, 100.0] {
                let n = ((big_n as f64) / (1.0 + ratio)) as usize;
                let z0 = qr_fit(m, n, |u| y[u]);
                let want = qr_fit(m, big_n, |u| if u < n { eval_old(&z0, n, u) } else { y[u] });
                let run = |form: Option<Form>| {
                    let mut z = z0.clone();
                    match form {
                        None => advance_even_fit(m, n as u64, &mut z, &y[n..]),
                        Some(f) => advance_even_fit_in(m, n as u64, &mut z, &y[n..], f),
                    }
                    max_err(&scaled_errors(&z, &want, (big_n - 1) as f64))
                };
                let (e, ed, er) = (
                    run(None),
                    run(Some(Form::Direct)),
                    run(Some(Form::Residual)),
                );
                line += &format!(" {ratio}: {e:.0e} {ed:.0e} {er:.0e};");
                let tol = match m {
                    0..=2 => 1e-13,
                    3..=4 => 1e-12,
                    _ => 1e-10,
                };
                assert!(e < tol, "m {m} L/n {ratio}: {e:e}");
            }
            println!("{line}");
        }
    }

    /// Samples on a polynomial of degree `m` continue the old fit exactly: the result is the
    /// old polynomial re-expanded about the new newest sample, `z' = Φ(L) z`, for old runs up to
    /// 10¹² samples.
    #[test]
    fn expanding_block_reproduces_polynomials() {
        let mut worst = [0.0f64; MAX_BLOCK_DEGREE + 1];
        let mut worst_direct = [0.0f64; MAX_BLOCK_DEGREE + 1];
        for m in 0..=MAX_BLOCK_DEGREE {
            for n in [m as u64 + 1, 1000, 1_000_000_000, 1_000_000_000_000] {
                for len in [1usize, 700, 5000] {
                    let span = (n + len as u64 - 1) as f64;
                    // O(1) variation over the span in every degree
                    let z0: Vec<f64> = (0..=m)
                        .map(|k| (1.0 + 0.1 * k as f64) * if k % 2 == 0 { 1.0 } else { -1.0 })
                        .enumerate()
                        .map(|(k, c)| c / span.powi(k as i32))
                        .collect();
                    let zr: Vec<Rational> = z0.iter().map(|&v| rat(v)).collect();
                    let at = |u: i64| -> Rational {
                        let x = Rational::from_i64(u);
                        zr.iter()
                            .rev()
                            .fold(Rational::zero(), |acc, c| acc * &x + c)
                    };
                    // y at u = n … n+L−1, i.e. offsets 1 … L from the old newest
                    let ys: Vec<f64> = (1..=len as i64).map(|d| at(d).to_f64()).collect();
                    // Φ(L) z exactly
                    let lr = Rational::from_i64(len as i64);
                    let want: Vec<f64> = (0..=m)
                        .map(|j| {
                            (j..=m)
                                .fold(Rational::zero(), |acc, k| {
                                    let c = crate::calculus::choose::<Rational>(k, j);
                                    let mut p = Rational::from_i64(1);
                                    for _ in j..k {
                                        p *= &lr;
                                    }
                                    acc + &zr[k] * c * p
                                })
                                .to_f64()
                        })
                        .collect();
                    let mut z = z0.clone();
                    advance_even_fit(m, n, &mut z, &ys);
                    let e = max_err(&scaled_errors(&z, &want, span));
                    let mut z = z0.clone();
                    advance_even_fit_in(m, n, &mut z, &ys, Form::Direct);
                    let e2 = max_err(&scaled_errors(&z, &want, span));
                    worst[m] = worst[m].max(e);
                    worst_direct[m] = worst_direct[m].max(e2);
                    let tol = match m {
                        0..=2 => 1e-13,
                        3..=4 => 1e-12,
                        _ => 1e-10,
                    };
                    assert!(e < tol, "m {m} n {n} L {len}: {e:e}");
                }
            }
        }
        for m in 0..=MAX_BLOCK_DEGREE {
            println!(
                "polynomial data m {m}: {:.1e} (direct form throughout: {:.1e})",
                worst[m], worst_direct[m]
            );
        }
    }

    /// The running mean (m = 0) is the plain mean, also from one old sample.
    #[test]
    fn expanding_block_degree_zero_is_the_running_mean() {
        let y: Vec<f64> = (0..10_007)
            .map(|i| ((i * 37) % 101) as f64 - 50.0)
            .collect();
        let mut z = [y[0]];
        advance_even_fit(0, 1, &mut z, &y[1..]);
        let mean = y.iter().sum::<f64>() / y.len() as f64;
        assert!((z[0] - mean).abs() <= 1e-15 * 50.0, "{} vs {mean}", z[0]);
        let mut z = [4.0];
        advance_even_fit(0, 3, &mut z, &[]);
        assert_eq!(z, [4.0]);
    }
}
