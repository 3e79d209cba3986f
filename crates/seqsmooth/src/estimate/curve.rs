//! The maximum-likelihood fit of a curve model `y(t_k) = h(θ, t_k) + v_k`, `v_k` independent
//! Gaussian of known variance `σ_k²` (Villien & Ostertag 2009, eqs. 1-2):
//!
//! | quantity | | source |
//! |---|---|---|
//! | `θ̂ = argmin e(θ)`, `e(θ) = Σ_k (y_k − h(θ, t_k))²/σ_k²` | Levenberg–Marquardt (MINPACK's `lmder`, crate `levenberg-marquardt`) on the whitened residuals | V&O eq. 2; Morrison (8.6.36) for the linearisation |
//! | Fisher information `F(θ) = Σ_k ∇h ∇hᵀ/σ_k²` | the whitened Jacobian's Householder QR, `F = RᵀR` | V&O §VI (the CRLB) |
//! | Cramér–Rao bound, and the fit's covariance at `θ̂` | `F⁻¹ = R⁻¹R⁻ᵀ`, never the inverse of `F` formed | Morrison (8.6.38) |
//!
//! The same fit on a segment's polynomial samples (their nodes, values and variances) is the
//! PAML estimate (V&O eqs. 3-4): [`crate::paml::PolynomialSamples::fit`].
//!
//! The Levenberg–Marquardt step is MINPACK's trust-region form with the Jacobian's column
//! norms as the scaling, so parameters of different units (metres and metres per second) need
//! no rescaling. It stops when the relative reduction of `e` (actual and predicted) or the
//! relative step falls below `1e-10`; Gauss–Newton steps then finish the fit until the
//! correction `δ` still proposed is at most `1e-9` of its own σ, `sqrt(δᵀ F δ) ≤ 1e-9` (the
//! convergence test of [`super::gauss_newton`], on the same QR that gives the covariance), so
//! that a fit on 6 samples and one on 1 200 stop at the same distance from their minimum.
//! The covariance is the first-order one of the last linearisation (Morrison §11.4); it equals
//! the Cramér–Rao bound at `θ̂`.
//!
//! The Jacobian `∂h/∂θ` is the model's when given ([`CurveModel::jacobian`]); otherwise central
//! differences with the step `ε^{1/3} max(|θ_j|, 1)` (error `O(ε^{2/3})` relative for
//! parameters of order one or more; give the analytic Jacobian for smaller ones). A
//! differenced Jacobian whose singular values span more than `10⁸` leaves the parameters
//! undetermined ([`Error::Unobservable`]): differences resolve no finer.

use super::batch::{is_usable_sigma, Factored, Solved};
use crate::error::{check_finite, Error, Param};
use crate::model::nonlinear::central_differences;
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt, TerminationReason};
use nalgebra::{DMatrix, DVector, Dyn, Owned};
use std::cell::RefCell;
use std::sync::Arc;

/// A model `h(θ, t)` of a scalar signal with `m` parameters, evaluated at many times at once.
///
/// ```
/// use nalgebra::DMatrix;
/// use seqsmooth::estimate::curve::CurveModel;
/// use seqsmooth::Error;
/// /// h = θ₀ e^{θ₁ t}
/// struct Decay;
/// impl CurveModel for Decay {
///     fn parameters(&self) -> usize { 2 }
///     fn values(&self, th: &[f64], times: &[f64]) -> Result<Vec<f64>, Error> {
///         Ok(times.iter().map(|t| th[0] * (th[1] * t).exp()).collect())
///     }
/// }
/// assert_eq!(Decay.values(&[2.0, 0.0], &[1.0, 5.0]).unwrap(), vec![2.0, 2.0]);
/// assert!(Decay.jacobian(&[2.0, 0.0], &[1.0]).is_none()); // differenced by the fit
/// ```
pub trait CurveModel {
    /// `m`, the number of parameters.
    fn parameters(&self) -> usize;

    /// `h(θ, t_k)` for every time, in order.
    fn values(&self, theta: &[f64], times: &[f64]) -> Result<Vec<f64>, Error>;

    /// `∂h/∂θ_j (θ, t_k)`, one row a time and one column a parameter; `None` (the default)
    /// asks for central differences of [`values`](Self::values).
    fn jacobian(&self, theta: &[f64], times: &[f64]) -> Option<Result<DMatrix<f64>, Error>> {
        let _ = (theta, times);
        None
    }
}

