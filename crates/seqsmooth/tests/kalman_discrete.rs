//! The Kalman filter on a discrete-time linear model with explicit matrices
//! (`kalman::discrete`): the same numbers as the polynomial model's filter on unit steps, its
//! batch's predictions, the RTS smoother over its pass equal to the whole-interval smoother run
//! again over the measurements, the fixed-lag smoother equal to the whole-interval one over
//! the data up to each lag, and refusals that leave the filter as it was.

use nalgebra::{DMatrix, DVector};
use seqsmooth::kalman::discrete::{LinearKalmanFilter, Pass, PassInto, StepMatrices};
use seqsmooth::kalman::noise::{ProcessNoise, WhiteNoiseDerivative};
use seqsmooth::kalman::{smoother, KalmanFilter};
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
use seqsmooth::model::observation::LinearObservation;
use seqsmooth::Error;

/// Constant acceleration on two axes (n = 6), positions observed with a full R, unit steps,
/// white-noise driving: the polynomial filter and the same model as matrices.
struct Problem {
    poly: KalmanFilter<PolynomialDynamics, LinearObservation>,
    linear: LinearKalmanFilter,
    zs: Vec<f64>,
    r: DMatrix<f64>,
}

fn problem(steps: usize) -> Problem {
    let (m, d) = (2, 2);
    let n = (m + 1) * d;
    let dynamics = PolynomialDynamics::new(m, d);
    let f = dynamics.transition(1.0);
    let noise = WhiteNoiseDerivative::new(m, d, 0.3).unwrap();
    let q = noise.covariance(0.0, 1.0).unwrap();
    let h = DMatrix::from_fn(d, n, |i, j| f64::from(i == j));
    let r = DMatrix::from_row_slice(2, 2, &[2.0, 0.4, 0.4, 1.0]);
    let x0 = DVector::from_vec(vec![1.0, -2.0, 0.5, 0.3, 0.0, 0.0]);
    let p0 = DMatrix::from_diagonal(&DVector::from_vec(vec![9.0, 9.0, 4.0, 4.0, 1.0, 1.0]));
    let poly = KalmanFilter::new(
        dynamics,
        LinearObservation::new(h.clone()).unwrap(),
        x0.clone(),
        p0.clone(),
        0.0,
    )
    .unwrap()
    .with_process_noise(noise)
    .unwrap();
    let linear = LinearKalmanFilter::new(x0, p0, f, h, q, r.clone()).unwrap();
    let mut zs = Vec::new();
    for k in 0..steps {
        let t = (k + 1) as f64;
        zs.push(1.0 + 0.5 * t + 0.05 * t * t + (k as f64 * 0.7).sin());
        // Every seventh step the second component is missing, every eleventh both.
        let y = if k % 7 == 3 {
            f64::NAN
        } else {
            -2.0 + 0.3 * t + (k as f64 * 1.3).cos()
        };
        zs.push(y);
        if k % 11 == 5 {
            let l = zs.len();
            zs[l - 2] = f64::NAN;
            zs[l - 1] = f64::NAN;
        }
    }
    Problem {
        poly,
        linear,
        zs,
        r,
    }
}

fn measurements(zs: &[f64], r: &DMatrix<f64>) -> Vec<Measurement> {
    zs.chunks_exact(2)
        .enumerate()
        .map(|(k, z)| Measurement {
            time: (k + 1) as f64,
            values: z.iter().map(|&v| (!v.is_nan()).then_some(v)).collect(),
            noise: NoiseCovariance::Full(r.clone()),
        })
        .collect()
}

fn close(a: &[f64], b: &[f64], tol: f64) -> f64 {
    let scale = b.iter().fold(1e-300_f64, |m, v| m.max(v.abs()));
    let worst = a
        .iter()
        .zip(b)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
    assert_eq!(a.len(), b.len());
    assert!(worst <= tol * scale, "differ by {worst:e} of {scale:e}");
    worst / scale
}

/// On unit steps the matrices `F = Ψ(1) ⊗ I`, `Q` of (15.2.23) give the polynomial filter's
/// numbers: the same prediction and Joseph update, the state to rounding (`F x` is a general
/// product here), the covariance bit for bit.
#[test]
fn matrices_give_the_polynomial_filter() {
    let Problem {
        mut poly,
        mut linear,
        zs,
        r,
    } = problem(60);
    let mut pass = Pass::default();
    linear
        .update_many(&zs, |_| StepMatrices::default(), &mut pass)
        .unwrap();
    for (k, m) in measurements(&zs, &r).iter().enumerate() {
        poly.predict(m.time).unwrap();
        let n = 6;
        close(
            &pass.predicted_states[k * n..(k + 1) * n],
            poly.state().as_slice(),
            1e-14,
        );
        assert_eq!(
            &pass.predicted_covariances[k * n * n..(k + 1) * n * n],
            poly.covariance().as_slice()
        );
        poly.update(m).unwrap();
        close(
            &pass.states[k * n..(k + 1) * n],
            poly.state().as_slice(),
            1e-13,
        );
        close(
            &pass.covariances[k * n * n..(k + 1) * n * n],
            poly.covariance().as_slice(),
            1e-13,
        );
    }
    assert_eq!(linear.steps(), 60);
}

