//! Prints the accuracy of the filter banks (`polynomial::bank`) against the single-stream gain
//! engines: the numbers the `polynomial::bank` module docs quote. The tests in `tests/bank.rs`
//! assert bounds on the same measurements (`tests/common/bank.rs`).
//!
//! Run: `cargo run --release -p seqsmooth --example accuracy_bank`
//!
//! Data per channel: a slow sine of channel-dependent phase and size, a trend and a unit
//! pseudo-random term. Reported: the largest difference per derivative `k`, relative to the
//! largest `|x^(k)|` of the single stream over the run, worst over `k` (and per `k`).

#[path = "../tests/common/mod.rs"]
mod common;

use common::bank::{compare_expanding, compare_fading};

fn worst(rel: &[f64]) -> f64 {
    rel.iter().copied().fold(0.0, f64::max)
}

fn fmt(rel: &[f64]) -> String {
    let v: Vec<String> = rel.iter().map(|r| format!("{r:.1e}")).collect();
    v.join(", ")
}

fn main() {
    println!("FadingBank vs FadingMemory (gain engine), θ = 0.95, τ = 1, 2 channels, 10⁴ steps");
    println!();
    println!("| m | worst over k | per k |");
    println!("|---:|---:|---|");
    for m in 1..=4 {
        let rel = compare_fading(m, 0.95, 1.0, 2, 10_000, m);
        println!("| {m} | {:.1e} | {} |", worst(&rel), fmt(&rel));
    }
    println!();
    println!("FadingBank vs FadingMemory (gain engine), θ = 0.9, τ = 0.5");
    println!();
    println!("| K | steps | m | worst over k |");
    println!("|---:|---:|---:|---:|");
    for k in [1, 7, 1000] {
        let steps = if k == 1000 { 150 } else { 400 };
        for m in 0..=4 {
            let rel = compare_fading(m, 0.9, 0.5, k, steps, m);
            println!("| {k} | {steps} | {m} | {:.1e} |", worst(&rel));
        }
    }
    println!();
    println!("ExpandingBank vs ExpandingMemory (gain engine), 7 channels, 300 steps");
    println!("(difference relative to max(|x|, 1))");
    println!();
    println!("| m | largest difference |");
    println!("|---:|---:|");
    for m in 0..=4 {
        println!("| {m} | {:.1e} |", compare_expanding(m));
    }
}
