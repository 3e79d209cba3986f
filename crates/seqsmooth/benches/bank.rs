//! Throughput of the single-stream expanding- and fading-memory filters and of the filter
//! banks, with the machine's copy bandwidth measured in the same run for reference.
//!
//! Run: `cargo bench -p seqsmooth --bench bank` (results in BENCHMARKS.md).
//!
//! - `single_stream/<memory>_<engine>[_many|_many_into]/<m>`: one filter (fading: θ = 0.9,
//!   τ = 1) already past its start-up; each iteration processes a batch of samples, by `update`
//!   per sample, by one `update_many` call, or by one `update_many_into` call (which also
//!   writes every sample's estimate); throughput in samples.
//! - `one_call/<memory>_<engine>_many_into/2`: a fresh degree-2 filter (fading: θ = 0.9,
//!   τ = 1) given 10⁶ unit-step samples in one `update_many_into` call (every estimate
//!   written, start-up included): the figure the Python package's `update_many` is compared
//!   with (`scripts/py_bench.sh`); `one_call/fading_gain_many_into_fresh_output/2`, the same
//!   into a new buffer per call; and `one_call/stream_fading_exact_10000x1000/2`: 10⁴ series
//!   of 10³ samples interleaved, through a `StreamBank` on the rayon pool (the Python
//!   `filter_frame`'s counterpart, `seqsmooth filter --id-col` without the CSV), and
//!   `…_fresh_columns`, the same into a new buffer per call written column by column, as
//!   `filter_frame` runs it.
//! - `bank/<serial|parallel>/<K>`: a degree-2 [`FadingBank`] (θ = 0.9) of `K` channels past
//!   its switch; each iteration is one time step of all channels; throughput in
//!   channel-updates.
//! - `copy/256MiB`: `copy_from_slice` of a 256 MiB buffer; throughput counts bytes read plus
//!   bytes written (STREAM "copy" convention), so it compares directly with the bank's
//!   traffic of `(m+1)·16 + 8` bytes per channel-update (state read and written, input read).

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use seqsmooth::polynomial::bank::FadingBank;
use seqsmooth::polynomial::stream::{Chunk, StreamBank};
use seqsmooth::{Engine, ExpandingMemory, FadingMemory, PolynomialFilter};
mod common;

use common::data;
use std::time::Duration;

fn single_stream(c: &mut Criterion) {
    const BATCH: usize = 1_000;
    let ys = data(1 << 12);
    let mask = ys.len() - 1;
    let mut group = c.benchmark_group("single_stream");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2))
        .throughput(Throughput::Elements(BATCH as u64));
    for (memory, engine) in [
        ("fading", Engine::Gain),
        ("fading", Engine::Exact),
        ("expanding", Engine::Gain),
        ("expanding", Engine::Exact),
    ] {
        let eng = if engine == Engine::Gain {
            "gain"
        } else {
            "exact"
        };
        for api in ["", "_many", "_many_into"] {
            let batch = !api.is_empty();
            for m in 0..=5usize {
                let id = BenchmarkId::new(format!("{memory}_{eng}{api}"), m);
                group.bench_function(id, |b| {
                    let mut f: Box<dyn PolynomialFilter> = if memory == "fading" {
                        Box::new(FadingMemory::new(m, 0.9, 1.0, engine).unwrap())
                    } else {
                        Box::new(ExpandingMemory::new(m, engine).unwrap())
                    };
                    // Past the start-up (the fading switch is at n < 100 for m ≤ 5, θ = 0.9).
                    let mut n = 0usize;
                    while n < 1_000 {
                        f.update(n as f64, ys[n & mask]).unwrap();
                        n += 1;
                    }
                    let mut times = vec![0.0; BATCH];
                    let mut est = vec![0.0; BATCH * (m + 1)];
                    b.iter(|| {
                        if batch {
                            // The times of this batch (filling them costs ≈ 0.3 ns/sample).
                            for (i, t) in times.iter_mut().enumerate() {
                                *t = (n + i) as f64;
                            }
                            let from = (n & mask).min(ys.len() - BATCH);
                            let y = &ys[from..from + BATCH];
                            if api == "_many" {
                                f.update_many(&times, y).unwrap();
                            } else {
                                f.update_many_into(&times, y, &mut est).unwrap();
                            }
                            n += BATCH;
                        } else {
                            for _ in 0..BATCH {
                                f.update(n as f64, ys[n & mask]).unwrap();
                                n += 1;
                            }
                        }
                        black_box(f.samples())
                    });
                });
            }
        }
    }
    group.finish();
}

