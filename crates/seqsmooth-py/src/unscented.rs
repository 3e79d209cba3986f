//! The unscented Kalman filter over the built-in models as a Python class,
//! `UnscentedKalmanFilter`: the library's `kalman::UnscentedKalmanFilter` with
//! `PolynomialDynamics` (degree `m` on `axes` axes, the state ordered derivative then axis),
//! white-noise driving of the highest derivative (`q`), and a linear observation (the
//! positions by default, or the caller's `M`) or a radar's range, azimuth and elevation
//! (`model::radar::Radar`, the azimuth residual wrapped); and the unscented RTS smoother
//! (`kalman::unscented_smoother`). With `f=` and `h=` it runs over the caller's own model, the
//! Python callables of [`crate::callables`].

use crate::arrays::series;
use crate::callables::{
    callables_of, model_again, stacked, stand_ins, user_model, Callable, Raised, Run, Transition,
    UserDynamics, UserObservation,
};
use crate::errors::{raise, IntoPy, Kind};
use crate::fixed_lag::lagged;
use crate::kalman::{
    before, measurement, measurements, observation_from, out_of_order, square, square_from,
    PyInnovation,
};
use crate::persist;
use nalgebra::DVector;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::kalman::sigma_points::SigmaPoints;
use seqsmooth::kalman::{smooth_unscented, UnscentedFixedLagSmoother, UnscentedKalmanFilter};
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::measurement::Measurement;
use seqsmooth::model::observation::{LinearObservation, Observation};
use seqsmooth::model::radar::Radar;
use seqsmooth::persist::{DynamicsLeftOut, ObservationLeftOut};
use seqsmooth::Error;

/// The filter on one of the built-in observations.
#[derive(Clone, Debug)]
enum Model {
    Linear(UnscentedKalmanFilter<PolynomialDynamics, LinearObservation>),
    Radar(UnscentedKalmanFilter<PolynomialDynamics, Radar>),
    User(UnscentedKalmanFilter<UserDynamics, UserObservation>),
}

/// `$body` with `$f` the filter, whichever the observation.
macro_rules! each {
    ($model:expr, $f:ident => $body:expr) => {
        match $model {
            Model::Linear($f) => $body,
            Model::Radar($f) => $body,
            Model::User($f) => $body,
        }
    };
}

/// A filter of `D` and `O` from the prior, the sigma points and the driving noise.
fn build<O: Observation>(
    dynamics: PolynomialDynamics,
    observation: O,
    x0: DVector<f64>,
    p0: nalgebra::DMatrix<f64>,
    t0: f64,
    points: SigmaPoints,
    q: f64,
) -> PyResult<UnscentedKalmanFilter<PolynomialDynamics, O>> {
    let mut f = UnscentedKalmanFilter::new(dynamics, observation, x0, p0, t0)
        .py()?
        .with_sigma_points(points)
        .py()?;
    if q != 0.0 {
        let noise = WhiteNoiseDerivative::new(dynamics.degree(), dynamics.axes(), q).py()?;
        f = f.with_process_noise(noise).py()?;
    }
    Ok(f)
}

