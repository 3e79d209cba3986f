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

use super::batch::solve_whitened;
use crate::error::{Error, Param};
use crate::model::dynamics::Dynamics;
pub use crate::model::measurement::{Measurement, NoiseCovariance};
use crate::model::observation::Observation;
use crate::numeric::unrolled::unrolled_sizes;
use nalgebra::{Cholesky, DMatrix, DMatrixViewMut, DVector, DVectorViewMut, Dyn};

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

/// How one measurement's present components are whitened: `R_k = L Lᵀ` on those rows.
#[derive(Clone, Debug)]
struct Rows {
    time: f64,
    present: Vec<usize>,
    values: Vec<f64>,
    whiten: Whiten,
}

#[derive(Clone, Debug)]
enum Whiten {
    Scale(Vec<f64>),
    Factor(Cholesky<f64, Dyn>),
}

impl Whiten {
    fn apply_vector(&self, v: &mut DVectorViewMut<f64>) {
        match self {
            Whiten::Scale(s) => v.iter_mut().zip(s).for_each(|(x, s)| *x *= s),
            Whiten::Factor(c) => {
                let _ = c.l_dirty().solve_lower_triangular_mut(v);
            }
        }
    }

    fn apply_matrix(&self, m: &mut DMatrixViewMut<f64>) {
        match self {
            Whiten::Scale(s) => {
                for (r, s) in s.iter().enumerate() {
                    m.row_mut(r).scale_mut(*s);
                }
            }
            Whiten::Factor(c) => {
                let _ = c.l_dirty().solve_lower_triangular_mut(m);
            }
        }
    }
}

/// The whitened linear system at one nominal state.
struct Linearised {
    t: DMatrix<f64>,
    r: DVector<f64>,
    chi_squared: f64,
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
        let rows = prepare(observation, measurements)?;
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
            rows.iter().map(|r| r.present.len()).sum::<usize>() + prior.as_ref().map_or(0, |_| n);
        if used < n {
            return Err(Error::TooFewSamples {
                needed: n,
                got: used,
            });
        }

