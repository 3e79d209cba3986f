//! Villien & Ostertag's Example 3 (§VI-C, eqs. 43-44, Table III): the RMS position error of
//! ML, PAML (order 5, 2 s segments) and the EKF on a walker inside four UWB emitters at the
//! corners of a 19 m square, at three noise levels (the paper prints none).
//!
//! cargo run --release -p seqsmooth --example paml_example3 -- [--runs 300] [--seed 1]
//!
//! It prints the block docs/paml.md holds (the test `paml_examples` regenerates it at a small
//! `--runs`).

#[path = "../tests/common/paml_ex3.rs"]
mod paml_ex3;
#[path = "../tests/common/paml_report.rs"]
mod paml_report;

fn main() {
    let o = paml_report::options(300);
    print!("{}", paml_ex3::report(o.runs, o.seed).text);
}
