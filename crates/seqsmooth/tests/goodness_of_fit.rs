//! Reyneke et al. §7.1's goodness of fit (`stats::goodness_of_fit`) against independent
//! oracles: the residuals of a direct QR fit, and Monte Carlo with tolerances from the sample
//! size for its mean and its false-alarm rate.

use rand::rngs::StdRng;
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use seqsmooth::estimate::PolynomialFit;
use seqsmooth::stats::{
    gof_false_alarm_rate, gof_mean, gof_threshold, goodness_of_fit, reyneke_gof_limit,
    ChiSquaredTest,
};
use seqsmooth::Error;

/// `N` unit-noise samples fitted with degree `m`: the measure with `R = 1`.
fn window(n: usize, m: usize, rng: &mut StdRng) -> (f64, f64) {
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.7).collect();
    let y: Vec<f64> = t
        .iter()
        .map(|t| 2.0 - t + Distribution::<f64>::sample(&StandardNormal, rng))
        .collect();
    let fit = PolynomialFit::new(&t, &y, None, m).unwrap();
    let r: Vec<f64> = t
        .iter()
        .zip(&y)
        .map(|(&t, &y)| y - fit.derivatives_at(t)[0])
        .collect();
    (goodness_of_fit(&r, 1.0).unwrap(), fit.residual_sq())
}

#[test]
fn the_measure_is_the_fits_residual_sum_of_squares_per_sample() {
    let mut rng = StdRng::seed_from_u64(5);
    for (n, m) in [(5, 0), (12, 1), (30, 3)] {
        let (g, rss) = window(n, m, &mut rng);
        assert!(
            (g * n as f64 - rss).abs() < 1e-10 * rss.max(1.0),
            "N {n} m {m}"
        );
    }
}

#[test]
fn its_mean_is_one_minus_the_parameters_per_sample_not_the_printed_limit() {
    // E[G] = (N − m − 1)/N; G·N is χ²_{N−m−1}, variance 2(N − m − 1): σ of the mean of `runs`.
    let runs = 20_000;
    let mut rng = StdRng::seed_from_u64(11);
    for (n, m) in [(20, 1), (50, 2)] {
        let mean = (0..runs).map(|_| window(n, m, &mut rng).0).sum::<f64>() / runs as f64;
        let dof = (n - m - 1) as f64;
        let sd = (2.0 * dof).sqrt() / n as f64 / (runs as f64).sqrt();
        let expected = gof_mean(n, m).unwrap();
        assert!(
            (mean - expected).abs() < 5.0 * sd,
            "N {n} m {m}: {mean} vs {expected}"
        );
        // the printed limit is many σ away
        let limit = reyneke_gof_limit(n).unwrap();
        assert!(
            (mean - limit).abs() > 20.0 * sd,
            "N {n}: {mean} vs limit {limit}"
        );
    }
}

#[test]
fn false_alarm_rates_match_monte_carlo_and_the_threshold_is_the_chi_squared_test() {
    let runs = 20_000;
    let mut rng = StdRng::seed_from_u64(13);
    let (n, m) = (20, 1);
    let limit = reyneke_gof_limit(n).unwrap();
    let threshold = gof_threshold(n, m, 0.05).unwrap();
    let chi = ChiSquaredTest::new((n - m - 1) as f64, 0.05).unwrap();
    let (mut over_limit, mut over_threshold) = (0usize, 0usize);
    for _ in 0..runs {
        let (g, rss) = window(n, m, &mut rng);
        over_limit += usize::from(g > limit);
        over_threshold += usize::from(g > threshold);
        assert_eq!(g > threshold, chi.rejects(rss), "G {g}, residual χ² {rss}");
    }
    for (count, p) in [
        (over_limit, gof_false_alarm_rate(n, m, limit).unwrap()),
        (over_threshold, 0.05),
    ] {
        let sd = (p * (1.0 - p) / runs as f64).sqrt();
        let rate = count as f64 / runs as f64;
        assert!((rate - p).abs() < 5.0 * sd, "rate {rate} vs {p}");
    }
    assert!(gof_false_alarm_rate(n, m, limit).unwrap() > 0.5);
}

#[test]
fn bad_input_is_refused_by_name() {
    for e in [
        goodness_of_fit(&[], 1.0).unwrap_err(),
        gof_mean(2, 1).unwrap_err(),
        gof_threshold(10, 1, 1.0).unwrap_err(),
        reyneke_gof_limit(0).unwrap_err(),
    ] {
        assert!(matches!(e, Error::InvalidParameter { .. }), "{e:?}");
    }
    assert!(matches!(
        goodness_of_fit(&[1.0, f64::INFINITY], 1.0),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        gof_false_alarm_rate(10, 1, f64::NAN),
        Err(Error::NonFinite { .. })
    ));
}
