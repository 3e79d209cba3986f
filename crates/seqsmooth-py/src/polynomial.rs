//! The polynomial filters as Python classes: `ExpandingMemory`, `FadingMemory` and
//! `FixedMemory`, each a subclass of `PolynomialFilter`, which holds the library's filter and
//! owns every method (`update`, `update_many`, `estimate`, `estimate_at`). The numbers are the
//! library's: each class is built by the library's `FilterSpec`, and `update_many` runs the
//! library's row runner (`AnyFilter::run_rows`), as `seqsmooth filter` does, so the same
//! input gives the same bits.

use crate::arrays::{matrix, pair, zeros};
use crate::errors::{raise, IntoPy, Kind};
use crate::persist;
use numpy::{
    PyArray1, PyArray2, PyArrayDescrMethods, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use pyo3::types::{PySlice, PyTuple, PyType};
use seqsmooth::discount::Discount;
use seqsmooth::polynomial::fixed::FixedEngine;
use seqsmooth::polynomial::prior::Prior;
use seqsmooth::polynomial::rows::RowLayout;
use seqsmooth::polynomial::spec::{AnyFilter, FilterKind, FilterSpec};
use seqsmooth::{Engine, PolynomialFilter, PolynomialState};

/// Samples run between two checks for Ctrl-C (each run without the GIL).
const CHUNK: usize = 1 << 16;

/// The estimate of a polynomial filter at one time.
#[pyclass(name = "State", module = "seqsmooth", frozen)]
pub struct State {
    state: PolynomialState,
}

impl From<PolynomialState> for State {
    fn from(state: PolynomialState) -> Self {
        Self { state }
    }
}

#[pymethods]
impl State {
    /// The time the estimate is valid at.
    #[getter]
    fn time(&self) -> f64 {
        self.state.time
    }

    /// ``[x, x', x'', …]`` at ``time``: unscaled derivatives in the caller's time units.
    #[getter]
    fn derivatives<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.state.derivatives)
    }

    /// The covariance of the derivatives' errors, ``(m+1, m+1)``, or ``None`` when the
    /// filter was given no noise ``sigma``.
    #[getter]
    fn covariance<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.state
            .covariance
            .as_ref()
            .map(|c| {
                let n = c.nrows();
                // nalgebra is column-major; the covariance is symmetric, so this is row-major.
                matrix(py, c.as_slice().to_vec(), n, n)
            })
            .transpose()
    }

    /// The 1σ error of each derivative (the square roots of the covariance's diagonal), or
    /// ``None`` without a covariance.
    #[getter]
    fn std_devs<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.state.std_devs().map(|s| PyArray1::from_vec(py, s))
    }

    /// ``std_devs`` by its old name (kept: the same numbers).
    #[getter]
    fn sigma<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.std_devs(py)
    }

    fn __repr__(&self) -> String {
        format!(
            "State(time={:?}, derivatives={:?}, sigma={:?})",
            self.state.time,
            self.state.derivatives,
            self.state.std_devs()
        )
    }
}

/// The estimate of `filter` at `t` (without `t`, at its newest sample) as a [`State`]; why
/// there is none as the error.
pub(crate) fn state_of(filter: &dyn PolynomialFilter, t: Option<f64>) -> PyResult<State> {
    match t {
        None => filter.try_estimate().py().map(State::from),
        Some(t) if !t.is_finite() => Err(raise(
            Kind::InvalidInput,
            format!("time {t} is not finite"),
            None,
        )),
        Some(t) => filter.try_estimate_at(t).py().map(State::from),
    }
}

/// The base of the polynomial filters: ``update``, ``update_many``, ``estimate`` and
/// ``estimate_at`` (Morrison chs. 9, 13; Reyneke et al. 2012 on irregular times).
#[pyclass(name = "PolynomialFilter", module = "seqsmooth", subclass)]
pub struct PyPolynomialFilter {
    filter: AnyFilter,
}

