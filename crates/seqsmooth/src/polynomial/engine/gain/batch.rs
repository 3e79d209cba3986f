//! The gain engine's batch path ([`GainEngine::update_many`]): which kernel takes each run of
//! samples from the per-sample compensated recursion — the plain-`f64` kernel
//! ([`super::plain`]: expanding memory after the start at low degree, fading memory after the
//! switch), the expanding memory's runs of even steps as one least-squares update
//! ([`super::expanding_run`]), the steady fading memory's whole blocks
//! ([`super::steady_block`]) — and the constants that decide it.

use super::*;

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
                i += self.steady_run(&ts[i..], &ys[i..], rows, write, &[]);
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
}
