//! `kalman::bayes` with fading memory, the fading-memory Bayes filter of Morrison (14.4.26)-
//! (14.4.32): against the fading Kalman filter (14.4.34)-(14.4.40) on random problems (the
//! inversion lemma with the old information discounted, (14.4.33)); from no information against
//! the exact fading-memory polynomial filter (ch. 13, the same recursion with the polynomial
//! model: estimate and true covariance); `β = 1` against the plain Bayes filter; and the true
//! covariance against a Monte Carlo of the estimate's error.

use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use seqsmooth::kalman::bayes::MAX_VARIANCE_INFLATION;
use seqsmooth::kalman::{BayesFilter, Discount, KalmanFilter};
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::measurement::Measurement;
use seqsmooth::model::measurement::NoiseCovariance;
use seqsmooth::model::observation::LinearObservation;
use seqsmooth::{DiscountMode, Engine, FadingMemory, PolynomialFilter};

/// `|a − b|` over the larger of `|b|` and `scale`.
fn rel(a: f64, b: f64, scale: f64) -> f64 {
    (a - b).abs() / b.abs().max(scale)
}

/// The worst difference of two estimates and covariances, each entry relative to its σ (the
/// covariance's `(k, j)` to `σ_k σ_j`).
fn worst_difference(
    x: &DVector<f64>,
    s: &DMatrix<f64>,
    x_ref: &DVector<f64>,
    s_ref: &DMatrix<f64>,
) -> f64 {
    let n = x.len();
    let mut worst: f64 = 0.0;
    for k in 0..n {
        let sk = s_ref[(k, k)].sqrt();
        worst = worst.max(rel(x[k], x_ref[k], sk));
        for j in 0..n {
            let sj = s_ref[(j, j)].sqrt();
            worst = worst.max((s[(k, j)] - s_ref[(k, j)]).abs() / (sk * sj));
        }
    }
    worst
}

/// Two axes, both positions observed, with random noise, correlated components and one
/// component in twenty missing: the fading Bayes filter equals the fading Kalman filter from the
/// same prior, time- and count-based, degrees 0-3, ≤ 1e-9 σ.
#[test]
fn fading_bayes_equals_fading_kalman() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(1404);
    let mut worst: f64 = 0.0;
    for m in 0..=3 {
        for discount in [
            Discount::PerTime(0.7),
            Discount::PerTime(0.95),
            Discount::PerUpdate(0.8),
        ] {
            let n = 2 * (m + 1);
            let dynamics = PolynomialDynamics::new(m, 2);
            let observe = LinearObservation::new(DMatrix::from_fn(2, n, |i, j| {
                if j == i * (m + 1) {
                    1.0
                } else {
                    0.0
                }
            }))
            .unwrap();
            let x0 = DVector::from_fn(n, |_, _| rng.gen_range(-1.0..1.0));
            let a = DMatrix::from_fn(n, n, |_, _| rng.gen_range(-1.0..1.0));
            let p0 = &a * a.transpose() + DMatrix::identity(n, n);
            let mut kalman =
                KalmanFilter::new(dynamics, observe.clone(), x0.clone(), p0.clone(), 0.0)
                    .unwrap()
                    .with_fading(discount)
                    .unwrap();
            let mut bayes = BayesFilter::new(dynamics, observe, 0.0)
                .unwrap()
                .with_prior(&x0, &p0)
                .unwrap()
                .with_fading(discount)
                .unwrap();
            let mut t: f64 = 0.0;
            for _ in 0..40 {
                t += rng.gen_range(0.1..1.5);
                let values: Vec<Option<f64>> = (0..2)
                    .map(|_| (rng.gen_range(0.0..1.0) > 0.05).then(|| rng.gen_range(-5.0..5.0)))
                    .collect();
                let (v0, v1): (f64, f64) = (rng.gen_range(0.5..2.0), rng.gen_range(0.5..2.0));
                let c = 0.6 * (v0 * v1).sqrt();
                let noise = NoiseCovariance::Full(DMatrix::from_row_slice(2, 2, &[v0, c, c, v1]));
                let meas = Measurement {
                    time: t,
                    values,
                    noise,
                };
                kalman.update(&meas).unwrap();
                bayes.update(&meas).unwrap();
                let e = worst_difference(
                    &bayes.estimate().unwrap(),
                    &bayes.covariance().unwrap(),
                    kalman.state(),
                    kalman.covariance(),
                );
                worst = worst.max(e);
                assert!(e <= 1e-9, "m {m} {discount:?} t {t}: {e:e}");
            }
        }
    }
    println!("fading Bayes against fading Kalman: worst {worst:.2e} σ");
}