/// The unscented Kalman filter (Julier and Uhlmann 1997; Wan and van der Merwe 2000) over the
/// polynomial model: degree ``degree`` on ``axes`` axes, the state ``(x, y, …, x', y', …)``
/// (derivative, then axis), unscaled derivatives in the caller's time units, observed in a
/// linear ``M`` or by a radar.
///
/// Parameters
/// ----------
/// degree : int
///     The polynomial degree of the motion on each axis (1: constant velocity).
/// x0, P0 : array_like
///     The prior state and covariance (a number: that variance on every state; a vector: the
///     diagonal) at time ``t0``; ``P0`` positive definite (the sigma points come from its
///     Cholesky factor).
/// t0 : float
///     The prior's time.
/// axes : int
///     The number of axes (default 1; ``observation="radar"`` needs 3: it observes the
///     position ``(x, y, z)``).
/// q : float
///     The spectral density of the white noise driving the highest derivative of each axis
///     (value²/time^(2m+1)); 0 for none. ``Q`` is integrated over each actual step.
/// observation : array_like or "radar", optional
///     The observation matrix ``M``, components × states (default the positions,
///     ``[I_axes, 0, …]``), or ``"radar"``: range, azimuth and elevation (radians; azimuth
///     from +x towards +y, elevation from the x-y plane) of the position ``(x, y, z)`` seen
///     from ``site``, the azimuth's residual wrapped to (−π, π].
/// site : (float, float, float)
///     The radar's position (``observation="radar"`` only; default the origin).
/// sigma_points : (float, float, float)
///     The scaled sigma points' ``(alpha, beta, kappa)`` (Wan and van der Merwe (15);
///     filterpy's ``MerweScaledSigmaPoints(n, alpha, beta, kappa)``):
///     ``λ = alpha² (n + kappa) − n``, points at ``x ± √(n + λ)`` times the Cholesky columns
///     of ``P``. Default ``(1, 2, 0)``: points at ``±√n σ`` with every covariance weight
///     non-negative (a small ``alpha`` such as 1e-3 weighs the central point by about
///     ``−1/alpha²``; a negative central weight can make a covariance indefinite, and such an
///     update is refused). One tuple, not three keywords: ``beta`` elsewhere in the package
///     was a fading discount, and ``alpha`` is filterpy's fading factor.
///
/// f, h : callable, optional
///     The caller's own model instead of the polynomial one (then no ``degree``, ``axes``,
///     ``q``, ``observation`` or ``site``): ``f(x, t0, t1) -> x1`` carries each sigma point
///     over the step, ``h(x, t) -> z`` observes it (``p`` values, counted by one call
///     ``h(x0, t0)``), as for :class:`ExtendedKalmanFilter` (no Jacobians are needed).
/// dxdt : callable, optional
///     Instead of ``f``: ``dxdt(x, t) -> dx/dt`` (``n`` values), integrated by the library
///     over each step for each sigma point (DOP853, tolerances 1e-10 relative, 1e-12
///     absolute), as for :class:`ExtendedKalmanFilter`.
/// Q : array_like or callable, optional
///     With ``f``: the driving-noise covariance over each step, one ``n × n`` matrix (or a
///     number or diagonal) or ``Q(t0, t1)``. Default none.
/// angles : sequence of int, optional
///     With ``h``: the components of ``z`` that are angles in radians (residuals and the
///     predicted mean wrapped to (−π, π]).
///
/// A missing component (NaN) is left out, a time with none is a prediction only. A callable
/// that raises, returns the wrong shape, a NaN or an infinity is refused with a
/// ``ParameterError`` naming it and the time (in ``update_many`` also ``.index``), the filter
/// left as it was.
#[pyclass(name = "UnscentedKalmanFilter", module = "seqsmooth")]
#[derive(Clone)]
pub struct PyUnscentedKalmanFilter {
    model: Model,
    /// The observation's components `p`.
    components: usize,
    /// The exception a callable of the user's model raised (empty for the built-in models).
    raised: Raised,
    /// The driving noise `Q` if it is the caller's callable.
    q: Option<Callable>,
}

