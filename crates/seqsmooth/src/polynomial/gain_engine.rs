//! The fixed-gain recursion of Morrison's Tables 9.1 and 13.1 in the variable-step form of
//! Reyneke et al. §6, with the step scaling that makes it exact on evenly spaced samples for any
//! step (../shared/spec/others.md §4.8).

use super::gains::{fading_gains, ExpandingGainSchedule, GainForm};
use super::DiscountMode;
use crate::model::shift_scaled;
use nalgebra::DMatrix;

#[derive(Clone, Debug)]
pub(crate) struct FadingGains {
    pub theta: f64,
    pub mode: DiscountMode,
    /// First 0-based sample index that uses the fading-memory gains.
    pub switch_at: u64,
    /// Gains at θ (used whenever the effective discount is θ itself).
    pub steady: Vec<f64>,
}

/// State: Morrison's scaled `Z` (unit `τ`) valid at `t_last`.
#[derive(Clone, Debug)]
pub(crate) struct GainEngine {
    m: usize,
    tau: f64,
    fading: Option<FadingGains>,
    schedule: ExpandingGainSchedule,
    z: Vec<f64>,
    t_last: f64,
    n: u64,
    k: Vec<f64>,
    /// Noise variance and the scaled covariance of the estimate's random error.
    cov: Option<(f64, DMatrix<f64>)>,
}

impl GainEngine {
    pub fn new(m: usize, tau: f64, fading: Option<FadingGains>) -> Self {
        Self {
            m,
            tau,
            fading,
            schedule: ExpandingGainSchedule::new(m),
            z: vec![0.0; m + 1],
            t_last: f64::NAN,
            n: 0,
            k: vec![0.0; m + 1],
            cov: None,
        }
    }

    pub fn set_initial_scaled(&mut self, z: Vec<f64>) {
        self.z = z;
    }

    pub fn track_covariance(&mut self, sigma: f64) {
        self.cov = Some((sigma * sigma, DMatrix::zeros(self.m + 1, self.m + 1)));
    }

    pub fn samples(&self) -> u64 {
        self.n
    }

    pub fn tau(&self) -> f64 {
        self.tau
    }

    pub fn last_time(&self) -> f64 {
        self.t_last
    }

    pub fn switch_at(&self) -> Option<u64> {
        self.fading.as_ref().map(|f| f.switch_at)
    }

    /// Processes one sample; `t` must exceed the previous time (checked by the caller).
    pub fn update(&mut self, t: f64, y: f64) {
        let zeta = if self.n == 0 {
            1.0
        } else {
            (t - self.t_last) / self.tau
        };
        if self.n > 0 {
            shift_scaled(&mut self.z, zeta);
        }
        let e = y - self.z[0];
        match &self.fading {
            Some(f) if self.n >= f.switch_at => {
                let theta_eff = match f.mode {
                    DiscountMode::PerUpdate => f.theta,
                    DiscountMode::PerTime => f.theta.powf(zeta),
                };
                if theta_eff == f.theta {
                    self.k.copy_from_slice(&f.steady);
                } else {
                    self.k = fading_gains(self.m, theta_eff, GainForm::Current);
                }
            }
            _ => self.schedule.gains(self.n, &mut self.k),
        }
        if zeta != 1.0 {
            let mut zk = 1.0;
            for kk in self.k.iter_mut().skip(1) {
                zk *= zeta;
                *kk /= zk;
            }
        }
        for (zi, ki) in self.z.iter_mut().zip(&self.k) {
            *zi += ki * e;
        }
        if let Some((var, p)) = &mut self.cov {
            // P ← Φ(ζ) P Φ(ζ)ᵀ, then the Joseph form P ← (I - K e0ᵀ) P (I - K e0ᵀ)ᵀ + σ² K Kᵀ:
            // the exact covariance of this linear estimator's random error.
            if self.n > 0 {
                let transition = crate::model::phi(self.m, zeta);
                *p = &transition * &*p * transition.transpose();
            }
            let dim = self.m + 1;
            let a = DMatrix::from_fn(dim, dim, |i, j| {
                let id = if i == j { 1.0 } else { 0.0 };
                if j == 0 {
                    id - self.k[i]
                } else {
                    id
                }
            });
            let kv = nalgebra::DVector::from_column_slice(&self.k);
            *p = &a * &*p * a.transpose() + (&kv * kv.transpose()) * *var;
        }
        self.t_last = t;
        self.n += 1;
    }

    /// Unscaled derivatives (and their covariance) of the estimate valid at `t`.
    pub fn estimate_at(&self, t: f64) -> (Vec<f64>, Option<DMatrix<f64>>) {
        let v = (t - self.t_last) / self.tau;
        let mut z = self.z.clone();
        shift_scaled(&mut z, v);
        let x = crate::model::scaled_to_derivatives(&z, self.tau);
        let cov = self.cov.as_ref().map(|(_, p)| {
            let j = crate::model::scaling(self.m, self.tau) * crate::model::phi(self.m, v);
            &j * p * j.transpose()
        });
        (x, cov)
    }
}
