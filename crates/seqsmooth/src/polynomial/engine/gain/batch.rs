//! The gain engine's batch path ([`GainEngine::update_many`]): the plain-`f64` kernels that
//! take over from the per-sample compensated recursion where they apply (expanding memory
//! after the start at low degree, fading memory after the switch), the state in registers,
//! and the expanding memory's runs of even steps as one least-squares update
//! ([`super::super::expanding_block`]); the steady fading memory's whole blocks are
//! [`super::steady_block`]'s.

use super::*;

/// A kernel's output row (if any): the unscaled derivatives `x_k = z_k·k!/τ^k`; returns
/// `0·Σ x_k`, which is 0 when they are all finite and NaN when one is not (a probe the kernels
/// add up, three operations a row where marking each number would take nine).
#[inline(always)]
pub(super) fn write_row(row: Option<&mut [f64]>, z: &[f64], c: &[f64]) -> f64 {
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
pub(super) fn scale_gains_for_step(g: &mut [f64], step: f64) {
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
pub(super) struct PlainRun<const N: usize> {
    z: [f64; N],
    t_last: f64,
    done: usize,
}

/// Binomial coefficients `C(j, k)` for `j, k < N`.
pub(super) fn binomials<const N: usize>() -> [[f64; N]; N] {
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
pub(super) const STEADY_BLOCK: usize = 64;

/// A block map is built (for new gains or a new step) only once the batches at that step
/// (those so far and the current one) reach this many samples times `(m+1)²`, so that its cost
/// is spread over them.
pub(super) const STEADY_BLOCK_MIN_BUILD_RUN: usize = 512;

/// The largest relative deviation of a block's mean step from the typical step `ζ̄` that
/// the block map takes to first order (the dropped second-order term is then below 1e-18
/// relative, times binomial factors). The timestamps' rounding gives deviations near
/// `ε·|t|/(BΔt)`, far below.
pub(super) const LINEAR_STEP_DEVIATION: f64 = 1e-9;

/// The largest degree whose expanding-memory `update_many` runs on even runs as a
/// least-squares update ([`super::super::expanding_block`]).
pub(super) const EXPANDING_BLOCK_MAX_DEGREE: usize = 4;

/// The largest degree whose steady fading recursion `update_many` runs as block maps. Above
/// it the block map's rounding (weights of mixed sign, `Ā` far from normal) approaches the
/// tests' bound against the compensated per-sample path (tests/batch.rs; measured: see
/// ACCURACY.md).
pub(super) const STEADY_BLOCK_MAX_DEGREE: usize = 5;

impl GainEngine {
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

    pub(super) fn update_many_with(
        &mut self,
        ts: &[f64],
        ys: &[f64],
        out: &mut [f64],
        write: bool,
    ) {
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
    pub(super) fn derivatives_into(&self, row: &mut [f64]) {
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

    pub(super) fn plain_kernel_applies(&self) -> bool {
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
    pub(super) fn steady_run(
        &mut self,
        ts: &[f64],
        ys: &[f64],
        out: &mut [f64],
        write: bool,
    ) -> usize {
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
    pub(super) fn derivative_factors<const N: usize>(&self) -> [f64; N] {
        let mut c = [1.0; N];
        for (ck, d) in c.iter_mut().zip(derivative_scale(self.unit)) {
            *ck = d;
        }
        c
    }

    /// The state as plain `f64` (the double word folded), for the kernels below.
    pub(super) fn plain_state<const N: usize>(&self) -> [f64; N] {
        std::array::from_fn(|k| self.z[k] + self.z_lo[k])
    }

    /// Stores a kernel's state after `done` samples, the newest at `t_last`.
    pub(super) fn end_plain_run(&mut self, z: &[f64], t_last: f64, done: usize) {
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
    pub(super) fn plain_run_n<const N: usize, const W: bool>(
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

    /// Expanding memory on a run of whole blocks of [`STEADY_BLOCK`] even steps: on an even
    /// grid the filter's state is the least-squares polynomial through every sample so far
    /// (Morrison §9.4), so the run is folded in as one least-squares update
    /// ([`super::super::expanding_block::advance_even_fit`]) instead of a recursion per sample. The
    /// grid is the run's own: from the first sample to the run's last at their mean step (the
    /// old state moved onto it first, by the rounding of the timestamps); within it, the samples'
    /// own times differ from the grid by their rounding, which the per-sample recursion follows
    /// and this does not (measured in tests/batch.rs). Returns how many samples it took.
    pub(super) fn expanding_block_run(&mut self, ts: &[f64], ys: &[f64]) -> usize {
        if self.n <= self.m as u64 || ts.is_empty() {
            return 0;
        }
        if self.m == 0 {
            // Degree 0 is the running mean, whatever the steps.
            let mut z = [self.z[0] + self.z_lo[0]];
            super::super::expanding_block::advance_even_fit(0, self.n, &mut z, ys);
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
        super::super::expanding_block::advance_even_fit(m, n, z, &ys[..take]);
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
    pub(super) fn plain_run<const N: usize, const W: bool>(
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
}
