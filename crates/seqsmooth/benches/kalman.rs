//! The Kalman filter's predict + update per measurement (issue 12 must-show 7), two models:
//!
//! - `kalman3/…`: 3 states (`PolynomialDynamics::new(2, 1)`, constant acceleration on one
//!   axis), the position observed (`LinearObservation::value_of(3)`, σ 0.5), driving noise
//!   `WhiteNoiseDerivative::new(2, 1, Q3)`, [`SAMPLES`] measurements at irregular steps
//!   `0.001·U(0.5, 1.5)` of a slow sine plus noise, from a vague prior;
//! - `ekf6/…`: the extended filter on 6 states (`PolynomialDynamics::new(1, 3)`, constant
//!   velocity on three axes) with `Radar` (range, azimuth, elevation) and white-noise
//!   acceleration, over [`TRACKS`] simulated passes of 59 updates each (`common/kalman.rs`, the
//!   tracks `scripts/peers.py` gives filterpy's `ExtendedKalmanFilter`).
//!
//! Each function runs every measurement through a fresh copy of the filter (the copy made
//! outside the timing); the throughput is in measurements, so criterion's time per element is
//! one predict + update. The measurements are built once, outside the timing. Run:
//! `cargo bench -p seqsmooth --bench kalman` (results in BENCHMARKS.md).

use criterion::measurement::WallTime;
use criterion::{
    black_box, criterion_group, criterion_main, BatchSize, BenchmarkGroup, Criterion, Throughput,
};
use nalgebra::{DMatrix, DVector};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::kalman::KalmanFilter;
use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
use seqsmooth::model::measurement::Measurement;
use seqsmooth::model::measurement::NoiseCovariance;
use seqsmooth::model::observation::{LinearObservation, Observation};
use std::time::Duration;

#[path = "common/radar.rs"]
#[allow(dead_code)]
mod radar;

#[path = "common/kalman.rs"]
mod kalman_tracks;

/// Measurements of the 3-state filter.
const SAMPLES: usize = 100_000;
/// The 3-state filter's driving-noise spectral density (jerk), value²/time⁵.
const Q3: f64 = 1.0;
/// σ of the 3-state filter's measurements.
const SIGMA: f64 = 0.5;
/// Radar tracks of the extended filter (59 updates each).
const TRACKS: usize = 64;

/// The 3-state filter at its prior and its measurements.
fn polynomial_case() -> (
    KalmanFilter<PolynomialDynamics, LinearObservation>,
    Vec<Measurement>,
) {
    let mut rng = StdRng::seed_from_u64(20_260_417);
    let mut t = 0.0;
    let rows = (0..SAMPLES)
        .map(|_| {
            t += 1e-3 * rng.gen_range(0.5..1.5);
            let e: f64 = rng.sample(StandardNormal);
            let y = 10.0 * (t * std::f64::consts::TAU / 25.0).sin() + 0.5 * t + SIGMA * e;
            Measurement {
                time: t,
                values: vec![Some(y)],
                noise: NoiseCovariance::Variances(vec![SIGMA * SIGMA]),
            }
        })
        .collect();
    let filter = KalmanFilter::new(
        PolynomialDynamics::new(2, 1),
        LinearObservation::value_of(3),
        DVector::zeros(3),
        DMatrix::from_diagonal(&DVector::from_vec(vec![1e4, 1e4, 1e4])),
        0.0,
    )
    .unwrap()
    .with_process_noise(WhiteNoiseDerivative::new(2, 1, Q3).unwrap())
    .unwrap();
    (filter, rows)
}

/// Benchmark `name`: every filter of `filters` (a fresh copy each iteration, made outside the
/// timing) through its run of measurements in `runs`, one `update(filter, measurement)` each
/// (its NIS summed so that nothing is optimised away).
fn bench_updates<D: Dynamics + Clone, O: Observation + Clone>(
    group: &mut BenchmarkGroup<'_, WallTime>,
    name: &str,
    filters: &[KalmanFilter<D, O>],
    runs: &[&[Measurement]],
    update: impl Fn(&mut KalmanFilter<D, O>, &Measurement) -> f64,
) {
    group.bench_function(name, |b| {
        b.iter_batched(
            || filters.to_vec(),
            |mut fs| {
                let mut acc = 0.0;
                for (f, run) in fs.iter_mut().zip(runs) {
                    for m in *run {
                        acc += update(f, black_box(m));
                    }
                }
                (fs, acc)
            },
            BatchSize::LargeInput,
        )
    });
}

/// `update_stats` and `update` of every filter over its run, as two benchmarks of `group`.
fn bench_both<D: Dynamics + Clone, O: Observation + Clone>(
    group: &mut BenchmarkGroup<'_, WallTime>,
    filters: &[KalmanFilter<D, O>],
    runs: &[&[Measurement]],
) {
    bench_updates(group, "update_stats", filters, runs, |f, m| {
        f.update_stats(m).unwrap().map_or(0.0, |i| i.nis)
    });
    bench_updates(group, "update", filters, runs, |f, m| {
        f.update(m).unwrap().map_or(0.0, |i| i.nis)
    });
}

fn kalman3(c: &mut Criterion) {
    let (filter, rows) = polynomial_case();
    let mut group = c.benchmark_group("kalman3");
    group
        .sample_size(20)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4))
        .throughput(Throughput::Elements(rows.len() as u64));
    bench_both(&mut group, &[filter], &[&rows]);
    group.finish();
}

fn ekf6(c: &mut Criterion) {
    let tracks = kalman_tracks::tracks(radar::SEED, TRACKS);
    let filters: Vec<_> = tracks.iter().map(|t| t.filter()).collect();
    let runs: Vec<&[Measurement]> = tracks.iter().map(|t| t.measurements.as_slice()).collect();
    let updates: usize = runs.iter().map(|r| r.len()).sum();
    let mut group = c.benchmark_group("ekf6");
    group
        .sample_size(30)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4))
        .throughput(Throughput::Elements(updates as u64));
    bench_both(&mut group, &filters, &runs);
    group.finish();
}

criterion_group!(benches, kalman3, ekf6);
criterion_main!(benches);
