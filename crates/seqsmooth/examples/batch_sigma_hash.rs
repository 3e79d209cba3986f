//! FNV-1a hashes of the exact engine's batch rows, plain (`update_many_into`) and with σ
//! (`update_many_sigma_into`), degrees 0-10, expanding and fading memory per time and per
//! update, on 2·10⁴ irregular times: a change to the kernels that should leave every bit as it
//! was is checked by running this before and after it.
//!
//! Run: `cargo run --release -p seqsmooth --example batch_sigma_hash`

use seqsmooth::{DiscountMode, Engine, ExpandingMemory, FadingMemory, PolynomialFilter};

fn fnv(rows: &[f64]) -> u64 {
    rows.iter().fold(0xcbf2_9ce4_8422_2325, |h, v| {
        v.to_bits()
            .to_le_bytes()
            .iter()
            .fold(h, |h, b| (h ^ u64::from(*b)).wrapping_mul(0x100_0000_01b3))
    })
}

fn main() {
    let n = 20_000;
    // Irregular steps from a fixed sequence (gaps 0.01 to about 2 mean steps).
    let mut t = Vec::with_capacity(n);
    let (mut now, mut state) = (0.0f64, 12345u64);
    for _ in 0..n {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        now += 0.01 + 0.2 * ((state >> 11) as f64 / (1u64 << 53) as f64);
        t.push(now);
    }
    let y: Vec<f64> = t.iter().map(|&t| (0.3 * t).sin() + 1e-3 * t).collect();
    for m in 0..=10 {
        for kind in ["expanding", "per time", "per update"] {
            let filter = || -> Box<dyn PolynomialFilter> {
                match kind {
                    "expanding" => Box::new(
                        ExpandingMemory::new(m, Engine::Exact)
                            .unwrap()
                            .with_noise_sigma(0.3)
                            .unwrap(),
                    ),
                    _ => Box::new(
                        FadingMemory::new(m, 0.93, 0.1, Engine::Exact)
                            .unwrap()
                            .with_discount_mode(if kind == "per time" {
                                DiscountMode::PerTime
                            } else {
                                DiscountMode::PerUpdate
                            })
                            .unwrap()
                            .with_noise_sigma(0.3)
                            .unwrap(),
                    ),
                }
            };
            let w = m + 1;
            let mut plain = vec![0.0; n * w];
            filter().update_many_into(&t, &y, &mut plain).unwrap();
            let mut sigma = vec![0.0; n * 2 * w];
            filter().update_many_sigma_into(&t, &y, &mut sigma).unwrap();
            println!(
                "degree {m:2} {kind:10} plain {:016x} sigma {:016x}",
                fnv(&plain),
                fnv(&sigma)
            );
        }
    }
}
