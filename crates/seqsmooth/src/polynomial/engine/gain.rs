//! The fixed-gain recursion of Morrison's Tables 9.1 and 13.1 in the variable-step form of
//! Reyneke et al. §6, with the step scaling that makes it exact on evenly spaced samples for any
//! step: gains `h_k/ζ̄^k` and `θ_eff = θ^ζ̄` for the typical step `ζ̄` (Reyneke et al. §6.4).
//!
//! Numerics: the state — Taylor coefficients about the newest sample — is an ill-conditioned
//! representation, and the start-up gains `h_k(n)`, `n ≤ m`, are large; run in plain `f64`
//! from a zero state, the recursion loses accuracy at high degree, almost all of it from
//! rounding the start-up gains (measured accuracy: see ACCURACY.md). So the engine (1) starts from
//! the polynomial interpolating the first `m+1` samples, computed in double-word arithmetic
//! from Lagrange's form (no cancellation but in the final sum) — the state the recursion reaches from *any* initial state at `n = m` on even spacing
//! (Morrison §9.6), and the exact least-squares state on any spacing — and (2) carries the
//! state in compensated (double-word) arithmetic.

use super::recursion::predict_correct;
use crate::model::taylor::{unscale_in_range, unscale_stepwise};
use crate::model::{derivative_scale, factorial_powers, shift_scaled, shift_scaled_compensated};
use crate::numeric::double_word::{self as dw, two_prod, two_sum, DoubleWord};
use crate::numeric::memo::Memo;
use crate::numeric::steps::{same_step, snaps_to, StepCheck};
use crate::numeric::unrolled::{unrolled_sizes, UNROLLED_MAX_SIZE};
use crate::polynomial::expanding::gains::ExpandingGainSchedule;
use crate::polynomial::fading::gains::{fading_gains, fading_gains_exact};
use crate::polynomial::fading::switch::SwitchRule;
use crate::polynomial::fading::vrf::fading_vrf;
use crate::polynomial::form::{EstimateForm, GainForm};
use crate::polynomial::options::{DiscountMode, MAX_DEGREE};
use crate::scalar::{rational_from_f64, Scalar};
use nalgebra::DMatrix;
use std::sync::Arc;

/// A kernel's output row (if any): the unscaled derivatives `x_k = z_k·k!/τ^k`; returns
/// `0·Σ x_k`, which is 0 when they are all finite and NaN when one is not (a probe the kernels
/// add up, three operations a row where marking each number would take nine).
#[inline(always)]
fn write_row(row: Option<&mut [f64]>, z: &[f64], c: &[f64]) -> f64 {
    let mut sum = 0.0;
    if let Some(row) = row {
        for ((x, z), c) in row.iter_mut().zip(z).zip(c) {
            *x = z * c;
            sum += *x;
        }
    }
    sum * 0.0
}

/// `x`, or NaN ("no estimate") for an infinite `x`, branch-free: `x·((x − x) + 1)`, where
/// `x − x` is `0` for a finite `x` (so `x·1 = x`, the sign of a zero kept) and NaN for an
/// infinite one. Three floating-point operations, where the comparison `|x| = ∞` compiles to
/// integer masks; marking as the kernels write spares a pass over the rows.
#[inline(always)]
#[allow(clippy::eq_op)] // `x − x` is the test itself
pub(crate) fn out_of_range_as_nan(x: f64) -> f64 {
    x * ((x - x) + 1.0)
}

/// The gains for the typical step `ζ̄` from those for the unit step: `g_k ← g_k/ζ̄^k`
/// (Reyneke et al. §6.4), the powers as running products.
#[inline(always)]
fn scale_gains_for_step(g: &mut [f64], step: f64) {
    if step != 1.0 {
        let mut zk = 1.0;
        for gk in g.iter_mut().skip(1) {
            zk *= step;
            *gk /= zk;
        }
    }
}

/// A plain kernel's result: the state after `done` samples, the newest at `t_last`.
#[derive(Clone, Copy)]
struct PlainRun<const N: usize> {
    z: [f64; N],
    t_last: f64,
    done: usize,
}

/// Binomial coefficients `C(j, k)` for `j, k < N`.
fn binomials<const N: usize>() -> [[f64; N]; N] {
    let mut c = [[0.0; N]; N];
    for j in 0..N {
        c[j][0] = 1.0;
        for k in 1..=j {
            c[j][k] = c[j - 1][k - 1] + if k < j { c[j - 1][k] } else { 0.0 };
        }
    }
    c
}

/// The largest degree whose expanding-memory recursion [`GainEngine::update_many`] runs in
/// plain `f64`: above it the expanding recursion accumulates too much rounding against the
/// compensated path (measured: see ACCURACY.md).
pub(crate) const PLAIN_EXPANDING_MAX_DEGREE: usize = 4;

/// The largest degree whose steady fading recursion [`GainEngine::update_many`] runs in plain
/// `f64`: every size with unrolled code ([`crate::numeric::unrolled`]).
pub(crate) const PLAIN_KERNEL_MAX_DEGREE: usize = UNROLLED_MAX_SIZE - 1;

/// Samples per block of [`GainEngine::steady_block_run`] (a power of two: the block map's
/// power is formed by squaring).
const STEADY_BLOCK: usize = 64;

/// A block map is built (for new gains or a new step) only once the batches at that step
/// (those so far and the current one) reach this many samples times `(m+1)²`, so that its cost
/// is spread over them.
const STEADY_BLOCK_MIN_BUILD_RUN: usize = 512;

/// The largest relative deviation of a block's mean step from the typical step `ζ̄` that
/// the block map takes to first order (the dropped second-order term is then below 1e-18
/// relative, times binomial factors). The timestamps' rounding gives deviations near
/// `ε·|t|/(BΔt)`, far below.
const LINEAR_STEP_DEVIATION: f64 = 1e-9;

/// The largest degree whose expanding-memory `update_many` runs on even runs as a
/// least-squares update ([`super::expanding_block`]).
const EXPANDING_BLOCK_MAX_DEGREE: usize = 4;

/// The largest degree whose steady fading recursion `update_many` runs as block maps. Above
/// it the block map's rounding (weights of mixed sign, `Ā` far from normal) approaches the
/// tests' bound against the compensated per-sample path (tests/batch.rs; measured: see
/// ACCURACY.md).
const STEADY_BLOCK_MAX_DEGREE: usize = 5;

