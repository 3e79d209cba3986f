//! `kalman::filter`: Morrison's ch. 12 exercises (the notes' T12-1 to T12-6, exact values),
//! the Kalman filter against the Bayes (information) form and against the batch estimate with
//! a prior (sequential equals batch, `Q = 0`), the driving noise's prediction, the innovation
//! statistics against their definitions and a Monte Carlo check of NIS, and the refusals.

use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use seqsmooth::estimate::gauss_newton::{Epoch, GaussNewton, Measurement, Prior};
use seqsmooth::kalman::noise::{ProcessNoise, WhiteNoiseDerivative};
use seqsmooth::kalman::KalmanFilter;
use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
use seqsmooth::model::linear::LinearDynamics;
use seqsmooth::model::measurement::NoiseCovariance;
use seqsmooth::model::observation::LinearObservation;
use seqsmooth::stats::consistency::mean_interval;
use seqsmooth::Error;

fn m(rows: usize, cols: usize, v: &[f64]) -> DMatrix<f64> {
    DMatrix::from_row_slice(rows, cols, v)
}

fn assert_close(got: &DMatrix<f64>, want: &DMatrix<f64>, tol: f64, what: &str) {
    assert_eq!(got.shape(), want.shape(), "{what}");
    for (g, w) in got.iter().zip(want.iter()) {
        assert!((g - w).abs() <= tol, "{what}: {got} against {want}");
    }
}

/// A filter on a static state (`Φ = I`) of `n` components with prior `s`, observing `obs`.
fn static_filter(
    s: DMatrix<f64>,
    obs: DMatrix<f64>,
) -> KalmanFilter<PolynomialDynamics, LinearObservation> {
    let n = s.nrows();
    KalmanFilter::new(
        PolynomialDynamics::new(0, n),
        LinearObservation::new(obs).unwrap(),
        DVector::zeros(n),
        s,
        0.0,
    )
    .unwrap()
}

fn measurement(t: f64, values: &[f64], noise: NoiseCovariance) -> Measurement {
    Measurement {
        time: t,
        values: values.iter().map(|&v| Some(v)).collect(),
        noise,
    }
}

/// T12-1 (Ex. 12.1b): the Kalman update (12.2.20) equals the Bayes form (12.2.7),
/// `(S⁻¹ + Mᵀ R⁻¹ M)⁻¹ = (1/2)[[1, 1], [1, 3]]`.
#[test]
fn t12_1_kalman_equals_bayes() {
    let s = m(2, 2, &[1.0, 1.0, 1.0, 2.0]);
    let mut f = static_filter(s.clone(), m(1, 2, &[1.0, 0.0]));
    f.update(&measurement(
        0.0,
        &[0.3],
        NoiseCovariance::Variances(vec![1.0]),
    ))
    .unwrap();
    let want = m(2, 2, &[0.5, 0.5, 0.5, 1.5]);
    assert_close(f.covariance(), &want, 1e-15, "S_{n,n}");
    let mm = m(1, 2, &[1.0, 0.0]);
    let bayes = (s.try_inverse().unwrap() + mm.transpose() * &mm)
        .try_inverse()
        .unwrap();
    assert_close(f.covariance(), &bayes, 1e-15, "Bayes");
}

