//! Continuous linear models from Python: the class `ContinuousModel`, the library's
//! `model::continuous::ContinuousModel` (`dX/dt = A X + w`, white noise of spectral density
//! matrix `Q_c`, discretised exactly over each actual step: `Φ = e^{Aζ}` and Van Loan's
//! `Q(ζ)`; Morrison (15.2.23), Van Loan 1978) with its built-in models (polynomial, nearly
//! constant velocity and acceleration with per-axis noise, Singer 1970); and the class
//! `ContinuousKalmanFilter`, the library's `kalman::KalmanFilter` on such a model with a linear
//! observation `z = H x + v`, each measurement at its own (irregular) time, and its
//! Rauch–Tung–Striebel smoother. This file only converts arrays; every rule (shapes, ranges,
//! symmetric, positive semidefinite) is the library's.

use crate::arrays::{matrix, table};
use crate::callables::Run;
use crate::errors::{raise, IntoPy, Kind};
use crate::fixed_lag::lagged;
use crate::kalman::{
    before, measurement, measurements, noise, out_of_order, smoothed_run, square, PyInnovation,
};
use crate::persist;
use nalgebra::{DMatrix, DVector};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use seqsmooth::error::Param;
use seqsmooth::kalman::noise::check_covariance;
use seqsmooth::kalman::{smoother, FixedLagSmoother, KalmanFilter};
use seqsmooth::model::continuous::ContinuousModel;
use seqsmooth::model::dynamics::Dynamics;
use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
use seqsmooth::model::observation::{LinearObservation, Observation};

/// `obj` as a matrix named `name`: a 2-D array as it is; a 1-D array as one row when `row`
/// (a one-component `H`), else one column.
fn matrix_arg(obj: &Bound<'_, PyAny>, name: &str, row: bool) -> PyResult<DMatrix<f64>> {
    let ndim: usize = obj
        .py()
        .import("numpy")?
        .call_method1("ndim", (obj,))?
        .extract()?;
    let (values, rows, cols) = table(obj, name)?;
    if ndim == 1 && row {
        return Ok(DMatrix::from_row_slice(1, rows, values.as_slice()));
    }
    Ok(DMatrix::from_row_slice(rows, cols, values.as_slice()))
}

/// The spectral densities of `axes` axes from `q`: a number (the same on every axis, `axes`
/// default 1) or one per axis (`axes`, if given, their count).
fn per_axis(q: &Bound<'_, PyAny>, axes: Option<usize>) -> PyResult<Vec<f64>> {
    if let Ok(v) = q.extract::<f64>() {
        return Ok(vec![v; axes.unwrap_or(1)]);
    }
    let (values, rows, cols) = table(q, "q")?;
    let q: Vec<f64> = values.as_slice().to_vec();
    match axes {
        Some(a) if cols != 1 || a != rows => Err(raise(
            Kind::InvalidInput,
            format!("q has {} values for axes={a}: one per axis", q.len()),
            None,
        )),
        _ if cols != 1 => Err(raise(
            Kind::InvalidInput,
            format!("q is {rows}x{cols}: it must be a number or one value per axis"),
            None,
        )),
        _ => Ok(q),
    }
}

/// A continuous linear model ``dX/dt = A X + w``: white noise ``w`` of spectral density matrix
/// ``Qc`` (``E[w(t) w(s)ᵀ] = Qc δ(t − s)``), discretised exactly over any step ``ζ``:
/// ``F = e^{Aζ}``, ``Q = ∫₀^ζ e^{As} Qc e^{Aᵀs} ds`` (Morrison (15.2.23); Van Loan 1978).
///
/// Parameters
/// ----------
/// A : array_like, shape (n, n)
///     The dynamics matrix (finite).
/// Qc : array_like, shape (n, n)
///     The white noise's spectral density matrix: symmetric positive semidefinite (to 1e-12
///     of its largest entry), finite; state units² per time unit.
///
/// The built-in models (``polynomial``, ``nearly_constant_velocity``,
/// ``nearly_constant_acceleration``, ``singer``) order the state by derivative, then axis:
/// ``(x, y, …, x', y', …)``, as ``KalmanFilter``.
#[pyclass(name = "ContinuousModel", module = "seqsmooth", frozen)]
#[derive(Clone)]
pub struct PyContinuousModel {
    inner: ContinuousModel,
}

