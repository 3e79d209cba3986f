//! Polynomial samples (Villien & Ostertag 2009), BENCHMARKS.md "PAML":
//!
//! - `paml/online_push_all/<n>`: a segment of 1 000 samples (one layout, gains precomputed
//!   once) accumulated by `OnlineSmoother::push_all`; throughput in samples (the issue's
//!   target: ≥ 10⁸ samples/s at n = 5, one stream).
//! - `paml/online_push/<n>`: the same one `push` at a time.
//! - `paml/segment_batch/5`: `PolynomialSamples::from_segment` on the same 1 000 samples
//!   (the Jacobi matrix, the Gauss rule and the fit from nothing).
//! - `paml/layout/5`: `SmootherGains::new`, the offline part.
//! - `paml_fit/{raw,polynomial_samples}_{analytic,differenced}`: Example 1 (1 200 samples,
//!   eqs. 38-39, 1 m miss): the Levenberg–Marquardt maximum-likelihood fit on the raw samples
//!   and on their n = 5 and n = 11 polynomial samples, from the same start, with eq. 38's
//!   analytic gradient and with central differences (the target: ≥ 50× faster on the
//!   polynomial samples).

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
#[path = "../tests/common/doppler.rs"]
mod doppler;

use doppler::{prior, Doppler, DopplerDifferenced, Scenario, SAMPLES};
use rand::rngs::StdRng;
use rand::SeedableRng;
use seqsmooth::estimate::curve::{fit_curve, CurveModel};
use seqsmooth::paml::{PolynomialSamples, SmootherGains};
use std::time::Duration;

const N: usize = 1_000;

fn layout() -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let t: Vec<f64> = (0..N).map(|k| k as f64 * 4e-6).collect();
    let sigma: Vec<f64> = (0..N).map(|k| 1.0 + (k % 7) as f64).collect();
    let y: Vec<f64> = t.iter().map(|t| 5.0 * (2000.0 * t).sin()).collect();
    (t, sigma, y)
}

fn paml(c: &mut Criterion) {
    let (t, sigma, y) = layout();
    let mut group = c.benchmark_group("paml");
    group
        .sample_size(20)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2))
        .throughput(Throughput::Elements(N as u64));
    for n in [3, 5, 8] {
        let gains = SmootherGains::new(&t, &sigma, n).unwrap();
        group.bench_function(BenchmarkId::new("online_push_all", n), |b| {
            b.iter(|| {
                let mut s = gains.smoother();
                s.push_all(black_box(&y)).unwrap();
                black_box(s.taken())
            })
        });
        group.bench_function(BenchmarkId::new("online_push", n), |b| {
            b.iter(|| {
                let mut s = gains.smoother();
                for &v in black_box(&y) {
                    s.push(v).unwrap();
                }
                black_box(s.taken())
            })
        });
    }
    group.bench_function(BenchmarkId::new("segment_batch", 5), |b| {
        b.iter(|| PolynomialSamples::from_segment(black_box(&t), &y, &sigma, 5).unwrap())
    });
    group.bench_function(BenchmarkId::new("layout", 5), |b| {
        b.iter(|| SmootherGains::new(black_box(&t), &sigma, 5).unwrap())
    });
    group.finish();
}

fn paml_fit(c: &mut Criterion) {
    let sc = Scenario::new(1.0, SAMPLES);
    let mut rng = StdRng::seed_from_u64(1);
    let y = sc.measure(&mut rng);
    let start = prior(&sc.truth, &mut rng);
    let mut group = c.benchmark_group("paml_fit");
    group
        .sample_size(30)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2));
    let models: [(&str, &dyn CurveModel); 2] =
        [("analytic", &Doppler), ("differenced", &DopplerDifferenced)];
    for (name, model) in models {
        group.bench_function(format!("raw_{name}"), |b| {
            b.iter(|| fit_curve(model, black_box(&sc.times), &y, &sc.sigmas, &start).unwrap())
        });
        for n in [5, 11] {
            let ps = PolynomialSamples::from_segment(&sc.times, &y, &sc.sigmas, n).unwrap();
            group.bench_function(
                BenchmarkId::new(format!("polynomial_samples_{name}"), n),
                |b| b.iter(|| black_box(&ps).fit(model, &start).unwrap()),
            );
        }
    }
    group.finish();
}

criterion_group!(benches, paml, paml_fit);
criterion_main!(benches);
