//! The Kalman filter over the polynomial model as a Python class, `KalmanFilter`: the
//! library's `kalman::KalmanFilter` with `PolynomialDynamics` (degree `m` on `axes` axes, the
//! state ordered derivative then axis), a linear observation (the positions by default),
//! optional white-noise driving of the highest derivative (`q`, Morrison (15.2.23) over each
//! actual step) and optional fading memory (`beta` per unit time or `theta` per update, ch.
//! 14); and its Rauch–Tung–Striebel smoother.

use crate::arrays::{matrix, series, table, times};
use crate::errors::{raise, IntoPy, Kind};
use crate::fixed_lag::lagged;
use crate::persist;
use nalgebra::{DMatrix, DVector};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use seqsmooth::discount::Discount;
use seqsmooth::estimate::batch::NoiseCovariance;
use seqsmooth::estimate::gauss_newton::Measurement;
use seqsmooth::kalman::filter::Innovation;
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::kalman::{smoother, FixedLagSmoother, KalmanFilter};
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::observation::{LinearObservation, Observation};

type Linear = KalmanFilter<PolynomialDynamics, LinearObservation>;

/// What one update saw: the innovation `ν = z − M X_{n,n−1}` on the present components, its
/// covariance `V = M S Mᵀ + R`, the gain, the NIS `νᵀ V⁻¹ ν` and the log-likelihood.
#[pyclass(name = "Innovation", module = "seqsmooth", frozen)]
pub struct PyInnovation {
    pub(crate) inner: Innovation,
}

#[pymethods]
impl PyInnovation {
    /// The components used (the present ones), in the observation's order.
    #[getter]
    fn components(&self) -> Vec<usize> {
        self.inner.components.clone()
    }
    /// ``ν`` on those components.
    #[getter]
    fn innovation<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.innovation.as_slice())
    }
    /// ``V = M S Mᵀ + R``.
    #[getter]
    fn covariance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        square(py, &self.inner.covariance)
    }
    /// The gain ``S Mᵀ V⁻¹``, states × components.
    #[getter]
    fn gain<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let g = &self.inner.gain;
        matrix(py, g.transpose().as_slice().to_vec(), g.nrows(), g.ncols())
    }
    /// ``νᵀ V⁻¹ ν``, χ² with ``len(components)`` degrees of freedom for a consistent filter.
    #[getter]
    fn nis(&self) -> f64 {
        self.inner.nis
    }
    /// ``−(NIS + ln det V + p ln 2π)/2``.
    #[getter]
    fn log_likelihood(&self) -> f64 {
        self.inner.log_likelihood
    }
    fn __repr__(&self) -> String {
        format!(
            "Innovation(components={:?}, nis={:?}, log_likelihood={:?})",
            self.inner.components, self.inner.nis, self.inner.log_likelihood
        )
    }
}

impl From<Innovation> for PyInnovation {
    fn from(inner: Innovation) -> Self {
        Self { inner }
    }
}

/// A symmetric (or any square) matrix as a numpy array.
pub(crate) fn square<'py>(py: Python<'py>, m: &DMatrix<f64>) -> PyResult<Bound<'py, PyAny>> {
    matrix(py, m.transpose().as_slice().to_vec(), m.nrows(), m.ncols())
}

/// A vector of `n` from a scalar (every entry), or a matrix `n × n` from a scalar (times the
/// identity), a vector (the diagonal) or a matrix.
pub(crate) fn square_from(obj: &Bound<'_, PyAny>, n: usize, name: &str) -> PyResult<DMatrix<f64>> {
    if let Ok(v) = obj.extract::<f64>() {
        return Ok(DMatrix::from_diagonal_element(n, n, v));
    }
    let (values, rows, cols) = table(obj, name)?;
    let v = values.as_slice();
    match (rows, cols) {
        (r, 1) if r == n => Ok(DMatrix::from_diagonal(&DVector::from_column_slice(v))),
        (r, c) if r == n && c == n => Ok(DMatrix::from_row_slice(n, n, v)),
        (r, c) => Err(raise(
            Kind::InvalidInput,
            format!("{name} is {r}x{c}: it must be a number, {n} variances or {n}x{n}"),
            None,
        )),
    }
}

/// A state a setter hands in (`n` values: the library checks the length and that they are
/// finite).
pub(crate) fn state_from(obj: &Bound<'_, PyAny>) -> PyResult<DVector<f64>> {
    Ok(DVector::from_column_slice(series(obj, "state")?.as_slice()))
}

