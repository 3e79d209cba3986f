//! Prints the accuracy of the batch paths (`PolynomialFilter::update_many`) against the
//! compensated per-sample path: the tables the `polynomial` module docs quote. The tests in
//! `tests/batch.rs` assert bounds on the same measurements (`tests/common/batch.rs`).
//!
//! Run: `cargo run --release -p seqsmooth --example accuracy_batch`
//!
//! 1. Fading-memory plain-`f64` steady kernel, 60 000 samples at `t = k·0.1`, `τ = 0.1`, a sine
//!    of amplitude 100 plus a trend and unit noise, one batch of 20 000 then batches of 101: the
//!    largest difference over the second half of the run, relative to the largest `|x^(k)|`
//!    there, worst over `k`, per degree and θ.
//! 2. Expanding-memory plain-`f64` kernel (degrees ≤ 4; above, `update_many` takes the
//!    compensated path), same data in batches of 101, even and ±30 % jittered times, from sample
//!    `10(m+1)` on.
//! 3. `update_many` in batches of varied lengths against `update`, 3000 samples, every filter.

#[path = "../tests/common/mod.rs"]
mod common;

use common::batch::{
    plain_expanding_kernel_error, plain_steady_kernel_error, update_many_difference,
};

fn main() {
    let thetas = [0.5, 0.9, 0.99, 0.999];
    println!("Fading memory, plain steady kernel vs compensated per-sample path");
    println!();
    println!("| m | θ = 0.5 | θ = 0.9 | θ = 0.99 | θ = 0.999 |");
    println!("|---:|---:|---:|---:|---:|");
    for m in 0..=8 {
        let row: Vec<String> = thetas
            .iter()
            .map(|&theta| format!("{:.1e}", plain_steady_kernel_error(m, theta).0))
            .collect();
        println!("| {m} | {} |", row.join(" | "));
    }
    println!();
    println!("Expanding memory, plain kernel vs compensated per-sample path");
    println!();
    println!("| times | m = 0 | 1 | 2 | 3 | 4 | 5 | 6 | 7 | 8 |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for jitter in [false, true] {
        let row: Vec<String> = (0..=8)
            .map(|m| format!("{:.1e}", plain_expanding_kernel_error(m, jitter)))
            .collect();
        println!(
            "| {} | {} |",
            if jitter { "±30 %" } else { "even" },
            row.join(" | ")
        );
    }
    println!();
    println!("update_many vs update, 3000 samples, batches of varied lengths");
    println!();
    println!("| m | times | filter | largest relative difference |");
    println!("|---:|---|---|---:|");
    for m in [0, 1, 2, 3, 5, 8] {
        for irregular in [false, true] {
            for (name, worst) in update_many_difference(m, irregular) {
                let times = if irregular { "irregular" } else { "even" };
                println!("| {m} | {times} | {name} | {worst:.2e} |");
            }
        }
    }
}
