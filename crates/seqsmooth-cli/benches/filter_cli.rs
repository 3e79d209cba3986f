//! End-to-end throughput of the `seqsmooth filter` command: the built binary on a generated
//! CSV file of 10^6 rows, standard output discarded, so the time covers parsing, filtering and
//! formatting with round-trip precision (and process start-up, ~1 ms).
//!
//! Run: `cargo bench -p seqsmooth-cli --bench filter_cli` (results in BENCHMARKS.md).
//!
//! - `filter_cli/<kind>_<engine>`: one series `t,y` (evenly spaced times, a noisy sine),
//!   degree 2; fading memory with θ = 0.9 (τ the median step).
//! - `filter_cli/id_col_100/<kind>_<engine>`: the same number of rows as 100 series `id,t,y`,
//!   interleaved in a shuffled round-robin order, with `--id-col id`.
//! - `filter_cli/parquet_to_{csv,parquet}/fading_exact`: the single series as a Parquet file
//!   (`Float64` columns), to CSV on standard output and to a Parquet file.
//!
//! Throughput is in rows (criterion's elements/s).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

/// Rows of each generated input.
const ROWS: usize = 1_000_000;

/// Writes `ROWS` rows to `path` (once; kept between runs): one series, or `series` series
/// with an id column.
fn generate(path: &Path, series: Option<usize>) -> std::io::Result<()> {
    if path.exists() {
        return Ok(());
    }
    let tmp = path.with_extension("partial");
    let mut out = BufWriter::new(File::create(&tmp)?);
    let mut rng = StdRng::seed_from_u64(0x9E37_79B9_7F4A_7C15);
    match series {
        None => {
            writeln!(out, "t,y")?;
            for k in 0..ROWS {
                let t = k as f64 * 0.01;
                writeln!(out, "{t},{}", t.sin() + 0.1 * (rng.gen::<f64>() - 0.5))?;
            }
        }
        Some(n) => {
            writeln!(out, "id,t,y")?;
            let mut order: Vec<usize> = (0..n).collect();
            for round in 0..ROWS / n {
                // A fresh order every round: the series do not alternate regularly.
                for i in (1..n).rev() {
                    order.swap(i, rng.gen_range(0..=i));
                }
                for &s in &order {
                    let t = round as f64 * 0.01 + s as f64 * 1e-4;
                    let y = (t + s as f64).sin() + 0.1 * (rng.gen::<f64>() - 0.5);
                    writeln!(out, "s{s},{t},{y}")?;
                }
            }
        }
    }
    out.flush()?;
    drop(out);
    std::fs::rename(tmp, path)
}

/// Writes the CSV `csv` as the Parquet file `path` (once; kept between runs), through the
/// command itself (its output holds `t` and `y` as `Float64`).
fn to_parquet(csv: &Path, path: &Path) {
    if path.exists() {
        return;
    }
    let args = [
        "--kind",
        "expanding",
        "--degree",
        "0",
        "--no-progress",
        "-o",
    ];
    let status = Command::new(env!("CARGO_BIN_EXE_seqsmooth"))
        .arg("filter")
        .args(args)
        .arg(path)
        .arg(csv)
        .status()
        .expect("run seqsmooth");
    assert!(status.success(), "seqsmooth filter {args:?} failed");
}

/// Runs `seqsmooth filter args… input` with the output discarded.
fn run(args: &[&str], input: &Path) {
    let status = Command::new(env!("CARGO_BIN_EXE_seqsmooth"))
        .arg("filter")
        .args(args)
        .arg(input)
        .stdout(Stdio::null())
        .status()
        .expect("run seqsmooth");
    assert!(status.success(), "seqsmooth filter {args:?} failed");
}

fn filter_cli(c: &mut Criterion) {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let single = dir.join("filter_cli_1e6.csv");
    let multi = dir.join("filter_cli_1e6_100_series.csv");
    generate(&single, None).expect("write the bench input");
    generate(&multi, Some(100)).expect("write the bench input");
    let parquet = dir.join("filter_cli_1e6.parquet");
    to_parquet(&single, &parquet);
    let parquet_out = dir.join("filter_cli_out.parquet");

    let configs: [(&str, &[&str]); 4] = [
        (
            "fading_gain",
            &["--kind", "fading", "--theta", "0.9", "--engine", "gain"],
        ),
        (
            "fading_exact",
            &["--kind", "fading", "--theta", "0.9", "--engine", "exact"],
        ),
        (
            "expanding_gain",
            &["--kind", "expanding", "--engine", "gain"],
        ),
        (
            "expanding_exact",
            &["--kind", "expanding", "--engine", "exact"],
        ),
    ];
    let mut group = c.benchmark_group("filter_cli");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(8))
        .throughput(Throughput::Elements(ROWS as u64));
    for (name, args) in configs {
        let args = [args, &["--degree", "2"][..]].concat();
        group.bench_function(name, |b| b.iter(|| run(&args, &single)));
    }
    for (name, args) in &configs[..2] {
        let args = [args, &["--degree", "2", "--id-col", "id"][..]].concat();
        group.bench_function(format!("id_col_100/{name}"), |b| {
            b.iter(|| run(&args, &multi))
        });
    }
    let fading = [configs[1].1, &["--degree", "2"][..]].concat();
    group.bench_function("parquet_to_csv/fading_exact", |b| {
        b.iter(|| run(&fading, &parquet))
    });
    let out = parquet_out.to_str().expect("a UTF-8 path");
    let to_file = [&fading[..], &["-o", out][..]].concat();
    group.bench_function("parquet_to_parquet/fading_exact", |b| {
        b.iter(|| run(&to_file, &parquet))
    });
    group.finish();
}

criterion_group!(benches, filter_cli);
criterion_main!(benches);
