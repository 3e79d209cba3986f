//! The sliding engine: the moments of a fixed-length window of evenly spaced samples in the
//! discrete Legendre basis, updated in `O(m²)` per sample whatever the window (Morrison §9.5
//! for the recursion's instability, countered here by exact refreshes; the polynomials of
//! Morrison (A1.1)). It serves both the streaming [`super::FixedMemory`] and the whole-series
//! [`super::smooth`].
//!
//! On the window axis `x = 0` (oldest) … `L` (newest) the moments are
//! `μ_j = Σ_x y(x) p_j(x)`, and `β_j = μ_j/c_j²` are the coefficients of the fit (7.4.5).
//! Sliding by one sample: `μ' = M (μ − y_old 𝟙) + y_new (p_j(L))_j` with the exact shift matrix
//! `p_j(x-1) = Σ_l M_jl p_l(x)` (`p_j(0) = 1`, `p_j(L) = (-1)^j`). `M` is unipotent, so the
//! recursion never forgets a rounding error; `q` staggered accumulators each sum one future
//! window directly (every sample at its final position, no shift) and replace `μ` when their
//! window is complete, so no error is carried through more than `⌈(L+1)/q⌉` shifts.

use crate::basis::DiscreteLegendre;
use crate::numeric::unrolled::unrolled_sizes;
use crate::scalar::{Rational, Scalar};

/// The default number of staggered refresh accumulators for degree `m` (an exact refresh every
/// `⌈(L+1)/q⌉` samples): `q = 2^⌊(m-1)/2⌋`. A carried error is extrapolated over at most `1/q`
/// of a window, where `p_m` grows by a factor that stays near 10 for every `m`.
pub(crate) fn default_refreshes(m: usize) -> usize {
    1 << (m.saturating_sub(1) / 2).min(20)
}

/// The refresh accumulators of whole-series smoothing: `q(m)` for `m ≤ 2`, `4·q(m)` above (an
/// exact refresh every `⌈(L+1)/(4q)⌉` samples). There every row is reported, each derivative
/// up to `m` relative to its own scale; from `m = 3` on the highest of them need the shorter
/// carried extrapolation to stay within a few `1e-12` of the exact convolution, at `O(q·m)`
/// extra work per sample.
pub(crate) fn smoothing_refreshes(m: usize) -> usize {
    if m <= 2 {
        default_refreshes(m)
    } else {
        4 * default_refreshes(m)
    }
}

/// The exact shift matrix `M` with `p_j(x-1) = Σ_l M_jl p_l(x)` (lower triangular, unit
/// diagonal), computed in rationals and rounded; row `j` holds `M_j0 … M_jj`.
fn shift_matrix(m: usize, span: u64) -> Vec<f64> {
    let basis = DiscreteLegendre::new(Rational::from_integer(span.into()));
    let polys: Vec<_> = (0..=m).map(|j| basis.polynomial(j)).collect();
    let minus_one = -Rational::from_i64(1);
    let mut out = vec![0.0; (m + 1) * (m + 1)];
    for j in 0..=m {
        let mut c: Vec<Rational> = (0..=j)
            .map(|i| polys[j].taylor_coefficient(i, &minus_one))
            .collect();
        for l in (0..=j).rev() {
            let lead = polys[l].coeffs[l].clone();
            let f = c[l].clone() / lead;
            for (i, ci) in c.iter_mut().enumerate().take(l + 1) {
                *ci = ci.clone() - f.clone() * polys[l].coeffs[i].clone();
            }
            out[j * (m + 1) + l] = f.to_f64();
        }
    }
    out
}

/// `p_0(x) … p_m(x)` on `x = 0..L` by the three-term recursion (A1.1) with precomputed
/// coefficients: `p_j = (A_j x + B_j) p_{j-1} - C_j p_{j-2}`, `A_j = -2(2j-1)/(j(L-j+1))`,
/// `B_j = L(2j-1)/(j(L-j+1))`, `C_j = (j-1)(L+j)/(j(L-j+1))`.
#[derive(Clone, Debug)]
struct LegendreRecursion {
    span: f64,
    coeffs: Vec<(f64, f64, f64)>,
}

impl LegendreRecursion {
    fn new(m: usize, span: usize) -> Self {
        let l = span as f64;
        let coeffs = (0..=m)
            .map(|j| {
                if j < 2 {
                    return (0.0, 0.0, 0.0);
                }
                let jf = j as f64;
                let denom = jf * (l - jf + 1.0);
                let t = 2.0 * jf - 1.0;
                (
                    -2.0 * t / denom,
                    l * t / denom,
                    (jf - 1.0) * (l + jf) / denom,
                )
            })
            .collect();
        Self { span: l, coeffs }
    }

