//! The Kalman filter's predict + update per measurement (issue 12 must-show 7), two models:
//!
//! - `kalman3/…`: 3 states (`PolynomialDynamics::new(2, 1)`, constant acceleration on one
//!   axis), the position observed (`LinearObservation::value_of(3)`, σ 0.5), driving noise
//!   `WhiteNoiseDerivative::new(2, 1, Q3)`, [`SAMPLES`] measurements at irregular steps
//!   `0.001·U(0.5, 1.5)` of a slow sine plus noise, from a vague prior;
//! - `ekf6/…`: the extended filter on 6 states (`PolynomialDynamics::new(1, 3)`, constant
//!   velocity on three axes) with `Radar` (range, azimuth, elevation) and white-noise
//!   acceleration, over [`TRACKS`] simulated passes of 59 updates each (`common/kalman.rs`, the
//!   tracks `scripts/peers.py` gives filterpy's `ExtendedKalmanFilter`);
//! - `linear4/…`: `LinearKalmanFilter::update_many_into` on the Python benchmark's model
//!   (`crates/seqsmooth-py/bench/linear_kalman.py`: constant velocity on two axes, 4 states,
//!   both positions observed with a full `R`, unit steps) over [`LINEAR_STEPS`] steps, every
//!   step's predicted and updated state and covariance and NIS written: `fixed` (constant
//!   matrices: the fixed-size path), `general` (each step handed its `F`: the generic path,
//!   the same numbers), and `floor`, a hand-written loop of the same filter on `nalgebra`'s
//!   fixed-size matrices (`(I − K H) P (I − K H)ᵀ + K R Kᵀ` formed, `V⁻¹` by inverse: not the
//!   library's arithmetic, its cost only).
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
use nalgebra::{Matrix2, Matrix4, Matrix4x2, SMatrix, Vector2, Vector4};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use seqsmooth::kalman::discrete::{LinearKalmanFilter, PassInto, StepMatrices};
use seqsmooth::kalman::smoother::{self, Smoother};
use seqsmooth::kalman::KalmanFilter;
use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
use seqsmooth::model::measurement::Measurement;
use seqsmooth::model::observation::{LinearObservation, Observation};
use std::time::Duration;

#[path = "common/radar.rs"]
#[allow(dead_code)]
mod radar;

#[path = "common/kalman.rs"]
mod kalman_tracks;

#[path = "common/floor.rs"]
mod floor;

/// Measurements of the 3-state filter.
const SAMPLES: usize = 100_000;
/// Radar tracks of the extended filter (59 updates each).
const TRACKS: usize = 64;

/// Steps of the `linear4` batch.
const LINEAR_STEPS: usize = 2_000;

/// The 3-state filter at its prior and its measurements ([`floor::polynomial_case`]).
fn polynomial_case() -> (
    KalmanFilter<PolynomialDynamics, LinearObservation>,
    Vec<Measurement>,
) {
    floor::polynomial_case(SAMPLES)
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

/// The library's filter over `run` by `update_stats`: its state, covariance and summed
/// log-likelihood, to check a floor against.
fn library_run<D: Dynamics + Clone, O: Observation + Clone>(
    filter: &KalmanFilter<D, O>,
    run: &[Measurement],
) -> (Vec<f64>, Vec<f64>, f64) {
    let mut f = filter.clone();
    let total = run
        .iter()
        .map(|m| f.update_stats(m).unwrap().map_or(0.0, |s| s.log_likelihood))
        .sum();
    (
        f.state().as_slice().to_vec(),
        f.covariance().as_slice().to_vec(),
        total,
    )
}

/// Panics unless `got` (a floor's state, covariance and log-likelihood) equals `want` (the
/// library's) within `tol` relative to each one's largest entry.
fn assert_agrees(
    what: &str,
    got: (&[f64], &[f64], f64),
    want: &(Vec<f64>, Vec<f64>, f64),
    tol: f64,
) {
    let close = |a: &[f64], b: &[f64]| {
        let scale = b.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol * scale)
    };
    assert!(
        close(got.0, &want.0) && close(got.1, &want.1) && close(&[got.2], &[want.2]),
        "{what}: the floor does not run the library's recursion"
    );
}

