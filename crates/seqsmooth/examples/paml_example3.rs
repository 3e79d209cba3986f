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

fn main() {
    let mut runs = 300;
    let mut seed = 1;
    let v: Vec<String> = std::env::args().skip(1).collect();
    for pair in v.chunks(2) {
        let value = pair.get(1).expect("every option takes a value");
        match pair[0].as_str() {
            "--runs" => runs = value.parse().expect("--runs N"),
            "--seed" => seed = value.parse().expect("--seed N"),
            other => panic!("unknown option {other}"),
        }
    }
    print!("{}", paml_ex3::report(runs, seed).text);
}
