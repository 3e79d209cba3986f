//! Differential correction over a sliding window (Morrison §8.7, the fixed-memory form of
//! [`super::gauss_newton`]): after each measurement, the Gauss–Newton fit of the last `W`
//! measurements (all of them while fewer have come).
//!
//! Each window's iteration starts from the previous window's estimate carried to the new epoch
//! by the dynamics (one or two iterations where the windows overlap), or, for the first window
//! and whenever that start fails, from the rule the caller chose: the radar nominal of §8.5
//! ([`super::bootstrap::radar`]) or a given state (for a linear model any start converges in
//! one correction). The converged estimate does not depend on the start beyond the tolerance.

use super::bootstrap;
use super::gauss_newton::{Correction, Epoch, GaussNewton, Measurement};
use crate::error::{Error, Param};
use crate::model::dynamics::{Dynamics, PolynomialDynamics};
use crate::model::measurement::NoiseCovariance;
use crate::model::observation::{LinearObservation, Observation};
use crate::model::radar::Radar;
use nalgebra::DVector;
use std::collections::VecDeque;

/// The rows of a radar fit's window when none is given (`seqsmooth fit --model radar`,
/// `seqsmooth track --method window`): short enough that a constant-velocity window fits an
/// airliner's approach at 2.7 s steps most of the time (ACCURACY.md, "The tracker's
/// coverage"); a window that does not fit is flagged and its covariance carries the misfit.
pub const RADAR_WINDOW: usize = 8;

/// The rows of a polynomial fit's window when none is given (`seqsmooth fit --model
/// polynomial`).
pub const POLYNOMIAL_WINDOW: usize = 60;

/// The range of a window's length in samples (rows), whatever the model: at least one, the
/// rule every window of the command and of Python shares before the model's own (a
/// fixed-memory fit's `m + 1`, [`crate::polynomial::fixed::check_window`]; a radar track's 2).
///
/// ```
/// use seqsmooth::estimate::sliding::check_window_length;
/// assert!(check_window_length(1).is_ok() && check_window_length(0).is_err());
/// ```
pub fn check_window_length(window: usize) -> Result<(), Error> {
    if window == 0 {
        return Err(Error::InvalidParameter {
            name: Param::Window,
            value: "0".into(),
            reason: "must hold at least 1 sample".into(),
        });
    }
    Ok(())
}

/// Where a window's iteration starts when there is no previous estimate to carry forward.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Start {
    /// The nominal state of §8.5 from polynomial fits of this degree (at most one less than
    /// the window's complete measurements) to the radar's range, azimuth and elevation.
    Radar {
        /// The radar the measurements are from.
        radar: Radar,
        /// The degree of the fits (1 or more).
        degree: usize,
    },
    /// This state at the epoch.
    State(DVector<f64>),
}

/// The start rule's range for a model of `n` states: a state of `n` finite entries, or the
/// radar's nominal of degree 1 or more for `n` states.
fn check_start(start: &Start, n: usize) -> Result<(), Error> {
    match start {
        Start::State(x) if x.len() != n || x.iter().any(|v| !v.is_finite()) => {
            Err(Error::InvalidParameter {
                name: Param::StartState,
                value: format!("{:?}", x.as_slice()),
                reason: format!("must have {n} finite entries"),
            })
        }
        Start::Radar { radar, degree } if radar.state_dimension() != n || *degree == 0 => {
            Err(Error::InvalidParameter {
                name: Param::RadarStart,
                value: format!("degree {degree} for {} states", radar.state_dimension()),
                reason: format!("needs degree 1 or more and the model's {n} states"),
            })
        }
        _ => Ok(()),
    }
}