fn kalman3(c: &mut Criterion) {
    let (filter, rows) = polynomial_case();
    let ts: Vec<f64> = rows.iter().map(|m| m.time).collect();
    let ys: Vec<f64> = rows.iter().map(|m| m.values[0].unwrap()).collect();
    let x0 = [0.0; 3];
    let s0 = [[1e4, 0.0, 0.0], [0.0, 1e4, 0.0], [0.0, 0.0, 1e4]];
    let floor_run = |ts: &[f64], ys: &[f64]| {
        floor::kalman3(x0, s0, 0.0, floor::Q3, floor::SIGMA3.powi(2), ts, ys)
    };
    let (x, s, total) = floor_run(&ts, &ys);
    let s_flat: Vec<f64> = (0..9).map(|k| s[k % 3][k / 3]).collect();
    assert_agrees(
        "kalman3",
        (&x, &s_flat, total),
        &library_run(&filter, &rows),
        1e-9,
    );
    let mut group = c.benchmark_group("kalman3");
    group
        .sample_size(20)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4))
        .throughput(Throughput::Elements(rows.len() as u64));
    bench_both(&mut group, std::slice::from_ref(&filter), &[&rows]);
    group.bench_function("floor", |b| {
        b.iter(|| floor_run(black_box(&ts), black_box(&ys)).2)
    });
    group.finish();
}

/// A radar track as the floor takes it: prior, times, measured triples.
type FloorTrack = ([f64; 6], [[f64; 6]; 6], f64, Vec<f64>, Vec<[f64; 3]>);

fn floor_tracks(tracks: &[kalman_tracks::Track]) -> Vec<FloorTrack> {
    tracks
        .iter()
        .map(|t| {
            let x: [f64; 6] = std::array::from_fn(|i| t.state[i]);
            let s: [[f64; 6]; 6] =
                std::array::from_fn(|i| std::array::from_fn(|j| t.covariance[(i, j)]));
            let ts = t.measurements.iter().map(|m| m.time).collect();
            let zs = t
                .measurements
                .iter()
                .map(|m| std::array::from_fn(|c| m.values[c].unwrap()))
                .collect();
            (x, s, t.time, ts, zs)
        })
        .collect()
}

/// The radar floor over every track: its summed log-likelihood.
fn floor_ekf6(tracks: &[FloorTrack]) -> f64 {
    let r = [
        radar::SIGMA_RANGE.powi(2),
        radar::SIGMA_ANGLE.powi(2),
        radar::SIGMA_ANGLE.powi(2),
    ];
    tracks
        .iter()
        .map(|(x, s, t0, ts, zs)| floor::ekf6(*x, *s, *t0, kalman_tracks::Q, r, ts, zs).2)
        .sum()
}

fn ekf6(c: &mut Criterion) {
    let tracks = kalman_tracks::tracks(radar::SEED, TRACKS);
    let filters: Vec<_> = tracks.iter().map(|t| t.filter()).collect();
    let runs: Vec<&[Measurement]> = tracks.iter().map(|t| t.measurements.as_slice()).collect();
    let updates: usize = runs.iter().map(|r| r.len()).sum();
    let hand = floor_tracks(&tracks);
    let r = [
        radar::SIGMA_RANGE.powi(2),
        radar::SIGMA_ANGLE.powi(2),
        radar::SIGMA_ANGLE.powi(2),
    ];
    for (f, (t, h)) in filters.iter().zip(tracks.iter().zip(&hand)) {
        let (x, s, total) = floor::ekf6(h.0, h.1, h.2, kalman_tracks::Q, r, &h.3, &h.4);
        let s_flat: Vec<f64> = (0..36).map(|k| s[k % 6][k / 6]).collect();
        assert_agrees(
            "ekf6",
            (&x, &s_flat, total),
            &library_run(f, &t.measurements),
            1e-7,
        );
    }
    let mut group = c.benchmark_group("ekf6");
    group
        .sample_size(30)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4))
        .throughput(Throughput::Elements(updates as u64));
    bench_both(&mut group, &filters, &runs);
    group.bench_function("floor", |b| b.iter(|| floor_ekf6(black_box(&hand))));
    group.finish();
}

