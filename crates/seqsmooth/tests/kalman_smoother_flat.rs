//! `kalman::smoother::smooth_flat` (the whole-interval Rauch–Tung–Striebel smoother on flat
//! buffers in the textbook form, what `smooth` and Python's `KalmanFilter.smooth` run): the
//! measurement-at-a-time [`Smoother`]'s numbers (`push`, then `finish`: the backward maps) to
//! 1e-9 of σ (measured: 1.7e-10 on the ill-conditioned 12-state models, 4.2e-12 on the radar), the filtered ones bit for bit, on every state size 1-12 (the
//! backward kernel's fixed sizes and its general one), with driving noise, one to three
//! components, missing ones and irregular times, and on the radar extended filter; the same
//! errors; and each step against the textbook form with an explicit inverse,
//! `C = S_{k|k} Φᵀ S_{k+1|k}⁻¹`, `X_{k|N} = X_{k|k} + C (X_{k+1|N} − X_{k+1|k})`,
//! `S_{k|N} = S_{k|k} + C (S_{k+1|N} − S_{k+1|k}) Cᵀ`.

use nalgebra::{DMatrix, DVector};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::kalman::smoother::{smooth, smooth_flat, Smoother};
use seqsmooth::kalman::KalmanFilter;
use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
use seqsmooth::model::observation::{LinearObservation, Observation};
use seqsmooth::model::radar::Radar;
use seqsmooth::Error;

/// A polynomial model of `degree` on `axes` axes, `p` random observed combinations, random
/// noise, a random prior; `count` measurements at irregular times, about a fifth of the
/// components missing.
fn case(
    rng: &mut StdRng,
    degree: usize,
    axes: usize,
    p: usize,
    count: usize,
) -> (
    KalmanFilter<PolynomialDynamics, LinearObservation>,
    Vec<Measurement>,
) {
    let n = (degree + 1) * axes;
    let h = DMatrix::from_fn(p, n, |_, _| rng.gen_range(-1.0..1.0));
    let a = DMatrix::from_fn(n, n, |_, _| rng.gen_range(-1.0..1.0));
    let prior = &a * a.transpose() + DMatrix::identity(n, n);
    let filter = KalmanFilter::new(
        PolynomialDynamics::new(degree, axes),
        LinearObservation::new(h).unwrap(),
        DVector::from_fn(n, |_, _| rng.gen_range(-3.0..3.0)),
        prior,
        0.0,
    )
    .unwrap()
    .with_process_noise(WhiteNoiseDerivative::new(degree, axes, 0.3).unwrap())
    .unwrap();
    let b = DMatrix::from_fn(p, p, |_, _| rng.gen_range(-0.5..0.5));
    let r = &b * b.transpose() + DMatrix::identity(p, p) * 0.5;
    let mut t = 0.0;
    let rows = (0..count)
        .map(|_| {
            t += rng.gen_range(0.05..1.0);
            Measurement {
                time: t,
                values: (0..p)
                    .map(|_| (rng.gen_range(0.0..1.0) > 0.2).then(|| rng.gen_range(-5.0..5.0)))
                    .collect(),
                noise: NoiseCovariance::Full(r.clone()),
            }
        })
        .collect();
    (filter, rows)
}

/// Asserts that `smooth` and `smooth_flat` give the `Smoother`'s numbers (its backward maps
/// applied in turn) to rounding: within 1e-9 of each σ (the tolerance of the smoother against the batch estimate, `kalman_smoother.rs`) (of `σ_i σ_j` for a covariance
/// entry), the filtered estimates and NIS bit for bit.
fn assert_same<D: Dynamics + Clone, O: Observation + Clone>(
    filter: &KalmanFilter<D, O>,
    rows: &[Measurement],
) -> f64 {
    let mut s = Smoother::new(filter.clone());
    for m in rows {
        s.push(m).unwrap();
    }
    let want = s.finish().unwrap();
    let got = smooth(filter.clone(), rows).unwrap();
    assert_eq!(got, want);
    let flat = smooth_flat(filter.clone(), rows).unwrap();
    let n = flat.dimension;
    let mut worst: f64 = 0.0;
    for (k, (w, g)) in want.iter().zip(&got).enumerate() {
        assert_eq!(
            (&g.filtered_state, &g.filtered_covariance, g.nis, g.time),
            (&w.filtered_state, &w.filtered_covariance, w.nis, w.time)
        );
        assert_eq!(flat.nis[k], w.nis);
        let sigma = w.covariance.diagonal().map(f64::sqrt);
        for i in 0..n {
            worst = worst.max((flat.states[k * n + i] - w.state[i]).abs() / sigma[i]);
            for j in 0..n {
                let e = (flat.covariances[k * n * n + i + j * n] - w.covariance[(i, j)]).abs();
                worst = worst.max(e / (sigma[i] * sigma[j]));
            }
        }
    }
    assert!(worst < 1e-9, "worst {worst:e} of σ");
    worst
}