/// A Gauss–Newton fit of the last `W` measurements, renewed at each one.
///
/// ```
/// use nalgebra::DVector;
/// use seqsmooth::model::measurement::NoiseCovariance;
/// use seqsmooth::estimate::gauss_newton::{Epoch, Measurement};
/// use seqsmooth::estimate::sliding::{SlidingFit, Start};
/// use seqsmooth::model::dynamics::PolynomialDynamics;
/// use seqsmooth::model::observation::LinearObservation;
/// // A straight line, 3 samples a window.
/// let mut fit = SlidingFit::new(
///     PolynomialDynamics::new(1, 1),
///     LinearObservation::value_of(2),
///     3,
///     Epoch::End,
///     Start::State(DVector::zeros(2)),
/// )
/// .unwrap();
/// let mut last = None;
/// for (t, y) in [(0.0, 1.0), (1.0, 3.0), (2.0, 5.0), (3.0, 7.5)] {
///     let m = Measurement { time: t, values: vec![Some(y)], noise: NoiseCovariance::Variances(vec![1.0]) };
///     last = fit.push(m).unwrap();
/// }
/// let c = last.unwrap(); // the line through (1, 3), (2, 5), (3, 7.5)
/// assert!((c.state[1] - 2.25).abs() < 1e-12);
/// ```
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct SlidingFit<D: Dynamics, O: Observation> {
    dynamics: D,
    observation: O,
    solver: GaussNewton,
    window: usize,
    epoch: Epoch,
    start: Start,
    rows: VecDeque<Measurement>,
    last: Option<Correction>,
    /// Whether each fit's covariance carries its misfit ([`misfit_scale`]).
    scaled: bool,
}

/// The factor `max(1, χ²/ν)` by which a fit's covariance is scaled to carry its misfit: the
/// residual χ² of a window that fits has mean `ν`, its degrees of freedom (§8.6), and a
/// residual variance `χ²/ν` times the noise's says the noise alone does not explain the
/// residuals — a model that does not follow the data over the window (Morrison §7.13), whose
/// error the scaled covariance takes in; 1 with `ν = 0`.
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::estimate::gauss_newton::Correction;
/// use seqsmooth::estimate::sliding::misfit_scale;
/// let c = Correction { epoch: 0.0, state: DVector::zeros(1), covariance: DMatrix::identity(1, 1),
///     chi_squared: 40.0, degrees_of_freedom: 10, condition_number: 1.0, iterations: vec![] };
/// assert_eq!(misfit_scale(&c), 4.0);
/// assert_eq!(misfit_scale(&Correction { chi_squared: 5.0, ..c }), 1.0);
/// ```
pub fn misfit_scale(c: &Correction) -> f64 {
    if c.degrees_of_freedom == 0 {
        return 1.0;
    }
    (c.chi_squared / c.degrees_of_freedom as f64).max(1.0)
}

