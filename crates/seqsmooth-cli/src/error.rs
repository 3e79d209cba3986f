//! The command's errors and their exit codes.

use thiserror::Error;

/// Exit code of a command-line (argument) error; clap uses the same code for its own.
pub const EXIT_USAGE: u8 = 2;
/// Exit code of an input-data or file error.
pub const EXIT_DATA: u8 = 1;

/// Why a command failed. The message is printed after `error: ` on stderr.
#[derive(Debug, Error)]
pub enum CliError {
    /// The arguments are inconsistent or out of range (exit code 2).
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
            CliError::Usage(_) => EXIT_USAGE,
            CliError::Data(_) => EXIT_DATA,
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
