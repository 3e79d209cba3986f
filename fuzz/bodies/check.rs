//! The invariants the bodies share.

use seqsmooth::PolynomialState;
use std::fmt::Display;

/// An error is typed and says why: its message is not empty.
pub fn error_message(e: &impl Display) {
    let text = e.to_string();
    assert!(!text.trim().is_empty(), "an error with an empty message");
}

/// Every number of `values` is finite (`what` names them in the panic).
pub fn finite(values: &[f64], what: &str) {
    if let Some(v) = values.iter().find(|v| !v.is_finite()) {
        panic!("{what}: non-finite {v} in {values:?}");
    }
}

/// An estimate's time, derivatives and covariance are finite, and it has derivatives.
pub fn state(s: &PolynomialState, what: &str) {
    assert!(s.time.is_finite(), "{what}: time {}", s.time);
    assert!(!s.derivatives.is_empty(), "{what}: no derivatives");
    finite(&s.derivatives, what);
    if let Some(c) = &s.covariance {
        finite(c.as_slice(), &format!("{what} covariance"));
    }
    if let Some(sd) = s.std_devs() {
        finite(&sd, &format!("{what} std devs"));
    }
}

/// Whether to print the decoded call (environment variable `FUZZ_TRACE` set): how the
/// reproducers in the findings were decoded.
pub fn trace() -> bool {
    static TRACE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *TRACE.get_or_init(|| std::env::var_os("FUZZ_TRACE").is_some())
}