impl<D: Dynamics, O: Observation> SlidingFit<D, O> {
    /// The fit of the last `window ≥ 1` measurements at `epoch`, started by `start`, with
    /// [`GaussNewton::default`] limits.
    ///
    /// ```
    /// use nalgebra::DVector;
    /// use seqsmooth::estimate::gauss_newton::Epoch;
    /// use seqsmooth::estimate::sliding::{SlidingFit, Start};
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let bad = SlidingFit::new(
    ///     PolynomialDynamics::new(1, 1),
    ///     LinearObservation::value_of(2),
    ///     0,
    ///     Epoch::End,
    ///     Start::State(DVector::zeros(2)),
    /// );
    /// assert!(bad.is_err());
    /// ```
    pub fn new(
        dynamics: D,
        observation: O,
        window: usize,
        epoch: Epoch,
        start: Start,
    ) -> Result<Self, Error> {
        let n = dynamics.dimension();
        check_window_length(window)?;
        if observation.state_dimension() != n {
            return Err(Error::InvalidParameter {
                name: Param::ObservationModel,
                value: format!("for {} states", observation.state_dimension()),
                reason: format!("the dynamics have {n} states"),
            });
        }
        check_start(&start, n)?;
        epoch.check()?;
        Ok(Self {
            dynamics,
            observation,
            solver: GaussNewton::default(),
            window,
            epoch,
            start,
            rows: VecDeque::with_capacity(window.min(1 << 12)),
            last: None,
            scaled: false,
        })
    }

    /// With these iteration limits.
    ///
    /// ```
    /// use nalgebra::DVector;
    /// use seqsmooth::estimate::gauss_newton::{Epoch, GaussNewton};
    /// use seqsmooth::estimate::sliding::{SlidingFit, Start};
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let fit = SlidingFit::new(
    ///     PolynomialDynamics::new(0, 1),
    ///     LinearObservation::value_of(1),
    ///     5,
    ///     Epoch::End,
    ///     Start::State(DVector::zeros(1)),
    /// )
    /// .unwrap()
    /// .with_solver(GaussNewton { max_iterations: 10, ..GaussNewton::default() });
    /// assert_eq!(fit.window(), 5);
    /// ```
    pub fn with_solver(mut self, solver: GaussNewton) -> Self {
        self.solver = solver;
        self
    }

    /// With each fit's covariance scaled by [`misfit_scale`] (the radar fits').
    ///
    /// ```
    /// use seqsmooth::estimate::gauss_newton::{Epoch, GaussNewton};
    /// use seqsmooth::estimate::sliding::SlidingFit;
    /// let fit = SlidingFit::polynomial(1, 3, Epoch::End, GaussNewton::default()).unwrap();
    /// assert_eq!(fit.with_misfit_scale().window(), 3);
    /// ```
    pub fn with_misfit_scale(mut self) -> Self {
        self.scaled = true;
        self
    }

    /// The window length `W`.
    ///
    /// ```
    /// use nalgebra::DVector;
    /// use seqsmooth::estimate::gauss_newton::Epoch;
    /// use seqsmooth::estimate::sliding::{SlidingFit, Start};
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let fit = SlidingFit::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1), 7,
    ///     Epoch::End, Start::State(DVector::zeros(1))).unwrap();
    /// assert_eq!(fit.window(), 7);
    /// ```
    pub fn window(&self) -> usize {
        self.window
    }

    /// The epoch each fit's state refers to.
    ///
    /// ```
    /// use seqsmooth::estimate::gauss_newton::{Epoch, GaussNewton};
    /// use seqsmooth::estimate::sliding::SlidingFit;
    /// let fit = SlidingFit::polynomial(1, 3, Epoch::End, GaussNewton::default()).unwrap();
    /// assert_eq!(fit.epoch(), Epoch::End);
    /// ```
    pub fn epoch(&self) -> Epoch {
        self.epoch
    }

    /// The dynamic and observation models.
    ///
    /// ```
    /// use seqsmooth::estimate::gauss_newton::{Epoch, GaussNewton};
    /// use seqsmooth::estimate::sliding::SlidingFit;
    /// use seqsmooth::model::dynamics::Dynamics;
    /// let fit = SlidingFit::polynomial(2, 5, Epoch::End, GaussNewton::default()).unwrap();
    /// assert_eq!(fit.models().0.dimension(), 3);
    /// ```
    pub fn models(&self) -> (&D, &O) {
        (&self.dynamics, &self.observation)
    }

    /// A restored fit's invariants ([`crate::persist`]): the window, epoch, start and limits
    /// in the constructors' ranges; at most `W` measurements in the window, at finite
    /// increasing times, each of the observation's components (finite where present) and its
    /// noise of them (variances positive and finite, a full `R` symmetric positive
    /// semi-definite); the last fit's state and covariance of the model's dimension.
    pub(crate) fn check_saved(&self) -> Result<(), String> {
        use crate::linalg::invariant::{covariance, finite, vector};
        let text = |e: Error| e.to_string();
        let (n, p) = (self.dynamics.dimension(), self.observation.components());
        check_window_length(self.window).map_err(text)?;
        self.epoch.check().map_err(text)?;
        check_start(&self.start, n).map_err(text)?;
        let GaussNewton {
            max_iterations,
            tolerance,
            max_halvings,
        } = self.solver;
        super::gauss_newton::check_max_iterations(max_iterations).map_err(text)?;
        if !(tolerance.is_finite() && tolerance > 0.0) || max_halvings > 64 {
            return Err(format!(
                "limits: tolerance {tolerance}, {max_halvings} halvings"
            ));
        }
        if self.observation.state_dimension() != n || self.rows.len() > self.window {
            return Err(format!(
                "window of {} rows over {}",
                self.rows.len(),
                self.window
            ));
        }
        let mut previous = f64::NEG_INFINITY;
        for m in &self.rows {
            if !(m.time.is_finite() && m.time > previous) || m.values.len() != p {
                return Err(format!("measurement at {} out of order or shape", m.time));
            }
            previous = m.time;
            finite(
                &m.values.iter().flatten().copied().collect::<Vec<_>>(),
                "value",
            )?;
            match &m.noise {
                NoiseCovariance::Identity => {}
                NoiseCovariance::Variances(v) if v.len() == p => {
                    if v.iter().any(|&v| !(v.is_finite() && v > 0.0)) {
                        return Err(format!("noise variances {v:?}"));
                    }
                }
                NoiseCovariance::Full(r) => covariance(r, p, "measurement noise")?,
                NoiseCovariance::Variances(v) => {
                    return Err(format!("{} noise variances for {p} components", v.len()))
                }
            }
        }
        if let Some(c) = &self.last {
            vector(&c.state, n, "last fit's state")?;
            covariance(&c.covariance, n, "last fit's covariance")?;
        }
        Ok(())
    }

    /// The measurements in the window, oldest first.
    ///
    /// ```
    /// use nalgebra::DVector;
    /// use seqsmooth::model::measurement::NoiseCovariance;
    /// use seqsmooth::estimate::gauss_newton::{Epoch, Measurement};
    /// use seqsmooth::estimate::sliding::{SlidingFit, Start};
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let mut fit = SlidingFit::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1), 2,
    ///     Epoch::End, Start::State(DVector::zeros(1))).unwrap();
    /// for t in 0..3 {
    ///     let m = Measurement { time: t as f64, values: vec![Some(1.0)], noise: NoiseCovariance::Identity };
    ///     fit.push(m).unwrap();
    /// }
    /// assert_eq!(fit.measurements().map(|m| m.time).collect::<Vec<_>>(), vec![1.0, 2.0]);
    /// ```
    pub fn measurements(&self) -> impl Iterator<Item = &Measurement> {
        self.rows.iter()
    }