/// T12-2 (Ex. 12.10): `S = [[1, 2], [2, 5]]`, `R = diag(1, 2)`, `M = I`: `H = (1/10)[[3, 2],
/// [4, 6]]`, `S_{n,n} = (1/10)[[3, 4], [4, 12]]`; the two components one at a time (Ex. 12.10's
/// sequential form, valid for diagonal `R`) give the same, through `H = (1/2)(1, 2)ᵀ` and
/// `(1/5)(1, 3)ᵀ`.
#[test]
fn t12_2_joint_and_sequential_updates() {
    let s = m(2, 2, &[1.0, 2.0, 2.0, 5.0]);
    let mut joint = static_filter(s.clone(), DMatrix::identity(2, 2));
    let i = joint
        .update(&measurement(
            0.0,
            &[1.0, 2.0],
            NoiseCovariance::Variances(vec![1.0, 2.0]),
        ))
        .unwrap()
        .unwrap();
    assert_close(
        &i.gain,
        &(m(2, 2, &[3.0, 2.0, 4.0, 6.0]) / 10.0),
        1e-15,
        "H",
    );
    let want = m(2, 2, &[0.3, 0.4, 0.4, 1.2]);
    assert_close(joint.covariance(), &want, 1e-15, "S");
    // Sequentially, as a two-component observation with one component missing at a time.
    let mut seq = static_filter(s, DMatrix::identity(2, 2));
    let noise = NoiseCovariance::Variances(vec![1.0, 2.0]);
    let first = Measurement {
        time: 0.0,
        values: vec![Some(1.0), None],
        noise: noise.clone(),
    };
    let i1 = seq.update(&first).unwrap().unwrap();
    assert_close(&i1.gain, &m(2, 1, &[0.5, 1.0]), 1e-15, "H first");
    assert_close(
        seq.covariance(),
        &m(2, 2, &[0.5, 1.0, 1.0, 3.0]),
        1e-15,
        "S first",
    );
    let second = Measurement {
        time: 0.0,
        values: vec![None, Some(2.0)],
        noise,
    };
    let i2 = seq.update(&second).unwrap().unwrap();
    assert_close(&i2.gain, &m(2, 1, &[0.2, 0.6]), 1e-15, "H second");
    assert_close(seq.covariance(), &want, 1e-15, "S sequential");
    assert_close(
        &DMatrix::from_column_slice(2, 1, seq.state().as_slice()),
        &DMatrix::from_column_slice(2, 1, joint.state().as_slice()),
        1e-15,
        "X",
    );
}

/// T12-3 (Ex. 12.12): a perfect observation of `x₀` (`R = 0`) with `S = [[a, b], [b, c]]`:
/// `H = (1, b/a)ᵀ`, `X = (y, x₁ + (b/a)(y − x₀))`, `S_{n,n} = [[0, 0], [0, c − b²/a]]`.
/// T12-4 (Ex. 12.13): perfect observations of `x₀` then `x₁` with `S = [[1,1,1],[1,2,2],[1,2,2]]`
/// leave `[[0,0,0],[0,1,1],[0,1,1]]` then 0; a second perfect observation of a component known
/// exactly is refused (`0/0`), and the filter is unchanged.
#[test]
fn t12_3_and_t12_4_perfect_observations() {
    let (a, b, c) = (2.0, 0.5, 3.0);
    let mut f = KalmanFilter::new(
        PolynomialDynamics::new(0, 2),
        LinearObservation::new(m(1, 2, &[1.0, 0.0])).unwrap(),
        DVector::from_vec(vec![1.0, 4.0]),
        m(2, 2, &[a, b, b, c]),
        0.0,
    )
    .unwrap();
    let y = 1.6;
    let i = f
        .update(&measurement(
            0.0,
            &[y],
            NoiseCovariance::Variances(vec![0.0]),
        ))
        .unwrap()
        .unwrap();
    assert_close(&i.gain, &m(2, 1, &[1.0, b / a]), 1e-15, "H");
    assert_eq!(f.state()[0], y);
    assert!((f.state()[1] - (4.0 + (b / a) * (y - 1.0))).abs() < 1e-15);
    assert_close(
        f.covariance(),
        &m(2, 2, &[0.0, 0.0, 0.0, c - b * b / a]),
        1e-15,
        "S",
    );

    let s = m(3, 3, &[1.0, 1.0, 1.0, 1.0, 2.0, 2.0, 1.0, 2.0, 2.0]);
    let mut f = static_filter(s, DMatrix::identity(3, 3));
    let perfect = |k: usize, v: f64| Measurement {
        time: 0.0,
        values: (0..3).map(|j| (j == k).then_some(v)).collect(),
        noise: NoiseCovariance::Variances(vec![0.0; 3]),
    };
    f.update(&perfect(0, 1.0)).unwrap();
    assert_close(
        f.covariance(),
        &m(3, 3, &[0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 1.0, 1.0]),
        1e-15,
        "after x0",
    );
    f.update(&perfect(1, 2.0)).unwrap();
    assert_close(f.covariance(), &DMatrix::zeros(3, 3), 1e-15, "after x1");
    let before = (f.state().clone(), f.covariance().clone());
    let e = f.update(&perfect(0, 1.0));
    assert!(matches!(e, Err(Error::InvalidParameter { .. })), "{e:?}");
    assert_eq!((f.state(), f.covariance()), (&before.0, &before.1));
}

