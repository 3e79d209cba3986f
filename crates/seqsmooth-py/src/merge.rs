//! Exact merges of a partitioned series as a Python class, `Information`: the library's
//! `polynomial::merge::Information` (each partition reduced to its least-squares information
//! in the Legendre basis of the whole span, the informations added), pickled in the library's
//! saved form so that a cluster ships it between workers.

use crate::arrays::{series, times};
use crate::errors::{raise, IntoPy, Kind};
use crate::persist;
use crate::polynomial::State;
use pyo3::prelude::*;
use pyo3::types::{PyTuple, PyType};
use seqsmooth::polynomial::merge;
use seqsmooth::polynomial::prior::Prior;

/// The least-squares information of one part of a long series: reduce each partition of the
/// series where it lies, merge the partitions' informations (in any order and grouping), and
/// read the fit of the whole series — the same numbers as one pass over all the samples.
///
/// Expanding memory, batch least squares and the Bayes filter (Morrison chs. 9, 10) minimise
/// a sum over the samples, ``Σ (y_k − p(t_k))²`` (plus the prior's term for Bayes): the sums
/// ``TᵀT``, ``TᵀY``, ``YᵀY`` of disjoint sets of samples add. Each partition's sums are taken
/// in one basis, the Legendre polynomials on the whole series' span ``[start, end]``, as double
/// words (exact products, error-free sums: about 32 significant digits), so that merging adds
/// them exactly whatever the order; the estimate solves the normal equations in the same
/// precision and rounds the coefficients once.
///
/// Parameters
/// ----------
/// degree : int
///     The polynomial's degree ``m``, 0 to ``MAX_DEGREE``.
/// start, end : float
///     The whole series' span (its first and last times, or any interval holding them;
///     ``start <= end``): every partition's information must be made with the same span.
/// sigma : float, optional
///     The samples' noise standard deviation: the estimates then carry their covariance, and
///     a prior can be added.
///
/// Raises
/// ------
/// ParameterError
///     a degree, span or sigma out of range.
///
/// Examples
/// --------
/// >>> import numpy as np, seqsmooth
/// >>> t = np.arange(100.0); y = 1.0 + 0.5 * t
/// >>> a = seqsmooth.Information(1, 0.0, 99.0); b = seqsmooth.Information(1, 0.0, 99.0)
/// >>> a.reduce(t[:40], y[:40]); b.reduce(t[40:], y[40:])
/// >>> a.merge(b)
/// >>> a.estimate(99.0).derivatives.round(12)
/// array([50.5,  0.5])
#[pyclass(name = "Information", module = "seqsmooth")]
#[derive(Clone)]
pub struct PyInformation {
    inner: merge::Information,
}

#[pymethods]
impl PyInformation {
    #[new]
    #[pyo3(signature = (degree, start, end, sigma = None))]
    fn new(degree: usize, start: f64, end: f64, sigma: Option<f64>) -> PyResult<Self> {
        let inner = merge::Information::new(degree, start, end, sigma).py()?;
        Ok(Self { inner })
    }

    /// The polynomial's degree ``m``.
    #[getter]
    fn degree(&self) -> usize {
        self.inner.degree()
    }

    /// The span ``(start, end)`` of the basis.
    #[getter]
    fn span(&self) -> (f64, f64) {
        self.inner.span()
    }

    /// The samples' noise σ, or ``None``.
    #[getter]
    fn sigma(&self) -> Option<f64> {
        self.inner.sigma()
    }

    /// The number of samples reduced (merged ones included).
    #[getter]
    fn samples(&self) -> u64 {
        self.inner.samples()
    }

    /// Whether a prior has been added (in this information or one merged into it).
    #[getter]
    fn has_prior(&self) -> bool {
        self.inner.has_prior()
    }

    /// Adds the samples ``(t[i], y[i])``: in any order, at any times (best inside the span);
    /// an empty batch adds nothing. The work runs without the GIL.
    ///
    /// Raises
    /// ------
    /// InvalidInputError
    ///     NaN or infinite values (``.index`` is the sample's position; nothing is added),
    ///     mismatched lengths, values so large their squares overflow.
    /// InvalidTypeError
    ///     arrays that do not hold real numbers.
    fn reduce(
        &mut self,
        py: Python<'_>,
        t: &Bound<'_, PyAny>,
        y: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let (ts, ys) = (times(t, "t")?, series(y, "y")?);
        let (t, y) = (ts.as_slice(), ys.as_slice());
        if t.len() != y.len() {
            return Err(raise(
                Kind::InvalidInput,
                format!(
                    "t has {} values and y {}: one time per value",
                    t.len(),
                    y.len()
                ),
                None,
            ));
        }
        let inner = &mut self.inner;
        py.detach(|| inner.reduce(t, y)).py()
    }

