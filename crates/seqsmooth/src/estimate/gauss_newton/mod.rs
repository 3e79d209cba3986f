//! Gauss–Newton iterative differential correction over a window of observations (Morrison
//! §8.6-8.7), with or without an a-priori estimate (ch. 11):
//!
//! | step | | source |
//! |---|---|---|
//! | nominal `X̄` at the epoch `t_c` | the user's, or [`super::bootstrap`] | §8.5 |
//! | trajectory and `Φ(t_k, t_c; X̄)` | [`Dynamics::propagate`], outwards from `t_c` | steps II, IV, (8.6.28)-(8.6.29) |
//! | `T = [M_k Φ(t_k, t_c)]`, `δY_k = Y_k − G(X̄(t_k))` | [`Observation::predict`], present components only | steps III-VII, (8.6.35) |
//! | `δX = (Tᵀ R⁻¹ T)⁻¹ Tᵀ R⁻¹ δY`, `S = (Tᵀ R⁻¹ T)⁻¹` | the whitened system's Householder QR, as [`super::batch::minimum_variance`] solves it | (8.6.36)-(8.6.38) |
//! | with a prior `X_p`, `S_p`: the rows `S_p^{−1/2} (X_p − X̄)` stacked on | | (11.2.24)-(11.2.27), (11.4.33) |
//! | `X̄ ← X̄ + λ δX`, `λ = 1, 1/2, …` until `e(X)` falls | | (8.7.1), step halving |
//!
//! `e(X) = Σ_k δY_kᵀ R_k⁻¹ δY_k (+ (X_p − X)ᵀ S_p⁻¹ (X_p − X))` is the residual chi-squared
//! (11.4.9), (11.4.33). Convergence: the correction in units of its own standard deviation,
//! `c = sqrt(δXᵀ S⁻¹ δX)`, at most the tolerance. `c` is also the norm of the whitened gradient
//! `Tᵀ R⁻¹ δY (+ S_p⁻¹ (X_p − X̄))` in the metric `S`, so `c → 0` is the stationarity condition
//! (11.4.5), (11.4.26); and `c²` is the fall of the residual chi-squared the linearised step
//! predicts, `e(X̄) − |δY − T δX|²`, so the one test bounds both the correction and the change
//! of `e` still to come. The covariance reported is `S` of the last linearisation (8.6.38); for a
//! nonlinear model it is the first-order approximation the book warns of (§11.4).

use super::batch::{
    certainly_full_rank, covariance_of, factor_in_place, full_rank, solve_factored, solve_step,
};
use crate::error::{Error, Param};
use crate::model::dynamics::Dynamics;
pub use crate::model::measurement::{Measurement, NoiseCovariance};
use crate::model::observation::Observation;
use linearise::{prepare, prepare_prior, radar_cv, Layout, Model, Scratch, System};
use nalgebra::{DMatrix, DVector};

mod linearise;

/// The instant the estimate refers to.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Epoch {
    /// The last observation time (the leading edge, §8.3).
    End,
    /// The mean of the observation times, where the bias is smallest (§8.6).
    Centre,
    /// A given time.
    At(f64),
}

impl Epoch {
    /// The epoch a front end names: `end`, `centre` (or `center`); `None` for any other name
    /// (a time, which the front end parses as a number).
    ///
    /// ```
    /// use seqsmooth::estimate::gauss_newton::Epoch;
    /// assert_eq!(Epoch::from_name("center"), Some(Epoch::Centre));
    /// assert_eq!(Epoch::from_name("12.5"), None);
    /// ```
    pub fn from_name(name: &str) -> Option<Epoch> {
        match name {
            "end" => Some(Epoch::End),
            "centre" | "center" => Some(Epoch::Centre),
            _ => None,
        }
    }

