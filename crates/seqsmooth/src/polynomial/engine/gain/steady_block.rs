//! The steady fading recursion over whole blocks of [`STEADY_BLOCK`] even steps as one linear
//! map each ([`SteadyBlock`]; Morrison's fading-memory filter is time-invariant once its gains
//! are fixed, (13.5.35)).

use super::batch::{LINEAR_STEP_DEVIATION, STEADY_BLOCK, STEADY_BLOCK_MIN_BUILD_RUN};
use super::*;

/// The steady fading recursion `Z ← Ā Z + G y`, `Ā = (I − G e₀ᵀ) Φ(ζ̄)`, over
/// [`STEADY_BLOCK`] samples on an exactly even grid as one linear map:
/// `Z_B = Āᴮ Z_0 + Σ_j Ā^(B−1−j) G y_j` (the recursion unrolled; Morrison's fading-memory
/// filter is time-invariant once its gains are fixed, (13.5.35)). Computed once per gains and
/// step.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub(super) struct SteadyBlock {
    step: f64,
    gains: Vec<f64>,
    /// `Āᴮ`, row-major.
    power: Vec<f64>,
    /// Row `k` holds `[Ā^(B−1−j) G]_k` for `j = 0..B`.
    weights: Vec<f64>,
    /// The derivatives of `power` and `weights` with respect to the step `ζ`.
    power_d: Vec<f64>,
    weights_d: Vec<f64>,
}

impl SteadyBlock {
    /// The block map from the `f64` gains and step, and its derivative with respect to the
    /// step: `Ā = (I − G e₀ᵀ) Φ(ζ̄)` and `Ā' = (I − G e₀ᵀ) Φ'(ζ̄)` in double words (from the
    /// `f64` gains and step), the weights `Āʲ G` and their derivatives
    /// `(Āʲ G)' = Ā' Āʲ⁻¹ G + Ā (Āʲ⁻¹ G)'` one product at a time, and `Āᴮ`, `(Āᴮ)'` by
    /// repeated squaring (`(A²)' = A' A + A A'`), all in double-word arithmetic, each rounded
    /// once to `f64`. `Ā` is far from normal at high degree and `θ → 1`, so powers formed in
    /// plain `f64` lose accuracy (measured: see ACCURACY.md).
    pub(super) fn new(step: f64, gains: &[f64]) -> Self {
        let n = gains.len();
        // ζ̄ʲ in double words, and j·ζ̄^(j−1).
        let mut pw = vec![(1.0, 0.0); n];
        for j in 1..n {
            pw[j] = dw::mul_f64(pw[j - 1], step);
        }
        let times_int = |x: DoubleWord, c: f64| (x.0 * c, x.1 * c); // exact for small c·2^k
        let entry = |k: usize, j: usize, derivative: bool| -> DoubleWord {
            // Φ_kj = C(j,k) ζ^(j−k), Φ'_kj = C(j,k) (j−k) ζ^(j−k−1); minus g_k times row 0.
            let term = |kk: usize| -> DoubleWord {
                if j < kk || (derivative && j == kk) {
                    return (0.0, 0.0);
                }
                let c = crate::calculus::choose::<f64>(j, kk);
                if derivative {
                    times_int(pw[j - kk - 1], c * (j - kk) as f64)
                } else {
                    times_int(pw[j - kk], c)
                }
            };
            let row0 = term(0);
            let phi = if k == 0 { row0 } else { term(k) };
            dw::sub(phi, dw::scale(gains[k], row0))
        };
        let a: Vec<DoubleWord> = (0..n * n).map(|i| entry(i / n, i % n, false)).collect();
        let da: Vec<DoubleWord> = (0..n * n).map(|i| entry(i / n, i % n, true)).collect();
        let times = dw::mat_vec;
        let round = dw::round;
        let (mut weights, mut weights_d) =
            (vec![0.0; n * STEADY_BLOCK], vec![0.0; n * STEADY_BLOCK]);
        let mut w: Vec<DoubleWord> = gains.iter().map(|&g| (g, 0.0)).collect();
        let mut dw = vec![(0.0, 0.0); n];
        for j in (0..STEADY_BLOCK).rev() {
            for k in 0..n {
                weights[k * STEADY_BLOCK + j] = round(&w[k]);
                weights_d[k * STEADY_BLOCK + j] = round(&dw[k]);
            }
            // (w, w') ← (Ā w, Ā' w + Ā w')
            dw = dw::add_vectors(&times(&da, &w), &times(&a, &dw));
            w = times(&a, &w);
        }
        // Āᴮ and (Āᴮ)' by squaring (B is a power of two).
        let (mut p, mut dp) = (a, da);
        let mut size = 1;
        while size < STEADY_BLOCK {
            dp = dw::add_vectors(&dw::mat_mul(&dp, &p, n), &dw::mat_mul(&p, &dp, n));
            p = dw::mat_mul(&p, &p, n);
            size *= 2;
        }
        Self {
            step,
            gains: gains.to_vec(),
            power: p.iter().map(round).collect(),
            weights,
            power_d: dp.iter().map(round).collect(),
            weights_d,
        }
    }
}

