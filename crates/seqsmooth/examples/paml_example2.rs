//! Villien & Ostertag's Example 2 (§VI-B, eqs. 40-42, Fig. 5): a bullet's ballistic track seen
//! by three ranging radars; ML, PAML (order 7) and the Cramér–Rao bound by observation time,
//! with the radars' positions and the parameters' ranges chosen (the paper prints neither).
//!
//! cargo run --release -p seqsmooth --example paml_example2 -- [--runs 1000] [--seed 1]
//!
//! The paper ran 20,000 runs (`--runs 20000`). It prints the block docs/paml.md holds (the
//! test `paml_examples` regenerates it at a small `--runs`).

#[path = "../tests/common/doppler.rs"]
mod doppler;
#[path = "../tests/common/paml_ex1.rs"]
mod paml_ex1;
#[path = "../tests/common/paml_ex2.rs"]
mod paml_ex2;

fn main() {
    let mut runs = 1000;
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
    print!("{}", paml_ex2::report(runs, seed).text);
}