#[test]
fn flat_smoother_is_the_smoother_on_every_size() {
    let mut rng = StdRng::seed_from_u64(33);
    let (mut sizes, mut worst): (usize, f64) = (0, 0.0);
    for degree in 0..=3 {
        for axes in 1..=3 {
            for p in 1..=3 {
                let (filter, rows) = case(&mut rng, degree, axes, p, 60);
                worst = worst.max(assert_same(&filter, &rows));
                sizes += 1;
            }
        }
    }
    assert_eq!(sizes, 36);
    println!("worst against the maps: {worst:e} of σ");
}

#[test]
fn flat_smoother_is_the_smoother_on_the_radar() {
    let mut rng = StdRng::seed_from_u64(34);
    let radar = Radar::new([0.0; 3], 6).unwrap();
    let mut x: DVector<f64> = DVector::from_vec(vec![20e3, -5e3, 3e3, -150.0, 80.0, 5.0]);
    let mut t = 0.0;
    let rows: Vec<Measurement> = (0..60)
        .map(|_| {
            let dt = rng.gen_range(0.5..1.5);
            t += dt;
            for a in 0..3 {
                x[a] += dt * x[a + 3];
            }
            let (h, rho) = (x[0].hypot(x[1]), x.rows(0, 3).norm());
            Measurement {
                time: t,
                values: vec![
                    Some(rho + rng.gen_range(-10.0..10.0)),
                    Some(x[1].atan2(x[0]) + rng.gen_range(-1e-3..1e-3)),
                    Some(x[2].atan2(h)),
                ],
                noise: NoiseCovariance::Variances(vec![100.0, 1e-6, 1e-6]),
            }
        })
        .collect();
    let prior = DMatrix::from_diagonal(&DVector::from_vec(vec![1e4, 1e4, 1e4, 1e5, 1e5, 1e5]));
    let start = DVector::from_vec(vec![20e3, -5e3, 3e3, 0.0, 0.0, 0.0]);
    let filter = KalmanFilter::new(PolynomialDynamics::new(1, 3), radar, start, prior, 0.0)
        .unwrap()
        .with_process_noise(WhiteNoiseDerivative::new(1, 3, 1.0).unwrap())
        .unwrap();
    println!(
        "worst against the maps: {:e} of σ",
        assert_same(&filter, &rows)
    );
}

