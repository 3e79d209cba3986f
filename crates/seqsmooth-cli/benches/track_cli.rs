//! End-to-end throughput of the `seqsmooth track` command: the built binary on a generated
//! radar pass of 2·10^5 rows, standard output discarded, so the time covers parsing, the
//! tracking and formatting with round-trip precision (and process start-up, ~1 ms).
//!
//! Run: `cargo bench -p seqsmooth-cli --bench track_cli` (results in BENCHMARKS.md, section
//! "`seqsmooth track`"; peak memory by `scripts/track_memory.sh`).
//!
//! The input (`target/tmp/track_cli_2e5.csv`, written once, seed 2026): a target in straight
//! flight at (−40, 25, −1) m/s from (20, −15, 3) km, seen from the origin at steps
//! U(0.05, 0.15) s, range noise σ 10 m and angle noise σ 1 mrad, columns
//! `t,range,azimuth,elevation` (azimuth from +x). Methods: `kalman --q 1`, `fading --theta 0.9 --tau 1`,
//! `smooth --q 1` (the window method fits 60 rows per row, ~10^4 rows/s; not benched).
//!
//! Throughput is in rows (criterion's elements/s).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

/// Rows of the generated input.
const ROWS: usize = 200_000;

/// Writes the pass to `path` (once; kept between runs).
fn generate(path: &Path) -> std::io::Result<()> {
    if path.exists() {
        return Ok(());
    }
    let tmp = path.with_extension("partial");
    let mut out = BufWriter::new(File::create(&tmp)?);
    let mut rng = StdRng::seed_from_u64(2026);
    let (range_noise, angle_noise) = (
        Normal::new(0.0, 10.0).expect("sigma"),
        Normal::new(0.0, 1e-3).expect("sigma"),
    );
    writeln!(out, "t,range,azimuth,elevation")?;
    let mut t = 0.0f64;
    for _ in 0..ROWS {
        let (x, y, z) = (2e4 - 40.0 * t, -1.5e4 + 25.0 * t, 3e3 - t);
        let range = (x * x + y * y + z * z).sqrt() + range_noise.sample(&mut rng);
        let azimuth = y.atan2(x) + angle_noise.sample(&mut rng);
        let elevation = z.atan2(x.hypot(y)) + angle_noise.sample(&mut rng);
        writeln!(out, "{t},{range},{azimuth},{elevation}")?;
        t += rng.gen_range(0.05..0.15);
    }
    out.flush()?;
    drop(out);
    std::fs::rename(tmp, path)
}

/// Runs `seqsmooth track args… input` with the output discarded.
fn run(args: &[&str], input: &Path) {
    let status = Command::new(env!("CARGO_BIN_EXE_seqsmooth"))
        .arg("track")
        .args(args)
        .args(["--sigma-range", "10", "--sigma-angle", "1e-3"])
        .arg(input)
        .stdout(Stdio::null())
        .status()
        .expect("run seqsmooth");
    assert!(status.success(), "seqsmooth track {args:?} failed");
}

fn track_cli(c: &mut Criterion) {
    let input = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("track_cli_2e5.csv");
    generate(&input).expect("write the bench input");
    let configs: [(&str, &[&str]); 3] = [
        ("kalman", &["--method", "kalman", "--q", "1"]),
        (
            "fading",
            &["--method", "fading", "--theta", "0.9", "--tau", "1"],
        ),
        ("smooth", &["--method", "smooth", "--q", "1"]),
    ];
    let mut group = c.benchmark_group("track_cli");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(10))
        .throughput(Throughput::Elements(ROWS as u64));
    for (name, args) in configs {
        group.bench_function(name, |b| b.iter(|| run(args, &input)));
    }
    group.finish();
}

criterion_group!(benches, track_cli);
criterion_main!(benches);
