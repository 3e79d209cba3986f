//! Exact recursive least squares with the polynomial model on arbitrary timestamps: the
//! polynomial instance of the square-root information filter of [`crate::recursive`].
//!
//! The state is the coefficient vector `a` of `f(t) = Σ_k a_k u^k` with the centred, scaled
//! time `u = (t - c)/s`. Keeping `c` near the middle of the (effective) memory and `s` near its
//! half-width keeps the rows `(1, u, …, u^m)` in `[-1, 1]`-like ranges; when the memory moves
//! the basis is re-centred by the upper-triangular change of variables
//! `a_old = A a_new`, `A_kj = C(j,k) (-β)^(j-k) / α^j` (`u_old = α u_new + β`), so `R ← R A`
//! stays triangular and no re-factorisation is needed. Re-centring happens `O(log n)` times for
//! expanding memory and about once per quarter memory span for fading memory; the new unit is
//! the old one times a power of two and the centre moves by a multiple of unit/8, so `α`, `β`
//! and `A` are exact, and on evenly spaced samples the same `A` repeats (cached).
//!
//! The fading-memory discount is applied lazily: instead of multiplying `[R | d]` by `√θ^ζ` at
//! every sample, new rows get the weight `1/Π θ^ζ`, folded back into the factor when its square
//! root passes 1e30. The estimate `R⁻¹d` and the sandwich covariance do not depend on that
//! common scale. The factor itself is kept in Gentleman's square-root-free form
//! ([`TriangularFactor`]): no square roots per sample.

use super::DiscountMode;
use crate::calculus::choose;
use crate::model::shift_scaled;
use crate::recursive::{InformationFilter, TriangularFactor};
use nalgebra::DMatrix;

/// When the lazy discount's row scale `1/√(Π θ^ζ)` exceeds this, it is folded into the factors
/// (the rows' weights are its square, the noise factor's its fourth power: ≤ 1e120, far from
/// overflow in the squares the square-root-free rotations form).
const RENORMALISE: f64 = 1e30;

#[derive(Clone, Copy, Debug)]
pub(crate) struct Discount {
    pub theta: f64,
    pub tau: f64,
    pub mode: DiscountMode,
}

#[derive(Clone, Debug)]
pub(crate) struct ExactEngine {
    m: usize,
    discount: Option<Discount>,
    info: InformationFilter,
    /// Square root of `Σ w_k² h_k h_kᵀ`: the fading-memory estimate's covariance is the sandwich
    /// `(RᵀR)⁻¹ (QᵀQ) (RᵀR)⁻¹ σ²` (weights are discounts, not inverse variances).
    noise: Option<TriangularFactor>,
    centre: f64,
    unit: f64,
    t_first: f64,
    t_last: f64,
    n: u64,
    row: Vec<f64>,
    sigma: Option<f64>,
    /// Cache: the last step `Δt` and its discount's square root `√(θ^(Δt/τ))` (per time), so
    /// the power is evaluated only when the step changes.
    step_cached: f64,
    root_cached: f64,
    /// `-ln θ`, for the effective memory span, and that span `3τ/(-ln θ)` (per time).
    neg_ln_theta: f64,
    span_per_time: f64,
    /// The discount applied lazily: the true factors are the stored ones divided by
    /// `inv_scale` (the noise factor by `inv_scale²`), and each new row gets the weight
    /// `inv_scale²` (`inv_scale⁴`). Solutions and the sandwich covariance do not depend on the
    /// common scale.
    inv_scale: f64,
    /// `k!/s^k` for the unit `s` (unscaled derivatives from the coefficients).
    unscale: Vec<f64>,
    /// The last re-centring `(α, β, A)`.
    recentre_cache: Option<(f64, f64, DMatrix<f64>)>,
}

impl ExactEngine {
    pub fn new(m: usize, discount: Option<Discount>) -> Self {
        Self {
            m,
            discount,
            info: InformationFilter::new(m + 1),
            noise: None,
            centre: 0.0,
            unit: 1.0,
            t_first: f64::NAN,
            t_last: f64::NAN,
            n: 0,
            row: vec![0.0; m + 1],
            sigma: None,
            step_cached: f64::NAN,
            root_cached: 1.0,
            neg_ln_theta: discount.map_or(0.0, |d| -d.theta.ln()),
            span_per_time: discount.map_or(0.0, |d| 3.0 * d.tau / -d.theta.ln()),
            recentre_cache: None,
            unscale: vec![0.0; m + 1],
            inv_scale: 1.0,
        }
    }

    pub fn track_covariance(&mut self, sigma: f64) {
        self.sigma = Some(sigma);
        if self.discount.is_some() {
            self.noise = Some(TriangularFactor::new(self.m + 1));
        }
    }

    pub fn samples(&self) -> u64 {
        self.n
    }

    pub fn last_time(&self) -> f64 {
        self.t_last
    }

    /// Processes one sample; `t` must exceed the previous time (checked by the caller).
    pub fn update(&mut self, t: f64, y: f64) {
        if self.n == 0 {
            self.t_first = t;
            self.centre = t;
            self.unit = 1.0;
            self.set_unscale();
        } else {
            if let Some(d) = self.discount {
                let dt = t - self.t_last;
                if dt != self.step_cached {
                    self.step_cached = dt;
                    self.root_cached = match d.mode {
                        DiscountMode::PerTime => d.theta.powf(dt / d.tau).sqrt(),
                        DiscountMode::PerUpdate => d.theta.sqrt(),
                    };
                }
                // Lazily: the factors stay as they are and new rows get the weight
                // 1/Π θ^ζ instead.
                self.inv_scale /= self.root_cached;
                if self.inv_scale > RENORMALISE {
                    let f = 1.0 / (self.inv_scale * self.inv_scale);
                    self.info.discount(f);
                    if let Some(q) = &mut self.noise {
                        q.discount(f * f);
                    }
                    self.inv_scale = 1.0;
                }
            }
            self.maybe_recentre(t);
        }
        let u = (t - self.centre) / self.unit;
        let mut p = 1.0;
        for r in self.row.iter_mut() {
            *r = p;
            p *= u;
        }
        let w = self.inv_scale * self.inv_scale;
        self.info.observe(&self.row, y, w);
        if let Some(q) = &mut self.noise {
            q.add_row(&self.row, 0.0, w * w);
        }
        self.t_last = t;
        self.n += 1;
    }

