//! The Bayes filter (`kalman::BayesFilter`) over the polynomial model as a Python class,
//! `BayesFilter`: Morrison ch. 10 in square-root information form, starting from no
//! information (or a prior), with optional fading memory (ch. 14) and its true covariance.
//! The model and observation are `KalmanFilter`'s (`kalman.rs`'s parsers).

use crate::arrays::matrix;
use crate::errors::{raise, IntoPy, Kind};
use crate::kalman::{
    before, covariance_from, discount_from, measurement, measurements, observation_from,
    out_of_order, square, state_from,
};
use crate::persist;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::kalman::BayesFilter;
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::observation::{LinearObservation, Observation};

type Filter = BayesFilter<PolynomialDynamics, LinearObservation>;

/// The Bayes filter (Morrison ch. 10, (10.2.40)-(10.2.44)) over the polynomial model, in
/// square-root information form: the recursion of the exact polynomial engine. It starts
/// from no information (``(S_{1,0})⁻¹ = 0``, (10.3.5)), so the estimate exists once the
/// measurements determine it; with fading memory (ch. 14, (14.4.26)-(14.4.32)) the reported
/// covariance is the estimate's true one.
///
/// Parameters
/// ----------
/// degree : int
///     The polynomial degree of the motion on each axis.
/// t0 : float
///     The filter's starting time.
/// axes : int
///     The number of axes (default 1); the state is ``(x, y, …, x', y', …)``.
/// observation : array_like, optional
///     The observation matrix ``M``, components × states; default the positions.
/// x0, P0 : array_like, optional
///     A prior state and covariance at ``t0`` (both or neither).
/// theta, tau : float, optional
///     Fading memory: the discount ``theta`` in (0, 1) per span ``tau`` of time, both or
///     neither (as ``FadingMemory``'s).
/// theta_per_update : float, optional
///     Fading memory with the discount in (0, 1) per update (what ``theta`` alone meant
///     before; ``beta`` per unit of time is now ``theta``, ``tau=1.0``).
/// q : float
///     The spectral density of the white noise driving the highest derivative of each axis
///     (value²/time^(2m+1), as ``KalmanFilter``'s ``q``); 0 for none. Each prediction adds
///     ``Q`` over the step (ch. 15) in information form: the filter is then the Kalman filter
///     with the same ``q`` (which it equals to rounding), and may still start from no
///     information. Not with fading memory.
///
/// ``state`` and ``covariance`` are settable once determined; ``set_estimate(x, P)`` sets
/// both at any time (``P`` positive definite: the filter holds its inverse).
#[pyclass(name = "BayesFilter", module = "seqsmooth")]
pub struct PyBayesFilter {
    filter: Filter,
    /// The observation's components `p`.
    components: usize,
    /// The states `(m + 1) · axes`.
    states: usize,
}