    /// As [`SlidingFit::push`], and an estimate whose state or 1-σ errors
    /// `sqrt(S*_{k,k})` are not all finite (beyond the double range: epoch-sized times in a
    /// small unit, or huge values) is refused too, as [`Error::NonFinite`] with `what`
    /// `"fitted state"` and the first such number (state first, then the σ); the fit is then
    /// as before the measurement.
    ///
    /// ```
    /// use seqsmooth::model::measurement::NoiseCovariance;
    /// use seqsmooth::estimate::gauss_newton::{Epoch, GaussNewton, Measurement};
    /// use seqsmooth::estimate::sliding::SlidingFit;
    /// use seqsmooth::{Error, Param};
    /// let mut fit = SlidingFit::polynomial(1, 3, Epoch::End, GaussNewton::default()).unwrap();
    /// let m = |t: f64, y: f64| Measurement { time: t, values: vec![Some(y)], noise: NoiseCovariance::Variances(vec![1.0]) };
    /// assert!(fit.push_finite(m(0.0, 1.0)).unwrap().is_none()); // one value: no line yet
    /// let c = fit.push_finite(m(1.0, 3.0)).unwrap().unwrap();
    /// assert!((c.state[1] - 2.0).abs() < 1e-12);
    /// assert!(matches!(fit.push_finite(m(1.0, 5.0)), Err(Error::InvalidParameter { name: Param::Time, .. })));
    /// assert_eq!(fit.measurements().count(), 2);
    /// ```
    ///
    /// (The refusal of a non-finite estimate is a guard: the windows that would give one,
    /// found so far, already fail as a linearised system or a rank that is not finite.)
    pub fn push_finite(&mut self, measurement: Measurement) -> Result<Option<Correction>, Error> {
        self.push_checked(measurement, |c| {
            let n = c.state.len();
            let sigmas = (0..n).map(|k| c.covariance[(k, k)].sqrt());
            match c
                .state
                .iter()
                .copied()
                .chain(sigmas)
                .find(|v| !v.is_finite())
            {
                Some(value) => Err(Error::NonFinite {
                    what: "fitted state",
                    value,
                }),
                None => Ok(()),
            }
        })
    }

    /// Takes a measurement (after the previous one in time), drops the oldest beyond `W`, and
    /// fits the window.
    ///
    /// `Ok(None)` while the window is not yet full and does not determine the state (too few
    /// components, or [`Error::Unobservable`]); once it holds `W` measurements, a window that
    /// does not determine the state is that error. Any error refuses the measurement: the fit
    /// is then as before it (a measurement that is not after the previous one, malformed, or
    /// that leaves the full window undetermined).
    pub fn push(&mut self, measurement: Measurement) -> Result<Option<Correction>, Error> {
        self.push_checked(measurement, |_| Ok(()))
    }

