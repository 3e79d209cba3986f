//! Prints the accuracy of whole-series smoothing (`polynomial::fixed::smooth`, the sliding
//! engine) against the convolution with the exact weights, summed error-free: the table in
//! ACCURACY.md. `tests/fixed_sliding_smooth.rs` asserts the bound (1e-11) on the same
//! measurement (`tests/common/smooth.rs`).
//!
//! Run: `cargo run --release -p seqsmooth --example accuracy_smooth`

#[path = "../tests/common/mod.rs"]
mod common;

use common::smooth::{worst_error, SMOOTH_RUNS};

fn main() {
    println!("| m | window | samples | d0 | d1 | d2 |");
    println!("|---|---|---|---|---|---|");
    for (m, window, len) in SMOOTH_RUNS {
        let e: Vec<String> = worst_error(m, window, len)
            .iter()
            .map(|v| format!("{v:.1e}"))
            .collect();
        println!("| {m} | {window} | {len} | {} |", e.join(" | "));
    }
}