/// T12-5 (Ex. 12.14): perfectly correlated errors (`R` of rank 1) leave `S` of rank 2:
/// `S = (1/5)[[3,3,2],[3,3,2],[2,2,13]]`; carried by `Φ = [[1,−1,1],[0,1,−2],[0,0,1]]` (the one
/// step of `dX/dt = A X`, `A = log Φ = [[0,−1,0],[0,0,−2],[0,0,0]]`) to `(1/5)[[13,−24,13],
/// [−24,47,−24],[13,−24,13]]`; updated with `R = [[1,1],[1,2]]` to `(1/133)[[20,−17,20],
/// [−17,61,−17],[20,−17,20]]`, or with `R = [[1,1],[1,1]]` to `(7/115)` ones.
#[test]
fn t12_5_correlated_errors() {
    let a = m(3, 3, &[0.0, -1.0, 0.0, 0.0, 0.0, -2.0, 0.0, 0.0, 0.0]);
    let dynamics = LinearDynamics::new(a).unwrap();
    let phi = dynamics.transition(1.0).unwrap();
    assert_close(
        &phi,
        &m(3, 3, &[1.0, -1.0, 1.0, 0.0, 1.0, -2.0, 0.0, 0.0, 1.0]),
        0.0,
        "Φ",
    );
    let new = || {
        KalmanFilter::new(
            dynamics.clone(),
            LinearObservation::new(m(2, 3, &[1.0, 0.0, 0.0, 0.0, 1.0, 0.0])).unwrap(),
            DVector::zeros(3),
            m(3, 3, &[2.0, 1.0, 1.0, 1.0, 2.0, 1.0, 1.0, 1.0, 3.0]),
            0.0,
        )
        .unwrap()
    };
    let rank_one = NoiseCovariance::Full(m(2, 2, &[1.0, 1.0, 1.0, 1.0]));
    let mut f = new();
    f.update(&measurement(0.0, &[0.0, 0.0], rank_one.clone()))
        .unwrap();
    let s1 = m(3, 3, &[3.0, 3.0, 2.0, 3.0, 3.0, 2.0, 2.0, 2.0, 13.0]) / 5.0;
    assert_close(f.covariance(), &s1, 1e-14, "S_{n,n}");
    f.predict(1.0).unwrap();
    let s2 = m(
        3,
        3,
        &[13.0, -24.0, 13.0, -24.0, 47.0, -24.0, 13.0, -24.0, 13.0],
    ) / 5.0;
    assert_close(f.covariance(), &s2, 1e-13, "S_{n+1,n}");
    let mut g = f.clone();
    f.update(&measurement(
        1.0,
        &[0.0, 0.0],
        NoiseCovariance::Full(m(2, 2, &[1.0, 1.0, 1.0, 2.0])),
    ))
    .unwrap();
    let s3 = m(
        3,
        3,
        &[20.0, -17.0, 20.0, -17.0, 61.0, -17.0, 20.0, -17.0, 20.0],
    ) / 133.0;
    assert_close(f.covariance(), &s3, 1e-13, "S_{n+1,n+1}");
    g.update(&measurement(1.0, &[0.0, 0.0], rank_one)).unwrap();
    assert_close(
        g.covariance(),
        &(DMatrix::from_element(3, 3, 7.0 / 115.0)),
        1e-13,
        "rank 1",
    );
}