impl PyPolynomialFilter {
    /// The filter `spec` describes.
    fn new(spec: FilterSpec) -> PyResult<PyClassInitializer<Self>> {
        let filter = spec.build().py()?;
        Ok(PyClassInitializer::from(Self { filter }))
    }
}

#[pymethods]
impl PyPolynomialFilter {
    /// The polynomial degree ``m``.
    #[getter]
    fn degree(&self) -> usize {
        self.filter.degree()
    }

    /// The number of samples taken.
    #[getter]
    fn samples(&self) -> u64 {
        self.filter.samples()
    }

    /// The newest sample's time, or ``None`` before the first.
    #[getter]
    fn last_time(&self) -> Option<f64> {
        self.filter.last_time()
    }

    /// Whether the filter has an estimate (enough samples at distinct times).
    #[getter]
    fn is_determined(&self) -> bool {
        self.filter.is_determined()
    }

    /// ``pickle`` support (``copy.copy`` and ``copy.deepcopy`` too): the filter's state in
    /// the library's saved form, restored bit for bit. Filters are mutable: a copy is a deep
    /// copy of the state, and the copy and the original then run apart.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        persist::reduce_saved(slf.as_any(), &slf.borrow().filter)
    }

    /// The filter ``__reduce__`` saved (a ``DamagedStateError`` if ``state`` is damaged or
    /// another class's).
    #[classmethod]
    fn _from_state<'py>(
        cls: &Bound<'py, PyType>,
        state: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let py = cls.py();
        let filter: AnyFilter = persist::load(state)?;
        let kind = filter.kind();
        let base = PyClassInitializer::from(Self { filter });
        let obj = match kind {
            FilterKind::Expanding => {
                Bound::new(py, base.add_subclass(PyExpandingMemory))?.into_any()
            }
            FilterKind::Fading => Bound::new(py, base.add_subclass(PyFadingMemory))?.into_any(),
            FilterKind::Fixed => Bound::new(py, base.add_subclass(PyFixedMemory))?.into_any(),
            FilterKind::Automatic => {
                return Err(persist::damaged("the state of an AutomaticFilter"))
            }
        };
        persist::of_class(obj, cls)
    }

    /// Takes one sample ``y`` at time ``t`` (after the previous sample's time).
    ///
    /// Raises
    /// ------
    /// InvalidInputError
    ///     ``t`` or ``y`` NaN or infinite, or ``t`` not after the previous time.
    fn update(&mut self, t: f64, y: f64) -> PyResult<()> {
        self.filter.update(t, y).py()
    }

    /// Takes the samples ``(t[i], y[i])`` in order and returns the estimate after each:
    /// an array ``(len(t), m+1)`` whose row ``i`` is ``[x, x', …, x^(m)]`` at ``t[i]`` from the
    /// samples up to ``i`` (NaN while the filter is not yet determined). With
    /// ``return_sigma=True`` also the 1σ errors, a second array of the same shape (the filter
    /// needs its noise ``sigma``): the two are views of one ``(len(t), 2(m+1))`` buffer, the
    /// rows ``d0..dM, s0..sM`` of ``seqsmooth filter --sigma``, written by the library's batch
    /// σ path (no covariance matrix per sample; 1.1-1.6× the plain call's time for the gain
    /// engines and fixed memory, the output being twice as large; under 2× for the exact
    /// engine at degrees to 8 into a reused ``out``, more into new arrays where clearing new
    /// memory is slow: BENCHMARKS.md). The rows are the library's row runner's,
    /// with its rule: a row the determined fit cannot give (a fading discount that
    /// underflowed, a number beyond the double range) is refused with its index.
    ///
    /// ``out``, a C-contiguous, writeable float64 array of that ``(len(t), m+1)`` or
    /// ``(len(t), 2(m+1))`` shape, is written instead of a new array and returned (with
    /// ``return_sigma``, as its two views): a caller running many batches reuses one buffer
    /// and pays for no new memory per call (on some systems the clearing of a new array's
    /// pages costs as much as the σ themselves: BENCHMARKS.md, "The batch σ path"). It must
    /// not share memory with ``t`` or ``y`` (refused), and, as with numpy's ``out=``, no other
    /// thread may use it during the call (the work runs without the GIL). On an error its
    /// rows before the refused sample hold their estimates; the rest are unspecified.
    ///
    /// The work runs without the GIL; Ctrl-C stops it between blocks of 65,536 samples, the
    /// samples before the block taken.
    ///
    /// Raises
    /// ------
    /// InvalidInputError
    ///     NaN or infinite values, times that do not increase (``.index`` is the sample's
    ///     position; the samples before it are taken), mismatched or empty arrays; an ``out``
    ///     of the wrong shape, not C-contiguous or not writeable (nothing is taken).
    /// InvalidTypeError
    ///     arrays that do not hold real numbers; an ``out`` that is not a float64 array.
    /// NotDeterminedError, NumericalError
    ///     a row refused (``.index`` its position).
    #[pyo3(signature = (t, y, return_sigma = false, *, out = None))]
    fn update_many<'py>(
        &mut self,
        py: Python<'py>,
        t: &Bound<'py, PyAny>,
        y: &Bound<'py, PyAny>,
        return_sigma: bool,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (ts, ys) = pair(t, y)?;
        let (t, y) = (ts.as_slice(), ys.as_slice());
        let (n, w) = (t.len(), self.filter.degree() + 1);
        let layout = RowLayout {
            sigma: return_sigma,
            ..RowLayout::default()
        };
        let stride = self.filter.stride(layout);
        let rows = match out {
            Some(given) => output_buffer(given, n, stride, [t, y])?,
            None => zeros(py, n, stride),
        };
        {
            let mut buffer = writable_rows(&rows)?;
            let out = buffer.as_slice_mut().expect("checked by writable_rows");
            for start in (0..n).step_by(CHUNK) {
                let end = (start + CHUNK).min(n);
                let (tc, yc) = (&t[start..end], &y[start..end]);
                let oc = &mut out[start * stride..end * stride];
                let filter = &mut self.filter;
                py.detach(|| filter.run_rows(tc, yc, oc, layout))
                    .py_at(start)?;
                py.check_signals()?;
            }
        }
        if !return_sigma {
            return Ok(rows.into_any());
        }
        // Rows [d, s]: the two arrays are views of the one buffer (no copy).
        let all = PySlice::full(py);
        let d = rows.get_item((&all, PySlice::new(py, 0, w as isize, 1)))?;
        let s = rows.get_item((&all, PySlice::new(py, w as isize, stride as isize, 1)))?;
        Ok((d, s).into_pyobject(py)?.into_any())
    }

    /// The estimate at the newest sample's time.
    ///
    /// Raises
    /// ------
    /// TooFewSamplesError, NumericalError
    ///     no estimate yet, or none to working accuracy (the reason in the message).
    fn estimate(&self) -> PyResult<State> {
        state_of(&self.filter, None)
    }

    /// The estimate carried to time ``t`` (a prediction ahead of the newest sample, a
    /// retrodiction before it), its covariance carried with it.
    fn estimate_at(&self, t: f64) -> PyResult<State> {
        state_of(&self.filter, Some(t))
    }

    fn __repr__(slf: &Bound<'_, Self>) -> PyResult<String> {
        let this = slf.borrow();
        Ok(format!(
            "{}(degree={}, samples={}, last_time={:?})",
            slf.get_type().name()?,
            this.filter.degree(),
            this.filter.samples(),
            this.filter.last_time()
        ))
    }
}

