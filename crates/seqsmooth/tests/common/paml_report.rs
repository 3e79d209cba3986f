//! What the PAML example programs share: their options and number formatting.

#![allow(dead_code)]

/// `--runs N`, `--seed N`, `--plot PATH`.
pub struct Options {
    pub runs: usize,
    pub seed: u64,
    pub plot: Option<String>,
}

/// The options from the command line (`runs` unless `--runs` is given; seed 1).
pub fn options(runs: usize) -> Options {
    let mut o = Options {
        runs,
        seed: 1,
        plot: None,
    };
    let v: Vec<String> = std::env::args().skip(1).collect();
    for pair in v.chunks(2) {
        let value = pair.get(1).expect("every option takes a value");
        match pair[0].as_str() {
            "--runs" => o.runs = value.parse().expect("--runs N"),
            "--seed" => o.seed = value.parse().expect("--seed N"),
            "--plot" => o.plot = Some(value.clone()),
            other => panic!("unknown option {other}"),
        }
    }
    o
}

/// `v` to `digits` significant figures.
pub fn sig(v: f64, digits: i32) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let d = (digits - 1 - v.abs().log10().floor() as i32).max(0);
    format!("{:.*}", d as usize, v)
}