/// A covariance a setter hands in: a number (times the identity), `n` variances (the
/// diagonal) or a matrix of any shape, which the library checks (`n × n`, finite, symmetric,
/// positive semidefinite; a refusal naming `P`).
pub(crate) fn covariance_from(obj: &Bound<'_, PyAny>, n: usize) -> PyResult<DMatrix<f64>> {
    if let Ok(v) = obj.extract::<f64>() {
        return Ok(DMatrix::from_diagonal_element(n, n, v));
    }
    let (values, rows, cols) = table(obj, "covariance")?;
    let v = values.as_slice();
    Ok(match (rows, cols) {
        (r, 1) if r == n && n > 1 => DMatrix::from_diagonal(&DVector::from_column_slice(v)),
        (r, c) => DMatrix::from_row_slice(r, c, v),
    })
}

/// The measurement noise of `p` components from `R`: a variance for every component, `p`
/// variances, or `p × p`.
pub(crate) fn noise(obj: &Bound<'_, PyAny>, p: usize) -> PyResult<NoiseCovariance> {
    if let Ok(v) = obj.extract::<f64>() {
        return Ok(NoiseCovariance::Variances(vec![v; p]));
    }
    let (values, rows, cols) = table(obj, "R")?;
    match (rows, cols) {
        (r, 1) if r == p => Ok(NoiseCovariance::Variances(values.as_slice().to_vec())),
        (r, c) if r == p && c == p => Ok(NoiseCovariance::Full(DMatrix::from_row_slice(
            p,
            p,
            values.as_slice(),
        ))),
        (r, c) => Err(raise(
            Kind::InvalidInput,
            format!("R is {r}x{c}: it must be a number, {p} variances or {p}x{p}"),
            None,
        )),
    }
}

/// The measurements `(t[i], z[i])` with noise `R`: `z` is `n` values (one component) or
/// `n × p`; NaN marks a missing component.
pub(crate) fn measurements(
    t: &Bound<'_, PyAny>,
    z: &Bound<'_, PyAny>,
    r: &Bound<'_, PyAny>,
    p: usize,
) -> PyResult<Vec<Measurement>> {
    let ts = times(t, "t")?;
    let (zs, rows, cols) = table(z, "z")?;
    let t = ts.as_slice();
    if rows != t.len() || cols != p {
        return Err(raise(
            Kind::InvalidInput,
            format!(
                "z is {rows}x{cols} for {} times: it must hold {p} component(s) per time",
                t.len()
            ),
            None,
        ));
    }
    if t.is_empty() {
        return Err(raise(Kind::InvalidInput, "t and z are empty", None));
    }
    let noise = noise(r, p)?;
    Ok(t.iter()
        .zip(zs.as_slice().chunks_exact(p))
        .map(|(&time, row)| Measurement {
            time,
            values: row.iter().map(|&v| (!v.is_nan()).then_some(v)).collect(),
            noise: noise.clone(),
        })
        .collect())
}

/// The observation matrix `M` (components × `n` states) from the caller's, or the positions
/// of `axes` axes (`[I_axes, 0, …]`).
pub(crate) fn observation_from(
    observation: Option<&Bound<'_, PyAny>>,
    axes: usize,
    n: usize,
) -> PyResult<LinearObservation> {
    match observation {
        None => LinearObservation::new(DMatrix::from_fn(axes, n, |i, j| f64::from(i == j))).py(),
        Some(m) => {
            let (values, rows, cols) = table(m, "observation")?;
            if cols != n {
                return Err(raise(
                    Kind::InvalidInput,
                    format!("observation is {rows}x{cols}: it needs {n} columns (states)"),
                    None,
                ));
            }
            LinearObservation::new(DMatrix::from_row_slice(rows, cols, values.as_slice())).py()
        }
    }
}

/// The fading discount by the names of every front end (docs/names.md): `theta` per `tau` of
/// time, or `theta_per_update`, by the library's rule (`Discount::from_names`); `beta`, the
/// old discount per unit of time, refused with its new spelling.
pub(crate) fn discount_from(
    theta: Option<f64>,
    tau: Option<f64>,
    theta_per_update: Option<f64>,
    beta: Option<f64>,
) -> PyResult<Option<Discount>> {
    if let Some(b) = beta {
        return Err(raise(
            Kind::Parameter,
            format!(
                "beta is gone: a discount of {b} per unit of time is now theta={b}, tau=1.0 \
                 (and theta alone meant per update: now theta_per_update)"
            ),
            None,
        ));
    }
    Discount::from_names(theta, tau, theta_per_update).py()
}