#[pymethods]
impl PyUnscentedKalmanFilter {
    /// ``pickle`` support (``copy.copy`` and ``copy.deepcopy`` too): the filter's state in
    /// the library's saved form, restored bit for bit. Filters are mutable: a copy is a deep
    /// copy of the state. Over the caller's model, the state is saved over the library's
    /// stand-in models and the callables ``f``/``dxdt``, ``h`` and a callable ``Q`` are
    /// pickled beside it by Python (a module-level function pickles; a lambda or a local
    /// function raises pickle's own error).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let me = slf.borrow();
        let state = match &me.model {
            Model::Linear(f) => ("linear", persist::save(py, f)?),
            Model::Radar(f) => ("radar", persist::save(py, f)?),
            Model::User(f) => {
                let (d, o) = f.models();
                let callables = callables_of(py, d, o, me.q.as_ref())?;
                let (dynamics, observation) = stand_ins(d, o);
                let mut f = f.clone();
                if me.q.is_some() {
                    f.take_process_noise();
                }
                let bare = f.with_models(dynamics, observation).py()?;
                let body = [persist::save(py, &bare)?, callables.into_any()];
                ("user", PyTuple::new(py, body)?.into_any())
            }
        };
        persist::reduce(slf.as_any(), state.into_pyobject(py)?.into_any())
    }

    /// The filter ``__reduce__`` saved (a ``DamagedStateError`` if ``state`` is damaged or
    /// another class's).
    #[staticmethod]
    fn _from_state(state: &Bound<'_, PyAny>) -> PyResult<Self> {
        let items = persist::items(state, 2)?;
        let body = items.get_item(1)?;
        let (model, components) = match items.get_item(0)?.extract::<String>().as_deref() {
            Ok("linear") => {
                let f: UnscentedKalmanFilter<PolynomialDynamics, LinearObservation> =
                    persist::load(&body)?;
                let p = f.models().1.components();
                (Model::Linear(f), p)
            }
            Ok("radar") => {
                let f: UnscentedKalmanFilter<PolynomialDynamics, Radar> = persist::load(&body)?;
                let p = f.models().1.components();
                (Model::Radar(f), p)
            }
            Ok("user") => {
                let body = persist::items(&body, 2)?;
                let mut bare: UnscentedKalmanFilter<DynamicsLeftOut, ObservationLeftOut> =
                    persist::load(&body.get_item(0)?)?;
                let (d, o) = bare.models();
                let user = model_again(&body.get_item(1)?, d, o)?;
                let (p, q) = (user.observation.components(), user.q_callable());
                if q.is_some() && bare.take_process_noise().is_some() {
                    return Err(persist::damaged(
                        "the driving noise is both in the bytes and beside them",
                    ));
                }
                let mut f = bare.with_models(user.dynamics, user.observation).py()?;
                if let Some(noise) = user.noise {
                    f = f.with_process_noise(noise).py()?;
                }
                return Ok(Self {
                    model: Model::User(f),
                    components: p,
                    raised: user.raised,
                    q,
                });
            }
            _ => return Err(persist::damaged("not an UnscentedKalmanFilter's model")),
        };
        Ok(Self {
            model,
            components,
            raised: Raised::default(),
            q: None,
        })
    }

    #[new]
    #[allow(non_snake_case, clippy::too_many_arguments)]
    #[pyo3(signature = (degree = None, x0 = None, P0 = None, t0 = 0.0, axes = 1, q = 0.0, observation = None, site = None, sigma_points = (1.0, 2.0, 0.0), *, f = None, h = None, Q = None, angles = None, dxdt = None))]
    fn new(
        degree: Option<usize>,
        x0: Option<&Bound<'_, PyAny>>,
        P0: Option<&Bound<'_, PyAny>>,
        t0: f64,
        axes: usize,
        q: f64,
        observation: Option<&Bound<'_, PyAny>>,
        site: Option<(f64, f64, f64)>,
        sigma_points: (f64, f64, f64),
        f: Option<&Bound<'_, PyAny>>,
        h: Option<&Bound<'_, PyAny>>,
        Q: Option<&Bound<'_, PyAny>>,
        angles: Option<Vec<usize>>,
        dxdt: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let (Some(x0), Some(P0)) = (x0, P0) else {
            return Err(raise(Kind::Parameter, "x0 and P0 are required", None));
        };
        let (alpha, beta, kappa) = sigma_points;
        let points = SigmaPoints::new(alpha, beta, kappa).py()?;
        let polynomial =
            degree.is_some() || axes != 1 || q != 0.0 || observation.is_some() || site.is_some();
        let dynamics = f.or(dxdt);
        let degree = match (degree, dynamics, h) {
            (None, Some(_), Some(h)) if !polynomial => {
                let x = DVector::from_column_slice(series(x0, "x0")?.as_slice());
                let p0 = square_from(P0, x.len(), "P0")?;
                let transition = Transition {
                    f,
                    dxdt,
                    ..Transition::default()
                };
                let user = user_model(&x, t0, transition, h, None, Q, angles)?;
                let (components, q) = (user.observation.components(), user.q_callable());
                let mut filter =
                    UnscentedKalmanFilter::new(user.dynamics, user.observation, x, p0, t0)
                        .py()?
                        .with_sigma_points(points)
                        .py()?;
                if let Some(noise) = user.noise {
                    filter = filter.with_process_noise(noise).py()?;
                }
                return Ok(Self {
                    model: Model::User(filter),
                    components,
                    raised: user.raised,
                    q,
                });
            }
            (Some(degree), None, None) if Q.is_none() && angles.is_none() => degree,
            _ => {
                return Err(raise(
                    Kind::Parameter,
                    "give either degree (the polynomial model, with axes, q, observation, \
                     site) or both f and h (the caller's model, with Q and angles)",
                    None,
                ))
            }
        };
        // The library's polynomial model: its degree, axes and states.
        let n = seqsmooth::polynomial::check_model(degree, axes).py()?;
        let (x, p0) = crate::kalman::polynomial_prior(x0, P0, degree, axes, n)?;
        let dynamics = PolynomialDynamics::new(degree, axes);
        let radar = match observation {
            Some(o) => o.extract::<String>().ok(),
            None => None,
        };
        let (model, components) = match radar.as_deref() {
            Some("radar") => {
                let [a, b, c] = site.map_or([0.0; 3], |(a, b, c)| [a, b, c]);
                let radar = Radar::of_polynomial([a, b, c], &dynamics).py()?;
                let p = radar.components();
                (
                    Model::Radar(build(dynamics, radar, x, p0, t0, points, q)?),
                    p,
                )
            }
            Some(other) => {
                return Err(raise(
                    Kind::Parameter,
                    format!("observation {other:?} is not a matrix or 'radar'"),
                    None,
                ))
            }
            None if site.is_some() => {
                return Err(raise(
                    Kind::Parameter,
                    "site applies only to observation='radar'",
                    None,
                ))
            }
            None => {
                let linear = observation_from(observation, axes, n)?;
                let p = linear.components();
                (
                    Model::Linear(build(dynamics, linear, x, p0, t0, points, q)?),
                    p,
                )
            }
        };
        Ok(Self {
            model,
            components,
            raised: Raised::default(),
            q: None,
        })
    }

    /// The current estimate ``X``; settable (``n`` finite numbers, checked by the library;
    /// on an error the filter is unchanged).
    #[getter]
    fn state<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        each!(&self.model, f => PyArray1::from_slice(py, f.state().as_slice()))
    }

    #[setter]
    fn set_state(&mut self, x: &Bound<'_, PyAny>) -> PyResult<()> {
        let x = crate::kalman::state_from(x)?;
        each!(&mut self.model, f => {
            let (p, t) = (f.covariance().clone(), f.time());
            f.set_estimate(x, p, t).py()
        })
    }

    /// The covariance of ``X``'s errors; settable (finite, symmetric, positive definite:
    /// the sigma points come from its Cholesky factor; checked by the library: a
    /// ``ParameterError`` naming ``P`` otherwise, the filter unchanged).
    #[getter]
    fn covariance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        each!(&self.model, f => square(py, f.covariance()))
    }

    #[setter]
    fn set_covariance(&mut self, p: &Bound<'_, PyAny>) -> PyResult<()> {
        let n = self.state_len();
        let p = crate::kalman::covariance_from(p, n)?;
        each!(&mut self.model, f => {
            let (x, t) = (f.state().clone(), f.time());
            f.set_estimate(x, p, t).py()
        })
    }

    /// The 1σ of each state component, the square roots of ``covariance``'s diagonal.
    #[getter]
    fn std_devs<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        each!(&self.model, f => PyArray1::from_vec(py, f.std_devs()))
    }

    /// The time the estimate is valid at.
    #[getter]
    fn time(&self) -> f64 {
        each!(&self.model, f => f.time())
    }

    /// The sigma points' ``(alpha, beta, kappa)``.
    #[getter]
    fn sigma_points(&self) -> (f64, f64, f64) {
        let s = each!(&self.model, f => f.sigma_points());
        (s.alpha(), s.beta(), s.kappa())
    }

    /// Carries the estimate and its covariance to time ``t`` through the sigma points (no
    /// measurement).
    fn predict(&mut self, t: f64) -> PyResult<()> {
        let result = each!(&mut self.model, f => f.predict(t));
        self.raised.py(result)
    }

    /// Predicts to ``t`` and updates with ``z`` (a number, or one value per component; NaN
    /// for a missing one) of noise ``R`` (a variance for every component, the variances, or
    /// the covariance). Returns the :class:`Innovation`, or ``None`` when every component is
    /// missing (a prediction only). On an error the filter is unchanged.
    #[allow(non_snake_case)]
    #[pyo3(signature = (t, z, R))]
    fn update(
        &mut self,
        t: f64,
        z: &Bound<'_, PyAny>,
        R: &Bound<'_, PyAny>,
    ) -> PyResult<Option<PyInnovation>> {
        let m = measurement(t, z, R, self.components, self.time())?;
        let result = each!(&mut self.model, f => f.update(&m));
        let innovation = self.raised.py(result)?;
        Ok(innovation.map(|inner| PyInnovation { inner }))
    }

    /// Runs the measurements ``(t[i], z[i])`` (``z`` of shape ``(n,)`` or ``(n, p)``, NaN for
    /// a missing component) with noise ``R`` on every one. Returns ``(states, covariances,
    /// nis)``: ``(n, dim)``, ``(n, dim, dim)`` and ``(n,)`` (NaN where nothing was measured).
    /// The work runs without the GIL. On an error (``.index`` names the measurement) the
    /// measurements before it are taken.
    #[allow(non_snake_case)]
    #[pyo3(signature = (t, z, R))]
    fn update_many<'py>(
        &mut self,
        py: Python<'py>,
        t: &Bound<'py, PyAny>,
        z: &Bound<'py, PyAny>,
        R: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let mut rows = measurements(t, z, R, self.components)?;
        let disorder = out_of_order(self.time(), &rows);
        if let Some((k, _, _)) = disorder {
            rows.truncate(k);
        }
        let n = self.state_len();
        let mut run = Run::new(rows.len(), n);
        let model = &mut self.model;
        let outcome = py.detach(|| {
            each!(model, f => {
                for (i, m) in rows.iter().enumerate() {
                    let innovation = f.update(m).map_err(|e| Error::InBatch {
                        index: i,
                        source: Box::new(e),
                    })?;
                    run.record(i, f.state(), f.covariance(), innovation.map(|s| s.nis));
                }
            });
            Ok::<(), Error>(())
        });
        self.raised.py(outcome)?;
        if let Some((k, t, previous)) = disorder {
            return Err(before(t, previous, Some(k)));
        }
        run.into_tuple(py)
    }

    /// The unscented Rauch–Tung–Striebel smoother (Särkkä 2008) over the measurements, from
    /// this filter's current state (the filter itself is not changed): at each measurement's
    /// time the estimate from all of them, from the forward pass's own predictions and
    /// cross-covariances. Returns ``(states, covariances)``, ``(n, dim)`` and
    /// ``(n, dim, dim)``.
    #[allow(non_snake_case)]
    #[pyo3(signature = (t, z, R))]
    fn smooth<'py>(
        &self,
        py: Python<'py>,
        t: &Bound<'py, PyAny>,
        z: &Bound<'py, PyAny>,
        R: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let rows: Vec<Measurement> = measurements(t, z, R, self.components)?;
        if let Some((k, t, previous)) = out_of_order(self.time(), &rows) {
            return Err(before(t, previous, Some(k)));
        }
        let model = self.model.clone();
        let smoothed = py.detach(|| each!(model, f => smooth_unscented(f, &rows)));
        let smoothed = self.raised.py(smoothed)?;
        stacked(py, smoothed.iter().map(|s| (&s.state, &s.covariance)))
    }

    /// The fixed-lag smoother over the measurements (as ``smooth`` takes them), from this
    /// filter's current state (the filter itself is not changed): each measurement's estimate
    /// from the ``lag`` measurements after it (the last ``lag`` from all of them; a ``lag`` of
    /// at least their number gives ``smooth``'s): the unscented RTS recursion of ``smooth``
    /// (Särkkä 2008) over the last ``lag + 1`` at each measurement, by the library's
    /// ``UnscentedFixedLagSmoother``, which holds ``lag + 1`` measurements however many there
    /// are. Returns ``(states, covariances)``, ``(N, dim)``
    /// and ``(N, dim, dim)``; an error's ``.index`` names the measurement.
    #[allow(non_snake_case)]
    #[pyo3(signature = (t, z, R, lag))]
    fn fixed_lag_smoother<'py>(
        &self,
        py: Python<'py>,
        t: &Bound<'py, PyAny>,
        z: &Bound<'py, PyAny>,
        R: &Bound<'py, PyAny>,
        lag: usize,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let rows: Vec<Measurement> = measurements(t, z, R, self.components)?;
        if let Some((k, t, previous)) = out_of_order(self.time(), &rows) {
            return Err(before(t, previous, Some(k)));
        }
        let (model, n) = (self.model.clone(), self.state_len());
        let out = py
            .detach(|| each!(model, f => lagged(UnscentedFixedLagSmoother::new(f, lag), &rows, n)));
        self.raised.py(out)?.into_tuple(py)
    }

    fn __repr__(&self) -> String {
        let (a, b, k) = self.sigma_points();
        format!(
            "UnscentedKalmanFilter(states={}, time={:?}, sigma_points=({a:?}, {b:?}, {k:?}))",
            self.state_len(),
            self.time()
        )
    }
}

impl PyUnscentedKalmanFilter {
    fn state_len(&self) -> usize {
        each!(&self.model, f => f.state().len())
    }
}
