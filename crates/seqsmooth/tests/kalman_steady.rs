//! `kalman::steady`: the fading filter's steady state (Morrison §14.7) against the fading-memory
//! polynomial filter of the core (gains Table 13.1, VRF (13.6.x)), the notes' closed forms of
//! `P_∞` (Ex. 14.11 (III)), Ex. 14.9a/b and 14.6/14.7, and the fading Kalman filter run to its
//! limit on a non-polynomial model.

use nalgebra::{DMatrix, DVector};
use seqsmooth::kalman::steady::steady_state;
use seqsmooth::kalman::{Discount, KalmanFilter};
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::linear::LinearDynamics;
use seqsmooth::model::measurement::Measurement;
use seqsmooth::model::measurement::NoiseCovariance;
use seqsmooth::model::observation::LinearObservation;
use seqsmooth::polynomial::fading::gains::fading_gains;
use seqsmooth::polynomial::fading::vrf::fading_vrf;
use seqsmooth::polynomial::form::{EstimateForm, GainForm};
use seqsmooth::Error;

fn fact(k: usize) -> f64 {
    (1..=k).map(|i| i as f64).product()
}

fn e0(n: usize) -> DMatrix<f64> {
    let mut m = DMatrix::zeros(1, n);
    m[(0, 0)] = 1.0;
    m
}

/// The polynomial model on unit steps at θ: the gain is the core's `h_k k!` and the covariance
/// its VRF `k! j! [S_Z]_kj`, θ = 0.5, 0.8, 0.95; within 1e-10 relative at degrees 0-4 and 1e-8
/// at 5-6 (the Kronecker system's condition grows with the degree: measured 2.6e-12 at degree
/// 4, 2.1e-11 at 5, 1.2e-9 at 6; printed per degree).
#[test]
fn the_polynomial_model_is_the_fading_memory_filter() {
    for m in 0..=6 {
        let mut worst: f64 = 0.0;
        let bound = if m <= 4 { 1e-10 } else { 1e-8 };
        for theta in [0.5, 0.8, 0.95] {
            let n = m + 1;
            let phi = PolynomialDynamics::new(m, 1).transition(1.0);
            let s = steady_state(&phi, &e0(n), &DMatrix::identity(1, 1), theta).unwrap();
            let h = fading_gains(m, theta, GainForm::Current);
            let vrf = fading_vrf(m, theta, EstimateForm::Current).unwrap();
            for k in 0..n {
                let e = (s.gain[(k, 0)] / (h[k] * fact(k)) - 1.0).abs();
                worst = worst.max(e);
                assert!(
                    e < bound,
                    "m {m} θ {theta} H{k}: {} against {}",
                    s.gain[(k, 0)],
                    h[k] * fact(k)
                );
                for j in 0..n {
                    let want = vrf[(k, j)] * fact(k) * fact(j);
                    let e = (s.covariance[(k, j)] / want - 1.0).abs();
                    worst = worst.max(e);
                    assert!(
                        e < bound,
                        "m {m} θ {theta} S[{k},{j}]: {} against {want}",
                        s.covariance[(k, j)]
                    );
                }
            }
        }
        println!("degree {m}: worst relative difference {worst:e}");
    }
}

/// The notes' `P_∞` (ch10-15 §5.6, from Ex. 14.11 (III)), scaled state, σ = 1: degree 1
/// `[[1−θ², (1−θ)²], [(1−θ)², (1−θ)³/θ]]`; degree 2 as printed there (`z₂ = x''/2`).
#[test]
fn closed_form_weights() {
    for th in [0.3, 0.7, 0.9] {
        let s = steady_state(
            &PolynomialDynamics::new(1, 1).transition(1.0),
            &e0(2),
            &DMatrix::identity(1, 1),
            th,
        )
        .unwrap();
        let om = 1.0 - th;
        let want =
            DMatrix::from_row_slice(2, 2, &[1.0 - th * th, om * om, om * om, om.powi(3) / th]);
        assert!(
            (&s.weight - &want).amax() < 1e-13,
            "m 1 θ {th}: {}",
            s.weight
        );
        let s = steady_state(
            &PolynomialDynamics::new(2, 1).transition(1.0),
            &e0(3),
            &DMatrix::identity(1, 1),
            th,
        )
        .unwrap();
        let z = [
            [
                1.0 - th.powi(3),
                1.5 * om * om * (1.0 + th),
                0.5 * om.powi(3),
            ],
            [
                0.0,
                om.powi(3) * (1.0 + th) * (1.0 + 9.0 * th) / (4.0 * th * th),
                om.powi(4) * (1.0 + 3.0 * th) / (4.0 * th * th),
            ],
            [0.0, 0.0, om.powi(5) / (4.0 * th * th)],
        ];
        let d = [1.0, 1.0, 2.0]; // x'' = 2 z₂
        for k in 0..3 {
            for j in k..3 {
                let want = z[k][j] * d[k] * d[j];
                assert!(
                    (s.weight[(k, j)] - want).abs() < 1e-12 * want.abs().max(1e-3),
                    "m 2 θ {th} P[{k},{j}]"
                );
                assert_eq!(s.weight[(k, j)], s.weight[(j, k)]);
            }
        }
    }
}

