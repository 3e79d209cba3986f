//! The statistics module against exact values, identities and Monte Carlo.
//!
//! Monte Carlo tolerances come from the sample size: a mean of `R` independent terms is checked
//! to within 4.5 of its standard errors (two-sided false-alarm probability 7e-6 per check; the
//! seeds are fixed, so the tests are reproducible), and a rate `p` from `N` trials to within
//! 4.5 `√(p(1-p)/N)`.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal, StandardNormal};
use seqsmooth::estimate::PolynomialFit;
use seqsmooth::stats::{
    chi_squared_cdf, chi_squared_quantile, chi_squared_sf, difference_variance,
    fit_residual_variance, normal_quantile, normalised_divided_difference, residual_variance,
    reyneke_eq39_variance, reyneke_stdd, reyneke_stddw, two_sided_tail, two_sided_threshold,
    ChiSquaredTest, DifferenceNoise, InnovationChiSquared, Welford,
};
use seqsmooth::{Engine, Error, ExpandingMemory, FadingMemory, PolynomialFilter};

const Z: f64 = 4.5;

fn rng(seed: u64) -> StdRng {
    StdRng::seed_from_u64(seed)
}

fn gauss(r: &mut StdRng) -> f64 {
    StandardNormal.sample(r)
}

fn choose(n: u64, k: u64) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

// ---------------------------------------------------------------------------------------------
// Chi-squared and Gaussian helpers

#[test]
fn chi_squared_quantiles_match_tables_and_closed_forms() {
    // (dof, p, quantile) from standard tables.
    let table = [
        (1.0, 0.95, 3.841458820694124),
        (1.0, 0.99, 6.634896601021214),
        (2.0, 0.95, 5.991464547107979),
        (5.0, 0.05, 1.145476226061769),
        (10.0, 0.99, 23.209251158954356),
    ];
    for (dof, p, q) in table {
        let x = chi_squared_quantile(dof, p).unwrap();
        assert!(
            (x - q).abs() <= 1e-10 * q,
            "quantile({dof}, {p}) = {x}, table {q}"
        );
    }
    // 2 dof is exponential: q = −2 ln(1 − p).
    for p in [1e-6f64, 0.01, 0.5, 0.99, 0.9999, 1.0 - 1e-9] {
        let q = -2.0 * (-p).ln_1p();
        let x = chi_squared_quantile(2.0, p).unwrap();
        assert!((x - q).abs() <= 1e-11 * q, "p {p}: {x} vs {q}");
    }
    // 3 dof near 0: P(χ²_3 ≤ x) ≈ x^(3/2)/(2^(3/2) Γ(5/2)) (1 − 3x/10).
    let x = chi_squared_quantile(3.0, 1e-6).unwrap();
    let approx =
        x.powf(1.5) / (2f64.powf(1.5) * 0.75 * std::f64::consts::PI.sqrt()) * (1.0 - 0.3 * x);
    assert!((approx - 1e-6).abs() < 1e-12);
}

#[test]
fn chi_squared_helpers_reject_bad_input() {
    assert!(matches!(
        chi_squared_quantile(0.0, 0.5),
        Err(Error::InvalidParameter { .. })
    ));
    assert!(chi_squared_quantile(f64::NAN, 0.5).is_err());
    assert!(chi_squared_quantile(3.0, 0.0).is_err());
    assert!(chi_squared_quantile(3.0, 1.0).is_err());
    assert!(chi_squared_quantile(3.0, f64::NAN).is_err());
    assert!(chi_squared_cdf(-1.0, 1.0).is_err());
    assert!(matches!(
        chi_squared_cdf(2.0, f64::NAN),
        Err(Error::NonFinite { .. })
    ));
    assert_eq!(chi_squared_cdf(2.0, -3.0).unwrap(), 0.0);
    assert_eq!(chi_squared_sf(2.0, -3.0).unwrap(), 1.0);
    assert_eq!(chi_squared_sf(2.0, f64::INFINITY).unwrap(), 0.0);
    assert!(normal_quantile(1.0).is_err());
    assert!(two_sided_tail(-1.0).is_err());
    assert!(two_sided_threshold(0.0).is_err());
    assert!(ChiSquaredTest::new(3.0, 1.5).is_err());
}