type Value = Arc<dyn Fn(&[f64], f64) -> f64 + Send + Sync>;
type Gradient = Arc<dyn Fn(&[f64], f64, &mut [f64]) + Send + Sync>;

/// A [`CurveModel`] from a function of one time, `h(θ, t)`, and optionally its gradient.
///
/// ```
/// use seqsmooth::estimate::curve::{Curve, CurveModel};
/// // h = θ₀ + θ₁ sin t, with its gradient (1, sin t)
/// let h = Curve::new(2, |th: &[f64], t| th[0] + th[1] * t.sin())
///     .with_gradient(|_th: &[f64], t, g: &mut [f64]| { g[0] = 1.0; g[1] = t.sin(); });
/// let j = h.jacobian(&[0.0, 1.0], &[0.0, 1.0]).unwrap().unwrap();
/// assert_eq!((j[(1, 0)], j[(1, 1)]), (1.0, 1f64.sin()));
/// ```
#[derive(Clone)]
pub struct Curve {
    parameters: usize,
    value: Value,
    gradient: Option<Gradient>,
}

impl std::fmt::Debug for Curve {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Curve")
            .field("parameters", &self.parameters)
            .field("analytic_gradient", &self.gradient.is_some())
            .finish()
    }
}

impl Curve {
    /// `h(θ, t)` with `parameters` parameters; its gradient by central differences.
    ///
    /// ```
    /// use seqsmooth::estimate::curve::{Curve, CurveModel};
    /// let line = Curve::new(2, |th: &[f64], t| th[0] + th[1] * t);
    /// assert_eq!(line.values(&[1.0, 2.0], &[0.0, 3.0]).unwrap(), vec![1.0, 7.0]);
    /// ```
    pub fn new<H>(parameters: usize, value: H) -> Self
    where
        H: Fn(&[f64], f64) -> f64 + Send + Sync + 'static,
    {
        Self {
            parameters,
            value: Arc::new(value),
            gradient: None,
        }
    }

    /// With the analytic gradient: `gradient(θ, t, g)` writes `∂h/∂θ_j` into `g[j]`.
    ///
    /// ```
    /// use seqsmooth::estimate::curve::{Curve, CurveModel};
    /// let line = Curve::new(2, |th: &[f64], t| th[0] + th[1] * t)
    ///     .with_gradient(|_th: &[f64], t, g: &mut [f64]| g.copy_from_slice(&[1.0, t]));
    /// assert_eq!(line.jacobian(&[0.0, 0.0], &[2.0]).unwrap().unwrap()[(0, 1)], 2.0);
    /// ```
    pub fn with_gradient<G>(mut self, gradient: G) -> Self
    where
        G: Fn(&[f64], f64, &mut [f64]) + Send + Sync + 'static,
    {
        self.gradient = Some(Arc::new(gradient));
        self
    }
}

impl CurveModel for Curve {
    fn parameters(&self) -> usize {
        self.parameters
    }

    fn values(&self, theta: &[f64], times: &[f64]) -> Result<Vec<f64>, Error> {
        Ok(times.iter().map(|&t| (self.value)(theta, t)).collect())
    }

    fn jacobian(&self, theta: &[f64], times: &[f64]) -> Option<Result<DMatrix<f64>, Error>> {
        let gradient = self.gradient.as_ref()?;
        let mut j = DMatrix::zeros(times.len(), self.parameters);
        let mut g = vec![0.0; self.parameters];
        for (k, &t) in times.iter().enumerate() {
            g.fill(0.0);
            gradient(theta, t, &mut g);
            for (c, v) in g.iter().enumerate() {
                j[(k, c)] = *v;
            }
        }
        Some(Ok(j))
    }
}

/// A converged fit.
#[derive(Clone, Debug, PartialEq)]
pub struct CurveFit {
    /// `θ̂`.
    pub parameters: DVector<f64>,
    /// `F(θ̂)⁻¹`: the fit's covariance to first order, the Cramér–Rao bound at `θ̂`.
    pub covariance: DMatrix<f64>,
    /// `e(θ̂) = Σ_k (y_k − h(θ̂, t_k))²/σ_k²`.
    pub chi_squared: f64,
    /// Samples less parameters.
    pub degrees_of_freedom: usize,
    /// The condition number of the whitened Jacobian at `θ̂`.
    pub condition_number: f64,
    /// `sqrt(δᵀ F δ)` for the Gauss–Newton correction `δ` still proposed at `θ̂`: how far
    /// from the minimum it is, in units of its own σ (at most `1e-9` unless rounding or a
    /// long curved valley stopped it first; a fit above `1e-3` is refused).
    pub correction: f64,
    /// Evaluations of the model: the Levenberg–Marquardt stage's residual evaluations and one a
    /// Gauss–Newton finishing step (its values and Jacobian together).
    pub evaluations: usize,
}

