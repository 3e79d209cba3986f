//! `seqsmooth::stats::consistency`: NEES against exact rationals and closed forms, the interval
//! of the mean against printed χ² tables, the closed-form CDF of even degrees of freedom and
//! Wilson–Hilferty, its narrowing with the run count; Monte Carlo: the mean NEES of N(0, S)
//! errors inside its 99% interval and the false-rejection rate of that test near 1%, the test's
//! power against a mis-scaled covariance, NEES and NIS of a Kalman filter with missing
//! components; the refusals.

mod common;

use common::rational::{f, fr, inv, z, Q};
use common::stats::Z;
use nalgebra::{DMatrix, DVector};
use num_traits::Zero;
use rand::rngs::StdRng;
use rand::Rng;
use rand_distr::{Distribution, Normal};
use seqsmooth::kalman::noise::{ProcessNoise, WhiteNoiseDerivative};
use seqsmooth::kalman::KalmanFilter;
use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
use seqsmooth::model::measurement::Measurement;
use seqsmooth::model::measurement::NoiseCovariance;
use seqsmooth::model::observation::LinearObservation;
use seqsmooth::stats::consistency::{mean_interval, nees, ConsistencyTest};
use seqsmooth::stats::normal_quantile;
use seqsmooth::Error;

fn v(xs: &[f64]) -> DVector<f64> {
    DVector::from_column_slice(xs)
}

/// `eᵀ S⁻¹ e` in exact rationals.
fn nees_exact(s: &DMatrix<Q>, e: &[Q]) -> Q {
    let si = inv(s);
    let n = e.len();
    let mut acc = Q::zero();
    for i in 0..n {
        for j in 0..n {
            acc += e[i].clone() * si[(i, j)].clone() * e[j].clone();
        }
    }
    acc
}

/// NEES against exact rational arithmetic: `S = A Aᵀ + D` for small integer `A` and rational
/// errors, dimensions 1 to 5; the error is `estimate − truth` with both offset.
#[test]
fn nees_matches_exact_rationals() {
    let mut worst = 0.0f64;
    for n in 1..=5usize {
        let a = DMatrix::from_fn(n, n, |i, j| z(((3 * i + 5 * j + 1) % 7) as i64 - 3));
        let mut s = DMatrix::from_fn(n, n, |i, j| {
            (0..n).fold(Q::zero(), |acc, k| {
                acc + a[(i, k)].clone() * a[(j, k)].clone()
            })
        });
        for i in 0..n {
            s[(i, i)] += fr(1 + i as i64, 2);
        }
        let e: Vec<Q> = (0..n)
            .map(|i| fr((2 * i as i64 + 1) * if i % 2 == 0 { 1 } else { -1 }, 8))
            .collect();
        let want = f(&nees_exact(&s, &e));
        let truth = DVector::from_fn(n, |i, _| 100.0 + i as f64);
        let estimate = DVector::from_fn(n, |i, _| truth[i] + f(&e[i]));
        let got = nees(&estimate, &s.map(|q| f(&q)), &truth).unwrap();
        let rel = (got - want).abs() / want;
        worst = worst.max(rel);
        assert!(rel < 1e-12, "n {n}: {got} against exact {want} ({rel:e})");
    }
    println!("NEES against exact rationals, n = 1..5: worst relative difference {worst:e}");
}

