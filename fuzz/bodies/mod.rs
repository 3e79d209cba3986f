//! The bodies of the fuzz targets: each takes the fuzzer's bytes, decodes its own parameters
//! from them ([`input`]) and panics when an invariant fails. Included both by the cargo-fuzz
//! targets (`fuzz/fuzz_targets/*.rs`, nightly) and by the stable replay test
//! (`crates/seqsmooth-cli/tests/fuzz_replay.rs`), which runs every file of
//! `fuzz/corpus/<target>/` through the same body.
//!
//! Invariants every body checks: no panic; every number written or returned is finite (NaN
//! only where the API documents it as "not determined"); an `Err` is a typed error with a
//! non-empty message. Time-outs (> 10 s on one input) are failures too: libFuzzer's
//! `-timeout=10` and the replay test's clock.
#![allow(dead_code)]

pub mod check;
pub mod cli;
pub mod csv_layer;
pub mod filters;
pub mod input;
pub mod number;

/// A target's body: panics when an invariant fails on the input.
pub type Body = fn(&[u8]);

/// The targets, by name: `fuzz/corpus/<name>/` and `fuzz/regressions/<name>/` hold their
/// inputs.
pub const TARGETS: [(&str, Body); 4] = [
    ("csv", csv_layer::run),
    ("number", number::run),
    ("filters", filters::run),
    ("cli", cli::run),
];
