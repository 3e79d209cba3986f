//! `seqsmooth::stats::noise`: Reyneke et al. (2012) §7 difference-based noise estimators (the
//! trend bias of eq. 39 and stdd, removed by higher differences), windows, irregular samples, bad
//! input.
//!
//! Monte Carlo tolerances come from the sample size: a mean of `R` independent terms is checked
//! to within 4.5 of its standard errors (two-sided false-alarm probability 7e-6 per check; the
//! seeds are fixed, so the tests are reproducible), and a rate `p` from `N` trials to within
//! 4.5 `√(p(1-p)/N)`.

mod common;

use common::stats::*;
use rand::Rng;
use rand_distr::{Distribution, Normal, StandardNormal};
use seqsmooth::stats::{
    difference_variance, normalised_divided_difference, reyneke_eq39_variance, reyneke_stdd,
    reyneke_stddw, DifferenceNoise, Welford,
};
use seqsmooth::Error;

fn choose(n: u64, k: u64) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

/// Reyneke et al. §7 comparison: white noise σ = 1 plus no trend, a 0.5/sample ramp,
/// or a 1e-3 n² parabola, N = 2000. Expected values: eq. 39 → √(1 + Σ Δtrend²/(2N−2)) =
/// 1.000 / 1.061 / 1.915, stdd → √(1 + Var(Δtrend)/2) = 1.000 / 1.000 / 1.291; the paper prints
/// 1.000/1.061/1.914 and 1.000/1.001/1.290.
#[test]
fn reyneke_noise_estimators_reproduce_the_trend_bias_and_higher_differences_remove_it() {
    let n = 2000usize;
    let mut r = rng(2012);
    let noise: Vec<f64> = (0..n).map(|_| StandardNormal.sample(&mut r)).collect();
    type Trend = Box<dyn Fn(f64) -> f64>;
    let trends: [(&str, Trend); 3] = [
        ("none", Box::new(|_| 0.0)),
        ("linear", Box::new(|k| 0.5 * k)),
        ("quadratic", Box::new(|k| 1e-3 * k * k)),
    ];
    let printed_eq39 = [1.000, 1.061, 1.914];
    let printed_stdd = [1.000, 1.001, 1.290];
    // Standard errors of σ̂ from N samples: ½√(2·ρ/N) with the overlap factor ρ of k-th
    // differences, C(4k,2k)/C(2k,k)² (1.5 for k = 1, 2.31 for k = 3).
    let se =
        |k: u64| 0.5 * (2.0 * choose(4 * k, 2 * k) / choose(2 * k, k).powi(2) / n as f64).sqrt();
    let mut third = Vec::new();
    for (i, (name, trend)) in trends.iter().enumerate() {
        let y: Vec<f64> = (0..n).map(|k| trend(k as f64) + noise[k]).collect();
        let e39 = reyneke_eq39_variance(&y).unwrap().sqrt();
        let stdd = reyneke_stdd(&y).unwrap();
        let d2 = difference_variance(&y, 2).unwrap().sqrt();
        let d3 = difference_variance(&y, 3).unwrap().sqrt();
        // the expected (bias) values, exactly
        let d: Vec<f64> = (1..n)
            .map(|k| trend(k as f64) - trend(k as f64 - 1.0))
            .collect();
        let bias39 = d.iter().map(|v| v * v).sum::<f64>() / (2 * n - 2) as f64;
        let mean_d = d.iter().sum::<f64>() / d.len() as f64;
        let var_d = d.iter().map(|v| (v - mean_d).powi(2)).sum::<f64>() / (d.len() - 1) as f64;
        let want39 = (1.0 + bias39).sqrt();
        let want_stdd = (1.0 + var_d / 2.0).sqrt();
        assert!((want39 - printed_eq39[i]).abs() < 1.5e-3, "{want39}");
        assert!((want_stdd - printed_stdd[i]).abs() < 1.5e-3, "{want_stdd}");
        // the realisation agrees with the expectation within the sampling error
        assert!(
            (e39 - want39).abs() < Z * se(1),
            "{name}: eq39 {e39} vs {want39}"
        );
        assert!(
            (stdd - want_stdd).abs() < Z * se(1),
            "{name}: stdd {stdd} vs {want_stdd}"
        );
        // the third difference annihilates all three trends: same value as for pure noise, and
        // the second difference all but the quadratic
        assert!((d3 - 1.0).abs() < Z * se(3), "{name}: ∇³ {d3}");
        if i < 2 {
            assert!((d2 - 1.0).abs() < Z * se(2), "{name}: ∇² {d2}");
        }
        third.push(d3);
    }
    // exactly the same numbers, up to rounding of the trend values
    assert!((third[0] - third[1]).abs() < 1e-9 && (third[0] - third[2]).abs() < 1e-9);
}