/// The batch into the caller's memory (`update_many_into`) gives `update_many`'s numbers and
/// the single-step `predict` + `update` numbers bit for bit, missing components included;
/// slices of the wrong length are refused before any step.
#[test]
fn batch_into_memory_is_the_step_by_step_filter() {
    let Problem { mut linear, zs, .. } = problem(80);
    let (n, rows) = (6, 80);
    let (mut stepwise, mut into) = (linear.clone(), linear.clone());
    let mut pass = Pass::default();
    linear
        .update_many(&zs, |_| StepMatrices::default(), &mut pass)
        .unwrap();
    let (mut x, mut p) = (vec![0.0; rows * n], vec![0.0; rows * n * n]);
    let (mut xp, mut pp, mut nis) = (
        vec![0.0; rows * n],
        vec![0.0; rows * n * n],
        vec![0.0; rows],
    );
    let out = PassInto {
        states: &mut x,
        covariances: &mut p,
        predicted_states: &mut xp,
        predicted_covariances: &mut pp,
        nis: Some(&mut nis),
    };
    into.update_many_into(&zs, |_| StepMatrices::default(), out)
        .unwrap();
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&x), bits(&pass.states));
    assert_eq!(bits(&p), bits(&pass.covariances));
    assert_eq!(bits(&xp), bits(&pass.predicted_states));
    assert_eq!(bits(&pp), bits(&pass.predicted_covariances));
    assert_eq!(bits(&nis), bits(&pass.nis));
    for (k, z) in zs.chunks_exact(2).enumerate() {
        stepwise.predict(&StepMatrices::default()).unwrap();
        assert_eq!(
            bits(stepwise.state().as_slice()),
            bits(&xp[k * n..(k + 1) * n])
        );
        let c = stepwise.covariance().as_slice();
        assert_eq!(bits(c), bits(&pp[k * n * n..(k + 1) * n * n]));
        stepwise.update(z, &StepMatrices::default()).unwrap();
        assert_eq!(
            bits(stepwise.state().as_slice()),
            bits(&x[k * n..(k + 1) * n])
        );
        let c = stepwise.covariance().as_slice();
        assert_eq!(bits(c), bits(&p[k * n * n..(k + 1) * n * n]));
    }
    let mut short = vec![0.0; rows * n - 1];
    let (mut p, mut xp, mut pp) = (vec![0.0; rows * n * n], vec![0.0; rows * n], p.clone());
    let out = PassInto {
        states: &mut short,
        covariances: &mut p,
        predicted_states: &mut xp,
        predicted_covariances: &mut pp,
        nis: None,
    };
    let before = into.steps();
    let refused = into.update_many_into(&zs, |_| StepMatrices::default(), out);
    assert!(
        matches!(refused, Err(Error::InvalidParameter { .. })),
        "{refused:?}"
    );
    assert_eq!(into.steps(), before);
}

/// The RTS smoother over the batch's own pass (no measurement read again) gives the
/// whole-interval smoother's estimates (which runs the filter again), its gains
/// `C_k = S_{k|k} Fᵀ S_{k+1|k}⁻¹` and predicted covariances those of the pass.
#[test]
fn rts_over_the_pass_is_the_smoother() {
    let Problem {
        poly,
        mut linear,
        zs,
        r,
    } = problem(40);
    let start = linear.clone();
    let mut pass = Pass::default();
    linear
        .update_many(&zs, |_| StepMatrices::default(), &mut pass)
        .unwrap();
    let rts = start
        .rts_smoother(&pass.states, &pass.covariances, |_| StepMatrices::default())
        .unwrap();
    let whole = smoother::smooth(poly, &measurements(&zs, &r)).unwrap();
    let n = 6;
    let f = start.matrices().0.clone();
    for (k, (a, b)) in rts.iter().zip(&whole).enumerate() {
        close(a.state.as_slice(), b.state.as_slice(), 1e-10);
        close(a.covariance.as_slice(), b.covariance.as_slice(), 1e-10);
        if k + 1 < rts.len() {
            assert_eq!(
                a.predicted_covariance.as_slice(),
                &pass.predicted_covariances[(k + 1) * n * n..(k + 2) * n * n]
            );
            let p = DMatrix::from_row_slice(n, n, &pass.covariances[k * n * n..(k + 1) * n * n]);
            let want = &p * f.transpose() * a.predicted_covariance.clone().try_inverse().unwrap();
            close(a.gain.as_slice(), want.as_slice(), 1e-9);
        } else {
            assert_eq!(a.gain, DMatrix::zeros(n, n));
        }
    }
}

