//! Villien & Ostertag's Example 1 (§VI-A, eqs. 38-39, Fig. 3) as the paper ran it: zero-crossing
//! samples to the crossing, random speed (1,000-1,800 m/s) and miss distance, PAML at order 5,
//! ML, the EKF and the Cramér–Rao bound by observation span, and PAML's σ by order.
//!
//! cargo run --release -p seqsmooth --example paml_example1 -- [--runs 300] [--seed 1]
//!     [--plot docs/images/paml-example1.svg]
//!
//! It prints the block docs/paml.md holds (the test `paml_examples` regenerates it).

#[path = "../tests/common/doppler.rs"]
mod doppler;
#[path = "../tests/common/paml_ex1.rs"]
mod paml_ex1;
#[path = "../tests/common/paml_plot.rs"]
mod paml_plot;
#[path = "../tests/common/paml_report.rs"]
mod paml_report;

fn main() {
    let o = paml_report::options(300);
    let r = paml_ex1::report(o.runs, o.seed);
    print!("{}", r.text);
    if let Some(path) = o.plot {
        let x: Vec<f64> = paml_ex1::ENDS.iter().map(|e| paml_ex1::START - e).collect();
        let panels = [0usize, 1].map(|i| {
            let series = ["CRLB", "ML", "PAML order 5", "EKF"]
                .iter()
                .enumerate()
                .map(|(m, name)| (name.to_string(), r.sigma.iter().map(|s| s[m][i]).collect()))
                .collect();
            paml_plot::Panel {
                title: format!("σ of {} ({} runs)", ["x0", "y0"][i], r.runs),
                y_label: format!("σ of {} (m)", ["x0", "y0"][i]),
                series,
            }
        });
        paml_plot::draw(&path, "distance flown from x0 = 10 m (m)", &x, &panels).expect("plot");
        println!("plot: {path}");
    }
}
