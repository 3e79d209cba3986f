//! Fuzz target `filters`: the body is `fuzz/bodies/filters.rs` (replayed on stable by
//! `crates/seqsmooth-cli/tests/fuzz_replay.rs`).
#![no_main]

#[path = "../bodies/mod.rs"]
mod bodies;

libfuzzer_sys::fuzz_target!(|data: &[u8]| bodies::filters::run(data));