impl CurveFit {
    /// `sqrt` of the covariance's diagonal: each parameter's standard deviation.
    ///
    /// ```
    /// use seqsmooth::estimate::curve::{fit_curve, Curve};
    /// let line = Curve::new(2, |th: &[f64], t| th[0] + th[1] * t);
    /// let t = [-1.0, 0.0, 1.0];
    /// let fit = fit_curve(&line, &t, &[1.0, 2.0, 3.0], &[1.0; 3], &[0.0, 0.0])?;
    /// let s = fit.std_devs();
    /// // 1/3 and 1/Σt²; to 1e-11, the differenced Jacobian's rounding
    /// assert!((s[0] - (1.0f64 / 3.0).sqrt()).abs() < 1e-10 && (s[1] - 0.5f64.sqrt()).abs() < 1e-10);
    /// # Ok::<(), seqsmooth::Error>(())
    /// ```
    pub fn std_devs(&self) -> Vec<f64> {
        crate::linalg::std_devs(&self.covariance)
    }

    /// [`Self::std_devs`], by its old name.
    #[deprecated(note = "use std_devs, the one name of an estimate's 1σ")]
    pub fn standard_deviations(&self) -> Vec<f64> {
        self.std_devs()
    }
}

/// The samples, checked: times and values finite, σ usable, lengths equal, enough of them.
struct Samples<'a> {
    times: &'a [f64],
    values: &'a [f64],
    inverse_sigmas: Vec<f64>,
}

impl<'a> Samples<'a> {
    fn new(
        times: &'a [f64],
        values: Option<&'a [f64]>,
        sigmas: &[f64],
        parameters: usize,
    ) -> Result<Self, Error> {
        let n = times.len();
        if sigmas.len() != n || values.is_some_and(|v| v.len() != n) {
            return Err(Error::InvalidParameter {
                name: Param::InputLengths,
                value: format!(
                    "{n} times, {} values, {} sigmas",
                    values.map_or(n, <[f64]>::len),
                    sigmas.len()
                ),
                reason: "one value and one sigma per time".into(),
            });
        }
        if parameters == 0 {
            return Err(Error::InvalidParameter {
                name: Param::Model,
                value: "with 0 parameters".into(),
                reason: "there is nothing to estimate".into(),
            });
        }
        if n < parameters {
            return Err(Error::TooFewSamples {
                needed: parameters,
                got: n,
            });
        }
        check_finite("time", times)?;
        if let Some(v) = values {
            check_finite("value", v)?;
        }
        if let Some(&s) = sigmas.iter().find(|&&s| !is_usable_sigma(s)) {
            return Err(Error::InvalidParameter {
                name: Param::Sigmas,
                value: s.to_string(),
                reason: "each sigma must be positive and finite, with a normal square".into(),
            });
        }
        Ok(Self {
            times,
            values: values.unwrap_or(&[]),
            inverse_sigmas: sigmas.iter().map(|s| 1.0 / s).collect(),
        })
    }

    /// `h(θ, t_k)`, checked: `N` finite numbers.
    fn model_values<M: CurveModel + ?Sized>(
        &self,
        model: &M,
        theta: &[f64],
    ) -> Result<Vec<f64>, Error> {
        let h = model.values(theta, self.times)?;
        if h.len() != self.times.len() {
            return Err(Error::InvalidParameter {
                name: Param::Model,
                value: format!("gave {} values", h.len()),
                reason: format!("{} times were asked for", self.times.len()),
            });
        }
        check_finite("model value", &h)?;
        Ok(h)
    }

    /// `∂h/∂θ`, checked: `N × m` finite numbers; the model's or central differences.
    fn model_jacobian<M: CurveModel + ?Sized>(
        &self,
        model: &M,
        theta: &[f64],
    ) -> Result<DMatrix<f64>, Error> {
        self.jacobian_and_kind(model, theta).map(|(j, _)| j)
    }