/// One measurement `(t, z)` of `p` components (a number, or one value per component; NaN
/// a missing one) with noise `R`, not before the filter's time `now`.
pub(crate) fn measurement(
    t: f64,
    z: &Bound<'_, PyAny>,
    r: &Bound<'_, PyAny>,
    p: usize,
    now: f64,
) -> PyResult<Measurement> {
    let values: Vec<f64> = match z.extract::<f64>() {
        Ok(v) => vec![v],
        Err(_) => series(z, "z")?.as_slice().to_vec(),
    };
    if values.len() != p {
        return Err(raise(
            Kind::InvalidInput,
            format!(
                "z has {} values: the observation has {p} components",
                values.len()
            ),
            None,
        ));
    }
    if t < now {
        return Err(before(t, now, None));
    }
    Ok(Measurement {
        time: t,
        values: values.iter().map(|&v| (!v.is_nan()).then_some(v)).collect(),
        noise: noise(r, p)?,
    })
}

/// A measurement at `t` before the time `previous` the filter has reached, as an error.
pub(crate) fn before(t: f64, previous: f64, index: Option<usize>) -> PyErr {
    let at = index.map_or(String::new(), |i| format!("sample {i} of the batch: "));
    raise(
        Kind::InvalidInput,
        format!(
            "{at}time {t} is before the previous time {previous}: measurements must come in \
             time order (predict() goes anywhere)"
        ),
        index,
    )
}

/// The first measurement of `rows` before its predecessor (the first, before `start`): its
/// index, time and the predecessor's time. (A NaN time is the library's to refuse.)
pub(crate) fn out_of_order(start: f64, rows: &[Measurement]) -> Option<(usize, f64, f64)> {
    let mut previous = start;
    for (k, m) in rows.iter().enumerate() {
        if m.time < previous {
            return Some((k, m.time, previous));
        }
        if !m.time.is_nan() {
            previous = m.time;
        }
    }
    None
}

/// The Kalman filter (Morrison chs. 12, 15; fading memory ch. 14) over the polynomial model:
/// degree ``degree`` on ``axes`` axes, the state ``(x, y, …, x', y', …)`` (derivative, then
/// axis), unscaled derivatives in the caller's time units.
///
/// Parameters
/// ----------
/// degree : int
///     The polynomial degree of the motion on each axis (1: constant velocity).
/// x0, P0 : array_like
///     The prior state and covariance (a number: that variance on every state; a vector: the
///     diagonal) at time ``t0``.
/// t0 : float
///     The prior's time.
/// axes : int
///     The number of axes (default 1).
/// q : float
///     The spectral density of the white noise driving the highest derivative of each axis
///     (value²/time^(2m+1)); 0 for none. ``Q`` is integrated over each actual step.
/// observation : array_like, optional
///     The observation matrix ``M``, components × states; default the positions
///     (``[I_axes, 0, …]``).
/// theta, tau : float, optional
///     Fading memory (ch. 14): the discount ``theta`` in (0, 1) per span ``tau`` of time (an
///     observation ``dt`` old weighs ``theta ** (dt / tau)``, as in ``FadingMemory``); both or
///     neither. The covariance reported is then the true one, not the recursion's own matrix.
/// theta_per_update : float, optional
///     Fading memory with the discount in (0, 1) per update, whatever the spacing (what
///     ``theta`` alone meant before; ``beta`` per unit of time is now ``theta``, ``tau=1.0``).
///
/// The update is Joseph's form (12.3.7); a missing component (NaN) is left out, a time with
/// none is a prediction only.
#[pyclass(name = "KalmanFilter", module = "seqsmooth")]
pub struct PyKalmanFilter {
    filter: Linear,
    /// The observation's components `p`.
    components: usize,
}

