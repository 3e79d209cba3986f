//! The batch σ path against the plain batch call of the exact engine (issue must-show: Python's
//! `update_many(…, return_sigma=True)` within 2× of the plain call; both front ends' σ rows come
//! from `PolynomialFilter::update_many_sigma_into`).
//!
//! [`SAMPLES`] unit-step samples of a slow sine plus a small deterministic ripple, the fading
//! (θ = 0.9 per τ = 1) and expanding filters on the exact engine with a noise σ (so that the
//! plain call keeps the same covariance factors), degrees 1, 2 and 8; each call on a fresh
//! filter into a new zeroed buffer (its pages are first touched inside the timing, as with the
//! new array Python returns):
//!
//! - `{kind}/m{m}/plain`: `update_many_into`, the derivatives only (`m + 1` cells a sample);
//! - `{kind}/m{m}/sigma`: `update_many_sigma_into`, the derivatives and their 1σ (`2(m + 1)`).
//!
//! The throughput is in samples. Run: `cargo bench -p seqsmooth --bench batch_sigma` (results
//! in BENCHMARKS.md, "The batch σ path").

use criterion::{black_box, criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use seqsmooth::{Engine, ExpandingMemory, FadingMemory, PolynomialFilter};
use std::time::Duration;

/// Samples per call.
const SAMPLES: usize = 1_000_000;

fn filter(kind: &str, m: usize) -> Box<dyn PolynomialFilter> {
    match kind {
        "fading" => Box::new(
            FadingMemory::new(m, 0.9, 1.0, Engine::Exact)
                .unwrap()
                .with_noise_sigma(0.3)
                .unwrap(),
        ),
        _ => Box::new(
            ExpandingMemory::new(m, Engine::Exact)
                .unwrap()
                .with_noise_sigma(0.3)
                .unwrap(),
        ),
    }
}

fn batch_sigma(c: &mut Criterion) {
    let t: Vec<f64> = (0..SAMPLES).map(|k| k as f64).collect();
    let y: Vec<f64> = t
        .iter()
        .map(|&t| 10.0 * (t * 1e-3).sin() + 0.01 * ((t * 7.0) % 13.0))
        .collect();
    let mut group = c.benchmark_group("batch_sigma");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4))
        .throughput(Throughput::Elements(SAMPLES as u64));
    for m in [1, 2, 8] {
        for kind in ["fading", "expanding"] {
            let w = m + 1;
            group.bench_function(format!("{kind}/m{m}/plain"), |b| {
                b.iter_batched(
                    || (filter(kind, m), vec![0.0; SAMPLES * w]),
                    |(mut f, mut out)| {
                        f.update_many_into(black_box(&t), black_box(&y), &mut out)
                            .unwrap();
                        (f, out)
                    },
                    BatchSize::LargeInput,
                )
            });
            group.bench_function(format!("{kind}/m{m}/sigma"), |b| {
                b.iter_batched(
                    || (filter(kind, m), vec![0.0; SAMPLES * 2 * w]),
                    |(mut f, mut out)| {
                        f.update_many_sigma_into(black_box(&t), black_box(&y), &mut out)
                            .unwrap();
                        (f, out)
                    },
                    BatchSize::LargeInput,
                )
            });
        }
    }
    group.finish();
}

criterion_group!(benches, batch_sigma);
criterion_main!(benches);