/// Closed forms: a diagonal `S` over 16 orders of magnitude (`Σ e_i²/s_i`), a 2×2 correlation
/// near 1 (`(a² − 2ρab + b²)/(1 − ρ²)`), and the invariance of NEES under a change of units
/// `S → D S D`, `e → D e`.
#[test]
fn nees_closed_forms_and_units() {
    let s = [1e-8, 3.0, 0.25, 7e7];
    let e = [2e-4, -1.5, 0.125, 3e4];
    let want: f64 = s.iter().zip(&e).map(|(s, e)| e * e / s).sum();
    let got = nees(&v(&e), &DMatrix::from_diagonal(&v(&s)), &DVector::zeros(4)).unwrap();
    assert!(
        (got - want).abs() <= 4.0 * f64::EPSILON * want,
        "{got} vs {want}"
    );

    for rho in [0.5, -0.9, 0.999, 1.0 - 1e-6] {
        let (a, b) = (0.75, -0.5);
        let want = (a * a - 2.0 * rho * a * b + b * b) / (1.0 - rho * rho);
        let s = DMatrix::from_row_slice(2, 2, &[1.0, rho, rho, 1.0]);
        let got = nees(&v(&[a, b]), &s, &DVector::zeros(2)).unwrap();
        // the conditioning is 2/(1 − ρ): allow that many ulps and a little more
        let tol = 8.0 * f64::EPSILON / (1.0 - rho.abs());
        assert!((got - want).abs() <= tol * want, "ρ {rho}: {got} vs {want}");
    }

    let s = DMatrix::from_row_slice(3, 3, &[4.0, 1.0, -0.5, 1.0, 2.0, 0.3, -0.5, 0.3, 1.0]);
    let e = v(&[0.3, -1.1, 0.7]);
    let base = nees(&e, &s, &DVector::zeros(3)).unwrap();
    let d = DMatrix::from_diagonal(&v(&[1e6, 1.0, 1e-6]));
    let scaled = nees(&(&d * &e), &(&d * &s * &d), &DVector::zeros(3)).unwrap();
    assert!((scaled - base).abs() <= 1e-14 * base, "{scaled} vs {base}");
    // the two triangles are averaged: a rounding-level asymmetry is accepted
    let mut t = s.clone();
    t[(0, 1)] *= 1.0 + 1e-13;
    assert!((nees(&e, &t, &DVector::zeros(3)).unwrap() - base).abs() <= 1e-12 * base);
}

/// The Poisson form of the χ² CDF of even degrees of freedom `2k`:
/// `P(χ²_{2k} ≤ x) = P(Poisson(x/2) ≥ k)`, summed in logarithms from the side of the small tail.
fn even_chi_squared_tails(k: usize, x: f64) -> (f64, f64) {
    let lambda = 0.5 * x;
    let term = |j: usize| {
        let ln_fact: f64 = (1..=j).map(|i| (i as f64).ln()).sum();
        (-lambda + j as f64 * lambda.ln() - ln_fact).exp()
    };
    let upper: f64 = (0..k).map(term).sum(); // P(χ² > x)
    let mut lower = 0.0; // P(χ² ≤ x)
    let mut j = k;
    loop {
        let t = term(j);
        lower += t;
        if t < 1e-20 * lower && j as f64 > lambda {
            break;
        }
        j += 1;
    }
    (lower, upper)
}

/// The interval against printed tables (3-4 digits), `χ²_1` against the normal quantile
/// (`χ²_1(p) = Φ⁻¹((1+p)/2)²`), even totals against the Poisson form of the CDF (1e-10), and
/// large totals against Wilson–Hilferty.
#[test]
fn mean_interval_against_tables_and_closed_forms() {
    // (dof per run, runs, printed 0.005 and 0.995 points of χ²(dof·runs))
    let table = [
        (1, 1, 3.927e-5, 7.879),
        (10, 1, 2.156, 25.188),
        (1, 10, 2.156, 25.188),
        (3, 10, 13.787, 53.672),
        (5, 4, 7.434, 39.997),
        (10, 10, 67.328, 140.169),
    ];
    for (dof, runs, lo_t, hi_t) in table {
        let (lo, hi) = mean_interval(dof, runs, 0.99).unwrap();
        let r = runs as f64;
        assert!(
            (lo * r - lo_t).abs() <= 6e-4 * lo_t && (hi * r - hi_t).abs() <= 6e-4 * hi_t,
            "dof {dof} runs {runs}: [{}, {}] against the table's [{lo_t}, {hi_t}]",
            lo * r,
            hi * r
        );
    }

    for c in [0.5, 0.9, 0.95, 0.99, 0.999] {
        let (lo, hi) = mean_interval(1, 1, c).unwrap();
        let qlo = normal_quantile(0.5 + 0.25 * (1.0 - c)).unwrap().powi(2);
        let qhi = normal_quantile(0.5 + 0.25 * (1.0 + c)).unwrap().powi(2);
        assert!((lo - qlo).abs() <= 1e-9 * qlo, "c {c}: {lo} vs {qlo}");
        assert!((hi - qhi).abs() <= 1e-12 * qhi, "c {c}: {hi} vs {qhi}");
    }

    let mut worst = 0.0f64;
    for (dof, runs) in [(2, 1), (1, 2), (2, 5), (4, 10), (6, 20), (3, 100)] {
        for c in [0.9, 0.99] {
            let (lo, hi) = mean_interval(dof, runs, c).unwrap();
            let k = dof * runs / 2;
            let tail = 0.5 * (1.0 - c);
            let (below, _) = even_chi_squared_tails(k, lo * runs as f64);
            let (_, above) = even_chi_squared_tails(k, hi * runs as f64);
            for got in [below, above] {
                let rel = (got - tail).abs() / tail;
                worst = worst.max(rel);
                assert!(
                    rel < 1e-10,
                    "dof {dof} runs {runs} c {c}: tail {got} vs {tail}"
                );
            }
        }
    }
    println!("tails at the interval's ends against the Poisson form: worst relative {worst:e}");

    for (dof, runs) in [(4, 2000), (6, 10_000), (1, 100_000)] {
        let k = (dof * runs) as f64;
        let wh = |p: f64| {
            let c = 2.0 / (9.0 * k);
            k * (1.0 - c + normal_quantile(p).unwrap() * c.sqrt()).powi(3) / runs as f64
        };
        let (lo, hi) = mean_interval(dof, runs, 0.99).unwrap();
        for (got, approx) in [(lo, wh(0.005)), (hi, wh(0.995))] {
            assert!(
                (got - approx).abs() <= 1e-5 * approx,
                "dof {dof} runs {runs}: {got} vs Wilson–Hilferty {approx}"
            );
        }
    }
}

