//! Prints the accuracy of the fixed-memory sliding engine over long runs, and the drift of the
//! naive sliding recursion that the engine's refreshes prevent: the table BENCHMARKS.md quotes.
//! The tests in `tests/fixed_filter.rs` assert bounds on the same measurements
//! (`tests/common/fixed.rs`).
//!
//! Run: `cargo run --release -p seqsmooth --example accuracy_fixed_filter`
//!
//! Data: `100 sin(2πn/5000) + 50` plus uniform noise in ±0.5, rounded to multiples of 2⁻⁴⁰.
//! Reported: the worst error of the scaled estimate against `W(0)` applied to the stored
//! window (checked every `every` samples and over the last window) and of the final state
//! against exact least squares, relative to the data scale.

#[path = "../tests/common/mod.rs"]
mod common;

use common::fixed::{
    naive_sliding_drift, sliding_long_run, SLIDING_ACCEPTANCE_RUN, SLIDING_HIGHER_DEGREE_RUNS,
    SLIDING_SHORTER_RUNS,
};

fn main() {
    println!("Sliding engine against the exact window fit");
    println!();
    println!("| m | window | samples | checked every | worst relative error |");
    println!("|---:|---:|---:|---:|---:|");
    let runs = std::iter::once(SLIDING_ACCEPTANCE_RUN)
        .chain(SLIDING_SHORTER_RUNS)
        .chain(SLIDING_HIGHER_DEGREE_RUNS);
    for (m, window, total, every, seed) in runs {
        let e = sliding_long_run(m, window, total, every, seed);
        println!("| {m} | {window} | {total} | {every} | {e:.2e} |");
    }
    println!();
    let (naive, engine) = naive_sliding_drift();
    println!(
        "m = 2, L = 100, after 10⁵ samples: naive sliding recursion {naive:.2e}, engine {engine:.2e}"
    );
}
