//! The even-time banks as Python classes, `FadingBank` and `ExpandingBank`: `K` filters of one
//! configuration fed one time step of all channels at a time (`update`) or a `(time × K)`
//! matrix (`update_many`), the channels on the rayon pool without the GIL (Morrison Tables
//! 9.1 and 13.1 per channel; Reyneke et al.'s image-sensor bank).

use crate::arrays::{matrix, table};
use crate::errors::{raise, IntoPy, Kind};
use crate::persist;
use pyo3::prelude::*;
use pyo3::types::{PyTuple, PyType};
use seqsmooth::polynomial::bank::{ExpandingBank, FadingBank};
use seqsmooth::Error;

/// What the two banks share, for the one set of Python methods below.
trait Bank: Send {
    fn degree(&self) -> usize;
    fn channels(&self) -> usize;
    fn samples(&self) -> u64;
    fn rows(&mut self, matrix: &[f64]) -> Result<(), Error>;
    fn derivative_into(&self, k: usize, out: &mut [f64]) -> Result<(), Error>;
    fn save<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>>;
}

macro_rules! bank {
    ($ty:ty) => {
        impl Bank for $ty {
            fn degree(&self) -> usize {
                <$ty>::degree(self)
            }
            fn channels(&self) -> usize {
                <$ty>::channels(self)
            }
            fn samples(&self) -> u64 {
                <$ty>::samples(self)
            }
            fn rows(&mut self, matrix: &[f64]) -> Result<(), Error> {
                self.update_rows_par(matrix)
            }
            fn derivative_into(&self, k: usize, out: &mut [f64]) -> Result<(), Error> {
                <$ty>::derivative_into(self, k, out)
            }
            fn save<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
                persist::save(py, self)
            }
        }
    };
}
bank!(FadingBank);
bank!(ExpandingBank);

/// The time steps of `y` (one row of `K` values, or `n × K`) into `bank`; on a bad row the
/// rows before it are taken and the error names the row.
fn update(py: Python<'_>, bank: &mut dyn Bank, y: &Bound<'_, PyAny>) -> PyResult<()> {
    let (values, rows, cols) = table(y, "y")?;
    let k = bank.channels();
    let (rows, cols) = if cols == 1 && rows == k {
        (1, k)
    } else {
        (rows, cols)
    };
    if cols != k {
        return Err(raise(
            Kind::InvalidInput,
            format!("y has {cols} columns: the bank has {k} channels (one column each)"),
            None,
        ));
    }
    if rows == 0 {
        return Err(raise(Kind::InvalidInput, "y has no time steps", None));
    }
    let values = values.as_slice();
    py.detach(|| bank.rows(values)).py()
}

/// Every channel's estimate, `K × (m+1)` unscaled derivatives (NaN before `m+1` steps).
fn estimates<'py>(py: Python<'py>, bank: &dyn Bank) -> PyResult<Bound<'py, PyAny>> {
    let (k, w) = (bank.channels(), bank.degree() + 1);
    let mut columns = vec![f64::NAN; k * w];
    if bank.samples() > bank.degree() as u64 {
        for (d, column) in columns.chunks_exact_mut(k).enumerate() {
            bank.derivative_into(d, column).py()?;
        }
    }
    let mut rows = vec![0.0; k * w];
    for (d, column) in columns.chunks_exact(k).enumerate() {
        for (c, &v) in column.iter().enumerate() {
            rows[c * w + d] = v;
        }
    }
    matrix(py, rows, k, w)
}

/// The base of the banks: ``update``, ``estimate`` and ``samples`` (the banks differ only in
/// how they are made).
#[pyclass(name = "Bank", module = "seqsmooth", subclass)]
pub struct PyBank {
    bank: Box<dyn Bank + Sync>,
}

#[pymethods]
impl PyBank {
    /// ``pickle`` support (``copy.copy`` and ``copy.deepcopy`` too): the bank's state in
    /// the library's saved form, restored bit for bit. Filters are mutable: a copy is a deep
    /// copy of the state, and the copy and the original then run apart.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let state = slf.borrow().bank.save(slf.py())?;
        persist::reduce(slf.as_any(), state)
    }

    /// The time steps taken.
    #[getter]
    fn samples(&self) -> u64 {
        self.bank.samples()
    }
    /// Takes one time step (``K`` values) or many (``n × K``).
    fn update(&mut self, py: Python<'_>, y: &Bound<'_, PyAny>) -> PyResult<()> {
        update(py, &mut *self.bank, y)
    }
    /// Every channel's estimate, ``K × (m+1)`` (NaN before ``m+1`` steps).
    fn estimate<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        estimates(py, &*self.bank)
    }
}

/// ``channels`` fading-memory filters of degree ``degree`` on evenly spaced samples (step
/// ``tau``), discount ``theta`` per sample (Morrison Table 13.1, started by the
/// expanding-memory gains of Table 9.1 until the switch of §13.8).
///
/// ``update(y)`` takes one time step (``K`` values) or many (an ``n × K`` array);
/// ``estimate()`` returns every channel's ``[x, x', …]`` as a ``K × (m+1)`` array.
#[pyclass(name = "FadingBank", module = "seqsmooth", extends = PyBank)]
pub struct PyFadingBank;

#[pymethods]
impl PyFadingBank {
    /// The bank ``__reduce__`` saved (a ``DamagedStateError`` if ``state`` is damaged or
    /// another class's).
    #[classmethod]
    fn _from_state<'py>(
        cls: &Bound<'py, PyType>,
        state: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let bank: Box<FadingBank> = Box::new(persist::load(state)?);
        let obj = Bound::new(
            cls.py(),
            PyClassInitializer::from(PyBank { bank }).add_subclass(Self),
        )?;
        persist::of_class(obj.into_any(), cls)
    }

    #[new]
    #[pyo3(signature = (degree, theta, channels, tau = 1.0))]
    fn new(
        degree: usize,
        theta: f64,
        channels: usize,
        tau: f64,
    ) -> PyResult<PyClassInitializer<Self>> {
        let bank = Box::new(FadingBank::new(degree, theta, tau, channels).py()?);
        Ok(PyClassInitializer::from(PyBank { bank }).add_subclass(Self))
    }
}

/// ``channels`` expanding-memory filters of degree ``degree`` on evenly spaced samples (step
/// ``tau``; Morrison Table 9.1). Methods as :class:`FadingBank`.
#[pyclass(name = "ExpandingBank", module = "seqsmooth", extends = PyBank)]
pub struct PyExpandingBank;

#[pymethods]
impl PyExpandingBank {
    /// The bank ``__reduce__`` saved (a ``DamagedStateError`` if ``state`` is damaged or
    /// another class's).
    #[classmethod]
    fn _from_state<'py>(
        cls: &Bound<'py, PyType>,
        state: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let bank: Box<ExpandingBank> = Box::new(persist::load(state)?);
        let obj = Bound::new(
            cls.py(),
            PyClassInitializer::from(PyBank { bank }).add_subclass(Self),
        )?;
        persist::of_class(obj.into_any(), cls)
    }

    #[new]
    #[pyo3(signature = (degree, channels, tau = 1.0))]
    fn new(degree: usize, channels: usize, tau: f64) -> PyResult<PyClassInitializer<Self>> {
        let bank = Box::new(ExpandingBank::new(degree, tau, channels).py()?);
        Ok(PyClassInitializer::from(PyBank { bank }).add_subclass(Self))
    }
}
