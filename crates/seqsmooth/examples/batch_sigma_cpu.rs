//! The exact engine's batch σ call against its plain batch call in the calling thread's CPU
//! time, which a busy machine disturbs less than the wall time of `benches/batch_sigma.rs`:
//! `update_many_sigma_into` (derivatives and their 1σ, `2(m + 1)` cells a sample) against
//! `update_many_into` (derivatives, `m + 1`), each on a fresh filter with a noise σ (fading
//! θ = 0.9 per τ = 1, and expanding) into a new zeroed buffer, best of 3, for each degree.
//!
//! Run: `cargo run --release -p seqsmooth --example batch_sigma_cpu -- [SAMPLES] [DEGREES]
//! [touched]` (defaults 10⁷ and `1,2,8`; e.g. `-- 10000000 0,1,2,4,8,9,12`); with `touched`
//! every buffer is written once before its call is timed, so that the system's mapping and
//! clearing of its pages is left out and the ratio is that of the arithmetic and the stores. The CPU time is read from
//! `/proc/thread-self/schedstat` (Linux); elsewhere the wall time is measured instead.

#[path = "common/cpu.rs"]
mod cpu;

use cpu::{cpu_ns, seconds};
use seqsmooth::{Engine, ExpandingMemory, FadingMemory, PolynomialFilter};

fn filter(fading: bool, m: usize) -> Box<dyn PolynomialFilter> {
    if fading {
        Box::new(
            FadingMemory::new(m, 0.9, 1.0, Engine::Exact)
                .unwrap()
                .with_noise_sigma(0.3)
                .unwrap(),
        )
    } else {
        Box::new(
            ExpandingMemory::new(m, Engine::Exact)
                .unwrap()
                .with_noise_sigma(0.3)
                .unwrap(),
        )
    }
}

fn main() {
    let mut args = std::env::args().skip(1);
    let n: usize = args
        .next()
        .map_or(10_000_000, |s| s.parse().expect("SAMPLES"));
    let degrees: Vec<usize> = args.next().map_or(vec![1, 2, 8], |s| {
        s.split(',').map(|d| d.parse().expect("DEGREES")).collect()
    });
    let t: Vec<f64> = (0..n).map(|k| k as f64).collect();
    let y: Vec<f64> = t
        .iter()
        .map(|&t| 10.0 * (t * 1e-3).sin() + 0.01 * ((t * 7.0) % 13.0))
        .collect();
    let touched = args.next().is_some_and(|s| s == "touched");
    let unit = if cpu_ns().is_some() { "CPU" } else { "wall" };
    let pages = if touched {
        "buffers written before timing"
    } else {
        "new zeroed buffers"
    };
    println!("{n} samples, best of 3, {unit} time, {pages}");
    let buffer = |len: usize| {
        let mut out = vec![0.0; len];
        if touched {
            out.fill(1.0);
        }
        out
    };
    for &m in &degrees {
        for fading in [true, false] {
            let w = m + 1;
            let (mut plain, mut sigma) = (f64::INFINITY, f64::INFINITY);
            for _ in 0..3 {
                let (mut f, mut out) = (filter(fading, m), buffer(n * w));
                plain = plain.min(seconds(|| f.update_many_into(&t, &y, &mut out).unwrap()));
                let (mut f, mut out) = (filter(fading, m), buffer(n * 2 * w));
                sigma = sigma.min(seconds(|| {
                    f.update_many_sigma_into(&t, &y, &mut out).unwrap()
                }));
            }
            println!(
                "{:9} degree {m:2}: plain {plain:.3} s, sigma {sigma:.3} s, ratio {:.2} \
                 ({:.1} / {:.1} ns a sample)",
                if fading { "fading" } else { "expanding" },
                sigma / plain,
                plain * 1e9 / n as f64,
                sigma * 1e9 / n as f64
            );
        }
    }
}
