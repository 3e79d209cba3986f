//! The automatic filter's cost per sample against the fading-memory filter's, on a long
//! manoeuvring series (issue must-show: auto within 3× of fading per sample on long runs).
//!
//! [`SAMPLES`] samples at steps 1 s ± 40% of a target whose acceleration steps every 40-160 s
//! to a value in ±3 m/s², σ = 10 m, 2% outliers of 5-10σ (the scenario of
//! `tests/automatic_manoeuvres.rs`). Degree 2, θ = 0.95 per τ = 1 s, exact engine (the
//! command's defaults), every filter a fresh copy each iteration (made outside the timing):
//!
//! - `fading/update_many`: the fading filter's batch update, no estimates (`seqsmooth filter
//!   --kind fading` without `--sigma`);
//! - `fading/update_estimate_sigma`: one `update` and the estimate with its covariance per
//!   sample (`--kind fading --sigma`);
//! - `auto/update`: the automatic filter's `update` (estimate, σ, flags and the review's
//!   decisions) per sample, `σ` estimated, every setting at its default.
//!
//! The throughput is in samples, so criterion's time per element is the cost per sample. Run:
//! `cargo bench -p seqsmooth --bench automatic` (results in BENCHMARKS.md).

use criterion::{black_box, criterion_group, criterion_main, BatchSize, Criterion, Throughput};
#[path = "common/manoeuvring.rs"]
mod manoeuvring;

use seqsmooth::polynomial::automatic::AutomaticFilter;
use seqsmooth::{Engine, FadingMemory, PolynomialFilter};
use std::time::Duration;

/// Samples of the series.
const SAMPLES: usize = 100_000;

/// The manoeuvring series (see the file docs).
fn series() -> (Vec<f64>, Vec<f64>) {
    manoeuvring::series(SAMPLES, None)
}

fn per_sample(c: &mut Criterion) {
    let (ts, ys) = series();
    let fading = FadingMemory::new(2, 0.95, 1.0, Engine::Exact).unwrap();
    let fading_sigma = fading.clone().with_noise_sigma(10.0).unwrap();
    let auto = AutomaticFilter::new(2, 0.95, 1.0).unwrap();
    let mut group = c.benchmark_group("per_sample");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(10))
        .throughput(Throughput::Elements(SAMPLES as u64));
    group.bench_function("fading/update_many", |b| {
        b.iter_batched(
            || fading.clone(),
            |mut f| {
                f.update_many(black_box(&ts), black_box(&ys)).unwrap();
                f
            },
            BatchSize::LargeInput,
        )
    });
    group.bench_function("fading/update_estimate_sigma", |b| {
        b.iter_batched(
            || fading_sigma.clone(),
            |mut f| {
                let mut acc = 0.0;
                for (&t, &y) in ts.iter().zip(&ys) {
                    f.update(black_box(t), black_box(y)).unwrap();
                    if let Some(s) = f.estimate() {
                        acc += s.derivatives[0] + s.covariance.map_or(0.0, |c| c[(0, 0)]);
                    }
                }
                (f, acc)
            },
            BatchSize::LargeInput,
        )
    });
    group.bench_function("auto/update", |b| {
        b.iter_batched(
            || auto.clone(),
            |mut f| {
                let mut acc = 0.0;
                for (&t, &y) in ts.iter().zip(&ys) {
                    let o = f.update(black_box(t), black_box(y)).unwrap();
                    acc += o.estimate.map_or(0.0, |s| s.derivatives[0]);
                }
                (f, acc)
            },
            BatchSize::LargeInput,
        )
    });
    group.finish();
}

criterion_group!(benches, per_sample);
criterion_main!(benches);