/// The caller's `out` for [`PyPolynomialFilter::update_many`]: a float64 array (native byte
/// order) of shape `n × stride`, C-contiguous, sharing no memory with the inputs, checked
/// before any sample is taken — a wrong dtype or object is [`Kind::InvalidType`], a wrong
/// shape, order or overlap [`Kind::InvalidInput`], as `arrays`' checks of inputs are. The
/// overlap is found from the addresses before any slice of `out` is made (numpy's own check
/// of a shared base does not see two `frombuffer` arrays over one buffer); writeability and
/// alignment are checked as it is borrowed ([`writable_rows`]).
fn output_buffer<'py>(
    out: &Bound<'py, PyAny>,
    n: usize,
    stride: usize,
    inputs: [&[f64]; 2],
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let need = format!("({n}, {stride})");
    let untyped = out.cast::<PyUntypedArray>().map_err(|_| {
        let kind = out.get_type().name().map_or("?".into(), |s| s.to_string());
        let why = format!("out must be a float64 numpy array of shape {need}, not a {kind}");
        raise(Kind::InvalidType, why, None)
    })?;
    let dtype = untyped.dtype();
    if !dtype.is_equiv_to(&numpy::dtype::<f64>(out.py())) {
        let why = format!("out has dtype {dtype}; it must be float64 in native byte order");
        return Err(raise(Kind::InvalidType, why, None));
    }
    if untyped.shape() != [n, stride] {
        let got = out.getattr("shape")?.str()?.to_string();
        let why = format!("out has shape {got}; these {n} samples need {need}");
        return Err(raise(Kind::InvalidInput, why, None));
    }
    if !untyped.is_c_contiguous() {
        return Err(raise(Kind::InvalidInput, "out is not C-contiguous", None));
    }
    let array = untyped.cast::<PyArray2<f64>>()?;
    let start = array.data() as usize;
    let end = start + n * stride * std::mem::size_of::<f64>();
    for (name, input) in ["t", "y"].into_iter().zip(inputs) {
        let other = input.as_ptr_range();
        if start < other.end as usize && (other.start as usize) < end {
            let why = format!("out shares memory with {name}: give it a buffer of its own");
            return Err(raise(Kind::InvalidInput, why, None));
        }
    }
    Ok(array.clone())
}

