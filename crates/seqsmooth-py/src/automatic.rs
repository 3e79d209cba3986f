//! The automatic filter (`polynomial::automatic::AutomaticFilter`) as a Python class: start-up
//! on expanding memory, the switch to fading memory, outlier rejection, noise estimation,
//! misfit restarts and the degree settling, with each sample's flags; `update_many` gives the
//! numbers `seqsmooth filter --kind auto` writes (the estimate of each update, its 1σ, the
//! noise in use, the flags) and the final outlier decisions made at each call, and `finish`
//! those of the samples still under review: as the library's `AutoOutput::decided` and
//! `AutomaticFilter::finish`, so the object holds no row of its past (its memory and its
//! pickle do not grow with the samples).

use crate::arrays::{matrix, pair};
use crate::errors::IntoPy;
use crate::persist;
use crate::polynomial::{engine as engine_named, state_of, State};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use pyo3::types::{PyBytes, PyInt, PyTuple};
use seqsmooth::polynomial::rows::{decisions, degree_in_use, RowLayout};
use seqsmooth::polynomial::spec::{AnyFilter, FilterKind, FilterSpec};
use seqsmooth::{Error, PolynomialFilter};

/// The automatic polynomial filter of degree up to ``degree`` (Reyneke et al. 2012; Morrison
/// chs. 9, 13): it starts on expanding memory, switches to fading memory with ``theta`` per
/// ``tau`` at Morrison's (13.8.8) point, rejects outliers at a gate from the innovation's σ,
/// estimates the noise unless ``sigma`` is given, restarts on a misfit, and settles the
/// degree; every estimate's covariance covers the noise and the estimated bias.
///
/// Parameters
/// ----------
/// degree : int
///     The highest degree, 0 to 24.
/// theta : float
///     The fading-memory discount per ``tau``, ``0 < theta < 1``.
/// tau : float
///     The time interval ``theta`` applies to (default 1).
/// engine : {"exact", "gain"}
///     The engine of every internal filter.
/// sigma : float, optional
///     The noise's standard deviation, if known (otherwise estimated).
/// review_window : int, optional
///     Accepted samples after a sample before its outlier decision is final (default degree
///     + 4).
#[pyclass(name = "AutomaticFilter", module = "seqsmooth")]
pub struct PyAutomaticFilter {
    /// The library's automatic filter, run by its row runner.
    filter: AnyFilter,
    /// The samples whose final outlier decision has been reported (`update_many`'s
    /// `decided`, then `finish`).
    decided: u64,
    /// Final decisions made but not reported yet (by a call that then refused a sample),
    /// reported first by the next call: at most the review's window and a refused batch's.
    waiting: Vec<bool>,
}

