//! Exact recursive least squares with the polynomial model on arbitrary timestamps: the
//! polynomial instance of the square-root information filter of [`crate::recursive`].
//!
//! The state is the coefficient vector `a` of `f(t) = Σ_k a_k u^k` with the centred, scaled
//! time `u = (t - c)/s`. Keeping `c` near the middle of the (effective) memory and `s` near its
//! half-width keeps the rows `(1, u, …, u^m)` in `[-1, 1]`-like ranges; when the memory moves
//! the basis is re-centred by the upper-triangular change of variables
//! `a_old = A a_new`, `A_kj = C(j,k) (-β)^(j-k) / α^j` (`u_old = α u_new + β`), so `R ← R A`
//! stays triangular and no re-factorisation is needed. Re-centring happens `O(log n)` times for
//! expanding memory and about once per quarter memory span for fading memory.

use super::DiscountMode;
use crate::calculus::choose;
use crate::model::shift_scaled;
use crate::recursive::{InformationFilter, TriangularFactor};
use nalgebra::DMatrix;

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
        } else {
            if let Some(d) = self.discount {
                let f = match d.mode {
                    DiscountMode::PerTime => d.theta.powf((t - self.t_last) / d.tau),
                    DiscountMode::PerUpdate => d.theta,
                };
                self.info.discount(f);
                if let Some(q) = &mut self.noise {
                    q.discount(f * f);
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
        self.info.observe(&self.row, y, 1.0);
        if let Some(q) = &mut self.noise {
            q.add_row(&self.row, 0.0, 1.0);
        }
        self.t_last = t;
        self.n += 1;
    }

    fn maybe_recentre(&mut self, t: f64) {
        let start = match self.discount {
            None => self.t_first,
            Some(d) => {
                // Effective memory: weights fall by e^-3 over this span.
                let per_unit_time = match d.mode {
                    DiscountMode::PerTime => -d.theta.ln() / d.tau,
                    DiscountMode::PerUpdate => {
                        let mean_step = (t - self.t_first) / self.n as f64;
                        -d.theta.ln() / mean_step
                    }
                };
                (t - 3.0 / per_unit_time).max(self.t_first)
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
            self.recentre(target_c, target_s);
        }
    }

    fn recentre(&mut self, c_new: f64, s_new: f64) {
        let alpha = s_new / self.unit;
        let beta = (c_new - self.centre) / self.unit;
        let p = self.m + 1;
        let a = DMatrix::from_fn(p, p, |k, j| {
            if j < k {
                0.0
            } else {
                choose::<f64>(j, k) * (-beta).powi((j - k) as i32) / alpha.powi(j as i32)
            }
        });
        self.info.change_variables(&a);
        if let Some(q) = &mut self.noise {
            q.change_variables(&a);
        }
        self.centre = c_new;
        self.unit = s_new;
    }

    pub fn is_determined(&self) -> bool {
        self.n > self.m as u64 && self.info.is_determined()
    }

    /// Unscaled derivatives (and covariance, when tracked) of the fit evaluated at `t`.
    pub fn estimate_at(&self, t: f64) -> Option<(Vec<f64>, Option<DMatrix<f64>>)> {
        if !self.is_determined() {
            return None;
        }
        let a = self.info.solve()?;
        let v = (t - self.centre) / self.unit;
        let mut z: Vec<f64> = a.iter().copied().collect();
        shift_scaled(&mut z, v);
        let x = crate::model::scaled_to_derivatives(&z, self.unit);
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
                        for mut col in kt.column_iter_mut() {
                            let mut c: Vec<f64> = col.iter().copied().collect();
                            if !crate::linalg::solve_upper_in_place(self.info.factor().r(), &mut c)
                            {
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