    /// [`SlidingFit::push`], the estimate also refused where `accept` refuses it.
    fn push_checked(
        &mut self,
        measurement: Measurement,
        accept: impl Fn(&Correction) -> Result<(), Error>,
    ) -> Result<Option<Correction>, Error> {
        if !measurement.time.is_finite() {
            return Err(Error::NonFinite {
                what: "time",
                value: measurement.time,
            });
        }
        if let Some(previous) = self.rows.back() {
            if measurement.time <= previous.time {
                return Err(Error::InvalidParameter {
                    name: Param::Time,
                    value: measurement.time.to_string(),
                    reason: format!(
                        "must be after the previous measurement's time {}",
                        previous.time
                    ),
                });
            }
        }
        let dropped = if self.rows.len() == self.window {
            self.rows.pop_front()
        } else {
            None
        };
        self.rows.push_back(measurement);
        self.rows.make_contiguous();
        let scaled = |mut c: Correction| {
            if self.scaled {
                c.covariance *= misfit_scale(&c);
            }
            c
        };
        match self.fit().map(scaled).and_then(|c| accept(&c).map(|()| c)) {
            Ok(c) => {
                self.last = Some(c.clone());
                Ok(Some(c))
            }
            Err(Error::Unobservable { .. } | Error::TooFewSamples { .. })
                if self.rows.len() < self.window =>
            {
                self.last = None;
                Ok(None)
            }
            Err(e) => {
                self.rows.pop_back();
                if let Some(d) = dropped {
                    self.rows.push_front(d);
                }
                Err(e)
            }
        }
    }

    /// The fit of the window: from the previous estimate carried forward, else (or if that
    /// fails) from the start rule.
    fn fit(&self) -> Result<Correction, Error> {
        let rows = self.rows.as_slices().0;
        let times: Vec<f64> = rows.iter().map(|m| m.time).collect();
        let epoch = self.epoch.time_for(&times);
        let n = self.dynamics.dimension();
        let components: usize = rows.iter().map(|m| m.values.iter().flatten().count()).sum();
        if components < n {
            return Err(Error::TooFewSamples {
                needed: n,
                got: components,
            });
        }
        let solve = |nominal: &DVector<f64>| {
            self.solver.fit(
                &self.dynamics,
                &self.observation,
                rows,
                Epoch::At(epoch),
                nominal,
                None,
            )
        };
        if let Some(last) = &self.last {
            if let Ok(carried) = self.dynamics.propagate(&last.state, last.epoch, epoch) {
                match solve(&carried.state) {
                    Ok(c) => return Ok(c),
                    Err(Error::Diverged { .. } | Error::NotConverged { .. }) => {}
                    Err(e) => return Err(e),
                }
            }
        }
        solve(&self.nominal(rows, epoch)?)
    }

    /// The start rule's nominal state at `epoch`.
    fn nominal(&self, rows: &[Measurement], epoch: f64) -> Result<DVector<f64>, Error> {
        match &self.start {
            Start::State(x) => Ok(x.clone()),
            Start::Radar { radar, degree } => {
                let (times, measured): (Vec<f64>, Vec<[f64; 3]>) = rows
                    .iter()
                    .filter_map(|m| match m.values.as_slice() {
                        [Some(r), Some(a), Some(e), ..] => Some((m.time, [*r, *a, *e])),
                        _ => None,
                    })
                    .unzip();
                if times.len() < 2 {
                    return Err(Error::TooFewSamples {
                        needed: 2,
                        got: times.len(),
                    });
                }
                let degree = (*degree).min(times.len() - 1);
                bootstrap::radar(radar, &times, &measured, epoch, degree)
            }
        }
    }
}

