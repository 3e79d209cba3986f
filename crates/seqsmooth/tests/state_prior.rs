//! Settable estimates, priors and driving noise: `set_estimate` on the Kalman, unscented and
//! Bayes filters (checked: finite, symmetric, positive semidefinite; refused naming the state
//! or its covariance, the filter unchanged); the expanding- and fading-memory filters started
//! from a prior (Morrison ch. 10's Bayes filter; (14.4.26)-(14.4.32) with fading) against a
//! direct QR solve of the weighted least-squares problem with the prior as pseudo-observations,
//! and a vague prior against no prior; the Bayes filter with driving noise against the Kalman
//! filter with the same `q` (one estimator in two forms, ch. 15).

use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use seqsmooth::error::Param;
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::kalman::{BayesFilter, KalmanFilter, UnscentedKalmanFilter};
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
use seqsmooth::model::observation::LinearObservation;
use seqsmooth::polynomial::prior::Prior;
use seqsmooth::{Engine, Error, ExpandingMemory, FadingMemory, PolynomialFilter};

fn names(e: Result<(), Error>) -> Param {
    match e {
        Err(Error::InvalidParameter { name, .. }) => name,
        other => panic!("expected a parameter error, got {other:?}"),
    }
}

/// A symmetric matrix that is not positive semidefinite, one that is not symmetric, one with
/// a NaN.
fn bad_covariances() -> [DMatrix<f64>; 3] {
    [
        DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]),
        DMatrix::from_row_slice(2, 2, &[1.0, 0.5, 0.0, 1.0]),
        DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, f64::NAN]),
    ]
}

#[test]
fn set_estimate_is_checked_and_refusals_leave_the_filter_unchanged() {
    let (dynamics, obs) = (
        PolynomialDynamics::new(1, 1),
        LinearObservation::value_of(2),
    );
    let x = DVector::from_vec(vec![1.0, 2.0]);
    let p = DMatrix::from_row_slice(2, 2, &[4.0, 1.0, 1.0, 2.0]);
    let mut k = KalmanFilter::new(dynamics, obs.clone(), x.clone(), p.clone(), 0.0).unwrap();
    let mut u =
        UnscentedKalmanFilter::new(dynamics, obs.clone(), x.clone(), p.clone(), 0.0).unwrap();
    let mut b = BayesFilter::new(dynamics, obs, 0.0).unwrap();
    b.set_estimate(&x, &p).unwrap();
    assert!((b.covariance().unwrap() - &p).amax() < 1e-14);
    let y = DVector::from_vec(vec![-3.0, 0.5]);
    k.set_estimate(y.clone(), p.clone() * 2.0, 0.0).unwrap();
    assert_eq!((k.state(), k.covariance()), (&y, &(p.clone() * 2.0)));
    u.set_estimate(y.clone(), p.clone() * 2.0, 0.0).unwrap();
    assert_eq!((u.state(), u.covariance()), (&y, &(p.clone() * 2.0)));
    for bad in bad_covariances() {
        assert_eq!(
            names(k.set_estimate(x.clone(), bad.clone(), 0.0)),
            Param::StateCovarianceP
        );
        assert_eq!(
            names(u.set_estimate(x.clone(), bad.clone(), 0.0)),
            Param::StateCovarianceP
        );
        assert_eq!(names(b.set_estimate(&x, &bad)), Param::StateCovarianceP);
    }
    let nan = DVector::from_vec(vec![f64::NAN, 0.0]);
    assert_eq!(
        names(k.set_estimate(nan.clone(), p.clone(), 0.0)),
        Param::State
    );
    assert_eq!(
        names(u.set_estimate(nan.clone(), p.clone(), 0.0)),
        Param::State
    );
    assert_eq!(names(b.set_estimate(&nan, &p)), Param::State);
    let short = DVector::from_vec(vec![1.0]);
    assert_eq!(
        names(k.set_estimate(short.clone(), p.clone(), 0.0)),
        Param::State
    );
    // Positive semidefinite but singular: the Kalman filter takes it; the sigma points and the
    // information form cannot.
    let singular = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 1.0, 1.0]);
    assert_eq!(
        names(u.set_estimate(x.clone(), singular.clone(), 0.0)),
        Param::StateCovarianceP
    );
    assert_eq!(
        names(b.set_estimate(&x, &singular)),
        Param::StateCovarianceP
    );
    // Unchanged by every refusal.
    assert_eq!((k.state(), k.covariance()), (&y, &(p.clone() * 2.0)));
    assert_eq!((u.state(), u.covariance()), (&y, &(p.clone() * 2.0)));
    assert!((b.estimate().unwrap() - &x).amax() < 1e-14);
    k.set_estimate(x.clone(), singular, 0.0).unwrap();
}

