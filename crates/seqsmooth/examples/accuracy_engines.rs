//! Prints the accuracy of both engines of the expanding- and fading-memory filters against
//! least squares: the numbers the `polynomial` module docs quote ("Accuracy"). The tests in
//! `tests/expanding_filter.rs`, `tests/fading_filter.rs` and `tests/exact_engine.rs` assert
//! bounds on the same runs (`tests/common/engine.rs`).
//!
//! Run: `cargo run --release -p seqsmooth --example accuracy_engines`
//!
//! Error: the largest relative error per derivative (floored at 1e-3 of the oracle's largest
//! magnitude over the run), worst over the run, of the current estimate and the 1-step
//! prediction. Oracles: batch QR in a Legendre basis, or exact rational least squares.

#[path = "../tests/common/mod.rs"]
mod common;

use common::engine::{
    expanding_even_errors, expanding_irregular_errors, expanding_long_run_error,
    fading_even_errors, fading_irregular_error, high_degree_errors,
};
use seqsmooth::polynomial::MAX_DEGREE;
use seqsmooth::{DiscountMode, Engine};

fn main() {
    println!("Expanding memory, 200 even samples, against batch QR");
    println!();
    println!("| m | exact engine | gain engine |");
    println!("|---:|---:|---:|");
    for m in 0..=8 {
        let (exact, gain) = expanding_even_errors(m);
        println!("| {m} | {exact:.1e} | {gain:.1e} |");
    }
    println!();
    println!("Expanding memory, 10⁵ even samples, against batch QR at 10³, 10⁴, 10⁵");
    println!();
    println!("| m | exact engine | gain engine |");
    println!("|---:|---:|---:|");
    for m in [1, 2, 4, 8] {
        let exact = expanding_long_run_error(m, Engine::Exact);
        let gain = expanding_long_run_error(m, Engine::Gain);
        println!("| {m} | {exact:.1e} | {gain:.1e} |");
    }
    println!();
    println!("Exact engine on irregular times, against batch QR");
    println!();
    println!("| m | expanding, jittered ±40 % | expanding, Poisson | fading per time | fading per update |");
    println!("|---:|---:|---:|---:|---:|");
    for m in 0..=8 {
        let exp: Vec<String> = expanding_irregular_errors(m)
            .into_iter()
            .map(|(_, e)| format!("{e:.1e}"))
            .collect();
        let per_time = fading_irregular_error(m, DiscountMode::PerTime);
        let per_update = fading_irregular_error(m, DiscountMode::PerUpdate);
        println!(
            "| {m} | {} | {per_time:.1e} | {per_update:.1e} |",
            exp.join(" | ")
        );
    }
    println!();
    println!("Fading memory θ = 0.9, 1000 even samples, against exact discounted least squares");
    println!();
    println!("| m | gain engine (from sample 700) | exact engine |");
    println!("|---:|---:|---:|");
    for m in 0..=8 {
        let (gain, exact) = fading_even_errors(m);
        println!("| {m} | {gain:.1e} | {exact:.1e} |");
    }
    println!();
    println!("Exact engine at high degree, 2000 jittered samples, against batch QR");
    println!();
    println!("| m | expanding | fading θ = 0.99 |");
    println!("|---:|---:|---:|");
    for m in [10, 12, 14, 16, 20, MAX_DEGREE] {
        let (expanding, fading) = high_degree_errors(m);
        println!("| {m} | {expanding:.1e} | {fading:.1e} |");
    }
}