#[pymethods]
impl PyBayesFilter {
    /// ``pickle`` support (``copy.copy`` and ``copy.deepcopy`` too): the filter's state in
    /// the library's saved form, restored bit for bit. Filters are mutable: a copy is a deep
    /// copy of the state, and the copy and the original then run apart.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        persist::reduce_saved(slf.as_any(), &slf.borrow().filter)
    }

    /// The filter ``__reduce__`` saved (a ``DamagedStateError`` if ``state`` is damaged or
    /// another class's).
    #[staticmethod]
    fn _from_state(state: &Bound<'_, PyAny>) -> PyResult<Self> {
        let filter: Filter = persist::load(state)?;
        let (dynamics, observation) = filter.models();
        let (states, components) = (
            seqsmooth::model::dynamics::Dynamics::dimension(dynamics),
            observation.components(),
        );
        Ok(Self {
            filter,
            components,
            states,
        })
    }

    #[new]
    #[allow(non_snake_case, clippy::too_many_arguments)]
    #[pyo3(signature = (degree, t0 = 0.0, axes = 1, observation = None, x0 = None, P0 = None, theta = None, tau = None, theta_per_update = None, beta = None, q = 0.0))]
    fn new(
        degree: usize,
        t0: f64,
        axes: usize,
        observation: Option<&Bound<'_, PyAny>>,
        x0: Option<&Bound<'_, PyAny>>,
        P0: Option<&Bound<'_, PyAny>>,
        theta: Option<f64>,
        tau: Option<f64>,
        theta_per_update: Option<f64>,
        beta: Option<f64>,
        q: f64,
    ) -> PyResult<Self> {
        // The library's polynomial model: its degree, axes and states.
        let n = seqsmooth::polynomial::check_model(degree, axes).py()?;
        let observe = observation_from(observation, axes, n)?;
        let components = observe.components();
        let mut filter =
            BayesFilter::new(PolynomialDynamics::new(degree, axes), observe, t0).py()?;
        if let Some(d) = discount_from(theta, tau, theta_per_update, beta)? {
            filter = filter.with_fading(d).py()?;
        }
        match (x0, P0) {
            (Some(x0), Some(p0)) => {
                let (x, p) = crate::kalman::polynomial_prior(x0, p0, degree, axes, n)?;
                filter = filter.with_prior(&x, &p).py()?;
            }
            (None, None) => {}
            _ => {
                return Err(raise(
                    Kind::Parameter,
                    "x0 and P0 go together: give both for a prior, or neither",
                    None,
                ))
            }
        }
        if q != 0.0 {
            filter = filter
                .with_process_noise(WhiteNoiseDerivative::new(degree, axes, q).py()?)
                .py()?;
        }
        Ok(Self {
            filter,
            components,
            states: n,
        })
    }

    /// Whether the measurements so far determine the state.
    #[getter]
    fn is_determined(&self) -> bool {
        self.filter.estimate().is_some()
    }

    /// The estimate ``X = R⁻¹ d`` (10.2.33), or ``None`` while not determined.
    #[getter]
    fn state<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.filter
            .estimate()
            .map(|x| PyArray1::from_slice(py, x.as_slice()))
    }

    /// The covariance of ``X``'s errors (10.2.34); with fading memory the true one
    /// (14.3.11)-(14.3.13). ``None`` while not determined.
    #[getter]
    fn covariance<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.filter.covariance().map(|c| square(py, &c)).transpose()
    }

    /// Sets the estimate (state only; the covariance kept): the information becomes that
    /// of the estimate as a prior (10.3.8). Once determined; before, ``set_estimate``.
    #[setter]
    fn set_state(&mut self, x: &Bound<'_, PyAny>) -> PyResult<()> {
        let p = self.filter.covariance().ok_or_else(undetermined)?;
        self.filter.set_estimate(&state_from(x)?, &p).py()
    }

    /// Sets the covariance (the state kept), positive definite; once determined.
    #[setter]
    fn set_covariance(&mut self, p: &Bound<'_, PyAny>) -> PyResult<()> {
        let x = self.filter.estimate().ok_or_else(undetermined)?;
        let p = covariance_from(p, self.states)?;
        self.filter.set_estimate(&x, &p).py()
    }

    /// Replaces the information by that of the estimate ``x`` with covariance ``P`` at the
    /// filter's time, as a prior ((10.3.8); the information before forgotten): ``x`` finite,
    /// ``P`` finite, symmetric and positive definite (the filter holds its inverse), checked by
    /// the library — a ``ParameterError`` naming the state or ``P`` otherwise, the filter
    /// unchanged. With fading memory the discount counts from now.
    #[allow(non_snake_case)]
    fn set_estimate(&mut self, x: &Bound<'_, PyAny>, P: &Bound<'_, PyAny>) -> PyResult<()> {
        let p = covariance_from(P, self.states)?;
        self.filter.set_estimate(&state_from(x)?, &p).py()
    }

    /// The 1σ of each state component, the square roots of ``covariance``'s diagonal;
    /// ``None`` while not determined.
    #[getter]
    fn std_devs<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.filter.std_devs().map(|s| PyArray1::from_vec(py, s))
    }

    /// With fading memory, the recursion's own matrix ``P`` (not the covariance); without,
    /// the covariance. ``None`` while not determined.
    #[getter]
    fn information_covariance<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.filter
            .information_covariance()
            .map(|c| square(py, &c))
            .transpose()
    }

    /// The time the estimate is valid at.
    #[getter]
    fn time(&self) -> f64 {
        self.filter.time()
    }

    /// Carries the information to time ``t`` (no measurement; (10.2.40)-(10.2.41)).
    fn predict(&mut self, t: f64) -> PyResult<()> {
        self.filter.predict(t).py()
    }

    /// Predicts to ``t`` (not before the filter's time) and folds in ``z`` (a number, or one
    /// value per component; NaN for a missing one) of noise ``R`` (a variance for every
    /// component, the variances, or the covariance; positive definite). On an error the
    /// filter is unchanged.
    #[allow(non_snake_case)]
    #[pyo3(signature = (t, z, R))]
    fn update(&mut self, t: f64, z: &Bound<'_, PyAny>, R: &Bound<'_, PyAny>) -> PyResult<()> {
        let m = measurement(t, z, R, self.components, self.filter.time())?;
        self.filter.update(&m).py()
    }

    /// Runs the measurements ``(t[i], z[i])`` (``z`` of shape ``(n,)`` or ``(n, p)``, NaN for
    /// a missing component) with noise ``R`` on every one. Returns ``(states, covariances)``,
    /// ``(n, dim)`` and ``(n, dim, dim)``, NaN rows while the state is not determined. The
    /// work runs without the GIL. On an error (``.index`` names the measurement) the
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
        let disorder = out_of_order(self.filter.time(), &rows);
        if let Some((k, _, _)) = disorder {
            rows.truncate(k);
        }
        let n = self.states;
        let mut states = vec![f64::NAN; rows.len() * n];
        let mut covariances = vec![f64::NAN; rows.len() * n * n];
        let filter = &mut self.filter;
        py.detach(|| {
            for (i, m) in rows.iter().enumerate() {
                filter.update(m).map_err(|e| seqsmooth::Error::InBatch {
                    index: i,
                    source: Box::new(e),
                })?;
                if let (Some(x), Some(c)) = (filter.estimate(), filter.covariance()) {
                    states[i * n..(i + 1) * n].copy_from_slice(x.as_slice());
                    // Symmetric: column-major is row-major.
                    covariances[i * n * n..(i + 1) * n * n].copy_from_slice(c.as_slice());
                }
            }
            Ok::<(), seqsmooth::Error>(())
        })
        .py()?;
        if let Some((k, t, previous)) = disorder {
            return Err(before(t, previous, Some(k)));
        }
        let count = rows.len();
        let states = matrix(py, states, count, n)?;
        let covariances = PyArray1::from_vec(py, covariances)
            .reshape([count, n, n])?
            .into_any();
        PyTuple::new(py, [states, covariances])
    }

    fn __repr__(&self) -> String {
        format!(
            "BayesFilter(states={}, time={:?}, determined={})",
            self.states,
            self.filter.time(),
            self.is_determined()
        )
    }
}

/// The refusal of a partial estimate (state or covariance alone) before the filter is
/// determined.
fn undetermined() -> PyErr {
    raise(
        Kind::NotDetermined,
        "the filter is not determined yet: set both with set_estimate(x, P)",
        None,
    )
}