/// The weighted least-squares estimate of the derivatives at `t_n` (the last time) from the
/// prior (`x0`, `p0` at `t0`, weight `w0`) and the samples `(t_k, y_k)` of noise `sigma`
/// (weights `w_k`), by a direct QR solve of the whitened, weighted rows; and its covariance,
/// the sandwich `M (Aᵀ W² A) M` with `M = (Aᵀ W A)⁻¹` (the estimator's true covariance with
/// fading memory, (14.3.11); `M` itself with unit weights).
#[allow(clippy::too_many_arguments)]
fn direct(
    m: usize,
    t0: f64,
    x0: &[f64],
    p0: &DMatrix<f64>,
    w0: f64,
    samples: &[(f64, f64, f64)],
    sigma: f64,
) -> (DVector<f64>, DMatrix<f64>) {
    let p = m + 1;
    let tn = samples.last().unwrap().0;
    // Row of y(t) = Σ_j x_j (t − t_n)^j / j!.
    let taylor = |t: f64| -> Vec<f64> {
        let mut row = vec![1.0; p];
        for j in 1..p {
            row[j] = row[j - 1] * (t - tn) / j as f64;
        }
        row
    };
    // x(t0) = Φ(t0 − t_n) x(t_n): row i is the i-th derivative of the Taylor row.
    let phi = DMatrix::from_fn(p, p, |i, j| {
        if j < i {
            0.0
        } else {
            let k = j - i;
            (t0 - tn).powi(k as i32) / (1..=k).map(|v| v as f64).product::<f64>()
        }
    });
    let l = p0.clone().cholesky().unwrap().l();
    let li = l.clone().try_inverse().unwrap();
    let rows = samples.len() + p;
    let (mut a, mut b, mut w) = (
        DMatrix::zeros(rows, p),
        DVector::zeros(rows),
        vec![0.0; rows],
    );
    let pa = &li * &phi;
    let pb = &li * DVector::from_column_slice(x0);
    for i in 0..p {
        a.row_mut(i).copy_from(&pa.row(i));
        b[i] = pb[i];
        w[i] = w0;
    }
    for (k, &(t, y, wk)) in samples.iter().enumerate() {
        let r = taylor(t);
        for j in 0..p {
            a[(p + k, j)] = r[j] / sigma;
        }
        b[p + k] = y / sigma;
        w[p + k] = wk;
    }
    let sw = DMatrix::from_fn(rows, rows, |i, j| if i == j { w[i].sqrt() } else { 0.0 });
    let qr = (&sw * &a).qr();
    let r = qr.r();
    let qtb = qr.q().transpose() * (&sw * &b);
    let x = r.clone().solve_upper_triangular(&qtb).unwrap();
    let ri = r.try_inverse().unwrap();
    let mm = &ri * ri.transpose();
    let w2 = DMatrix::from_fn(rows, rows, |i, j| if i == j { w[i] * w[i] } else { 0.0 });
    let cov = &mm * (a.transpose() * w2 * &a) * &mm;
    (x, cov)
}

fn random_prior(rng: &mut impl Rng, p: usize) -> (Vec<f64>, DMatrix<f64>) {
    let g = DMatrix::from_fn(p, p, |_, _| rng.gen_range(-1.0..1.0));
    let cov = &g * g.transpose() + DMatrix::identity(p, p) * 0.5;
    ((0..p).map(|_| rng.gen_range(-2.0..2.0)).collect(), cov)
}

fn relative(a: f64, b: f64, scale: f64) -> f64 {
    (a - b).abs() / scale.max(b.abs())
}

