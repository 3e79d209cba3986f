//! Unit tests of `error`: every library error kind to its exit code, by the library's rule
//! (`seqsmooth::error::ErrorKind`), never by the error's name.

use seqsmooth::error::{Error, ErrorKind, Param};
use seqsmooth_cli::error::{flag, CliError};

/// An error of each kind (the match is exhaustive: a new kind fails to compile here).
fn example(kind: ErrorKind) -> Error {
    match kind {
        ErrorKind::InvalidInput => Error::InvalidParameter {
            name: Param::Azimuth,
            value: "7".into(),
            reason: "is outside [-2pi, 2pi]".into(),
        },
        ErrorKind::Parameter => Error::InvalidParameter {
            name: Param::Window,
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
        ErrorKind::DamagedState => Error::DamagedState {
            reason: "checksum mismatch: a byte has changed".into(),
        },
    }
}

#[test]
fn every_kind_has_its_exit_code() {
    for kind in ErrorKind::ALL {
        let e = example(kind);
        assert_eq!(e.kind(), kind);
        let message = e.message_in(&flag);
        let cli = CliError::from(e);
        let want = if kind == ErrorKind::Parameter { 2 } else { 1 };
        assert_eq!(cli.exit_code(), want, "{kind:?}");
        assert_eq!(cli.to_string(), message);
        // Put in context, the error keeps its exit code.
        let line = cli.reworded(|m| format!("line 7: {m}"));
        assert_eq!(line.exit_code(), want, "{kind:?}");
        assert_eq!(line.to_string(), format!("line 7: {message}"));
    }
    // Every parameter's refusal takes its kind's exit code, named by its flag where it has one.
    for &p in Param::ALL {
        let e = Error::InvalidParameter {
            name: p,
            value: "0".into(),
            reason: "test".into(),
        };
        let want = if p.kind() == ErrorKind::Parameter {
            2
        } else {
            1
        };
        let cli = CliError::from(e);
        assert_eq!(cli.exit_code(), want, "{p:?}");
        let word = flag(p).unwrap_or(p.name());
        assert_eq!(cli.to_string(), format!("{word} 0 is invalid: test"));
    }
    // The command's words: a setting by its flag, the data by the library's word.
    assert_eq!(
        CliError::from(Error::ThetaOutOfRange { theta: 1.5 }).to_string(),
        "--theta 1.5 is out of range: it must lie strictly between 0 and 1"
    );
    assert_eq!(
        CliError::from(example(ErrorKind::Parameter)).to_string(),
        "--window 0 is invalid: must be at least 1"
    );
    assert_eq!(
        CliError::from(example(ErrorKind::InvalidInput)).to_string(),
        "azimuth 7 is invalid: is outside [-2pi, 2pi]"
    );
    // A window longer than the series, and no default tau from the data: exit code 1.
    let short = CliError::from(Error::TooFewSamplesFor {
        param: Param::Window,
        needed: 31,
        got: 30,
    });
    assert_eq!(short.exit_code(), 1);
    assert_eq!(
        short.to_string(),
        "too few samples for --window 31: 30 given, at least 31 needed"
    );
    let tau = CliError::from(Error::NoDefault {
        param: Param::Tau,
        why: "no step".into(),
    });
    assert_eq!(tau.exit_code(), 1);
    assert_eq!(
        tau.to_string(),
        "the data give no default --tau: no step; give --tau"
    );
    // Inside a batch, the kind (and so the exit code) is the cause's.
    let batch = Error::InBatch {
        index: 4,
        source: Box::new(example(ErrorKind::Parameter)),
    };
    assert_eq!(CliError::from(batch).exit_code(), 2);
}