#[pymethods]
impl PyAutomaticFilter {
    /// ``pickle`` support (``copy.copy`` and ``copy.deepcopy`` too): the filter's state in
    /// the library's saved form, restored bit for bit. Filters are mutable: a copy is a deep
    /// copy of the state, and the copy and the original then run apart.
    /// The state is the library's saved form, the count of final decisions reported and the
    /// decisions made but not reported yet.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let me = slf.borrow();
        let waiting: Vec<u8> = me.waiting.iter().map(|&d| u8::from(d)).collect();
        let decisions = PyTuple::new(
            py,
            [
                me.decided.into_pyobject(py)?.into_any(),
                PyBytes::new(py, &waiting).into_any(),
            ],
        )?;
        let state = PyTuple::new(py, [persist::save(py, &me.filter)?, decisions.into_any()])?;
        persist::reduce(slf.as_any(), state.into_any())
    }

    /// The filter ``__reduce__`` saved (a ``DamagedStateError`` if ``state`` is damaged or
    /// another class's).
    #[staticmethod]
    fn _from_state(state: &Bound<'_, PyAny>) -> PyResult<Self> {
        let items = persist::items(state, 2)?;
        let filter: AnyFilter = persist::load(&items.get_item(0)?)?;
        if filter.kind() != FilterKind::Automatic {
            return Err(persist::damaged(
                "the state of another filter than an AutomaticFilter",
            ));
        }
        // The count of decisions reported and those waiting; a pickle of an earlier version
        // kept every decision made (bytes of 0 and 1), none of them reported yet.
        let item = items.get_item(1)?;
        let flags = |bytes: &Bound<'_, PyBytes>| -> PyResult<Vec<bool>> {
            let bytes = bytes.as_bytes();
            if bytes.iter().any(|&d| d > 1) {
                return Err(persist::damaged("the decisions are not 0 or 1"));
            }
            Ok(bytes.iter().map(|&d| d == 1).collect())
        };
        let (decided, waiting) = if let Ok(bytes) = item.cast::<PyBytes>() {
            (0, flags(bytes)?)
        } else {
            let pair = persist::items(&item, 2)?;
            let count = pair.get_item(0)?;
            let count = count
                .cast::<PyInt>()
                .ok()
                .and_then(|c| c.extract::<u64>().ok())
                .ok_or_else(|| persist::damaged("the count of decisions is not a count"))?;
            let waiting = pair.get_item(1)?;
            let waiting = waiting
                .cast::<PyBytes>()
                .map_err(|_| persist::damaged("the waiting decisions are not bytes"))?;
            (count, flags(waiting)?)
        };
        Ok(Self {
            filter,
            decided,
            waiting,
        })
    }

    #[new]
    #[pyo3(signature = (degree, theta, tau = 1.0, engine = "exact", sigma = None, review_window = None))]
    fn new(
        degree: usize,
        theta: f64,
        tau: f64,
        engine: &str,
        sigma: Option<f64>,
        review_window: Option<usize>,
    ) -> PyResult<Self> {
        // The library's filter of this description.
        let spec = FilterSpec {
            theta: Some(theta),
            tau: Some(tau),
            engine: engine_named(engine)?,
            sigma,
            review_window,
            ..FilterSpec::new(FilterKind::Automatic, degree)
        };
        Ok(Self {
            filter: spec.build().py()?,
            decided: 0,
            waiting: Vec::new(),
        })
    }

    /// The highest degree ``m``.
    #[getter]
    fn degree(&self) -> usize {
        self.filter.degree()
    }

    /// The number of samples accepted (a rejected outlier is not counted).
    #[getter]
    fn samples(&self) -> u64 {
        self.filter.samples()
    }

    /// The number of samples, from the first, whose final outlier decision has been
    /// reported (by ``update_many``'s ``decided`` and by :meth:`finish`).
    #[getter]
    fn decided(&self) -> u64 {
        self.decided
    }

    /// Takes the samples ``(t[i], y[i])`` and returns, per sample, what ``seqsmooth filter
    /// --kind auto`` writes: a dict of numpy arrays ``d`` and ``s`` (``(n, m+1)``: the
    /// estimate at ``t[i]`` of the active degree and its 1σ, NaN above that degree, before
    /// the filter is determined, and while ``noise`` is NaN: no estimate is given without its
    /// σ), ``noise`` (the σ in use, NaN until estimated), ``bias`` (the estimated bias of
    /// ``d0``), ``degree`` (the active degree), the flags ``outlier`` (the decision at the
    /// update) and ``misfit``, and ``decided``: the final outlier decisions this call made, in
    /// sample order, of the samples from number :attr:`decided` (before the call) on — a
    /// sample's decision is final once the review has seen ``review_window`` accepted samples
    /// after it (Morrison §14.8); :meth:`finish` gives those of the samples still under review.
    /// The filter keeps no decision once reported, so its memory is bounded.
    fn update_many<'py>(
        &mut self,
        py: Python<'py>,
        t: &Bound<'py, PyAny>,
        y: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (ts, ys) = pair(t, y)?;
        let (t, y) = (ts.as_slice(), ys.as_slice());
        // The library's rows (`seqsmooth filter --kind auto`'s): d, s, noise, outlier, misfit,
        // bias, then the update's cells (its final decisions, the degree in use).
        let layout = RowLayout {
            sigma: true,
            lead: 0.0,
            trailing: true,
        };
        let (n, w, stride) = (
            t.len(),
            self.filter.degree() + 1,
            self.filter.stride(layout),
        );
        let mut rows = vec![0.0; n * stride];
        let filter = &mut self.filter;
        let run = py.detach(|| filter.run_rows(t, y, &mut rows, layout));
        // The decisions of the rows taken, up to a refused one.
        let taken = match &run {
            Err(Error::InBatch { index, .. }) => *index,
            _ => n,
        };
        let cells = |i: usize| &rows[i * stride + 2 * w + 4..(i + 1) * stride];
        // Those still waiting from a refused call first, then this call's; kept for the next
        // call if this one refused a sample (its error is what this call returns).
        let mut decided = std::mem::take(&mut self.waiting);
        decided.extend((0..taken).flat_map(|i| decisions(cells(i))));
        if let Err(e) = run {
            self.waiting = decided;
            return Err(e).py();
        }
        self.decided += decided.len() as u64;
        let column = |k: usize| (0..n).map(|i| rows[i * stride + k]).collect::<Vec<f64>>();
        let flag = |k: usize| {
            (0..n)
                .map(|i| rows[i * stride + k] == 1.0)
                .collect::<Vec<_>>()
        };
        let part = |from: usize| {
            let cells = rows.chunks_exact(stride).flat_map(|r| &r[from..from + w]);
            cells.copied().collect::<Vec<f64>>()
        };
        let degree: Vec<usize> = (0..n).map(|i| degree_in_use(cells(i))).collect();
        let out = PyDict::new(py);
        out.set_item("d", matrix(py, part(0), n, w)?)?;
        out.set_item("s", matrix(py, part(w), n, w)?)?;
        out.set_item("noise", PyArray1::from_vec(py, column(2 * w)))?;
        out.set_item("bias", PyArray1::from_vec(py, column(2 * w + 3)))?;
        out.set_item("degree", PyArray1::from_vec(py, degree))?;
        out.set_item("outlier", PyArray1::from_vec(py, flag(2 * w + 1)))?;
        out.set_item("misfit", PyArray1::from_vec(py, flag(2 * w + 2)))?;
        out.set_item("decided", PyArray1::from_vec(py, decided))?;
        Ok(out)
    }

    /// Decides every sample still waiting for its review and returns those final outlier
    /// decisions (``True``: rejected), in sample order, of the samples from number
    /// :attr:`decided` on: after the ``decided`` arrays of every ``update_many``, they make
    /// the final decision of every sample taken (the library's ``AutomaticFilter::finish``).
    fn finish<'py>(&mut self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        let mut tail = std::mem::take(&mut self.waiting);
        if let Some(f) = self.filter.automatic_mut() {
            tail.extend(f.finish());
        }
        self.decided += tail.len() as u64;
        PyArray1::from_vec(py, tail)
    }

    /// The estimate at the newest sample (the active filter's; after a rejected sample, the
    /// prediction across it).
    fn estimate(&self) -> PyResult<State> {
        state_of(&self.filter, None)
    }

    /// The estimate carried to time ``t``.
    fn estimate_at(&self, t: f64) -> PyResult<State> {
        state_of(&self.filter, Some(t))
    }

    fn __repr__(&self) -> String {
        format!(
            "AutomaticFilter(degree={}, samples={})",
            self.filter.degree(),
            self.filter.samples()
        )
    }
}
