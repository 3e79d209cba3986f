//! The command's errors and their exit codes.

use seqsmooth::error::{ErrorKind, Param};
use thiserror::Error;

/// Why a command failed. The message is printed after `error: ` on stderr.
#[derive(Debug, Error)]
pub enum CliError {
    /// The arguments are inconsistent or out of range (exit code 2, clap's for its own errors).
    #[error("{0}")]
    Usage(String),
    /// The input data or a file is unusable (exit code 1).
    #[error("{0}")]
    Data(String),
    /// The reader of our output went away (e.g. `seqsmooth … | head`): stop quietly.
    #[error("broken pipe")]
    BrokenPipe,
}

impl CliError {
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Usage(_) => 2,
            CliError::Data(_) => 1,
            CliError::BrokenPipe => 0,
        }
    }

    /// An error writing the output named `what` (a file name or "standard output").
    pub fn write(what: &str, e: std::io::Error) -> Self {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            CliError::BrokenPipe
        } else {
            CliError::Data(format!("cannot write to {what}: {e}"))
        }
    }
}

/// The command's word for each parameter the library's errors name ([`seqsmooth::Param`]):
/// its flag. The one table of the command's spelling; a parameter no flag sets (the data's, a
/// model's) keeps the library's word.
pub fn flag(p: Param) -> Option<&'static str> {
    Some(match p {
        Param::Degree => "--degree",
        Param::Theta => "--theta",
        Param::Beta => "--beta",
        Param::Tau => "--tau",
        Param::Window => "--window",
        Param::Lead => "--lead",
        Param::Derivative => "--derivative",
        Param::Sigma => "--sigma",
        Param::Q => "--q",
        Param::MaxIterations => "--max-iterations",
        Param::ReviewWindow => "--review-window",
        Param::Site => "--site",
        Param::SegmentLength => "--segment",
        Param::AzimuthConvention => "--azimuth",
        Param::NewestIndex => "--n",
        Param::Epoch => "--epoch",
        Param::MotionModel => "--model",
        Param::ManoeuvreAlpha => "--manoeuvre-alpha",
        Param::ManoeuvreVariance => "--manoeuvre-variance",
        Param::TurnRateNoise => "--turn-rate-noise",
        _ => return None,
    })
}

/// A library error by its kind ([`seqsmooth::error::ErrorKind`], the library's rule): a
/// setting out of range is a usage error (exit code 2, as for a bad argument), anything else a
/// data error (1). The message names a parameter by its flag ([`flag`]). Every library error
/// the command reports becomes a `CliError` here (with [`CliError::reworded`] for context).
impl From<seqsmooth::Error> for CliError {
    fn from(e: seqsmooth::Error) -> Self {
        let message = e.message_in(&flag);
        match e.kind() {
            ErrorKind::Parameter => CliError::Usage(message),
            ErrorKind::InvalidInput
            | ErrorKind::TooFewSamples
            | ErrorKind::NotDetermined
            | ErrorKind::Numerical => CliError::Data(message),
        }
    }
}

impl CliError {
    /// The same error (so the same exit code) with its message rewritten by `f`: a library
    /// error put in context (`line 7: …`).
    pub fn reworded(self, f: impl FnOnce(String) -> String) -> Self {
        match self {
            CliError::Usage(m) => CliError::Usage(f(m)),
            CliError::Data(m) => CliError::Data(f(m)),
            CliError::BrokenPipe => CliError::BrokenPipe,
        }
    }
}
