//! The window fit on evenly spaced samples, from the window's discrete Legendre moments
//! `μ_j = Σ_{x=0..L} y(x) p_j(x)`: `β_j = μ_j/c_j²` (the factor `C B` of `W(h) = T(L+h) C B`,
//! Morrison (7.4.10)) and the derivatives at any `r` on the window axis through `T(r)`
//! (7.4.15), (7.5.21).

use super::ring::Ring;
use super::sliding::SlidingMoments;
use super::weights::{inverse_norms, legendre_values, taylor_at};
use crate::basis::DiscreteLegendre;
use crate::model::taylor::{
    derivative_scale, scaling_diagonal, unscale_in_range, unscale_stepwise,
};
use crate::numeric::unrolled::unrolled_sizes;
use nalgebra::DMatrix;
use std::borrow::Cow;

/// Window fits from their moments: `β_j = μ_j/c_j²`, and at `r` on the window axis the
/// derivatives `x^(i) = (i!/τ^i) Σ_j [T(r) C]_ij μ_j` and their covariance
/// `σ² D(τ) T(r) C T(r)ᵀ D(τ)` (7.5.26)-(7.5.28) for samples `τ` apart; `T(r)` (upper
/// triangular) and `T(r) C` are kept for one `r`, computed for the others.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub(super) struct MomentFit {
    m: usize,
    basis: DiscreteLegendre<f64>,
    inv_norm: Vec<f64>,
    kept_r: f64,
    kept: DMatrix<f64>,
    /// `T(kept_r) C`, row-major.
    kept_tc: Vec<f64>,
}

impl MomentFit {
    /// Degree `m` over windows of span `L`, keeping `T(kept_r)`.
    pub(super) fn new(m: usize, span: usize, kept_r: usize) -> Self {
        let basis = DiscreteLegendre::new(span as f64);
        let inv_norm = inverse_norms(m, &basis);
        let kept = taylor_at(m, &basis, &(kept_r as f64));
        Self {
            m,
            kept_tc: Self::times_c(&kept, &inv_norm),
            inv_norm,
            kept_r: kept_r as f64,
            kept,
            basis,
        }
    }

    /// `T C`, row-major.
    fn times_c(t: &DMatrix<f64>, inv_norm: &[f64]) -> Vec<f64> {
        let p = inv_norm.len();
        (0..p * p)
            .map(|k| t[(k / p, k % p)] * inv_norm[k % p])
            .collect()
    }

    fn taylor(&self, r: f64) -> Cow<'_, DMatrix<f64>> {
        if r == self.kept_r {
            Cow::Borrowed(&self.kept)
        } else {
            Cow::Owned(taylor_at(self.m, &self.basis, &r))
        }
    }

    /// Unscaled derivatives at `r` of the fit with moments `mu`.
    pub(super) fn derivatives(&self, mu: &[f64], r: f64, step: f64) -> Vec<f64> {
        let mut out = vec![0.0; mu.len()];
        self.derivatives_into(mu, r, step, &mut out);
        out
    }

    /// [`Self::derivatives`] into `out` (`m+1` values), allocating nothing at the kept `r`.
    pub(super) fn derivatives_into(&self, mu: &[f64], r: f64, step: f64, out: &mut [f64]) {
        let computed;
        let tc = if r == self.kept_r {
            &self.kept_tc
        } else {
            computed = Self::times_c(&self.taylor(r), &self.inv_norm);
            &computed
        };
        apply_upper(tc, mu, out);
        unscale(out, step);
    }

    /// The 1σ of the unscaled derivatives at `r` for noise σ `sigma`: the square roots of the
    /// diagonal of `σ² D(τ) T(r) C T(r)ᵀ D(τ)` (7.5.26)-(7.5.28), into `out` (`T` upper
    /// triangular: `O(m²)`, allocating nothing at the kept `r`).
    pub(super) fn std_devs_into(&self, r: f64, step: f64, sigma: f64, out: &mut [f64]) {
        let t = self.taylor(r);
        for (i, o) in out.iter_mut().enumerate() {
            let v: f64 = (i..=self.m)
                .map(|j| t[(i, j)] * t[(i, j)] * self.inv_norm[j])
                .sum();
            *o = sigma * v.sqrt();
        }
        unscale(out, step);
    }

    /// Unscaled derivatives at `r` of the fit with moments `mu` and, given the noise σ, their
    /// covariance.
    pub(super) fn estimate(
        &self,
        mu: &[f64],
        r: f64,
        step: f64,
        sigma: Option<f64>,
    ) -> (Vec<f64>, Option<DMatrix<f64>>) {
        let x = self.derivatives(mu, r, step);
        let cov = sigma.map(|s| {
            let t = self.taylor(r);
            let scale = scaling_diagonal::<f64>(self.m, step);
            DMatrix::from_fn(self.m + 1, self.m + 1, |i, k| {
                let v: f64 = (0..=self.m)
                    .map(|j| t[(i, j)] * t[(k, j)] * self.inv_norm[j])
                    .sum();
                v * scale[i] * scale[k] * s * s
            })
        });
        (x, cov)
    }
}