/// Every smoothed estimate against the textbook backward recursion with `S_{k+1|k}⁻¹` by an
/// explicit inverse, over the filter's own predictions (re-run here step by step).
#[test]
fn flat_smoother_against_the_textbook_recursion() {
    let mut rng = StdRng::seed_from_u64(35);
    let mut worst: f64 = 0.0;
    for (degree, axes, p) in [(1, 1, 1), (2, 1, 1), (1, 3, 3), (3, 3, 2)] {
        let (filter, rows) = case(&mut rng, degree, axes, p, 40);
        let got = smooth_flat(filter.clone(), &rows).unwrap();
        let (mut f, mut filtered, mut predicted) = (filter, Vec::new(), Vec::new());
        for m in &rows {
            let before = f.clone();
            let mut g = before.clone();
            g.predict(m.time).unwrap();
            let phi = PolynomialDynamics::new(degree, axes)
                .propagate(before.state(), before.time(), m.time)
                .unwrap()
                .transition;
            predicted.push((phi, g.state().clone(), g.covariance().clone()));
            f.update(m).unwrap();
            filtered.push((f.state().clone(), f.covariance().clone()));
        }
        let n = filtered[0].0.len();
        let (mut xs, mut ss) = filtered.last().cloned().unwrap();
        for k in (0..rows.len() - 1).rev() {
            let (x, s) = &filtered[k];
            let (phi, xp, sp) = &predicted[k + 1];
            let c = s * phi.transpose() * sp.clone().try_inverse().unwrap();
            xs = x + &c * (&xs - xp);
            ss = s + &c * (&ss - sp) * c.transpose();
            let scale = ss.diagonal().map(f64::sqrt);
            // The run's gain C_k and S_{k+1|k}: the backward step's own, and the prediction's.
            let gain = &got.gains[k * n * n..(k + 1) * n * n];
            let largest = c.amax();
            for (e, want) in gain.iter().zip(c.iter()) {
                worst = worst.max((e - want).abs() / largest);
            }
            let sd = sp.diagonal().map(f64::sqrt);
            for (e, (i, j)) in got
                .predicted_covariance(k)
                .unwrap()
                .iter()
                .zip((0..n).flat_map(|j| (0..n).map(move |i| (i, j))))
            {
                worst = worst.max((e - sp[(i, j)]).abs() / (sd[i] * sd[j]));
            }
            for i in 0..n {
                worst = worst.max((got.states[k * n + i] - xs[i]).abs() / scale[i]);
                for j in 0..n {
                    let e = got.covariances[k * n * n + i + j * n] - ss[(i, j)];
                    worst = worst.max(e.abs() / (scale[i] * scale[j]));
                }
            }
        }
        let last = rows.len() - 1;
        assert!(got.gains[last * n * n..].iter().all(|&g| g == 0.0));
        assert!(got.predicted_covariance(last).is_none());
    }
    assert!(worst < 1e-8, "worst {worst:e} of σ");
}

/// The errors of the measurement-at-a-time smoother, with the same indices: a time before
/// the previous, a bad value, a prediction that is not positive definite (no prior
/// uncertainty, no driving noise), and a row with two faults.
#[test]
fn flat_smoother_refuses_as_the_smoother() {
    let row = |t: f64, y: f64| Measurement {
        time: t,
        values: vec![Some(y)],
        noise: NoiseCovariance::Identity,
    };
    let known = KalmanFilter::new(
        PolynomialDynamics::new(1, 1),
        LinearObservation::value_of(2),
        DVector::zeros(2),
        DMatrix::zeros(2, 2),
        0.0,
    )
    .unwrap();
    let vague = KalmanFilter::new(
        PolynomialDynamics::new(1, 1),
        LinearObservation::value_of(2),
        DVector::zeros(2),
        DMatrix::identity(2, 2),
        0.0,
    )
    .unwrap();
    // The last: the map into measurement 1 fails before the bad value of measurement 2.
    let cases: [(&KalmanFilter<_, _>, Vec<Measurement>); 5] = [
        // A step too long to predict over and a bad value in one row: the prediction's
        // error, which the smoother meets first.
        (&vague, vec![row(1.0, 1.0), row(1e300, f64::INFINITY)]),
        (&vague, vec![row(1.0, 1.0), row(2.0, 1.0), row(1.5, 1.0)]),
        (&vague, vec![row(1.0, 1.0), row(2.0, f64::INFINITY)]),
        (&known, vec![row(1.0, 1.0), row(2.0, 1.0), row(3.0, 1.0)]),
        (
            &known,
            vec![row(1.0, 1.0), row(2.0, 1.0), row(3.0, f64::INFINITY)],
        ),
    ];
    for (filter, rows) in cases {
        let mut s = Smoother::new(filter.clone());
        let want = rows
            .iter()
            .enumerate()
            .try_for_each(|(index, m)| {
                s.push(m).map(|_| ()).map_err(|e| Error::InBatch {
                    index,
                    source: Box::new(e),
                })
            })
            .unwrap_err();
        let got = smooth_flat(filter.clone(), &rows).unwrap_err();
        assert_eq!(format!("{got:?}"), format!("{want:?}"));
    }
}
