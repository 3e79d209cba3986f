//! The library's [`seqsmooth::Error`] as the Python exceptions of `seqsmooth.errors` (defined
//! in Python, so that `InvalidTypeError` can be both an `InvalidInputError` and a
//! `TypeError`): the class by the kind of error, the message the library's, and the sample's
//! index for an error inside a batch.

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::PyType;
use seqsmooth::error::ErrorKind;
use seqsmooth::Error;

/// The Python class of each kind of error (its name in `seqsmooth.errors`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    InvalidInput,
    InvalidType,
    Parameter,
    TooFewSamples,
    NotDetermined,
    Numerical,
}

impl Kind {
    fn class_name(self) -> &'static str {
        match self {
            Kind::InvalidInput => "InvalidInputError",
            Kind::InvalidType => "InvalidTypeError",
            Kind::Parameter => "ParameterError",
            Kind::TooFewSamples => "TooFewSamplesError",
            Kind::NotDetermined => "NotDeterminedError",
            Kind::Numerical => "NumericalError",
        }
    }

    /// The class of a library error: its [`ErrorKind`] (the library's rule; inside a batch,
    /// its cause's).
    pub fn of(error: &Error) -> Kind {
        Kind::of_kind(error.kind())
    }

    /// The class of each library [`ErrorKind`], one for one.
    fn of_kind(kind: ErrorKind) -> Kind {
        match kind {
            ErrorKind::InvalidInput => Kind::InvalidInput,
            ErrorKind::Parameter => Kind::Parameter,
            ErrorKind::TooFewSamples => Kind::TooFewSamples,
            ErrorKind::NotDetermined => Kind::NotDetermined,
            ErrorKind::Numerical => Kind::Numerical,
        }
    }
}

/// The library's error kinds and the name of each one's Python class, for the test that walks
/// every kind to its class.
#[pyfunction]
pub fn error_kinds() -> Vec<(&'static str, &'static str)> {
    ErrorKind::ALL
        .iter()
        .map(|&k| (k.name(), Kind::of_kind(k).class_name()))
        .collect()
}

/// An exception of `kind` with `message` and `index` (the offending sample's position).
pub fn raise(kind: Kind, message: impl Into<String>, index: Option<usize>) -> PyErr {
    let message = message.into();
    Python::attach(|py| {
        let class = py
            .import("seqsmooth.errors")
            .and_then(|m| m.getattr(kind.class_name()))
            .and_then(|c| c.cast_into::<PyType>().map_err(PyErr::from));
        match class.and_then(|c| c.call1((message.clone(), index))) {
            Ok(instance) => PyErr::from_value(instance),
            // The package's own module is missing: still an exception, never a panic.
            Err(e) => PyRuntimeError::new_err(format!("{message} (and seqsmooth.errors: {e})")),
        }
    })
}

/// A library error as its Python exception; `offset` is added to a batch index (the batch
/// was a slice of the caller's arrays starting there).
pub fn to_py(error: Error, offset: usize) -> PyErr {
    // A bank's error is its channel's: the row's index and the cause.
    let error = match error {
        Error::InChannel { source, .. } if matches!(*source, Error::InBatch { .. }) => *source,
        other => other,
    };
    let index = match &error {
        Error::InBatch { index, .. } => Some(index + offset),
        _ => None,
    };
    let message = match (&error, index) {
        (Error::InBatch { source, .. }, Some(i)) => format!("sample {i} of the batch: {source}"),
        _ => error.to_string(),
    };
    raise(Kind::of(&error), message, index)
}

/// `Result<T, Error>` into `PyResult<T>`.
pub trait IntoPy<T> {
    /// The error as its Python exception, a batch index shifted by `offset`.
    fn py_at(self, offset: usize) -> PyResult<T>;
    /// The error as its Python exception.
    fn py(self) -> PyResult<T>;
}

impl<T> IntoPy<T> for Result<T, Error> {
    fn py_at(self, offset: usize) -> PyResult<T> {
        self.map_err(|e| to_py(e, offset))
    }
    fn py(self) -> PyResult<T> {
        self.py_at(0)
    }
}
