//! Array-likes from Python as `f64` slices: a contiguous `float64` numpy array is borrowed (no
//! copy); any other real array-like (lists, integers, `float32`, strided views, pandas
//! series) goes through `numpy.asarray` and is converted once, by numpy. Complex, string, object and
//! date arrays, and arrays of the wrong shape, are refused with [`Kind::InvalidType`] /
//! [`Kind::InvalidInput`] naming the argument.

use crate::errors::{raise, Kind};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyUntypedArrayMethods};
use pyo3::prelude::*;

/// A contiguous one-dimensional `f64` array from Python: the caller's own, or the
/// conversion of what the caller passed.
pub struct Series<'py>(PyReadonlyArray1<'py, f64>);

impl Series<'_> {
    /// The values.
    pub fn as_slice(&self) -> &[f64] {
        self.0.as_slice().expect("contiguous by construction")
    }
}

/// `numpy.asarray(obj)`, its failure an [`Kind::InvalidType`] error naming `name`.
fn asarray<'py>(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<Bound<'py, PyAny>> {
    let np = obj.py().import("numpy")?;
    np.call_method1("asarray", (obj,)).map_err(|e| {
        raise(
            Kind::InvalidType,
            format!("{name} is not an array of numbers: {e}"),
            None,
        )
    })
}

/// `obj` as a one-dimensional series of reals, named `name` in errors.
pub fn series<'py>(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<Series<'py>> {
    if let Ok(a) = obj.cast::<PyArray1<f64>>() {
        let a = a.readonly();
        if a.is_contiguous() {
            return Ok(Series(a));
        }
    }
    let array = asarray(obj, name)?;
    let kind: String = array.getattr("dtype")?.getattr("kind")?.extract()?;
    if !matches!(kind.as_str(), "f" | "i" | "u") {
        let dtype = array.getattr("dtype")?.str()?.to_string();
        return Err(raise(
            Kind::InvalidType,
            format!("{name} has dtype {dtype}: it must hold real numbers (float, int)"),
            None,
        ));
    }
    let ndim: usize = array.getattr("ndim")?.extract()?;
    if ndim != 1 {
        let shape = array.getattr("shape")?.str()?.to_string();
        return Err(raise(
            Kind::InvalidInput,
            format!("{name} has shape {shape}: it must be one-dimensional"),
            None,
        ));
    }
    let np = obj.py().import("numpy")?;
    let converted = np.call_method1("ascontiguousarray", (array, "float64"))?;
    Ok(Series(converted.cast::<PyArray1<f64>>()?.readonly()))
}

/// Two series of one length, `t` and `y`, none empty.
pub fn pair<'py>(
    t: &Bound<'py, PyAny>,
    y: &Bound<'py, PyAny>,
) -> PyResult<(Series<'py>, Series<'py>)> {
    let (ts, ys) = (series(t, "t")?, series(y, "y")?);
    let (nt, ny) = (ts.as_slice().len(), ys.as_slice().len());
    if nt != ny {
        return Err(raise(
            Kind::InvalidInput,
            format!("t has {nt} values and y {ny}: one time per value"),
            None,
        ));
    }
    if nt == 0 {
        return Err(raise(
            Kind::InvalidInput,
            "t and y are empty: a batch needs at least one sample",
            None,
        ));
    }
    Ok((ts, ys))
}

/// `rows × cols` values (row-major) as a numpy array of that shape, without a copy.
pub fn matrix<'py>(
    py: Python<'py>,
    values: Vec<f64>,
    rows: usize,
    cols: usize,
) -> PyResult<Bound<'py, PyAny>> {
    PyArray1::from_vec(py, values)
        .reshape([rows, cols])
        .map(Bound::into_any)
}

/// `obj` as a row-major table of reals, named `name` in errors: a 2-D array as it is, a 1-D
/// array as one column; its values (contiguous, row-major), rows and columns.
pub fn table<'py>(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<(Series<'py>, usize, usize)> {
    let array = asarray(obj, name)?;
    let ndim: usize = array.getattr("ndim")?.extract()?;
    let (rows, cols) = match ndim {
        1 => (array.getattr("shape")?.get_item(0)?.extract()?, 1),
        2 => array.getattr("shape")?.extract()?,
        _ => {
            let shape = array.getattr("shape")?.str()?.to_string();
            return Err(raise(
                Kind::InvalidInput,
                format!("{name} has shape {shape}: it must be one- or two-dimensional"),
                None,
            ));
        }
    };
    let flat = array.call_method1("reshape", (-1,))?;
    Ok((series(&flat, name)?, rows, cols))
}
