//! The Kalman filter on a discrete-time linear model with the user's matrices as a Python
//! class, `LinearKalmanFilter`: the library's `kalman::discrete::LinearKalmanFilter` (`F`,
//! `H`, `Q`, `R`, `B u`, constant or one per step), its batch, the RTS smoother over the
//! batch's own pass and the fixed-lag smoother. This file only converts arrays; every check
//! (shapes, finite, symmetric, positive semidefinite) is the library's.

use crate::arrays::matrix;
use crate::errors::{raise, IntoPy, Kind};
use crate::kalman::{square, PyInnovation};
use crate::persist;
use nalgebra::{DMatrix, DVector};
use numpy::{PyArray1, PyArray2, PyArray3, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{IntoPyDict, PyTuple};
use seqsmooth::kalman::discrete::{LinearFixedLag, LinearKalmanFilter, PassInto, StepMatrices};
use seqsmooth::kalman::Smoothed;

/// `obj` as a C-contiguous float64 array: its values (row-major) and shape, named `name`.
fn nd(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<(Vec<f64>, Vec<usize>)> {
    let np = obj.py().import("numpy")?;
    let a = np.call_method1("asarray", (obj,)).map_err(|e| {
        raise(
            Kind::InvalidType,
            format!("{name} is not an array of numbers: {e}"),
            None,
        )
    })?;
    let kind: String = a.getattr("dtype")?.getattr("kind")?.extract()?;
    if !matches!(kind.as_str(), "f" | "i" | "u" | "b") {
        let dtype = a.getattr("dtype")?.str()?.to_string();
        return Err(raise(
            Kind::InvalidType,
            format!("{name} has dtype {dtype}: it must hold real numbers"),
            None,
        ));
    }
    // `asarray` (not `ascontiguousarray`, which makes a number one-dimensional) in C order.
    let a = np.call_method(
        "asarray",
        (a, "float64"),
        Some(&[("order", "C")].into_py_dict(obj.py())?),
    )?;
    let a = a.cast::<PyArrayDyn<f64>>()?.readonly();
    Ok((a.as_slice()?.to_vec(), a.shape().to_vec()))
}

/// A matrix from `obj`: a 2-D array as it is; a number (or 0-D array) times the `n × n`
/// identity where `square` is `Some(n)` (filterpy's scalar `R`, `Q`, `P`); a 1-D array as one
/// row when `row` (a one-component `H`), else as one column.
fn matrix_from(
    obj: &Bound<'_, PyAny>,
    name: &str,
    square: Option<usize>,
    row: bool,
) -> PyResult<DMatrix<f64>> {
    let (v, shape) = nd(obj, name)?;
    match (shape.as_slice(), square) {
        ([], Some(n)) => Ok(DMatrix::from_diagonal_element(n, n, v[0])),
        ([r, c], _) => Ok(DMatrix::from_row_slice(*r, *c, &v)),
        ([len], _) if row => Ok(DMatrix::from_row_slice(1, *len, &v)),
        ([len], _) => Ok(DMatrix::from_column_slice(*len, 1, &v)),
        (s, _) => Err(raise(
            Kind::InvalidInput,
            format!("{name} has shape {s:?}: it must be a matrix"),
            None,
        )),
    }
}

/// A per-step argument: `None`, one value for every step, or one per step (a leading axis of
/// `steps`): matrices (`vector` false, `base` the dimensions of one) or vectors (`u`).
enum PerStep {
    None,
    Constant(DMatrix<f64>),
    Each(Vec<DMatrix<f64>>),
}

impl PerStep {
    /// `obj` (`Fs`, `Qs`, …) for `steps` steps: with one more axis than a step's value, one
    /// per step; else the same for every step (a number times the identity of `square`).
    fn from(
        obj: Option<&Bound<'_, PyAny>>,
        name: &str,
        steps: usize,
        square: Option<usize>,
        vector: bool,
    ) -> PyResult<Self> {
        let Some(obj) = obj.filter(|o| !o.is_none()) else {
            return Ok(PerStep::None);
        };
        let (v, shape) = nd(obj, name)?;
        let one = if vector { 1 } else { 2 };
        if shape.len() == one + 1 {
            if shape[0] != steps {
                return Err(raise(
                    Kind::InvalidInput,
                    format!(
                        "{name} has {} steps for {steps} measurements: one per measurement",
                        shape[0]
                    ),
                    None,
                ));
            }
            let (r, c) = if vector {
                (shape[1], 1)
            } else {
                (shape[1], shape[2])
            };
            let each = v
                .chunks_exact((r * c).max(1))
                .take(steps)
                .map(|b| DMatrix::from_row_slice(r, c, &b[..r * c]))
                .collect();
            return Ok(PerStep::Each(each));
        }
        if shape.len() == 1 && shape[0] == steps && !vector && square == Some(1) {
            // One number per step for a one-component R or a one-state Q.
            return Ok(PerStep::Each(
                v.iter().map(|&x| DMatrix::from_element(1, 1, x)).collect(),
            ));
        }
        Ok(PerStep::Constant(matrix_from(obj, name, square, false)?))
    }

    fn at(&self, k: usize) -> Option<&DMatrix<f64>> {
        match self {
            PerStep::None => None,
            PerStep::Constant(m) => Some(m),
            PerStep::Each(v) => v.get(k),
        }
    }
}

/// The per-step arguments of a batch, and `u` as vectors.
struct Steps {
    f: PerStep,
    q: PerStep,
    h: PerStep,
    r: PerStep,
    b: PerStep,
    u: Vec<DVector<f64>>,
    u_constant: Option<DVector<f64>>,
}

impl Steps {
    #[allow(clippy::too_many_arguments)]
    fn new(
        kf: &LinearKalmanFilter,
        steps: usize,
        fs: Option<&Bound<'_, PyAny>>,
        qs: Option<&Bound<'_, PyAny>>,
        hs: Option<&Bound<'_, PyAny>>,
        rs: Option<&Bound<'_, PyAny>>,
        bs: Option<&Bound<'_, PyAny>>,
        us: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let (n, p) = (kf.dimension(), kf.components());
        let u = PerStep::from(us, "us", steps, None, true)?;
        let (u, u_constant) = match u {
            PerStep::None => (Vec::new(), None),
            PerStep::Constant(m) => (Vec::new(), Some(DVector::from_column_slice(m.as_slice()))),
            PerStep::Each(v) => (
                v.into_iter()
                    .map(|m| DVector::from_column_slice(m.as_slice()))
                    .collect(),
                None,
            ),
        };
        Ok(Self {
            f: PerStep::from(fs, "Fs", steps, None, false)?,
            q: PerStep::from(qs, "Qs", steps, Some(n), false)?,
            h: PerStep::from(hs, "Hs", steps, None, false)?,
            r: PerStep::from(rs, "Rs", steps, Some(p), false)?,
            b: PerStep::from(bs, "Bs", steps, None, false)?,
            u,
            u_constant,
        })
    }

    fn at(&self, k: usize) -> StepMatrices<'_> {
        StepMatrices {
            f: self.f.at(k),
            q: self.q.at(k),
            b: self.b.at(k),
            u: self.u.get(k).or(self.u_constant.as_ref()),
            h: self.h.at(k),
            r: self.r.at(k),
        }
    }
}

/// Rows × `p` measurements from `zs` (`(N,)` for one component, or `(N, p)`; NaN a missing
/// component, `None` in a list a missing measurement).
fn measurements(zs: &Bound<'_, PyAny>, p: usize) -> PyResult<(Vec<f64>, usize)> {
    // A list may hold None for a missing measurement (filterpy's convention); an array is
    // taken as it is.
    let listed = zs.is_instance_of::<pyo3::types::PyList>();
    let zs = match listed
        .then(|| zs.extract::<Vec<Option<Vec<f64>>>>().ok())
        .flatten()
    {
        Some(rows) if rows.iter().any(Option::is_none) => {
            let filled: Vec<Vec<f64>> = rows
                .into_iter()
                .map(|r| r.unwrap_or_else(|| vec![f64::NAN; p]))
                .collect();
            filled.into_pyobject(zs.py())?.into_any()
        }
        _ => match listed
            .then(|| zs.extract::<Vec<Option<f64>>>().ok())
            .flatten()
        {
            Some(rows) if rows.iter().any(Option::is_none) => rows
                .into_iter()
                .map(|v| v.unwrap_or(f64::NAN))
                .collect::<Vec<f64>>()
                .into_pyobject(zs.py())?
                .into_any(),
            _ => zs.clone(),
        },
    };
    let (v, shape) = nd(&zs, "zs")?;
    let rows = match shape.as_slice() {
        [rows] if p == 1 => *rows,
        [rows, c] if *c == p => *rows,
        s => {
            return Err(raise(
                Kind::InvalidInput,
                format!("zs has shape {s:?}: it must be (N, {p}) (or (N,) for one component)"),
                None,
            ))
        }
    };
    Ok((v, rows))
}

/// One step's matrices from Python (`None` where not given): `F`, `Q`, `B`, `u`, `H`, `R` for a
/// model of `n` states and `p` components (a number for `Q` or `R`: times the identity).
#[derive(Default)]
struct OneStep {
    f: Option<DMatrix<f64>>,
    q: Option<DMatrix<f64>>,
    b: Option<DMatrix<f64>>,
    u: Option<DVector<f64>>,
    h: Option<DMatrix<f64>>,
    r: Option<DMatrix<f64>>,
}

type Arg<'a, 'py> = Option<&'a Bound<'py, PyAny>>;

impl OneStep {
    /// `[u, B, F, Q, H, R]` as given.
    fn parse(n: usize, p: usize, args: [Arg<'_, '_>; 6]) -> PyResult<Self> {
        let [u, b, f, q, h, r] = args.map(|o| o.filter(|o| !o.is_none()));
        let m = |o: Arg<'_, '_>, name, square, row| {
            o.map(|o| matrix_from(o, name, square, row)).transpose()
        };
        Ok(Self {
            f: m(f, "F", Some(n), false)?,
            q: m(q, "Q", Some(n), false)?,
            b: m(b, "B", None, false)?,
            u: match u {
                Some(u) => Some(DVector::from_vec(nd(u, "u")?.0)),
                None => None,
            },
            h: m(h, "H", None, true)?,
            r: m(r, "R", Some(p), false)?,
        })
    }

    fn matrices(&self) -> StepMatrices<'_> {
        StepMatrices {
            f: self.f.as_ref(),
            q: self.q.as_ref(),
            b: self.b.as_ref(),
            u: self.u.as_ref(),
            h: self.h.as_ref(),
            r: self.r.as_ref(),
        }
    }
}