#[test]
fn gaussian_gate_helpers_are_inverse() {
    for alpha in [0.5, 0.1, 0.0027, 1e-4, 1e-9] {
        let k = two_sided_threshold(alpha).unwrap();
        let back = two_sided_tail(k).unwrap();
        assert!(
            (back - alpha).abs() <= 1e-9 * alpha,
            "{alpha}: k {k}, back {back}"
        );
        // P(|Z| > k) = P(χ²_1 > k²)
        let chi = chi_squared_sf(1.0, k * k).unwrap();
        assert!((chi - alpha).abs() <= 1e-9 * alpha);
    }
    assert!((normal_quantile(0.5).unwrap()).abs() < 1e-15);
    assert!((normal_quantile(0.15865525393145707).unwrap() + 1.0).abs() < 1e-9);
}

#[test]
fn morrison_tv5_6_chi_squared_consistency_test() {
    // R = [[1,-1],[-1,1.01]], R⁻¹ = [[101,100],[100,100]], N = (1/2, 1/2): χ² = 100.25.
    let (a, b) = (0.5f64, 0.5f64);
    let chi2 = 101.0 * a * a + 200.0 * a * b + 100.0 * b * b;
    assert!((chi2 - 100.25).abs() < 1e-12);
    let test = ChiSquaredTest::new(2.0, 0.05).unwrap();
    assert!(test.rejects(chi2));
    assert!(chi_squared_cdf(2.0, chi2).unwrap() > 0.99999);
    assert!(test.p_value(chi2).unwrap() < 1e-20);
}

// ---------------------------------------------------------------------------------------------
// The windowed innovation test

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
    println!("expanding m=1: mean k² {mean:.4}, lag-1 corr {lag:.4}, misfit rate {rate:.4}");
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
        let (mut rate, mut mean, mut lag, mut scored) = (0.0, 0.0, 0.0, 0);
        let runs = 20;
        for seed in 0..runs {
            let f = FadingMemory::new(m, theta, 1.0, Engine::Exact)
                .unwrap()
                .with_noise_sigma(1.0)
                .unwrap();
            let (mm, l, r, s) = innovation_run(Box::new(f), 4_000, 300, 10, 0.01, 100 + seed);
            rate += r * s as f64;
            mean += mm;
            lag += l;
            scored += s;
        }
        rate /= scored as f64;
        mean /= runs as f64;
        lag /= runs as f64;
        println!(
            "fading m={m} θ={theta}: mean k² {mean:.4}, lag-1 corr {lag:.4}, misfit rate {rate:.4}"
        );
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

// ---------------------------------------------------------------------------------------------
// Noise estimation

