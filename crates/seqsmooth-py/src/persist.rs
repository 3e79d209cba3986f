//! `pickle`, `copy` and `deepcopy` of the filter classes: each class's `__reduce__` returns
//! `(seqsmooth._persist.restore, (cls, state))`, `state` the library's saved form
//! ([`seqsmooth::persist`]; with a class's own Python objects beside it where it has any),
//! and `cls._from_state(state)` builds the filter again. A copy is thus a deep copy of the
//! filter's state, bit for bit. A damaged state raises `DamagedStateError`.

use crate::errors::{raise, IntoPy, Kind};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyTuple, PyType};
use seqsmooth::persist::{from_bytes, to_bytes, Persist};

/// The library's saved form of `value`, as Python bytes.
pub(crate) fn save<'py, T: Persist>(py: Python<'py>, value: &T) -> PyResult<Bound<'py, PyAny>> {
    Ok(PyBytes::new(py, &to_bytes(value).py()?).into_any())
}

/// The value `state` (bytes) holds, checked by the library.
pub(crate) fn load<T: Persist>(state: &Bound<'_, PyAny>) -> PyResult<T> {
    let bytes = state
        .cast::<PyBytes>()
        .map_err(|_| damaged("the saved state is not bytes"))?;
    from_bytes(bytes.as_bytes()).py()
}

/// A `DamagedStateError` saying `why`.
pub(crate) fn damaged(why: impl Into<String>) -> PyErr {
    raise(
        Kind::DamagedState,
        format!("damaged saved state: {}", why.into()),
        None,
    )
}

/// What `__reduce__` returns: `(seqsmooth._persist.restore, (type(obj), state))`.
pub(crate) fn reduce<'py>(
    obj: &Bound<'py, PyAny>,
    state: Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyTuple>> {
    let py = obj.py();
    let restore = py.import("seqsmooth._persist")?.getattr("restore")?;
    let args = PyTuple::new(py, [obj.get_type().into_any(), state])?;
    PyTuple::new(py, [restore, args.into_any()])
}

/// What `__reduce__` returns for a class whose state is the saved form of `value` alone.
pub(crate) fn reduce_saved<'py, T: Persist>(
    obj: &Bound<'py, PyAny>,
    value: &T,
) -> PyResult<Bound<'py, PyTuple>> {
    reduce(obj, save(obj.py(), value)?)
}

/// `obj` if it is exactly of class `cls`, else the `DamagedStateError` of another class's
/// state.
pub(crate) fn of_class<'py>(
    obj: Bound<'py, PyAny>,
    cls: &Bound<'py, PyType>,
) -> PyResult<Bound<'py, PyAny>> {
    if obj.get_type().is(cls) {
        Ok(obj)
    } else {
        Err(damaged(format!(
            "the state of a {}, not of a {}",
            obj.get_type().name()?,
            cls.name()?
        )))
    }
}

/// A tuple `state` of `n` items, else the `DamagedStateError`.
pub(crate) fn items<'py>(state: &Bound<'py, PyAny>, n: usize) -> PyResult<Bound<'py, PyTuple>> {
    match state.cast::<PyTuple>() {
        Ok(t) if t.len() == n => Ok(t.clone()),
        _ => Err(damaged(format!("a tuple of {n} items expected"))),
    }
}