/// From no information (which the Kalman filter cannot start from), the fading Bayes filter
/// with the polynomial model is the exact fading-memory polynomial filter of ch. 13 run by time
/// (`θ^(Δt/τ)` per step, `β = θ^(1/τ)`): the same estimate and the same true covariance
/// (Table 13.2's VRFs in the limit), degrees 0-8, irregular steps, ≤ 1e-9 σ.
#[test]
fn fading_bayes_is_the_exact_fading_memory_polynomial_filter() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(1313);
    let mut worst: f64 = 0.0;
    for m in 0..=8 {
        let (theta, tau, sigma) = (0.9, 0.5, 0.3);
        let beta = f64::powf(theta, 1.0 / tau);
        let mut poly = FadingMemory::new(m, theta, tau, Engine::Exact)
            .unwrap()
            .with_discount_mode(DiscountMode::PerTime)
            .unwrap()
            .with_noise_sigma(sigma)
            .unwrap();
        let mut bayes = BayesFilter::new(
            PolynomialDynamics::new(m, 1),
            LinearObservation::value_of(m + 1),
            0.0,
        )
        .unwrap()
        .with_fading(Discount::PerTime(beta))
        .unwrap();
        let mut t: f64 = 0.0;
        for k in 0..(4 * m + 60) {
            t += rng.gen_range(0.2..0.8);
            let y = (0.3 * t).sin() * 10.0 + rng.gen_range(-1.0..1.0);
            poly.update(t, y).unwrap();
            bayes
                .update(&Measurement {
                    time: t,
                    values: vec![Some(y)],
                    noise: NoiseCovariance::Variances(vec![sigma * sigma]),
                })
                .unwrap();
            if k < m + 2 {
                continue;
            }
            let est = poly.estimate().unwrap();
            let x_ref = DVector::from_vec(est.derivatives.clone());
            let s_ref = est.covariance.clone().unwrap();
            let e = worst_difference(
                &bayes.estimate().unwrap(),
                &bayes.covariance().unwrap(),
                &x_ref,
                &s_ref,
            );
            worst = worst.max(e);
            assert!(e <= 1e-9, "m {m} k {k}: {e:e}");
        }
    }
    println!("fading Bayes against the exact fading-memory polynomial filter: worst {worst:.2e} σ");
}

/// `β = 1` and `θ = 1` are the plain Bayes filter: the estimate to the last bit (the same
/// rows into the same factor), the covariance (now the sandwich `P P⁻¹ P`) within rounding.
#[test]
fn no_discount_is_the_plain_bayes_filter() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    for discount in [Discount::PerTime(1.0), Discount::PerUpdate(1.0)] {
        let dynamics = PolynomialDynamics::new(2, 1);
        let observe = LinearObservation::value_of(3);
        let mut plain = BayesFilter::new(dynamics, observe.clone(), 0.0).unwrap();
        let mut fading = BayesFilter::new(dynamics, observe, 0.0)
            .unwrap()
            .with_fading(discount)
            .unwrap();
        let mut t: f64 = 0.0;
        for k in 0..50 {
            t += rng.gen_range(0.1..2.0);
            let meas = Measurement {
                time: t,
                values: vec![Some(rng.gen_range(-3.0..3.0))],
                noise: NoiseCovariance::Variances(vec![rng.gen_range(0.5..2.0)]),
            };
            plain.update(&meas).unwrap();
            fading.update(&meas).unwrap();
            if k < 3 {
                continue;
            }
            assert_eq!(plain.estimate(), fading.estimate(), "{discount:?} k {k}");
            let (a, b) = (plain.covariance().unwrap(), fading.covariance().unwrap());
            assert!(
                worst_difference(
                    &plain.estimate().unwrap(),
                    &b,
                    &plain.estimate().unwrap(),
                    &a
                ) <= 1e-11
            );
        }
    }
}

