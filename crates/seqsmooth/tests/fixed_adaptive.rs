//! `FixedEngine::Adaptive`: the sliding engine while the steps are even, and from the first
//! uneven step the irregular (QR) engine, fed the newest `window` samples. Oracle: a direct
//! batch least-squares fit of each window by Householder QR ([`PolynomialFit`]), on data that
//! are evenly spaced and then jittered, degrees 0..=8, checked at every sample including the
//! transition; and the engines it hands over between, bit for bit.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use seqsmooth::error::Param;
use seqsmooth::estimate::PolynomialFit;
use seqsmooth::polynomial::fixed::{FixedEngine, FixedMemory};
use seqsmooth::{Error, PolynomialFilter};

/// `even` evenly spaced times (step 0.25 from 3.0), then steps jittered by ±30 %.
fn even_then_jittered(even: usize, len: usize, seed: u64) -> Vec<f64> {
    let mut rng = StdRng::seed_from_u64(seed);
    let mut t = Vec::with_capacity(len);
    for k in 0..len {
        t.push(if k < even {
            3.0 + 0.25 * k as f64
        } else {
            t[k - 1] + 0.25 * (1.0 + 0.3 * (2.0 * rng.gen::<f64>() - 1.0))
        });
    }
    t
}

/// A smooth signal with O(1) derivatives and noise.
fn signal(times: &[f64], seed: u64) -> Vec<f64> {
    let mut rng = StdRng::seed_from_u64(seed);
    times
        .iter()
        .map(|&t| 2.0 + (0.4 * t).sin() + 0.1 * t + 0.05 * (2.0 * rng.gen::<f64>() - 1.0))
        .collect()
}

/// `|a - b|` relative to `max(|b|, 1/τ^i)` per derivative `i` (`τ` = 0.25): the data are O(1).
fn rel(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .enumerate()
        .map(|(i, (x, y))| (x - y).abs() / y.abs().max(4f64.powi(i as i32)))
        .fold(0.0, f64::max)
}

#[test]
fn adaptive_equals_window_least_squares_across_the_switch() {
    // Every sample from the first full window on, at the newest sample and at a lead and a lag,
    // against the QR fit of the window; covariance with σ against σ² (AᵀA)⁻¹ mapped to
    // derivatives. Measured worst 4.1e-13 (ACCURACY.md); bound 1e-9.
    let sigma = 0.3;
    for m in 0..=8usize {
        let window = 2 * m + 7;
        let even = 3 * window + 5;
        let times = even_then_jittered(even, even + 3 * window, 40 + m as u64);
        let ys = signal(&times, 90 + m as u64);
        let mut f = FixedMemory::new(m, window, FixedEngine::Adaptive)
            .unwrap()
            .with_noise_sigma(sigma)
            .unwrap();
        for (n, (&t, &y)) in times.iter().zip(&ys).enumerate() {
            f.update(t, y).unwrap();
            let want_engine = if n < even {
                FixedEngine::Sliding
            } else {
                FixedEngine::Irregular
            };
            assert_eq!(f.engine(), want_engine, "m = {m}, sample {n}");
            if n + 1 < window {
                assert!(f.estimate().is_none());
                continue;
            }
            let s = n + 1 - window;
            let fit = PolynomialFit::new(&times[s..=n], &ys[s..=n], None, m).unwrap();
            for at in [t, t + 0.3, t - 0.6] {
                let got = f.estimate_at(at).unwrap();
                let want = fit.derivatives_at(at);
                let e = rel(&got.derivatives, &want);
                assert!(e <= 1e-9, "m = {m}, sample {n}, t = {at}: {e:.2e}");
                let cov = got.covariance.unwrap();
                let want_cov = fit.covariance_at(at) * (sigma * sigma);
                for i in 0..=m {
                    for k in 0..=m {
                        let scale = (want_cov[(i, i)] * want_cov[(k, k)]).sqrt();
                        let e = (cov[(i, k)] - want_cov[(i, k)]).abs() / scale;
                        assert!(e <= 1e-9, "m = {m}, sample {n}, cov ({i}, {k}): {e:.2e}");
                    }
                }
            }
        }
    }
}

