//! Gauss rules for any positive measure, polynomial samples (Villien & Ostertag 2009), their
//! online smoother, the maximum-likelihood curve fit that PAML runs on them, and Luenberger's
//! gains (1967): `gauss_rule`, `polynomial_samples`, `OnlineSmoother`, `fit_curve`,
//! `cramer_rao_bound`, `CurveFit`, `luenberger_gains`.

use crate::arrays::{series, table, times};
use crate::errors::{raise, IntoPy, Kind};
use crate::kalman::square;
use crate::persist;
use nalgebra::DMatrix;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyList, PyTuple};
use seqsmooth::basis::{GaussRule, Jacobi};
use seqsmooth::error::Param;
use seqsmooth::estimate::curve::{self, CurveFit, CurveModel};
use seqsmooth::paml::{OnlineSmoother, PolynomialSamples, SmootherGains};
use seqsmooth::polynomial::expanding::continuous::{
    check_coefficients, hilbert_gains, luenberger_gains as gains,
};
use seqsmooth::scalar::Rational;
use seqsmooth::Error;
use std::cell::RefCell;
use std::sync::Arc;

fn array<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyAny> {
    PyArray1::from_vec(py, v).into_any()
}

/// The Gauss rule of ``n+1`` nodes for a positive measure, by Golub–Welsch on the recurrence
/// of its orthonormal polynomials: ``Σ_k λ_k f(t_k) = ∫ f dμ`` for every polynomial of degree
/// ``≤ 2n+1`` (Villien & Ostertag 2009, Lemma 3, eq. 26).
///
/// Parameters
/// ----------
/// n : int
///     The rule has ``n+1`` nodes.
/// t : array_like, optional
///     Sample times: the discrete measure ``Σ_j w_j δ(t − t_j)`` (at least ``n+1`` distinct).
/// weights : array_like, optional
///     ``w_j > 0`` with ``t`` (e.g. ``1/σ²``; default all 1).
/// kind : {"legendre", "chebyshev"}
///     Without ``t``: ``dt`` or ``dt/√((t − a)(b − t))`` on ``[a, b]``.
/// a, b : float
///     The interval for ``kind``.
///
/// Returns
/// -------
/// (nodes, weights) : two numpy arrays of ``n+1`` (nodes ascending; the weights are the
/// Christoffel numbers, summing to the measure's mass).
#[pyfunction]
#[pyo3(signature = (n, t = None, weights = None, kind = "legendre", a = -1.0, b = 1.0))]
pub fn gauss_rule<'py>(
    py: Python<'py>,
    n: usize,
    t: Option<&Bound<'py, PyAny>>,
    weights: Option<&Bound<'py, PyAny>>,
    kind: &str,
    a: f64,
    b: f64,
) -> PyResult<Bound<'py, PyAny>> {
    // The degree's range is the library's (`basis::MAX_JACOBI_DEGREE`).
    let rule: GaussRule = match t {
        Some(t) => {
            let ts = times(t, "t")?;
            let ws = match weights {
                Some(w) => series(w, "weights")?.as_slice().to_vec(),
                None => vec![1.0; ts.as_slice().len()],
            };
            let ts = ts.as_slice().to_vec();
            py.detach(|| Jacobi::discrete(&ts, &ws, n).and_then(|j| j.gauss()))
                .py()?
        }
        None => {
            if weights.is_some() {
                return Err(raise(
                    Kind::Parameter,
                    "weights go with t (sample times)",
                    None,
                ));
            }
            let jacobi = match kind {
                "legendre" => Jacobi::legendre(n, a, b),
                "chebyshev" => Jacobi::chebyshev(n, a, b),
                other => {
                    return Err(raise(
                        Kind::Parameter,
                        format!("kind {other:?} is not one of 'legendre', 'chebyshev'"),
                        None,
                    ))
                }
            }
            .py()?;
            py.detach(|| jacobi.gauss()).py()?
        }
    };
    let nodes = rule.nodes();
    Ok((array(py, nodes), array(py, rule.weights))
        .into_pyobject(py)?
        .into_any())
}