/// `(N, n)` and `(N, n, n)` arrays from row-major values.
fn states_and_covariances<'py>(
    py: Python<'py>,
    states: Vec<f64>,
    covariances: Vec<f64>,
    n: usize,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let count = states.len() / n;
    Ok((
        matrix(py, states, count, n)?,
        PyArray1::from_vec(py, covariances)
            .reshape([count, n, n])?
            .into_any(),
    ))
}

/// A new `(rows, n, n)` array of zeros allocated by numpy, for the library to write into.
fn cube(py: Python<'_>, rows: usize, n: usize) -> Bound<'_, PyArray3<f64>> {
    PyArray3::zeros(py, [rows, n, n], false)
}

/// The Kalman filter on a discrete-time linear model given by its matrices (filterpy's
/// ``KalmanFilter``): ``x_k = F x_{k-1} + B u_k + w``, ``w ~ N(0, Q)``; ``z_k = H x_k + v``,
/// ``v ~ N(0, R)``. One ``predict`` then one ``update`` per step; every matrix may also be
/// given for one step (``predict(F=...)``, ``update(R=...)``) or one per step in a batch.
///
/// Parameters
/// ----------
/// x0 : array_like, shape (n,)
///     The prior state.
/// P0 : array_like, shape (n, n), or float
///     Its covariance (a number: times the identity); symmetric positive semidefinite.
/// F : array_like, shape (n, n)
///     The transition matrix.
/// H : array_like, shape (p, n)
///     The observation matrix (a 1-D array: one component).
/// Q : array_like, shape (n, n), or float
///     The process-noise covariance over one step (e.g. filterpy's
///     ``Q_discrete_white_noise``); symmetric positive semidefinite.
/// R : array_like, shape (p, p), or float
///     The measurement-noise covariance; symmetric positive semidefinite.
/// B : array_like, shape (n, c), optional
///     The control matrix: ``predict(u)`` adds ``B u``.
///
/// The update is Joseph's form, ``P = (I - K H) P (I - K H)ᵀ + K R Kᵀ`` (Morrison (12.3.7)),
/// the gain from a Cholesky factorisation of ``H P Hᵀ + R``; a NaN in ``z`` is a missing
/// component (left out), all NaN a prediction only. A refused call (``SeqsmoothError``,
/// naming the matrix, and in a batch ``.index`` the step) leaves the filter unchanged.
#[pyclass(name = "LinearKalmanFilter", module = "seqsmooth")]
pub struct PyLinearKalmanFilter {
    inner: LinearKalmanFilter,
}

#[pymethods]
impl PyLinearKalmanFilter {
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
    #[allow(non_snake_case, clippy::too_many_arguments)]
    #[pyo3(signature = (x0, P0, F, H, Q, R, B = None))]
    fn new(
        x0: &Bound<'_, PyAny>,
        P0: &Bound<'_, PyAny>,
        F: &Bound<'_, PyAny>,
        H: &Bound<'_, PyAny>,
        Q: &Bound<'_, PyAny>,
        R: &Bound<'_, PyAny>,
        B: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let (x, _) = nd(x0, "x0")?;
        let n = x.len();
        let h = matrix_from(H, "H", None, true)?;
        let p = h.nrows();
        let mut inner = LinearKalmanFilter::new(
            DVector::from_vec(x),
            matrix_from(P0, "P0", Some(n), false)?,
            matrix_from(F, "F", Some(n), false)?,
            h,
            matrix_from(Q, "Q", Some(n), false)?,
            matrix_from(R, "R", Some(p), false)?,
        )
        .py()?;
        if let Some(b) = B.filter(|b| !b.is_none()) {
            inner = inner.with_control(matrix_from(b, "B", None, false)?).py()?;
        }
        Ok(Self { inner })
    }

    /// The estimate ``x``, shape ``(n,)``; settable (checked: ``n`` finite numbers).
    #[getter]
    fn x<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.state().as_slice())
    }

    #[setter(x)]
    fn set_x(&mut self, x: &Bound<'_, PyAny>) -> PyResult<()> {
        let (v, _) = nd(x, "x")?;
        let p = self.inner.covariance().clone();
        self.inner.set_estimate(DVector::from_vec(v), p).py()
    }

    /// Its covariance ``P``, shape ``(n, n)``; settable (checked: symmetric positive
    /// semidefinite, finite).
    #[getter(P)]
    fn p<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        square(py, self.inner.covariance())
    }

    #[setter(P)]
    fn set_p(&mut self, p: &Bound<'_, PyAny>) -> PyResult<()> {
        let n = self.inner.dimension();
        let p = matrix_from(p, "P", Some(n), false)?;
        let x = self.inner.state().clone();
        self.inner.set_estimate(x, p).py()
    }

    /// ``x`` (the name of the other filters); settable as ``x``.
    #[getter]
    fn state<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.x(py)
    }

    #[setter]
    fn set_state(&mut self, x: &Bound<'_, PyAny>) -> PyResult<()> {
        self.set_x(x)
    }

    /// ``P`` (the name of the other filters); settable as ``P``.
    #[getter]
    fn covariance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.p(py)
    }

    #[setter]
    fn set_covariance(&mut self, p: &Bound<'_, PyAny>) -> PyResult<()> {
        self.set_p(p)
    }

    /// The 1σ of each state component, ``sqrt(diag(P))``.
    #[getter]
    fn std_devs<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.std_devs())
    }

    /// The steps taken (predictions).
    #[getter]
    fn steps(&self) -> usize {
        self.inner.steps()
    }

    /// The constant ``F``; settable (checked).
    #[getter(F)]
    fn f<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        square(py, self.inner.matrices().0)
    }

    #[setter(F)]
    fn set_f(&mut self, m: &Bound<'_, PyAny>) -> PyResult<()> {
        self.set_matrix("F", m)
    }

    /// The constant ``H``; settable (checked).
    #[getter(H)]
    fn h<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        square(py, self.inner.matrices().1)
    }

    #[setter(H)]
    fn set_h(&mut self, m: &Bound<'_, PyAny>) -> PyResult<()> {
        self.set_matrix("H", m)
    }

    /// The constant ``Q``; settable (checked).
    #[getter(Q)]
    fn q<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        square(py, self.inner.matrices().2)
    }

    #[setter(Q)]
    fn set_q(&mut self, m: &Bound<'_, PyAny>) -> PyResult<()> {
        self.set_matrix("Q", m)
    }

    /// The constant ``R``; settable (checked).
    #[getter(R)]
    fn r<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        square(py, self.inner.matrices().3)
    }

    #[setter(R)]
    fn set_r(&mut self, m: &Bound<'_, PyAny>) -> PyResult<()> {
        self.set_matrix("R", m)
    }

    /// Predicts one step: ``x = F x + B u``, ``P = F P Fᵀ + Q``, with this step's ``F``,
    /// ``Q``, ``B`` where given (the constants otherwise). ``u`` needs a ``B``.
    #[allow(non_snake_case)]
    #[pyo3(signature = (u = None, B = None, F = None, Q = None))]
    fn predict(
        &mut self,
        u: Option<&Bound<'_, PyAny>>,
        B: Option<&Bound<'_, PyAny>>,
        F: Option<&Bound<'_, PyAny>>,
        Q: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let (n, p) = (self.inner.dimension(), self.inner.components());
        let step = OneStep::parse(n, p, [u, B, F, Q, None, None])?;
        self.inner.predict(&step.matrices()).py()
    }

    /// Updates with ``z`` (``p`` values, or a number for one component; NaN a missing
    /// component; ``None`` or all NaN: nothing to update), with this step's ``R``, ``H`` where
    /// given. Returns the :class:`Innovation` (``None`` when nothing was measured).
    #[allow(non_snake_case)]
    #[pyo3(signature = (z, R = None, H = None))]
    fn update(
        &mut self,
        z: Option<&Bound<'_, PyAny>>,
        R: Option<&Bound<'_, PyAny>>,
        H: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Option<PyInnovation>> {
        let p = self.inner.components();
        let z = match z.filter(|z| !z.is_none()) {
            Some(z) => nd(z, "z")?.0,
            None => vec![f64::NAN; p],
        };
        let step = OneStep::parse(self.inner.dimension(), p, [None, None, None, None, H, R])?;
        Ok(self
            .inner
            .update(&z, &step.matrices())
            .py()?
            .map(PyInnovation::from))
    }

    /// ``predict`` then ``update`` for each measurement of ``zs`` (``(N, p)``, or ``(N,)`` for
    /// one component; NaN a missing component, a row of NaN a prediction only), as filterpy's
    /// ``batch_filter``. ``Fs``, ``Qs``, ``Hs``, ``Rs``, ``Bs``: one matrix for every step, or
    /// one per step (a leading axis of ``N``); ``us``: ``(N, c)`` or one ``(c,)``. Returns
    /// ``(means, covariances, means_p, covariances_p)``: the updated and the predicted
    /// estimates, ``(N, n)`` and ``(N, n, n)``, as filterpy's. The filter ends at the last
    /// step. The work runs without the GIL. On an error (``.index`` names the step) the steps
    /// before it are taken.
    #[allow(non_snake_case, clippy::too_many_arguments)]
    #[pyo3(signature = (zs, Fs = None, Qs = None, Hs = None, Rs = None, Bs = None, us = None))]
    fn update_many<'py>(
        &mut self,
        py: Python<'py>,
        zs: &Bound<'py, PyAny>,
        Fs: Option<&Bound<'py, PyAny>>,
        Qs: Option<&Bound<'py, PyAny>>,
        Hs: Option<&Bound<'py, PyAny>>,
        Rs: Option<&Bound<'py, PyAny>>,
        Bs: Option<&Bound<'py, PyAny>>,
        us: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let (z, rows) = measurements(zs, self.inner.components())?;
        let steps = Steps::new(&self.inner, rows, Fs, Qs, Hs, Rs, Bs, us)?;
        let n = self.inner.dimension();
        // The four outputs allocated by numpy and filled in place (no batch-long buffer and
        // copy; numpy maps a large array in huge pages where the system allows it).
        let (x, p) = (PyArray2::zeros(py, [rows, n], false), cube(py, rows, n));
        let (xp, pp) = (PyArray2::zeros(py, [rows, n], false), cube(py, rows, n));
        {
            let (mut xw, mut pw) = (x.readwrite(), p.readwrite());
            let (mut xpw, mut ppw) = (xp.readwrite(), pp.readwrite());
            let contiguous = "a new array is contiguous";
            let out = PassInto {
                states: xw.as_slice_mut().expect(contiguous),
                covariances: pw.as_slice_mut().expect(contiguous),
                predicted_states: xpw.as_slice_mut().expect(contiguous),
                predicted_covariances: ppw.as_slice_mut().expect(contiguous),
                nis: None,
            };
            let inner = &mut self.inner;
            py.detach(|| inner.update_many_into(&z, |k| steps.at(k), out))
                .py()?;
        }
        PyTuple::new(
            py,
            [x.into_any(), p.into_any(), xp.into_any(), pp.into_any()],
        )
    }

    /// The Rauch–Tung–Striebel smoother over a forward pass's ``Xs`` ``(N, n)`` and ``Ps``
    /// ``(N, n, n)`` (``update_many``'s first two outputs), with the same ``Fs``, ``Qs``,
    /// ``Bs``, ``us`` as that pass: each prediction is the filter's own (``x_{k+1|k} = F x +
    /// B u``), so no measurement is read again. Returns ``(x, P, K, Pp)`` as filterpy's
    /// ``rts_smoother``: smoothed states and covariances, the smoother gains ``K[k] = P[k]
    /// Fᵀ Pp[k]⁻¹`` and the predicted covariances ``Pp[k] = F P[k] Fᵀ + Q`` (the last gain 0,
    /// the last ``Pp`` its own ``P``). filterpy leaves ``B u`` out of the smoother's
    /// prediction; here it is in.
    #[allow(non_snake_case, clippy::too_many_arguments)]
    #[pyo3(signature = (Xs, Ps, Fs = None, Qs = None, Bs = None, us = None))]
    fn rts_smoother<'py>(
        &self,
        py: Python<'py>,
        Xs: &Bound<'py, PyAny>,
        Ps: &Bound<'py, PyAny>,
        Fs: Option<&Bound<'py, PyAny>>,
        Qs: Option<&Bound<'py, PyAny>>,
        Bs: Option<&Bound<'py, PyAny>>,
        us: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let n = self.inner.dimension();
        let (xs, xshape) = nd(Xs, "Xs")?;
        let (ps, pshape) = nd(Ps, "Ps")?;
        let rows = xshape.first().copied().unwrap_or(0);
        if xshape != [rows, n] || pshape != [rows, n, n] {
            return Err(raise(
                Kind::InvalidInput,
                format!("Xs {xshape:?} and Ps {pshape:?}: they must be (N, {n}) and (N, {n}, {n})"),
                None,
            ));
        }
        let steps = Steps::new(&self.inner, rows, Fs, Qs, None, None, Bs, us)?;
        let inner = &self.inner;
        let out = py
            .detach(|| inner.rts_smoother(&xs, &ps, |k| steps.at(k)))
            .py()?;
        let flat = |get: &dyn Fn(&seqsmooth::kalman::RtsStep) -> Vec<f64>| -> Vec<f64> {
            out.iter().flat_map(get).collect()
        };
        // Row-major: a symmetric covariance is its own transpose; a gain is not.
        let x = flat(&|s| s.state.as_slice().to_vec());
        let p = flat(&|s| s.covariance.transpose().as_slice().to_vec());
        let k = flat(&|s| s.gain.transpose().as_slice().to_vec());
        let pp = flat(&|s| s.predicted_covariance.transpose().as_slice().to_vec());
        let (x, p) = states_and_covariances(py, x, p, n)?;
        let (_, k) = states_and_covariances(py, vec![0.0; rows * n], k, n)?;
        let (_, pp) = states_and_covariances(py, vec![0.0; rows * n], pp, n)?;
        PyTuple::new(py, [x, p, k, pp])
    }

    /// The fixed-lag smoother from this filter's estimate (the filter itself is not
    /// changed): each measurement's estimate from the ``lag`` measurements after it (the last
    /// ``lag`` from all), in memory bounded by ``lag``, the per-step matrices as in
    /// ``update_many``. Returns ``(states, covariances)``, ``(N, n)`` and ``(N, n, n)``.
    #[allow(non_snake_case, clippy::too_many_arguments)]
    #[pyo3(signature = (zs, lag, Fs = None, Qs = None, Hs = None, Rs = None, Bs = None, us = None))]
    fn fixed_lag_smoother<'py>(
        &self,
        py: Python<'py>,
        zs: &Bound<'py, PyAny>,
        lag: usize,
        Fs: Option<&Bound<'py, PyAny>>,
        Qs: Option<&Bound<'py, PyAny>>,
        Hs: Option<&Bound<'py, PyAny>>,
        Rs: Option<&Bound<'py, PyAny>>,
        Bs: Option<&Bound<'py, PyAny>>,
        us: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let (z, rows) = measurements(zs, self.inner.components())?;
        let steps = Steps::new(&self.inner, rows, Fs, Qs, Hs, Rs, Bs, us)?;
        let n = self.inner.dimension();
        let (mut x, mut p) = (vec![0.0; rows * n], vec![0.0; rows * n * n]);
        let inner = &self.inner;
        py.detach(|| {
            inner.fixed_lag(
                &z,
                lag,
                |k| steps.at(k),
                |k, s| {
                    x[k * n..(k + 1) * n].copy_from_slice(s.state.as_slice());
                    p[k * n * n..(k + 1) * n * n].copy_from_slice(s.covariance.as_slice());
                },
            )
        })
        .py()?;
        let (x, p) = states_and_covariances(py, x, p, n)?;
        PyTuple::new(py, [x, p])
    }

    fn __repr__(&self) -> String {
        format!(
            "LinearKalmanFilter(states={}, components={}, steps={})",
            self.inner.dimension(),
            self.inner.components(),
            self.inner.steps()
        )
    }
}

