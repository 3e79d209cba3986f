//! The maximum-likelihood curve fit (`estimate::curve`) against independent oracles: scipy's
//! `least_squares` (MINPACK) on a stored fixture (tests/fixtures/curve/, made by
//! scripts/make_curve_fixtures.py), a direct weighted QR solve for a model linear in its
//! parameters, and a Monte Carlo check of the Cramér–Rao bound; and its refusals.

use nalgebra::{DMatrix, DVector};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use seqsmooth::error::Param;
use seqsmooth::estimate::curve::{cramer_rao_bound, fit_curve, Curve, CurveModel};
use seqsmooth::Error;

/// A test model `h = a e^{b t} + c t` (not in Villien & Ostertag: their examples are eqs. 38,
/// 41 and 43-44).
fn demo(analytic: bool) -> Curve {
    let h = Curve::new(3, |th: &[f64], t| th[0] * (th[1] * t).exp() + th[2] * t);
    if analytic {
        h.with_gradient(|th: &[f64], t, g: &mut [f64]| {
            let e = (th[1] * t).exp();
            g.copy_from_slice(&[e, th[0] * t * e, t]);
        })
    } else {
        h
    }
}

fn fixture(name: &str) -> Vec<Vec<String>> {
    let path = format!("{}/tests/fixtures/curve/{name}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{path}: {e}"))
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

#[test]
fn equals_scipy_least_squares_on_the_demonstration_model() {
    let rows = fixture("demo.csv");
    let col = |c: usize| -> Vec<f64> { rows.iter().map(|r| r[c].parse().unwrap()).collect() };
    let (t, y, s) = (col(0), col(1), col(2));
    let expected: std::collections::HashMap<String, f64> = fixture("fit.csv")
        .into_iter()
        .map(|r| (r[0].clone(), r[1].parse().unwrap()))
        .collect();
    let theta = [0, 1, 2].map(|i| expected[&format!("theta{i}")]);
    let cov = DMatrix::from_fn(3, 3, |i, k| expected[&format!("cov{i}{k}")]);
    // (analytic Jacobian, bound on |Δθ|/σ, on the covariance's relative error); with the
    // differenced Jacobian the stationary point moves by its O(ε^{2/3}) error: 1.5e-7 σ measured.
    for (analytic, theta_tol, cov_tol) in [(true, 1e-9, 1e-9), (false, 1e-6, 1e-6)] {
        let fit = fit_curve(&demo(analytic), &t, &y, &s, &[0.5, 0.0, 0.0]).unwrap();
        for i in 0..3 {
            let err = (fit.parameters[i] - theta[i]).abs() / cov[(i, i)].sqrt();
            assert!(
                err <= theta_tol,
                "analytic {analytic}: θ{i} off by {err:e} σ"
            );
        }
        let rel = (&fit.covariance - &cov).amax() / cov.amax();
        assert!(
            rel <= cov_tol,
            "analytic {analytic}: covariance off by {rel:e}"
        );
        let chi = (fit.chi_squared / expected["chi_squared"] - 1.0).abs();
        assert!(chi <= 1e-12, "chi-squared off by {chi:e}");
        assert_eq!(fit.degrees_of_freedom, 1997);
        assert!(fit.correction <= 1e-9, "correction {:e}", fit.correction);
        assert!(fit.evaluations > 1);
    }
}

#[test]
fn a_model_linear_in_its_parameters_is_the_weighted_qr_solution() {
    // h = θ₀ + θ₁ sin 3t + θ₂ e^{−t} on irregular times with tenfold-varying noise.
    let mut rng = StdRng::seed_from_u64(7);
    let mut t: Vec<f64> = (0..300).map(|_| rng.gen_range(0.0..4.0)).collect();
    t.sort_by(f64::total_cmp);
    let basis = |t: f64| [1.0, (3.0 * t).sin(), (-t).exp()];
    let truth = [2.0, -0.7, 5.0];
    let s: Vec<f64> = t.iter().map(|t| 0.1 + 0.25 * t).collect();
    let y: Vec<f64> = t
        .iter()
        .zip(&s)
        .map(|(&t, s)| {
            let b = basis(t);
            (0..3).map(|i| b[i] * truth[i]).sum::<f64>() + s * rng.sample::<f64, _>(StandardNormal)
        })
        .collect();
    let a = DMatrix::from_fn(t.len(), 3, |k, i| basis(t[k])[i] / s[k]);
    let b = DVector::from_iterator(t.len(), y.iter().zip(&s).map(|(y, s)| y / s));
    let qr = a.clone().qr();
    let r = qr.r();
    let x = r
        .solve_upper_triangular(&(qr.q().transpose() * &b))
        .unwrap();
    let r_inv = r.solve_upper_triangular(&DMatrix::identity(3, 3)).unwrap();
    let cov = &r_inv * r_inv.transpose();
    let model = Curve::new(3, move |th: &[f64], t| {
        let b = basis(t);
        th[0] * b[0] + th[1] * b[1] + th[2] * b[2]
    });
    let fit = fit_curve(&model, &t, &y, &s, &[0.0; 3]).unwrap();
    for i in 0..3 {
        let err = (fit.parameters[i] - x[i]).abs() / cov[(i, i)].sqrt();
        assert!(err <= 1e-9, "θ{i} off by {err:e} σ");
    }
    assert!((&fit.covariance - &cov).amax() <= 1e-8 * cov.amax());
    let bound = cramer_rao_bound(&model, &truth, &t, &s).unwrap();
    assert!((&bound - &cov).amax() <= 1e-8 * cov.amax());
}

