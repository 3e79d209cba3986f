//! Array-likes from Python as `f64` slices: a contiguous `float64` numpy array is borrowed (no
//! copy); any other real array-like (lists, integers, `float32`, strided views, pandas
//! series) goes through `numpy.asarray` and is converted once, by numpy. Complex, string and
//! object arrays, and arrays of the wrong shape, are refused with [`Kind::InvalidType`] /
//! [`Kind::InvalidInput`] naming the argument.
//!
//! Times ([`times`]) may also be dates: numpy `datetime64` of any unit, pandas datetime columns
//! (tz-aware too), Polars `Datetime` / `Date`, Arrow timestamps and dates, read as seconds since
//! the Unix epoch by the library's rule ([`seqsmooth::numeric::epoch`], as the command reads
//! Parquet timestamps and ISO-8601 cells); a `timedelta64` as its seconds. A naive date is UTC.

use crate::errors::{raise, Kind};
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::IntoPyDict;

/// A contiguous, aligned one-dimensional `f64` array from Python: the caller's own, or the
/// conversion of what the caller passed.
pub struct Series<'py>(PyReadonlyArray1<'py, f64>);

impl<'py> Series<'py> {
    /// `a` when it can be read as a slice (contiguous and aligned), else an error (never a
    /// panic: a contiguous array unpickled from a buffer may be unaligned).
    fn new(a: PyReadonlyArray1<'py, f64>, name: &str) -> PyResult<Self> {
        if a.as_slice().is_err() {
            return Err(raise(
                Kind::InvalidInput,
                format!("{name} could not be read as a contiguous, aligned float64 array"),
                None,
            ));
        }
        Ok(Series(a))
    }

    /// The values.
    pub fn as_slice(&self) -> &[f64] {
        self.0.as_slice().unwrap_or(&[])
    }
}

/// `numpy.require(array, dtype, ["C", "A"])`: contiguous and aligned (a copy only when needed).
fn contiguous_aligned<'py, T: IntoPyObject<'py>>(
    array: &Bound<'py, PyAny>,
    dtype: T,
) -> PyResult<Bound<'py, PyAny>> {
    let np = array.py().import("numpy")?;
    np.call_method1("require", (array, dtype, vec!["C", "A"]))
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

/// The error of an array `name` that is not one-dimensional.
fn one_dimensional(array: &Bound<'_, PyAny>, name: &str) -> PyResult<()> {
    let ndim: usize = array.getattr("ndim")?.extract()?;
    if ndim != 1 {
        let shape = array.getattr("shape")?.str()?.to_string();
        return Err(raise(
            Kind::InvalidInput,
            format!("{name} has shape {shape}: it must be one-dimensional"),
            None,
        ));
    }
    Ok(())
}

