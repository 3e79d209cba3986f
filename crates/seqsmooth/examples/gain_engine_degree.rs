//! Measures how far the gain engine's recursion can be trusted as the degree grows: the
//! largest difference between the gain and the exact engine, in units of the exact estimate's
//! own 1σ, over every sample after the start-up, for each memory, degree and schedule. Prints
//! the table behind the gain engine's degree bound (ACCURACY.md).
//!
//! Run: `cargo run --release -p seqsmooth --example gain_engine_degree`
//!
//! It measures degrees up to the bound the engine accepts ([`GAIN_MAX_DEGREE`]). The degrees
//! above it, which gave the bound, are measured by raising the constant to `MAX_DEGREE` (24)
//! in `polynomial/options.rs` and running this example again (ACCURACY.md quotes both).
//!
//! Each cell is the median and the largest over 10 seeds.
//!
//! Data: a quadratic truth (values near 1e4, like a track in metres) plus white noise of
//! σ = 1, 2000 samples at a nominal step of 1 (expanding memory: 400 samples). Schedules:
//! even; "landing": even with one step in 60 of 0.5 to 1.5 times the nominal (as on a real
//! track's 8 irregular steps in 474); jitter 20%: every step uniform in ±20%.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use seqsmooth::polynomial::GAIN_MAX_DEGREE;
use seqsmooth::{Engine, ExpandingMemory, FadingMemory, PolynomialFilter};

fn schedule(kind: &str, n: usize, r: &mut StdRng) -> Vec<f64> {
    let mut t = 0.0;
    (0..n)
        .map(|_| {
            let now = t;
            let u: f64 = r.gen();
            t += match kind {
                "even" => 1.0,
                "landing" if r.gen_range(0..60) == 0 => 0.5 + u,
                "landing" => 1.0,
                _ => 1.0 + 0.4 * (u - 0.5),
            };
            now
        })
        .collect()
}

/// The filter; the exact one tracks its covariance for unit noise (the σ of the table).
fn build(memory: &str, m: usize, engine: Engine) -> Box<dyn PolynomialFilter> {
    let sigma = |e: Engine| (e == Engine::Exact).then_some(1.0);
    match memory {
        "expanding" => {
            let f = ExpandingMemory::new(m, engine).unwrap();
            match sigma(engine) {
                Some(s) => Box::new(f.with_noise_sigma(s).unwrap()),
                None => Box::new(f),
            }
        }
        _ => {
            let theta: f64 = memory.trim_start_matches("fading θ=").parse().unwrap();
            let f = FadingMemory::new(m, theta, 1.0, engine).unwrap();
            match sigma(engine) {
                Some(s) => Box::new(f.with_noise_sigma(s).unwrap()),
                None => Box::new(f),
            }
        }
    }
}

/// The largest |gain − exact|/σ of the position over the last quarter of the samples (infinite once the
/// gain engine is not finite).
fn deviation(memory: &str, m: usize, sched: &str, seed: u64) -> f64 {
    let mut r = StdRng::seed_from_u64(seed);
    let n = if memory == "expanding" { 400 } else { 2000 };
    let times = schedule(sched, n, &mut r);
    let values: Vec<f64> = times
        .iter()
        .map(|t| {
            1e4 + 30.0 * t - 0.01 * t * t + {
                let z: f64 = StandardNormal.sample(&mut r);
                z
            }
        })
        .collect();
    let mut gain = build(memory, m, Engine::Gain);
    let mut exact = build(memory, m, Engine::Exact);
    let mut worst = 0.0f64;
    for (i, (&t, &y)) in times.iter().zip(&values).enumerate() {
        gain.update(t, y).unwrap();
        exact.update(t, y).unwrap();
        if i < n * 3 / 4 {
            continue;
        }
        let g = gain.estimate_at(t).unwrap().derivatives[0];
        let e = exact.estimate_at(t).unwrap();
        let s = e
            .covariance
            .as_ref()
            .map(|c| c[(0, 0)].sqrt())
            .unwrap_or(1.0);
        let d = ((g - e.derivatives[0]) / s).abs();
        worst = if d.is_finite() {
            worst.max(d)
        } else {
            f64::INFINITY
        };
    }
    worst
}

fn main() {
    println!("| memory | schedule | m | median | largest |");
    println!("|---|---|---:|---:|---:|");
    for memory in ["expanding", "fading θ=0.5", "fading θ=0.9", "fading θ=0.99"] {
        for sched in ["even", "landing", "jitter 20%"] {
            for m in (0..=GAIN_MAX_DEGREE).step_by(2) {
                let mut d: Vec<f64> = (0..10)
                    .map(|seed| deviation(memory, m, sched, seed))
                    .collect();
                d.sort_by(f64::total_cmp);
                println!("| {memory} | {sched} | {m} | {:.1e} | {:.1e} |", d[5], d[9]);
            }
        }
    }
}