    /// The range of an epoch: a given time must be finite ([`Param::Epoch`]; every front
    /// end's check, and the sliding fit's).
    ///
    /// ```
    /// use seqsmooth::estimate::gauss_newton::Epoch;
    /// assert!(Epoch::At(1.5).check().is_ok() && Epoch::At(f64::INFINITY).check().is_err());
    /// ```
    pub fn check(self) -> Result<(), Error> {
        match self {
            Epoch::At(t) if !t.is_finite() => Err(Error::InvalidParameter {
                name: Param::Epoch,
                value: t.to_string(),
                reason: "must be 'end', 'centre' or a finite time".into(),
            }),
            _ => Ok(()),
        }
    }

    /// The time, for observations at `times` (not empty).
    ///
    /// ```
    /// use seqsmooth::estimate::gauss_newton::Epoch;
    /// assert_eq!(Epoch::Centre.time_for(&[0.0, 1.0, 5.0]), 2.0);
    /// assert_eq!(Epoch::End.time_for(&[0.0, 1.0, 5.0]), 5.0);
    /// ```
    pub fn time_for(&self, times: &[f64]) -> f64 {
        match *self {
            Epoch::End => times.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            Epoch::Centre => {
                // The mean about the first time, so that epoch-sized times keep their digits.
                let t0 = times.first().copied().unwrap_or(0.0);
                t0 + times.iter().map(|t| t - t0).sum::<f64>() / times.len().max(1) as f64
            }
            Epoch::At(t) => t,
        }
    }
}

/// An a-priori estimate at the fit's epoch: the state and its covariance (symmetric positive
/// definite).
#[derive(Clone, Debug, PartialEq)]
pub struct Prior {
    /// `X*_{n,k}`.
    pub state: DVector<f64>,
    /// `S*_{n,k}`.
    pub covariance: DMatrix<f64>,
}

/// One iteration of the correction.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Iteration {
    /// The estimate after the step, `X̄ + step · δX`.
    pub state: DVector<f64>,
    /// `sqrt(δXᵀ S⁻¹ δX)`: the correction proposed at this iteration, in units of its own σ.
    pub correction: f64,
    /// The fraction of it taken: 1, or 2⁻ʰ after `h` halvings.
    pub step: f64,
    /// `e(X)` after the step.
    pub chi_squared: f64,
}

/// A converged differential correction.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Correction {
    /// The epoch `t_c` of the state.
    pub epoch: f64,
    /// `X*(t_c)`.
    pub state: DVector<f64>,
    /// `S*(t_c) = (Tᵀ R⁻¹ T (+ S_p⁻¹))⁻¹` at the last linearisation.
    pub covariance: DMatrix<f64>,
    /// `e(X*)`.
    pub chi_squared: f64,
    /// Observation components used (plus `n` with a prior) less `n`.
    pub degrees_of_freedom: usize,
    /// The condition number of the whitened `T`.
    pub condition_number: f64,
    /// Every iteration, in order; the last one's correction met the tolerance.
    pub iterations: Vec<Iteration>,
}

/// The most linearisations a fit may be allowed ([`GaussNewton::max_iterations`]): a bound on
/// the work of one window, far beyond what a fit that converges needs (two or three where the
/// windows overlap, Morrison §8.7).
pub const MAX_ITERATIONS: usize = 1000;

/// The range of [`GaussNewton::max_iterations`]: `1 ≤ n ≤ MAX_ITERATIONS` (every front end's
/// check, and the fit's own).
///
/// ```
/// use seqsmooth::estimate::gauss_newton::{check_max_iterations, MAX_ITERATIONS};
/// assert!(check_max_iterations(1).is_ok() && check_max_iterations(MAX_ITERATIONS).is_ok());
/// assert!(check_max_iterations(0).is_err() && check_max_iterations(MAX_ITERATIONS + 1).is_err());
/// ```
pub fn check_max_iterations(n: usize) -> Result<(), Error> {
    if !(1..=MAX_ITERATIONS).contains(&n) {
        return Err(Error::InvalidParameter {
            name: Param::MaxIterations,
            value: n.to_string(),
            reason: format!("must be from 1 to {MAX_ITERATIONS}"),
        });
    }
    Ok(())
}