/// `(Σ aᵢ yᵢ, Σ bᵢ yᵢ)` in one pass over `y`, each with four partial sums.
#[inline(always)]
pub(super) fn dot2(a: &[f64], b: &[f64], y: &[f64]) -> (f64, f64) {
    let (mut p, mut q) = ([0.0; 4], [0.0; 4]);
    for ((x, w), v) in a
        .chunks_exact(4)
        .zip(b.chunks_exact(4))
        .zip(y.chunks_exact(4))
    {
        for i in 0..4 {
            p[i] += x[i] * v[i];
            q[i] += w[i] * v[i];
        }
    }
    let r = y.len() - y.len() % 4;
    let (mut sp, mut sq) = ((p[0] + p[1]) + (p[2] + p[3]), (q[0] + q[1]) + (q[2] + q[3]));
    for ((x, w), v) in a[r..].iter().zip(&b[r..]).zip(&y[r..]) {
        sp += x * v;
        sq += w * v;
    }
    (sp, sq)
}

/// Row `k` of a `(N × STEADY_BLOCK)` row-major table.
#[inline(always)]
pub(super) fn block_row(w: &[f64], k: usize) -> &[f64] {
    &w[k * STEADY_BLOCK..(k + 1) * STEADY_BLOCK]
}

/// `Σ aᵢ bᵢ` with four independent partial sums (so the loop vectorises).
#[inline(always)]
pub(super) fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; 4];
    for (x, y) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        for i in 0..4 {
            acc[i] += x[i] * y[i];
        }
    }
    let mut s = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    let r = a.len() - a.len() % 4;
    for (x, y) in a[r..].iter().zip(&b[r..]) {
        s += x * y;
    }
    s
}

impl GainEngine {
    /// The steady fading recursion on whole blocks of [`STEADY_BLOCK`] even steps, each as one
    /// linear map ([`SteadyBlock`]): `N` dot products of the block's values and one `N × N`
    /// product per block instead of a recursion per sample. The map is that of a block whose
    /// samples are exactly its mean step `ζ̄ + δ` apart, to first order in `δ` (the mean step
    /// of decimal timestamps such as `k·0.001` differs from the typical step `ζ̄` by their
    /// rounding); within the block the samples' own times differ from that grid by a few units
    /// in the last place of `t`, which the per-sample recursion follows and the block map does
    /// not: the two differ by the order of that rounding (tests/batch.rs; measured: see
    /// ACCURACY.md). Returns how many samples it took (whole
    /// blocks; the first block with an uneven step stops it).
    pub(super) fn steady_block_run<const N: usize>(&mut self, ts: &[f64], ys: &[f64]) -> usize {
        let step = self.step_mean;
        let tau = self.unit;
        let check = StepCheck::new(step, tau);
        let even_block = |tb: &[f64], prev: f64| check.all_agree(tb, prev, 1.0 / tau);
        if ts.len() < STEADY_BLOCK || !even_block(&ts[..STEADY_BLOCK], self.t_last) {
            return 0;
        }
        let stale = match &self.block {
            Some(b) => b.step != step || b.gains[..] != self.k[..],
            None => true,
        };
        if stale {
            // Building the map costs about as much as the recursion over thousands of samples
            // (`O(B m³)` in double words; see BENCHMARKS.md): it is built once the recursion
            // has run `STEADY_BLOCK_MIN_BUILD_RUN·(m+1)²` samples at this step, or for a batch
            // that long.
            if self.block_credit_step != step {
                self.block_credit_step = step;
                self.block_credit = 0;
            }
            if self.block_credit.saturating_add(ts.len()) < STEADY_BLOCK_MIN_BUILD_RUN * N * N {
                return 0;
            }
            self.block = Some(Box::new(SteadyBlock::new(step, &self.k)));
        }
        let block = self.block.as_deref().expect("built above");
        let matrix = |v: &[f64]| -> [[f64; N]; N] {
            std::array::from_fn(|k| std::array::from_fn(|j| v[k * N + j]))
        };
        let (power, power_d) = (matrix(&block.power), matrix(&block.power_d));
        let (weights, weights_d) = (&block.weights, &block.weights_d);
        let linear = LINEAR_STEP_DEVIATION * step;
        let mut z = self.plain_state::<N>();
        let mut t_last = self.t_last;
        let mut done = 0;
        for (tb, yb) in ts
            .chunks_exact(STEADY_BLOCK)
            .zip(ys.chunks_exact(STEADY_BLOCK))
        {
            // The block's own mean step ζ̄ + δ: the map to first order in δ.
            let t_end = tb[STEADY_BLOCK - 1];
            let delta = (t_end - t_last) / (STEADY_BLOCK as f64 * tau) - step;
            let linear_enough = delta.abs() <= linear;
            if !linear_enough || !even_block(tb, t_last) {
                break;
            }
            let mut next: [f64; N] = if delta == 0.0 {
                std::array::from_fn(|k| dot(block_row(weights, k), yb))
            } else {
                std::array::from_fn(|k| {
                    let (w, wd) = dot2(block_row(weights, k), block_row(weights_d, k), yb);
                    w + delta * wd
                })
            };
            for (nk, (p, pd)) in next.iter_mut().zip(power.iter().zip(&power_d)) {
                *nk += dot(p, &z) + delta * dot(pd, &z);
            }
            z = next;
            t_last = t_end;
            done += STEADY_BLOCK;
        }
        self.end_plain_run(&z, t_last, done);
        done
    }
}