/// The ``n+1`` polynomial samples of a segment (Villien & Ostertag 2009, §II): its weighted
/// least-squares polynomial of degree ``n`` (weights ``1/σ²``) at the Gauss nodes of the
/// samples' own measure, where the samples are uncorrelated with variances ``1/λ_k``
/// (eqs. 19-21, 37).
///
/// Parameters
/// ----------
/// t, y : array_like
///     The segment's times (any order, at least ``n+1`` distinct) and values.
/// sigma : float or array_like
///     The noise standard deviation, one for all or one per sample.
/// degree : int
///     The polynomial's degree ``n`` (``n=``, the paper's name, is an alias).
///
/// Returns
/// -------
/// (times, values, variances) : three numpy arrays of ``n+1``.
#[pyfunction]
#[pyo3(signature = (t, y, sigma, degree = None, *, n = None))]
pub fn polynomial_samples<'py>(
    py: Python<'py>,
    t: &Bound<'py, PyAny>,
    y: &Bound<'py, PyAny>,
    sigma: &Bound<'py, PyAny>,
    degree: Option<usize>,
    n: Option<usize>,
) -> PyResult<Bound<'py, PyAny>> {
    let n = degree_of(degree, n)?;
    let (ts, ys) = crate::arrays::pair(t, y)?;
    let (ts, ys) = (ts.as_slice().to_vec(), ys.as_slice().to_vec());
    let sigmas = sigmas(sigma, ts.len())?;
    let ps = py
        .detach(|| PolynomialSamples::from_segment(&ts, &ys, &sigmas, n))
        .py()?;
    samples_tuple(py, ps)
}

/// `sigma` as one per sample: a float for all, or an array.
fn sigmas(sigma: &Bound<'_, PyAny>, samples: usize) -> PyResult<Vec<f64>> {
    Ok(match sigma.extract::<f64>() {
        Ok(s) => vec![s; samples],
        Err(_) => series(sigma, "sigma")?.as_slice().to_vec(),
    })
}

/// The degree, given as `degree` or by the paper's `n` (one of them).
fn degree_of(degree: Option<usize>, n: Option<usize>) -> PyResult<usize> {
    match (degree, n) {
        (Some(d), None) | (None, Some(d)) => Ok(d),
        (Some(_), Some(_)) => Err(raise(
            Kind::Parameter,
            "degree and n are both given: n is the paper's name of degree; give one",
            None,
        )),
        (None, None) => Err(raise(
            Kind::Parameter,
            "the degree is missing: give degree",
            None,
        )),
    }
}

