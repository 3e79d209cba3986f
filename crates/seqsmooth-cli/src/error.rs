//! The command's errors and their exit codes.

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

/// A library error by its kind ([`seqsmooth::error::ErrorKind`], the library's rule): a
/// setting out of range is a usage error (exit code 2, as for a bad argument), anything else a
/// data error (1).
impl From<seqsmooth::Error> for CliError {
    fn from(e: seqsmooth::Error) -> Self {
        match e.kind() {
            seqsmooth::error::ErrorKind::Parameter => CliError::Usage(e.to_string()),
            _ => CliError::Data(e.to_string()),
        }
    }
}