impl PyLinearKalmanFilter {
    /// Sets the constant matrix `name` (`F`, `H`, `Q` or `R`) to `m`, checked by the library.
    fn set_matrix(&mut self, name: &str, m: &Bound<'_, PyAny>) -> PyResult<()> {
        let (n, p) = (self.inner.dimension(), self.inner.components());
        let square = match name {
            "Q" => Some(n),
            "R" => Some(p),
            _ => None,
        };
        let m = matrix_from(m, name, square, name == "H")?;
        let mut step = StepMatrices::default();
        match name {
            "F" => step.f = Some(&m),
            "H" => step.h = Some(&m),
            "Q" => step.q = Some(&m),
            _ => step.r = Some(&m),
        }
        self.inner.set_matrices(&step).py()
    }
}

/// The fixed-lag smoother on a :class:`LinearKalmanFilter`'s model, a measurement at a time
/// (filterpy's ``FixedLagSmoother.smooth``, with the exact fixed-lag estimates): each step's
/// estimate from the ``lag`` steps after it, given once they are in, in memory bounded by the
/// lag however long it runs.
///
/// Parameters
/// ----------
/// filter : LinearKalmanFilter
///     The model and the estimate to start from (not changed).
/// lag : int
///     The lag, in measurements.
#[pyclass(name = "LinearFixedLagSmoother", module = "seqsmooth")]
pub struct PyLinearFixedLagSmoother {
    inner: Option<LinearFixedLag>,
    n: usize,
}

