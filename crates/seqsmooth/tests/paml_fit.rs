//! The PAML estimate (`PolynomialSamples::fit`, Villien & Ostertag eqs. 3-4) against the raw
//! samples' maximum-likelihood fit (eq. 2): equal where Lemma 3 makes their normal equations
//! one; Example 1's Monte Carlo (must-show 3) at the orders where it holds; Example 3's
//! compression.

#[path = "common/doppler.rs"]
mod doppler;

use doppler::{prior, Doppler, Scenario, SAMPLES};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use seqsmooth::estimate::curve::{cramer_rao_bound, fit_curve, Curve};
use seqsmooth::paml::PolynomialSamples;

#[test]
fn paml_is_the_raw_fit_when_the_normal_equations_are_polynomial_of_degree_2n_plus_1() {
    // h = θ₀ + θ₁ t + θ₂² t²: ∇h = (1, t, 2θ₂ t²) has degree 2 = n and h ∇h degree 4 ≤ 2n+1,
    // so the Gauss rule of the samples' measure integrates the normal equations exactly
    // (Lemma 3): the PAML estimate and covariance are the raw ones, on irregular times with
    // noise varying twentyfold, from 3 numbers instead of 500.
    let mut rng = StdRng::seed_from_u64(5);
    let mut t: Vec<f64> = (0..500).map(|_| rng.gen_range(0.0..10.0)).collect();
    t.sort_by(f64::total_cmp);
    let s: Vec<f64> = t.iter().map(|t| 0.05 * (1.0 + 2.0 * t)).collect();
    let truth = [1.0, -0.4, 0.3];
    let y: Vec<f64> = t
        .iter()
        .zip(&s)
        .map(|(&t, s)| {
            truth[0]
                + truth[1] * t
                + truth[2] * truth[2] * t * t
                + s * rng.sample::<f64, _>(StandardNormal)
        })
        .collect();
    let h = Curve::new(3, |th: &[f64], t| th[0] + th[1] * t + th[2] * th[2] * t * t);
    let start = [0.0, 0.0, 1.0];
    let raw = fit_curve(&h, &t, &y, &s, &start).unwrap();
    let ps = PolynomialSamples::from_segment(&t, &y, &s, 2).unwrap();
    assert_eq!(ps.values.len(), 3);
    let paml = ps.fit(&h, &start).unwrap();
    for i in 0..3 {
        let sigma = raw.covariance[(i, i)].sqrt();
        let err = (paml.parameters[i] - raw.parameters[i]).abs() / sigma;
        assert!(err <= 1e-7, "θ{i}: PAML off the raw fit by {err:e} σ");
    }
    let rel = (&paml.covariance - &raw.covariance).amax() / raw.covariance.amax();
    assert!(rel <= 1e-9, "covariance off by {rel:e}");
    // At a higher order the samples carry the same information.
    let paml4 = PolynomialSamples::from_segment(&t, &y, &s, 4)
        .unwrap()
        .fit(&h, &start)
        .unwrap();
    assert!((&paml4.covariance - &raw.covariance).amax() <= 1e-9 * raw.covariance.amax());
    // The raw chi-squared is the PAML one plus the polynomial's own misfit, which is free of
    // θ: the PAML chi-squared has n+1-m = 0 degrees of freedom here and is ~0.
    assert_eq!(paml.degrees_of_freedom, 0);
    assert!(paml.chi_squared <= 1e-12 * raw.chi_squared);
}

/// Must-show 3 on Example 1: ≥ 95 % of 300 runs have the PAML estimate within 1 % of the ML
/// σ of the ML estimate (each parameter), and the two σ within 10 % of each other and of the
/// Cramér–Rao bound.
fn example_1(miss: f64, order: usize) -> ([f64; 3], [f64; 3], [f64; 3], [f64; 3]) {
    let sc = Scenario::new(miss, SAMPLES);
    let crlb = cramer_rao_bound(&Doppler, &sc.truth, &sc.times, &sc.sigmas).unwrap();
    let mut rng = StdRng::seed_from_u64(1);
    let runs = 300;
    let (mut ml, mut pa) = (vec![], vec![]);
    for _ in 0..runs {
        let y = sc.measure(&mut rng);
        let start = prior(&sc.truth, &mut rng);
        let raw = fit_curve(&Doppler, &sc.times, &y, &sc.sigmas, &start).unwrap();
        let paml = PolynomialSamples::from_segment(&sc.times, &y, &sc.sigmas, order)
            .unwrap()
            .fit(&Doppler, &start)
            .unwrap();
        ml.push(raw.parameters);
        pa.push(paml.parameters);
    }
    let rms = |e: &[nalgebra::DVector<f64>]| {
        [0, 1, 2].map(|i| {
            (e.iter()
                .map(|p| (p[i].abs() - sc.truth[i]).powi(2))
                .sum::<f64>()
                / runs as f64)
                .sqrt()
        })
    };
    let (ml_sigma, pa_sigma) = (rms(&ml), rms(&pa));
    let within = [0, 1, 2].map(|i| {
        ml.iter()
            .zip(&pa)
            .filter(|(m, p)| (p[i] - m[i]).abs() <= 0.01 * ml_sigma[i])
            .count() as f64
            / runs as f64
    });
    (
        [0, 1, 2].map(|i| crlb[(i, i)].sqrt()),
        ml_sigma,
        pa_sigma,
        within,
    )
}