/// T12-6 (Ex. 12.16): `S = [[1111, 1111], [1111, 1112]]`, `M = (1, 0)`, `R = 1`: the exact
/// `S_{n,n} = [[1111, 1111], [1111, 2223]]/1112`. Joseph's form holds it to a few ulp (the
/// book's 4-digit `(I − H M) S` kept one digit).
#[test]
fn t12_6_precision() {
    let mut f = static_filter(
        m(2, 2, &[1111.0, 1111.0, 1111.0, 1112.0]),
        m(1, 2, &[1.0, 0.0]),
    );
    f.update(&measurement(
        0.0,
        &[0.0],
        NoiseCovariance::Variances(vec![1.0]),
    ))
    .unwrap();
    let want = m(2, 2, &[1111.0, 1111.0, 1111.0, 2223.0]) / 1112.0;
    for (g, w) in f.covariance().iter().zip(want.iter()) {
        assert!((g - w).abs() <= 8.0 * f64::EPSILON * w, "{g} against {w}");
    }
}

/// Sequential equals batch: with `Q = 0`, the filter started from a prior at `t₀` and run over
/// irregular measurements of a polynomial state gives, at the last time, the batch minimum-
/// variance estimate with that prior (`GaussNewton` with the prior carried to the last time,
/// (11.2.24)-(11.2.27)), the state within 5e-9 of max(|x|, σ) and the covariance within 5e-9
/// of `σ_k σ_j`; degrees 0-4, observations of one or two components. The covariance form's
/// rounding grows with the spread of `S`'s scales (at degree 4 over 20 time units the fourth
/// derivative's variance is 1e-8 of the value's): measured 1.7e-9 and 7.6e-10 there, where
/// the batch QR is the reference (the information form is the remedy, §12.4).
#[test]
fn sequential_equals_batch() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(21);
    let (mut worst, mut worst_s): (f64, f64) = (0.0, 0.0);
    for m_deg in 0..=4 {
        let n = m_deg + 1;
        let dynamics = PolynomialDynamics::new(m_deg, 1);
        let mut obs = DMatrix::zeros(2, n);
        obs[(0, 0)] = 1.0;
        if n > 1 {
            obs[(1, 1)] = 1.0;
        } else {
            obs[(1, 0)] = 2.0;
        }
        let observation = LinearObservation::new(obs).unwrap();
        let prior_x = DVector::from_fn(n, |_, _| rng.gen_range(-1.0..1.0));
        let l = DMatrix::from_fn(
            n,
            n,
            |i, j| if i >= j { rng.gen_range(0.1..1.0) } else { 0.0 },
        );
        let prior_s = &l * l.transpose() * 4.0;
        let t0 = 3.0;
        let mut f = KalmanFilter::new(
            dynamics,
            observation.clone(),
            prior_x.clone(),
            prior_s.clone(),
            t0,
        )
        .unwrap();
        let mut rows = Vec::new();
        let mut t = t0;
        for k in 0..(3 * n + 4) {
            t += rng.gen_range(0.2..1.5);
            let values = if k % 3 == 0 {
                vec![Some(rng.gen_range(-5.0..5.0)), None]
            } else {
                vec![
                    Some(rng.gen_range(-5.0..5.0)),
                    Some(rng.gen_range(-5.0..5.0)),
                ]
            };
            let noise = NoiseCovariance::Full(m(2, 2, &[1.5, 0.3, 0.3, 0.8]));
            let row = Measurement {
                time: t,
                values,
                noise,
            };
            f.update(&row).unwrap();
            rows.push(row);
        }
        // The prior carried to the last time.
        let (px, ps) = dynamics
            .propagate_covariance(&prior_x, &prior_s, t0, t)
            .unwrap();
        let prior = Prior {
            state: px,
            covariance: ps,
        };
        let batch = GaussNewton::default()
            .fit(
                &dynamics,
                &observation,
                &rows,
                Epoch::At(t),
                &prior.state,
                Some(&prior),
            )
            .unwrap();
        for k in 0..n {
            let scale = batch.state[k].abs().max(batch.covariance[(k, k)].sqrt());
            let e = (f.state()[k] - batch.state[k]).abs() / scale;
            worst = worst.max(e);
            assert!(
                e <= 5e-9,
                "m {m_deg} x{k}: {} against {} (sigma {}, condition {:e})",
                f.state()[k],
                batch.state[k],
                batch.covariance[(k, k)].sqrt(),
                batch.condition_number
            );
            for j in 0..n {
                let s = batch.covariance[(k, j)];
                let scale = (batch.covariance[(k, k)] * batch.covariance[(j, j)]).sqrt();
                let e = (f.covariance()[(k, j)] - s).abs() / scale;
                worst_s = worst_s.max(e);
                assert!(
                    e <= 5e-9,
                    "m {m_deg} S[{k},{j}]: {} against {s}",
                    f.covariance()[(k, j)]
                );
            }
        }
    }
    println!(
        "worst: state {worst:e} of max(|x|, sigma), covariance {worst_s:e} of sigma_k sigma_j"
    );
}