/// The Python benchmark's model: `F`, `H`, `Q` (`Q_discrete_white_noise(2, 1, 0.01)` per
/// axis), `R`, and its measurements (a line on each axis plus unit noise).
struct Linear4 {
    f: Matrix4<f64>,
    h: SMatrix<f64, 2, 4>,
    q: Matrix4<f64>,
    r: Matrix2<f64>,
    zs: Vec<f64>,
}

fn linear4_case() -> Linear4 {
    let f = Matrix4::new(
        1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0,
    );
    let axis = Matrix2::new(0.25, 0.5, 0.5, 1.0) * 0.01;
    let mut q = Matrix4::zeros();
    q.fixed_view_mut::<2, 2>(0, 0).copy_from(&axis);
    q.fixed_view_mut::<2, 2>(2, 2).copy_from(&axis);
    let h = SMatrix::<f64, 2, 4>::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0);
    let r = Matrix2::new(1.0, 0.2, 0.2, 0.5);
    let mut rng = StdRng::seed_from_u64(1);
    let zs = (0..LINEAR_STEPS)
        .flat_map(|k| {
            let t = k as f64;
            let (a, b): (f64, f64) = (rng.sample(StandardNormal), rng.sample(StandardNormal));
            [0.5 * t + a, 3.0 - 0.2 * t + b]
        })
        .collect();
    Linear4 { f, h, q, r, zs }
}

/// Every step's outputs, as the Python batch returns them.
struct Outputs {
    x: Vec<f64>,
    p: Vec<f64>,
    xp: Vec<f64>,
    pp: Vec<f64>,
    nis: Vec<f64>,
}

impl Outputs {
    fn new(steps: usize, n: usize) -> Self {
        let v = |len| vec![0.0; len];
        Self {
            x: v(steps * n),
            p: v(steps * n * n),
            xp: v(steps * n),
            pp: v(steps * n * n),
            nis: v(steps),
        }
    }

    fn pass(&mut self) -> PassInto<'_> {
        PassInto {
            states: &mut self.x,
            covariances: &mut self.p,
            predicted_states: &mut self.xp,
            predicted_covariances: &mut self.pp,
            nis: Some(&mut self.nis),
        }
    }
}

/// The hand-written fixed-size loop: predict, update in Joseph's form, every output written.
fn floor_loop(case: &Linear4, x0: Vector4<f64>, p0: Matrix4<f64>, out: &mut Outputs) -> f64 {
    let (f, h, q, r) = (&case.f, &case.h, &case.q, &case.r);
    let (mut x, mut p) = (x0, p0);
    let mut acc = 0.0;
    for (k, z) in case.zs.chunks_exact(2).enumerate() {
        let xp = f * x;
        let pp = f * p * f.transpose() + q;
        let pht: Matrix4x2<f64> = pp * h.transpose();
        let v = h * pht + r;
        let vi = v.try_inverse().expect("V positive definite");
        let gain = pht * vi;
        let nu = Vector2::new(z[0], z[1]) - h * xp;
        x = xp + gain * nu;
        let ikh = Matrix4::identity() - gain * h;
        p = ikh * pp * ikh.transpose() + gain * r * gain.transpose();
        let nis = nu.dot(&(vi * nu));
        out.xp[4 * k..4 * k + 4].copy_from_slice(xp.as_slice());
        out.pp[16 * k..16 * k + 16].copy_from_slice(pp.as_slice());
        out.x[4 * k..4 * k + 4].copy_from_slice(x.as_slice());
        out.p[16 * k..16 * k + 16].copy_from_slice(p.as_slice());
        out.nis[k] = nis;
        acc += nis;
    }
    acc
}