/// With more runs the interval narrows around `dof` (its lower end rises, its upper end falls),
/// and its width approaches the normal `2 z √(2 dof / N)`.
#[test]
fn mean_interval_narrows_with_runs() {
    for dof in [1usize, 2, 3, 6] {
        let mut last = (0.0, f64::INFINITY);
        let runs: Vec<usize> = (1..=100)
            .chain([300, 1000, 3000, 10_000, 100_000])
            .collect();
        for &n in &runs {
            let (lo, hi) = mean_interval(dof, n, 0.99).unwrap();
            assert!(
                lo > last.0 && hi < last.1,
                "dof {dof} runs {n}: [{lo}, {hi}] after {last:?}"
            );
            assert!(lo < dof as f64 && (dof as f64) < hi);
            last = (lo, hi);
        }
        let n = 100_000.0;
        let normal = 2.0 * normal_quantile(0.995).unwrap() * (2.0 * dof as f64 / n).sqrt();
        let width = last.1 - last.0;
        assert!(
            (width - normal).abs() < 1e-3 * normal,
            "dof {dof}: {width} vs {normal}"
        );
    }
    // a higher confidence, a wider interval
    let (a, b) = mean_interval(3, 50, 0.9).unwrap();
    let (c, d) = mean_interval(3, 50, 0.999).unwrap();
    assert!(c < a && b < d);
}

/// A random symmetric positive definite `n × n` matrix `A Aᵀ + I/2`.
fn random_spd(r: &mut StdRng, n: usize) -> DMatrix<f64> {
    let a = DMatrix::from_fn(n, n, |_, _| common::stats::gauss(r));
    &a * a.transpose() + DMatrix::identity(n, n) * 0.5
}

/// Mean NEES of `runs` errors drawn from `N(0, actual)` and judged against `reported`.
fn mean_nees_test(
    r: &mut StdRng,
    actual_factor: &DMatrix<f64>,
    reported: &DMatrix<f64>,
    truth: &DVector<f64>,
    runs: usize,
) -> ConsistencyTest {
    let n = truth.len();
    let mut test = ConsistencyTest::new(n).unwrap();
    for _ in 0..runs {
        let w = DVector::from_fn(n, |_, _| common::stats::gauss(r));
        let estimate = truth + actual_factor * w;
        test.push(nees(&estimate, reported, truth).unwrap())
            .unwrap();
    }
    test
}

