//! Fuzz target `csv`: the body is `fuzz/bodies/csv_layer.rs` (replayed on stable by
//! `crates/seqsmooth-cli/tests/fuzz_replay.rs`).
#![no_main]

#[path = "../bodies/mod.rs"]
mod bodies;

libfuzzer_sys::fuzz_target!(|data: &[u8]| bodies::csv_layer::run(data));