/// `(times, values, variances)`.
fn samples_tuple(py: Python<'_>, ps: PolynomialSamples) -> PyResult<Bound<'_, PyAny>> {
    let times = ps.times();
    Ok((
        array(py, times),
        array(py, ps.values),
        array(py, ps.variances),
    )
        .into_pyobject(py)?
        .into_any())
}

/// A segment's polynomial samples accumulated a sample at a time (Villien & Ostertag 2009,
/// §V, eqs. 34-37): the layout (the times and σ of the segment's samples, known in advance) is
/// prepared once, then each value costs ``n+1`` multiplications and additions, and
/// ``polynomial_samples()`` gives what ``polynomial_samples(t, y, sigma, n)`` gives.
///
/// Parameters
/// ----------
/// t : array_like
///     The segment's sample times, increasing (at least ``n+1``).
/// sigma : float or array_like
///     The noise standard deviation, one for all or one per sample.
/// degree : int
///     The polynomial's degree ``n`` (``n=``, the paper's name, is an alias).
#[pyclass(name = "OnlineSmoother", module = "seqsmooth")]
pub struct PyOnlineSmoother {
    inner: OnlineSmoother<Arc<SmootherGains>>,
}

#[pymethods]
impl PyOnlineSmoother {
    /// ``pickle`` support (``copy.copy`` and ``copy.deepcopy`` too): the filter's state in
    /// the library's saved form, restored bit for bit. Filters are mutable: a copy is a deep
    /// copy of the state, and the copy and the original then run apart.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        persist::reduce_saved(slf.as_any(), &slf.borrow().inner)
    }

    /// The filter ``__reduce__`` saved (a ``DamagedStateError`` if ``state`` is damaged or
    /// another class's).
    #[staticmethod]
    fn _from_state(state: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(Self {
            inner: persist::load(state)?,
        })
    }

    #[new]
    #[pyo3(signature = (t, sigma, degree = None, *, n = None))]
    fn new(
        py: Python<'_>,
        t: &Bound<'_, PyAny>,
        sigma: &Bound<'_, PyAny>,
        degree: Option<usize>,
        n: Option<usize>,
    ) -> PyResult<Self> {
        let n = degree_of(degree, n)?;
        let ts = times(t, "t")?.as_slice().to_vec();
        let sigmas = sigmas(sigma, ts.len())?;
        let gains = py.detach(|| SmootherGains::new(&ts, &sigmas, n)).py()?;
        Ok(Self {
            inner: OnlineSmoother::new(Arc::new(gains)),
        })
    }

    /// The next sample's value (the layout gives its time and σ).
    fn push(&mut self, y: f64) -> PyResult<()> {
        self.inner.push(y).py()
    }

    /// Several next values at once (nothing is taken on an error).
    fn push_all(&mut self, y: &Bound<'_, PyAny>) -> PyResult<()> {
        let ys = series(y, "y")?;
        self.inner.push_all(ys.as_slice()).py()
    }

    /// The values taken so far.
    #[getter]
    fn taken(&self) -> usize {
        self.inner.taken()
    }

    /// The samples in the layout.
    #[getter]
    fn size(&self) -> usize {
        self.inner.gains().len()
    }

    /// ``(times, values, variances)`` once every sample of the layout is in.
    fn polynomial_samples<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let ps = self.inner.polynomial_samples().py()?;
        samples_tuple(py, ps)
    }

    /// Start the next segment with the same layout.
    fn reset(&mut self) {
        self.inner = OnlineSmoother::new(Arc::clone(self.inner.gains()));
    }

    fn __repr__(&self) -> String {
        format!(
            "OnlineSmoother(size={}, taken={})",
            self.inner.gains().len(),
            self.inner.taken()
        )
    }
}

/// A Python model ``h(theta, t)`` (and optionally ``jac(theta, t)``), both given numpy arrays
/// (``theta`` of ``m``, ``t`` of the times) and returning ``h`` at every time and the
/// ``len(t) × m`` Jacobian. The first exception it raises is kept and raised again as it is.
struct PyCurve<'a, 'py> {
    h: &'a Bound<'py, PyAny>,
    jac: Option<&'a Bound<'py, PyAny>>,
    parameters: usize,
    raised: RefCell<Option<PyErr>>,
}

impl<'py> PyCurve<'_, 'py> {
    fn keep(&self, e: PyErr) -> Error {
        let message = e.to_string();
        self.raised.borrow_mut().get_or_insert(e);
        Error::InvalidParameter {
            name: Param::Model,
            value: "raised".into(),
            reason: message,
        }
    }

    fn call(
        &self,
        f: &Bound<'py, PyAny>,
        theta: &[f64],
        times: &[f64],
    ) -> PyResult<Bound<'py, PyAny>> {
        let py = f.py();
        f.call1((
            PyArray1::from_slice(py, theta),
            PyArray1::from_slice(py, times),
        ))
    }

    /// The first exception, or the library's error.
    fn result<T>(&self, r: Result<T, Error>) -> PyResult<T> {
        match self.raised.borrow_mut().take() {
            Some(e) => Err(e),
            None => r.py(),
        }
    }
}

impl CurveModel for PyCurve<'_, '_> {
    fn parameters(&self) -> usize {
        self.parameters
    }