/// Ex. 14.9b: `Φ = diag(1, −1)`, `M = (1, 1)`, `R = 1`: `Z_∞ = I/(1−β) + [[0,1],[1,0]]/(1+β)`.
/// Ex. 14.9a: `Φ = I`: `Z_∞ = ones/(1−β)`, singular: the state is not determined. Ex. 14.6/14.7
/// (τ = π): `Φ = blockdiag(−I₂, I₂)`, `M = (M₁ | M₂)`, `R = I`: `Z_∞ = [[M₁ᵀM₁/(1−β),
/// M₁ᵀM₂/(1+β)], [M₂ᵀM₁/(1+β), M₂ᵀM₂/(1−β)]]`.
#[test]
fn morrison_examples_14_6_to_14_9() {
    let beta = 0.8;
    let m = DMatrix::from_row_slice(1, 2, &[1.0, 1.0]);
    let r = DMatrix::identity(1, 1);
    let s = steady_state(
        &DMatrix::from_diagonal(&DVector::from_vec(vec![1.0, -1.0])),
        &m,
        &r,
        beta,
    )
    .unwrap();
    let want = DMatrix::identity(2, 2) / (1.0 - beta)
        + DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 1.0, 0.0]) / (1.0 + beta);
    assert!((&s.information - want).amax() < 1e-13);
    let e = steady_state(&DMatrix::identity(2, 2), &m, &r, beta);
    assert!(
        matches!(e, Err(Error::Unobservable { states: 2, .. })),
        "{e:?}"
    );

    let m1 = DMatrix::from_row_slice(3, 2, &[1.0, 0.5, 0.0, 2.0, 1.0, 1.0]);
    let m2 = DMatrix::from_row_slice(3, 2, &[0.3, 1.0, 1.0, 0.0, -1.0, 2.0]);
    let mut m = DMatrix::zeros(3, 4);
    m.view_mut((0, 0), (3, 2)).copy_from(&m1);
    m.view_mut((0, 2), (3, 2)).copy_from(&m2);
    let phi = DMatrix::from_diagonal(&DVector::from_vec(vec![-1.0, -1.0, 1.0, 1.0]));
    let s = steady_state(&phi, &m, &DMatrix::identity(3, 3), beta).unwrap();
    let mut want = DMatrix::zeros(4, 4);
    want.view_mut((0, 0), (2, 2))
        .copy_from(&(m1.transpose() * &m1 / (1.0 - beta)));
    want.view_mut((0, 2), (2, 2))
        .copy_from(&(m1.transpose() * &m2 / (1.0 + beta)));
    want.view_mut((2, 0), (2, 2))
        .copy_from(&(m2.transpose() * &m1 / (1.0 + beta)));
    want.view_mut((2, 2), (2, 2))
        .copy_from(&(m2.transpose() * &m2 / (1.0 - beta)));
    assert!((&s.information - want).amax() < 1e-12);
}

/// An oscillator (`ẍ = −ω² x`, ω = 0.7, observed in position, unit steps, β = 0.9): the
/// fading Kalman filter run for 600 updates reaches the steady state's gain and covariance
/// within 1e-10.
#[test]
fn the_fading_filter_reaches_it() {
    let w = 0.7_f64;
    let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -w * w, 0.0]);
    let dynamics = LinearDynamics::new(a).unwrap();
    let phi = dynamics.transition(1.0).unwrap();
    let s = steady_state(&phi, &e0(2), &DMatrix::from_element(1, 1, 0.5), 0.9).unwrap();
    let mut f = KalmanFilter::new(
        dynamics,
        LinearObservation::value_of(2),
        DVector::zeros(2),
        DMatrix::identity(2, 2) * 100.0,
        0.0,
    )
    .unwrap()
    .with_fading(Discount::PerTime(0.9))
    .unwrap();
    let mut gain = DMatrix::zeros(2, 1);
    for k in 1..=600 {
        let z = Measurement {
            time: k as f64,
            values: vec![Some((k as f64).sin())],
            noise: NoiseCovariance::Variances(vec![0.5]),
        };
        gain = f.update(&z).unwrap().unwrap().gain;
    }
    assert!(
        (&gain - &s.gain).amax() < 1e-10,
        "{gain} against {}",
        s.gain
    );
    assert!((f.covariance() - &s.covariance).amax() < 1e-10 * s.covariance.amax());
}

#[test]
fn refusals() {
    let one = DMatrix::identity(1, 1);
    assert!(steady_state(&one, &one, &one, 1.0).is_err());
    assert!(steady_state(&one, &one, &one, 0.0).is_err());
    assert!(steady_state(&one, &one, &DMatrix::from_element(1, 1, -1.0), 0.5).is_err());
    assert!(steady_state(&DMatrix::zeros(1, 1), &one, &one, 0.5).is_err());
    assert!(steady_state(&one, &DMatrix::identity(2, 2), &one, 0.5).is_err());
    assert!(steady_state(&DMatrix::from_element(1, 1, f64::NAN), &one, &one, 0.5).is_err());
}