/// `rows` borrowed for writing, refused when it is read-only, borrowed elsewhere, or cannot
/// be written as a contiguous, aligned float64 slice.
fn writable_rows<'py>(
    rows: &Bound<'py, PyArray2<f64>>,
) -> PyResult<numpy::PyReadwriteArray2<'py, f64>> {
    let mut buffer = rows.try_readwrite().map_err(|e| {
        let why = format!("out is not writeable, or is in use by another array ({e})");
        raise(Kind::InvalidInput, why, None)
    })?;
    if buffer.as_slice_mut().is_err() {
        let why = "out could not be written as a contiguous, aligned float64 array";
        return Err(raise(Kind::InvalidInput, why, None));
    }
    Ok(buffer)
}

/// The engine named `name`: `"exact"` or `"gain"`.
pub(crate) fn engine(name: &str) -> PyResult<Engine> {
    match name {
        "exact" => Ok(Engine::Exact),
        "gain" => Ok(Engine::Gain),
        other => Err(raise(
            Kind::Parameter,
            format!("engine {other:?} is not one of 'exact', 'gain'"),
            None,
        )),
    }
}

/// The fixed-memory engine named `name`: `"adaptive"`, `"sliding"`, `"direct"` or
/// `"irregular"`.
pub(crate) fn fixed_engine(name: &str) -> PyResult<FixedEngine> {
    match name {
        "adaptive" => Ok(FixedEngine::Adaptive),
        "sliding" => Ok(FixedEngine::Sliding),
        "direct" => Ok(FixedEngine::Direct),
        "irregular" => Ok(FixedEngine::Irregular),
        other => Err(raise(
            Kind::Parameter,
            format!("engine {other:?} is not one of 'adaptive', 'sliding', 'direct', 'irregular'"),
            None,
        )),
    }
}

