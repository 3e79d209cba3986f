//! The systematic error of the active estimate, estimated from the next degree on the same
//! memory, and the honest covariance that includes it (Morrison §7.13, §13.9; (7.13.5),
//! (13.9.10), (13.9.28)).
//!
//! A degree-`d` least-squares estimate (expanding or fading memory) of a trend of higher degree
//! carries the bias `b = Σ_{j>d} γ̃_j p_j(r)` (13.9.10), dominated by the `(d+1)`-th term
//! (7.13.5), (13.9.28). The degree-`(d+1)` estimate `x_{d+1}` on the same samples with the same
//! weights removes that term, so `Δ = x_d − x_{d+1}` has mean `≈ b` (to the `(d+2)`-th term).
//! The two estimates are nested weighted least squares: `x_{d+1} = x_d + ` the projection on the
//! one added (orthogonalised) basis function, which is uncorrelated with `x_d`, so
//! `Cov(Δ) = σ²(V_{d+1} − V_d)` with `V` the VRFs. Hence `E{Δ_i²} = b_i² + σ²(V_{d+1} − V_d)_ii`,
//! and `b̂_i² = max(0, Δ_i² − σ²(V_{d+1} − V_d)_ii)` estimates `b_i²` without bias where it is
//! positive. The reported covariance is the mean squared error matrix
//! `E{e eᵀ} = σ² V_d + b bᵀ` with `b_i = sign(Δ_i) b̂_i` (positive semi-definite): a start-up at
//! a low degree, a degree still settling and a manoeuvre the model does not follow are all in
//! it. The same holds for a prediction: the innovation variance is
//! `σ_ε² = σ²(1 + v) + b̂₀²` at the sample's time.
//!
//! While the misfit test is up, the position's `b̂₀²` is at least the innovations' mean
//! square excess over their noise variance in the misfit window (Morrison §14.8: the
//! normalised squared innovations have mean 1 while the model fits).
//!
//! No bias is estimated (the covariance is the noise's only, [`AutoOutput::bias`] is `None`)
//! when the next degree is not determined yet or does not exist (`d = MAX_DEGREE`).

use super::filter::AutomaticFilter;
#[cfg(doc)]
use super::{AutoConfig, AutoOutput};
use crate::model::PolynomialState;
use crate::polynomial::filter::PolynomialFilter;
use crate::polynomial::options::MAX_DEGREE;

/// `Δ_i` counts as a bias beyond this many of its own noise standard deviations (1: whenever
/// `Δ_i²` exceeds its noise variance).
const SIGNIFICANCE: f64 = 1.0;

/// A rejected sample is a marginal crossing (evidence of bias when the next sample crosses on
/// the same side) up to this many gate widths.
const MARGINAL: f64 = 1.25;

/// The bias `b` (one entry per derivative of `raw`) of the unit noise state `raw` estimated from
/// its degree-`(d+1)` companion's state `upper` at the same time, for noise `σ`:
/// `sign(Δ_i) √max(0, Δ_i² − σ²(V_{d+1} − V_d)_ii)`, `Δ = x_d − x_{d+1}`. `None` without
/// covariances.
pub(super) fn difference_bias(
    raw: &PolynomialState,
    upper: &PolynomialState,
    sigma: f64,
) -> Option<Vec<f64>> {
    significant_bias(raw, upper, sigma, SIGNIFICANCE)
}

/// [`difference_bias`], counted only where `|Δ_i|` exceeds `z` of its noise standard deviations
/// (0 elsewhere).
pub(super) fn significant_bias(
    raw: &PolynomialState,
    upper: &PolynomialState,
    sigma: f64,
    z: f64,
) -> Option<Vec<f64>> {
    let (vu, vd) = (upper.covariance.as_ref()?, raw.covariance.as_ref()?);
    Some(
        raw.derivatives
            .iter()
            .zip(&upper.derivatives)
            .enumerate()
            .map(|(i, (&xd, &xu))| position_bias((xd, vd[(i, i)]), (xu, vu[(i, i)]), sigma, z))
            .collect(),
    )
}