#[test]
fn the_spread_of_the_estimates_is_the_cramer_rao_bound() {
    // 2,000 fits of 200 samples: each variance's relative error has σ = sqrt(2/1999) = 0.032,
    // each mean's σ is σ_θ/sqrt(2000); the bounds are four of those σ.
    let runs = 2000;
    let t: Vec<f64> = (0..200).map(|k| k as f64 / 100.0).collect();
    let s: Vec<f64> = t.iter().map(|t| 0.05 * (1.0 + t)).collect();
    let truth = [1.0, 0.8, -0.5];
    let model = demo(true);
    let bound = cramer_rao_bound(&model, &truth, &t, &s).unwrap();
    let mut rng = StdRng::seed_from_u64(11);
    let mut sum = [0.0; 3];
    let mut sq = [0.0; 3];
    for _ in 0..runs {
        let y: Vec<f64> = t
            .iter()
            .zip(&s)
            .map(|(&t, s)| (0.8 * t).exp() - 0.5 * t + s * rng.sample::<f64, _>(StandardNormal))
            .collect();
        let fit = fit_curve(&model, &t, &y, &s, &[0.5, 0.0, 0.0]).unwrap();
        for i in 0..3 {
            let e = fit.parameters[i] - truth[i];
            sum[i] += e;
            sq[i] += e * e;
        }
    }
    let n = runs as f64;
    for i in 0..3 {
        let sigma = bound[(i, i)].sqrt();
        let mean = sum[i] / n;
        assert!(
            mean.abs() <= 4.0 * sigma / n.sqrt(),
            "θ{i} biased: {mean:e}"
        );
        let ratio = (sq[i] / n) / bound[(i, i)];
        assert!(
            (ratio - 1.0).abs() <= 4.0 * (2.0 / (n - 1.0)).sqrt(),
            "θ{i}: variance {ratio} of the bound"
        );
    }
}