#[pymethods]
impl PyContinuousModel {
    #[new]
    #[allow(non_snake_case)]
    fn new(A: &Bound<'_, PyAny>, Qc: &Bound<'_, PyAny>) -> PyResult<Self> {
        let a = matrix_arg(A, "A", false)?;
        let qc = matrix_arg(Qc, "Qc", false)?;
        Ok(Self {
            inner: ContinuousModel::new(a, qc).py()?,
        })
    }

    /// The polynomial model of degree ``degree``: white noise of spectral density ``q`` on
    /// each axis' highest derivative (``q``: one number for every axis, or one per axis;
    /// ``axes`` their count, default 1 or ``len(q)``). ``Q`` is Morrison (15.2.23)'s closed
    /// form, as ``KalmanFilter(degree=, q=)``'s.
    #[staticmethod]
    #[pyo3(signature = (degree, q, axes = None))]
    fn polynomial(degree: usize, q: &Bound<'_, PyAny>, axes: Option<usize>) -> PyResult<Self> {
        let q = per_axis(q, axes)?;
        // The polynomial model's limits (its degree, as every polynomial class's).
        seqsmooth::polynomial::check_model(degree, q.len().max(1)).py()?;
        Ok(Self {
            inner: ContinuousModel::polynomial(degree, &q).py()?,
        })
    }

    /// Nearly constant velocity: white acceleration of spectral density ``q`` on each axis
    /// (one number, or one per axis); the state ``(x, y, …, x', y', …)``.
    #[staticmethod]
    #[pyo3(signature = (q, axes = None))]
    fn nearly_constant_velocity(q: &Bound<'_, PyAny>, axes: Option<usize>) -> PyResult<Self> {
        let q = per_axis(q, axes)?;
        Ok(Self {
            inner: ContinuousModel::nearly_constant_velocity(&q).py()?,
        })
    }

    /// Nearly constant acceleration: white jerk of spectral density ``q`` on each axis (one
    /// number, or one per axis).
    #[staticmethod]
    #[pyo3(signature = (q, axes = None))]
    fn nearly_constant_acceleration(q: &Bound<'_, PyAny>, axes: Option<usize>) -> PyResult<Self> {
        let q = per_axis(q, axes)?;
        Ok(Self {
            inner: ContinuousModel::nearly_constant_acceleration(&q).py()?,
        })
    }

    /// The Singer model (Singer 1970) on ``axes`` axes: position, velocity and an acceleration
    /// correlated as ``manoeuvre_variance · exp(−manoeuvre_alpha |τ|)``, ``da/dt = −α a + w``
    /// with ``w`` of spectral density ``2 α σ_m²``. ``manoeuvre_alpha > 0`` is the reciprocal
    /// of the manoeuvre time constant, ``manoeuvre_variance ≥ 0`` the acceleration's variance
    /// ``σ_m²``.
    #[staticmethod]
    #[pyo3(signature = (manoeuvre_alpha, manoeuvre_variance, axes = 1))]
    fn singer(manoeuvre_alpha: f64, manoeuvre_variance: f64, axes: usize) -> PyResult<Self> {
        Ok(Self {
            inner: ContinuousModel::singer(axes, manoeuvre_alpha, manoeuvre_variance).py()?,
        })
    }

    /// ``(F, Q)`` over a step ``dt ≥ 0``: ``e^{A dt}`` and Van Loan's ``Q(dt)``, each
    /// ``(n, n)``.
    fn discretise<'py>(&self, py: Python<'py>, dt: f64) -> PyResult<Bound<'py, PyTuple>> {
        let (phi, q) = self.inner.discretise(dt).py()?;
        PyTuple::new(py, [square(py, &phi)?, square(py, &q)?])
    }

    /// The dynamics matrix ``A``.
    #[getter(A)]
    fn a<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        square(py, self.inner.dynamics().matrix())
    }

    /// The spectral density matrix ``Qc`` (symmetrised).
    #[getter(Qc)]
    fn qc<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        square(py, self.inner.spectral_density())
    }

    /// The state dimension ``n``.
    #[getter]
    fn dimension(&self) -> usize {
        self.inner.dimension()
    }

    fn __repr__(&self) -> String {
        format!("ContinuousModel(states={})", self.inner.dimension())
    }
}