/// The bias of one derivative from its value and unit variance `(x, v)` in a filter and
/// `(x₊, v₊)` in its degree-`(d+1)` companion at the same time: `sign(Δ) √(Δ² − σ²(v₊ − v))`
/// (the excess of `Δ²` over its noise variance) where `|Δ|` exceeds `z` of its noise standard
/// deviations, else 0.
pub(super) fn position_bias((x, v): (f64, f64), (xu, vu): (f64, f64), sigma: f64, z: f64) -> f64 {
    let delta = x - xu;
    let var = sigma * sigma * (vu - v).max(0.0);
    let b = if delta * delta > z * z * var {
        (delta * delta - var).sqrt()
    } else {
        0.0
    };
    if b.is_finite() {
        b.copysign(delta)
    } else {
        0.0
    }
}

impl AutomaticFilter {
    /// The filter of the active degree plus one on the active filter's memory: the next rung of
    /// the ladder, or the companion of the final degree's memory in use.
    fn companion(&self) -> Option<&dyn PolynomialFilter> {
        if self.active < self.cfg.degree {
            self.filter(self.active + 1)
        } else {
            self.memory_companion(self.memory)
        }
    }

    /// The estimated bias `b` (one entry per derivative of `raw`) of the active filter's unit
    /// noise state `raw` at its time, for noise `σ` ([`difference_bias`]), the position's
    /// raised to the innovations' excess. `None` when the companion is not determined.
    pub(super) fn bias_of(&self, raw: &PolynomialState, sigma: f64) -> Option<Vec<f64>> {
        let mut xu = [0.0; MAX_DEGREE + 2];
        let mut vu = [0.0; MAX_DEGREE + 2];
        let mut b = if self.companion_variances(raw.time, &mut xu, &mut vu) {
            let vd = raw.covariance.as_ref()?;
            let upper = (0..raw.derivatives.len()).map(|i| (xu[i], vu[i]));
            raw.derivatives
                .iter()
                .enumerate()
                .zip(upper)
                .map(|((i, &x), u)| position_bias((x, vd[(i, i)]), u, sigma, SIGNIFICANCE))
                .collect()
        } else {
            let upper = self.companion()?.estimate_at(raw.time)?;
            difference_bias(raw, &upper, sigma)?
        };
        // The position's bias is at least what the innovations' excess says.
        let floor = self.excess.sqrt();
        if b[0].abs() < floor {
            b[0] = floor.copysign(b[0]);
        }
        Some(b)
    }

    /// The active filter's position at `t` and its unit variance, without allocating.
    pub(super) fn active_position(&self, t: f64) -> Option<(f64, f64)> {
        if self.active < self.cfg.degree {
            self.ladder[self.active].as_ref()?.position_at(t)
        } else {
            self.memory_position(self.memory, t)
        }
    }

    /// The derivatives at `t` of the active filter's companion ([`companion`](Self::companion))
    /// and their variances into `x` and `var`, without allocating on the exact engine; false
    /// when it is not determined (or has no such path: the caller takes its estimate).
    fn companion_variances(&self, t: f64, x: &mut [f64], var: &mut [f64]) -> bool {
        let c = self.active + 1;
        let m = self.cfg.degree;
        if self.active == m {
            let j = self.memory;
            if j > 0 {
                return self.shorter[j - 1].upper.variances_at(t, x, var);
            }
            return match (&self.upper_expanding, &self.upper_fading, self.switched) {
                (Some(e), _, false) => e.variances_at(t, x, var),
                (_, Some(f), _) => f.variances_at(t, x, var),
                _ => false,
            };
        }
        if c < m {
            return self.ladder[c]
                .as_ref()
                .is_some_and(|f| f.variances_at(t, x, var));
        }
        match (self.memory, &self.expanding, self.switched) {
            (0, Some(e), false) => e.variances_at(t, x, var),
            (0, _, _) => self.fading.variances_at(t, x, var),
            (j, _, _) => self.shorter[j - 1].fading.variances_at(t, x, var),
        }
    }

    /// The position at `t` of the active filter's companion ([`companion`](Self::companion)).
    fn companion_position(&self, t: f64) -> Option<(f64, f64)> {
        let c = self.active + 1;
        if self.active == self.cfg.degree {
            self.memory_companion_position(self.memory, t)
        } else if c < self.cfg.degree {
            self.ladder[c].as_ref()?.position_at(t)
        } else {
            self.memory_position(self.memory, t)
        }
    }