        let mut layout = Layout::new(&rows, t_c, prior.as_ref().map_or(0, |_| n));
        if dynamics.is_linear() {
            layout = layout.with_transitions(dynamics, &rows, t_c, nominal)?;
        }
        let mut x = nominal.clone();
        let mut lin = linearise(
            dynamics,
            observation,
            &rows,
            &layout,
            t_c,
            &x,
            prior.as_ref(),
        )?;
        let mut iterations = Vec::new();
        for iteration in 1..=self.max_iterations {
            let Linearised { t, r, chi_squared } = lin;
            let solution = solve_whitened(t, r)?;
            let dx = &solution.x;
            // |T δX| = sqrt(δXᵀ S⁻¹ δX), the correction in its own σ.
            let correction = solution.explained;
            if correction <= self.tolerance {
                x += dx;
                let covariance = solution.covariance();
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
            let lin_chi_squared = chi_squared;
            let slack = 1e-10 * lin_chi_squared.max(1.0);
            let mut step = 1.0;
            let mut accepted = None;
            for _ in 0..=self.max_halvings {
                let candidate = &x + dx * step;
                if let Ok(next) = linearise(
                    dynamics,
                    observation,
                    &rows,
                    &layout,
                    t_c,
                    &candidate,
                    prior.as_ref(),
                ) {
                    if next.chi_squared <= lin_chi_squared + slack {
                        accepted = Some((candidate, next));
                        break;
                    }
                }
                step *= 0.5;
            }
            let Some((candidate, next)) = accepted else {
                return Err(Error::Diverged {
                    iteration,
                    chi_squared: lin_chi_squared,
                    halvings: self.max_halvings,
                });
            };
            iterations.push(Iteration {
                state: candidate.clone(),
                correction,
                step,
                chi_squared: next.chi_squared,
            });
            x = candidate;
            lin = next;
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

/// Checks every measurement and builds its whitening of the present components.
fn prepare<O: Observation>(
    observation: &O,
    measurements: &[Measurement],
) -> Result<Vec<Rows>, Error> {
    let p = observation.components();
    measurements
        .iter()
        .enumerate()
        .map(|(index, m)| {
            prepare_one(p, m).map_err(|source| Error::InBatch {
                index,
                source: Box::new(source),
            })
        })
        .collect()
}

fn prepare_one(p: usize, m: &Measurement) -> Result<Rows, Error> {
    let (present, values) = m.present(p)?;
    let bad = |value: String, reason: &str| Error::InvalidParameter {
        name: Param::MeasurementNoise,
        value,
        reason: reason.into(),
    };
    let whiten = match &m.noise {
        NoiseCovariance::Identity => Whiten::Scale(vec![1.0; present.len()]),
        NoiseCovariance::Variances(v) => {
            if v.len() != p {
                return Err(bad(
                    format!("{} variances", v.len()),
                    &format!("need {p}, one per component"),
                ));
            }
            let mut scale = Vec::with_capacity(present.len());
            for &k in &present {
                if !(v[k].is_finite() && v[k] > 0.0) {
                    return Err(bad(
                        format!("variance {}", v[k]),
                        "must be positive and finite",
                    ));
                }
                scale.push(1.0 / v[k].sqrt());
            }
            Whiten::Scale(scale)
        }
        NoiseCovariance::Full(r) => {
            if r.shape() != (p, p) {
                return Err(bad(
                    format!("{}x{}", r.nrows(), r.ncols()),
                    &format!("must be {p}x{p}"),
                ));
            }
            if r.iter().any(|v| !v.is_finite())
                || (r - r.transpose()).abs().max() > 1e-12 * r.abs().max()
            {
                return Err(bad(format!("{r:?}"), "must be finite and symmetric"));
            }
            let sub = DMatrix::from_fn(present.len(), present.len(), |i, j| {
                r[(present[i], present[j])]
            });
            match Cholesky::new(sub) {
                Some(c) => Whiten::Factor(c),
                None if present.is_empty() => Whiten::Scale(Vec::new()),
                None => return Err(bad(format!("{r:?}"), "must be positive definite")),
            }
        }
    };
    Ok(Rows {
        time: m.time,
        present,
        values,
        whiten,
    })
}

/// The prior's whitening `S_p = L Lᵀ` and state.
struct PriorRows {
    state: DVector<f64>,
    factor: Cholesky<f64, Dyn>,
}

fn prepare_prior(p: &Prior, n: usize) -> Result<PriorRows, Error> {
    let bad = |value: String, reason: &str| Error::InvalidParameter {
        name: Param::Prior,
        value,
        reason: reason.into(),
    };
    if p.state.len() != n || p.covariance.shape() != (n, n) {
        return Err(bad(
            format!(
                "state of length {}, covariance {}x{}",
                p.state.len(),
                p.covariance.nrows(),
                p.covariance.ncols()
            ),
            &format!("the model has {n} states"),
        ));
    }
    if let Some(&value) = p
        .state
        .iter()
        .chain(p.covariance.iter())
        .find(|v| !v.is_finite())
    {
        return Err(Error::NonFinite {
            what: "prior entry",
            value,
        });
    }
    let c = &p.covariance;
    if (c - c.transpose()).abs().max() > 1e-12 * c.abs().max() {
        return Err(bad(format!("{c:?}"), "the covariance must be symmetric"));
    }
    let factor = Cholesky::new(c.clone())
        .ok_or_else(|| bad(format!("{c:?}"), "the covariance must be positive definite"))?;
    Ok(PriorRows {
        state: p.state.clone(),
        factor,
    })
}

/// The order the trajectory is carried in, fixed by the times and the epoch: each
/// measurement's first row of `T`, the measurements at or after `t_c` by increasing time, those
/// before it by decreasing time, and the rows in all.
struct Layout {
    offsets: Vec<usize>,
    after: Vec<usize>,
    before: Vec<usize>,
    total: usize,
    /// `Φ(t_k, t_c)` of each row, once per fit, for dynamics whose `Φ` does not depend on the
    /// state ([`Dynamics::is_linear`]).
    transitions: Option<Vec<DMatrix<f64>>>,
}

impl Layout {
    fn new(rows: &[Rows], t_c: f64, prior_states: usize) -> Self {
        let mut offsets = Vec::with_capacity(rows.len());
        let mut at = 0;
        for row in rows {
            offsets.push(at);
            at += row.present.len();
        }
        let mut order: Vec<usize> = (0..rows.len()).collect();
        order.sort_by(|&a, &b| rows[a].time.total_cmp(&rows[b].time));
        let split = order.partition_point(|&k| rows[k].time < t_c);
        let after = order.split_off(split);
        order.reverse();
        Self {
            offsets,
            after,
            before: order,
            total: at + prior_states,
            transitions: None,
        }
    }

    /// With each row's `Φ(t_k, t_c)`, carried from `t_c` directly (any state will do).
    fn with_transitions<D: Dynamics>(
        mut self,
        dynamics: &D,
        rows: &[Rows],
        t_c: f64,
        x: &DVector<f64>,
    ) -> Result<Self, Error> {
        let n = x.len();
        let mut state = DVector::zeros(n);
        let mut all = Vec::with_capacity(rows.len());
        for row in rows {
            let mut phi = DMatrix::zeros(n, n);
            dynamics.propagate_into(x, t_c, row.time, &mut state, &mut phi)?;
            all.push(phi);
        }
        self.transitions = Some(all);
        Ok(self)
    }
}

/// `out = a b` for the small `Φ` and `M Φ` products: nalgebra's product of dynamically sized
/// matrices goes through a general blocked multiplication whose set-up costs more than a 6 × 6
/// product (it was 30 % of a radar fit's instructions), so the inner size `n` (the state
/// dimension) goes through the crate's one unrolled-size dispatch.
fn product_into(a: &DMatrix<f64>, b: &DMatrix<f64>, out: &mut DMatrix<f64>) {
    let (rows, inner) = a.shape();
    debug_assert_eq!(
        (b.nrows(), out.nrows(), out.ncols()),
        (inner, rows, b.ncols())
    );
    product_slices(rows, inner, a.as_slice(), b.as_slice(), out.as_mut_slice());
}

/// `out = a x` ([`product_into`] for a vector).
fn product_vector_into(a: &DMatrix<f64>, x: &DVector<f64>, out: &mut DVector<f64>) {
    let (rows, inner) = a.shape();
    debug_assert_eq!((x.len(), out.len()), (inner, rows));
    product_slices(rows, inner, a.as_slice(), x.as_slice(), out.as_mut_slice());
}

/// The column-major product of `a` (`rows × inner`) and `b` (`inner × out.len()/rows`).
fn product_slices(rows: usize, inner: usize, a: &[f64], b: &[f64], out: &mut [f64]) {
    unrolled_sizes!(inner, N => product_n::<N>(rows, a, b, out), n => product_any(rows, n, a, b, out));
}

/// [`product_into`] for an inner size `N` known at compile time (column-major slices).
fn product_n<const N: usize>(rows: usize, a: &[f64], b: &[f64], out: &mut [f64]) {
    for (o, b) in out.chunks_exact_mut(rows).zip(b.chunks_exact(N)) {
        let b: &[f64; N] = b.try_into().expect("a column of N");
        for (i, o) in o.iter_mut().enumerate() {
            let mut sum = 0.0;
            for (l, &w) in b.iter().enumerate() {
                sum += a[i + l * rows] * w;
            }
            *o = sum;
        }
    }
}

/// [`product_into`] for any inner size `n`.
fn product_any(rows: usize, n: usize, a: &[f64], b: &[f64], out: &mut [f64]) {
    for (o, b) in out.chunks_exact_mut(rows).zip(b.chunks_exact(n)) {
        for (i, o) in o.iter_mut().enumerate() {
            *o = b
                .iter()
                .enumerate()
                .map(|(l, &w)| a[i + l * rows] * w)
                .sum();
        }
    }
}

/// Writes one observation's present rows, `M Φ` and the residuals, whitened, at `at`.
fn write_rows<O: Observation>(
    observation: &O,
    row: &Rows,
    at: usize,
    m: &DMatrix<f64>,
    value: &DVector<f64>,
    t: &mut DMatrix<f64>,
    r: &mut DVector<f64>,
) {
    let (count, n) = (row.present.len(), m.ncols());
    for (i, &c) in row.present.iter().enumerate() {
        t.row_mut(at + i).copy_from(&m.row(c));
        r[at + i] = observation.residual(c, row.values[i], value[c]);
    }
    row.whiten
        .apply_matrix(&mut t.view_mut((at, 0), (count, n)));
    row.whiten.apply_vector(&mut r.rows_mut(at, count));
}

/// `T` and `δY` whitened, and `e(X̄)`, at the nominal `x` (state at `t_c`): the trajectory is
/// carried outwards from `t_c` through the sorted times, `Φ(t_k, t_c) = Φ(t_k, t_{k∓1}) Φ(t_{k∓1}, t_c)`.
fn linearise<D: Dynamics, O: Observation>(
    dynamics: &D,
    observation: &O,
    rows: &[Rows],
    layout: &Layout,
    t_c: f64,
    x: &DVector<f64>,
    prior: Option<&PriorRows>,
) -> Result<Linearised, Error> {
    let n = x.len();
    let mut t = DMatrix::zeros(layout.total, n);
    let mut r = DVector::zeros(layout.total);
    let p = observation.components();
    let mut carried = DMatrix::<f64>::zeros(n, n);
    let mut m = DMatrix::<f64>::zeros(p, n);
    let (mut step, mut next) = (DMatrix::<f64>::zeros(n, n), DVector::<f64>::zeros(n));
    let (mut value, mut jacobian) = (DVector::<f64>::zeros(p), DMatrix::<f64>::zeros(p, n));
    if let Some(transitions) = &layout.transitions {
        for (k, (row, phi)) in rows.iter().zip(transitions).enumerate() {
            let count = row.present.len();
            if count == 0 {
                continue;
            }
            product_vector_into(phi, x, &mut next);
            observation.predict_into(&next, row.time, &mut value, &mut jacobian)?;
            product_into(&jacobian, phi, &mut m);
            write_rows(
                observation,
                row,
                layout.offsets[k],
                &m,
                &value,
                &mut t,
                &mut r,
            );
        }
    }
    let sides = match layout.transitions {
        Some(_) => [&[][..], &[][..]],
        None => [&layout.after[..], &layout.before[..]],
    };
    for side in sides {
        let mut state = x.clone();
        let mut phi = DMatrix::<f64>::identity(n, n);
        let mut time = t_c;
        for &k in side {
            let row = &rows[k];
            if row.time != time {
                dynamics.propagate_into(&state, time, row.time, &mut next, &mut step)?;
                product_into(&step, &phi, &mut carried);
                std::mem::swap(&mut phi, &mut carried);
                std::mem::swap(&mut state, &mut next);
                time = row.time;
            }
            let count = row.present.len();
            if count == 0 {
                continue;
            }
            observation.predict_into(&state, row.time, &mut value, &mut jacobian)?;
            product_into(&jacobian, &phi, &mut m);
            write_rows(
                observation,
                row,
                layout.offsets[k],
                &m,
                &value,
                &mut t,
                &mut r,
            );
        }
    }
    if let Some(p) = prior {
        let at = layout.total - n;
        let mut block = DMatrix::identity(n, n);
        let mut residual = &p.state - x;
        let l = p.factor.l_dirty();
        let _ = l.solve_lower_triangular_mut(&mut block);
        let _ = l.solve_lower_triangular_mut(&mut residual);
        t.view_mut((at, 0), (n, n)).copy_from(&block);
        r.rows_mut(at, n).copy_from(&residual);
    }
    let chi_squared = r.norm_squared();
    if !chi_squared.is_finite() || t.iter().any(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            what: "linearised observation system",
            value: chi_squared,
        });
    }
    Ok(Linearised { t, r, chi_squared })
}
