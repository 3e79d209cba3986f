//! `kalman::smoother`: the Rauch–Tung–Striebel smoother against the batch minimum-variance
//! estimate from the prior and every measurement (`GaussNewton` with the prior carried to each
//! time, Morrison (11.2.24)-(11.2.27)) for linear models without driving noise, on irregular
//! times with missing components; its relations to the forward filter with driving noise; and
//! its refusals.

use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use seqsmooth::estimate::gauss_newton::{Epoch, GaussNewton, Measurement, Prior};
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::kalman::{smooth, KalmanFilter};
use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
use seqsmooth::model::measurement::NoiseCovariance;
use seqsmooth::model::observation::LinearObservation;
use seqsmooth::Error;

/// Random measurements of one or two components (every third missing its second), irregular
/// times from `t0`.
fn rows(rng: &mut rand::rngs::StdRng, count: usize, t0: f64) -> Vec<Measurement> {
    let mut t = t0;
    (0..count)
        .map(|k| {
            t += rng.gen_range(0.2..1.5);
            let second = (k % 3 != 0).then(|| rng.gen_range(-5.0..5.0));
            Measurement {
                time: t,
                values: vec![Some(rng.gen_range(-5.0..5.0)), second],
                noise: NoiseCovariance::Full(DMatrix::from_row_slice(2, 2, &[1.5, 0.3, 0.3, 0.8])),
            }
        })
        .collect()
}

/// At every measurement time the smoothed state and covariance equal the batch estimate from
/// the prior and all the measurements, degrees 0-3, within 1e-9 of max(|x|, σ) and of σ_k σ_j.
#[test]
fn smoother_equals_the_whole_interval_batch_estimate() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(12);
    let (mut worst, mut worst_s): (f64, f64) = (0.0, 0.0);
    for degree in 0..=3 {
        let n = degree + 1;
        let dynamics = PolynomialDynamics::new(degree, 1);
        let mut obs = DMatrix::zeros(2, n);
        obs[(0, 0)] = 1.0;
        obs[(1, n - 1)] = 1.0;
        if n == 1 {
            obs[(1, 0)] = 2.0;
        }
        let observation = LinearObservation::new(obs).unwrap();
        let prior_x = DVector::from_fn(n, |_, _| rng.gen_range(-1.0..1.0));
        let prior_s = DMatrix::from_diagonal(&DVector::from_fn(n, |_, _| rng.gen_range(1.0..4.0)));
        let t0 = 2.0;
        let measurements = rows(&mut rng, 4 * n + 6, t0);
        let filter = KalmanFilter::new(
            dynamics,
            observation.clone(),
            prior_x.clone(),
            prior_s.clone(),
            t0,
        )
        .unwrap();
        let smoothed = smooth(filter, &measurements).unwrap();
        assert_eq!(smoothed.len(), measurements.len());
        let last = smoothed.last().unwrap();
        assert_eq!(last.state, last.filtered_state);
        for s in &smoothed {
            let (px, ps) = dynamics
                .propagate_covariance(&prior_x, &prior_s, t0, s.time)
                .unwrap();
            let prior = Prior {
                state: px.clone(),
                covariance: ps,
            };
            let batch = GaussNewton::default()
                .fit(
                    &dynamics,
                    &observation,
                    &measurements,
                    Epoch::At(s.time),
                    &px,
                    Some(&prior),
                )
                .unwrap();
            for k in 0..n {
                let sk = batch.covariance[(k, k)].sqrt();
                let e = (s.state[k] - batch.state[k]).abs() / batch.state[k].abs().max(sk);
                worst = worst.max(e);
                assert!(
                    e <= 1e-9,
                    "degree {degree} t {} x{k}: {} against {}",
                    s.time,
                    s.state[k],
                    batch.state[k]
                );
                for j in 0..n {
                    let scale = (batch.covariance[(k, k)] * batch.covariance[(j, j)]).sqrt();
                    let e = (s.covariance[(k, j)] - batch.covariance[(k, j)]).abs() / scale;
                    worst_s = worst_s.max(e);
                    assert!(e <= 1e-9, "degree {degree} t {} S[{k},{j}]", s.time);
                }
            }
        }
    }
    println!("worst: state {worst:e}, covariance {worst_s:e}");
}

/// With driving noise: the smoothed variances are positive and at most the filtered ones (the
/// later measurements add information), and the last estimate is the filter's.
#[test]
fn smoothing_with_driving_noise() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(13);
    let dynamics = PolynomialDynamics::new(1, 1);
    let observation =
        LinearObservation::new(DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 1.0, 1.0])).unwrap();
    let measurements = rows(&mut rng, 40, 0.0);
    let filter = KalmanFilter::new(
        dynamics,
        observation,
        DVector::zeros(2),
        DMatrix::identity(2, 2) * 10.0,
        0.0,
    )
    .unwrap()
    .with_process_noise(WhiteNoiseDerivative::new(1, 1, 0.2).unwrap())
    .unwrap();
    let smoothed = smooth(filter, &measurements).unwrap();
    for s in &smoothed {
        for k in 0..2 {
            assert!(
                s.covariance[(k, k)] <= s.filtered_covariance[(k, k)] * (1.0 + 1e-12),
                "t {}",
                s.time
            );
            assert!(s.covariance[(k, k)] > 0.0);
        }
        assert!(s.nis.is_some());
    }
    let last = smoothed.last().unwrap();
    assert_eq!(last.covariance, last.filtered_covariance);
}

/// Refusals: times going backwards (by index), a failing update (by index).
#[test]
fn refusals() {
    let filter = KalmanFilter::new(
        PolynomialDynamics::new(0, 1),
        LinearObservation::value_of(1),
        DVector::zeros(1),
        DMatrix::identity(1, 1),
        0.0,
    )
    .unwrap();
    let row = |t: f64, y: f64| Measurement {
        time: t,
        values: vec![Some(y)],
        noise: NoiseCovariance::Identity,
    };
    let e = smooth(filter.clone(), &[row(1.0, 1.0), row(0.5, 1.0)]);
    assert!(matches!(e, Err(Error::InBatch { index: 1, .. })), "{e:?}");
    let e = smooth(filter.clone(), &[row(1.0, 1.0), row(2.0, f64::NAN)]);
    assert!(matches!(e, Err(Error::InBatch { index: 1, .. })), "{e:?}");
    assert!(smooth(filter, &[]).unwrap().is_empty());
}