    /// `∂h/∂θ` and whether it was differenced.
    fn jacobian_and_kind<M: CurveModel + ?Sized>(
        &self,
        model: &M,
        theta: &[f64],
    ) -> Result<(DMatrix<f64>, bool), Error> {
        let m = model.parameters();
        let analytic = model.jacobian(theta, self.times);
        let differenced = analytic.is_none();
        let j = match analytic {
            Some(j) => j?,
            None => {
                let failed = RefCell::new(None);
                let x = DVector::from_column_slice(theta);
                let j = central_differences(self.times.len(), &x, |probe| {
                    match self.model_values(model, probe.as_slice()) {
                        Ok(h) => Some(DVector::from_vec(h)),
                        Err(e) => {
                            failed.replace(Some(e));
                            None
                        }
                    }
                });
                match j {
                    Some(j) => j,
                    None => return Err(failed.into_inner().expect("set on failure")),
                }
            }
        };
        if j.shape() != (self.times.len(), m) {
            return Err(Error::InvalidParameter {
                name: Param::Model,
                value: format!("gave a {}x{} Jacobian", j.nrows(), j.ncols()),
                reason: format!("{} times and {m} parameters", self.times.len()),
            });
        }
        check_finite("model Jacobian entry", j.as_slice())?;
        Ok((j, differenced))
    }

    /// `(y − h(θ, t))/σ`.
    fn whitened_residuals<M: CurveModel + ?Sized>(
        &self,
        model: &M,
        theta: &[f64],
    ) -> Result<DVector<f64>, Error> {
        let h = self.model_values(model, theta)?;
        Ok(DVector::from_iterator(
            h.len(),
            h.iter()
                .zip(self.values)
                .zip(&self.inverse_sigmas)
                .map(|((h, y), w)| (y - h) * w),
        ))
    }

    /// `diag(1/σ) J`.
    fn whiten(&self, mut j: DMatrix<f64>) -> DMatrix<f64> {
        for (mut row, w) in j.row_iter_mut().zip(&self.inverse_sigmas) {
            row *= *w;
        }
        j
    }
}

/// The least-squares problem the optimiser sees: whitened residuals `(h − y)/σ` and their
/// Jacobian; the first model error is kept to be returned as it is.
struct Problem<'a, M: CurveModel + ?Sized> {
    model: &'a M,
    samples: &'a Samples<'a>,
    theta: DVector<f64>,
    error: RefCell<Option<Error>>,
}

impl<M: CurveModel + ?Sized> Problem<'_, M> {
    fn keep<T>(&self, r: Result<T, Error>) -> Option<T> {
        r.map_err(|e| {
            let mut slot = self.error.borrow_mut();
            if slot.is_none() {
                *slot = Some(e);
            }
        })
        .ok()
    }
}

impl<M: CurveModel + ?Sized> LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_, M> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.theta.copy_from(x);
    }

    fn params(&self) -> DVector<f64> {
        self.theta.clone()
    }

    /// `(h − y)/σ`: the optimiser's sign, the negated whitened residuals.
    fn residuals(&self) -> Option<DVector<f64>> {
        self.keep(
            self.samples
                .whitened_residuals(self.model, self.theta.as_slice()),
        )
        .map(|r| -r)
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let j = self.keep(
            self.samples
                .model_jacobian(self.model, self.theta.as_slice()),
        )?;
        Some(self.samples.whiten(j))
    }
}