/// The prior of an expanding or fading memory from ``x0`` (the ``degree + 1`` derivatives
/// at ``t0``) and ``P0`` (their covariance: a number, the diagonal or the matrix), both or
/// neither; checked by the library (``polynomial::prior::Prior``).
#[allow(non_snake_case)]
fn prior_from(
    x0: Option<&Bound<'_, PyAny>>,
    P0: Option<&Bound<'_, PyAny>>,
    t0: f64,
    degree: usize,
) -> PyResult<Option<Prior>> {
    match (x0, P0) {
        (None, None) => Ok(None),
        (Some(x0), Some(p0)) => {
            let n = degree + 1;
            let x = crate::arrays::series(x0, "x0")?.as_slice().to_vec();
            let p = crate::kalman::square_from(p0, n, "P0")?;
            Prior::new(t0, x, p).py().map(Some)
        }
        _ => Err(raise(
            Kind::Parameter,
            "x0 and P0 go together: give both for a prior, or neither",
            None,
        )),
    }
}

/// The expanding-memory polynomial filter of degree ``degree`` (Morrison ch. 9; Reyneke et
/// al. 2012 eqs. 20-27 on irregular times): the least-squares polynomial through every
/// sample so far, updated recursively.
///
/// Parameters
/// ----------
/// degree : int
///     ``m``, 0 to 24 (0 to 10 with ``engine="gain"``).
/// engine : {"exact", "gain"}
///     ``"exact"``: recursive least squares, exact on any timestamps. ``"gain"``: Morrison's
///     fixed-gain recursion (9.3.x), exact on evenly spaced times only.
/// sigma : float, optional
///     The white noise's standard deviation: the estimates then carry their covariance.
/// x0, P0 : array_like, optional
///     A prior (keywords): the ``degree + 1`` derivatives ``x, x', …`` at ``t0`` and their
///     covariance (a number, the diagonal or the matrix; positive definite), both or neither.
///     The filter starts from it instead of from no information: the Bayes filter (ch. 10),
///     whose estimate is the least-squares fit with the prior as ``degree + 1`` more
///     observations. Needs ``sigma`` (the prior is weighed against the samples by it) and
///     the exact engine; the first sample may be at ``t0``.
/// t0 : float
///     The prior's time (default 0).
#[pyclass(name = "ExpandingMemory", module = "seqsmooth", extends = PyPolynomialFilter)]
pub struct PyExpandingMemory;

#[pymethods]
impl PyExpandingMemory {
    #[new]
    #[allow(non_snake_case)]
    #[pyo3(signature = (degree, engine = "exact", sigma = None, *, x0 = None, P0 = None, t0 = 0.0))]
    fn new(
        degree: usize,
        engine: &str,
        sigma: Option<f64>,
        x0: Option<&Bound<'_, PyAny>>,
        P0: Option<&Bound<'_, PyAny>>,
        t0: f64,
    ) -> PyResult<PyClassInitializer<Self>> {
        let spec = FilterSpec {
            engine: self::engine(engine)?,
            sigma,
            prior: prior_from(x0, P0, t0, degree)?,
            ..FilterSpec::new(FilterKind::Expanding, degree)
        };
        Ok(PyPolynomialFilter::new(spec)?.add_subclass(Self))
    }
}

