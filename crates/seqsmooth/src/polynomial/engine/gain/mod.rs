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
use crate::numeric::sigma::std_dev;
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

mod batch;
mod expanding_run;
mod plain;
mod steady_block;
impl GainEngine {
    /// The invariants of a restored engine ([`crate::persist`]): degree in range, the state,
    /// its low words, the gains and the covariance `m + 1` wide.
    pub(crate) fn check_saved(&self, m: usize) -> Result<(), String> {
        if self.m != m || m > MAX_DEGREE {
            return Err(format!(
                "engine's degree {} is not the filter's {m}",
                self.m
            ));
        }
        for (v, what) in [(&self.z, "state"), (&self.z_lo, "state's low words")] {
            if v.len() != m + 1 {
                return Err(format!(
                    "engine's {what} has {} numbers, {} expected",
                    v.len(),
                    m + 1
                ));
            }
        }
        for (v, what) in [(&self.k, "gains"), (&self.k_lo, "gains' low words")] {
            if !v.is_empty() && v.len() != m + 1 {
                return Err(format!(
                    "engine's {what} has {} numbers, {} expected",
                    v.len(),
                    m + 1
                ));
            }
        }
        if self.start.len() > m + 1 || self.schedule.degree() != m {
            return Err("engine's start or gain schedule is not of its degree".into());
        }
        if let Some((_, c)) = &self.cov {
            crate::linalg::invariant::matrix(c, m + 1, m + 1, "engine's covariance")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;

pub(crate) use batch::out_of_range_as_nan;
use batch::scale_gains_for_step;
use steady_block::SteadyBlock;

#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
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
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
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
            let sd = std_dev(p[(k, k)]);
            *s = if tk.is_normal() {
                sd * f / tk
            } else {
                unscale_stepwise(sd, k, self.unit)
            };
        }
    }

    /// [`update_many_into`](Self::update_many_into) with each row's 1σ: rows of `2(m+1)`
    /// (derivatives, then 1σ). The plain kernels run where they apply — with a tracked
    /// covariance, once it is steady ([`Self::update`]), its 1σ then the same for the run, and
    /// written with each row by the kernel — the per-sample recursion elsewhere.
    pub fn update_many_sigma_into(&mut self, ts: &[f64], ys: &[f64], rows: &mut [f64]) {
        let w = self.m + 1;
        let mut i = 0;
        while i < ts.len() {
            if self.plain_kernel_applies() {
                let mut sd = [0.0; MAX_DEGREE + 1];
                self.std_devs_into(&mut sd[..w]);
                let out = &mut rows[i * 2 * w..];
                i += self.steady_run(&ts[i..], &ys[i..], out, true, &sd[..w]);
                if i == ts.len() {
                    break;
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