/// The iteration's limits.
///
/// ```
/// use seqsmooth::estimate::gauss_newton::GaussNewton;
/// let g = GaussNewton::default();
/// assert_eq!((g.max_iterations, g.tolerance, g.max_halvings), (20, 1e-6, 30));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GaussNewton {
    /// Linearisations allowed before [`Error::NotConverged`].
    pub max_iterations: usize,
    /// The correction, in its own σ, below which the iteration has converged.
    pub tolerance: f64,
    /// Halvings of one correction before [`Error::Diverged`].
    pub max_halvings: usize,
}

impl Default for GaussNewton {
    fn default() -> Self {
        Self {
            max_iterations: 20,
            tolerance: 1e-6,
            max_halvings: 30,
        }
    }
}

impl GaussNewton {
    /// The default limits with `max_iterations` linearisations, checked
    /// ([`check_max_iterations`]).
    ///
    /// ```
    /// use seqsmooth::estimate::gauss_newton::GaussNewton;
    /// assert_eq!(GaussNewton::with_max_iterations(5).unwrap().max_iterations, 5);
    /// assert!(GaussNewton::with_max_iterations(0).is_err());
    /// ```
    pub fn with_max_iterations(max_iterations: usize) -> Result<Self, Error> {
        check_max_iterations(max_iterations)?;
        Ok(Self {
            max_iterations,
            ..Self::default()
        })
    }
}