#[test]
fn a_prior_is_the_weighted_least_squares_fit_with_it_as_pseudo_observations() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(41);
    let (sigma, theta, tau) = (0.7, 0.8, 1.5);
    let mut worst = (0.0f64, 0.0f64);
    for m in 0..=3 {
        for trial in 0..6 {
            let p = m + 1;
            let (x0, p0) = random_prior(&mut rng, p);
            let t0 = rng.gen_range(-1.0..1.0);
            let prior = Prior::new(t0, x0.clone(), p0.clone()).unwrap();
            let mut expanding = ExpandingMemory::new(m, Engine::Exact)
                .unwrap()
                .with_noise_sigma(sigma)
                .unwrap()
                .with_prior(&prior)
                .unwrap();
            let mut fading = FadingMemory::new(m, theta, tau, Engine::Exact)
                .unwrap()
                .with_noise_sigma(sigma)
                .unwrap()
                .with_prior(&prior)
                .unwrap();
            // Irregular times from the prior's (the first at it in half the trials).
            let mut t = if trial % 2 == 0 { t0 } else { t0 + 0.3 };
            let mut samples = Vec::new();
            for _ in 0..12 {
                let y = x0[0] + rng.gen_range(-1.0..1.0);
                expanding.update(t, y).unwrap();
                fading.update(t, y).unwrap();
                samples.push((t, y));
                for (f, fade) in [
                    (&expanding as &dyn PolynomialFilter, false),
                    (&fading, true),
                ] {
                    let w = |s: f64| if fade { theta.powf((t - s) / tau) } else { 1.0 };
                    let rows: Vec<_> = samples.iter().map(|&(s, y)| (s, y, w(s))).collect();
                    let (x, cov) = direct(m, t0, &x0, &p0, w(t0), &rows, sigma);
                    let got = f.estimate_at(t).unwrap();
                    let c = got.covariance.unwrap();
                    for i in 0..p {
                        let e = relative(got.derivatives[i], x[i], cov[(i, i)].sqrt());
                        worst.0 = worst.0.max(e);
                        for j in 0..p {
                            let s = (cov[(i, i)] * cov[(j, j)]).sqrt();
                            worst.1 = worst.1.max(relative(c[(i, j)], cov[(i, j)], s));
                        }
                    }
                }
                t += rng.gen_range(0.05..1.0);
            }
        }
    }
    // Relative to the estimate's σ (the estimate) and to the covariance's scale.
    eprintln!("worst (estimate, covariance) {worst:?}");
    assert!(worst.0 < 1e-12 && worst.1 < 1e-11, "worst {worst:?}");
}

#[test]
fn a_vague_prior_tends_to_the_filter_without_one() {
    let (m, sigma) = (2, 0.5);
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    let samples: Vec<(f64, f64)> = (0..40)
        .map(|k| {
            let t = k as f64 * 0.5 + rng.gen_range(0.0..0.3);
            (t, 1.0 + 0.2 * t - 0.01 * t * t + rng.gen_range(-0.5..0.5))
        })
        .collect();
    let t0 = samples[0].0;
    for scale in [1e4, 1e8] {
        let prior = Prior::new(t0, vec![0.0; 3], DMatrix::identity(3, 3) * scale).unwrap();
        let run = |with_prior: bool, fading: bool| -> Vec<f64> {
            let mut f: Box<dyn PolynomialFilter> = match (fading, with_prior) {
                (false, p) => {
                    let f = ExpandingMemory::new(m, Engine::Exact)
                        .unwrap()
                        .with_noise_sigma(sigma)
                        .unwrap();
                    Box::new(if p { f.with_prior(&prior).unwrap() } else { f })
                }
                (true, p) => {
                    let f = FadingMemory::new(m, 0.9, 1.0, Engine::Exact)
                        .unwrap()
                        .with_noise_sigma(sigma)
                        .unwrap();
                    Box::new(if p { f.with_prior(&prior).unwrap() } else { f })
                }
            };
            for &(t, y) in &samples {
                f.update(t, y).unwrap();
            }
            f.estimate().unwrap().derivatives
        };
        for fading in [false, true] {
            let (a, b) = (run(true, fading), run(false, fading));
            let gap = a
                .iter()
                .zip(&b)
                .map(|(x, y)| (x - y).abs() / y.abs().max(0.01))
                .fold(0.0, f64::max);
            // The prior's weight is σ²/scale of a sample's: the gap shrinks with it.
            eprintln!("scale {scale:e}, fading {fading}: gap {gap:e}");
            assert!(
                gap < 1e2 / scale,
                "scale {scale}, fading {fading}: gap {gap}"
            );
            assert!(gap > 0.0);
        }
    }
}

