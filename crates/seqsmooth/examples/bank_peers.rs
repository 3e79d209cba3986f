//! The seqsmooth side of the Kalman-bank peer comparison (`scripts/peers_bank.py`, run by
//! `scripts/peers.sh`): the library's [`KalmanBank`] on the constant-velocity model with
//! white-noise driving, position observed, over the series the script generated; times the
//! filter and the filter + RTS smoother and writes their estimates for the script's agreement
//! check against simdkalman and pykalman.
//!
//! By hand: `cargo run --release -p seqsmooth --example bank_peers -- DIR REPS`, with
//! `DIR/bank.txt` holding `series steps q r p0` and `DIR/bank.t.f64`, `DIR/bank.z.f64` the
//! times and values (`series × steps` raw little-endian doubles, series by series, NaN missing).
//! Writes `DIR/bank.filtered.f64`, `DIR/bank.smoothed.f64` (`series × steps × 2`: the state) and
//! prints `filter,SECONDS` and `filter+rts,SECONDS`, the best of `REPS` runs (I/O excluded),
//! each run into new output buffers, and `filter-reused,SECONDS`, `filter+rts-reused,SECONDS`
//! into the same buffers every run ([`KalmanBank::filter_into`]: no page faults); then
//! `cpu:NAME,SECONDS`, the process' CPU time (all threads, user + system) of the best run of
//! each. The previous run's output is freed before each run's clock starts. With `-v` after
//! `REPS`, every run's wall time, CPU time and minor page faults go to stderr.

use nalgebra::{DMatrix, DVector};
use seqsmooth::kalman::bank::{BankRows, KalmanBank, Panel};
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::observation::LinearObservation;
use std::time::Instant;

fn read(path: &str) -> Vec<f64> {
    std::fs::read(path)
        .unwrap_or_else(|e| panic!("{path}: {e}"))
        .chunks_exact(8)
        .map(|b| f64::from_le_bytes(b.try_into().expect("8 bytes")))
        .collect()
}

fn write(path: &str, v: &[f64]) {
    let bytes: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
    std::fs::write(path, bytes).unwrap_or_else(|e| panic!("{path}: {e}"));
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (dir, reps): (&str, usize) = (&args[1], args[2].parse().expect("REPS"));
    // `-v` after REPS: every run's wall and CPU time and page faults on stderr.
    let verbose = args.get(3).is_some_and(|a| a == "-v");
    let spec = std::fs::read_to_string(format!("{dir}/bank.txt")).expect("bank.txt");
    let w: Vec<f64> = spec
        .split_whitespace()
        .map(|v| v.parse().expect("a number"))
        .collect();
    let (series, steps, q, r, p0) = (w[0] as usize, w[1] as usize, w[2], w[3], w[4]);
    let times = read(&format!("{dir}/bank.t.f64"));
    let values = read(&format!("{dir}/bank.z.f64"));
    let offsets: Vec<usize> = (0..=series).map(|s| s * steps).collect();
    let panel = Panel {
        offsets: &offsets,
        times: &times,
        values: &values,
    };
    let bank = KalmanBank::new(
        PolynomialDynamics::new(1, 1),
        LinearObservation::value_of(2),
        DMatrix::from_element(1, 1, r),
        DVector::zeros(2),
        DMatrix::identity(2, 2) * p0,
    )
    .expect("the model")
    .with_process_noise(WhiteNoiseDerivative::new(1, 1, q).expect("q"))
    .expect("the noise");
    // The best wall time of `reps` runs, and the process' CPU time (user + system, every
    // thread) of that run: on a shared machine the CPU time is the steadier figure.
    let cpu = std::cell::Cell::new(Vec::new());
    let best = |run: &dyn Fn() -> BankRows| {
        let (mut best, mut best_cpu) = (f64::INFINITY, f64::INFINITY);
        let mut out = BankRows::default();
        for _ in 0..reps {
            // The previous run's output freed before the clock starts (the caller's, not the
            // bank's work).
            drop(std::mem::take(&mut out));
            let (start, start_cpu, start_faults) = (Instant::now(), cpu_seconds(), faults());
            out = run();
            let (wall, used) = (start.elapsed().as_secs_f64(), cpu_seconds() - start_cpu);
            if verbose {
                eprintln!(
                    "run: {wall:.4} s wall, {used:.4} s CPU, {} page faults",
                    faults() - start_faults
                );
            }
            if wall < best {
                (best, best_cpu) = (wall, used);
            }
        }
        let mut all = cpu.take();
        all.push(best_cpu);
        cpu.set(all);
        (best, out.state)
    };
    // New output buffers every run (their pages faulted in, as a caller's first run or
    // simdkalman's new arrays), then the same buffers reused (`filter_into`: no page faults).
    let (filter, filtered) = best(&|| bank.filter(&panel).expect("filter"));
    let (rts, smoothed) = best(&|| bank.smooth(&panel).expect("smooth"));
    let reused = std::cell::RefCell::new(BankRows::default());
    let (filter_reused, _) = best(&|| {
        let mut out = reused.borrow_mut();
        bank.filter_into(&panel, &mut out).expect("filter");
        BankRows::default()
    });
    let (rts_reused, _) = best(&|| {
        let mut out = reused.borrow_mut();
        bank.smooth_into(&panel, &mut out).expect("smooth");
        BankRows::default()
    });
    write(&format!("{dir}/bank.filtered.f64"), &filtered);
    write(&format!("{dir}/bank.smoothed.f64"), &smoothed);
    println!("filter,{filter}");
    println!("filter+rts,{rts}");
    println!("filter-reused,{filter_reused}");
    println!("filter+rts-reused,{rts_reused}");
    let cpu = cpu.take();
    for (name, seconds) in ["filter", "filter+rts", "filter-reused", "filter+rts-reused"]
        .iter()
        .zip(cpu)
    {
        println!("cpu:{name},{seconds}");
    }
}

/// The process' minor page faults so far.
fn faults() -> i64 {
    // SAFETY: getrusage writes the struct it is given.
    let usage = unsafe {
        let mut usage: libc::rusage = std::mem::zeroed();
        libc::getrusage(libc::RUSAGE_SELF, &mut usage);
        usage
    };
    usage.ru_minflt as i64
}

/// The process' CPU time so far (user + system, all threads), seconds.
fn cpu_seconds() -> f64 {
    // SAFETY: getrusage writes the struct it is given.
    let usage = unsafe {
        let mut usage: libc::rusage = std::mem::zeroed();
        libc::getrusage(libc::RUSAGE_SELF, &mut usage);
        usage
    };
    let seconds = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    seconds(usage.ru_utime) + seconds(usage.ru_stime)
}
