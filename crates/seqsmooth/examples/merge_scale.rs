//! One series of `P × 10⁶` samples (default `P = 100`: 10⁸) cut into `P` partitions, each
//! generated where it is reduced (no partition holds another's samples; the series is never
//! in memory at once), reduced to its `polynomial::merge::Information` on the rayon pool and
//! merged in a tree, against the single passes over the same samples in order: the same
//! reduction in one `Information` fed partition after partition, and the exact
//! expanding-memory filter sample by sample. Prints wall time, process CPU time
//! (`CLOCK_PROCESS_CPUTIME_ID`: all threads, other processes on a shared machine excluded),
//! peak resident memory (`getrusage`), and the relative differences in the two measures of
//! ACCURACY.md (derivatives scaled by `h^k` at the end of the span; the curve over the span).
//!
//! Run: `cargo run --release -p seqsmooth --example merge_scale -- [P] [DEGREE...]`
//! (default `100 2 8`; `RAYON_NUM_THREADS` sets the pool).

use rayon::prelude::*;
use seqsmooth::polynomial::merge::Information;
use seqsmooth::{Engine, ExpandingMemory, PolynomialFilter};
use std::time::Instant;

const PART: usize = 1_000_000;

/// xorshift64*, seeded per partition.
struct Rng(u64);

impl Rng {
    fn uniform(&mut self) -> f64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        (x.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
}

const T0: f64 = 1.7e9;

/// Partition `p` of `parts`: times `T0 + k + U(0, 0.9)` for its rows `k`, values a smooth
/// curve over the whole span plus uniform noise.
fn partition(p: usize, parts: usize) -> (Vec<f64>, Vec<f64>) {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15 ^ (p as u64 + 1).wrapping_mul(0xBF58_476D_1CE4_E5B9));
    let total = (parts * PART) as f64;
    let mut t = Vec::with_capacity(PART);
    let mut y = Vec::with_capacity(PART);
    for i in 0..PART {
        let k = (p * PART + i) as f64;
        t.push(T0 + k + 0.9 * rng.uniform());
        let u = k / total;
        y.push(5.0 + 3.0 * u - 2.0 * u * u + (6.0 * u).sin() + (rng.uniform() - 0.5) * 3.0);
    }
    (t, y)
}

fn cpu_seconds() -> f64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `t` is a valid timespec for clock_gettime to write.
    let ok = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut t) };
    assert_eq!(ok, 0, "clock_gettime");
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}

fn peak_mib() -> f64 {
    // SAFETY: a zeroed rusage is a valid buffer for getrusage to fill.
    let mut r: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: `r` is a valid rusage for getrusage to write.
    let ok = unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut r) };
    assert_eq!(ok, 0, "getrusage");
    r.ru_maxrss as f64 / 1024.0
}

/// `max_k |a_k − b_k| h^k / max_k |b_k| h^k`.
fn derivatives_relative(a: &[f64], b: &[f64], h: f64) -> f64 {
    let (mut num, mut den): (f64, f64) = (0.0, 0.0);
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        let s = h.powi(k as i32);
        num = num.max((x - y).abs() * s);
        den = den.max(y.abs() * s);
    }
    num / den
}

/// `max_t |a(t) − b(t)| / max_t |b(t)|` over 201 times of the span.
fn curve_relative(a: impl Fn(f64) -> f64, b: impl Fn(f64) -> f64, (s, e): (f64, f64)) -> f64 {
    let (mut num, mut den): (f64, f64) = (0.0, 0.0);
    for i in 0..=200 {
        let t = s + (e - s) * f64::from(i) / 200.0;
        num = num.max((a(t) - b(t)).abs());
        den = den.max(b(t).abs());
    }
    num / den
}

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("numbers: P then degrees"))
        .collect();
    let parts = args.first().copied().unwrap_or(100);
    let degrees = if args.len() > 1 {
        args[1..].to_vec()
    } else {
        vec![2, 8]
    };
    // The span: the first and last times (the generator's rows 0 and N − 1).
    let start = partition(0, parts).0[0];
    let end = *partition(parts - 1, parts)
        .0
        .last()
        .expect("a partition has rows");
    let h = 0.5 * (end - start);
    println!(
        "{} samples in {parts} partitions of {PART}; rayon threads {}",
        parts * PART,
        rayon::current_num_threads()
    );
    for &m in &degrees {
        let empty = Information::new(m, start, end, None).expect("degree in range");
        // Partitions generated and reduced in parallel, merged in a tree (rayon's reduce).
        let (wall, cpu) = (Instant::now(), cpu_seconds());
        let merged = (0..parts)
            .into_par_iter()
            .map(|p| {
                let (t, y) = partition(p, parts);
                let mut info = empty.clone();
                info.reduce(&t, &y).expect("finite samples");
                info
            })
            .reduce(
                || empty.clone(),
                |mut a, b| {
                    a.merge(&b).expect("the same shape");
                    a
                },
            );
        let (wall, cpu) = (wall.elapsed().as_secs_f64(), cpu_seconds() - cpu);
        println!(
            "degree {m}: partitioned reduce + tree merge: wall {wall:.1} s, CPU {cpu:.1} s \
             ({:.0} ns/sample CPU, generation included)",
            cpu / (parts * PART) as f64 * 1e9
        );
        // The single passes, partition after partition in order.
        let (wall, cpu) = (Instant::now(), cpu_seconds());
        let mut one = empty.clone();
        let mut filter = ExpandingMemory::new(m, Engine::Exact).expect("degree in range");
        let mut filter_cpu = 0.0;
        for p in 0..parts {
            let (t, y) = partition(p, parts);
            one.reduce(&t, &y).expect("finite samples");
            let c = cpu_seconds();
            filter.update_many(&t, &y).expect("increasing times");
            filter_cpu += cpu_seconds() - c;
        }
        let (wall, cpu) = (wall.elapsed().as_secs_f64(), cpu_seconds() - cpu);
        println!(
            "degree {m}: single passes (one reduction, expanding memory): wall {wall:.1} s, CPU \
             {cpu:.1} s, of which the filter {filter_cpu:.1} s"
        );
        let got = merged.estimate(end).expect("determined").derivatives;
        let want_one = one.estimate(end).expect("determined").derivatives;
        let want_filter = filter.estimate().expect("determined").derivatives;
        let fit = merged.fit().expect("determined");
        let one_fit = one.fit().expect("determined");
        println!(
            "degree {m}: derivatives (h^k-scaled, at the end): merged vs one pass {:.1e}, vs \
             expanding memory {:.1e}; curve: merged vs one pass {:.1e}, vs expanding memory \
             {:.1e}",
            derivatives_relative(&got, &want_one, h),
            derivatives_relative(&got, &want_filter, h),
            curve_relative(
                |t| fit.value_and_vrf_at(t).0,
                |t| one_fit.value_and_vrf_at(t).0,
                (start, end)
            ),
            curve_relative(
                |t| fit.value_and_vrf_at(t).0,
                |t| filter.estimate_at(t).expect("determined").derivatives[0],
                (start, end)
            ),
        );
    }
    println!("peak resident memory {:.0} MiB", peak_mib());
}