impl SlidingFit<PolynomialDynamics, Radar> {
    /// The radar fit of `seqsmooth fit --model radar`: a Cartesian target of constant velocity
    /// (`degree` 1, state `(x, y, z, vx, vy, vz)`) or constant acceleration (`degree` 2, and
    /// `(ax, ay, az)`), `PolynomialDynamics::new(degree, 3)` (Morrison ch. 4), seen by a
    /// [`Radar`] at `site` (range, azimuth from +x
    /// towards +y, elevation from the x-y plane). The first window's iteration (and any whose
    /// carried-forward start fails) starts from the nominal of §8.5: polynomial fits of degree
    /// `max(2, degree)` (at most one less than the complete rows) to the range and angles,
    /// then Gauss–Newton differential correction (§8.6-8.7) with `solver`'s limits; each
    /// fit's covariance carries its misfit ([`misfit_scale`]).
    ///
    /// Errors: a degree other than 1 or 2, a `window` of 0, a site or an [`Epoch::At`] time
    /// not finite ([`Error::InvalidParameter`], [`Error::NonFinite`]).
    ///
    /// ```
    /// use seqsmooth::estimate::gauss_newton::{Epoch, GaussNewton};
    /// use seqsmooth::estimate::sliding::SlidingFit;
    /// let fit = SlidingFit::radar([0.0; 3], 1, 10, Epoch::End, GaussNewton::default()).unwrap();
    /// assert_eq!(fit.window(), 10);
    /// assert!(SlidingFit::radar([0.0; 3], 3, 10, Epoch::End, GaussNewton::default()).is_err());
    /// ```
    pub fn radar(
        site: [f64; 3],
        degree: usize,
        window: usize,
        epoch: Epoch,
        solver: GaussNewton,
    ) -> Result<Self, Error> {
        if !(1..=2).contains(&degree) {
            return Err(Error::InvalidParameter {
                name: Param::Degree,
                value: degree.to_string(),
                reason: "must be 1 (constant velocity) or 2 (constant acceleration) for the \
                         radar model"
                    .into(),
            });
        }
        let radar = Radar::new(site, 3 * (degree + 1))?;
        Ok(SlidingFit::new(
            PolynomialDynamics::new(degree, 3),
            radar,
            window,
            epoch,
            Start::Radar {
                radar,
                degree: 2.max(degree),
            },
        )?
        .with_solver(solver)
        .with_misfit_scale())
    }
}

impl SlidingFit<PolynomialDynamics, LinearObservation> {
    /// The scalar polynomial fit of `seqsmooth fit --model polynomial`: the state
    /// `(y, y', …, y⁽ᵐ⁾)` of a degree-`m` polynomial in `t` (`PolynomialDynamics::new(m, 1)`,
    /// ch. 4), observed through `M = (1, 0, …, 0)` (8.3.5). The model is linear, so each
    /// window's converged correction is its weighted least-squares fit, `X* = (Tᵀ R⁻¹ T)⁻¹
    /// Tᵀ R⁻¹ Y` with `S* = (Tᵀ R⁻¹ T)⁻¹` at the epoch (§8.6-8.7), whatever the start.
    ///
    /// Errors: a `window` shorter than `degree + 1`, an [`Epoch::At`] time not finite. The
    /// degree is not bounded here (the command and the Python binding bound it by the
    /// polynomial filters' largest degree, `polynomial::check_degree`; beyond ~20 the window's
    /// design is ill-conditioned).
    ///
    /// ```
    /// use seqsmooth::estimate::gauss_newton::{Epoch, GaussNewton};
    /// use seqsmooth::estimate::sliding::SlidingFit;
    /// assert!(SlidingFit::polynomial(2, 3, Epoch::Centre, GaussNewton::default()).is_ok());
    /// assert!(SlidingFit::polynomial(2, 2, Epoch::Centre, GaussNewton::default()).is_err());
    /// ```
    pub fn polynomial(
        degree: usize,
        window: usize,
        epoch: Epoch,
        solver: GaussNewton,
    ) -> Result<Self, Error> {
        if window < degree + 1 {
            return Err(Error::InvalidParameter {
                name: Param::Window,
                value: window.to_string(),
                reason: format!(
                    "too small for degree {degree}: a degree-{degree} fit needs a window of at \
                     least {} rows",
                    degree + 1
                ),
            });
        }
        Ok(SlidingFit::new(
            PolynomialDynamics::new(degree, 1),
            LinearObservation::value_of(degree + 1),
            window,
            epoch,
            Start::State(DVector::zeros(degree + 1)),
        )?
        .with_solver(solver))
    }
}