#[test]
fn a_prior_is_refused_where_it_cannot_be_held() {
    let prior = Prior::new(0.0, vec![1.0, 0.0], DMatrix::identity(2, 2)).unwrap();
    let refused = |r: Result<(), Error>| assert_eq!(names(r), Param::Prior);
    // The gain engine; no noise σ; the wrong degree; after a sample; σ after the prior.
    let gain = ExpandingMemory::new(1, Engine::Gain)
        .unwrap()
        .with_noise_sigma(1.0)
        .unwrap();
    refused(gain.with_prior(&prior).map(|_| ()));
    refused(
        ExpandingMemory::new(1, Engine::Exact)
            .unwrap()
            .with_prior(&prior)
            .map(|_| ()),
    );
    let f = FadingMemory::new(2, 0.9, 1.0, Engine::Exact)
        .unwrap()
        .with_noise_sigma(1.0)
        .unwrap();
    refused(f.with_prior(&prior).map(|_| ()));
    let mut f = FadingMemory::new(1, 0.9, 1.0, Engine::Exact)
        .unwrap()
        .with_noise_sigma(1.0)
        .unwrap();
    f.update(0.0, 1.0).unwrap();
    refused(f.with_prior(&prior).map(|_| ()));
    let f = FadingMemory::new(1, 0.9, 1.0, Engine::Exact)
        .unwrap()
        .with_noise_sigma(1.0)
        .unwrap();
    refused(
        f.with_prior(&prior)
            .unwrap()
            .with_noise_sigma(2.0)
            .map(|_| ()),
    );
    // Covariances: singular, not symmetric, negative.
    for bad in [
        DMatrix::zeros(2, 2),
        DMatrix::from_row_slice(2, 2, &[1.0, 0.5, 0.0, 1.0]),
        -DMatrix::identity(2, 2),
    ] {
        assert_eq!(
            names(Prior::new(0.0, vec![1.0, 0.0], bad).map(|_| ())),
            Param::PriorCovariance
        );
    }
    assert_eq!(
        names(Prior::new(f64::NAN, vec![1.0], DMatrix::identity(1, 1)).map(|_| ())),
        Param::Prior
    );
    // A first sample before the prior's time is refused; at it, taken.
    let mut f = ExpandingMemory::new(1, Engine::Exact)
        .unwrap()
        .with_noise_sigma(1.0)
        .unwrap()
        .with_prior(&prior)
        .unwrap();
    assert!(
        matches!(f.update(-0.5, 1.0), Err(Error::TimeNotIncreasing { previous, .. }) if previous == 0.0)
    );
    assert!(matches!(
        f.update_many(&[-0.5], &[1.0]),
        Err(Error::InBatch { index: 0, .. })
    ));
    f.update(0.0, 1.0).unwrap();
    assert_eq!(f.samples(), 1);
}