type Continuous = KalmanFilter<ContinuousModel, LinearObservation>;

/// The Kalman filter (Morrison chs. 12, 15) on a continuous linear model
/// (:class:`ContinuousModel`) observed linearly, ``z = H x + v``, ``v ~ N(0, R)``: each
/// measurement at its own time, the prediction over the actual step by ``F = e^{A dt}`` and
/// Van Loan's ``Q(dt)``.
///
/// Parameters
/// ----------
/// model : ContinuousModel
///     ``A`` and ``Qc``.
/// H : array_like, shape (p, n)
///     The observation matrix (a 1-D array: one component).
/// R : array_like, shape (p, p), or float
///     The measurement-noise covariance (a number: that variance on every component; ``p``
///     numbers: the variances); each update may give its own.
/// x0, P0 : array_like
///     The prior state (``n`` values) and its covariance (a number: that variance on every
///     state; a vector: the diagonal; or ``n × n``) at time ``t0``.
/// t0 : float
///     The prior's time.
///
/// The update is Joseph's form (12.3.7); a missing component (NaN) is left out, a time with
/// none is a prediction only. A refused call (``SeqsmoothError``; in a batch ``.index`` names
/// the measurement) leaves the filter unchanged.
#[pyclass(name = "ContinuousKalmanFilter", module = "seqsmooth")]
#[derive(Clone)]
pub struct PyContinuousKalmanFilter {
    filter: Continuous,
    /// The constant measurement noise.
    r: NoiseCovariance,
    /// The observation's components `p`.
    components: usize,
}