    /// Fills `out` (length `m+1`) with `p_0(x) … p_m(x)`.
    fn values(&self, x: f64, out: &mut [f64]) {
        out[0] = 1.0;
        if out.len() > 1 {
            out[1] = 1.0 - 2.0 * x / self.span;
        }
        for j in 2..out.len() {
            let (a, b, c) = self.coeffs[j];
            out[j] = (a * x + b) * out[j - 1] - c * out[j - 2];
        }
    }
}

/// The moments `μ_j = Σ_{x=0..L} y(x) p_j(x)` of the newest `L+1` evenly spaced samples, by the
/// sliding recursion with `q` staggered exact refreshes.
#[derive(Clone, Debug)]
pub(super) struct SlidingMoments {
    window: usize,
    recursion: LegendreRecursion,
    /// `p_j(x)`, row `x = 0..=L`, when tabulated (else evaluated by the recursion as needed).
    table: Vec<f64>,
    shift: Vec<f64>,
    mu: Vec<f64>,
    valid: bool,
    /// Refresh accumulator `a` starts at sample `a·period`, holds `counts[a]` samples of its
    /// window and the sums `Σ y p_j(x)` in `sums[a(m+1)..(a+1)(m+1)]`, each sample added at
    /// its final position `x`.
    counts: Vec<usize>,
    sums: Vec<f64>,
    /// The accumulators started so far (`⌊n/period⌋ + 1`, at most `q`).
    started: usize,
    period: usize,
    scratch: Vec<f64>,
}

impl SlidingMoments {
    /// Degree `m`, `window = L+1 ≥ m+1` samples, `refreshes` accumulators (clamped to
    /// `1..=window`); `tabulate` keeps the `(L+1)(m+1)` values `p_j(x)` rather than evaluating
    /// them per sample (the same values: a table for whole series, none for streams).
    pub(super) fn new(m: usize, window: usize, refreshes: usize, tabulate: bool) -> Self {
        let q = refreshes.clamp(1, window);
        let recursion = LegendreRecursion::new(m, window - 1);
        let mut table = Vec::new();
        if tabulate {
            table.resize(window * (m + 1), 0.0);
            for (x, row) in table.chunks_exact_mut(m + 1).enumerate() {
                recursion.values(x as f64, row);
            }
        }
        Self {
            window,
            recursion,
            table,
            shift: shift_matrix(m, (window - 1) as u64),
            mu: vec![0.0; m + 1],
            valid: false,
            counts: vec![0; q],
            sums: vec![0.0; q * (m + 1)],
            started: 0,
            period: window.div_ceil(q),
            scratch: vec![0.0; m + 1],
        }
    }

    /// The samples between exact refreshes, `⌈(L+1)/q⌉`.
    pub(super) fn refresh_period(&self) -> usize {
        self.period
    }

    /// Takes the sample `y` with 0-based index `n` (every sample, in order: `n = 0, 1, …`);
    /// `old` is the sample leaving the window (`None` while the window fills).
    pub(super) fn push(&mut self, n: u64, y: f64, old: Option<f64>) {
        unrolled_sizes!(self.mu.len(), N => self.push_sized(N, n, y, old), p => self.push_sized(p, n, y, old));
    }

    /// [`Self::push`] for `p = m+1` (a constant where the dispatch makes it one).
    #[inline(always)]
    fn push_sized(&mut self, p: usize, n: u64, y: f64, old: Option<f64>) {
        let mu = &mut self.mu[..p];
        let scratch = &mut self.scratch[..p];
        if let (true, Some(o)) = (self.valid, old) {
            for (s, m) in scratch.iter_mut().zip(mu.iter()) {
                *s = m - o;
            }
            for (j, mj) in mu.iter_mut().enumerate() {
                let row = &self.shift[j * p..j * p + j + 1];
                let mut acc = 0.0;
                for (r, s) in row.iter().zip(scratch.iter()) {
                    acc += r * s;
                }
                *mj = if j % 2 == 0 { acc + y } else { acc - y };
            }
        }
        if self.started < self.counts.len() && n == (self.started * self.period) as u64 {
            self.started += 1;
        }
        for (count, sums) in self.counts[..self.started]
            .iter_mut()
            .zip(self.sums.chunks_exact_mut(p))
        {
            let values = if self.table.is_empty() {
                self.recursion.values(*count as f64, scratch);
                &scratch[..]
            } else {
                &self.table[*count * p..(*count + 1) * p]
            };
            for (s, r) in sums.iter_mut().zip(values) {
                *s += y * r;
            }
            *count += 1;
            if *count == self.window {
                mu.copy_from_slice(sums);
                self.valid = true;
                *count = 0;
                sums.iter_mut().for_each(|v| *v = 0.0);
            }
        }
    }

    /// The moments of the newest full window (`None` until `L+1` samples have arrived).
    pub(super) fn moments(&self) -> Option<&[f64]> {
        self.valid.then_some(&self.mu[..])
    }
}