/// NEES of errors drawn from `N(0, S)` for a random 4×4 SPD `S`: the mean of 2,000 lies in its
/// 99% interval; over 5,000 such tests the false-rejection rate is near 1% (0.5% in each tail)
/// within 4.5 binomial standard errors; a covariance reported 1.25 times too small or too large
/// is rejected.
#[test]
fn monte_carlo_nees_is_chi_squared() {
    let mut r = common::rng(20260415);
    let n = 4;
    let s = random_spd(&mut r, n);
    let l = s.clone().cholesky().unwrap().l();
    let truth = DVector::from_fn(n, |i, _| 10.0 * (i as f64 + 1.0));
    let (runs, confidence) = (2000, 0.99);

    let one = mean_nees_test(&mut r, &l, &s, &truth, runs);
    let (lo, hi) = mean_interval(n, runs, confidence).unwrap();
    let mean = one.mean().unwrap();
    assert_eq!(one.interval(confidence).unwrap(), (lo, hi));
    assert!(one.contains(confidence).unwrap());
    assert!(
        lo <= mean && mean <= hi,
        "mean NEES {mean} outside [{lo}, {hi}]"
    );
    println!("mean NEES of {runs} runs, n = {n}: {mean:.4} in [{lo:.4}, {hi:.4}]");

    let repetitions = 5000;
    let (mut below, mut above) = (0usize, 0usize);
    for _ in 0..repetitions {
        let m = mean_nees_test(&mut r, &l, &s, &truth, runs).mean().unwrap();
        below += usize::from(m < lo);
        above += usize::from(m > hi);
    }
    let rate = |k: usize| k as f64 / repetitions as f64;
    let se = |p: f64| (p * (1.0 - p) / repetitions as f64).sqrt();
    let alpha = 1.0 - confidence;
    println!(
        "false rejections over {repetitions} tests: {:.4} (below {:.4}, above {:.4}); \
         expected {alpha:.4} ± {:.4}",
        rate(below + above),
        rate(below),
        rate(above),
        se(alpha)
    );
    assert!((rate(below + above) - alpha).abs() <= Z * se(alpha));
    for k in [below, above] {
        assert!((rate(k) - alpha / 2.0).abs() <= Z * se(alpha / 2.0));
    }

    // power: errors 1.25 times the reported covariance (over-confident), and 1/1.25 of it
    for (factor, high) in [(1.25f64, true), (0.8, false)] {
        let t = mean_nees_test(&mut r, &(&l * factor.sqrt()), &s, &truth, runs);
        let m = t.mean().unwrap();
        assert!(!t.contains(confidence).unwrap(), "factor {factor}: {m}");
        assert_eq!(m > hi, high, "factor {factor}: {m}");
    }
}

/// NEES and NIS of a constant-velocity Kalman filter in two axes with driving noise and a prior
/// drawn from its own covariance, 1,000 independent runs of 20 updates, each measured component
/// missing with probability 0.3: the end-of-run NEES (χ²(4)) and every update's NIS (χ² of the
/// components used, by `push_with_dof`) have means inside their 99% intervals.
#[test]
fn kalman_filter_nees_and_nis_with_missing_components() {
    let mut r = common::rng(12);
    let unit = Normal::new(0.0, 1.0).unwrap();
    let dynamics = PolynomialDynamics::new(1, 2);
    let noise = WhiteNoiseDerivative::new(1, 2, 0.05).unwrap();
    let m = DMatrix::from_row_slice(2, 4, &[1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0]);
    let p0 = DMatrix::from_diagonal(&v(&[4.0, 4.0, 1.0, 1.0]));
    let p0_factor = p0.clone().cholesky().unwrap().l();
    let sigma = 0.7;
    let mut nees_test = ConsistencyTest::new(4).unwrap();
    let mut nis_test = ConsistencyTest::new(2).unwrap();
    let mut partial = 0;
    for _ in 0..1000 {
        let mut truth = v(&[0.0, 0.0, 1.0, -1.0]);
        let prior = &truth + &p0_factor * DVector::from_fn(4, |_, _| unit.sample(&mut r));
        let mut filter = KalmanFilter::new(
            dynamics,
            LinearObservation::new(m.clone()).unwrap(),
            prior,
            p0.clone(),
            0.0,
        )
        .unwrap()
        .with_process_noise(noise)
        .unwrap();
        let mut t = 0.0;
        for _ in 0..20 {
            let dt = r.gen_range(0.3..1.7);
            let qc = noise.covariance(t, t + dt).unwrap().cholesky().unwrap().l();
            let w = DVector::from_fn(4, |_, _| unit.sample(&mut r));
            truth = dynamics.propagate(&truth, t, t + dt).unwrap().state + qc * w;
            t += dt;
            let values: Vec<Option<f64>> = (0..2)
                .map(|k| {
                    let y = truth[k] + sigma * unit.sample(&mut r);
                    (r.gen::<f64>() >= 0.3).then_some(y)
                })
                .collect();
            let measurement = Measurement {
                time: t,
                values,
                noise: NoiseCovariance::Variances(vec![sigma * sigma; 2]),
            };
            if let Some(i) = filter.update(&measurement).unwrap() {
                partial += usize::from(i.components.len() < 2);
                nis_test.push_with_dof(i.nis, i.components.len()).unwrap();
            }
        }
        nees_test
            .push(nees(filter.state(), filter.covariance(), &truth).unwrap())
            .unwrap();
    }
    assert!(
        partial > 1000,
        "only {partial} updates with a missing component"
    );
    for (what, test) in [("NEES", &nees_test), ("NIS", &nis_test)] {
        let (lo, hi) = test.interval(0.99).unwrap();
        let mean = test.mean().unwrap();
        println!(
            "{what}: {} values, {} dof, mean {mean:.4} in [{lo:.4}, {hi:.4}] (expected {:.4})",
            test.runs(),
            test.total_dof(),
            test.total_dof() as f64 / test.runs() as f64
        );
        assert!(
            test.contains(0.99).unwrap(),
            "{what} mean {mean} outside [{lo}, {hi}]"
        );
    }
}