/// Reyneke's comparison (others.md §4.7): white noise σ = 1 plus no trend, a 0.5/sample ramp,
/// or a 1e-3 n² parabola, N = 2000. Expected values: eq. 39 → √(1 + Σ Δtrend²/(2N−2)) =
/// 1.000 / 1.061 / 1.915, stdd → √(1 + Var(Δtrend)/2) = 1.000 / 1.000 / 1.291; the spec prints
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
    println!("trend      eq39   stdd   ∇² est ∇³ est   (printed eq39 / stdd)");
    for (i, (name, trend)) in trends.iter().enumerate() {
        let y: Vec<f64> = (0..n).map(|k| trend(k as f64) + noise[k]).collect();
        let e39 = reyneke_eq39_variance(&y).unwrap().sqrt();
        let stdd = reyneke_stdd(&y).unwrap();
        let d2 = difference_variance(&y, 2).unwrap().sqrt();
        let d3 = difference_variance(&y, 3).unwrap().sqrt();
        println!(
            "{name:10} {e39:.3}  {stdd:.3}  {d2:.3}  {d3:.3}   ({:.3} / {:.3})",
            printed_eq39[i], printed_stdd[i]
        );
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
    println!(
        "order-4 divided differences: mean σ̂² {mean:.4} (σ² = {:.4}, se {se:.4}); order 1: {:.1}",
        sigma * sigma,
        w_first.mean().unwrap()
    );
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

#[test]
fn residual_variance_is_unbiased_and_chi_squared() {
    // Morrison (6.10.21)/(6.10.24): E{e°} = σ²(N_O − N_X); e°/σ² ~ χ²_{N_O−N_X} (standard).
    let (runs, n, m, sigma) = (4000, 25, 2, 0.3);
    let dof = (n - m - 1) as f64;
    let q95 = chi_squared_quantile(dof, 0.95).unwrap();
    let mut w = Welford::new();
    let mut above = 0;
    let mut r = rng(610);
    let noise = Normal::new(0.0, sigma).unwrap();
    for _ in 0..runs {
        let t: Vec<f64> = (0..n).map(|k| k as f64 + 0.4 * r.gen::<f64>()).collect();
        let y: Vec<f64> = t
            .iter()
            .map(|t| 1.0 + 0.2 * t - 0.05 * t * t + noise.sample(&mut r))
            .collect();
        let fit = PolynomialFit::new(&t, &y, None, m).unwrap();
        let s2 = fit_residual_variance(&fit).unwrap();
        w.push(s2).unwrap();
        if s2 * dof / (sigma * sigma) > q95 {
            above += 1;
        }
    }
    let mean = w.mean().unwrap();
    let se = sigma * sigma * (2.0 / dof / runs as f64).sqrt();
    let rate = above as f64 / runs as f64;
    println!(
        "residual variance: mean {mean:.5} (σ² {:.5}), above χ² 95%: {rate:.4}",
        sigma * sigma
    );
    assert!((mean - sigma * sigma).abs() < Z * se);
    assert!((rate - 0.05).abs() < Z * (0.05 * 0.95 / runs as f64).sqrt());
    assert!(residual_variance(-1.0, 10, 2).is_err());
    assert!(residual_variance(f64::NAN, 10, 2).is_err());
    assert!(matches!(
        residual_variance(1.0, 2, 2),
        Err(Error::TooFewSamples { .. })
    ));
}

#[test]
fn recursive_residuals_sum_to_the_batch_residual() {
    // For expanding memory the normalised innovations ν²/(1+v) are the recursive residuals:
    // their sum over samples m+1.. equals the batch fit's residual sum of squares.
    let mut r = rng(9);
    let m = 2;
    let t: Vec<f64> = (0..200)
        .map(|k| k as f64 * 0.3 + 0.1 * r.gen::<f64>())
        .collect();
    let y: Vec<f64> = t
        .iter()
        .map(|t| 4.0 - t + 0.1 * t * t + gauss(&mut r))
        .collect();
    let mut f = ExpandingMemory::new(m, Engine::Exact)
        .unwrap()
        .with_noise_sigma(1.0)
        .unwrap();
    let mut sum = 0.0;
    for (&tk, &yk) in t.iter().zip(&y) {
        if let Some(p) = f.estimate_at(tk) {
            let v = p.covariance.as_ref().unwrap()[(0, 0)];
            sum += (yk - p.derivatives[0]).powi(2) / (1.0 + v);
        }
        f.update(tk, yk).unwrap();
    }
    let fit = PolynomialFit::new(&t, &y, None, m).unwrap();
    assert!((sum - fit.residual_sq()).abs() < 1e-9 * fit.residual_sq());
}

#[test]
fn welford_matches_two_pass_and_merges() {
    let mut r = rng(1);
    let x: Vec<f64> = (0..1000).map(|_| 1e6 + 3.0 * gauss(&mut r)).collect();
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (x.len() - 1) as f64;
    let mut w = Welford::new();
    let (mut a, mut b) = (Welford::new(), Welford::new());
    for (k, v) in x.iter().enumerate() {
        w.push(*v).unwrap();
        if k < 333 {
            a.push(*v).unwrap()
        } else {
            b.push(*v).unwrap()
        }
    }
    assert!((w.mean().unwrap() - mean).abs() < 1e-9);
    assert!((w.sample_variance().unwrap() - var).abs() < 1e-9 * var);
    a.merge(&b);
    assert_eq!(a.count(), 1000);
    assert!((a.sample_variance().unwrap() - var).abs() < 1e-9 * var);
    assert!((w.population_variance().unwrap() - var * 999.0 / 1000.0).abs() < 1e-9);
    let mut e = Welford::new();
    assert!(e.mean().is_none() && e.sample_variance().is_none());
    assert!(e.push(f64::NAN).is_err());
    assert_eq!(e.count(), 0);
}
