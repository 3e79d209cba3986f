//! Unit tests of `error`: every library error kind to its exit code, by the library's rule
//! (`seqsmooth::error::ErrorKind`), never by the error's name.

use seqsmooth::error::{Error, ErrorKind};
use seqsmooth_cli::error::CliError;

/// An error of each kind (the match is exhaustive: a new kind fails to compile here).
fn example(kind: ErrorKind) -> Error {
    match kind {
        ErrorKind::InvalidInput => Error::InvalidParameter {
            name: "azimuth",
            value: "7".into(),
            reason: "is outside [-2pi, 2pi]".into(),
        },
        ErrorKind::Parameter => Error::InvalidParameter {
            name: "window",
            value: "0".into(),
            reason: "must be at least 1".into(),
        },
        ErrorKind::TooFewSamples => Error::TooFewSamples { needed: 3, got: 1 },
        ErrorKind::NotDetermined => Error::NotDetermined {
            samples: 1,
            why: "one sample".into(),
        },
        ErrorKind::Numerical => Error::NotConverged {
            iterations: 20,
            correction: 1.0,
            tolerance: 1e-9,
            chi_squared: 1e5,
        },
    }
}

#[test]
fn every_kind_has_its_exit_code() {
    for kind in ErrorKind::ALL {
        let e = example(kind);
        assert_eq!(e.kind(), kind);
        let message = e.to_string();
        let cli = CliError::from(e);
        let want = if kind == ErrorKind::Parameter { 2 } else { 1 };
        assert_eq!(cli.exit_code(), want, "{kind:?}");
        assert_eq!(cli.to_string(), message);
    }
    // Inside a batch, the kind (and so the exit code) is the cause's.
    let batch = Error::InBatch {
        index: 4,
        source: Box::new(example(ErrorKind::Parameter)),
    };
    assert_eq!(CliError::from(batch).exit_code(), 2);
}
