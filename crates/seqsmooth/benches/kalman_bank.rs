//! Throughput of the Kalman bank (`kalman::bank`): constant velocity with white-noise
//! driving, the position observed, 10³ series of 10³ unit steps; each iteration is the
//! whole panel: `filter`, `smooth` (filter + RTS) and `stream` (the streaming form, a step of
//! every series at a time); throughput in updates (series × steps).
//!
//! Run: `cargo bench -p seqsmooth --bench kalman_bank` (results in BENCHMARKS.md; the
//! comparison with simdkalman and pykalman is `scripts/peers.sh`, `scripts/peers_bank.py`).

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use nalgebra::{DMatrix, DVector};
use seqsmooth::kalman::bank::{BankRows, KalmanBank, Panel};
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::observation::LinearObservation;
use std::time::Duration;

const SERIES: usize = 1_000;
const STEPS: usize = 1_000;

fn bank() -> KalmanBank<PolynomialDynamics> {
    KalmanBank::new(
        PolynomialDynamics::new(1, 1),
        LinearObservation::value_of(2),
        DMatrix::identity(1, 1),
        DVector::zeros(2),
        DMatrix::identity(2, 2) * 100.0,
    )
    .unwrap()
    .with_process_noise(WhiteNoiseDerivative::new(1, 1, 0.01).unwrap())
    .unwrap()
}

fn kalman_bank(c: &mut Criterion) {
    let offsets: Vec<usize> = (0..=SERIES).map(|s| s * STEPS).collect();
    let times: Vec<f64> = (0..SERIES * STEPS).map(|i| (i % STEPS) as f64).collect();
    let values: Vec<f64> = (0..SERIES * STEPS)
        .map(|i| 0.5 * (i % STEPS) as f64 + ((i * 7919) % 1000) as f64 / 500.0 - 1.0)
        .collect();
    let panel = Panel {
        offsets: &offsets,
        times: &times,
        values: &values,
    };
    let bank = bank();
    let mut group = c.benchmark_group("kalman_bank");
    group
        .throughput(Throughput::Elements((SERIES * STEPS) as u64))
        .sample_size(10)
        .measurement_time(Duration::from_secs(10));
    group.bench_function("filter/1000x1000", |b| {
        b.iter(|| black_box(bank.filter(&panel).unwrap()))
    });
    group.bench_function("smooth/1000x1000", |b| {
        b.iter(|| black_box(bank.smooth(&panel).unwrap()))
    });
    group.bench_function("stream/1000x1000", |b| {
        b.iter(|| {
            let mut stream = bank.clone().stream(SERIES);
            let mut out = BankRows::default();
            let mut t = vec![0.0; SERIES];
            let mut z = vec![0.0; SERIES];
            for k in 0..STEPS {
                for s in 0..SERIES {
                    t[s] = times[s * STEPS + k];
                    z[s] = values[s * STEPS + k];
                }
                stream.update(&t, &z, &mut out).unwrap();
            }
            black_box(out)
        })
    });
    group.finish();
}

criterion_group!(benches, kalman_bank);
criterion_main!(benches);