    fn values(&self, theta: &[f64], times: &[f64]) -> Result<Vec<f64>, Error> {
        self.call(self.h, theta, times)
            .and_then(|v| Ok(series(&v, "h(theta, t)")?.as_slice().to_vec()))
            .map_err(|e| self.keep(e))
    }

    fn jacobian(&self, theta: &[f64], times: &[f64]) -> Option<Result<DMatrix<f64>, Error>> {
        let jac = self.jac?;
        Some(
            self.call(jac, theta, times)
                .and_then(|v| {
                    let (values, rows, cols) = table(&v, "jac(theta, t)")?;
                    Ok(DMatrix::from_row_slice(rows, cols, values.as_slice()))
                })
                .map_err(|e| self.keep(e)),
        )
    }
}

fn model<'a, 'py>(
    h: &'a Bound<'py, PyAny>,
    jac: Option<&'a Bound<'py, PyAny>>,
    parameters: usize,
) -> PyResult<PyCurve<'a, 'py>> {
    for (name, f) in [("h", Some(h)), ("jac", jac)] {
        if let Some(f) = f {
            if !f.is_callable() {
                let kind = f.get_type().name()?.to_string();
                return Err(raise(
                    Kind::InvalidType,
                    format!("{name} is a {kind}: it must be a function of (theta, t)"),
                    None,
                ));
            }
        }
    }
    Ok(PyCurve {
        h,
        jac,
        parameters,
        raised: RefCell::new(None),
    })
}

/// The maximum-likelihood estimate of ``theta`` for ``y = h(theta, t) + noise`` of known
/// ``sigma`` (Villien & Ostertag 2009, eq. 2): the least ``Σ ((y − h)/σ)²`` by
/// Levenberg–Marquardt (MINPACK's ``lmder``) from ``start``, with its covariance (the
/// Cramér–Rao bound at the estimate). On polynomial samples (``t, values, sqrt(variances)``
/// of ``polynomial_samples``) it is the PAML estimate (eqs. 3-4).
///
/// Parameters
/// ----------
/// h : callable
///     ``h(theta, t)``: given numpy arrays ``theta`` (``m``) and ``t``, the model at every
///     time.
/// t, y : array_like
///     The samples.
/// sigma : float or array_like
///     Their noise standard deviations.
/// start : array_like
///     The starting ``theta`` (its length is ``m``).
/// jac : callable, optional
///     ``jac(theta, t)``: the ``len(t) × m`` Jacobian ``∂h/∂theta``; default central
///     differences.
///
/// Returns
/// -------
/// CurveFit
#[pyfunction]
#[pyo3(signature = (h, t, y, sigma, start, jac = None))]
pub fn fit_curve(
    h: &Bound<'_, PyAny>,
    t: &Bound<'_, PyAny>,
    y: &Bound<'_, PyAny>,
    sigma: &Bound<'_, PyAny>,
    start: &Bound<'_, PyAny>,
    jac: Option<&Bound<'_, PyAny>>,
) -> PyResult<PyCurveFit> {
    let (ts, ys) = crate::arrays::pair(t, y)?;
    let sigmas = sigmas(sigma, ts.as_slice().len())?;
    let start = series(start, "start")?;
    let model = model(h, jac, start.as_slice().len())?;
    let fit = curve::fit_curve(
        &model,
        ts.as_slice(),
        ys.as_slice(),
        &sigmas,
        start.as_slice(),
    );
    Ok(PyCurveFit {
        inner: model.result(fit)?,
    })
}