/// The prediction adds `Q` over the actual step: `S_{n,n−1} = Φ S Φᵀ + Q(ζ)` (15.4.11) on an
/// irregular step; `Q = 0` is ch. 12's prediction.
#[test]
fn prediction_with_driving_noise() {
    let dynamics = PolynomialDynamics::new(2, 1);
    let s0 = m(3, 3, &[2.0, 0.1, 0.0, 0.1, 1.0, 0.2, 0.0, 0.2, 0.5]);
    let noise = WhiteNoiseDerivative::new(2, 1, 0.3).unwrap();
    let mut f = KalmanFilter::new(
        dynamics,
        LinearObservation::value_of(3),
        DVector::zeros(3),
        s0.clone(),
        1.0,
    )
    .unwrap()
    .with_process_noise(noise)
    .unwrap();
    f.predict(3.7).unwrap();
    let phi = dynamics.transition(2.7);
    let want = &phi * &s0 * phi.transpose() + noise.covariance(1.0, 3.7).unwrap();
    assert_close(f.covariance(), &want, 1e-13, "S_{n,n-1}");
    assert!(KalmanFilter::new(
        dynamics,
        LinearObservation::value_of(3),
        DVector::zeros(3),
        s0,
        1.0
    )
    .unwrap()
    .with_process_noise(WhiteNoiseDerivative::new(1, 1, 0.3).unwrap())
    .is_err());
}

/// NIS and log-likelihood against their definitions on one update, and the NIS of a correctly
/// modelled constant-velocity track with driving noise, 2,000 updates of 2 components: its mean
/// lies in the two-sided 99% interval of χ²(2N)/N.
#[test]
fn innovation_statistics() {
    let mut f = static_filter(m(2, 2, &[2.0, 0.5, 0.5, 1.0]), DMatrix::identity(2, 2));
    let i = f
        .update(&measurement(
            0.0,
            &[1.0, -0.5],
            NoiseCovariance::Variances(vec![1.0, 0.5]),
        ))
        .unwrap()
        .unwrap();
    let v = m(2, 2, &[3.0, 0.5, 0.5, 1.5]);
    assert_close(&i.covariance, &v, 1e-15, "V");
    let nu = DVector::from_vec(vec![1.0, -0.5]);
    let nis = nu.dot(&(v.clone().try_inverse().unwrap() * &nu));
    assert!((i.nis - nis).abs() < 1e-15);
    let ll = -0.5 * (nis + v.determinant().ln() + 2.0 * (2.0 * std::f64::consts::PI).ln());
    assert!((i.log_likelihood - ll).abs() < 1e-14);

    let mut rng = rand::rngs::StdRng::seed_from_u64(8);
    let q = 0.05;
    let dynamics = PolynomialDynamics::new(1, 2);
    let noise = WhiteNoiseDerivative::new(1, 2, q).unwrap();
    let obs = LinearObservation::new(m(2, 4, &[1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0])).unwrap();
    let mut truth = DVector::from_vec(vec![0.0, 0.0, 1.0, -1.0]);
    let mut f = KalmanFilter::new(dynamics, obs, truth.clone(), DMatrix::zeros(4, 4), 0.0)
        .unwrap()
        .with_process_noise(noise)
        .unwrap();
    let (sigma, unit) = (0.7, Normal::new(0.0, 1.0).unwrap());
    let (mut t, mut sum, count) = (0.0, 0.0, 2000);
    for _ in 0..count {
        let dt = rng.gen_range(0.3..1.7);
        // The truth's driving noise over the step, drawn from Q(dt) by its Cholesky factor.
        let qc = noise.covariance(t, t + dt).unwrap().cholesky().unwrap().l();
        let w = DVector::from_fn(4, |_, _| unit.sample(&mut rng));
        truth = dynamics.propagate(&truth, t, t + dt).unwrap().state + qc * w;
        t += dt;
        let y = [
            truth[0] + sigma * unit.sample(&mut rng),
            truth[1] + sigma * unit.sample(&mut rng),
        ];
        let i = f
            .update(&measurement(
                t,
                &y,
                NoiseCovariance::Variances(vec![sigma * sigma; 2]),
            ))
            .unwrap()
            .unwrap();
        sum += i.nis;
    }
    let (lo, hi) = mean_interval(2, count, 0.99).unwrap();
    let mean = sum / count as f64;
    assert!(
        lo <= mean && mean <= hi,
        "mean NIS {mean} outside [{lo}, {hi}]"
    );
}