/// `(index, state, covariance)` of a smoothed step.
fn smoothed_tuple<'py>(
    py: Python<'py>,
    index: usize,
    s: &Smoothed,
) -> PyResult<Bound<'py, PyTuple>> {
    let state = PyArray1::from_slice(py, s.state.as_slice()).into_any();
    let covariance = square(py, &s.covariance)?;
    PyTuple::new(py, [index.into_pyobject(py)?.into_any(), state, covariance])
}

#[pymethods]
impl PyLinearFixedLagSmoother {
    /// ``pickle`` support (``copy.copy`` and ``copy.deepcopy`` too): the smoother's state in
    /// the library's saved form, restored bit for bit. Filters are mutable: a copy is a deep
    /// copy of the state, and the copy and the original then run apart.
    /// A smoother after ``finish`` cannot be saved (it holds nothing more).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        persist::reduce_saved(slf.as_any(), slf.borrow().smoother()?)
    }

    /// The smoother ``__reduce__`` saved (a ``DamagedStateError`` if ``state`` is damaged or
    /// another class's).
    #[staticmethod]
    fn _from_state(state: &Bound<'_, PyAny>) -> PyResult<Self> {
        let inner: LinearFixedLag = persist::load(state)?;
        let n = inner.dimension();
        Ok(Self {
            inner: Some(inner),
            n,
        })
    }

    #[new]
    fn new(filter: PyRef<'_, PyLinearKalmanFilter>, lag: usize) -> Self {
        Self {
            inner: Some(LinearFixedLag::new(&filter.inner, lag)),
            n: filter.inner.dimension(),
        }
    }

    /// The measurements pushed so far.
    #[getter]
    fn pushed(&self) -> PyResult<usize> {
        Ok(self.smoother()?.pushed())
    }

    /// The lag, in measurements.
    #[getter]
    fn lag(&self) -> PyResult<usize> {
        Ok(self.smoother()?.lag())
    }

    /// One step: the prediction and the update with ``z`` (NaN a missing component) and this
    /// step's matrices where given. Returns ``(index, state, covariance)``, the step ``lag``
    /// before smoothed by every step since, or ``None`` while fewer than ``lag`` are in. On an
    /// error the smoother is unchanged.
    #[allow(non_snake_case, clippy::too_many_arguments)]
    #[pyo3(signature = (z, u = None, B = None, F = None, Q = None, H = None, R = None))]
    fn update<'py>(
        &mut self,
        py: Python<'py>,
        z: &Bound<'py, PyAny>,
        u: Option<&Bound<'py, PyAny>>,
        B: Option<&Bound<'py, PyAny>>,
        F: Option<&Bound<'py, PyAny>>,
        Q: Option<&Bound<'py, PyAny>>,
        H: Option<&Bound<'py, PyAny>>,
        R: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Option<Bound<'py, PyTuple>>> {
        let n = self.n;
        let smoother = self.smoother_mut()?;
        let index = smoother.pushed().checked_sub(smoother.lag());
        let z = nd(z, "z")?.0;
        let step = OneStep::parse(n, z.len(), [u, B, F, Q, H, R])?;
        match smoother.push(&z, &step.matrices()).py()? {
            Some(s) => Ok(Some(smoothed_tuple(py, index.unwrap_or(0), &s)?)),
            None => Ok(None),
        }
    }

    /// The steps held (the last ``lag``), each smoothed by every step pushed: ``(indices,
    /// states, covariances)``, ``(m,)``, ``(m, n)`` and ``(m, n, n)``. The smoother is spent.
    fn finish<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let smoother = self.inner.take().ok_or_else(spent)?;
        let first = smoother.pushed() - smoother.pushed().min(smoother.lag());
        let out = smoother.finish().py()?;
        let n = self.n;
        let x: Vec<f64> = out.iter().flat_map(|s| s.state.iter().copied()).collect();
        let p: Vec<f64> = out
            .iter()
            .flat_map(|s| s.covariance.iter().copied())
            .collect();
        let indices: Vec<usize> = (first..first + out.len()).collect();
        let (x, p) = states_and_covariances(py, x, p, n)?;
        PyTuple::new(py, [PyArray1::from_vec(py, indices).into_any(), x, p])
    }
}

/// The error of a smoother used after `finish`.
fn spent() -> PyErr {
    raise(
        Kind::InvalidInput,
        "the smoother is finished: make a new one",
        None,
    )
}

impl PyLinearFixedLagSmoother {
    fn smoother(&self) -> PyResult<&LinearFixedLag> {
        self.inner.as_ref().ok_or_else(spent)
    }

    fn smoother_mut(&mut self) -> PyResult<&mut LinearFixedLag> {
        self.inner.as_mut().ok_or_else(spent)
    }
}
