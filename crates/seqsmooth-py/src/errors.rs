//! The library's [`seqsmooth::Error`] as the Python exceptions of `seqsmooth.errors` (defined
//! in Python, so that `InvalidTypeError` can be both an `InvalidInputError` and a
//! `TypeError`): the class by the kind of error, the message the library's, and the sample's
//! index for an error inside a batch.

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::PyType;
use seqsmooth::error::{ErrorKind, Param};
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

/// Every parameter the library's errors name, its kind and the name of its Python class, for
/// the test that walks every parameter to its class.
#[pyfunction]
pub fn parameter_kinds() -> Vec<(&'static str, &'static str, &'static str)> {
    Param::ALL
        .iter()
        .map(|&p| {
            let e = Error::InvalidParameter {
                name: p,
                value: String::new(),
                reason: String::new(),
            };
            (p.name(), e.kind().name(), Kind::of(&e).class_name())
        })
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

/// The package's word for a parameter the library's errors name: its keyword where it differs
/// from the library's word ([`Param::name`]). The spelling of every call but `smooth`'s.
pub fn keyword(p: Param) -> Option<&'static str> {
    match p {
        Param::ReviewWindow => Some("review_window"),
        Param::SigmaPointAlpha => Some("sigma_points alpha"),
        Param::SigmaPointBeta => Some("sigma_points beta"),
        Param::SigmaPointKappa => Some("sigma_points kappa"),
        Param::AzimuthConvention => Some("azimuth"),
        Param::Coefficients => Some("n"),
        Param::TransitionMatrixF => Some("F"),
        Param::ObservationMatrixH => Some("H"),
        Param::ProcessNoiseQ => Some("Q"),
        Param::MeasurementNoiseR => Some("R"),
        Param::ControlMatrixB => Some("B"),
        Param::ControlInputU => Some("u"),
        Param::StateCovarianceP => Some("P"),
        Param::TransitionFunction => Some("f"),
        Param::TransitionJacobian => Some("F_jacobian"),
        Param::ObservationFunction => Some("h"),
        Param::ObservationJacobian => Some("H_jacobian"),
        Param::ProcessNoiseFunction => Some("Q"),
        Param::AngleComponents => Some("angles"),
        Param::DerivativeFunction => Some("dxdt"),
        Param::DerivativeJacobian => Some("dxdt_jacobian"),
        Param::DynamicsMatrixA => Some("A"),
        Param::SpectralDensity => Some("Qc"),
        Param::ManoeuvreAlpha => Some("manoeuvre_alpha"),
        Param::ManoeuvreVariance => Some("manoeuvre_variance"),
        Param::MotionModel => Some("model"),
        Param::TurnRateNoise => Some("turn_rate_noise"),
        _ => None,
    }
}

/// The words of `smooth`, scipy's `savgol_filter` names: `window_length`, `polyorder`,
/// `deriv`.
pub fn scipy(p: Param) -> Option<&'static str> {
    match p {
        Param::Window => Some("window_length"),
        Param::Degree => Some("polyorder"),
        Param::Derivative => Some("deriv"),
        Param::Step => Some("delta"),
        _ => keyword(p),
    }
}

/// A library error as its Python exception; `offset` is added to a batch index (the batch
/// was a slice of the caller's arrays starting there).
pub fn to_py(error: Error, offset: usize) -> PyErr {
    to_py_in(error, offset, &keyword)
}

/// [`to_py`], the parameter named by `spell` (the words of the call: [`keyword`], [`scipy`]).
pub fn to_py_in(
    error: Error,
    offset: usize,
    spell: &dyn Fn(Param) -> Option<&'static str>,
) -> PyErr {
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
        (Error::InBatch { source, .. }, Some(i)) => {
            format!("sample {i} of the batch: {}", source.message_in(spell))
        }
        _ => error.message_in(spell),
    };
    raise(Kind::of(&error), message, index)
}

/// `Result<T, Error>` into `PyResult<T>`.
pub trait IntoPy<T> {
    /// The error as its Python exception, a batch index shifted by `offset`.
    fn py_at(self, offset: usize) -> PyResult<T>;
    /// The error as its Python exception.
    fn py(self) -> PyResult<T>;
    /// The error as its Python exception, its parameter in the words of `spell`.
    fn py_in(self, spell: &dyn Fn(Param) -> Option<&'static str>) -> PyResult<T>;
}

impl<T> IntoPy<T> for Result<T, Error> {
    fn py_at(self, offset: usize) -> PyResult<T> {
        self.map_err(|e| to_py(e, offset))
    }
    fn py(self) -> PyResult<T> {
        self.py_at(0)
    }
    fn py_in(self, spell: &dyn Fn(Param) -> Option<&'static str>) -> PyResult<T> {
        self.map_err(|e| to_py_in(e, 0, spell))
    }
}