/// The Cramér–Rao bound ``F(theta)⁻¹``, ``F = Σ_k ∇h ∇hᵀ/σ_k²``: the least covariance of an
/// unbiased estimate of ``theta`` from samples at ``t`` with noise ``sigma`` (an ``m × m``
/// numpy array). ``h`` and ``jac`` as for ``fit_curve``.
#[pyfunction]
#[pyo3(signature = (h, theta, t, sigma, jac = None))]
pub fn cramer_rao_bound<'py>(
    py: Python<'py>,
    h: &Bound<'py, PyAny>,
    theta: &Bound<'py, PyAny>,
    t: &Bound<'py, PyAny>,
    sigma: &Bound<'py, PyAny>,
    jac: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let ts = times(t, "t")?;
    let sigmas = sigmas(sigma, ts.as_slice().len())?;
    let theta = series(theta, "theta")?;
    let model = model(h, jac, theta.as_slice().len())?;
    let bound = curve::cramer_rao_bound(&model, theta.as_slice(), ts.as_slice(), &sigmas);
    let bound = model.result(bound)?;
    square(py, &bound)
}

/// A converged maximum-likelihood fit (``fit_curve``).
#[pyclass(name = "CurveFit", module = "seqsmooth", frozen)]
pub struct PyCurveFit {
    inner: CurveFit,
}

#[pymethods]
impl PyCurveFit {
    /// The estimate ``theta`` (numpy array of ``m``).
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        array(py, self.inner.parameters.as_slice().to_vec())
    }

    /// Its covariance to first order, ``F(theta)⁻¹`` (``m × m``).
    #[getter]
    fn covariance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let c = &self.inner.covariance;
        square(py, c)
    }

    /// The 1σ of each parameter, the square roots of the covariance's diagonal.
    #[getter]
    fn std_devs<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        array(py, self.inner.std_devs())
    }

    /// ``std_devs`` by its old name (kept: the same numbers).
    #[getter]
    fn standard_deviations<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        self.std_devs(py)
    }

    /// ``Σ ((y − h(theta, t))/σ)²`` at the estimate.
    #[getter]
    fn chi_squared(&self) -> f64 {
        self.inner.chi_squared
    }

    /// Samples less parameters.
    #[getter]
    fn degrees_of_freedom(&self) -> usize {
        self.inner.degrees_of_freedom
    }

    /// The condition number of the whitened Jacobian at the estimate.
    #[getter]
    fn condition_number(&self) -> f64 {
        self.inner.condition_number
    }

    /// The Gauss–Newton correction still proposed at the estimate, in units of its own σ
    /// (``sqrt(δᵀ F δ)``; at most ``1e-9`` unless rounding stopped it first).
    #[getter]
    fn correction(&self) -> f64 {
        self.inner.correction
    }

    /// Model evaluations made.
    #[getter]
    fn evaluations(&self) -> usize {
        self.inner.evaluations
    }

    fn __repr__(&self) -> String {
        format!(
            "CurveFit(parameters={:?}, chi_squared={:?}, degrees_of_freedom={})",
            self.inner.parameters.as_slice(),
            self.inner.chi_squared,
            self.inner.degrees_of_freedom
        )
    }
}

/// Luenberger's gains ``b = H⁻¹·1`` for ``n`` coefficients (a polynomial of degree
/// ``n − 1``; ``H`` the Hilbert matrix): his continuous-time law ``a_i' = (b_i/T^i) ε(T)``.
/// Integers: ``b_j = (−1)^(n+j) (n+j−1)!/(((j−1)!)² (n−j)!)`` (his explicit expression with
/// its factorial squared).
///
/// Returns a numpy array, or with ``exact=True`` a list of ``int`` (by exact inversion of
/// ``H``).
#[pyfunction]
#[pyo3(signature = (n, exact = false))]
pub fn luenberger_gains<'py>(
    py: Python<'py>,
    n: usize,
    exact: bool,
) -> PyResult<Bound<'py, PyAny>> {
    check_coefficients(n).py()?;
    if !exact {
        return Ok(array(py, gains::<f64>(n)));
    }
    let b: Vec<Rational> = py.detach(|| hilbert_gains(n));
    let list = PyList::empty(py);
    for v in &b {
        list.append(
            py.import("builtins")?
                .getattr("int")?
                .call1((v.to_integer().to_string(),))?,
        )?;
    }
    Ok(list.into_any())
}