/// The steady fading recursion `Z ← Ā Z + G y`, `Ā = (I − G e₀ᵀ) Φ(ζ̄)`, over
/// [`STEADY_BLOCK`] samples on an exactly even grid as one linear map:
/// `Z_B = Āᴮ Z_0 + Σ_j Ā^(B−1−j) G y_j` (the recursion unrolled; Morrison's fading-memory
/// filter is time-invariant once its gains are fixed, (13.5.35)). Computed once per gains and
/// step.
#[derive(Clone, Debug)]
struct SteadyBlock {
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
    fn new(step: f64, gains: &[f64]) -> Self {
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
fn dot2(a: &[f64], b: &[f64], y: &[f64]) -> (f64, f64) {
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
fn block_row(w: &[f64], k: usize) -> &[f64] {
    &w[k * STEADY_BLOCK..(k + 1) * STEADY_BLOCK]
}

/// `Σ aᵢ bᵢ` with four independent partial sums (so the loop vectorises).
#[inline(always)]
fn dot(a: &[f64], b: &[f64]) -> f64 {
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

#[derive(Clone, Debug)]
pub(crate) struct FadingGains {
    pub theta: f64,
    pub mode: DiscountMode,
    pub rule: SwitchRule,
    /// For the constant rules: switch once `n ≥ c/(1-θ_s)`.
    pub constant: Option<f64>,
    /// The sample index at which the fading gains took over.
    pub switched_at: Option<u64>,
    /// Cache: the effective discount the gains below belong to, and the step it was computed
    /// for (so `θ^ζ̄` is not re-evaluated while the step repeats).
    pub theta_eff: f64,
    pub step_cached: f64,
    pub gains: Vec<f64>,
    /// Low words of `gains` (double-word gains), exact to ~2⁻¹⁰⁶.
    pub gains_lo: Vec<f64>,
    /// The double-word gains of `θ` itself (computed once per `(m, θ)` in the process).
    pub steady: Arc<(Vec<f64>, Vec<f64>)>,
}

/// The fading-memory gains at `θ` as double words `hi + lo`, from the exact rational formula.
pub(crate) fn fading_gains_double_word(m: usize, theta: f64) -> Arc<(Vec<f64>, Vec<f64>)> {
    static GAINS: Memo<(usize, u64), (Vec<f64>, Vec<f64>)> = Memo::new();
    GAINS.get((m, theta.to_bits()), || {
        fading_gains_double_word_uncached(m, theta)
    })
}

fn fading_gains_double_word_uncached(m: usize, theta: f64) -> (Vec<f64>, Vec<f64>) {
    let exact = fading_gains_exact(m, theta);
    let hi: Vec<f64> = exact.iter().map(|g| g.to_f64()).collect();
    let lo = exact
        .iter()
        .zip(&hi)
        .map(|(g, h)| (g.clone() - rational_from_f64(*h).unwrap_or_default()).to_f64())
        .collect();
    (hi, lo)
}

impl FadingGains {
    pub fn new(m: usize, theta: f64, mode: DiscountMode, rule: SwitchRule) -> Self {
        let constant = rule.asymptotic_constant(m);
        let dw = fading_gains_double_word(m, theta);
        Self {
            theta,
            mode,
            rule,
            constant,
            switched_at: None,
            theta_eff: theta,
            step_cached: 1.0,
            gains: dw.0.clone(),
            gains_lo: dw.1.clone(),
            steady: dw,
        }
    }
}

/// State: Morrison's scaled `Z` (unit `τ`) valid at `t_last`, as the double-word `z + z_lo`.
#[derive(Clone, Debug)]
pub(crate) struct GainEngine {
    m: usize,
    /// The discount's interval `τ`.
    tau: f64,
    /// The time unit of the state (scaled derivatives `z_k = x_k unit^k/k!`) and of the steps
    /// `ζ`: `τ`, unless the samples' step is so far from `τ` (beyond 2^±32) that the powers
    /// `ζ^k` and `unit^k` would overflow or underflow; then the power of two nearest the step
    /// (chosen at the start, [`Self::exact_start`]). The estimate does not depend on it beyond
    /// rounding.
    unit: f64,
    /// `unit/τ`: a step in units of the state times this is the step in units of `τ`, the
    /// exponent of the discount `θ^ζ`.
    per_tau: f64,
    /// Whether `k!/unit^k`, `k ≤ m`, are normal doubles (the batch kernels' read-out factors);
    /// set with the unit, so the per-sample loop does not recompute it.
    unit_in_range: bool,
    fading: Option<FadingGains>,
    schedule: ExpandingGainSchedule,
    z: Vec<f64>,
    z_lo: Vec<f64>,
    /// The first `m+1` samples, until the exact start.
    start: Vec<(f64, f64)>,
    t_first: f64,
    t_last: f64,
    /// The typical step `ζ̄` (in units of `τ`) the gains are scaled for: the mean step so far,
    /// and after a fading-memory switch an exponentially weighted mean over the memory.
    step_mean: f64,
    n: u64,
    k: Vec<f64>,
    k_lo: Vec<f64>,
    /// Noise variance and the scaled covariance of the estimate's random error.
    cov: Option<(f64, DMatrix<f64>)>,
    /// The covariance after the previous update (row-major), and whether the update left it
    /// unchanged (to [`COV_STEADY`] relative in every entry) after the fading switch: the steady state of
    /// the covariance's recursion for the current step and gains, which the plain kernels then
    /// keep while the steps stay equal to the typical one.
    cov_last: Vec<f64>,
    cov_steady: bool,
    /// The steady fading recursion's block map (built on first use).
    block: Option<Box<SteadyBlock>>,
    /// Samples the steady recursion has run in batches since the typical step was last
    /// `block_credit_step`: a new block map is built once they would have paid for it.
    block_credit: usize,
    block_credit_step: f64,
}

/// The relative change of every covariance entry below which an update has left the fading
/// filter's covariance at its steady state (the Joseph recursion contracts by `θ²` a step, and
/// its rounding keeps the last few bits moving): the plain kernels then keep it, the reported
/// 1σ within this of the recursion's.
const COV_STEADY: f64 = 1e-13;

impl GainEngine {
    pub fn new(m: usize, tau: f64, fading: Option<FadingGains>) -> Self {
        Self {
            m,
            tau,
            unit: tau,
            per_tau: 1.0,
            unit_in_range: unscale_in_range(m, tau),
            fading,
            schedule: ExpandingGainSchedule::new(m),
            z: vec![0.0; m + 1],
            z_lo: vec![0.0; m + 1],
            start: Vec::with_capacity(m + 1),
            t_first: f64::NAN,
            t_last: f64::NAN,
            step_mean: 1.0,
            n: 0,
            k: vec![0.0; m + 1],
            k_lo: vec![0.0; m + 1],
            cov: None,
            cov_last: Vec::new(),
            cov_steady: false,
            block: None,
            block_credit: 0,
            block_credit_step: f64::NAN,
        }
    }

    pub fn track_covariance(&mut self, sigma: f64) {
        self.cov = Some((sigma * sigma, DMatrix::zeros(self.m + 1, self.m + 1)));
        self.cov_last = vec![f64::NAN; (self.m + 1) * (self.m + 1)];
        self.cov_steady = false;
    }

    /// Whether the covariance is tracked (a noise σ was given).
    pub fn tracks_covariance(&self) -> bool {
        self.cov.is_some()
    }

    /// The 1σ of the unscaled derivatives at the newest sample, `√P_kk · k!/τ^k`, into `row`
    /// (NaN until determined or without a tracked covariance; a value beyond the double range
    /// is infinite, for the caller to refuse).
    pub fn std_devs_into(&self, row: &mut [f64]) {
        let Some((_, p)) = self.cov.as_ref().filter(|_| self.n > self.m as u64) else {
            row.fill(f64::NAN);
            return;
        };
        for (k, (s, (f, tk))) in row.iter_mut().zip(factorial_powers(self.unit)).enumerate() {
            let sd = p[(k, k)].max(0.0).sqrt();
            *s = if tk.is_normal() {
                sd * f / tk
            } else {
                unscale_stepwise(sd, k, self.unit)
            };
        }
    }

    /// [`update_many_into`](Self::update_many_into) with each row's 1σ: rows of `2(m+1)`
    /// (derivatives, then 1σ). The plain kernels run where they apply — with a tracked
    /// covariance, once it is steady ([`Self::update`]), its 1σ then the same for the run —
    /// the per-sample recursion elsewhere. `scratch` holds `ts.len()·(m+1)` derivatives.
    pub fn update_many_sigma_into(
        &mut self,
        ts: &[f64],
        ys: &[f64],
        rows: &mut [f64],
        scratch: &mut Vec<f64>,
    ) {
        let w = self.m + 1;
        let mut i = 0;
        while i < ts.len() {
            if self.plain_kernel_applies() {
                scratch.clear();
                scratch.resize((ts.len() - i) * w, 0.0);
                let done = self.steady_run(&ts[i..], &ys[i..], scratch, true);
                if done > 0 {
                    let mut sd = [0.0; MAX_DEGREE + 1];
                    self.std_devs_into(&mut sd[..w]);
                    for (row, d) in rows[i * 2 * w..(i + done) * 2 * w]
                        .chunks_exact_mut(2 * w)
                        .zip(scratch.chunks_exact(w))
                    {
                        row[..w].copy_from_slice(d);
                        row[w..].copy_from_slice(&sd[..w]);
                    }
                    i += done;
                    if i == ts.len() {
                        break;
                    }
                }
            }
            self.update(ts[i], ys[i]);
            let row = &mut rows[i * 2 * w..(i + 1) * 2 * w];
            let (d, s) = row.split_at_mut(w);
            self.derivatives_into(d);
            self.std_devs_into(s);
            i += 1;
        }
    }

    pub fn samples(&self) -> u64 {
        self.n
    }

    pub fn last_time(&self) -> f64 {
        self.t_last
    }

    pub fn switched_at(&self) -> Option<u64> {
        self.fading.as_ref().and_then(|f| f.switched_at)
    }

    /// Processes one sample; `t` must exceed the previous time (checked by the caller).
    pub fn update(&mut self, t: f64, y: f64) {
        if self.n == 0 {
            self.t_first = t;
        }
        if self.n <= self.m as u64 {
            self.start.push((t, y));
            self.t_last = t;
            self.n += 1;
            if self.n == self.m as u64 + 1 {
                self.exact_start();
            }
            return;
        }
        let zeta = (t - self.t_last) / self.unit;
        shift_scaled_compensated(&mut self.z, &mut self.z_lo, zeta);
        // e = y - (z0 + z0_lo) as the double-word e + e_lo.
        let (d, de) = two_sum(y, -self.z[0]);
        let (e, e_lo) = two_sum(d, de - self.z_lo[0]);
        self.update_step_mean(t, zeta);
        self.choose_gains(t);
        scale_gains_for_step(&mut self.k, self.step_mean);
        scale_gains_for_step(&mut self.k_lo, self.step_mean);
        for (((zi, lo), ki), kl) in self
            .z
            .iter_mut()
            .zip(self.z_lo.iter_mut())
            .zip(&self.k)
            .zip(&self.k_lo)
        {
            let (p, pe) = two_prod(*ki, e);
            let (s, se) = two_sum(*zi, p);
            let (s, l) = two_sum(s, *lo + se + pe + ki * e_lo + kl * e);
            *zi = s;
            *lo = l;
        }
        if let Some((var, p)) = &mut self.cov {
            // P ← Φ(ζ) P Φ(ζ)ᵀ, then the Joseph form P ← (I - K e0ᵀ) P (I - K e0ᵀ)ᵀ + σ² K Kᵀ:
            // the exact covariance of this linear estimator's random error. In place, without
            // allocating: the shift on P's columns, P transposed (Pᵀ Φᵀ = (Φ P)ᵀ), the shift
            // on its columns again; then (A P Aᵀ)_ij = P_ij − K_i P_0j − P_i0 K_j + K_i K_j P_00.
            let dim = self.m + 1;
            for col in p.as_mut_slice().chunks_exact_mut(dim) {
                shift_scaled(col, zeta);
            }
            p.transpose_mut();
            for col in p.as_mut_slice().chunks_exact_mut(dim) {
                shift_scaled(col, zeta);
            }
            let mut row0 = [0.0; MAX_DEGREE + 1];
            for (j, r) in row0[..dim].iter_mut().enumerate() {
                *r = p[(0, j)];
            }
            let mut col0 = [0.0; MAX_DEGREE + 1];
            for (i, c) in col0[..dim].iter_mut().enumerate() {
                *c = p[(i, 0)];
            }
            let p00 = row0[0] + *var;
            let mut converged = self
                .fading
                .as_ref()
                .is_some_and(|f| f.switched_at.is_some());
            for j in 0..dim {
                for i in 0..dim {
                    let (ki, kj) = (self.k[i], self.k[j]);
                    let v = p[(i, j)] - ki * row0[j] - col0[i] * kj + ki * kj * p00;
                    converged &= (v - self.cov_last[i * dim + j]).abs() <= COV_STEADY * v.abs();
                    self.cov_last[i * dim + j] = v;
                    p[(i, j)] = v;
                }
            }
            self.cov_steady = converged;
        }
        self.t_last = t;
        self.n += 1;
    }

    /// Processes a batch of checked samples: [`update`](Self::update) on each, except that
    /// the plain kernels take over where they apply ([`steady_run`](Self::steady_run)).
    pub fn update_many(&mut self, ts: &[f64], ys: &[f64]) {
        self.update_many_with(ts, ys, &mut [], false);
    }

    /// [`update_many`](Self::update_many), writing the unscaled derivatives after each sample
    /// into `out` (`ts.len()·(m+1)` values, row-major; NaN until determined, and for a
    /// derivative beyond the double range).
    pub fn update_many_into(&mut self, ts: &[f64], ys: &[f64], out: &mut [f64]) {
        self.update_many_with(ts, ys, out, true);
    }

    fn update_many_with(&mut self, ts: &[f64], ys: &[f64], out: &mut [f64], write: bool) {
        let w = self.m + 1;
        let mut i = 0;
        while i < ts.len() {
            if self.plain_kernel_applies() {
                let rows = if write {
                    &mut out[i * w..]
                } else {
                    &mut [][..]
                };
                i += self.steady_run(&ts[i..], &ys[i..], rows, write);
                if i == ts.len() {
                    break;
                }
            }
            self.update(ts[i], ys[i]);
            if write {
                self.derivatives_into(&mut out[i * w..(i + 1) * w]);
            }
            i += 1;
        }
    }

    /// The unscaled derivatives at the newest sample (NaN until determined): `x_k = z_k k!/τ^k`.
    fn derivatives_into(&self, row: &mut [f64]) {
        if self.n <= self.m as u64 {
            row.fill(f64::NAN);
            return;
        }
        for (k, (x, (f, tk))) in row.iter_mut().zip(factorial_powers(self.unit)).enumerate() {
            let z = self.z[k] + self.z_lo[k];
            *x = out_of_range_as_nan(if tk.is_normal() {
                z * f / tk
            } else {
                unscale_stepwise(z, k, self.unit)
            });
        }
    }

    fn plain_kernel_applies(&self) -> bool {
        (self.cov.is_none() || self.cov_steady)
            && self.unit_in_range
            && self.m <= PLAIN_KERNEL_MAX_DEGREE
            && match &self.fading {
                Some(f) => f.switched_at.is_some(),
                None => self.n > self.m as u64 && self.m <= PLAIN_EXPANDING_MAX_DEGREE,
            }
    }

    /// The steady-state fading recursion on a run of (nearly) even steps in plain `f64`, with
    /// the state in registers: `Z ← Φ(ζ) Z`, `ε = y − z₀`, `Z ← Z + K ε`, the gains `K` those
    /// of the typical step. Returns how many samples it took (it stops at the first step that
    /// differs from the typical one ([`crate::numeric::steps`]).
    fn steady_run(&mut self, ts: &[f64], ys: &[f64], out: &mut [f64], write: bool) -> usize {
        // Without per-sample outputs, whole blocks of the steady fading recursion first.
        let blocks = if self.fading.is_none() && !write && self.m <= EXPANDING_BLOCK_MAX_DEGREE {
            self.expanding_block_run(ts, ys)
        } else if self.fading.is_some() && !write && self.m <= STEADY_BLOCK_MAX_DEGREE {
            unrolled_sizes!(self.m + 1, N => self.steady_block_run::<N>(ts, ys), _ => 0)
        } else {
            0
        };
        let (ts, ys) = (&ts[blocks..], &ys[blocks..]);
        let steady = self.fading.is_some() && !write;
        let rest = if write {
            unrolled_sizes!(self.m + 1, N => self.plain_run_n::<N, true>(ts, ys, out), _ => 0)
        } else {
            unrolled_sizes!(self.m + 1, N => self.plain_run_n::<N, false>(ts, ys, out), _ => 0)
        };
        if steady {
            self.block_credit = self.block_credit.saturating_add(rest);
        }
        blocks + rest
    }

    /// `k!/τ^k`, the factors from scaled to unscaled derivatives (as in
    /// [`crate::model::scaled_to_derivatives`], rounded once more).
    fn derivative_factors<const N: usize>(&self) -> [f64; N] {
        let mut c = [1.0; N];
        for (ck, d) in c.iter_mut().zip(derivative_scale(self.unit)) {
            *ck = d;
        }
        c
    }

    /// The state as plain `f64` (the double word folded), for the kernels below.
    fn plain_state<const N: usize>(&self) -> [f64; N] {
        std::array::from_fn(|k| self.z[k] + self.z_lo[k])
    }

    /// Stores a kernel's state after `done` samples, the newest at `t_last`.
    fn end_plain_run(&mut self, z: &[f64], t_last: f64, done: usize) {
        self.z.copy_from_slice(z);
        self.z_lo.iter_mut().for_each(|v| *v = 0.0);
        self.t_last = t_last;
        self.n += done as u64;
    }

    /// The plain-`f64` kernels on a run after the exact start, the state in registers, both
    /// generated from one loop ([`plain_run`](Self::plain_run)) and tested against the
    /// reference recursion ([`predict_correct`]); with `W`, each sample's derivatives go to
    /// `out`. Returns how many samples it took.
    ///
    /// - Expanding memory, any steps: the same operations as [`update`](Self::update) (gains
    ///   `h_k(n)` of Table 9.1 scaled for the mean step) without the compensation, the
    ///   reference recursion itself per sample. Takes every sample.
    /// - Fading memory after the switch, the gains fixed: the reference recursion regrouped,
    ///   on a run of steps equal to the typical one ([`StepCheck`]).
    fn plain_run_n<const N: usize, const W: bool>(
        &mut self,
        ts: &[f64],
        ys: &[f64],
        out: &mut [f64],
    ) -> usize {
        if self.fading.is_none() {
            let mut g = [0.0; N];
            let (tau, t_first, schedule) = (self.unit, self.t_first, &self.schedule);
            let mut n = self.n;
            let mut last_step = self.step_mean;
            let run = self.plain_run::<N, W>(ts, ys, out, |z, t, zeta, y| {
                let mut step = (t - t_first) / (n as f64 * tau);
                if snaps_to(step, zeta) {
                    step = zeta;
                }
                schedule.gains(n, &mut g);
                scale_gains_for_step(&mut g, step);
                predict_correct(z, zeta, &g, y);
                last_step = step;
                n += 1;
                true
            });
            self.end_plain_run(&run.z, run.t_last, run.done);
            self.step_mean = last_step;
            run.done
        } else {
            let g: [f64; N] = std::array::from_fn(|k| self.k[k]);
            let check = StepCheck::new(self.step_mean, self.unit);
            // The correction folded into the prediction (so the chain from one sample to the next
            // is one multiplication and two additions deep): with `d = y − z₀` and the powers
            // `ζʲ`,
            //   z₀' = (1 − g₀) z₀ + g₀ y + Σ_{j≥1} (1 − g₀) ζʲ z_j,
            //   z_k' = Σ_{j≥1} M_kj z_j + g_k d,  M_kj = C(j,k) ζ^(j−k) [j ≥ k] − g_k ζʲ  (k ≥ 1),
            // which is `Φ(ζ)Z + G(y − [Φ(ζ)Z]₀)` regrouped. `M` is rebuilt only when `ζ` changes.
            let binom = binomials::<N>();
            let mut zeta_m = f64::NAN;
            let mut mk = [[0.0; N]; N];
            let (g0y, one_minus_g0) = (g[0], 1.0 - g[0]);
            let run = self.plain_run::<N, W>(ts, ys, out, |z, t, zeta, y| {
                if !check.agrees(zeta, t) {
                    return false;
                }
                if zeta != zeta_m {
                    zeta_m = zeta;
                    let mut pw = [1.0; N];
                    for j in 1..N {
                        pw[j] = pw[j - 1] * zeta;
                    }
                    for j in 1..N {
                        mk[0][j] = one_minus_g0 * pw[j];
                    }
                    for k in 1..N {
                        for j in 1..N {
                            let phi = if j >= k { binom[j][k] * pw[j - k] } else { 0.0 };
                            mk[k][j] = phi - g[k] * pw[j];
                        }
                    }
                }
                let d = y - z[0];
                let mut next = [0.0; N];
                next[0] = one_minus_g0 * z[0] + g0y * y;
                if N > 1 {
                    let mut tail = mk[0][1] * z[1];
                    for j in 2..N {
                        tail += mk[0][j] * z[j];
                    }
                    next[0] += tail;
                    for k in 1..N {
                        let mut acc = mk[k][1] * z[1];
                        for j in 2..N {
                            acc += mk[k][j] * z[j];
                        }
                        next[k] = acc + g[k] * d;
                    }
                }
                *z = next;
                true
            });
            self.end_plain_run(&run.z, run.t_last, run.done);
            run.done
        }
    }

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
    fn steady_block_run<const N: usize>(&mut self, ts: &[f64], ys: &[f64]) -> usize {
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

    /// Expanding memory on a run of whole blocks of [`STEADY_BLOCK`] even steps: on an even
    /// grid the filter's state is the least-squares polynomial through every sample so far
    /// (Morrison §9.4), so the run is folded in as one least-squares update
    /// ([`super::expanding_block::advance_even_fit`]) instead of a recursion per sample. The
    /// grid is the run's own: from the first sample to the run's last at their mean step (the
    /// old state moved onto it first, by the rounding of the timestamps); within it, the samples'
    /// own times differ from the grid by their rounding, which the per-sample recursion follows
    /// and this does not (measured in tests/batch.rs). Returns how many samples it took.
    fn expanding_block_run(&mut self, ts: &[f64], ys: &[f64]) -> usize {
        if self.n <= self.m as u64 || ts.is_empty() {
            return 0;
        }
        if self.m == 0 {
            // Degree 0 is the running mean, whatever the steps.
            let mut z = [self.z[0] + self.z_lo[0]];
            super::expanding_block::advance_even_fit(0, self.n, &mut z, ys);
            self.end_plain_run(&z, ts[ts.len() - 1], ts.len());
            return ts.len();
        }
        // The mean step so far (the one the recursion's gains are scaled for).
        let step = (self.t_last - self.t_first) / ((self.n - 1) as f64 * self.unit);
        let mut prev = self.t_last;
        let mut take = 0;
        for tb in ts.chunks_exact(STEADY_BLOCK) {
            if !StepCheck::new(step, self.unit).all_agree(tb, prev, 1.0 / self.unit) {
                break;
            }
            take += STEADY_BLOCK;
            prev = tb[STEADY_BLOCK - 1];
        }
        if take == 0 {
            return 0;
        }
        let (tau, m, n) = (self.unit, self.m, self.n);
        let t_end = ts[take - 1];
        // The grid from the first sample to the run's last, in units of its step.
        let grid = (t_end - self.t_first) / ((n + take as u64 - 1) as f64 * tau);
        // The old state onto the grid's sample n−1 (a rounding-sized move), then in grid units.
        let mut z = [0.0; MAX_DEGREE + 1];
        let z = &mut z[..=m];
        for (zk, (hi, lo)) in z.iter_mut().zip(self.z.iter().zip(&self.z_lo)) {
            *zk = hi + lo;
        }
        let moved = (self.t_first - self.t_last) / tau + (n - 1) as f64 * grid;
        shift_scaled(z, moved);
        let mut power = 1.0;
        for zk in z.iter_mut() {
            *zk *= power;
            power *= grid;
        }
        super::expanding_block::advance_even_fit(m, n, z, &ys[..take]);
        let mut power = 1.0;
        for zk in z.iter_mut() {
            *zk /= power;
            power *= grid;
        }
        self.z.copy_from_slice(z);
        self.z_lo.iter_mut().for_each(|v| *v = 0.0);
        self.t_last = t_end;
        self.n += take as u64;
        self.step_mean = grid;
        take
    }

    /// The plain kernels' common loop: from the state folded to `f64`, for each sample the
    /// step `ζ = (t − t_last)/τ` and `step(z, t, ζ, y)`, which advances `z` over the sample or
    /// returns false to stop before it; with `W`, the derivatives after each sample go to
    /// `out`. The caller stores the result ([`end_plain_run`](Self::end_plain_run)).
    #[inline(always)]
    fn plain_run<const N: usize, const W: bool>(
        &self,
        ts: &[f64],
        ys: &[f64],
        out: &mut [f64],
        mut step: impl FnMut(&mut [f64; N], f64, f64, f64) -> bool,
    ) -> PlainRun<N> {
        let c = self.derivative_factors::<N>();
        let mut rows = out.chunks_exact_mut(N);
        let mut z = self.plain_state::<N>();
        let (tau, mut t_last, mut done) = (self.unit, self.t_last, 0);
        let mut probe = 0.0;
        for (&t, &y) in ts.iter().zip(ys) {
            let zeta = (t - t_last) / tau;
            if !step(&mut z, t, zeta, y) {
                break;
            }
            if W {
                probe += write_row(rows.next(), &z, &c);
            }
            t_last = t;
            done += 1;
        }
        if W && probe != 0.0 {
            // A number beyond the double range (rare): marked NaN, "no estimate".
            for x in &mut out[..done * N] {
                *x = out_of_range_as_nan(*x);
            }
        }
        PlainRun { z, t_last, done }
    }

    /// The step the gains are scaled for. On even samples it is the step itself, which makes the
    /// recursion exact for any step (gains `h_k/ζ^k`, `θ_eff = θ^ζ`; Reyneke et al. §6.4). On
    /// irregular samples the current step would be the wrong scale — a burst of close samples
    /// would get gains `h_k/ζ^k` far too large, and the recursion diverges (measured on
    /// exponential gaps: see ACCURACY.md) — so the gains are scaled for the typical step of the memory.
    fn update_step_mean(&mut self, t: f64, zeta: f64) {
        let switched = self.fading.as_ref().and_then(|f| f.switched_at).is_some();
        if !switched {
            self.step_mean = (t - self.t_first) / (self.n as f64 * self.unit);
            // Exactly even samples: the mean equals the step up to rounding; use the step.
            if snaps_to(self.step_mean, zeta) {
                self.step_mean = zeta;
            }
        } else if !same_step(zeta, self.step_mean, t, self.unit) {
            // Steps equal to the typical one up to the rounding of the timestamps (even
            // sampling) keep the gains; the prediction always uses the true step.
            let f = self.fading.as_ref().expect("switched implies fading");
            let w = match f.mode {
                DiscountMode::PerUpdate => f.theta,
                DiscountMode::PerTime => f.theta.powf(self.step_mean * self.per_tau),
            };
            self.step_mean = w * self.step_mean + (1.0 - w) * zeta;
            if snaps_to(self.step_mean, zeta) {
                self.step_mean = zeta;
            }
        }
    }

    /// Writes the current-estimate gains for the sample with index `self.n` into `self.k`.
    fn choose_gains(&mut self, t: f64) {
        let n = self.n;
        let m = self.m;
        self.k_lo.iter_mut().for_each(|v| *v = 0.0);
        let Some(f) = &mut self.fading else {
            self.schedule.gains(n, &mut self.k);
            return;
        };
        if f.switched_at.is_none() {
            // The discount per sample so far: θ itself per update, or θ^(mean step/τ).
            let theta_s = match f.mode {
                DiscountMode::PerUpdate => f.theta,
                DiscountMode::PerTime => f
                    .theta
                    .powf((t - self.t_first) / (n as f64 * self.unit) * self.per_tau),
            };
            let (schedule, k) = (&self.schedule, &mut self.k);
            let crossover = || {
                // The expanding-memory position VRF h_0(n) against the fading-memory one.
                schedule.gains(n, k);
                let target = fading_vrf(m, theta_s, EstimateForm::Current)
                    .map(|s| s[(0, 0)])
                    .unwrap_or(0.0);
                Ok::<_, std::convert::Infallible>((k[0], target))
            };
            let switch = f
                .rule
                .switches(m, n, theta_s, f.constant, crossover)
                .unwrap_or_else(|never| match never {});
            if !switch {
                self.schedule.gains(n, &mut self.k);
                return;
            }
            f.switched_at = Some(n);
        }
        let theta_eff = match f.mode {
            DiscountMode::PerUpdate => f.theta,
            DiscountMode::PerTime if self.step_mean == f.step_cached => f.theta_eff,
            DiscountMode::PerTime => {
                f.step_cached = self.step_mean;
                f.theta.powf(self.step_mean * self.per_tau)
            }
        };
        if theta_eff != f.theta_eff {
            // The steady θ's gains are double words from the exact formula (computed once);
            // other effective discounts (steps ≠ τ) use the f64 formula, whose terms are all
            // positive (relative error ~1e-15), cached while the step repeats.
            f.theta_eff = theta_eff;
            if theta_eff == f.theta {
                f.gains.clone_from(&f.steady.0);
                f.gains_lo.clone_from(&f.steady.1);
            } else {
                f.gains = fading_gains(m, theta_eff, GainForm::Current);
                f.gains_lo.iter_mut().for_each(|v| *v = 0.0);
            }
        }
        self.k.copy_from_slice(&f.gains);
        self.k_lo.copy_from_slice(&f.gains_lo);
    }

    /// The polynomial through the first `m+1` samples, as scaled Taylor coefficients about the
    /// newest of them, and, when tracked, its covariance `σ² L Lᵀ` with `L` the interpolation
    /// weights. Lagrange's form in `u = (t − t_m)/τ` (every `u_j ≤ 0`):
    /// `ℓ_i(u) = Π_{j≠i} (u − u_j) / Π_{j≠i} (u_i − u_j)`, so `L_ki` is the coefficient of `u^k`
    /// in the numerator — a product of factors `u + |u_j|`, whose coefficients are sums of
    /// positive terms — over the product of the differences, each difference `(t_i − t_j)/τ`
    /// formed from the times without cancellation. In double words every `L_ki` is then good to
    /// a few units of 2⁻¹⁰⁶ relative, and `z_k = Σ_i L_ki y_i` is a double-word dot product: the
    /// start is as good as an exact one for an `f64` state, in `O(m³)` double-word operations
    /// instead of rational arithmetic whose numbers grow with the degree.
    fn exact_start(&mut self) {
        let m = self.m;
        if m > 0 {
            let step = (self.start[m].0 - self.start[0].0) / m as f64;
            let ratio = step / self.tau;
            if !(2f64.powi(-32)..=2f64.powi(32)).contains(&ratio) {
                // At most 2^980: Dekker's product, under every double-word operation, splits
                // its operands and needs them below 2^996.
                let unit = step.log2().round().clamp(-1000.0, 980.0).exp2();
                self.unit = unit;
                self.per_tau = unit / self.tau;
                self.unit_in_range = unscale_in_range(m, unit);
            }
        }
        let t = |i: usize| self.start[i].0;
        let diff = |i: usize, j: usize| dw::div(two_sum(t(i), -t(j)), (self.unit, 0.0));
        let mut weights = vec![(0.0, 0.0); (m + 1) * (m + 1)]; // L, row-major (k, i)
        let mut numerator = vec![(0.0, 0.0); m + 1];
        for i in 0..=m {
            numerator.fill((0.0, 0.0));
            numerator[0] = (1.0, 0.0);
            let mut denominator = (1.0, 0.0);
            for (len, j) in (1..).zip((0..=m).filter(|&j| j != i)) {
                // numerator ← numerator · (u + a_j), a_j = (t_m − t_j)/τ ≥ 0.
                let a = diff(m, j);
                for k in (0..=len).rev() {
                    let shifted = if k > 0 { numerator[k - 1] } else { (0.0, 0.0) };
                    let kept = if k < len {
                        dw::mul(a, numerator[k])
                    } else {
                        (0.0, 0.0)
                    };
                    numerator[k] = dw::add(shifted, kept);
                }
                denominator = dw::mul(denominator, diff(i, j));
            }
            for (k, c) in numerator.iter().enumerate() {
                weights[k * (m + 1) + i] = dw::div(*c, denominator);
            }
        }
        let ys: Vec<DoubleWord> = self.start.iter().map(|&(_, y)| (y, 0.0)).collect();
        for (k, row) in weights.chunks_exact(m + 1).enumerate() {
            let zk = dw::dot(row, &ys);
            (self.z[k], self.z_lo[k]) = two_sum(zk.0, zk.1);
        }
        if let Some((var, p)) = &mut self.cov {
            let l = DMatrix::from_fn(m + 1, m + 1, |k, i| dw::round(&weights[k * (m + 1) + i]));
            *p = &l * l.transpose() * *var;
            self.cov_steady = false;
        }
        self.start.clear();
    }

    /// Unscaled derivatives (and their covariance) of the estimate valid at `t`.
    pub fn estimate_at(&self, t: f64) -> (Vec<f64>, Option<DMatrix<f64>>) {
        let v = (t - self.t_last) / self.unit;
        let p = self.m + 1;
        let (mut hi, mut lo) = ([0.0; MAX_DEGREE + 1], [0.0; MAX_DEGREE + 1]);
        hi[..p].copy_from_slice(&self.z);
        lo[..p].copy_from_slice(&self.z_lo);
        shift_scaled_compensated(&mut hi[..p], &mut lo[..p], v);
        for (h, l) in hi[..p].iter_mut().zip(&lo[..p]) {
            *h += l;
        }
        let x = crate::model::scaled_to_derivatives(&hi[..p], self.unit);
        let cov = self.cov.as_ref().map(|(_, p)| {
            let j = crate::model::scaling(self.m, self.unit) * crate::model::phi(self.m, v);
            &j * p * j.transpose()
        });
        (x, cov)
    }
}

#[cfg(test)]
mod tests {
    //! Every fast path of the engine against the reference recursion
    //! ([`predict_correct`]) run from the same state with the same gains, degrees 0 … 8.
    use super::super::testing::scaled_errors;
    use super::*;

    /// Smooth data with a trend of degree `m` and deterministic pseudo-noise.
    fn data(n: usize, m: usize) -> Vec<f64> {
        (0..n)
            .map(|k| {
                let x = k as f64 / n as f64;
                let trend = (0..=m).fold(0.0, |acc, j| acc * x + 1.0 + 0.5 * j as f64);
                trend + (7.0 * x).sin() + 0.3 * (((k * 7919) % 101) as f64 / 101.0 - 0.5)
            })
            .collect()
    }

    /// The worst scaled error ([`scaled_errors`]) with `S` the memory span.
    fn scaled_error(z: &[f64], want: &[f64], span: f64) -> f64 {
        scaled_errors(z, want, span).into_iter().fold(0.0, f64::max)
    }

    /// The reference from the engine's state over `ts`, `ys` with the gains `h(i)`.
    fn reference(
        e: &GainEngine,
        ts: &[f64],
        ys: &[f64],
        h: impl Fn(usize) -> Vec<f64>,
    ) -> Vec<f64> {
        let mut z: Vec<f64> = e.z.iter().zip(&e.z_lo).map(|(a, b)| a + b).collect();
        let mut t_last = e.t_last;
        for (i, (&t, &y)) in ts.iter().zip(ys).enumerate() {
            predict_correct(&mut z, (t - t_last) / e.unit, &h(i), y);
            t_last = t;
        }
        z
    }

    /// A fading engine fed sample by sample up to its switch; returns it and the samples used.
    fn switched(m: usize, theta: f64, tau: f64, ts: &[f64], ys: &[f64]) -> (GainEngine, usize) {
        let fading = FadingGains::new(m, theta, DiscountMode::PerUpdate, SwitchRule::Position);
        let mut e = GainEngine::new(m, tau, Some(fading));
        let mut i = 0;
        while e.switched_at().is_none() {
            e.update(ts[i], ys[i]);
            i += 1;
        }
        (e, i)
    }

    /// The steady fading kernels (per sample, with and without outputs; block maps up to
    /// degree 5) and the compensated update against the reference, within the bound of the
    /// batch tests (1e-11).
    #[test]
    fn steady_fast_paths_match_the_reference() {
        for m in 0..=PLAIN_KERNEL_MAX_DEGREE {
            for &(theta, tau) in &[(0.9, 1.0), (0.95, 0.1)] {
                let n = 512 * (m + 1) * (m + 1) + 4 * STEADY_BLOCK + 1000;
                let ts: Vec<f64> = (0..n).map(|k| k as f64 * tau).collect();
                let ys = data(n, m);
                let (start, i) = switched(m, theta, tau, &ts, &ys);
                let (ts, ys) = (&ts[i..], &ys[i..]);
                let gains = start.k.clone();
                let span = 1.0 / (1.0 - theta);
                let want = reference(&start, ts, ys, |_| gains.clone());
                let mut out = vec![0.0; ts.len() * (m + 1)];
                for write in [false, true] {
                    let mut e = start.clone();
                    let done = match write {
                        false => {
                            unrolled_sizes!(m + 1, N => e.plain_run_n::<N, false>(ts, ys, &mut out), _ => 0)
                        }
                        true => {
                            unrolled_sizes!(m + 1, N => e.plain_run_n::<N, true>(ts, ys, &mut out), _ => 0)
                        }
                    };
                    assert_eq!(done, ts.len(), "m {m}: the kernel stopped early");
                    let err = scaled_error(&e.z, &want, span);
                    assert!(err <= 1e-11, "m {m} θ {theta} write {write}: {err:e}");
                }
                let mut e = start.clone();
                for (&t, &y) in ts.iter().zip(ys) {
                    e.update(t, y);
                }
                let folded: Vec<f64> = e.z.iter().zip(&e.z_lo).map(|(a, b)| a + b).collect();
                let err = scaled_error(&folded, &want, span);
                assert!(err <= 1e-11, "m {m} θ {theta} compensated: {err:e}");
                if m <= STEADY_BLOCK_MAX_DEGREE {
                    let mut e = start.clone();
                    let done = unrolled_sizes!(m + 1, N => e.steady_block_run::<N>(ts, ys), _ => 0);
                    assert!(
                        done >= ts.len() - STEADY_BLOCK,
                        "m {m}: {done} of {}",
                        ts.len()
                    );
                    let want = reference(&start, &ts[..done], &ys[..done], |_| gains.clone());
                    let err = scaled_error(&e.z, &want, span);
                    assert!(err <= 1e-11, "m {m} θ {theta} block: {err:e}");
                }
            }
        }
    }

    /// The expanding-memory kernels (per sample for every degree; the least-squares blocks up
    /// to degree 4) against the reference with the gains `h_k(n)` of Table 9.1 (unit steps, so
    /// no step scaling), within the bound of the batch tests (1e-12).
    #[test]
    fn expanding_fast_paths_match_the_reference() {
        for m in 0..=PLAIN_KERNEL_MAX_DEGREE {
            let n = 20 * STEADY_BLOCK + 37;
            let ts: Vec<f64> = (0..n).map(|k| k as f64).collect();
            let ys = data(n, m);
            let mut start = GainEngine::new(m, 1.0, None);
            for i in 0..=m {
                start.update(ts[i], ys[i]);
            }
            let (ts, ys) = (&ts[m + 1..], &ys[m + 1..]);
            let schedule = ExpandingGainSchedule::new(m);
            let gains = |i: usize| {
                let mut h = vec![0.0; m + 1];
                schedule.gains((m + 1 + i) as u64, &mut h);
                h
            };
            let want = reference(&start, ts, ys, gains);
            let span = n as f64;
            let mut e = start.clone();
            let done =
                unrolled_sizes!(m + 1, N => e.plain_run_n::<N, false>(ts, ys, &mut []), _ => 0);
            assert_eq!(done, ts.len());
            let err = scaled_error(&e.z, &want, span);
            assert!(err <= 1e-12, "m {m} per sample: {err:e}");
            if m <= EXPANDING_BLOCK_MAX_DEGREE {
                let mut e = start.clone();
                let done = e.expanding_block_run(ts, ys);
                assert!(done >= ts.len() - STEADY_BLOCK, "m {m}: {done}");
                let want = reference(&start, &ts[..done], &ys[..done], gains);
                let err = scaled_error(&e.z, &want, span);
                assert!(err <= 1e-12, "m {m} block: {err:e}");
            }
        }
    }

    /// The start from Lagrange's form in double words against the interpolating polynomial in
    /// exact rationals (Newton's divided differences, expanded about the newest time), state and
    /// covariance, degrees 0 … 12, on irregular times far from the origin and a τ that is not a
    /// power of two.
    #[test]
    fn start_equals_the_exact_interpolating_polynomial() {
        use crate::calculus::Polynomial;
        use crate::scalar::Rational;
        let exact = |x: f64| rational_from_f64(x).unwrap();
        for m in 0..=12 {
            let tau = 0.37;
            let ts: Vec<f64> = (0..=m)
                .map(|i| 1.7e9 + 0.01 * i as f64 + 0.003 * ((i * i) % 7) as f64)
                .collect();
            let ys: Vec<f64> = (0..=m).map(|i| 1e4 + (i as f64 * 1.3).sin()).collect();
            let mut e = GainEngine::new(m, tau, None);
            e.track_covariance(1.0);
            for (&t, &y) in ts.iter().zip(&ys) {
                e.update(t, y);
            }
            let u: Vec<Rational> = ts
                .iter()
                .map(|&t| (exact(t) - exact(ts[m])) / exact(tau))
                .collect();
            let interpolate = |v: &[Rational]| -> Vec<Rational> {
                let mut c = v.to_vec();
                for j in 1..=m {
                    for i in (j..=m).rev() {
                        c[i] =
                            (c[i].clone() - c[i - 1].clone()) / (u[i].clone() - u[i - j].clone());
                    }
                }
                let mut p = Polynomial::constant(c[m].clone());
                for j in (0..m).rev() {
                    p = p.mul(&Polynomial::new(vec![-u[j].clone(), Rational::from_i64(1)]));
                    p = p.add(&Polynomial::constant(c[j].clone()));
                }
                let mut coeffs = p.coeffs;
                coeffs.resize(m + 1, Rational::from_i64(0));
                coeffs
            };
            let want = interpolate(&ys.iter().map(|&y| exact(y)).collect::<Vec<_>>());
            // Column i of L: the interpolating polynomial of the i-th unit vector.
            let l: Vec<Vec<f64>> = (0..=m)
                .map(|i| {
                    let unit: Vec<Rational> = (0..=m)
                        .map(|j| Rational::from_i64(i64::from(i == j)))
                        .collect();
                    interpolate(&unit).iter().map(|c| c.to_f64()).collect()
                })
                .collect();
            let scale: f64 = ys.iter().map(|y| y.abs()).sum();
            let (_, p) = e.cov.as_ref().unwrap();
            for k in 0..=m {
                // The weights' relative error is a few 2⁻¹⁰⁶, so the sum's is that times Σ|L y|.
                let largest = l.iter().map(|col| col[k].abs()).fold(0.0, f64::max);
                let got = exact(e.z[k]) + exact(e.z_lo[k]);
                let err = (got - want[k].clone()).to_f64().abs();
                assert!(err <= 1e-28 * largest * scale, "m={m} k={k}: {err:e}");
                // The covariance P = L Lᵀ, its diagonal.
                let var: f64 = l.iter().map(|col| col[k] * col[k]).sum();
                let rel = (p[(k, k)] - var).abs() / var;
                assert!(rel <= 1e-13, "m={m} P_{k}{k}: {rel:e}");
            }
        }
    }
}