    fn maybe_recentre(&mut self, t: f64) {
        let start = match self.discount {
            None => self.t_first,
            Some(d) => {
                // Effective memory: weights fall by e^-3 over this span.
                let span = match d.mode {
                    DiscountMode::PerTime => self.span_per_time,
                    DiscountMode::PerUpdate => {
                        3.0 * (t - self.t_first) / (self.n as f64 * self.neg_ln_theta)
                    }
                };
                (t - span).max(self.t_first)
            }
        };
        let target_c = 0.5 * (start + t);
        let target_s = 0.5 * (t - start);
        if target_s.is_nan() || target_s <= 0.0 {
            return;
        }
        let off_centre = (self.centre - target_c).abs() > 0.5 * target_s;
        let off_scale = self.unit > 4.0 * target_s || self.unit < 0.25 * target_s;
        if off_centre || off_scale {
            // The new unit is the old one times a power of two and the centre moves by a
            // multiple of unit/8, so `α` and `β` below are exact and on evenly spaced samples
            // the same change of variables repeats (its matrix is cached).
            let alpha = if off_scale {
                (target_s / self.unit).log2().round().exp2()
            } else {
                1.0
            };
            let beta = ((target_c - self.centre) / self.unit * 8.0).round() / 8.0;
            self.recentre(alpha, beta);
        }
    }

    /// `k!/s^k` for the current unit `s`.
    fn set_unscale(&mut self) {
        let (mut f, mut sk) = (1.0, 1.0);
        for (k, c) in self.unscale.iter_mut().enumerate() {
            if k > 0 {
                f *= k as f64;
                sk *= self.unit;
            }
            *c = f / sk;
        }
    }

    /// Re-centres: `u_old = α u_new + β`, i.e. new centre `c + β·s`, new unit `α·s`.
    fn recentre(&mut self, alpha: f64, beta: f64) {
        if self.recentre_cache.as_ref().map(|c| (c.0, c.1)) != Some((alpha, beta)) {
            let p = self.m + 1;
            let a = DMatrix::from_fn(p, p, |k, j| {
                if j < k {
                    0.0
                } else {
                    choose::<f64>(j, k) * (-beta).powi((j - k) as i32) / alpha.powi(j as i32)
                }
            });
            self.recentre_cache = Some((alpha, beta, a));
        }
        let a = &self.recentre_cache.as_ref().expect("just set").2;
        self.info.change_variables_upper(a);
        if let Some(q) = &mut self.noise {
            q.change_variables_upper(a);
        }
        self.centre += beta * self.unit;
        self.unit *= alpha;
        self.set_unscale();
    }

    pub fn is_determined(&self) -> bool {
        self.n > self.m as u64 && self.info.is_determined()
    }

    /// Writes the unscaled derivatives of the fit at `t` into `out` (`m+1` values) without
    /// allocating: `a = R⁻¹d`, shifted to `u(t)`, `x_k = k! a_k / s^k`. False (and `out`
    /// untouched) while the fit is not determined.
    pub fn derivatives_into(&self, t: f64, out: &mut [f64]) -> bool {
        if !self.is_determined() {
            return false;
        }
        let p = self.m + 1;
        let mut buf = [0.0; super::MAX_DEGREE + 1];
        let a = &mut buf[..p];
        if !self.info.factor().solve_into(a) {
            return false;
        }
        shift_scaled(a, (t - self.centre) / self.unit);
        // `k!/s^k`: the unit `s` is a power of two (re-centring scales it by powers of two
        // from 1), so this equals `z·k!/s^k` computed with the division, bit for bit.
        for ((x, z), c) in out.iter_mut().zip(a.iter()).zip(&self.unscale) {
            *x = z * c;
        }
        true
    }

    /// Unscaled derivatives (and covariance, when tracked) of the fit evaluated at `t`.
    pub fn estimate_at(&self, t: f64) -> Option<(Vec<f64>, Option<DMatrix<f64>>)> {
        if !self.is_determined() {
            return None;
        }
        let mut x = vec![0.0; self.m + 1];
        if !self.derivatives_into(t, &mut x) {
            return None;
        }
        let v = (t - self.centre) / self.unit;
        let cov = match self.sigma {
            None => None,
            Some(sigma) => {
                let j = crate::model::scaling(self.m, self.unit) * crate::model::phi(self.m, v);
                let jr = self.info.right_divide(&j)?;
                let c = match &self.noise {
                    None => &jr * jr.transpose(),
                    Some(q) => {
                        // K = J (RᵀR)⁻¹, Kᵀ = R⁻¹ (J R⁻¹)ᵀ; covariance K QᵀQ Kᵀ.
                        let mut kt = jr.transpose();
                        let r = self.info.factor().r();
                        for mut col in kt.column_iter_mut() {
                            let mut c: Vec<f64> = col.iter().copied().collect();
                            if !crate::linalg::solve_upper_in_place(&r, &mut c) {
                                return None;
                            }
                            col.copy_from_slice(&c);
                        }
                        let qk = q.r() * kt;
                        qk.transpose() * qk
                    }
                };
                Some(c * (sigma * sigma))
            }
        };
        Some((x, cov))
    }
}