/// The reported true covariance covers the actual error: 4,000 runs of a constant-velocity
/// target observed with σ = 1 at irregular times through a β = 0.6 per unit time fading Bayes
/// filter from no information; the mean of the normalised squared error `eᵀ S*⁻¹ e` over the
/// runs lies inside its 99.9% χ² interval for 2 × 4,000 degrees of freedom, while the filter's
/// own `P` (the information's inverse) is not the covariance (its mean NEES falls well outside).
#[test]
fn true_covariance_covers_the_error() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(99);
    let runs = 4000;
    let (mut nees_true, mut nees_p) = (0.0, 0.0);
    for _ in 0..runs {
        let mut f = BayesFilter::new(
            PolynomialDynamics::new(1, 1),
            LinearObservation::value_of(2),
            0.0,
        )
        .unwrap()
        .with_fading(Discount::PerTime(0.6))
        .unwrap();
        let (x0, v) = (rng.gen_range(-10.0..10.0), rng.gen_range(-2.0..2.0));
        let mut t: f64 = 0.0;
        for _ in 0..25 {
            t += rng.gen_range(0.2..1.0);
            let e: f64 = StandardNormal.sample(&mut rng);
            f.update(&Measurement {
                time: t,
                values: vec![Some(x0 + v * t + e)],
                noise: NoiseCovariance::Identity,
            })
            .unwrap();
        }
        let err = f.estimate().unwrap() - DVector::from_vec(vec![x0 + v * t, v]);
        let s = f.covariance().unwrap();
        let p = f.information_covariance().unwrap();
        nees_true += (err.transpose() * s.try_inverse().unwrap() * &err)[(0, 0)];
        nees_p += (err.transpose() * p.try_inverse().unwrap() * &err)[(0, 0)];
    }
    let dof = 2.0 * runs as f64;
    // χ²(dof)/runs: mean 2, sd √(2·dof)/runs; 99.9% two-sided ≈ ±3.29 sd (dof large).
    let half = 3.29 * (2.0 * dof).sqrt() / runs as f64;
    let (mean_true, mean_p) = (nees_true / runs as f64, nees_p / runs as f64);
    println!("mean NEES with S*: {mean_true:.4}, with P: {mean_p:.4}, interval 2 ± {half:.4}");
    assert!((mean_true - 2.0).abs() <= half, "{mean_true}");
    assert!((mean_p - 2.0).abs() > 10.0 * half, "{mean_p}");
}

