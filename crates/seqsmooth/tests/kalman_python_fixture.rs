//! The numbers the Python package's `KalmanFilter` and `BayesFilter` must give to the last
//! bit: this library's own run over a fixed set of measurements (two axes, three components
//! with one a sum of the others, irregular Unix-epoch times, missing components), stored in
//! `crates/seqsmooth-py/tests/fixtures/kalman_rust.txt` with the inputs (every number in
//! shortest round-trip form). This test fails when the library's numbers change; rewrite the
//! file with `SEQSMOOTH_WRITE_FIXTURES=1 cargo test --test kalman_python_fixture`.
//! `crates/seqsmooth-py/tests/test_kalman.py` reads it.

use nalgebra::{DMatrix, DVector};
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::kalman::{BayesFilter, Discount, KalmanFilter};
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::measurement::Measurement;
use seqsmooth::model::measurement::NoiseCovariance;
use seqsmooth::model::observation::LinearObservation;
mod common;

use common::python_fixture::{check, line};

/// The inputs: times and three components (NaN missing), made from integers (exact).
fn inputs() -> Vec<(f64, [f64; 3])> {
    (0..60u32)
        .map(|k| {
            let t = 1.7e9 + f64::from(k) * 0.75 + f64::from(k % 4) * 0.125;
            let (a, b) = (
                f64::from((k * 37) % 11) - 5.0,
                f64::from((k * 53) % 7) - 3.0,
            );
            let x = 2.0 + 0.5 * f64::from(k) + a / 8.0;
            let y = -1.0 + 0.25 * f64::from(k) + b / 4.0;
            let mut z = [x, y, x + y + (a - b) / 16.0];
            if k % 7 == 3 {
                z[1] = f64::NAN;
            }
            if k % 11 == 5 {
                z = [f64::NAN; 3];
            }
            (t, z)
        })
        .collect()
}

/// The file's text: the inputs, then each row's Kalman state, covariance (row-major) and NIS,
/// then each row's Bayes estimate and covariance (`bayes,-` while not determined).
fn fixture() -> String {
    let m = DMatrix::from_row_slice(3, 4, &[1.0, 0., 0., 0., 0., 1., 0., 0., 1., 1., 0., 0.]);
    let r = vec![1.0, 2.0, 0.5];
    let rows: Vec<Measurement> = inputs()
        .into_iter()
        .map(|(time, z)| Measurement {
            time,
            values: z.iter().map(|&v| (!v.is_nan()).then_some(v)).collect(),
            noise: NoiseCovariance::Variances(r.clone()),
        })
        .collect();
    let mut out = String::new();
    for (t, z) in inputs() {
        line(&mut out, "input", [t].into_iter().chain(z));
    }
    let dynamics = PolynomialDynamics::new(1, 2);
    let observation = LinearObservation::new(m).unwrap();
    let x0 = DVector::from_vec(vec![1.0, 0.0, 0.3, 0.1]);
    let p0 = DMatrix::from_diagonal(&DVector::from_vec(vec![4.0, 4.0, 1.0, 1.0]));
    let mut kalman = KalmanFilter::new(dynamics, observation.clone(), x0, p0, 1.7e9 - 1.0)
        .unwrap()
        .with_process_noise(WhiteNoiseDerivative::new(1, 2, 0.05).unwrap())
        .unwrap();
    for m in &rows {
        let nis = kalman.update_stats(m).unwrap().map_or(f64::NAN, |i| i.nis);
        let p = kalman.covariance().transpose();
        let values = kalman.state().iter().chain(p.iter()).copied();
        line(&mut out, "kalman", values.chain([nis]));
    }
    let mut bayes = BayesFilter::new(dynamics, observation, 0.0)
        .unwrap()
        .with_fading(Discount::PerUpdate(0.9))
        .unwrap();
    for m in &rows {
        bayes.update(m).unwrap();
        match (bayes.estimate(), bayes.covariance()) {
            (Some(x), Some(p)) => {
                let p = p.transpose();
                line(&mut out, "bayes", x.iter().chain(p.iter()).copied());
            }
            _ => out.push_str("bayes,-\n"),
        }
    }
    out
}

#[test]
fn the_python_fixture_is_this_librarys_run() {
    let text = fixture();
    check("kalman_rust.txt", &text);
    assert!(text.lines().filter(|l| l.starts_with("bayes,-")).count() < 5);
}
