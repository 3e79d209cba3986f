//! Measures how far the gain engine (fixed gains, Reyneke's variable-step form) is from exact
//! least squares on irregular timestamps; prints the table quoted in the `polynomial` module docs.
//!
//! Run: `cargo run --release -p seqsmooth --example gain_engine_deviation`
//!
//! For each schedule and degree, 200 Monte Carlo runs of a degree-m polynomial truth plus white
//! noise (σ = 1) through both engines; reported: the ratio of the gain engine's mean squared
//! error (against the truth) to the exact engine's, for the value and the first derivative, and
//! the largest gain−exact difference in units of the exact estimate's own 1σ.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use seqsmooth::{Engine, ExpandingMemory, FadingMemory, PolynomialFilter};

fn schedule(kind: &str, n: usize, r: &mut StdRng) -> Vec<f64> {
    let mut t = 0.0;
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        out.push(t);
        let u: f64 = r.gen();
        t += match kind {
            "even" => 1.0,
            "jitter 20%" => 1.0 + 0.4 * (u - 0.5),
            "jitter 50%" => 1.0 + (u - 0.5),
            "random (exponential)" => (-(1.0 - u).ln()).max(0.01),
            _ => {
                // bursts and gaps: steps {0.5,1,1,1,2,3} × U(0.8, 1.2)
                let base = [0.5, 1.0, 1.0, 1.0, 2.0, 3.0][r.gen_range(0..6)];
                base * (0.8 + 0.4 * u)
            }
        };
    }
    out
}

fn main() {
    let schedules = [
        "even",
        "jitter 20%",
        "jitter 50%",
        "random (exponential)",
        "bursts and gaps",
    ];
    println!("| memory | schedule | m | MSE ratio x | MSE ratio x' | max abs(gain−exact)/σ x | max abs(gain−exact)/σ x' |");
    println!("|---|---|---|---|---|---|---|");
    for memory in ["expanding", "fading θ=0.9"] {
        for sched in schedules {
            for m in 1..=4 {
                let mut r = StdRng::seed_from_u64(7 + m as u64);
                let n = if memory == "expanding" { 100 } else { 400 };
                let from = if memory == "expanding" {
                    4 * (m + 1)
                } else {
                    200
                };
                let (mut se_g, mut se_e, mut dev) = ([0.0f64; 2], [0.0f64; 2], [0.0f64; 2]);
                for _ in 0..200 {
                    let times = schedule(sched, n, &mut r);
                    let coeffs: Vec<f64> = (0..=m).map(|_| r.gen::<f64>() - 0.5).collect();
                    let span = times[n - 1];
                    let truth = |t: f64| -> (f64, f64) {
                        let u = t / span;
                        let v = coeffs.iter().rev().fold(0.0, |a, c| a * u + c) * 10.0;
                        let d = coeffs
                            .iter()
                            .enumerate()
                            .skip(1)
                            .rev()
                            .fold(0.0, |a, (k, c)| a * u + k as f64 * c)
                            * 10.0
                            / span;
                        (v, d)
                    };
                    let make = |engine| -> Box<dyn PolynomialFilter> {
                        match memory {
                            "expanding" => Box::new(
                                ExpandingMemory::new(m, engine)
                                    .unwrap()
                                    .with_noise_sigma(1.0)
                                    .unwrap(),
                            ),
                            _ => Box::new(
                                FadingMemory::new(m, 0.9, 1.0, engine)
                                    .unwrap()
                                    .with_noise_sigma(1.0)
                                    .unwrap(),
                            ),
                        }
                    };
                    let (mut g, mut e) = (make(Engine::Gain), make(Engine::Exact));
                    for (k, &t) in times.iter().enumerate() {
                        let noise: f64 = StandardNormal.sample(&mut r);
                        let y = truth(t).0 + noise;
                        g.update(t, y).unwrap();
                        e.update(t, y).unwrap();
                        if k >= from {
                            let (a, b) = (g.estimate().unwrap(), e.estimate().unwrap());
                            let (v, d) = truth(t);
                            let sd = b.std_devs().unwrap();
                            for (i, tr) in [v, d].iter().enumerate() {
                                se_g[i] += (a.derivatives[i] - tr).powi(2);
                                se_e[i] += (b.derivatives[i] - tr).powi(2);
                                dev[i] =
                                    dev[i].max((a.derivatives[i] - b.derivatives[i]).abs() / sd[i]);
                            }
                        }
                    }
                }
                println!(
                    "| {memory} | {sched} | {m} | {:.3} | {:.3} | {:.2e} | {:.2e} |",
                    se_g[0] / se_e[0],
                    se_g[1] / se_e[1],
                    dev[0],
                    dev[1]
                );
            }
        }
    }
}