/// A smoothed run as ``(states, covariances)``, with ``(gains, predicted_covariances)`` after
/// them when `return_gains` (the last ``Pp`` the last covariance).
pub(crate) fn smoothed_run<'py>(
    py: Python<'py>,
    mut run: smoother::SmoothedRun,
    return_gains: bool,
) -> PyResult<Bound<'py, PyTuple>> {
    let (n, count) = (run.dimension, run.times.len());
    let nn = n * n;
    let cube = |v: Vec<f64>| -> PyResult<Bound<'py, PyAny>> {
        Ok(PyArray1::from_vec(py, v).reshape([count, n, n])?.into_any())
    };
    let mut out = vec![matrix(py, std::mem::take(&mut run.states), count, n)?];
    if return_gains {
        // A gain is not symmetric: column-major to row-major. A covariance is.
        let mut gains = vec![0.0; count * nn];
        for k in 0..count {
            for i in 0..n {
                for j in 0..n {
                    gains[k * nn + i * n + j] = run.gains[k * nn + i + j * n];
                }
            }
        }
        let mut predicted = Vec::with_capacity(count * nn);
        for k in 0..count {
            predicted.extend_from_slice(
                run.predicted_covariance(k)
                    .unwrap_or(&run.covariances[k * nn..(k + 1) * nn]),
            );
        }
        out.extend([cube(run.covariances)?, cube(gains)?, cube(predicted)?]);
    } else {
        out.push(cube(run.covariances)?);
    }
    PyTuple::new(py, out)
}