/// The sliding fit of either model of `seqsmooth fit` and of Python's `SlidingFit`: a radar's
/// Cartesian target ([`SlidingFit::radar`]) or a scalar polynomial
/// ([`SlidingFit::polynomial`]).
///
/// ```
/// use seqsmooth::estimate::batch::NoiseCovariance;
/// use seqsmooth::estimate::gauss_newton::{Epoch, GaussNewton, Measurement};
/// use seqsmooth::estimate::sliding::{Fitter, SlidingFit};
/// let fit = SlidingFit::polynomial(1, 3, Epoch::End, GaussNewton::default())?;
/// let mut fitter = Fitter::Polynomial(fit);
/// let row = |t: f64| Measurement {
///     time: t,
///     values: vec![Some(1.0 + 2.0 * t)],
///     noise: NoiseCovariance::Variances(vec![0.01]),
/// };
/// assert!(fitter.push_finite(row(0.0))?.is_none()); // one row does not determine a line
/// let c = fitter.push_finite(row(1.0))?.unwrap();
/// assert!((c.state[1] - 2.0).abs() < 1e-9);
/// # Ok::<(), seqsmooth::Error>(())
/// ```
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub enum Fitter {
    /// Range, azimuth and elevation of a target of constant velocity or acceleration.
    Radar(SlidingFit<PolynomialDynamics, Radar>),
    /// A scalar polynomial in time, observed directly.
    Polynomial(SlidingFit<PolynomialDynamics, LinearObservation>),
}

/// How a front end makes each row of a [`Fitter`] a measurement, saved beside the fit
/// ([`crate::persist::Beside`]): the noise σ (radar: the range's and the angles'; polynomial:
/// the value's, and 0), whether a radar's azimuth is a bearing, and the rows taken so far.
///
/// ```
/// use seqsmooth::estimate::sliding::RowNoise;
/// assert!(RowNoise { sigmas: [10.0, 1e-3], bearing: false, rows: 4 }.check().is_ok());
/// assert!(RowNoise { sigmas: [0.0, 1e-3], bearing: false, rows: 4 }.check().is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RowNoise {
    /// The σ of each row's components (see above).
    pub sigmas: [f64; 2],
    /// Whether a radar's azimuth is clockwise from +y.
    pub bearing: bool,
    /// The rows taken so far.
    pub rows: u64,
}

impl RowNoise {
    /// Why the σ cannot be used ([`is_usable_sigma`](crate::model::measurement::is_usable_sigma);
    /// the second may be 0), or nothing.
    pub fn check(&self) -> Result<(), String> {
        use crate::model::measurement::is_usable_sigma;
        let [a, b] = self.sigmas;
        if !is_usable_sigma(a) || !(b == 0.0 || is_usable_sigma(b)) {
            return Err(format!("row noise σ {a}, {b}"));
        }
        Ok(())
    }
}

impl Fitter {
    /// A restored fit's invariants ([`crate::persist`]), as [`SlidingFit`]'s.
    pub(crate) fn check_saved(&self) -> Result<(), String> {
        match self {
            Fitter::Radar(f) => f.check_saved(),
            Fitter::Polynomial(f) => f.check_saved(),
        }
    }

    /// [`SlidingFit::push_finite`] of the model's fit: the row taken and the window fitted,
    /// or the row refused and the fit as before it.
    pub fn push_finite(&mut self, m: Measurement) -> Result<Option<Correction>, Error> {
        match self {
            Fitter::Radar(f) => f.push_finite(m),
            Fitter::Polynomial(f) => f.push_finite(m),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::measurement::NoiseCovariance;

    fn value(t: f64, y: f64) -> Measurement {
        Measurement {
            time: t,
            values: vec![Some(y)],
            noise: NoiseCovariance::Variances(vec![1.0]),
        }
    }

    /// An estimate the check refuses leaves the window, the last estimate and so the next
    /// fit as before the refused measurement, also when the window was full.
    #[test]
    fn a_refused_estimate_leaves_the_fit_as_before() {
        let solver = GaussNewton::default();
        let mut a = SlidingFit::polynomial(1, 3, Epoch::End, solver).unwrap();
        let mut b = a.clone();
        for k in 0..5 {
            let m = value(k as f64, (k * k) as f64);
            assert_eq!(a.push(m.clone()).unwrap(), b.push_finite(m).unwrap());
        }
        let refused = b.push_checked(value(5.0, 1e9), |_| {
            Err(Error::NonFinite {
                what: "fitted state",
                value: f64::INFINITY,
            })
        });
        assert!(refused.is_err());
        let times = |f: &SlidingFit<_, _>| f.measurements().map(|m| m.time).collect::<Vec<_>>();
        assert_eq!(times(&a), times(&b));
        assert_eq!(a.last, b.last);
        assert_eq!(
            a.push(value(6.0, 30.0)).unwrap(),
            b.push(value(6.0, 30.0)).unwrap()
        );
    }
}
