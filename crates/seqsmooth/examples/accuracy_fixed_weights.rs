//! Prints the accuracy of the fixed-memory analytic functions in `f64` (`weights`,
//! `covariance`): the numbers the `polynomial::fixed` module docs quote ("Accuracy of the
//! analytic functions"). The tests in `tests/fixed_weights.rs` and `tests/fixed_covariance.rs`
//! assert bounds on the same measurements (`tests/common/fixed.rs`).
//!
//! Run: `cargo run --release -p seqsmooth --example accuracy_fixed_weights`

#[path = "../tests/common/mod.rs"]
mod common;

use common::fixed::{
    centre_covariance_errors, weights_vs_exact, weights_vs_exact_long_windows, weights_vs_qr,
};

fn main() {
    let qr = weights_vs_qr();
    let (m, l, h, e) = qr
        .iter()
        .copied()
        .fold((0, 0, 0.0, 0.0), |a, b| if b.3 > a.3 { b } else { a });
    println!(
        "f64 weights vs Householder QR (m ≤ 10, L ≤ 10⁴, 5 leads): worst row-relative difference \
         {e:.2e} (m = {m}, L = {l}, h = {h})"
    );
    let exact = weights_vs_exact();
    let worst = exact.iter().map(|c| c.3).fold(0.0, f64::max);
    let book = exact.iter().filter_map(|c| c.4).fold(0.0, f64::max);
    println!("f64 weights vs exact rationals (m ≤ 10, L ≤ 300): worst {worst:.2e}");
    for (m, e) in weights_vs_exact_long_windows() {
        println!("f64 weights vs exact rationals, m = {m}, L = 10⁴, centre: {e:.2e}");
    }
    println!("the book's product Φ(h) 𝒮 G C B with the explicit sums, in f64, m = 10, L = 300: {book:.2e}");
    let (recursion, product) = centre_covariance_errors();
    println!(
        "f64 covariance at the centre, m = 8, L = 1000: recursion {recursion:.1e}, Φ(h)-product \
         form {product:.1e}"
    );
}