fn one_call(c: &mut Criterion) {
    const LEN: usize = 1_000_000;
    const M: usize = 2;
    let ys = data(LEN);
    let times: Vec<f64> = (0..LEN).map(|n| n as f64).collect();
    let mut est = vec![0.0; LEN * (M + 1)];
    let mut group = c.benchmark_group("one_call");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(3))
        .throughput(Throughput::Elements(LEN as u64));
    for (memory, engine, eng) in [
        ("fading", Engine::Gain, "gain"),
        ("fading", Engine::Exact, "exact"),
        ("expanding", Engine::Gain, "gain"),
    ] {
        let id = BenchmarkId::new(format!("{memory}_{eng}_many_into"), M);
        group.bench_function(id, |b| {
            b.iter(|| {
                let mut f: Box<dyn PolynomialFilter> = if memory == "fading" {
                    Box::new(FadingMemory::new(M, 0.9, 1.0, engine).unwrap())
                } else {
                    Box::new(ExpandingMemory::new(M, engine).unwrap())
                };
                f.update_many_into(&times, &ys, &mut est).unwrap();
                black_box(est[est.len() - 1])
            });
        });
    }
    // The same with a fresh estimates buffer per call, as a caller that keeps every call's
    // estimates (and the Python `update_many`, which returns them) pays: the first touch of
    // 24 MB of new memory.
    group.bench_function(
        BenchmarkId::new("fading_gain_many_into_fresh_output", M),
        |b| {
            b.iter(|| {
                let mut f = FadingMemory::new(M, 0.9, 1.0, Engine::Gain).unwrap();
                let mut out = vec![0.0; LEN * (M + 1)];
                f.update_many_into(&times, &ys, &mut out).unwrap();
                black_box(out[out.len() - 1])
            });
        },
    );
    // Many series: 10⁴ series of 10³ samples, interleaved round-robin (row i·10⁴ + k is
    // sample i of series k at time i + k·10⁻³), through a growing `StreamBank` of degree-2
    // exact fading-memory filters on the rayon pool, every estimate written: what `seqsmooth
    // filter --id-col` runs without the CSV, and what the Python `filter_frame` is compared
    // with.
    const SERIES: usize = 10_000;
    const EACH: usize = 1_000;
    let rows = SERIES * EACH;
    let channels: Vec<usize> = (0..rows).map(|r| r % SERIES).collect();
    let times: Vec<f64> = (0..rows)
        .map(|r| (r / SERIES) as f64 + (r % SERIES) as f64 * 1e-3)
        .collect();
    let values = data(rows);
    let mut est = vec![0.0; rows * (M + 1)];
    group.throughput(Throughput::Elements(rows as u64));
    group.bench_function(BenchmarkId::new("stream_fading_exact_10000x1000", M), |b| {
        b.iter(|| {
            let prototype = FadingMemory::new(M, 0.9, 1.0, Engine::Exact).unwrap();
            let mut bank = StreamBank::growing(prototype).unwrap();
            let chunk = Chunk {
                channels: &channels,
                times: &times,
                values: &values,
                estimates: &mut est,
                stride: M + 1,
            };
            bank.update_par(
                chunk,
                |f: &mut FadingMemory, t: &[f64], y: &[f64], o: &mut [f64]| {
                    f.update_many_into(t, y, o)
                },
            )
            .unwrap();
            black_box(est[est.len() - 1])
        });
    });
    // The same as the Python `filter_frame` runs it: a fresh 240 MB estimates buffer per call
    // (its first touch is about 59,000 page faults), written column by column.
    group.bench_function(
        BenchmarkId::new("stream_fading_exact_10000x1000_fresh_columns", M),
        |b| {
            b.iter(|| {
                let prototype = FadingMemory::new(M, 0.9, 1.0, Engine::Exact).unwrap();
                let mut bank = StreamBank::growing(prototype).unwrap();
                let mut out = vec![0.0; rows * (M + 1)];
                let chunk = Chunk {
                    channels: &channels,
                    times: &times,
                    values: &values,
                    estimates: &mut out,
                    stride: M + 1,
                };
                bank.update_par_columns(
                    chunk,
                    |f: &mut FadingMemory, t: &[f64], y: &[f64], o: &mut [f64]| {
                        f.update_many_into(t, y, o)
                    },
                )
                .unwrap();
                black_box(out[out.len() - 1])
            });
        },
    );
    group.finish();
}

fn bank(c: &mut Criterion) {
    let mut group = c.benchmark_group("bank");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2));
    for k in [10_000usize, 1_000_000] {
        group.throughput(Throughput::Elements(k as u64));
        let inputs: Vec<Vec<f64>> = (0..4).map(|s| data(k + s).split_off(s)).collect();
        for parallel in [false, true] {
            let mode = if parallel { "parallel" } else { "serial" };
            group.bench_function(BenchmarkId::new(mode, k), |b| {
                let mut bank = FadingBank::new(2, 0.9, 1.0, k).unwrap();
                let mut n = 0usize;
                while (n as u64) <= bank.switch_index() {
                    bank.update(&inputs[n % 4]).unwrap();
                    n += 1;
                }
                b.iter(|| {
                    let y = &inputs[n % 4];
                    if parallel {
                        bank.update_par(y).unwrap();
                    } else {
                        bank.update(y).unwrap();
                    }
                    n += 1;
                    black_box(bank.samples())
                });
            });
        }
    }
    group.finish();
}

fn copy(c: &mut Criterion) {
    const LEN: usize = (256 << 20) / 8;
    let src: Vec<f64> = (0..LEN).map(|i| i as f64).collect();
    let mut dst = vec![0.0f64; LEN];
    let mut group = c.benchmark_group("copy");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2))
        .throughput(Throughput::Bytes(2 * 8 * LEN as u64));
    group.bench_function("256MiB", |b| {
        b.iter(|| {
            dst.copy_from_slice(black_box(&src));
            black_box(dst[LEN / 2])
        })
    });
    group.finish();
}

criterion_group!(benches, single_stream, one_call, bank, copy);
criterion_main!(benches);
