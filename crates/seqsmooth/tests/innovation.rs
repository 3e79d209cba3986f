//! `seqsmooth::stats::innovation`: the innovations of the expanding- and fading-memory filters
//! are white, the windowed test is calibrated, detects a bias and rejects bad input.
//!
//! Monte Carlo tolerances come from the sample size: a mean of `R` independent terms is checked
//! to within 4.5 of its standard errors (two-sided false-alarm probability 7e-6 per check; the
//! seeds are fixed, so the tests are reproducible), and a rate `p` from `N` trials to within
//! 4.5 `√(p(1-p)/N)`.

mod common;

use common::stats::*;
use rand_distr::{Distribution, StandardNormal};
use seqsmooth::stats::InnovationChiSquared;
use seqsmooth::{Engine, Error, ExpandingMemory, FadingMemory, PolynomialFilter};

/// Runs a filter over white noise (truth 0) and feeds its normalised 1-step innovations to the
/// windowed test; returns (mean k², lag-1 correlation of k, misfit rate, samples).
fn innovation_run(
    mut filter: Box<dyn PolynomialFilter>,
    samples: usize,
    skip: usize,
    window: usize,
    alpha: f64,
    seed: u64,
) -> (f64, f64, f64, usize) {
    let mut r = rng(seed);
    let mut test = InnovationChiSquared::new(window, alpha).unwrap();
    let (mut k2_sum, mut n, mut flagged, mut scored) = (0.0, 0usize, 0usize, 0usize);
    let (mut prev, mut lag_sum) = (None::<f64>, 0.0);
    for i in 0..samples {
        let t = i as f64;
        let y: f64 = StandardNormal.sample(&mut r);
        if let Some(p) = filter.estimate_at(t) {
            let v = p.covariance.as_ref().unwrap()[(0, 0)];
            if i >= skip {
                let k = (y - p.derivatives[0]) / (1.0 + v).sqrt();
                let out = test.push(y - p.derivatives[0], 1.0 + v).unwrap();
                k2_sum += k * k;
                n += 1;
                if let Some(q) = prev {
                    lag_sum += q * k;
                }
                prev = Some(k);
                if test.len() == window {
                    scored += 1;
                    if out.misfit {
                        flagged += 1;
                    }
                }
            }
        }
        filter.update(t, y).unwrap();
    }
    (
        k2_sum / n as f64,
        lag_sum / (n - 1) as f64,
        flagged as f64 / scored as f64,
        scored,
    )
}

#[test]
fn expanding_memory_innovations_are_white_and_the_test_is_calibrated() {
    // The innovations of expanding-memory least squares are the recursive residuals:
    // independent N(0, σ²(1+v)). So k² has mean 1, lag-1 correlation 0, and the window sum is
    // exactly χ²_K: the misfit rate is α.
    let runs = 40;
    let (mut rate, mut mean, mut lag, mut scored) = (0.0, 0.0, 0.0, 0);
    for seed in 0..runs {
        let f = ExpandingMemory::new(1, Engine::Exact)
            .unwrap()
            .with_noise_sigma(1.0)
            .unwrap();
        let (m, l, r, s) = innovation_run(Box::new(f), 2_000, 0, 10, 0.01, seed);
        rate += r * s as f64;
        mean += m;
        lag += l;
        scored += s;
    }
    rate /= scored as f64;
    mean /= runs as f64;
    lag /= runs as f64;
    let n = (runs * 1_995) as f64;
    assert!((mean - 1.0).abs() < Z * (2.0 / n).sqrt());
    assert!(lag.abs() < Z / n.sqrt());
    // Window sums overlap (K = 10), so the flagged samples come in runs; the standard error of
    // the rate is about √K times the binomial one.
    let se = (0.01 * 0.99 / scored as f64 * 10.0).sqrt();
    assert!((rate - 0.01).abs() < Z * se, "rate {rate}, se {se}");
}

#[test]
fn fading_memory_innovations_are_nearly_white() {
    // Fading memory is not the optimal estimator for the model, so its innovations are weakly
    // correlated: the window sum has mean K but not exactly the χ²_K spread. Measured here
    // (θ = 0.9 and 0.97, m = 1, 2) and required within a factor 2 of α.
    for (m, theta) in [(1, 0.9), (2, 0.9), (2, 0.97)] {
        let (mut rate, mut mean, mut scored) = (0.0, 0.0, 0);
        let runs = 20;
        for seed in 0..runs {
            let f = FadingMemory::new(m, theta, 1.0, Engine::Exact)
                .unwrap()
                .with_noise_sigma(1.0)
                .unwrap();
            let (mm, _, r, s) = innovation_run(Box::new(f), 4_000, 300, 10, 0.01, 100 + seed);
            rate += r * s as f64;
            mean += mm;
            scored += s;
        }
        rate /= scored as f64;
        mean /= runs as f64;
        let n = (runs * 3_700) as f64;
        assert!((mean - 1.0).abs() < Z * (2.0 / n).sqrt() * 1.5);
        assert!(rate < 0.02, "misfit rate {rate}");
    }
}

#[test]
fn innovation_test_detects_a_bias_and_resets() {
    let mut test = InnovationChiSquared::new(5, 0.01).unwrap();
    for _ in 0..5 {
        assert!(!test.push(0.5, 1.0).unwrap().misfit);
    }
    // A bias of 3σ_ε per sample: 5 × 9 = 45 > χ²_5(0.99) = 15.09 within two samples.
    let mut first = None;
    for k in 0..5 {
        let out = test.push(3.0, 1.0).unwrap();
        assert_eq!(out.dof, 5);
        if out.misfit && first.is_none() {
            first = Some(k);
        }
    }
    assert_eq!(first, Some(1));
    assert!(test.is_misfit());
    test.reset();
    assert!(test.is_empty() && !test.is_misfit());
    // partial windows use χ²_len
    let out = test.push(2.0, 1.0).unwrap();
    assert_eq!(out.dof, 1);
    assert!((out.threshold - 6.634896601021214).abs() < 1e-9);
    assert!(!out.misfit);
    assert!(test.push(3.0, 1.0).unwrap().misfit); // 4 + 9 = 13 > 9.21
}

#[test]
fn innovation_test_rejects_bad_input_without_changing() {
    assert!(InnovationChiSquared::new(0, 0.01).is_err());
    assert!(InnovationChiSquared::new(5, 0.0).is_err());
    assert!(InnovationChiSquared::new(5, 1.0).is_err());
    let mut test = InnovationChiSquared::new(5, 0.01).unwrap();
    test.push(1.0, 1.0).unwrap();
    assert!(matches!(
        test.push(f64::NAN, 1.0),
        Err(Error::NonFinite { .. })
    ));
    assert!(test.push(1.0, 0.0).is_err());
    assert!(test.push(1.0, -1.0).is_err());
    assert!(test.push(1.0, f64::INFINITY).is_err());
    assert!(test.push_normalised(-1.0).is_err());
    assert_eq!(test.len(), 1);
    assert_eq!(test.statistic(), 1.0);
}
