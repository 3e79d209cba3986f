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
mod tests;