fn assert_example_1(miss: f64, order: usize) {
    let (crlb, ml, pa, within) = example_1(miss, order);
    for i in 0..3 {
        assert!(within[i] >= 0.95, "θ{i}: {} of runs within 1 %", within[i]);
        assert!(
            (pa[i] / ml[i] - 1.0).abs() <= 0.10,
            "θ{i}: PAML σ {} ML σ {}",
            pa[i],
            ml[i]
        );
        assert!(
            (ml[i] / crlb[i] - 1.0).abs() <= 0.10,
            "θ{i}: ML σ {} CRLB {}",
            ml[i],
            crlb[i]
        );
        assert!(
            (pa[i] / crlb[i] - 1.0).abs() <= 0.10,
            "θ{i}: PAML σ {} CRLB {}",
            pa[i],
            crlb[i]
        );
    }
}

#[test]
fn example_1_paml_is_ml_at_order_11_with_a_1_m_miss() {
    assert_example_1(1.0, 11);
}

#[test]
fn example_1_paml_is_ml_at_order_8_with_a_2_m_miss() {
    assert_example_1(2.0, 8);
}

#[test]
fn example_1_at_the_papers_order_5_paml_is_not_ml() {
    // The paper's n = 5 does not approximate eq. 38's gradient over the whole 4.8 ms well
    // enough for must-show 3: PAML's σ is 40 % above ML's at a 1 m miss and the estimates
    // agree to 1 % of σ in almost no run (ACCURACY.md, "PAML on Example 1"). This pins that
    // measurement: were it to pass, the documented limit would be wrong.
    let (_, ml, pa, within) = example_1(1.0, 5);
    assert!(pa[0] / ml[0] > 1.2, "PAML σ {} ML σ {}", pa[0], ml[0]);
    assert!(within.iter().all(|&w| w < 0.1), "{within:?}");
}

#[test]
fn example_3_compression_is_57_to_1() {
    // Three TDOA streams, 11-bit samples every 2 ms, cut into 2 s segments sent as n+1 = 6
    // polynomial samples of 32 bits each (V&O §VI-C): the channel load falls 57.3-fold. The
    // segments are cut from a simulated stream by the library, and each keeps its
    // information: the samples' variances sum to the raw samples' information.
    let step = 0.002;
    let segment = 2.0;
    let n = 5;
    let sigma = 0.3e-9; // 0.3 ns of TDOA noise
    let mut rng = StdRng::seed_from_u64(9);
    let (mut raw_bits, mut paml_bits) = (0usize, 0usize);
    for stream in 0..3 {
        let total = (200.0 / step) as usize; // 200 s, as Table III's runs
        let t: Vec<f64> = (0..total).map(|k| k as f64 * step).collect();
        let y: Vec<f64> = t
            .iter()
            .map(|t| {
                1e-8 * (0.05 * t + stream as f64).sin()
                    + sigma * rng.sample::<f64, _>(StandardNormal)
            })
            .collect();
        let per = (segment / step).round() as usize;
        for (ts, ys) in t.chunks(per).zip(y.chunks(per)) {
            let ps = PolynomialSamples::from_segment(ts, ys, &vec![sigma; ts.len()], n).unwrap();
            raw_bits += 11 * ts.len();
            paml_bits += 32 * ps.values.len();
            let information: f64 = ps.variances.iter().map(|v| 1.0 / v).sum();
            let raw_information = ts.len() as f64 / (sigma * sigma);
            assert!((information / raw_information - 1.0).abs() < 1e-9);
        }
    }
    let ratio = raw_bits as f64 / paml_bits as f64;
    assert!((ratio - 57.29).abs() < 0.01, "ratio {ratio}");
    // and in bits a second: 16.5 kb/s raw, 288 b/s sent
    assert_eq!(raw_bits / 200, 16_500);
    assert_eq!(paml_bits / 200, 288);
}

#[test]
fn where_the_samples_hardly_determine_the_parameters_a_fit_is_close_to_its_minimum_or_refused() {
    // Example 1's first 2.4 ms: the Cramér–Rao σ of x₀ is 28 m for x₀ = 10 m. Over 300 runs
    // every fit either stops within 1e-3 σ of its minimum, with finite σ, or is refused by
    // name; about half are refused.
    let sc = Scenario::new(1.0, SAMPLES).first(600);
    let mut rng = StdRng::seed_from_u64(1);
    let (mut fitted, mut refused) = (0, 0);
    for _ in 0..300 {
        let y = sc.measure(&mut rng);
        let start = prior(&sc.truth, &mut rng);
        match fit_curve(&Doppler, &sc.times, &y, &sc.sigmas, &start) {
            Ok(fit) => {
                assert!(fit.correction <= 1e-3, "correction {:e}", fit.correction);
                assert!(fit.covariance.iter().all(|v| v.is_finite()));
                assert!(fit.parameters.iter().all(|v| v.is_finite()));
                fitted += 1;
            }
            Err(
                seqsmooth::Error::FitNotConverged { .. } | seqsmooth::Error::Unobservable { .. },
            ) => refused += 1,
            Err(e) => panic!("{e}"),
        }
    }
    assert!(
        fitted > 50 && refused > 50,
        "{fitted} fitted, {refused} refused"
    );
}
