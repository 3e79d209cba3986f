//! Fuzz target `number`: the body is `fuzz/bodies/number.rs` (replayed on stable by
//! `crates/seqsmooth-cli/tests/fuzz_replay.rs`).
#![no_main]

#[path = "../bodies/mod.rs"]
mod bodies;

libfuzzer_sys::fuzz_target!(|data: &[u8]| bodies::number::run(data));