impl GaussNewton {
    /// Corrects `nominal` (the state at `epoch`) by Gauss–Newton iteration until the correction
    /// is below [`Self::tolerance`] of its own σ, with step halving; `prior`, if given, is an
    /// a-priori estimate at the same epoch (ch. 11).
    ///
    /// ```
    /// use nalgebra::DVector;
    /// use seqsmooth::model::measurement::NoiseCovariance;
    /// use seqsmooth::estimate::gauss_newton::{Epoch, GaussNewton, Measurement};
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// // A straight line through three points: linear, so one correction, then a check.
    /// let m: Vec<Measurement> = [(0.0, 1.0), (1.0, 3.0), (2.0, 5.0)]
    ///     .iter()
    ///     .map(|&(t, y)| Measurement { time: t, values: vec![Some(y)], noise: NoiseCovariance::Variances(vec![1.0]) })
    ///     .collect();
    /// let fit = GaussNewton::default()
    ///     .fit(&PolynomialDynamics::new(1, 1), &LinearObservation::value_of(2), &m, Epoch::End, &DVector::zeros(2), None)
    ///     .unwrap();
    /// assert!((fit.state[0] - 5.0).abs() < 1e-12 && (fit.state[1] - 2.0).abs() < 1e-12);
    /// assert_eq!(fit.iterations.len(), 2);
    /// ```
    pub fn fit<D: Dynamics, O: Observation>(
        &self,
        dynamics: &D,
        observation: &O,
        measurements: &[Measurement],
        epoch: Epoch,
        nominal: &DVector<f64>,
        prior: Option<&Prior>,
    ) -> Result<Correction, Error> {
        self.check()?;
        let n = dynamics.dimension();
        if observation.state_dimension() != n {
            return Err(Error::InvalidParameter {
                name: Param::ObservationModel,
                value: format!("for {} states", observation.state_dimension()),
                reason: format!("the dynamics have {n} states"),
            });
        }
        if nominal.len() != n {
            return Err(Error::InvalidParameter {
                name: Param::NominalState,
                value: format!("of length {}", nominal.len()),
                reason: format!("must have the model's dimension {n}"),
            });
        }
        if let Some(&value) = nominal.iter().find(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "nominal state entry",
                value,
            });
        }
        let prepared = prepare(observation, measurements)?;
        let rows = &prepared.rows;
        let times: Vec<f64> = measurements.iter().map(|m| m.time).collect();
        if times.is_empty() {
            return Err(Error::TooFewSamples { needed: 1, got: 0 });
        }
        let t_c = epoch.time_for(&times);
        if !t_c.is_finite() {
            return Err(Error::NonFinite {
                what: "epoch",
                value: t_c,
            });
        }
        let prior = prior.map(|p| prepare_prior(p, n)).transpose()?;
        let used: usize =
            rows.iter().map(|r| r.count).sum::<usize>() + prior.as_ref().map_or(0, |_| n);
        if used < n {
            return Err(Error::TooFewSamples {
                needed: n,
                got: used,
            });
        }

        let mut layout = Layout::new(rows, t_c, prior.as_ref().map_or(0, |_| n));
        if dynamics.is_linear() {
            let radar = radar_cv(dynamics, observation).is_some();
            layout = layout.with_transitions(dynamics, rows, (t_c, nominal), radar)?;
        }
        // Every buffer of the iteration, made once: the system at the nominal and at the
        // candidate (swapped when the candidate is taken), `R`, `δX`, the candidate.
        let model = Model {
            dynamics,
            observation,
            rows: &prepared,
            layout: &layout,
            t_c,
            prior: prior.as_ref(),
        };
        let mut scratch = Scratch::new(n, observation.components());
        let mut lin = System::new(layout.total, n);
        let mut next = System::new(layout.total, n);
        let mut r = DMatrix::zeros(n.min(layout.total), n);
        let (mut dx, mut candidate) = (DVector::zeros(n), DVector::zeros(n));
        let mut x = nominal.clone();
        model.linearise(&x, &mut lin, &mut scratch)?;
        let mut iterations = Vec::new();
        for iteration in 1..=self.max_iterations {
            factor_in_place(&mut lin.t, &mut lin.r, &mut r);
            // The rank test by `T`'s singular values where a cheap bound of its condition
            // number cannot settle it; else the step at once, and the singular values (for
            // the condition number reported) only at the last iteration: the same numbers and
            // the same errors as testing at every iteration.
            let rows = lin.r.len();
            let mut solution = if certainly_full_rank(&r, rows, 0.0) {
                solve_step(&r, &lin.r, f64::NAN, &mut dx)?
            } else {
                solve_factored(&r, &lin.r, 0.0, &mut dx)?
            };
            // |T δX| = sqrt(δXᵀ S⁻¹ δX), the correction in its own σ.
            let correction = solution.explained;
            if correction <= self.tolerance {
                if solution.condition_number.is_nan() {
                    solution.condition_number = full_rank(&r, rows, n, 0.0)?;
                }
                x += &dx;
                let covariance = covariance_of(&r);
                if !(x.iter().chain(covariance.iter()).all(|v| v.is_finite())
                    && solution.chi_squared.is_finite())
                {
                    return Err(Error::EstimateOutOfRange {
                        what: "differential correction's state or covariance".into(),
                    });
                }
                iterations.push(Iteration {
                    state: x.clone(),
                    correction,
                    step: 1.0,
                    chi_squared: solution.chi_squared,
                });
                return Ok(Correction {
                    epoch: t_c,
                    state: x,
                    covariance,
                    chi_squared: solution.chi_squared,
                    degrees_of_freedom: solution.degrees_of_freedom,
                    condition_number: solution.condition_number,
                    iterations,
                });
            }
            let lin_chi_squared = lin.chi_squared;
            let slack = 1e-10 * lin_chi_squared.max(1.0);
            let mut step = 1.0;
            let mut accepted = false;
            for _ in 0..=self.max_halvings {
                for ((c, x), dx) in candidate.iter_mut().zip(&x).zip(&dx) {
                    *c = x + dx * step;
                }
                if model.linearise(&candidate, &mut next, &mut scratch).is_ok()
                    && next.chi_squared <= lin_chi_squared + slack
                {
                    accepted = true;
                    break;
                }
                step *= 0.5;
            }
            if !accepted {
                return Err(Error::Diverged {
                    iteration,
                    chi_squared: lin_chi_squared,
                    halvings: self.max_halvings,
                });
            }
            iterations.push(Iteration {
                state: candidate.clone(),
                correction,
                step,
                chi_squared: next.chi_squared,
            });
            std::mem::swap(&mut x, &mut candidate);
            std::mem::swap(&mut lin, &mut next);
        }
        Err(Error::NotConverged {
            iterations: self.max_iterations,
            correction: iterations.last().map_or(f64::INFINITY, |i| i.correction),
            tolerance: self.tolerance,
            chi_squared: lin.chi_squared,
        })
    }

    fn check(&self) -> Result<(), Error> {
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return Err(Error::InvalidParameter {
                name: Param::Tolerance,
                value: self.tolerance.to_string(),
                reason: "must be positive and finite".into(),
            });
        }
        check_max_iterations(self.max_iterations)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    /// The cheap rank bound never passes a system the singular values would refuse, and
    /// passes the well-conditioned ones: random `R` of 1-9 states with condition numbers
    /// from 1 to 10²⁰ (singular values spread by a diagonal scale), against [`full_rank`].
    #[test]
    fn the_rank_bound_agrees_with_the_singular_values() {
        let mut rng = StdRng::seed_from_u64(33);
        let (mut passed, mut refused) = (0, 0);
        for case in 0..2000 {
            let n = 1 + case % 9;
            let rows = n + rng.gen_range(0..200);
            let spread: f64 = rng.gen_range(0.0..20.0);
            let t = DMatrix::from_fn(rows, n, |_, j| {
                rng.gen_range(-1.0..1.0) * 10f64.powf(-spread * j as f64 / n.max(2) as f64)
            });
            let (mut t2, mut y, mut r) = (t, DVector::zeros(rows), DMatrix::zeros(n, n));
            factor_in_place(&mut t2, &mut y, &mut r);
            let floor = if case % 3 == 0 { 1e-8 } else { 0.0 };
            let exact = full_rank(&r, rows, n, floor);
            if certainly_full_rank(&r, rows, floor) {
                assert!(
                    exact.is_ok(),
                    "case {case}: the bound passed a refused system"
                );
                passed += 1;
            } else if exact.is_err() {
                refused += 1;
            }
        }
        assert!(passed > 1000 && refused > 100, "{passed} {refused}");
    }

    /// The in-place factors and solve give nalgebra's `qr()`, `q_tr_mul`, `r()` and
    /// `solve_upper_triangular` bit for bit, on random tall systems of 1-9 columns (one with a
    /// zero column, whose reflection is skipped).
    #[test]
    fn the_in_place_factors_are_nalgebras() {
        let mut rng = StdRng::seed_from_u64(8);
        for case in 0..300 {
            let n = 1 + case % 9;
            let rows = n + rng.gen_range(0..200);
            let mut t = DMatrix::from_fn(rows, n, |_, _| rng.gen_range(-3.0..3.0));
            if case % 50 == 7 {
                t.column_mut(n - 1).fill(0.0);
            }
            let y = DVector::from_fn(rows, |_, _| rng.gen_range(-3.0..3.0));
            let qr = t.clone().qr();
            let mut rotated = y.clone();
            qr.q_tr_mul(&mut rotated);
            let (mut t2, mut y2, mut r) = (t.clone(), y.clone(), DMatrix::zeros(n, n));
            factor_in_place(&mut t2, &mut y2, &mut r);
            assert_eq!(r, qr.r());
            assert_eq!(y2, rotated);
            let mut x = DVector::zeros(n);
            match solve_factored(&r, &y2, 0.0, &mut x) {
                Ok(step) => {
                    let head = rotated.rows(0, n).into_owned();
                    assert_eq!(Some(x), qr.r().solve_upper_triangular(&head));
                    assert_eq!(step.explained, head.norm());
                    let tail = rotated.rows(n, rows - n).norm_squared();
                    assert_eq!(step.chi_squared, tail);
                }
                Err(e) => assert!(case % 50 == 7, "{e}"),
            }
        }
    }
}
