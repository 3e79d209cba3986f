//! The seqsmooth side of the Kalman-bank peer comparison (`scripts/peers_bank.py`, run by
//! `scripts/peers.sh`): the library's [`KalmanBank`] on the constant-velocity model with
//! white-noise driving, position observed, over the series the script generated; times the
//! filter and the filter + RTS smoother and writes their estimates for the script's agreement
//! check against simdkalman and pykalman.
//!
//! By hand: `cargo run --release -p seqsmooth --example bank_peers -- DIR REPS`, with
//! `DIR/bank.txt` holding `series steps q r p0` and `DIR/bank.t.f64`, `DIR/bank.z.f64` the
//! times and values (`series × steps` raw little-endian doubles, series by series, NaN missing).
//! Writes `DIR/bank.filtered.f64`, `DIR/bank.smoothed.f64` (`series × steps × 2`: the state) and
//! prints `filter,SECONDS` and `filter+rts,SECONDS`, the best of `REPS` runs (I/O excluded).

use nalgebra::{DMatrix, DVector};
use seqsmooth::kalman::bank::{KalmanBank, Panel};
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::observation::LinearObservation;
use std::time::Instant;

fn read(path: &str) -> Vec<f64> {
    std::fs::read(path)
        .unwrap_or_else(|e| panic!("{path}: {e}"))
        .chunks_exact(8)
        .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
        .collect()
}

fn write(path: &str, v: &[f64]) {
    let bytes: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
    std::fs::write(path, bytes).unwrap_or_else(|e| panic!("{path}: {e}"));
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (dir, reps): (&str, usize) = (&args[1], args[2].parse().expect("REPS"));
    let spec = std::fs::read_to_string(format!("{dir}/bank.txt")).expect("bank.txt");
    let w: Vec<f64> = spec
        .split_whitespace()
        .map(|v| v.parse().expect("a number"))
        .collect();
    let (series, steps, q, r, p0) = (w[0] as usize, w[1] as usize, w[2], w[3], w[4]);
    let times = read(&format!("{dir}/bank.t.f64"));
    let values = read(&format!("{dir}/bank.z.f64"));
    let offsets: Vec<usize> = (0..=series).map(|s| s * steps).collect();
    let panel = Panel {
        offsets: &offsets,
        times: &times,
        values: &values,
    };
    let bank = KalmanBank::new(
        PolynomialDynamics::new(1, 1),
        LinearObservation::value_of(2),
        DMatrix::from_element(1, 1, r),
        DVector::zeros(2),
        DMatrix::identity(2, 2) * p0,
    )
    .expect("the model")
    .with_process_noise(WhiteNoiseDerivative::new(1, 1, q).expect("q"))
    .expect("the noise");
    let best = |run: &dyn Fn() -> Vec<f64>| {
        let mut best = f64::INFINITY;
        let mut out = Vec::new();
        for _ in 0..reps {
            let start = Instant::now();
            out = run();
            best = best.min(start.elapsed().as_secs_f64());
        }
        (best, out)
    };
    let (filter, filtered) = best(&|| bank.filter(&panel).expect("filter").state);
    let (rts, smoothed) = best(&|| bank.smooth(&panel).expect("smooth").state);
    write(&format!("{dir}/bank.filtered.f64"), &filtered);
    write(&format!("{dir}/bank.smoothed.f64"), &smoothed);
    println!("filter,{filter}");
    println!("filter+rts,{rts}");
}