/// Refusals: mismatched models and priors, a NaN measurement, a negative variance, a wrong
/// component count; a missing observation predicts only.
#[test]
fn refusals_and_missing_observations() {
    let d = PolynomialDynamics::new(1, 1);
    let o = LinearObservation::value_of(2);
    assert!(KalmanFilter::new(
        d,
        LinearObservation::value_of(3),
        DVector::zeros(2),
        DMatrix::identity(2, 2),
        0.0
    )
    .is_err());
    assert!(KalmanFilter::new(
        d,
        o.clone(),
        DVector::zeros(3),
        DMatrix::identity(2, 2),
        0.0
    )
    .is_err());
    assert!(KalmanFilter::new(
        d,
        o.clone(),
        DVector::zeros(2),
        m(2, 2, &[-1.0, 0.0, 0.0, 1.0]),
        0.0
    )
    .is_err());
    assert!(KalmanFilter::new(
        d,
        o.clone(),
        DVector::zeros(2),
        DMatrix::identity(2, 2),
        f64::NAN
    )
    .is_err());
    let mut f = KalmanFilter::new(d, o, DVector::zeros(2), DMatrix::identity(2, 2), 0.0).unwrap();
    for bad in [
        measurement(1.0, &[f64::NAN], NoiseCovariance::Identity),
        measurement(1.0, &[1.0], NoiseCovariance::Variances(vec![-1.0])),
        measurement(1.0, &[1.0, 2.0], NoiseCovariance::Identity),
        measurement(f64::INFINITY, &[1.0], NoiseCovariance::Identity),
    ] {
        assert!(f.update(&bad).is_err(), "{bad:?}");
        assert_eq!(f.time(), 0.0, "unchanged");
    }
    let none = Measurement {
        time: 2.0,
        values: vec![None],
        noise: NoiseCovariance::Identity,
    };
    assert!(f.update(&none).unwrap().is_none());
    assert_eq!(f.time(), 2.0);
    assert_close(
        f.covariance(),
        &m(2, 2, &[5.0, 2.0, 2.0, 1.0]),
        1e-15,
        "predicted only",
    );
}

