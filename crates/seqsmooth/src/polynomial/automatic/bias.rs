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

#[cfg(doc)]
use super::output::AutoOutput;
use crate::model::PolynomialState;
use crate::stats::InnovationChiSquared;

/// `Δ_i` counts as a bias beyond this many of its own noise standard deviations (1: whenever
/// `Δ_i²` exceeds its noise variance).
pub(super) const SIGNIFICANCE: f64 = 1.0;

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

/// `b` raised to `floor` in magnitude (its sign kept): the position's bias is at least what
/// the innovations' excess says.
pub(super) fn at_least(b: f64, floor: f64) -> f64 {
    if b.abs() < floor {
        floor.copysign(b)
    } else {
        b
    }
}

/// The innovations' mean square excess over their expected variance `var` in the misfit
/// window `chi`: `max(0, mean(k²) − 1)·var` (Morrison §14.8: the normalised squared
/// innovations have mean 1 while the model fits; their excess is the squared bias of the
/// predictions), counted while the misfit test says it is significant.
pub(super) fn innovation_excess(chi: &InnovationChiSquared, var: f64) -> f64 {
    let n = chi.len();
    if n == 0 {
        return 0.0;
    }
    let r = chi.statistic() / n as f64 - 1.0;
    if r.is_finite() && r > 0.0 && chi.is_misfit() {
        r * var
    } else {
        0.0
    }
}

/// The reported state of a unit noise state `raw`: covariance `factor·(σ² V + b bᵀ)` with the
/// estimated bias `b` (none: the noise's only), in place.
pub(super) fn honest(raw: &mut PolynomialState, sigma: f64, bias: Option<&[f64]>, factor: f64) {
    if let Some(c) = &mut raw.covariance {
        // Entry by entry `((c σ²) + b_i b_j)·factor`, column-major as the matrix is stored.
        let (p, s2) = (c.nrows(), sigma * sigma);
        match bias {
            Some(b) => {
                for (k, v) in c.as_mut_slice().iter_mut().enumerate() {
                    *v = (*v * s2 + b[k % p] * b[k / p]) * factor;
                }
            }
            None => c
                .as_mut_slice()
                .iter_mut()
                .for_each(|v| *v = *v * s2 * factor),
        }
    }
}
