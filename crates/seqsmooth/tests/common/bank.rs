//! Shared by the bank tests and the `accuracy_bank` example: deterministic multi-channel data
//! and the banks measured against the single-stream filters.

use seqsmooth::polynomial::bank::{ExpandingBank, FadingBank};
use seqsmooth::{Engine, ExpandingMemory, FadingMemory, PolynomialFilter};

/// Deterministic data for channel `c` at step `n`: a slow sine of channel-dependent phase and
/// size, a trend, and a cheap pseudo-random term of unit size.
pub fn sample(c: usize, n: usize) -> f64 {
    let mut s = (c as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (n as u64).wrapping_mul(0xD1B5_4A32_D192_ED03);
    s ^= s >> 29;
    s = s.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    s ^= s >> 32;
    let noise = (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
    let t = n as f64;
    (1.0 + c as f64 % 5.0) * (0.01 * t + c as f64).sin() + 0.001 * t + noise
}

/// Largest difference per derivative, relative to the largest `|x^(k)|` of the single stream
/// over the run, from step `from` on: a `FadingBank` of `k` channels against `k` `FadingMemory`
/// gain engines fed [`sample`] at `t = n·τ`.
pub fn compare_fading(
    m: usize,
    theta: f64,
    tau: f64,
    k: usize,
    steps: usize,
    from: usize,
) -> Vec<f64> {
    let mut bank = FadingBank::new(m, theta, tau, k).unwrap();
    let mut singles: Vec<_> = (0..k)
        .map(|_| FadingMemory::new(m, theta, tau, Engine::Gain).unwrap())
        .collect();
    let mut worst = vec![0.0f64; m + 1];
    let mut scale = vec![0.0f64; m + 1];
    let mut y = vec![0.0; k];
    for n in 0..steps {
        for (c, v) in y.iter_mut().enumerate() {
            *v = sample(c, n);
        }
        bank.update(&y).unwrap();
        for (c, f) in singles.iter_mut().enumerate() {
            f.update(n as f64 * tau, y[c]).unwrap();
            if n >= m {
                let want = f.estimate().unwrap().derivatives;
                let got = bank.estimate(c).unwrap();
                for d in 0..=m {
                    scale[d] = scale[d].max(want[d].abs());
                    if n >= from {
                        worst[d] = worst[d].max((got[d] - want[d]).abs());
                    }
                }
            } else {
                assert!(bank.estimate(c).is_none());
            }
        }
    }
    worst.iter().zip(&scale).map(|(w, s)| w / s).collect()
}

/// An `ExpandingBank` of 7 channels against `ExpandingMemory` gain engines over 300 steps of
/// [`sample`]: the largest difference over derivatives and steps, relative to `max(|x|, 1)`.
pub fn compare_expanding(m: usize) -> f64 {
    let k = 7;
    let mut bank = ExpandingBank::new(m, 1.0, k).unwrap();
    let mut singles: Vec<_> = (0..k)
        .map(|_| ExpandingMemory::new(m, Engine::Gain).unwrap())
        .collect();
    let mut y = vec![0.0; k];
    let mut worst = 0.0f64;
    for n in 0..300 {
        for (c, v) in y.iter_mut().enumerate() {
            *v = sample(c, n);
        }
        bank.update(&y).unwrap();
        for (c, f) in singles.iter_mut().enumerate() {
            f.update(n as f64, y[c]).unwrap();
            if n >= m {
                let want = f.estimate().unwrap().derivatives;
                let got = bank.estimate(c).unwrap();
                for d in 0..=m {
                    worst = worst.max((got[d] - want[d]).abs() / want[0].abs().max(1.0));
                }
            }
        }
    }
    worst
}
