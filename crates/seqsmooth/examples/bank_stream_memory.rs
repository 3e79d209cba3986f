//! The streaming Kalman bank's memory (`kalman::bank::BankStream`): `SERIES` series
//! (default 10⁶) of the constant-velocity model, fed `STEPS` steps (a row of every series at
//! a time, 10 % of the values missing); prints the bytes the stream holds a series and the
//! steps run. Its peak resident memory, measured by `scripts/bank_memory.sh` at two numbers of
//! steps, shows that the memory follows the series, not the steps.
//!
//! `cargo run --release -p seqsmooth --example bank_stream_memory -- SERIES STEPS`

use nalgebra::{DMatrix, DVector};
use seqsmooth::kalman::bank::{BankRows, KalmanBank};
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::observation::LinearObservation;

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("a count"))
        .collect();
    let (series, steps) = (
        args.first().copied().unwrap_or(1_000_000),
        args.get(1).copied().unwrap_or(100),
    );
    let bank = KalmanBank::new(
        PolynomialDynamics::new(1, 1),
        LinearObservation::value_of(2),
        DMatrix::identity(1, 1),
        DVector::zeros(2),
        DMatrix::identity(2, 2) * 100.0,
    )
    .expect("the model")
    .with_process_noise(WhiteNoiseDerivative::new(1, 1, 0.01).expect("q"))
    .expect("the noise");
    let mut stream = bank.stream(series);
    let mut out = BankRows::default();
    let mut times = vec![0.0; series];
    let mut values = vec![0.0; series];
    let mut x = 12345_u64;
    for k in 0..steps {
        for (s, (t, v)) in times.iter_mut().zip(values.iter_mut()).enumerate() {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let u = (x >> 11) as f64 / (1u64 << 53) as f64;
            *t = k as f64;
            *v = if u < 0.1 {
                f64::NAN
            } else {
                0.3 * k as f64 + s as f64 * 1e-6 + u
            };
        }
        stream.update(&times, &values, &mut out).expect("a step");
    }
    println!(
        "series {series}, steps {steps}, bytes held a series {}",
        stream.bytes_per_series()
    );
}
