//! The gain engine's plain-`f64` kernel: the reference recursion without the compensation,
//! the state in registers, on a run after the exact start (expanding memory at low degree;
//! fading memory after the switch, on steps equal to the typical one: [`GainEngine::steady_run`]).

use super::batch::{EXPANDING_BLOCK_MAX_DEGREE, STEADY_BLOCK_MAX_DEGREE};
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

impl GainEngine {
    /// The steady-state fading recursion on a run of (nearly) even steps in plain `f64`, with
    /// the state in registers: `Z ← Φ(ζ) Z`, `ε = y − z₀`, `Z ← Z + K ε`, the gains `K` those
    /// of the typical step. Returns how many samples it took (it stops at the first step that
    /// differs from the typical one ([`crate::numeric::steps`]). With `write`, each sample's
    /// derivatives go to `out`, followed in each row by `sd` (the run's constant 1σ, empty for
    /// rows of derivatives alone): rows of `(m+1) + sd.len()` values.
    pub(super) fn steady_run(
        &mut self,
        ts: &[f64],
        ys: &[f64],
        out: &mut [f64],
        write: bool,
        sd: &[f64],
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
            unrolled_sizes!(self.m + 1, N => self.plain_run_n::<N, true>(ts, ys, out, sd), _ => 0)
        } else {
            unrolled_sizes!(self.m + 1, N => self.plain_run_n::<N, false>(ts, ys, out, sd), _ => 0)
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
    /// `out`, each row followed by `sd` if it is not empty ([`plain_run`](Self::plain_run)).
    /// Returns how many samples it took.
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
        sd: &[f64],
    ) -> usize {
        if self.fading.is_none() {
            let mut g = [0.0; N];
            let (tau, t_first, schedule) = (self.unit, self.t_first, &self.schedule);
            let mut n = self.n;
            let mut last_step = self.step_mean;
            let run = self.plain_run::<N, W>(ts, ys, out, sd, |z, t, zeta, y| {
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
            let run = self.plain_run::<N, W>(ts, ys, out, sd, |z, t, zeta, y| {
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

    /// The plain kernels' common loop: from the state folded to `f64`, for each sample the
    /// step `ζ = (t − t_last)/τ` and `step(z, t, ζ, y)`, which advances `z` over the sample or
    /// returns false to stop before it; with `W`, the derivatives after each sample go to
    /// `out`, and with a non-empty `sd` (`N` values, the 1σ of a steady covariance) the row
    /// goes on with them (rows of `2N`: the batch σ path written in place, no second pass).
    /// The caller stores the result ([`end_plain_run`](Self::end_plain_run)).
    #[inline(always)]
    pub(super) fn plain_run<const N: usize, const W: bool>(
        &self,
        ts: &[f64],
        ys: &[f64],
        out: &mut [f64],
        sd: &[f64],
        mut step: impl FnMut(&mut [f64; N], f64, f64, f64) -> bool,
    ) -> PlainRun<N> {
        let c = self.derivative_factors::<N>();
        let sigma = !sd.is_empty();
        let s: [f64; N] = std::array::from_fn(|k| sd.get(k).copied().unwrap_or(0.0));
        let stride = if sigma { 2 * N } else { N };
        let mut rows = out.chunks_exact_mut(stride);
        let mut z = self.plain_state::<N>();
        let (tau, mut t_last, mut done) = (self.unit, self.t_last, 0);
        let mut probe = 0.0;
        for (&t, &y) in ts.iter().zip(ys) {
            let zeta = (t - t_last) / tau;
            if !step(&mut z, t, zeta, y) {
                break;
            }
            if W {
                let row = rows.next();
                if sigma {
                    if let Some(row) = row {
                        row[N..].copy_from_slice(&s);
                        probe += write_row(Some(&mut row[..N]), &z, &c);
                    }
                } else {
                    probe += write_row(row, &z, &c);
                }
            }
            t_last = t;
            done += 1;
        }
        if W && probe != 0.0 {
            // A number beyond the double range (rare): marked NaN, "no estimate".
            for x in &mut out[..done * stride] {
                *x = out_of_range_as_nan(*x);
            }
        }
        PlainRun { z, t_last, done }
    }
}