/// The fading-memory polynomial filter of degree ``degree`` (Morrison ch. 13; Reyneke et al.
/// 2012 on irregular times): the polynomial fitted with weight ``theta**((t_n − t_k)/tau)``
/// on sample ``k``.
///
/// Parameters
/// ----------
/// degree : int
///     ``m``, 0 to 24 (0 to 10 with ``engine="gain"``).
/// theta : float
///     The discount per span ``tau`` of time, ``0 < theta < 1`` (this or
///     ``theta_per_update``).
/// tau : float, optional
///     The span of time ``theta`` applies to (default 1 with ``theta``).
/// engine : {"exact", "gain"}
///     As for :class:`ExpandingMemory`.
/// sigma : float, optional
///     The white noise's standard deviation: the estimates then carry their covariance.
/// theta_per_update : float, optional
///     The discount per sample whatever the spacing, ``0 < theta_per_update < 1``, instead of
///     ``theta``: weight ``theta_per_update**(n − k)`` (the same names as ``KalmanFilter``'s).
/// x0, P0 : array_like, optional
///     A prior (keywords): the ``degree + 1`` derivatives ``x, x', …`` at ``t0`` and their
///     covariance (a number, the diagonal or the matrix; positive definite), both or neither.
///     The filter starts from it instead of from no information: the Bayes filter (ch. 10),
///     whose estimate is the least-squares fit with the prior as ``degree + 1`` more
///     observations, discounted like a sample at ``t0`` ((14.4.26)-(14.4.32)). Needs
///     ``sigma`` (the prior is weighed against the samples by it) and the exact engine; the
///     first sample may be at ``t0``.
/// t0 : float
///     The prior's time (default 0).
#[pyclass(name = "FadingMemory", module = "seqsmooth", extends = PyPolynomialFilter)]
pub struct PyFadingMemory;

#[pymethods]
impl PyFadingMemory {
    #[new]
    #[allow(non_snake_case, clippy::too_many_arguments)]
    #[pyo3(signature = (degree, theta = None, tau = None, engine = "exact", sigma = None,
        theta_per_update = None, *, x0 = None, P0 = None, t0 = 0.0))]
    fn new(
        degree: usize,
        theta: Option<f64>,
        tau: Option<f64>,
        engine: &str,
        sigma: Option<f64>,
        theta_per_update: Option<f64>,
        x0: Option<&Bound<'_, PyAny>>,
        P0: Option<&Bound<'_, PyAny>>,
        t0: f64,
    ) -> PyResult<PyClassInitializer<Self>> {
        // `tau` defaults to 1 with `theta` (as it always did).
        let tau = tau.or(theta.map(|_| 1.0));
        if Discount::from_names(theta, tau, theta_per_update)
            .py()?
            .is_none()
        {
            return Err(raise(
                Kind::Parameter,
                "FadingMemory needs a discount: theta (per tau of time) or theta_per_update",
                None,
            ));
        }
        let spec = FilterSpec {
            theta,
            tau,
            theta_per_update,
            engine: self::engine(engine)?,
            sigma,
            prior: prior_from(x0, P0, t0, degree)?,
            ..FilterSpec::new(FilterKind::Fading, degree)
        };
        Ok(PyPolynomialFilter::new(spec)?.add_subclass(Self))
    }
}

/// The fixed-memory polynomial filter (Morrison ch. 7): the least-squares polynomial of
/// degree ``degree`` through the newest ``window`` samples.
///
/// Parameters
/// ----------
/// degree : int
///     ``m``, 0 to 24.
/// window : int
///     The number of samples in the window, at least ``degree + 1`` (Morrison's ``L + 1``,
///     savgol's ``window_length``).
/// engine : {"adaptive", "sliding", "direct", "irregular"}
///     ``"adaptive"`` (default): the sliding moments while the steps are even, the QR refit
///     of the window from the first uneven step on; ``"sliding"`` and ``"direct"`` need evenly
///     spaced times; ``"irregular"`` refits every window by QR.
/// sigma : float, optional
///     The white noise's standard deviation: the estimates then carry their covariance.
#[pyclass(name = "FixedMemory", module = "seqsmooth", extends = PyPolynomialFilter)]
pub struct PyFixedMemory;

#[pymethods]
impl PyFixedMemory {
    #[new]
    #[pyo3(signature = (degree, window, engine = "adaptive", sigma = None))]
    fn new(
        degree: usize,
        window: usize,
        engine: &str,
        sigma: Option<f64>,
    ) -> PyResult<PyClassInitializer<Self>> {
        let spec = FilterSpec {
            window: Some(window),
            fixed_engine: fixed_engine(engine)?,
            sigma,
            ..FilterSpec::new(FilterKind::Fixed, degree)
        };
        Ok(PyPolynomialFilter::new(spec)?.add_subclass(Self))
    }
}