/// The maximum-likelihood estimate of `θ` from samples `(t_k, y_k)` with noise standard
/// deviations `σ_k`, by Levenberg–Marquardt from `start` (V&O eq. 2), with its covariance.
///
/// ```
/// use seqsmooth::estimate::curve::{fit_curve, Curve};
/// // h = θ₀ e^{θ₁ t} + θ₂ t on noiseless samples: the fit is the truth
/// let h = Curve::new(3, |th: &[f64], t| th[0] * (th[1] * t).exp() + th[2] * t);
/// let t: Vec<f64> = (0..50).map(|k| k as f64 / 49.0).collect();
/// let y: Vec<f64> = t.iter().map(|t| (0.8 * t).exp() - 0.5 * t).collect();
/// let fit = fit_curve(&h, &t, &y, &vec![0.05; 50], &[0.5, 0.0, 0.0])?;
/// assert!((fit.parameters[1] - 0.8).abs() < 1e-9 && (fit.parameters[2] + 0.5).abs() < 1e-9);
/// # Ok::<(), seqsmooth::Error>(())
/// ```
pub fn fit_curve<M: CurveModel + ?Sized>(
    model: &M,
    times: &[f64],
    values: &[f64],
    sigmas: &[f64],
    start: &[f64],
) -> Result<CurveFit, Error> {
    let m = model.parameters();
    let samples = Samples::new(times, Some(values), sigmas, m)?;
    check_start(start, m)?;
    let (theta, evaluations) = minimize(model, &samples, start, NEAR)?;
    let (mut finish, mut polish_evaluations) = polish(model, &samples, theta)?;
    let mut evaluations = evaluations + polish_evaluations;
    if finish.solved.explained > NOT_CONVERGED {
        // Gauss–Newton could not finish (a long curved valley): Levenberg–Marquardt to its
        // own limit of 30 ε from there, then the finish again.
        let (theta, more) = minimize(model, &samples, finish.theta.as_slice(), TIGHT)?;
        (finish, polish_evaluations) = polish(model, &samples, theta)?;
        evaluations += more + polish_evaluations;
    }
    let Finish {
        theta,
        chi_squared,
        solved,
    } = finish;
    if solved.explained > NOT_CONVERGED {
        return Err(Error::FitNotConverged {
            evaluations,
            reason: format!(
                "the Gauss-Newton correction is still {:e} of its own sigma",
                solved.explained
            ),
            chi_squared,
        });
    }
    Ok(CurveFit {
        covariance: solved.covariance(),
        chi_squared,
        degrees_of_freedom: solved.degrees_of_freedom,
        condition_number: solved.condition_number,
        correction: solved.explained,
        evaluations,
        parameters: theta,
    })
}

/// Levenberg–Marquardt from `start` to the relative tolerance `tolerance`: the estimate and
/// the evaluations it took, or why it stopped short.
fn minimize<M: CurveModel + ?Sized>(
    model: &M,
    samples: &Samples<'_>,
    start: &[f64],
    tolerance: f64,
) -> Result<(DVector<f64>, usize), Error> {
    let problem = Problem {
        model,
        samples,
        theta: DVector::from_column_slice(start),
        error: RefCell::new(None),
    };
    let (problem, report) = LevenbergMarquardt::new()
        .with_ftol(tolerance)
        .with_xtol(tolerance)
        .minimize(problem);
    if let Some(e) = problem.error.into_inner() {
        return Err(e);
    }
    match report.termination {
        TerminationReason::Converged { .. }
        | TerminationReason::Orthogonal
        | TerminationReason::ResidualsZero => {}
        reason => {
            return Err(Error::FitNotConverged {
                evaluations: report.number_of_evaluations,
                reason: match reason {
                    TerminationReason::LostPatience => {
                        "the evaluations allowed ran out".to_string()
                    }
                    TerminationReason::NoImprovementPossible(what) => {
                        format!("no step improves {what} at the double precision")
                    }
                    TerminationReason::Numerical(what) => {
                        format!("{what} is not finite")
                    }
                    other => format!("{other:?}"),
                },
                chi_squared: 2.0 * report.objective_function,
            })
        }
    }
    check_finite("estimated parameter", problem.theta.as_slice())?;
    Ok((problem.theta, report.number_of_evaluations))
}

/// The estimate after the Gauss–Newton finish, its residuals and last linearisation.
struct Finish {
    theta: DVector<f64>,
    chi_squared: f64,
    solved: Solved,
}