/// Refusals: shapes, non-finite entries, asymmetric, singular, indefinite or zero covariances,
/// and bad interval arguments; a refused push leaves the test unchanged.
#[test]
fn refusals() {
    let s = DMatrix::from_row_slice(2, 2, &[2.0, 0.5, 0.5, 1.0]);
    let (x, t) = (v(&[1.0, 2.0]), v(&[0.0, 0.0]));
    let invalid = |r: Result<f64, Error>, name: &str| match r {
        Err(Error::InvalidParameter { name: got, .. }) => assert_eq!(got, name),
        other => panic!("expected an invalid {name}, got {other:?}"),
    };
    invalid(nees(&v(&[]), &DMatrix::zeros(0, 0), &v(&[])), "estimate");
    invalid(nees(&x, &s, &v(&[0.0, 0.0, 0.0])), "truth");
    invalid(nees(&x, &DMatrix::identity(3, 3), &t), "covariance");
    invalid(nees(&x, &DMatrix::zeros(2, 3), &t), "covariance");
    for (what, e, c, tr) in [
        ("estimate entry", v(&[f64::NAN, 0.0]), s.clone(), t.clone()),
        (
            "truth entry",
            x.clone(),
            s.clone(),
            v(&[0.0, f64::INFINITY]),
        ),
        (
            "covariance entry",
            x.clone(),
            DMatrix::from_row_slice(2, 2, &[2.0, f64::NAN, 0.5, 1.0]),
            t.clone(),
        ),
    ] {
        assert!(matches!(nees(&e, &c, &tr), Err(Error::NonFinite { what: w, .. }) if w == what));
    }
    for bad in [
        [2.0, 0.5, -0.5, 1.0],        // not symmetric
        [1.0, 1.0, 1.0, 1.0],         // singular
        [1.0, 2.0, 2.0, 1.0],         // indefinite
        [0.0, 0.0, 0.0, 1.0],         // no variance
        [-1.0, 0.0, 0.0, 1.0],        // negative variance
        [1.0, 1.0, 1.0, 1.0 + 1e-17], // singular within rounding
    ] {
        let c = DMatrix::from_row_slice(2, 2, &bad);
        invalid(nees(&x, &c, &t), "covariance");
    }
    let e = nees(
        &x,
        &DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 1.0, 1.0]),
        &t,
    )
    .unwrap_err();
    assert!(e.to_string().contains("component 1"), "{e}");

    assert!(matches!(
        mean_interval(0, 5, 0.9),
        Err(Error::InvalidParameter { .. })
    ));
    assert!(matches!(
        mean_interval(2, 0, 0.9),
        Err(Error::TooFewSamples { .. })
    ));
    for c in [0.0, 1.0, -0.5, 1.5, f64::NAN] {
        assert!(matches!(
            mean_interval(2, 5, c),
            Err(Error::InvalidParameter { .. })
        ));
    }
    assert!(mean_interval(usize::MAX, 2, 0.9).is_err());

    assert!(ConsistencyTest::new(0).is_err());
    let mut test = ConsistencyTest::new(2).unwrap();
    assert_eq!(test.mean(), None);
    assert!(matches!(
        test.interval(0.9),
        Err(Error::TooFewSamples { .. })
    ));
    assert!(test.contains(0.9).is_err());
    test.push(1.0).unwrap();
    let before = test;
    assert!(test.push(f64::NAN).is_err());
    assert!(test.push(-0.1).is_err());
    assert!(test.push_with_dof(1.0, 0).is_err());
    assert_eq!(test, before);
    assert!(test.contains(1.0).is_err());
}
