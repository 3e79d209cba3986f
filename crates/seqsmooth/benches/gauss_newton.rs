//! One 60-sample window of a simulated radar pass (6-state constant velocity,
//! `PolynomialDynamics::new(1, 3)`, `Radar::new([0.0; 3], 6)`, σ 10 m and 1 mrad, irregular
//! steps; `common/radar.rs`, the windows `scripts/peers.py` gives scipy), fitted by Gauss–Newton
//! at the last time (`Epoch::End`):
//!
//! - `radar60/bootstrap_and_fit`: the bootstrap nominal (`bootstrap::radar`, degree 2) and the
//!   fit from it, what a user runs on a new window;
//! - `radar60/bootstrap`: the nominal alone;
//! - `radar60/fit_from_nominal`: the fit from the (precomputed) bootstrap nominal, what
//!   `scipy.optimize.least_squares` is given in the peer comparison.
//!
//! Each iteration fits the same `WINDOWS` windows (different geometries) in turn; the
//! throughput is in fits, so criterion's time per element is the time of one fit. The
//! measurements are built once, outside the timing. Run:
//! `cargo bench -p seqsmooth --bench gauss_newton` (results in BENCHMARKS.md).

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use std::time::Duration;

#[path = "common/radar.rs"]
mod radar;

/// Windows per iteration.
const WINDOWS: usize = 16;

fn radar60(c: &mut Criterion) {
    let (dynamics, radar) = radar::models();
    let windows = radar::windows(radar::SEED, WINDOWS);
    let rows: Vec<_> = windows.iter().map(|w| w.measurements()).collect();
    let nominals: Vec<_> = windows.iter().map(|w| w.nominal(&radar).unwrap()).collect();
    // Every window converges, from its nominal, near its truth.
    for ((w, r), x0) in windows.iter().zip(&rows).zip(&nominals) {
        let fit = radar::fit(&dynamics, &radar, r, x0).unwrap();
        let dt = w.epoch();
        let miss = (0..3)
            .map(|a| (fit.state[a] - (w.truth[a] + w.truth[a + 3] * dt)).abs())
            .fold(0.0, f64::max);
        assert!(miss < 200.0, "window misses its truth by {miss} m");
    }
    let mut group = c.benchmark_group("radar60");
    group
        .sample_size(30)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4))
        .throughput(Throughput::Elements(WINDOWS as u64));
    group.bench_function("bootstrap_and_fit", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for (w, r) in windows.iter().zip(&rows) {
                let x0 = w.nominal(&radar).unwrap();
                acc += radar::fit(&dynamics, &radar, black_box(r), &x0)
                    .unwrap()
                    .state[0];
            }
            acc
        })
    });
    group.bench_function("bootstrap", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for w in &windows {
                acc += black_box(w).nominal(&radar).unwrap()[0];
            }
            acc
        })
    });
    group.bench_function("fit_from_nominal", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for (r, x0) in rows.iter().zip(&nominals) {
                acc += radar::fit(&dynamics, &radar, black_box(r), x0)
                    .unwrap()
                    .state[0];
            }
            acc
        })
    });
    group.finish();
}

criterion_group!(benches, radar60);
criterion_main!(benches);