#[pymethods]
impl PyKalmanFilter {
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
        let filter: Linear = persist::load(state)?;
        let components = filter.observation().components();
        Ok(Self { filter, components })
    }

    #[new]
    #[allow(non_snake_case, clippy::too_many_arguments)]
    #[pyo3(signature = (degree, x0, P0, t0 = 0.0, axes = 1, q = 0.0, observation = None, theta = None, tau = None, theta_per_update = None, beta = None))]
    fn new(
        degree: usize,
        x0: &Bound<'_, PyAny>,
        P0: &Bound<'_, PyAny>,
        t0: f64,
        axes: usize,
        q: f64,
        observation: Option<&Bound<'_, PyAny>>,
        theta: Option<f64>,
        tau: Option<f64>,
        theta_per_update: Option<f64>,
        beta: Option<f64>,
    ) -> PyResult<Self> {
        // The library's polynomial model: its degree, axes and states.
        let n = seqsmooth::polynomial::check_model(degree, axes).py()?;
        let (x, p0) = polynomial_prior(x0, P0, degree, axes, n)?;
        let observe = observation_from(observation, axes, n)?;
        let components = observe.components();
        let mut filter =
            KalmanFilter::new(PolynomialDynamics::new(degree, axes), observe, x, p0, t0).py()?;
        if q != 0.0 {
            filter = filter
                .with_process_noise(WhiteNoiseDerivative::new(degree, axes, q).py()?)
                .py()?;
        }
        if let Some(d) = discount_from(theta, tau, theta_per_update, beta)? {
            filter = filter.with_fading(d).py()?;
        }
        Ok(Self { filter, components })
    }

    /// The current estimate ``X``; settable (``n`` finite numbers, checked by the library;
    /// on an error the filter is unchanged).
    #[getter]
    fn state<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.filter.state().as_slice())
    }

    #[setter]
    fn set_state(&mut self, x: &Bound<'_, PyAny>) -> PyResult<()> {
        let (p, t) = (self.filter.covariance().clone(), self.filter.time());
        self.filter.set_estimate(state_from(x)?, p, t).py()
    }

    /// The covariance of ``X``'s errors (with fading memory, the true covariance); settable
    /// (finite, symmetric, positive semidefinite, checked by the library: a ``ParameterError``
    /// naming ``P`` otherwise, the filter unchanged; with fading memory the recursion's own
    /// matrix restarts at it, §14.5).
    #[getter]
    fn covariance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        square(py, self.filter.covariance())
    }

    #[setter]
    fn set_covariance(&mut self, p: &Bound<'_, PyAny>) -> PyResult<()> {
        let (x, t) = (self.filter.state().clone(), self.filter.time());
        let p = covariance_from(p, x.len())?;
        self.filter.set_estimate(x, p, t).py()
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

    /// Carries the estimate and its covariance to time ``t`` (no measurement).
    fn predict(&mut self, t: f64) -> PyResult<()> {
        self.filter.predict(t).py()
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
        let m = measurement(t, z, R, self.filter_components(), self.filter.time())?;
        Ok(self
            .filter
            .update(&m)
            .py()?
            .map(|inner| PyInnovation { inner }))
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
        let mut rows = measurements(t, z, R, self.filter_components())?;
        let disorder = out_of_order(self.filter.time(), &rows);
        if let Some((k, _, _)) = disorder {
            rows.truncate(k);
        }
        let n = self.filter.state().len();
        let mut states = vec![0.0; rows.len() * n];
        let mut covariances = vec![0.0; rows.len() * n * n];
        let mut nis = vec![f64::NAN; rows.len()];
        let filter = &mut self.filter;
        py.detach(|| {
            for (i, m) in rows.iter().enumerate() {
                let stats = filter
                    .update_stats(m)
                    .map_err(|e| seqsmooth::Error::InBatch {
                        index: i,
                        source: Box::new(e),
                    })?;
                if let Some(s) = stats {
                    nis[i] = s.nis;
                }
                states[i * n..(i + 1) * n].copy_from_slice(filter.state().as_slice());
                // Symmetric: column-major is row-major.
                covariances[i * n * n..(i + 1) * n * n]
                    .copy_from_slice(filter.covariance().as_slice());
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
        let nis = PyArray1::from_vec(py, nis).into_any();
        PyTuple::new(py, [states, covariances, nis])
    }

    /// The Rauch–Tung–Striebel smoother over the measurements, from this filter's current
    /// state (the filter itself is not changed): at each measurement's time the estimate from
    /// all of them. Returns ``(states, covariances)``, ``(n, dim)`` and ``(n, dim, dim)``;
    /// with ``return_gains``, also the smoother gains ``C[k] = P[k] Φᵀ Pp[k]⁻¹`` and the
    /// predicted covariances ``Pp[k]`` out of each measurement, ``(n, dim, dim)`` each (the
    /// last gain 0, the last ``Pp`` its own covariance: filterpy's ``rts_smoother``'s ``K``
    /// and ``Pp``), from the same pass.
    #[allow(non_snake_case)]
    #[pyo3(signature = (t, z, R, return_gains = false))]
    fn smooth<'py>(
        &self,
        py: Python<'py>,
        t: &Bound<'py, PyAny>,
        z: &Bound<'py, PyAny>,
        R: &Bound<'py, PyAny>,
        return_gains: bool,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let rows = measurements(t, z, R, self.filter_components())?;
        let filter = self.filter.clone();
        let run = py.detach(|| smoother::smooth_flat(filter, &rows)).py()?;
        smoothed_run(py, run, return_gains)
    }

    /// The fixed-lag smoother over the measurements (as ``smooth`` takes them), from this
    /// filter's current state (the filter itself is not changed): each measurement's estimate
    /// from the ``lag`` measurements after it (the last ``lag`` from all of them; a ``lag`` of
    /// at least their number gives ``smooth``'s), by the library's ``FixedLagSmoother``,
    /// which holds ``lag + 1`` measurements however many there are. Returns
    /// ``(states, covariances)``, ``(N, dim)``
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
        let rows = measurements(t, z, R, self.filter_components())?;
        let smoother = FixedLagSmoother::new(self.filter.clone(), lag);
        let n = self.filter.state().len();
        py.detach(|| lagged(smoother, &rows, n))
            .py()?
            .into_tuple(py)
    }

    fn __repr__(&self) -> String {
        format!(
            "KalmanFilter(states={}, time={:?})",
            self.filter.state().len(),
            self.filter.time()
        )
    }
}

impl PyKalmanFilter {
    fn filter_components(&self) -> usize {
        self.components
    }
}

/// The prior `x0`, `P0` of the polynomial model of degree `degree` on `axes` axes (`n` states,
/// from the library's `check_model`): `x0` of `n` values and `P0` an `n × n` covariance (a
/// number or a diagonal as `square_from` reads it); the Kalman, Bayes and unscented classes'
/// one reading of it.
#[allow(non_snake_case)]
pub(crate) fn polynomial_prior(
    x0: &Bound<'_, PyAny>,
    P0: &Bound<'_, PyAny>,
    degree: usize,
    axes: usize,
    n: usize,
) -> PyResult<(DVector<f64>, DMatrix<f64>)> {
    let x = series(x0, "x0")?;
    if x.as_slice().len() != n {
        return Err(raise(
            Kind::InvalidInput,
            format!(
                "x0 has {} values: degree {degree} on {axes} axes has {n} states",
                x.as_slice().len()
            ),
            None,
        ));
    }
    Ok((
        DVector::from_column_slice(x.as_slice()),
        square_from(P0, n, "P0")?,
    ))
}