#[test]
fn bad_input_is_refused_by_name() {
    let model = demo(true);
    let t = [0.0, 0.5, 1.0, 1.5];
    let y = [1.0, 1.3, 1.7, 2.5];
    let s = [0.1; 4];
    let start = [1.0, 0.5, 0.0];
    let lengths = fit_curve(&model, &t, &y[..3], &s, &start);
    assert!(matches!(
        lengths,
        Err(Error::InvalidParameter {
            name: Param::InputLengths,
            ..
        })
    ));
    let sigma = fit_curve(&model, &t, &y, &[0.1, 0.0, 0.1, 0.1], &start);
    assert!(matches!(
        sigma,
        Err(Error::InvalidParameter {
            name: Param::Sigmas,
            ..
        })
    ));
    let nan = fit_curve(&model, &t, &[1.0, f64::NAN, 1.0, 1.0], &s, &start);
    assert!(matches!(nan, Err(Error::NonFinite { what: "value", .. })));
    let time = fit_curve(&model, &[0.0, f64::INFINITY, 1.0, 2.0], &y, &s, &start);
    assert!(matches!(time, Err(Error::NonFinite { what: "time", .. })));
    let few = fit_curve(&model, &t[..2], &y[..2], &s[..2], &start);
    assert!(matches!(
        few,
        Err(Error::TooFewSamples { needed: 3, got: 2 })
    ));
    let start_len = fit_curve(&model, &t, &y, &s, &[1.0, 0.5]);
    assert!(matches!(
        start_len,
        Err(Error::InvalidParameter {
            name: Param::Parameters,
            ..
        })
    ));
    let start_nan = fit_curve(&model, &t, &y, &s, &[1.0, f64::NAN, 0.0]);
    assert!(matches!(
        start_nan,
        Err(Error::NonFinite {
            what: "parameter",
            ..
        })
    ));
    // a model that overflows on the way
    let blows_up = Curve::new(1, |th: &[f64], t| (th[0] * t * 1e3).exp());
    let r = fit_curve(&blows_up, &t, &y, &s, &[1.0]);
    assert!(
        matches!(
            r,
            Err(Error::NonFinite {
                what: "model value",
                ..
            })
        ),
        "{r:?}"
    );
    // a model that gives the wrong number of values
    struct Short;
    impl CurveModel for Short {
        fn parameters(&self) -> usize {
            1
        }
        fn values(&self, th: &[f64], times: &[f64]) -> Result<Vec<f64>, Error> {
            Ok(vec![th[0]; times.len() - 1])
        }
    }
    let r = fit_curve(&Short, &t, &y, &s, &[1.0]);
    assert!(
        matches!(
            r,
            Err(Error::InvalidParameter {
                name: Param::Model,
                ..
            })
        ),
        "{r:?}"
    );
    // parameters the data cannot separate
    let twins = Curve::new(2, |th: &[f64], t| th[0] + th[1] + t);
    let r = fit_curve(&twins, &t, &y, &s, &[0.0, 0.0]);
    assert!(
        matches!(
            r,
            Err(Error::Unobservable {
                rank: 1,
                states: 2,
                ..
            })
        ),
        "{r:?}"
    );
    // away from zero the differenced columns differ by their rounding (~1e-11), which the
    // QR's rank rule alone would take for a second direction
    let t20: Vec<f64> = (0..20).map(|k| k as f64 * 2.0 / 19.0).collect();
    let y20: Vec<f64> = t20.iter().map(|t| (0.8 * t).exp()).collect();
    let r = fit_curve(&twins, &t20, &y20, &[0.05; 20], &[0.0, 0.0]);
    assert!(
        matches!(
            r,
            Err(Error::Unobservable {
                rank: 1,
                states: 2,
                ..
            })
        ),
        "{r:?}"
    );
    let r = cramer_rao_bound(&twins, &[0.0, 0.0], &t, &s);
    assert!(matches!(r, Err(Error::Unobservable { .. })), "{r:?}");
    // a model's own error comes back as it is
    struct Refuses;
    impl CurveModel for Refuses {
        fn parameters(&self) -> usize {
            1
        }
        fn values(&self, _th: &[f64], _times: &[f64]) -> Result<Vec<f64>, Error> {
            Err(Error::InvalidParameter {
                name: Param::Model,
                value: "refused".into(),
                reason: "test".into(),
            })
        }
    }
    let r = fit_curve(&Refuses, &t, &y, &s, &[1.0]);
    assert!(
        matches!(&r, Err(Error::InvalidParameter { value, .. }) if value == "refused"),
        "{r:?}"
    );
}

#[test]
fn the_fit_does_not_depend_on_the_time_origin() {
    // The model written about its own epoch: the same data at Unix-epoch times.
    let epoch = 1.7e9;
    let t: Vec<f64> = (0..400).map(|k| k as f64 * 0.01).collect();
    let s = vec![0.05; 400];
    let mut rng = StdRng::seed_from_u64(3);
    let y: Vec<f64> = t
        .iter()
        .map(|&t| (0.8 * t).exp() - 0.5 * t + 0.05 * rng.sample::<f64, _>(StandardNormal))
        .collect();
    let near = fit_curve(&demo(true), &t, &y, &s, &[0.5, 0.0, 0.0]).unwrap();
    let shifted: Vec<f64> = t.iter().map(|t| t + epoch).collect();
    let far_model = Curve::new(3, move |th: &[f64], t| {
        let u = t - epoch;
        th[0] * (th[1] * u).exp() + th[2] * u
    });
    let far = fit_curve(&far_model, &shifted, &y, &s, &[0.5, 0.0, 0.0]).unwrap();
    // ulp(1.7e9) = 2.4e-7 of time: the shift rounds each time by up to 1.2e-7
    for i in 0..3 {
        let sigma = near.covariance[(i, i)].sqrt();
        let err = (far.parameters[i] - near.parameters[i]).abs() / sigma;
        assert!(err <= 1e-4, "θ{i} moved {err:e} σ");
    }
}
