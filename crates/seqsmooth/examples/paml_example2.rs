//! Villien & Ostertag's Example 2 (§VI-B, eqs. 40-42, Fig. 5): a bullet's ballistic track seen
//! by three ranging radars; ML, PAML (order 7) and the Cramér–Rao bound by observation time,
//! with the radars' positions and the parameters' ranges chosen (the paper prints neither).
//!
//! cargo run --release -p seqsmooth --example paml_example2 -- [--runs 1000] [--seed 1]
//!
//! The paper ran 20,000 runs (`--runs 20000`). It prints the block docs/paml.md holds (the
//! test `paml_examples` regenerates it at a small `--runs`).

#[path = "../tests/common/paml_ex2.rs"]
mod paml_ex2;
#[path = "../tests/common/paml_report.rs"]
mod paml_report;

fn main() {
    let o = paml_report::options(1000);
    print!("{}", paml_ex2::report(o.runs, o.seed).text);
}