/// `obj` as a one-dimensional series of reals, named `name` in errors.
pub fn series<'py>(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<Series<'py>> {
    if let Ok(a) = obj.cast::<PyArray1<f64>>() {
        let a = a.readonly();
        if a.as_slice().is_ok() {
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
    one_dimensional(&array, name)?;
    let converted = contiguous_aligned(&array, "float64")?;
    Series::new(converted.cast::<PyArray1<f64>>()?.readonly(), name)
}

/// `obj` as one-dimensional times, named `name` in errors: reals as [`series`] takes them, or
/// dates (`datetime64`, pandas, Polars, Arrow) and durations (`timedelta64`) as seconds since
/// the Unix epoch (the rule of [`seqsmooth::numeric::epoch`]); `NaT` is refused with its index.
pub fn times<'py>(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<Series<'py>> {
    if obj.cast::<PyArray1<f64>>().is_ok() {
        return series(obj, name);
    }
    let py = obj.py();
    let np = py.import("numpy")?;
    // A tz-aware pandas column becomes an object array through `numpy.asarray`: take its UTC
    // instants in its own unit instead.
    let dtype = obj.getattr("dtype").ok();
    let tz_aware = dtype.as_ref().is_some_and(|d| {
        d.getattr("tz").is_ok_and(|tz| !tz.is_none()) && obj.hasattr("to_numpy").unwrap_or(false)
    });
    let array = if tz_aware {
        let unit: String = dtype
            .as_ref()
            .and_then(|d| d.getattr("unit").ok())
            .and_then(|u| u.extract().ok())
            .unwrap_or_else(|| "ns".to_string());
        obj.call_method(
            "to_numpy",
            (),
            Some(&[("dtype", format!("datetime64[{unit}]"))].into_py_dict(py)?),
        )?
    } else {
        asarray(obj, name)?
    };
    let kind: String = array.getattr("dtype")?.getattr("kind")?.extract()?;
    if !matches!(kind.as_str(), "M" | "m") {
        return series(&array, name);
    }
    one_dimensional(&array, name)?;
    let (unit, count): (String, i64) = np
        .call_method1("datetime_data", (array.getattr("dtype")?,))?
        .extract()?;
    let ticks =
        contiguous_aligned(&array, array.getattr("dtype")?)?.call_method1("view", ("int64",))?;
    let ticks = ticks.cast::<PyArray1<i64>>()?.readonly();
    let Ok(ticks) = ticks.as_slice() else {
        return Err(raise(
            Kind::InvalidInput,
            format!("{name} could not be read as a contiguous, aligned array of dates"),
            None,
        ));
    };
    let dtype = array.getattr("dtype")?.str()?.to_string();
    let seconds = tick_seconds(ticks, &unit, count, kind == "M").map_err(|(i, why)| {
        raise(
            Kind::InvalidInput,
            format!("{name}[{i}] ({dtype}): {why}"),
            Some(i),
        )
    })?;
    let out = PyArray1::from_vec(py, seconds);
    Series::new(out.readonly(), name)
}

/// numpy's `datetime64` / `timedelta64` ticks of `count` × `unit` as seconds (since the Unix
/// epoch for dates), or the index of the first that has none (`NaT`) and why.
fn tick_seconds(
    ticks: &[i64],
    unit: &str,
    count: i64,
    date: bool,
) -> Result<Vec<f64>, (usize, String)> {
    use seqsmooth::numeric::epoch::{days_from_civil, seconds_from_ticks};
    // Seconds per tick as num/den, or a calendar unit.
    let (num, den) = match unit {
        "W" => (604_800, 1),
        "D" => (86_400, 1),
        "h" => (3_600, 1),
        "m" => (60, 1),
        "s" => (1, 1),
        "ms" => (1, 1_000),
        "us" | "μs" => (1, 1_000_000),
        "ns" => (1, 1_000_000_000),
        "ps" => (1, 1_000_000_000_000),
        "fs" => (1, 1_000_000_000_000_000),
        "as" => (1, 1_000_000_000_000_000_000),
        "Y" | "M" if date => (0, 0),
        other => {
            return Err((
                0,
                format!("the unit '{other}' has no fixed length in seconds"),
            ))
        }
    };
    let mut out = Vec::with_capacity(ticks.len());
    for (i, &k) in ticks.iter().enumerate() {
        if k == i64::MIN {
            return Err((i, "NaT (not a time) has no seconds".into()));
        }
        let v = match k.checked_mul(count) {
            None => None,
            Some(k) if num == 0 => {
                // Years or months since 1970: their first day.
                let months = if unit == "Y" {
                    k.checked_mul(12)
                } else {
                    Some(k)
                };
                months.and_then(|mo| {
                    let (y, m) = (1970 + mo.div_euclid(12), mo.rem_euclid(12) as u32 + 1);
                    seconds_from_ticks(days_from_civil(y, m, 1), 86_400, 1).ok()
                })
            }
            Some(k) => seconds_from_ticks(k, num, den).ok(),
        };
        match v {
            Some(v) => out.push(v),
            None => return Err((i, format!("{k} ticks of {count} {unit} overflow"))),
        }
    }
    Ok(out)
}

/// Two series of one length, `t` and `y`, none empty.
pub fn pair<'py>(
    t: &Bound<'py, PyAny>,
    y: &Bound<'py, PyAny>,
) -> PyResult<(Series<'py>, Series<'py>)> {
    let (ts, ys) = (times(t, "t")?, series(y, "y")?);
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

/// A new `rows × cols` array of zeros allocated by numpy, for the library to write into: numpy's
/// allocator asks the kernel for huge pages for a large array (where the system allows it), so
/// its first writes take one page fault per 2 MiB rather than per 4 KiB — for a batch's rows
/// the larger part of the time of a fast filter (BENCHMARKS.md, "The batch σ path").
pub fn zeros(py: Python<'_>, rows: usize, cols: usize) -> Bound<'_, PyArray2<f64>> {
    PyArray2::zeros(py, [rows, cols], false)
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

/// ``t`` as float64 seconds: numbers as they are; dates (numpy ``datetime64`` of any unit,
/// pandas datetime columns, tz-aware too, Polars ``Datetime`` / ``Date``, Arrow timestamps and
/// dates) as seconds since the Unix epoch, a naive date read as UTC; ``timedelta64`` as
/// seconds — what every entry point that takes times does with them (the library's rule,
/// ``seqsmooth::numeric::epoch``, as the command reads Parquet timestamps and ISO-8601 cells).
///
/// Raises
/// ------
/// InvalidInputError
///     ``NaT`` (``.index`` its position), a calendar unit without a fixed length.
/// InvalidTypeError
///     anything else that is not real numbers.
#[pyfunction]
#[pyo3(signature = (t, name = "t"))]
pub fn seconds<'py>(
    py: Python<'py>,
    t: &Bound<'py, PyAny>,
    name: &str,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let s = times(t, name)?;
    Ok(PyArray1::from_slice(py, s.as_slice()))
}