/// The fixed-lag smoother's estimate of step `k` is the whole-interval smoother's over steps
/// `0..=k+L` read at `k`; per-step matrices (here `F`, `Q`, `H`, `R` given each step, equal to
/// the constants but for `R`, and a control input) reach it as they reach the batch.
#[test]
fn fixed_lag_is_the_smoother_up_to_the_lag() {
    let Problem { linear, zs, .. } = problem(30);
    let lag = 4;
    let rs: Vec<DMatrix<f64>> = (0..30)
        .map(|k| DMatrix::from_row_slice(2, 2, &[1.0 + k as f64 * 0.1, 0.2, 0.2, 1.5]))
        .collect();
    let b = DMatrix::from_fn(6, 1, |i, _| if i >= 4 { 1.0 } else { 0.0 });
    let us: Vec<DVector<f64>> = (0..30)
        .map(|k| DVector::from_vec(vec![(k as f64).sin() * 0.1]))
        .collect();
    let step = |k: usize| StepMatrices {
        r: Some(&rs[k]),
        b: Some(&b),
        u: Some(&us[k]),
        ..StepMatrices::default()
    };
    let mut lagged = vec![None; 30];
    linear
        .fixed_lag(&zs, lag, step, |k, s| lagged[k] = Some(s))
        .unwrap();
    for k in 0..30 {
        let end = (k + lag + 1).min(30);
        let mut f = linear.clone();
        let mut pass = Pass::default();
        f.update_many(&zs[..2 * end], step, &mut pass).unwrap();
        let rts = linear
            .rts_smoother(&pass.states, &pass.covariances, step)
            .unwrap();
        let got = lagged[k].as_ref().unwrap();
        close(got.state.as_slice(), rts[k].state.as_slice(), 1e-10);
        close(
            got.covariance.as_slice(),
            rts[k].covariance.as_slice(),
            1e-10,
        );
    }
}

/// Bad matrices are refused naming the matrix (and in a batch the step), and the filter is as
/// before; a batch keeps the steps before the bad one.
#[test]
fn bad_matrices_are_refused_and_change_nothing() {
    let Problem { mut linear, zs, .. } = problem(10);
    let before = (linear.state().clone(), linear.covariance().clone());
    let asym = DMatrix::from_row_slice(2, 2, &[1.0, 0.5, 0.0, 1.0]);
    let indefinite = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
    let nan6 = DMatrix::from_element(6, 6, f64::NAN);
    let wide = DMatrix::zeros(6, 5);
    let cases: Vec<(StepMatrices, &str)> = vec![
        (
            StepMatrices {
                r: Some(&asym),
                ..Default::default()
            },
            "measurement noise R",
        ),
        (
            StepMatrices {
                r: Some(&indefinite),
                ..Default::default()
            },
            "measurement noise R",
        ),
        (
            StepMatrices {
                f: Some(&nan6),
                ..Default::default()
            },
            "transition matrix F",
        ),
        (
            StepMatrices {
                f: Some(&wide),
                ..Default::default()
            },
            "transition matrix F",
        ),
        (
            StepMatrices {
                q: Some(&nan6),
                ..Default::default()
            },
            "process noise Q",
        ),
        (
            StepMatrices {
                h: Some(&wide),
                ..Default::default()
            },
            "observation matrix H",
        ),
    ];
    for (step, word) in &cases {
        let e = linear
            .predict(step)
            .and_then(|()| linear.update(&[1.0, 2.0], step).map(|_| ()));
        let e = e.unwrap_err();
        assert!(e.to_string().contains(word), "{e} for {word}");
        assert_eq!(
            (linear.state(), linear.covariance()),
            (&before.0, &before.1)
        );
        assert_eq!(linear.steps(), 0);
    }
    let mut pass = Pass::default();
    let e = linear
        .update_many(
            &zs,
            |k| {
                if k == 6 {
                    cases[1].0
                } else {
                    StepMatrices::default()
                }
            },
            &mut pass,
        )
        .unwrap_err();
    match e {
        Error::InBatch { index, source } => {
            assert_eq!(index, 6);
            assert!(
                source.to_string().contains("positive semidefinite"),
                "{source}"
            );
        }
        e => panic!("{e}"),
    }
    assert_eq!((linear.steps(), pass.nis.len()), (6, 6));
}