#[test]
fn the_bayes_filter_with_driving_noise_is_the_kalman_filter_with_it() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(3);
    let mut worst = 0.0f64;
    for (degree, axes) in [(0, 1), (1, 1), (1, 2), (2, 1), (2, 3)] {
        let n = (degree + 1) * axes;
        let obs =
            LinearObservation::new(DMatrix::from_fn(axes, n, |i, j| f64::from(i == j))).unwrap();
        let q = rng.gen_range(0.01..2.0);
        let g = DMatrix::from_fn(n, n, |_, _| rng.gen_range(-1.0..1.0));
        let p0 = &g * g.transpose() + DMatrix::identity(n, n);
        let x0 = DVector::from_fn(n, |_, _| rng.gen_range(-1.0..1.0));
        let dynamics = PolynomialDynamics::new(degree, axes);
        let noise = || WhiteNoiseDerivative::new(degree, axes, q).unwrap();
        let mut k = KalmanFilter::new(dynamics, obs.clone(), x0.clone(), p0.clone(), 0.0)
            .unwrap()
            .with_process_noise(noise())
            .unwrap();
        let mut b = BayesFilter::new(dynamics, obs, 0.0)
            .unwrap()
            .with_prior(&x0, &p0)
            .unwrap()
            .with_process_noise(noise())
            .unwrap();
        let mut t = 0.0;
        for step in 0..60 {
            t += rng.gen_range(0.05..1.5);
            // Missing components now and then; a prediction alone every 7th step.
            let values = (0..axes)
                .map(|_| (step % 7 != 6 && rng.gen_bool(0.85)).then(|| rng.gen_range(-5.0..5.0)))
                .collect();
            let meas = Measurement {
                time: t,
                values,
                noise: NoiseCovariance::Variances(vec![0.3; axes]),
            };
            k.update(&meas).unwrap();
            b.update(&meas).unwrap();
            let (bx, bc) = (b.estimate().unwrap(), b.covariance().unwrap());
            for i in 0..n {
                worst = worst.max(relative(bx[i], k.state()[i], k.covariance()[(i, i)].sqrt()));
                for j in 0..n {
                    let s = (k.covariance()[(i, i)] * k.covariance()[(j, j)]).sqrt();
                    worst = worst.max(relative(bc[(i, j)], k.covariance()[(i, j)], s));
                }
            }
        }
    }
    eprintln!("worst relative difference {worst:e}");
    assert!(worst < 1e-12, "worst relative difference {worst:e}");
}

#[test]
fn the_bayes_filter_with_driving_noise_starts_from_no_information() {
    // Against the Kalman filter from a vague prior: the same once the data determine it.
    let (degree, q) = (1, 0.5);
    let obs = LinearObservation::value_of(2);
    let dynamics = PolynomialDynamics::new(degree, 1);
    let mut b = BayesFilter::new(dynamics, obs.clone(), 0.0)
        .unwrap()
        .with_process_noise(WhiteNoiseDerivative::new(degree, 1, q).unwrap())
        .unwrap();
    let mut k = KalmanFilter::new(
        dynamics,
        obs,
        DVector::zeros(2),
        DMatrix::identity(2, 2) * 1e8,
        0.0,
    )
    .unwrap()
    .with_process_noise(WhiteNoiseDerivative::new(degree, 1, q).unwrap())
    .unwrap();
    for (i, (t, y)) in [(0.0, 1.0), (0.5, 2.0), (1.7, 2.5), (2.0, 4.0), (3.1, 4.4)]
        .into_iter()
        .enumerate()
    {
        let meas = Measurement {
            time: t,
            values: vec![Some(y)],
            noise: NoiseCovariance::Identity,
        };
        b.update(&meas).unwrap();
        k.update(&meas).unwrap();
        if i == 0 {
            assert!(b.estimate().is_none());
            continue;
        }
        // The vague prior's own weight, 1e-8 of a unit measurement's, is the gap's scale.
        let (bx, kx) = (b.estimate().unwrap(), k.state().clone());
        let gap = (bx - kx)
            .amax()
            .max((b.covariance().unwrap() - k.covariance()).amax());
        eprintln!("at {t}: gap {gap:e}");
        assert!(gap < 1e-6, "at {t}: gap {gap:e}");
    }
}

#[test]
fn driving_noise_and_fading_memory_are_refused_together() {
    let f = BayesFilter::new(
        PolynomialDynamics::new(1, 1),
        LinearObservation::value_of(2),
        0.0,
    )
    .unwrap();
    let noise = WhiteNoiseDerivative::new(1, 1, 1.0).unwrap();
    let fading = seqsmooth::kalman::Discount::PerUpdate { theta: 0.9 };
    let e = f
        .clone()
        .with_fading(fading)
        .unwrap()
        .with_process_noise(noise);
    assert!(matches!(
        e,
        Err(Error::InvalidParameter {
            name: Param::ProcessNoise,
            ..
        })
    ));
    let e = f.with_process_noise(noise).unwrap().with_fading(fading);
    assert!(matches!(
        e,
        Err(Error::InvalidParameter {
            name: Param::ProcessNoise,
            ..
        })
    ));
}