#[test]
fn stddw_is_a_centred_window_of_stdd() {
    let mut r = rng(5);
    let y: Vec<f64> = (0..60).map(|k| 0.3 * k as f64 + gauss(&mut r)).collect();
    let w = reyneke_stddw(&y, 20).unwrap();
    assert_eq!(w.len(), 60);
    // sample 30: window [20, 40)
    assert!((w[30] - reyneke_stdd(&y[20..40]).unwrap()).abs() < 1e-15);
    // sample 3: window [-7, 13) clipped to [0, 13)
    assert!((w[3] - reyneke_stdd(&y[0..13]).unwrap()).abs() < 1e-15);
    assert!(reyneke_stddw(&y, 0).is_err());
}

#[test]
fn difference_noise_is_unbiased_on_irregular_samples_with_a_polynomial_trend() {
    // Jittered and gapped timestamps, a cubic trend with large coefficients, σ = 0.7; order 4
    // divided differences. R runs of N samples: the mean of σ̂² must be σ² within the sampling
    // error measured from the runs themselves.
    let (runs, n, sigma) = (200, 400, 0.7);
    let mut w = Welford::new();
    let mut w_first = Welford::new();
    for seed in 0..runs {
        let mut r = rng(300 + seed);
        let noise = Normal::new(0.0, sigma).unwrap();
        let mut est = DifferenceNoise::new(4, None).unwrap();
        let mut first = DifferenceNoise::new(1, None).unwrap();
        let mut t = 0.0;
        for _ in 0..n {
            t += if r.gen::<f64>() < 0.1 {
                3.0
            } else {
                0.5 + r.gen::<f64>()
            };
            let y = 5.0 - 2.0 * t + 0.3 * t * t - 0.01 * t * t * t + noise.sample(&mut r);
            est.push(t, y).unwrap();
            first.push(t, y).unwrap();
        }
        w.push(est.variance().unwrap()).unwrap();
        w_first.push(first.variance().unwrap()).unwrap();
    }
    let mean = w.mean().unwrap();
    let se = (w.sample_variance().unwrap() / runs as f64).sqrt();
    assert!((mean - sigma * sigma).abs() < Z * se);
    assert!(w_first.mean().unwrap() > 10.0 * sigma * sigma); // the first difference is useless here
}

#[test]
fn difference_noise_on_even_samples_equals_the_batch_estimator_and_windows_slide() {
    let mut r = rng(77);
    let y: Vec<f64> = (0..300)
        .map(|k| (k as f64).sqrt() + gauss(&mut r))
        .collect();
    for order in 1..=4 {
        let mut est = DifferenceNoise::new(order, None).unwrap();
        for (k, v) in y.iter().enumerate() {
            est.push(2.5 * k as f64 - 10.0, *v).unwrap();
        }
        let batch = difference_variance(&y, order).unwrap();
        assert!((est.variance().unwrap() - batch).abs() < 1e-12 * batch);
        assert_eq!(est.len(), 300 - order);
    }
    // windowed: the last 50 differences of order 2
    let mut est = DifferenceNoise::new(2, Some(50)).unwrap();
    for (k, v) in y.iter().enumerate() {
        est.push(k as f64, *v).unwrap();
    }
    let tail = difference_variance(&y[248..], 2).unwrap();
    assert_eq!(est.len(), 50);
    assert!((est.variance().unwrap() - tail).abs() < 1e-12 * tail);
}

#[test]
fn difference_noise_rejects_bad_input_without_changing() {
    assert!(DifferenceNoise::new(0, None).is_err());
    assert!(DifferenceNoise::new(2, Some(0)).is_err());
    let mut est = DifferenceNoise::new(1, None).unwrap();
    est.push(0.0, 1.0).unwrap();
    est.push(1.0, 2.0).unwrap();
    assert!(matches!(
        est.push(1.0, 3.0),
        Err(Error::TimeNotIncreasing { .. })
    ));
    assert!(matches!(
        est.push(f64::NAN, 3.0),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        est.push(2.0, f64::INFINITY),
        Err(Error::NonFinite { .. })
    ));
    assert!(est.push_with_variance_factor(2.0, 1.0, 0.0).is_err());
    assert_eq!(est.len(), 1);
    assert!((est.variance().unwrap() - 0.5).abs() < 1e-15);
    assert!(normalised_divided_difference(&[0.0, 0.0], &[1.0, 2.0]).is_err());
    assert!(normalised_divided_difference(&[0.0], &[1.0]).is_err());
    assert!(difference_variance(&[1.0, 2.0], 2).is_err());
    assert!(difference_variance(&[1.0, f64::NAN, 2.0], 1).is_err());
    assert!(reyneke_eq39_variance(&[1.0]).is_err());
    assert!(reyneke_stdd(&[1.0, 2.0]).is_err());
}