/// Scaled `z_k = τ^k x^(k)/k!` to derivatives in place: `x^(k) = z_k k!/τ^k`.
fn unscale(out: &mut [f64], step: f64) {
    if unscale_in_range(out.len() - 1, step) {
        for (o, s) in out.iter_mut().zip(derivative_scale(step)) {
            *o *= s;
        }
    } else {
        // `k!/step^k` overflows or underflows: one factor at a time, so that a zero
        // coefficient stays 0 and only a derivative truly beyond the range is infinite.
        for (k, o) in out.iter_mut().enumerate() {
            *o = unscale_stepwise(*o, k, step);
        }
    }
}

/// `out_i = Σ_{j≥i} a_ij μ_j` for the upper-triangular, row-major `a` (`p × p`, `p` the
/// length of `mu`).
#[inline]
pub(super) fn apply_upper(a: &[f64], mu: &[f64], out: &mut [f64]) {
    unrolled_sizes!(mu.len(), N => apply_upper_sized(N, a, mu, out), p => apply_upper_sized(p, a, mu, out));
}

/// [`apply_upper`] for `p` (a constant where the dispatch makes it one).
#[inline(always)]
fn apply_upper_sized(p: usize, a: &[f64], mu: &[f64], out: &mut [f64]) {
    let (mu, out) = (&mu[..p], &mut out[..p]);
    for (i, o) in out.iter_mut().enumerate() {
        let row = &a[i * p + i..(i + 1) * p];
        *o = row.iter().zip(&mu[i..]).map(|(a, b)| a * b).sum::<f64>();
    }
}

/// How the moments are kept: recomputed from the stored window (`O(L·m)` per sample, with the
/// table of `p_j(x)`, row `x`) or slid.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
enum Moments {
    Direct { table: Vec<f64>, mu: Vec<f64> },
    Sliding(SlidingMoments),
}

/// The newest `L+1` evenly spaced samples and their moments.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub(super) struct EvenWindow {
    m: usize,
    ring: Ring<f64>,
    moments: Moments,
    /// Keeps `T(L)`, the current estimate's.
    fit: MomentFit,
}

impl EvenWindow {
    /// Degree `m` over `window` samples: the direct engine (`refreshes = None`) or the sliding
    /// one with that many refresh accumulators.
    pub(super) fn new(m: usize, window: usize, refreshes: Option<usize>) -> Self {
        let span = window - 1;
        let moments = match refreshes {
            None => {
                let basis = DiscreteLegendre::new(span as f64);
                let mut table = Vec::with_capacity(window * (m + 1));
                for x in 0..window {
                    table.extend(legendre_values(m, &basis, &(x as f64)));
                }
                Moments::Direct {
                    table,
                    mu: Vec::new(),
                }
            }
            Some(q) => Moments::Sliding(SlidingMoments::new(m, window, q, false)),
        };
        Self {
            m,
            ring: Ring::new(window),
            moments,
            fit: MomentFit::new(m, span, span),
        }
    }

    /// Sets the sliding engine's number of refresh accumulators (before the first sample; the
    /// direct engine has none).
    pub(super) fn set_refreshes(&mut self, refreshes: usize) {
        if let Moments::Sliding(s) = &mut self.moments {
            s.set_refreshes(refreshes);
        }
    }

    /// The sliding engine's refresh period (`None` for the direct engine).
    pub(super) fn refresh_period(&self) -> Option<usize> {
        match &self.moments {
            Moments::Sliding(s) => Some(s.refresh_period()),
            Moments::Direct { .. } => None,
        }
    }

    /// The window's values, oldest first.
    pub(super) fn values(&self) -> impl Iterator<Item = &f64> {
        self.ring.iter()
    }

    /// Processes the sample with 0-based index `n`.
    pub(super) fn update(&mut self, n: u64, y: f64) {
        let old = self.ring.push(y);
        match &mut self.moments {
            Moments::Sliding(s) => s.push(n, y, old),
            Moments::Direct { table, mu } => {
                if self.ring.is_full() {
                    let p = self.m + 1;
                    mu.clear();
                    mu.resize(p, 0.0);
                    for (x, &yv) in self.ring.iter().enumerate() {
                        for (m, r) in mu.iter_mut().zip(&table[x * p..(x + 1) * p]) {
                            *m += yv * r;
                        }
                    }
                }
            }
        }
    }

    fn moments(&self) -> Option<&[f64]> {
        match &self.moments {
            Moments::Sliding(s) => s.moments(),
            Moments::Direct { mu, .. } => (!mu.is_empty()).then_some(&mu[..]),
        }
    }

    /// Unscaled derivatives at `r` on the window axis and, given the noise σ, their covariance
    /// ([`MomentFit::estimate`]); `None` until the window is full.
    pub(super) fn estimate(
        &self,
        r: f64,
        step: f64,
        sigma: Option<f64>,
    ) -> Option<(Vec<f64>, Option<DMatrix<f64>>)> {
        Some(self.fit.estimate(self.moments()?, r, step, sigma))
    }
}

impl EvenWindow {
    /// A restored window's invariants ([`crate::persist`]): its degree and ring.
    pub(super) fn check_saved(&self, m: usize, window: usize) -> bool {
        self.m == m && self.ring.check_saved(window)
    }
}
