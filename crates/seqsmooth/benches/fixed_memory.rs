//! Cost per sample of the streaming fixed-memory filter (degree 2) against the window span L:
//! the sliding engine (O(m²) per sample, flat in L) and the direct engine (O(L·m)); and of the
//! whole-series `smooth` (degree 2, derivatives 0..=2, the same sliding engine) against its
//! window (`smooth/<window>`, throughput in samples of the series).
//!
//! Run: `cargo bench -p seqsmooth --bench fixed_memory` (results in BENCHMARKS.md).
//! Each iteration processes a batch of samples on a filter whose window is already full;
//! criterion's throughput is in samples (elements), so the reported time per element is the
//! cost per sample.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use seqsmooth::polynomial::fixed::{smooth, smooth_into, FixedEngine, FixedMemory};
use seqsmooth::PolynomialFilter;
mod common;

use common::data;
use std::time::Duration;

const SPANS: [usize; 4] = [10, 100, 1_000, 10_000];
const DEGREE: usize = 2;

/// A filter with a full window, and the index of the next sample.
fn primed(engine: FixedEngine, span: usize, ys: &[f64]) -> (FixedMemory, usize) {
    let mut f = FixedMemory::new(DEGREE, span + 1, engine).unwrap();
    for (n, y) in ys.iter().enumerate().take(span + 1) {
        f.update(n as f64, *y).unwrap();
    }
    (f, span + 1)
}

fn run(c: &mut Criterion, name: &str, engine: FixedEngine, estimate: bool, batch: usize) {
    let ys = data(1 << 16);
    let mask = ys.len() - 1;
    let mut group = c.benchmark_group(name);
    group
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3))
        .throughput(Throughput::Elements(batch as u64));
    for span in SPANS {
        group.bench_with_input(BenchmarkId::from_parameter(span), &span, |b, &span| {
            let (mut f, mut n) = primed(engine, span, &ys);
            b.iter(|| {
                let mut acc = 0.0;
                for _ in 0..batch {
                    f.update(n as f64, ys[n & mask]).unwrap();
                    n += 1;
                    if estimate {
                        acc += f.estimate().unwrap().derivatives[0];
                    }
                }
                black_box(acc)
            });
        });
    }
    group.finish();
}

fn sliding_update(c: &mut Criterion) {
    run(c, "sliding_update", FixedEngine::Sliding, false, 10_000);
}

fn sliding_update_estimate(c: &mut Criterion) {
    run(
        c,
        "sliding_update_estimate",
        FixedEngine::Sliding,
        true,
        10_000,
    );
}

fn direct_update(c: &mut Criterion) {
    run(c, "direct_update", FixedEngine::Direct, false, 200);
}

/// Whole-series smoothing of `SMOOTH_LEN` evenly spaced samples at windows 11 … 10001: rows
/// as vectors (`smooth`) and into one flat buffer (`smooth_into`).
fn smooth_series(c: &mut Criterion) {
    const SMOOTH_LEN: usize = 1 << 17;
    let ys = data(SMOOTH_LEN);
    let ts: Vec<f64> = (0..SMOOTH_LEN).map(|n| n as f64 * 0.01).collect();
    let mut out = vec![0.0; SMOOTH_LEN * (DEGREE + 1)];
    for flat in [false, true] {
        let mut group = c.benchmark_group(if flat { "smooth_into" } else { "smooth" });
        group
            .sample_size(10)
            .warm_up_time(Duration::from_millis(500))
            .measurement_time(Duration::from_secs(3))
            .throughput(Throughput::Elements(SMOOTH_LEN as u64));
        for window in [11usize, 101, 1_001, 10_001] {
            group.bench_with_input(
                BenchmarkId::from_parameter(window),
                &window,
                |b, &window| {
                    if flat {
                        b.iter(|| {
                            smooth_into(&ts, &ys, DEGREE, window, black_box(&mut out)).unwrap()
                        });
                    } else {
                        b.iter(|| black_box(smooth(&ts, &ys, DEGREE, window).unwrap()));
                    }
                },
            );
        }
        group.finish();
    }
}

criterion_group!(
    benches,
    sliding_update,
    sliding_update_estimate,
    direct_update,
    smooth_series
);
criterion_main!(benches);