    /// The position bias `b₀` of the active filter's position `(x, v)` at `t` (the first entry
    /// of [`bias_of`](Self::bias_of), without allocating): 0 while the companion is not
    /// determined. `companion`: the companion's position at `t` when already computed
    /// ([`choose_memory`](Self::choose_memory)'s).
    pub(super) fn position_bias_of(
        &self,
        position: (f64, f64),
        companion: Option<Option<(f64, f64)>>,
        t: f64,
        sigma: f64,
    ) -> f64 {
        let upper = companion.unwrap_or_else(|| self.companion_position(t));
        let Some(upper) = upper else {
            return 0.0;
        };
        let b = position_bias(position, upper, sigma, SIGNIFICANCE);
        let floor = self.excess.sqrt();
        if b.abs() < floor {
            floor.copysign(b)
        } else {
            b
        }
    }

    /// The prediction's position bias `b₀` raised by the current run of rejections: a
    /// rejected sample on the same side as the innovation `ν` and within [`MARGINAL`] gate widths
    /// (`|r| ≤ 1.25 k√(σ²(1+v) + b₀²)`, a marginal crossing, not a jump) is taken as evidence of
    /// bias (Morrison §14.8: repeated crossings mean bias), `b₀² ≥ r² − σ²(1+v)` with `r` its
    /// residual against the current prediction and `v` that prediction's VRF.
    pub(super) fn with_pending(&self, b0: f64, nu: Option<f64>, sigma: Option<f64>) -> f64 {
        let (Some(nu), Some(s)) = (nu, sigma) else {
            return b0;
        };
        let k = self.cfg.outliers.multiplier();
        let mut b2 = b0 * b0;
        for p in &self.pending {
            let Some(pred) = self.active_filter().estimate_at(p.t) else {
                continue;
            };
            let v = pred.covariance.as_ref().map_or(0.0, |c| c[(0, 0)].max(0.0));
            let r = p.y - pred.derivatives[0];
            let noise = s * s * (1.0 + v);
            let marginal = r.abs() <= MARGINAL * k * (noise + b0 * b0).sqrt();
            if marginal && r.signum() == nu.signum() && r * r - noise > b2 {
                b2 = r * r - noise;
            }
        }
        if b2.is_finite() {
            b2.sqrt().copysign(b0)
        } else {
            b0
        }
    }

    /// True when the current run of rejections ends with
    /// [`AutoConfig::same_side_rejections`] `≥ 2` samples all on the same side of the active
    /// filter's prediction (Morrison §14.8: repeated crossings on one side mean bias, not
    /// outliers; two outliers in a row on one side at an outlier rate `p` happen at `p²/2` per
    /// sample).
    pub(super) fn same_side_run(&self) -> bool {
        let n = self.cfg.same_side_rejections;
        if n < 2 || self.pending.len() < n {
            return false;
        }
        let f = self.active_filter();
        let mut side = 0.0;
        for p in &self.pending[self.pending.len() - n..] {
            let Some(pred) = f.estimate_at(p.t) else {
                return false;
            };
            let r = (p.y - pred.derivatives[0]).signum();
            if side != 0.0 && r != side {
                return false;
            }
            side = r;
        }
        true
    }

    /// The innovations' mean square excess over their expected variance `var` in the misfit
    /// window: `max(0, mean(k²) − 1)·var` (Morrison §14.8: the normalised squared innovations
    /// have mean 1 while the model fits; their excess is the squared bias of the predictions).
    pub(super) fn innovation_excess(&self, var: f64) -> f64 {
        let n = self.chi.len();
        if n == 0 {
            return 0.0;
        }
        // Counted while the misfit test says the excess is significant.
        let r = self.chi.statistic() / n as f64 - 1.0;
        if r.is_finite() && r > 0.0 && self.chi.is_misfit() {
            r * var
        } else {
            0.0
        }
    }

    /// The reported state of a unit noise state `raw` of the active filter: covariance
    /// `σ² V + b bᵀ` with the bias of [`bias_of`](Self::bias_of), and that bias; without `σ`
    /// no covariance and no bias.
    pub(super) fn honest(&self, raw: PolynomialState) -> (PolynomialState, Option<Vec<f64>>) {
        let Some(sigma) = self.noise_sigma() else {
            return (
                PolynomialState {
                    covariance: None,
                    ..raw
                },
                None,
            );
        };
        let bias = self.bias_of(&raw, sigma);
        let factor = self.calibration_factor();
        let mut raw = raw;
        if let Some(c) = &mut raw.covariance {
            // In place: the raw covariance is this call's own.
            *c *= sigma * sigma;
            if let Some(b) = &bias {
                for i in 0..c.nrows() {
                    for j in 0..c.ncols() {
                        c[(i, j)] += b[i] * b[j];
                    }
                }
            }
            *c *= factor;
        }
        (raw, bias)
    }
}