#[test]
fn adaptive_runs_the_sliding_then_the_irregular_engine_bit_for_bit() {
    // Before the first uneven step the adaptive filter is the sliding filter; from it on, the
    // irregular filter fed every sample from the start (the same windows refitted by the same QR).
    for m in [0usize, 2, 5] {
        let window = 9;
        let even = 40;
        let times = even_then_jittered(even, 80, 7);
        let ys = signal(&times, 8);
        let mut adaptive = FixedMemory::new(m, window, FixedEngine::Adaptive).unwrap();
        let mut sliding = FixedMemory::new(m, window, FixedEngine::Sliding).unwrap();
        let mut irregular = FixedMemory::new(m, window, FixedEngine::Irregular).unwrap();
        for (n, (&t, &y)) in times.iter().zip(&ys).enumerate() {
            adaptive.update(t, y).unwrap();
            irregular.update(t, y).unwrap();
            let got = adaptive.estimate_at(t - 0.1).map(|s| s.derivatives);
            if n < even {
                sliding.update(t, y).unwrap();
                assert_eq!(got, sliding.estimate_at(t - 0.1).map(|s| s.derivatives));
                assert_eq!(adaptive.step(), sliding.step());
                assert_eq!(adaptive.refresh_period(), sliding.refresh_period());
            } else {
                // The sliding filter rejects the transition sample; the adaptive one carries on.
                if n == even {
                    assert!(matches!(
                        sliding.update(t, y),
                        Err(Error::InvalidParameter {
                            name: Param::SampleTime,
                            ..
                        })
                    ));
                }
                assert_eq!(got, irregular.estimate_at(t - 0.1).map(|s| s.derivatives));
                assert_eq!((adaptive.step(), adaptive.refresh_period()), (None, None));
            }
            assert_eq!(adaptive.samples(), n as u64 + 1);
            assert_eq!(adaptive.last_time(), Some(t));
        }
    }
}

#[test]
fn adaptive_switch_before_the_window_is_full() {
    // The first uneven step arrives while the window is still filling: the samples so far are
    // replayed, the window fills on the irregular engine and its first estimate is the QR fit.
    let window = 6;
    let times = [0.0, 0.5, 1.0, 1.7, 2.0, 2.6, 3.1, 3.5];
    let ys: Vec<f64> = times.iter().map(|t| 1.0 - t + 0.5 * t * t).collect();
    let mut f = FixedMemory::new(2, window, FixedEngine::Adaptive).unwrap();
    for (n, (&t, &y)) in times.iter().zip(&ys).enumerate() {
        f.update(t, y).unwrap();
        assert_eq!(f.engine() == FixedEngine::Irregular, n >= 3, "sample {n}");
        assert_eq!(f.estimate().is_some(), n + 1 >= window);
    }
    let n = times.len();
    let fit = PolynomialFit::new(&times[n - window..], &ys[n - window..], None, 2).unwrap();
    let got = f.estimate().unwrap().derivatives;
    assert!(rel(&got, &fit.derivatives_at(3.5)) <= 1e-12);
    // The data are a parabola: its own fit.
    assert!((got[0] - (1.0 - 3.5 + 0.5 * 3.5 * 3.5)).abs() < 1e-12 && (got[2] - 1.0).abs() < 1e-11);
}

#[test]
fn adaptive_keeps_the_input_checks_and_the_refresh_setting() {
    let mut f = FixedMemory::new(1, 4, FixedEngine::Adaptive)
        .unwrap()
        .with_refreshes(2)
        .unwrap();
    assert_eq!(
        (f.engine(), f.refresh_period()),
        (FixedEngine::Sliding, Some(2))
    );
    f.update(0.0, 1.0).unwrap();
    assert!(matches!(
        f.update(0.0, 1.0),
        Err(Error::TimeNotIncreasing { .. })
    ));
    assert!(matches!(
        f.update(1.0, f64::NAN),
        Err(Error::NonFinite { .. })
    ));
    // A rejected sample changes nothing: the filter is still on the sliding engine.
    assert_eq!((f.engine(), f.samples()), (FixedEngine::Sliding, 1));
    assert!(f.with_refreshes(3).is_err()); // after the first sample
}