/// Ex. 14.9a (`Φ = I₂`, `M = (1, 1)`, `R = 1`, θ = 0.8 per update, prior `I`): the direction
/// `v = (1, −1)/√2` is never observed, so its information fades as `θ^n` and the estimate's
/// rounding error grows with the variance inflation (`θ^{−n}`). Oracle: the scalar recursion of
/// `u = (1, 1)/√2` — information `z_n = θ z_{n−1} + 2` from `z_0 = 1`, estimate
/// `û_n = (θ z_{n−1} û_{n−1} + √2 y_n)/z_n`, true variance `s_n = (θ z_{n−1}/z_n)² s_{n−1} +
/// 2/z_n²` — with `v` at its prior (mean 0, variance 1). While the filter reports an estimate
/// it is within 1e-4 σ of the oracle (its error ≤ 2 ε × the variance inflation; measured 1.1);
/// from the update where the inflation passes `MAX_VARIANCE_INFLATION` on (near n = 110) it
/// reports none (right or refused), up to n = 1,000.
#[test]
fn ex_14_9a_unobserved_direction_is_refused_once_it_has_faded() {
    let theta: f64 = 0.8;
    let mut f = BayesFilter::new(
        PolynomialDynamics::new(0, 2),
        LinearObservation::new(DMatrix::from_row_slice(1, 2, &[1.0, 1.0])).unwrap(),
        0.0,
    )
    .unwrap()
    .with_prior(&DVector::zeros(2), &DMatrix::identity(2, 2))
    .unwrap()
    .with_fading(Discount::PerUpdate(theta))
    .unwrap();
    let (mut z, mut u, mut s_u) = (1.0, 0.0, 1.0);
    let (mut worst, mut worst_ratio): (f64, f64) = (0.0, 0.0);
    let mut refused_from = None;
    for n in 1..=1000 {
        let y = (n as f64).cos() + 3.0;
        let z_old = theta * z;
        z = z_old + 2.0;
        u = (z_old * u + std::f64::consts::SQRT_2 * y) / z;
        s_u = (z_old / z).powi(2) * s_u + 2.0 / (z * z);
        f.update(&Measurement {
            time: n as f64,
            values: vec![Some(y)],
            noise: NoiseCovariance::Identity,
        })
        .unwrap();
        // The oracle's variance inflation: P = diag in (u, v) of 1/z_n and θ^{−n}; P_00 J_00.
        let inflation = (1.0 / z + theta.powi(-n)) / 2.0 * (z + theta.powi(n)) / 2.0;
        let (Some(x), Some(s)) = (f.estimate(), f.covariance()) else {
            refused_from.get_or_insert(n);
            assert!(
                inflation > 0.5 * MAX_VARIANCE_INFLATION,
                "n {n}: refused at inflation {inflation:e}"
            );
            continue;
        };
        assert!(
            refused_from.is_none(),
            "n {n}: reported again after a refusal"
        );
        let r = std::f64::consts::FRAC_1_SQRT_2;
        let want_x = DVector::from_vec(vec![u * r, u * r]);
        let want_s = DMatrix::from_row_slice(
            2,
            2,
            &[
                (s_u + 1.0) / 2.0,
                (s_u - 1.0) / 2.0,
                (s_u - 1.0) / 2.0,
                (s_u + 1.0) / 2.0,
            ],
        );
        let e = worst_difference(&x, &s, &want_x, &want_s);
        worst = worst.max(e);
        worst_ratio = worst_ratio.max(e / (f64::EPSILON * inflation));
        assert!(
            e <= 1e-4,
            "n {n}: {x} {s} against {want_x} {want_s} ({e:e})"
        );
        assert!(
            e <= 2.0 * f64::EPSILON * inflation.max(10.0),
            "n {n}: {e:e} at inflation {inflation:e}"
        );
    }
    let from = refused_from.expect("the faded direction is refused");
    assert!((100..=125).contains(&from), "refused from n = {from}");
    println!(
        "Ex. 14.9a: worst {worst:.2e} σ, {worst_ratio:.2} ε × inflation; refused from n = {from}"
    );
}

/// With no information yet there is nothing to discount: a fading filter started at time 0
/// whose first measurement is at a Unix-epoch time (β^(1.7e9) underflows) gives, bit for bit,
/// the estimates of one started at that measurement's time.
#[test]
fn the_first_update_does_not_discount_nothing() {
    let rows: Vec<Measurement> = (0..20)
        .map(|k| Measurement {
            time: 1.7e9 + f64::from(k) * 0.75,
            values: vec![Some(f64::from(k * k % 7))],
            noise: NoiseCovariance::Variances(vec![0.25]),
        })
        .collect();
    let run = |t0: f64| {
        let mut f = BayesFilter::new(
            PolynomialDynamics::new(2, 1),
            LinearObservation::value_of(3),
            t0,
        )
        .unwrap()
        .with_fading(Discount::PerTime(0.9))
        .unwrap();
        rows.iter()
            .map(|m| {
                f.update(m).unwrap();
                (f.estimate(), f.covariance())
            })
            .collect::<Vec<_>>()
    };
    let (a, b) = (run(0.0), run(1.7e9));
    assert!(a[19].0.is_some());
    assert_eq!(a, b);
}
