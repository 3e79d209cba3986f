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

use crate::calculus::choose_integer;
use crate::numeric::memo::Memo;
use crate::numeric::unrolled::unrolled_sizes;
use crate::scalar::{Rational, Scalar};
use num_bigint::BigInt;
use std::sync::Arc;

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
/// diagonal), computed in rationals ([`exact_shift_matrix`]) and rounded, once per degree and
/// span (a process-wide memo); row `j` holds `M_j0 … M_jj`.
fn shift_matrix(m: usize, span: u64) -> Arc<Vec<f64>> {
    static SHIFTS: Memo<(usize, u64), Vec<f64>> = Memo::new();
    SHIFTS.get((m, span), || {
        exact_shift_matrix(m, span)
            .iter()
            .map(Scalar::to_f64)
            .collect()
    })
}

/// `M` exactly, in the falling-factorial basis where the shift has integer coefficients:
/// `p_j(x) = Σ_ν a_jν x^(ν)` with `a_jν = (-1)^ν C(j,ν) C(j+ν,ν) / L^(ν)` (3.2.20), and
/// `(x-1)^(ν) = Σ_k (-1)^(ν-k) (ν!/k!) x^(k)` (Vandermonde's theorem for factorial powers), so
/// `p_j(x-1) = Σ_k b_jk x^(k)`, `b_jk = Σ_{ν≥k} (-1)^(ν-k) (ν!/k!) a_jν`; back-substitution
/// against the triangular `a` gives row `j`: `O(m³)` rational operations.
fn exact_shift_matrix(m: usize, span: u64) -> Vec<Rational> {
    let span = BigInt::from(span);
    // L^(ν) for ν = 0..=m.
    let mut falling = vec![BigInt::from(1)];
    for nu in 0..m {
        let next = &falling[nu] * (&span - BigInt::from(nu));
        falling.push(next);
    }
    let a: Vec<Vec<Rational>> = (0..=m)
        .map(|j| {
            (0..=j)
                .map(|nu| {
                    let c = choose_integer(j, nu) * choose_integer(j + nu, nu);
                    let c = if nu % 2 == 0 { c } else { -c };
                    Rational::new(c, falling[nu].clone())
                })
                .collect()
        })
        .collect();
    let zero = Rational::from_integer(BigInt::from(0));
    let mut out = vec![zero.clone(); (m + 1) * (m + 1)];
    for j in 0..=m {
        let mut b: Vec<Rational> = (0..=j)
            .map(|k| {
                // (-1)^(ν-k) ν!/k!, from ν = k up.
                let mut factor = BigInt::from(1);
                let mut acc = zero.clone();
                for (nu, a_nu) in a[j].iter().enumerate().skip(k) {
                    if nu > k {
                        factor = -factor * BigInt::from(nu);
                    }
                    acc += a_nu * Rational::from_integer(factor.clone());
                }
                acc
            })
            .collect();
        for l in (0..=j).rev() {
            let f = &b[l] / &a[l][l];
            for (bk, alk) in b.iter_mut().zip(&a[l]) {
                *bk -= &f * alk;
            }
            out[j * (m + 1) + l] = f;
        }
    }
    out
}

/// `p_0(x) … p_m(x)` on `x = 0..L` by the three-term recursion (A1.1) with precomputed
/// coefficients: `p_j = (A_j x + B_j) p_{j-1} - C_j p_{j-2}`, `A_j = -2(2j-1)/(j(L-j+1))`,
/// `B_j = L(2j-1)/(j(L-j+1))`, `C_j = (j-1)(L+j)/(j(L-j+1))`.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
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
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub(super) struct SlidingMoments {
    window: usize,
    recursion: LegendreRecursion,
    /// `p_j(x)`, row `x = 0..=L`, when tabulated (else evaluated by the recursion as needed).
    table: Vec<f64>,
    shift: Arc<Vec<f64>>,
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

    /// Sets the number of refresh accumulators (clamped to `1..=window`), before the first
    /// sample: the shift matrix and the table stay.
    pub(super) fn set_refreshes(&mut self, refreshes: usize) {
        debug_assert_eq!(self.started, 0, "refreshes set after a sample");
        let q = refreshes.clamp(1, self.window);
        self.counts = vec![0; q];
        self.sums = vec![0.0; q * self.mu.len()];
        self.period = self.window.div_ceil(q);
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

#[cfg(test)]
mod tests {
    use super::exact_shift_matrix;
    use crate::basis::DiscreteLegendre;
    use crate::scalar::{Rational, Scalar};

    /// `p_j(x-1) = Σ_l M_jl p_l(x)` exactly, with `p` evaluated by (3.2.20) directly, at
    /// `x = 0..=L+1` (more points than the degree: the polynomials are equal).
    #[test]
    fn shift_matrix_shifts_by_one_exactly() {
        let cases = (0..=12)
            .flat_map(|m: usize| {
                [m as u64, m as u64 + 1, m as u64 + 7, 40].map(move |span| (m, span))
            })
            .chain([(24, 24), (25, 62)]);
        for (m, span) in cases {
            let shift = exact_shift_matrix(m, span);
            let basis = DiscreteLegendre::new(Rational::from_i64(span as i64));
            for x in 0..=span as i64 + 1 {
                let p: Vec<Rational> = (0..=m)
                    .map(|l| basis.value(l, Rational::from_i64(x)))
                    .collect();
                for j in 0..=m {
                    let shifted = basis.value(j, Rational::from_i64(x - 1));
                    let sum = (0..=j).fold(Rational::from_i64(0), |acc, l| {
                        acc + shift[j * (m + 1) + l].clone() * p[l].clone()
                    });
                    assert_eq!(sum, shifted, "degree {m}, span {span}, p_{j}({x} - 1)");
                    assert!(shift[j * (m + 2)] == Rational::from_i64(1), "unit diagonal");
                    for l in j + 1..=m {
                        assert_eq!(shift[j * (m + 1) + l], Rational::from_i64(0));
                    }
                }
            }
        }
    }
}