/// Gauss–Newton steps from `theta` until the correction is at most [`CONVERGED`] of its own σ
/// (at most [`POLISH`] of them; near the minimum each squares it), and the evaluations made.
/// Each linearisation is factored once; the steps skip the rank check, the last one, whose
/// covariance is reported, has it.
fn polish<M: CurveModel + ?Sized>(
    model: &M,
    samples: &Samples<'_>,
    mut theta: DVector<f64>,
) -> Result<(Finish, usize), Error> {
    let mut evaluations = 0;
    let mut step = 0;
    loop {
        let residuals = samples.whitened_residuals(model, theta.as_slice())?;
        let chi_squared = residuals.norm_squared();
        let (j, differenced) = samples.jacobian_and_kind(model, theta.as_slice())?;
        let factored = Factored::new(samples.whiten(j), residuals);
        evaluations += 1;
        let proposed = if step < POLISH {
            factored
                .step()
                .filter(|(_, c)| *c > CONVERGED)
                .map(|(x, c)| (&theta + x, c))
                .filter(|(candidate, c)| {
                    // A correction within LINEAR of its σ is taken as it is (the
                    // linearisation holds there, and e(θ) changes by c² only, below the
                    // rounding of a sum of many squares); a larger one only if it lowers e(θ).
                    candidate.iter().all(|v| v.is_finite())
                        && (*c <= LINEAR
                            || samples
                                .whitened_residuals(model, candidate.as_slice())
                                .is_ok_and(|r| r.norm_squared() < chi_squared))
                })
        } else {
            None
        };
        match proposed {
            Some((candidate, _)) => {
                theta = candidate;
                step += 1;
            }
            None => {
                let floor = if differenced { DIFFERENCED_RANK } else { 0.0 };
                return Ok((
                    Finish {
                        theta,
                        chi_squared,
                        solved: factored.solve(floor)?,
                    },
                    evaluations,
                ));
            }
        }
    }
}

/// The Levenberg–Marquardt stage's relative tolerances (reduction of `e`, step): it brings
/// the estimate near the minimum; the Gauss–Newton steps after it finish in σ units.
const NEAR: f64 = 1e-10;
/// Converged: the Gauss–Newton correction `sqrt(δᵀ F δ)` at most this.
const CONVERGED: f64 = 1e-9;
/// A correction this small (in its own σ) is taken without checking that it lowers `e(θ)`.
const LINEAR: f64 = 1e-3;
/// Gauss–Newton steps allowed after Levenberg–Marquardt.
const POLISH: usize = 8;
/// A correction above this at the end is refused: the estimate is not known to be within a
/// thousandth of its σ of the minimum. (Between `CONVERGED` and this, rounding or a long
/// curved valley stopped the finish; [`CurveFit::correction`] says how far it got.)
const NOT_CONVERGED: f64 = 1e-3;
/// Levenberg–Marquardt's own limit, `30 ε`, when the finish from `NEAR` fails.
const TIGHT: f64 = 30.0 * f64::EPSILON;

/// The Cramér–Rao bound `F(θ)⁻¹`, `F = Σ_k ∇h(θ, t_k) ∇h(θ, t_k)ᵀ/σ_k²`: the least covariance
/// of an unbiased estimate of `θ` from samples at `times` with noise `sigmas`.
///
/// ```
/// use seqsmooth::estimate::curve::{cramer_rao_bound, Curve};
/// // the mean of n samples of σ = 2: variance 4/n
/// let mean = Curve::new(1, |th: &[f64], _t| th[0]);
/// let b = cramer_rao_bound(&mean, &[0.0], &[0.0, 1.0, 2.0, 3.0], &[2.0; 4])?;
/// assert!((b[(0, 0)] - 1.0).abs() < 1e-12);
/// # Ok::<(), seqsmooth::Error>(())
/// ```
pub fn cramer_rao_bound<M: CurveModel + ?Sized>(
    model: &M,
    theta: &[f64],
    times: &[f64],
    sigmas: &[f64],
) -> Result<DMatrix<f64>, Error> {
    let m = model.parameters();
    let samples = Samples::new(times, None, sigmas, m)?;
    check_start(theta, m)?;
    let (j, differenced) = samples.jacobian_and_kind(model, theta)?;
    let rows = j.nrows();
    let floor = if differenced { DIFFERENCED_RANK } else { 0.0 };
    Ok(Factored::new(samples.whiten(j), DVector::zeros(rows))
        .solve(floor)?
        .covariance())
}

/// The smallest singular value, relative to the largest, that a differenced Jacobian
/// resolves: central differences are accurate to about `ε^{2/3} ≈ 4e-11` of the largest, so a
/// direction they resolve no better is undetermined, not merely ill-conditioned (the QR's own
/// rank rule works at `ε`).
const DIFFERENCED_RANK: f64 = 1e-8;

fn check_start(theta: &[f64], m: usize) -> Result<(), Error> {
    if theta.len() != m {
        return Err(Error::InvalidParameter {
            name: Param::Parameters,
            value: format!("{} of them", theta.len()),
            reason: format!("the model has {m}"),
        });
    }
    check_finite("parameter", theta)
}