/// The iterated update of §12.5 is the Bayes filter with iterative differential correction of
/// ch. 11 ((12.5.17) against (11.2.27)): on T11-1 (range `sqrt(d² + x²)`, `d = 3`, prior 4 with
/// `a² = 1`, `s² = 0.01`, `ρ = 5.2`) it converges to 4.243697780575 with covariance
/// 0.014775907527, as `GaussNewton` with the prior does; for a linear observation it is the
/// plain update; a limit too small is `NotConverged` and leaves the filter unchanged.
#[test]
fn iterated_update_is_chapter_11() {
    use seqsmooth::model::observation::NonlinearObservation;
    let range = NonlinearObservation::new(1, 1, |_t, x: &DVector<f64>| {
        DVector::from_vec(vec![(9.0 + x[0] * x[0]).sqrt()])
    })
    .with_jacobian(|_t, x: &DVector<f64>| {
        DMatrix::from_element(1, 1, x[0] / (9.0 + x[0] * x[0]).sqrt())
    });
    let new = || {
        KalmanFilter::new(
            PolynomialDynamics::new(0, 1),
            range.clone(),
            DVector::from_vec(vec![4.0]),
            DMatrix::identity(1, 1),
            0.0,
        )
        .unwrap()
    };
    let rho = measurement(0.0, &[5.2], NoiseCovariance::Variances(vec![0.01]));
    let mut f = new();
    f.update_iterated(&rho, 1e-10, 20).unwrap().unwrap();
    assert!(
        (f.state()[0] - 4.243697780575).abs() < 5e-13,
        "{}",
        f.state()[0]
    );
    assert!((f.covariance()[(0, 0)] - 0.014775907527).abs() < 5e-13);
    let prior = Prior {
        state: DVector::from_vec(vec![4.0]),
        covariance: DMatrix::identity(1, 1),
    };
    let gn = GaussNewton {
        tolerance: 1e-10,
        ..GaussNewton::default()
    }
    .fit(
        &PolynomialDynamics::new(0, 1),
        &range,
        std::slice::from_ref(&rho),
        Epoch::End,
        &prior.state,
        Some(&prior),
    )
    .unwrap();
    assert!((f.state()[0] - gn.state[0]).abs() < 1e-14);
    assert!((f.covariance()[(0, 0)] - gn.covariance[(0, 0)]).abs() < 1e-14);
    // The one-pass (extended) update is the first iterate, 4.246153846154.
    let mut once = new();
    once.update(&rho).unwrap();
    assert!((once.state()[0] - 4.246153846154).abs() < 5e-13);
    // Too few iterations.
    let mut g = new();
    let e = g.update_iterated(&rho, 1e-12, 2);
    assert!(
        matches!(e, Err(Error::NotConverged { iterations: 2, .. })),
        "{e:?}"
    );
    assert_eq!((g.state()[0], g.time()), (4.0, 0.0));
    // Linear: the plain update.
    let s = m(2, 2, &[1.0, 2.0, 2.0, 5.0]);
    let z = measurement(0.0, &[1.0, 2.0], NoiseCovariance::Variances(vec![1.0, 2.0]));
    let (mut a, mut b) = (
        static_filter(s.clone(), DMatrix::identity(2, 2)),
        static_filter(s, DMatrix::identity(2, 2)),
    );
    a.update(&z).unwrap();
    b.update_iterated(&z, 1e-9, 5).unwrap();
    assert_close(a.covariance(), b.covariance(), 1e-15, "linear S");
    assert!((a.state() - b.state()).amax() < 1e-15);
}

/// A prior covariance that is symmetric with a positive diagonal but indefinite, or not
/// finite, is refused at construction by the rule `set_estimate` applies (the filter's and the
/// unscented filter's constructors alike), naming the prior covariance.
#[test]
fn an_indefinite_prior_covariance_is_refused_at_construction() {
    use seqsmooth::error::Param;
    use seqsmooth::kalman::UnscentedKalmanFilter;
    let indefinite = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
    let kf = |p: DMatrix<f64>| {
        KalmanFilter::new(
            PolynomialDynamics::new(1, 1),
            LinearObservation::value_of(2),
            DVector::zeros(2),
            p,
            0.0,
        )
    };
    assert!(matches!(
        kf(indefinite.clone()),
        Err(Error::InvalidParameter {
            name: Param::PriorCovariance,
            ..
        })
    ));
    assert!(kf(DMatrix::from_row_slice(
        2,
        2,
        &[1.0, f64::INFINITY, f64::INFINITY, 1.0]
    ))
    .is_err());
    assert!(kf(DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 1.0, 1.0])).is_ok()); // singular is a covariance
    let ukf = UnscentedKalmanFilter::new(
        PolynomialDynamics::new(1, 1),
        LinearObservation::value_of(2),
        DVector::zeros(2),
        indefinite,
        0.0,
    );
    assert!(ukf.is_err());
}