#[pymethods]
impl PyContinuousKalmanFilter {
    /// ``pickle`` support (``copy.copy`` and ``copy.deepcopy`` too): the filter's state and
    /// the constructor's ``R`` in the library's saved form, restored bit for bit. A copy is a
    /// deep copy of the state.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let me = slf.borrow();
        persist::reduce_saved(slf.as_any(), &(me.filter.clone(), me.r.clone()))
    }

    /// The filter ``__reduce__`` saved (a ``DamagedStateError`` if ``state`` is damaged or
    /// another class's).
    #[staticmethod]
    fn _from_state(state: &Bound<'_, PyAny>) -> PyResult<Self> {
        let (filter, r): (Continuous, NoiseCovariance) = persist::load(state)?;
        let components = filter.observation().components();
        let fits = match &r {
            NoiseCovariance::Identity => true,
            NoiseCovariance::Variances(v) => v.len() == components,
            NoiseCovariance::Full(m) => m.nrows() == components,
        };
        if !fits {
            return Err(persist::damaged("the measurement noise R does not fit H"));
        }
        Ok(Self {
            filter,
            r,
            components,
        })
    }

    #[new]
    #[allow(non_snake_case)]
    #[pyo3(signature = (model, H, R, x0, P0, t0 = 0.0))]
    fn new(
        model: PyRef<'_, PyContinuousModel>,
        H: &Bound<'_, PyAny>,
        R: &Bound<'_, PyAny>,
        x0: &Bound<'_, PyAny>,
        P0: &Bound<'_, PyAny>,
        t0: f64,
    ) -> PyResult<Self> {
        let model = model.inner.clone();
        let n = model.dimension();
        let x = DVector::from_column_slice(crate::arrays::series(x0, "x0")?.as_slice());
        let h = matrix_arg(H, "H", true)?;
        seqsmooth::kalman::noise::check_matrix(&h, (h.nrows(), n), Param::ObservationMatrixH)
            .py()?;
        let observation = LinearObservation::new(h).py()?;
        let p = observation.components();
        let r = noise(R, p)?;
        check_covariance(&full(&r, p), p, Param::MeasurementNoiseR).py()?;
        let p0 = crate::kalman::square_from(P0, x.len(), "P0")?;
        let filter = KalmanFilter::new(model.clone(), observation, x, p0, t0)
            .py()?
            .with_process_noise(model)
            .py()?;
        Ok(Self {
            filter,
            r,
            components: p,
        })
    }

    /// The current estimate ``X``.
    #[getter]
    fn state<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.filter.state().as_slice())
    }

    /// The covariance of ``X``'s errors.
    #[getter]
    fn covariance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        square(py, self.filter.covariance())
    }

    /// The 1σ of each state component, the square roots of ``covariance``'s diagonal.
    #[getter]
    fn std_devs<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.filter.std_devs())
    }

    /// The time the estimate is valid at.
    #[getter]
    fn time(&self) -> f64 {
        self.filter.time()
    }

    /// The observation matrix ``H``.
    #[getter(H)]
    fn h<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let m = self.filter.observation().matrix();
        matrix(py, m.transpose().as_slice().to_vec(), m.nrows(), m.ncols())
    }

    /// The constant measurement-noise covariance ``R``, ``(p, p)``.
    #[getter(R)]
    fn r<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        square(py, &full(&self.r, self.components))
    }

    /// Carries the estimate and its covariance to time ``t`` (no measurement): ``x = F x``,
    /// ``P = F P Fᵀ + Q`` over ``dt = t − time`` (either way).
    fn predict(&mut self, t: f64) -> PyResult<()> {
        self.filter.predict(t).py()
    }

    /// Predicts to ``t`` and updates with ``z`` (a number, or one value per component; NaN for
    /// a missing one) of noise ``R`` (default the constructor's). Returns the
    /// :class:`Innovation`, or ``None`` when every component is missing (a prediction only).
    /// On an error the filter is unchanged.
    #[allow(non_snake_case)]
    #[pyo3(signature = (t, z, R = None))]
    fn update(
        &mut self,
        t: f64,
        z: &Bound<'_, PyAny>,
        R: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Option<PyInnovation>> {
        let p = self.components;
        let m = match R.filter(|r| !r.is_none()) {
            Some(r) => measurement(t, z, r, p, self.filter.time())?,
            None => {
                let zero = 0.0_f64.into_pyobject(z.py())?.into_any();
                let mut m = measurement(t, z, &zero, p, self.filter.time())?;
                m.noise = self.r.clone();
                m
            }
        };
        Ok(self.filter.update(&m).py()?.map(PyInnovation::from))
    }

    /// Runs the measurements ``(t[i], z[i])`` (``z`` of shape ``(N,)`` or ``(N, p)``, NaN for
    /// a missing component; the times in order, any spacing) with noise ``R`` on every one
    /// (default the constructor's). Returns ``(states, covariances, nis)``: ``(N, n)``,
    /// ``(N, n, n)`` and ``(N,)`` (NaN where nothing was measured). The work runs without the
    /// GIL. On an error (``.index`` names the measurement) the measurements before it are
    /// taken.
    #[allow(non_snake_case)]
    #[pyo3(signature = (t, z, R = None))]
    fn update_many<'py>(
        &mut self,
        py: Python<'py>,
        t: &Bound<'py, PyAny>,
        z: &Bound<'py, PyAny>,
        R: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let mut rows = self.rows(t, z, R)?;
        let disorder = out_of_order(self.filter.time(), &rows);
        if let Some((k, _, _)) = disorder {
            rows.truncate(k);
        }
        let mut run = Run::new(rows.len(), self.filter.state().len());
        let filter = &mut self.filter;
        py.detach(|| {
            rows.iter().enumerate().try_for_each(|(i, m)| {
                let stats = filter
                    .update_stats(m)
                    .map_err(|e| seqsmooth::Error::InBatch {
                        index: i,
                        source: Box::new(e),
                    })?;
                run.record(i, filter.state(), filter.covariance(), stats.map(|s| s.nis));
                Ok::<(), seqsmooth::Error>(())
            })
        })
        .py()?;
        if let Some((k, t, previous)) = disorder {
            return Err(before(t, previous, Some(k)));
        }
        run.into_tuple(py)
    }

    /// The Rauch–Tung–Striebel smoother over the measurements (as ``update_many`` takes them),
    /// from this filter's current state (the filter itself is not changed): at each
    /// measurement's time the estimate from all of them. Returns ``(states, covariances)``,
    /// ``(N, n)`` and ``(N, n, n)``; with ``return_gains``, also the smoother gains ``C[k] =
    /// P[k] Φᵀ Pp[k]⁻¹`` and the predicted covariances ``Pp[k]`` out of each measurement (the
    /// last gain 0, the last ``Pp`` its own covariance: filterpy's ``rts_smoother``'s ``K``
    /// and ``Pp``), from the same pass.
    #[allow(non_snake_case)]
    #[pyo3(signature = (t, z, R = None, return_gains = false))]
    fn smooth<'py>(
        &self,
        py: Python<'py>,
        t: &Bound<'py, PyAny>,
        z: &Bound<'py, PyAny>,
        R: Option<&Bound<'py, PyAny>>,
        return_gains: bool,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let rows = self.rows(t, z, R)?;
        if let Some((k, t, previous)) = out_of_order(self.filter.time(), &rows) {
            return Err(before(t, previous, Some(k)));
        }
        let filter = self.filter.clone();
        let run = py.detach(|| smoother::smooth_flat(filter, &rows)).py()?;
        smoothed_run(py, run, return_gains)
    }

    /// The fixed-lag smoother over the measurements (as ``smooth`` takes them; ``R`` ``None``
    /// for the filter's own), from this filter's current state (the filter itself is not
    /// changed): each measurement's estimate from the ``lag`` measurements after it (the last
    /// ``lag`` from all of them; a ``lag`` of at least their number gives ``smooth``'s), by
    /// the library's ``FixedLagSmoother``, which holds ``lag + 1`` measurements however many
    /// there are. Returns ``(states, covariances)``, ``(N, dim)``
    /// and ``(N, dim, dim)``; an error's ``.index`` names the measurement.
    #[allow(non_snake_case)]
    #[pyo3(signature = (t, z, R, lag))]
    fn fixed_lag_smoother<'py>(
        &self,
        py: Python<'py>,
        t: &Bound<'py, PyAny>,
        z: &Bound<'py, PyAny>,
        R: Option<&Bound<'py, PyAny>>,
        lag: usize,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let rows = self.rows(t, z, R)?;
        if let Some((k, t, previous)) = out_of_order(self.filter.time(), &rows) {
            return Err(before(t, previous, Some(k)));
        }
        let smoother = FixedLagSmoother::new(self.filter.clone(), lag);
        let n = self.filter.state().len();
        py.detach(|| lagged(smoother, &rows, n))
            .py()?
            .into_tuple(py)
    }

    fn __repr__(&self) -> String {
        format!(
            "ContinuousKalmanFilter(states={}, components={}, time={:?})",
            self.filter.state().len(),
            self.components,
            self.filter.time()
        )
    }
}

impl PyContinuousKalmanFilter {
    /// The measurements of a batch with `R`, or the constant `R` where none is given.
    fn rows(
        &self,
        t: &Bound<'_, PyAny>,
        z: &Bound<'_, PyAny>,
        r: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Vec<Measurement>> {
        let p = self.components;
        match r.filter(|r| !r.is_none()) {
            Some(r) => measurements(t, z, r, p),
            None => {
                let zero = 0.0_f64.into_pyobject(z.py())?.into_any();
                let mut rows = measurements(t, z, &zero, p)?;
                for m in &mut rows {
                    m.noise = self.r.clone();
                }
                Ok(rows)
            }
        }
    }
}

/// `R` as its `p × p` matrix.
fn full(r: &NoiseCovariance, p: usize) -> DMatrix<f64> {
    match r {
        NoiseCovariance::Identity => DMatrix::identity(p, p),
        NoiseCovariance::Variances(v) => DMatrix::from_diagonal(&DVector::from_column_slice(v)),
        NoiseCovariance::Full(m) => m.clone(),
    }
}