fn linear4(c: &mut Criterion) {
    let case = linear4_case();
    let dm = |m: &[f64], r: usize, c: usize| DMatrix::from_column_slice(r, c, m);
    let (f, h) = (dm(case.f.as_slice(), 4, 4), dm(case.h.as_slice(), 2, 4));
    let (q, r) = (dm(case.q.as_slice(), 4, 4), dm(case.r.as_slice(), 2, 2));
    let (x0, p0) = (Vector4::zeros(), Matrix4::identity() * 100.0);
    let filter = LinearKalmanFilter::new(
        DVector::from_column_slice(x0.as_slice()),
        dm(p0.as_slice(), 4, 4),
        f.clone(),
        h,
        q,
        r,
    )
    .unwrap();
    let mut out = Outputs::new(LINEAR_STEPS, 4);
    let mut group = c.benchmark_group("linear4");
    group
        .sample_size(30)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3))
        .throughput(Throughput::Elements(LINEAR_STEPS as u64));
    group.bench_function("fixed", |b| {
        b.iter_batched(
            || filter.clone(),
            |mut kf| {
                kf.update_many_into(black_box(&case.zs), |_| StepMatrices::default(), out.pass())
                    .unwrap();
                kf
            },
            BatchSize::SmallInput,
        )
    });
    let each_f = StepMatrices {
        f: Some(&f),
        ..StepMatrices::default()
    };
    group.bench_function("general", |b| {
        b.iter_batched(
            || filter.clone(),
            |mut kf| {
                kf.update_many_into(black_box(&case.zs), |_| each_f, out.pass())
                    .unwrap();
                kf
            },
            BatchSize::SmallInput,
        )
    });
    group.bench_function("floor", |b| {
        b.iter(|| floor_loop(black_box(&case), x0, p0, &mut out))
    });
    group.finish();
}

/// Samples of the 3-state smoother's run.
const SMOOTH_SAMPLES: usize = 10_000;

/// The Rauch–Tung–Striebel smoother against its own filter, per measurement: `filter` (the
/// forward filter alone, `update_stats`); the measurement-at-a-time [`Smoother`]'s `forward`
/// pass ([`Smoother::push`], which also makes each step's backward map) and `backward` pass
/// ([`Smoother::finish`], the forward pass made outside the timing); `smooth_flat` (the
/// whole-interval smoother on flat buffers: the filter keeping its predictions, then every
/// backward map made and applied) and `smooth` (the same, each estimate in its own
/// `Smoothed`).
fn bench_smoother<D: Dynamics + Clone, O: Observation + Clone>(
    c: &mut Criterion,
    name: &str,
    filters: &[KalmanFilter<D, O>],
    runs: &[&[Measurement]],
) {
    let updates: usize = runs.iter().map(|r| r.len()).sum();
    let mut group = c.benchmark_group(name);
    group
        .sample_size(20)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3))
        .throughput(Throughput::Elements(updates as u64));
    bench_updates(&mut group, "filter", filters, runs, |f, m| {
        f.update_stats(m).unwrap().map_or(0.0, |i| i.nis)
    });
    let pushed = || -> Vec<Smoother<D, O>> {
        filters
            .iter()
            .zip(runs)
            .map(|(f, run)| {
                let mut s = Smoother::new(f.clone());
                for m in *run {
                    s.push(m).unwrap();
                }
                s
            })
            .collect()
    };
    group.bench_function("forward", |b| b.iter(|| pushed().len()));
    group.bench_function("backward", |b| {
        b.iter_batched(
            pushed,
            |ss| {
                ss.into_iter()
                    .map(|s| s.finish().unwrap().len())
                    .sum::<usize>()
            },
            BatchSize::LargeInput,
        )
    });
    group.bench_function("smooth_flat", |b| {
        b.iter(|| {
            filters
                .iter()
                .zip(runs)
                .map(|(f, run)| smoother::smooth_flat(f.clone(), run).unwrap().times.len())
                .sum::<usize>()
        })
    });
    group.bench_function("smooth", |b| {
        b.iter(|| {
            filters
                .iter()
                .zip(runs)
                .map(|(f, run)| smoother::smooth(f.clone(), run).unwrap().len())
                .sum::<usize>()
        })
    });
    group.finish();
}

fn rts3(c: &mut Criterion) {
    let (filter, rows) = polynomial_case();
    bench_smoother(c, "rts3", &[filter], &[&rows[..SMOOTH_SAMPLES]]);
}

fn rts6(c: &mut Criterion) {
    let tracks = kalman_tracks::tracks(radar::SEED, TRACKS);
    let filters: Vec<_> = tracks.iter().map(|t| t.filter()).collect();
    let runs: Vec<&[Measurement]> = tracks.iter().map(|t| t.measurements.as_slice()).collect();
    bench_smoother(c, "rts6", &filters, &runs);
}

criterion_group!(benches, kalman3, ekf6, linear4, rts3, rts6);
criterion_main!(benches);