    /// Adds ``other``'s information in place (the merge of two partitions): the same degree,
    /// span and sigma; a prior in at most one of them.
    ///
    /// Raises
    /// ------
    /// ParameterError
    ///     another degree, span or sigma, or a prior in both.
    fn merge(&mut self, other: &Self) -> PyResult<()> {
        self.inner.merge(&other.inner).py()
    }

    /// ``a + b``: a new information holding both (``merge`` without changing either), for
    /// ``functools.reduce``, Spark's ``reduce`` and Dask's tree reductions.
    fn __add__(&self, other: &Self) -> PyResult<Self> {
        let mut sum = self.clone();
        sum.inner.merge(&other.inner).py()?;
        Ok(sum)
    }

    /// Adds a prior (the Bayes filter, Morrison ch. 10): the ``degree + 1`` derivatives
    /// ``x0`` at ``t0`` and their covariance ``P0`` (a number, the diagonal or the matrix;
    /// positive definite), weighed against the samples by ``sigma`` (needed). Add it to one
    /// partition's information only.
    ///
    /// Raises
    /// ------
    /// ParameterError
    ///     no sigma, a second prior, a state of another length, ``P0`` not positive definite.
    #[allow(non_snake_case)]
    #[pyo3(signature = (x0, P0, t0 = 0.0))]
    fn add_prior(&mut self, x0: &Bound<'_, PyAny>, P0: &Bound<'_, PyAny>, t0: f64) -> PyResult<()> {
        let n = self.inner.degree() + 1;
        let x = series(x0, "x0")?.as_slice().to_vec();
        let p = crate::kalman::square_from(P0, n, "P0")?;
        let prior = Prior::new(t0, x, p).py()?;
        self.inner.add_prior(&prior).py()
    }

    /// The fit of every sample in (and the prior) at time ``t``: a :class:`State` whose
    /// ``derivatives`` are ``[x, x', …, x^(m)]`` at ``t`` and whose ``covariance`` is
    /// ``σ² J (TᵀT)⁻¹ Jᵀ`` with ``sigma`` (else ``None``).
    ///
    /// Raises
    /// ------
    /// TooFewSamplesError
    ///     fewer samples than ``m + 1`` (without a prior).
    /// NotDeterminedError
    ///     enough samples, but at too few distinct times to determine the polynomial.
    /// InvalidInputError, NumericalError
    ///     ``t`` not finite, or an estimate beyond the double range.
    fn estimate(&self, t: f64) -> PyResult<State> {
        self.inner.estimate(t).py().map(State::from)
    }

    /// The residual sum of squares ``Σ (y_k − p(t_k))²`` of the fit (with the prior's
    /// whitened misfit).
    ///
    /// Raises
    /// ------
    /// TooFewSamplesError, NotDeterminedError
    ///     as :meth:`estimate`.
    fn residual_sq(&self) -> PyResult<f64> {
        Ok(self.inner.fit().py()?.residual_sq())
    }

    /// ``pickle`` support (``copy.copy`` and ``copy.deepcopy`` too): the information in the
    /// library's saved form, restored bit for bit.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        persist::reduce_saved(slf.as_any(), &slf.borrow().inner)
    }

    /// The information ``__reduce__`` saved (a ``DamagedStateError`` if ``state`` is damaged
    /// or another class's).
    #[classmethod]
    fn _from_state<'py>(
        cls: &Bound<'py, PyType>,
        state: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let inner: merge::Information = persist::load(state)?;
        let obj = Bound::new(cls.py(), Self { inner })?.into_any();
        persist::of_class(obj, cls)
    }

    fn __repr__(&self) -> String {
        let (start, end) = self.inner.span();
        format!(
            "Information(degree={}, span=({start:?}, {end:?}), sigma={:?}, samples={}, \
             has_prior={})",
            self.inner.degree(),
            self.inner.sigma(),
            self.inner.samples(),
            if self.inner.has_prior() {
                "True"
            } else {
                "False"
            }
        )
    }
}
