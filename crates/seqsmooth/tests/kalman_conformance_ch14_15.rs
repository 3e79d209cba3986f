//! Morrison chs. 14 and 15 conformance, the items of the conformance index not covered by
//! `kalman_fading.rs` (fading Kalman → FMP gains and VRF, β = 1 is the plain filter) and
//! `kalman_steady.rs` (the steady-state solver against Ex. 14.6/14.7/14.9 and Ex. 14.11):
//!
//! - the fading Kalman filter itself run to the closed-form limits `Z_∞` of Ex. 14.9b and
//!   Ex. 14.6/14.7 (gain `H = Z_∞⁻¹ Mᵀ R⁻¹` (14.4.29), true covariance `P Z_∞(β²) P` (14.3.19)),
//!   and through Ex. 14.9a, where `Z_∞` is singular;
//! - the scalar examples Ex. 14.14 (`ẋ = −x`) and Ex. 14.15 (`ẋ = x`, also with `σ_n² = α/n`);
//! - ch. 15: `Q = 0` reproduces ch. 12, and the continuity of (15.4.11) in `Q`; `S_{n,n−1}`
//!   stays positive definite after a forced-singular `S_{n,n}` when `Q` is diagonal positive
//!   (§15.5, against "once singular, always singular", (12.4.9)).
//!
//! Misprints (the notes' register): (14.3.4)/(14.4.6)/(14.4.7)'s garbled block matrices are read
//! as `Q_(n) = blockdiag(R_n, β^{−(t_n − t_{n−1})} Q_(n−1))`, and (14.3.17)'s OCR "Q_n(β²)" as
//! `Q(β)⁻¹ R Q(β)⁻¹ = Q(β²)⁻¹`, which gives the true covariance `S = P(β) P(β²)⁻¹ P(β)`
//! (14.3.19) used as the oracle below; the display of Ex. 14.7 is reconstructed from its
//! derivation (`Z_∞ = Σ_k β^k Φ^{−kᵀ} Mᵀ M Φ^{−k}`, checked here term by term). The count-based
//! discount θ replaces `β^{t_n − t_{n−1}}` with no other change (Ex. 14.16). Ch. 15's equations
//! (15.2.23), (15.4.10)-(15.4.14) are used as printed.

mod common;

use common::kalman::cov_err;
use common::rational::{mm, to_f64};
use nalgebra::{DMatrix, DVector};
use num_traits::Zero;
use seqsmooth::kalman::noise::{ProcessNoise, WhiteNoiseDerivative};
use seqsmooth::kalman::{Discount, KalmanFilter};
use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics, Propagation};
use seqsmooth::model::linear::LinearDynamics;
use seqsmooth::model::measurement::Measurement;
use seqsmooth::model::measurement::NoiseCovariance;
use seqsmooth::model::observation::LinearObservation;
use seqsmooth::scalar::Rational;
use seqsmooth::Error;
use std::f64::consts::PI;

fn m(rows: usize, cols: usize, v: &[f64]) -> DMatrix<f64> {
    DMatrix::from_row_slice(rows, cols, v)
}

fn meas(t: f64, values: &[f64], variances: &[f64]) -> Measurement {
    Measurement {
        time: t,
        values: values.iter().map(|&v| Some(v)).collect(),
        noise: NoiseCovariance::Variances(variances.to_vec()),
    }
}

/// `Φ(ζ) = diag(1, (−1)^ζ)` on whole steps ζ (Ex. 14.9b's transition): a model no real
/// constant `A` gives, written here on the library's `Dynamics` trait.
#[derive(Clone, Copy, Debug)]
struct Flip;

impl Dynamics for Flip {
    fn dimension(&self) -> usize {
        2
    }

    fn propagate(&self, state: &DVector<f64>, t_a: f64, t_b: f64) -> Result<Propagation, Error> {
        let steps = t_b - t_a;
        if steps != steps.round() {
            return Err(Error::InvalidParameter {
                name: "step",
                value: steps.to_string(),
                reason: "Ex. 14.9b's model is defined on whole steps".into(),
            });
        }
        let sign = if (steps as i64).rem_euclid(2) == 0 {
            1.0
        } else {
            -1.0
        };
        let transition = m(2, 2, &[1.0, 0.0, 0.0, sign]);
        Ok(Propagation {
            state: &transition * state,
            transition,
        })
    }

    fn is_linear(&self) -> bool {
        true
    }
}

/// The closed-form limit's gain `Z⁻¹ Mᵀ R⁻¹` and true covariance `Z⁻¹ Z(β²) Z⁻¹` ((14.4.29),
/// (14.3.19)) from `Z(β)` and `Z(β²)`, `R = I`.
fn limit(z: &DMatrix<f64>, z2: &DMatrix<f64>, obs: &DMatrix<f64>) -> (DMatrix<f64>, DMatrix<f64>) {
    let p = z.clone().try_inverse().unwrap();
    (&p * obs.transpose(), &p * z2 * &p)
}

/// Runs the count-based fading Kalman filter (θ per update, Ex. 14.16) for `updates` updates at
/// times `k·step`, prior `100 I`, observations `sin k` on every component with `R = I`; returns
/// the last gain and the true covariance.
fn run_fading<D: Dynamics>(
    dynamics: D,
    obs: &DMatrix<f64>,
    theta: f64,
    step: f64,
    updates: usize,
) -> (DMatrix<f64>, DMatrix<f64>) {
    let n = obs.ncols();
    let p = obs.nrows();
    let mut f = KalmanFilter::new(
        dynamics,
        LinearObservation::new(obs.clone()).unwrap(),
        DVector::zeros(n),
        DMatrix::identity(n, n) * 100.0,
        0.0,
    )
    .unwrap()
    .with_fading(Discount::PerUpdate(theta))
    .unwrap();
    let mut gain = DMatrix::zeros(n, p);
    for k in 1..=updates {
        let y: Vec<f64> = (0..p).map(|c| ((k + c) as f64).sin()).collect();
        gain = f
            .update(&meas(k as f64 * step, &y, &vec![1.0; p]))
            .unwrap()
            .unwrap()
            .gain;
    }
    (gain, f.covariance().clone())
}

/// Runs [`run_fading`] for 400 updates and checks its gain and true covariance against
/// [`limit`] of `z` (`Z_∞` at θ) and `z2` (at θ²) within `tol` relative; returns the larger
/// error.
#[allow(clippy::too_many_arguments)]
fn reaches_limit<D: Dynamics>(
    dynamics: D,
    obs: &DMatrix<f64>,
    theta: f64,
    step: f64,
    z: &DMatrix<f64>,
    z2: &DMatrix<f64>,
    tol: f64,
    label: &str,
) -> f64 {
    let (want_h, want_s) = limit(z, z2, obs);
    let (h, s) = run_fading(dynamics, obs, theta, step, 400);
    let eh = (&h - &want_h).amax() / want_h.amax();
    let es = cov_err(&s, &want_s);
    assert!(eh < tol, "{label}: H {h} against {want_h} ({eh:e})");
    assert!(es < tol, "{label}: S {s} against {want_s} ({es:e})");
    eh.max(es)
}

/// Ex. 14.9b: `Φ = diag(1, −1)`, `M = (1, 1)`, `R = 1`: `Z_∞ = I/(1−β) + [[0, 1], [1, 0]]/(1+β)`
/// (positive definite: the filter settles). The count-based fading Kalman filter, θ = 0.5, 0.8,
/// 0.9, 400 updates: its gain and true covariance reach the closed form's within 1e-12 relative
/// (measured, printed).
#[test]
fn ex_14_9b_the_filter_reaches_z_infinity() {
    let obs = m(1, 2, &[1.0, 1.0]);
    let mut worst: f64 = 0.0;
    for theta in [0.5f64, 0.8, 0.9] {
        let z = |b: f64| {
            DMatrix::identity(2, 2) / (1.0 - b) + m(2, 2, &[0.0, 1.0, 1.0, 0.0]) / (1.0 + b)
        };
        // The closed form is the series Σ_k θ^k Φ^{−kᵀ} Mᵀ M Φ^{−k} (14.7.9).
        let series = (0..2000).fold(DMatrix::zeros(2, 2), |acc, k| {
            let d = m(2, 2, &[1.0, 0.0, 0.0, if k % 2 == 0 { 1.0 } else { -1.0 }]);
            acc + (&d * obs.transpose() * &obs * &d) * theta.powi(k)
        });
        assert!((&series - z(theta)).amax() < 1e-12 * z(theta).amax());
        let label = format!("θ {theta}");
        let e = reaches_limit(
            Flip,
            &obs,
            theta,
            1.0,
            &z(theta),
            &z(theta * theta),
            1e-12,
            &label,
        );
        worst = worst.max(e);
    }
    println!("worst: {worst:e}");
}

/// Ex. 14.6/14.7: `Φ(τ) = blockdiag([[cos τ, sin τ], [−sin τ, cos τ]], I₂)` (the library's
/// `e^{τA}`, `A = blockdiag([[0, 1], [−1, 0]], 0)`), `M = (M₁ | M₂)`, `R = I`. τ = π:
/// `Φ = blockdiag(−I₂, I₂)` and `Z_∞ = [[M₁ᵀM₁/(1−β), M₁ᵀM₂/(1+β)], [M₂ᵀM₁/(1+β), M₂ᵀM₂/(1−β)]]`
/// — here `M` (3 × 4) has rank 3 only, yet `M₁`, `M₂` have rank 2 each, which is enough. τ = 2π:
/// `Φ = I₄`, `Z_∞ = MᵀM/(1−β)`, which needs `M` of rank 4 (a 4 × 4 `M` here). θ = 0.8 per update,
/// 400 updates: gain and true covariance within 1e-11 relative of the closed form (the
/// library's `e^{πA}` is `−I` to rounding, which 400 steps accumulate; measured 2.7e-13,
/// printed).
#[test]
fn ex_14_6_and_14_7_the_filter_reaches_z_infinity() {
    let theta: f64 = 0.8;
    let mut a = DMatrix::zeros(4, 4);
    a[(0, 1)] = 1.0;
    a[(1, 0)] = -1.0;
    let dynamics = LinearDynamics::new(a).unwrap();
    let phi = dynamics.transition(PI).unwrap();
    let want_phi = DMatrix::from_diagonal(&DVector::from_vec(vec![-1.0, -1.0, 1.0, 1.0]));
    assert!((&phi - &want_phi).amax() < 1e-15, "{phi}");
    let m1 = m(3, 2, &[1.0, 0.5, 0.0, 2.0, 1.0, 1.0]);
    let m2 = m(3, 2, &[0.3, 1.0, 1.0, 0.0, -1.0, 2.0]);
    let mut obs = DMatrix::zeros(3, 4);
    obs.view_mut((0, 0), (3, 2)).copy_from(&m1);
    obs.view_mut((0, 2), (3, 2)).copy_from(&m2);
    assert_eq!(obs.rank(1e-12), 3);
    let z = |b: f64| {
        let mut z = DMatrix::zeros(4, 4);
        z.view_mut((0, 0), (2, 2))
            .copy_from(&(m1.transpose() * &m1 / (1.0 - b)));
        z.view_mut((0, 2), (2, 2))
            .copy_from(&(m1.transpose() * &m2 / (1.0 + b)));
        z.view_mut((2, 0), (2, 2))
            .copy_from(&(m2.transpose() * &m1 / (1.0 + b)));
        z.view_mut((2, 2), (2, 2))
            .copy_from(&(m2.transpose() * &m2 / (1.0 - b)));
        z
    };
    // The reconstructed display is the series (14.7.9) for this Φ.
    let series = (0..2000).fold(DMatrix::zeros(4, 4), |acc, k| {
        let s = if k % 2 == 0 { 1.0 } else { -1.0 };
        let d = DMatrix::from_diagonal(&DVector::from_vec(vec![s, s, 1.0, 1.0]));
        acc + (&d * obs.transpose() * &obs * &d) * theta.powi(k)
    });
    assert!((&series - z(theta)).amax() < 1e-12 * z(theta).amax());
    let mut worst: f64 = 0.0;
    let (z1, z2) = (z(theta), z(theta * theta));
    worst = worst.max(reaches_limit(
        dynamics.clone(),
        &obs,
        theta,
        PI,
        &z1,
        &z2,
        1e-11,
        "τ = π",
    ));

    // τ = 2π: Φ = I₄, Z = MᵀM/(1−θ) with a rank-4 M.
    let obs4 = m(
        4,
        4,
        &[
            1.0, 0.5, 0.0, 0.2, 0.0, 2.0, 1.0, 0.0, 1.0, 1.0, 0.3, 1.0, 0.0, -1.0, 2.0, 0.5,
        ],
    );
    assert_eq!(obs4.rank(1e-12), 4);
    let g = obs4.transpose() * &obs4;
    let (z1, z2) = (&g / (1.0 - theta), &g / (1.0 - theta * theta));
    worst = worst.max(reaches_limit(
        dynamics,
        &obs4,
        theta,
        2.0 * PI,
        &z1,
        &z2,
        1e-11,
        "τ = 2π",
    ));
    println!("worst: {worst:e}");
}

/// Ex. 14.9a: `Φ = I₂`, `M = (1, 1)`, `R = 1`: `Z_∞ = ones/(1−β)` is singular (Lemma 14.6:
/// `M v = 0` for `v = (1, −1)/√2`). The filter still runs: along `u = (1, 1)/√2` it is the scalar
/// fading filter of `y = √2 u + ν` (`z_n = θ z_{n−1} + 2` from `z_0 = 1`, gain `(1/z_n)(1, 1)ᵀ`,
/// true variance `s_n = (1 − 2/z_n)² s_{n−1} + 2/z_n²` → `(1−θ)/(2(1+θ))`), while `v` keeps its
/// prior variance 1 for ever (its `P` grows as `θ^{−n}`). Oracle: those scalar recursions; θ =
/// 0.8, prior `I`, n = 1..80: gain (relative) and covariance (of `sqrt(S_ii S_jj)`) within
/// `1e-14 θ^{−n}`: the growing `P` costs the gain digits (`P Mᵀ` cancels its unobservable
/// part; at n = 80 `θ^{−n}` is 6e7). Measured at most `1.2e-15 θ^{−n}`, printed: there is no
/// steady state to reach, and a long run loses the gain entirely (`θ^{−n} ε ≈ 1` near n = 160).
#[test]
fn ex_14_9a_singular_z_infinity() {
    let theta: f64 = 0.8;
    let mut f = KalmanFilter::new(
        PolynomialDynamics::new(0, 2),
        LinearObservation::new(m(1, 2, &[1.0, 1.0])).unwrap(),
        DVector::zeros(2),
        DMatrix::identity(2, 2),
        0.0,
    )
    .unwrap()
    .with_fading(Discount::PerUpdate(theta))
    .unwrap();
    let (mut z, mut s_u) = (1.0, 1.0);
    let mut worst: f64 = 0.0;
    for n in 1..=80 {
        z = theta * z + 2.0;
        s_u = (1.0 - 2.0 / z).powi(2) * s_u + 2.0 / (z * z);
        let inn = f
            .update(&meas(n as f64, &[(n as f64).cos()], &[1.0]))
            .unwrap()
            .unwrap();
        let want_h = DMatrix::from_element(2, 1, 1.0 / z);
        // S = s_u u uᵀ + 1 v vᵀ.
        let want_s = m(
            2,
            2,
            &[
                (s_u + 1.0) / 2.0,
                (s_u - 1.0) / 2.0,
                (s_u - 1.0) / 2.0,
                (s_u + 1.0) / 2.0,
            ],
        );
        let eh = (&inn.gain - &want_h).amax() / want_h.amax();
        let es = cov_err(f.covariance(), &want_s);
        // P's unobservable part is θ^{−n}: P Mᵀ cancels it, losing that many digits.
        let grow = theta.powi(-n);
        worst = worst.max(eh / grow).max(es / grow);
        assert!(
            eh < 1e-14 * grow,
            "n {n}: H {} against {want_h} ({eh:e})",
            inn.gain
        );
        assert!(
            es < 1e-14 * grow,
            "n {n}: S {} against {want_s} ({es:e})",
            f.covariance()
        );
    }
    let limit_u = (1.0 - theta) / (2.0 * (1.0 + theta));
    assert!((s_u / limit_u - 1.0).abs() < 1e-6, "the oracle's limit");
    let s = f.covariance();
    let v_var = (s[(0, 0)] + s[(1, 1)] - 2.0 * s[(0, 1)]) / 2.0;
    assert!(
        (v_var - 1.0).abs() < 1e-12,
        "v keeps its prior variance: {v_var}"
    );
    println!("worst: {worst:e}");
}

/// A scalar `ẋ = a x` (`Φ = e^{aτ}`, τ = 1) filtered with time-based fading β (β = 1: the plain
/// Kalman filter, no discount), prior `p_0 = 2` at t = 0, one observation `y = x + ν` per unit
/// time with variances `var(n)`; returns per n the gain, the true variance and the oracle's
/// `p_{n,n}` and `s*_{n,n}`: `p_n⁻¹ = β^τ e^{−2aτ} p_{n−1}⁻¹ + 1/σ_n²` ((14.7.6) as Ex.
/// 14.14/14.15 write it), `h_n = p_n/σ_n²` (14.4.29), and Joseph's
/// `s_n = (1 − h_n)² e^{2aτ} s_{n−1} + h_n² σ_n²` (14.4.32).
fn scalar_run(
    a: f64,
    beta: f64,
    updates: usize,
    var: impl Fn(usize) -> f64,
) -> Vec<(f64, f64, f64, f64)> {
    let dynamics = LinearDynamics::new(m(1, 1, &[a])).unwrap();
    let mut f = KalmanFilter::new(
        dynamics,
        LinearObservation::value_of(1),
        DVector::zeros(1),
        m(1, 1, &[2.0]),
        0.0,
    )
    .unwrap();
    if beta < 1.0 {
        f = f.with_fading(Discount::PerTime(beta)).unwrap();
    }
    let c = beta * (-2.0 * a).exp();
    let (mut zinv, mut s) = (0.5, 2.0);
    let mut out = Vec::new();
    for n in 1..=updates {
        let v = var(n);
        zinv = c * zinv + 1.0 / v;
        let h = 1.0 / (zinv * v);
        s = (1.0 - h).powi(2) * (2.0 * a).exp() * s + h * h * v;
        let inn = f
            .update(&meas(n as f64, &[(n as f64 * 0.37).sin()], &[v]))
            .unwrap()
            .unwrap();
        out.push((inn.gain[(0, 0)], f.covariance()[(0, 0)], 1.0 / zinv, s));
    }
    out
}

/// Checks each step of a [`scalar_run`] with constant `σ²`: `p = h σ²` and `s*` within 1e-12
/// relative of the recursions; returns the larger error.
fn follows_the_recursion(run: &[(f64, f64, f64, f64)], sigma2: f64, beta: f64) -> f64 {
    let mut worst: f64 = 0.0;
    for (n, &(h, s, p, s_want)) in run.iter().enumerate() {
        let eh = (h * sigma2 / p - 1.0).abs();
        let es = (s / s_want - 1.0).abs();
        worst = worst.max(eh).max(es);
        assert!(
            eh < 1e-12,
            "β {beta} n {}: p {} against {p}",
            n + 1,
            h * sigma2
        );
        assert!(es < 1e-12, "β {beta} n {}: s* {s} against {s_want}", n + 1);
    }
    worst
}

/// Ex. 14.14: `ẋ = −x`, eigenvalue `e^{−1}` inside the unit circle: `p_n⁻¹ = β^τ e^{2τ}
/// p_{n−1}⁻¹ + m²/σ²`, so for `e^{−2} < β ≤ 1` `p_{n,n} → 0` and `s*_{n,n} → 0`, with or without
/// observations. σ² = 1/4; β = 1, 0.5 (> e^{−2}): the gain is `p_n/σ²` of the recursion within
/// 1e-12 relative and the true variance the recursion's within 1e-12 relative for n = 1..120,
/// and both fall below 1e-20 (measured, printed); β = 0.1 (< e^{−2}, outside the exercise's
/// range): `p_n → σ²(1 − β e²)`, not 0. Without observations (every measurement missing) the
/// variance is `2 e^{−2n}` (the prediction alone), within 1e-13 relative.
#[test]
fn ex_14_14_stable_scalar() {
    let sigma2 = 0.25;
    let mut worst: f64 = 0.0;
    for beta in [1.0, 0.5, 0.1] {
        let run = scalar_run(-1.0, beta, 120, |_| sigma2);
        worst = worst.max(follows_the_recursion(&run, sigma2, beta));
        let &(h, s, _, _) = run.last().unwrap();
        if beta > (-2.0f64).exp() {
            assert!(
                h * sigma2 < 1e-20 && s < 1e-20,
                "β {beta}: p {} s {s}",
                h * sigma2
            );
        } else {
            let c = beta * 2.0f64.exp();
            let want = sigma2 * (1.0 - c);
            assert!(
                (h * sigma2 / want - 1.0).abs() < 1e-12,
                "β {beta}: p {}",
                h * sigma2
            );
        }
    }
    // Without observations: s = 2 e^{−2n} → 0.
    let mut f = KalmanFilter::new(
        LinearDynamics::new(m(1, 1, &[-1.0])).unwrap(),
        LinearObservation::value_of(1),
        DVector::zeros(1),
        m(1, 1, &[2.0]),
        0.0,
    )
    .unwrap()
    .with_fading(Discount::PerTime(0.5))
    .unwrap();
    for n in 1..=60 {
        let none = Measurement {
            time: n as f64,
            values: vec![None],
            noise: NoiseCovariance::Variances(vec![sigma2]),
        };
        assert!(f.update(&none).unwrap().is_none());
        let want = 2.0 * (-2.0 * n as f64).exp();
        let e = (f.covariance()[(0, 0)] / want - 1.0).abs();
        worst = worst.max(e);
        assert!(
            e < 1e-13,
            "n {n}: {} against {want}",
            f.covariance()[(0, 0)]
        );
    }
    println!("worst: {worst:e}");
}

/// Ex. 14.15: `ẋ = x`, eigenvalue `e` outside the unit circle: `p_n⁻¹ = β^τ e^{−2τ} p_{n−1}⁻¹ +
/// m²/σ²`, `lim p_{n,n} = σ²(1 − β^τ e^{−2τ})` (m = 1), not 0 even for β = 1 (then `p` is the
/// Kalman filter's variance). (c) With `σ_n² = α/n` and β = 1, `s*_{n,n} → 0`. σ² = 1/4, β = 1,
/// 0.7; α = 3: the gain and true variance follow the recursions within 1e-12 relative (n =
/// 1..60; (c) n = 1..2000), the limit within 1e-13 relative at n = 60, and in (c) `n s_n` within
/// 1e-3 of `α(1 − e^{−2})` at n = 2000 (its limit; measured, printed).
#[test]
fn ex_14_15_unstable_scalar() {
    let sigma2 = 0.25;
    let mut worst: f64 = 0.0;
    for beta in [1.0, 0.7] {
        let run = scalar_run(1.0, beta, 60, |_| sigma2);
        worst = worst.max(follows_the_recursion(&run, sigma2, beta));
        let &(h, s, _, _) = run.last().unwrap();
        let want = sigma2 * (1.0 - beta * (-2.0f64).exp());
        assert!(
            (h * sigma2 / want - 1.0).abs() < 1e-13,
            "β {beta}: p {}",
            h * sigma2
        );
        if beta == 1.0 {
            assert!((s / want - 1.0).abs() < 1e-13, "β = 1: S = P = {s}");
        }
    }
    let alpha = 3.0;
    let run = scalar_run(1.0, 1.0, 2000, |n| alpha / n as f64);
    for (n, &(h, s, p, s_want)) in run.iter().enumerate() {
        let v = alpha / (n + 1) as f64;
        let eh = (h * v / p - 1.0).abs();
        let es = (s / s_want - 1.0).abs();
        worst = worst.max(eh).max(es);
        assert!(eh < 1e-12 && es < 1e-12, "(c) n {}: {eh:e} {es:e}", n + 1);
    }
    let s = run.last().unwrap().1;
    let ns = 2000.0 * s / (alpha * (1.0 - (-2.0f64).exp()));
    assert!((ns - 1.0).abs() < 1e-3, "(c): n s_n / α(1 − e^-2) = {ns}");
    println!("worst: {worst:e}; (c) n s_n / α(1 − e^-2) at n = 2000: {ns}");
}

/// A fixed run of a degree-2 model on two axes observed in both positions (full `R`, some
/// components missing), irregular times, with white-noise-jerk driving noise of density `q`
/// (`None`: no driving noise at all); the states, covariances and gains after every update.
type Trace = Vec<(DVector<f64>, DMatrix<f64>, Option<DMatrix<f64>>)>;

fn driven_run(q: Option<f64>) -> Trace {
    let mut obs = DMatrix::zeros(2, 6);
    obs[(0, 0)] = 1.0;
    obs[(1, 1)] = 1.0;
    let x0 = DVector::from_vec(vec![1.0, -2.0, 0.5, 0.25, 0.0, -0.1]);
    let s0 = DMatrix::from_diagonal(&DVector::from_vec(vec![4.0, 4.0, 1.0, 1.0, 0.25, 0.25]));
    let mut f = KalmanFilter::new(
        PolynomialDynamics::new(2, 2),
        LinearObservation::new(obs).unwrap(),
        x0,
        s0,
        0.0,
    )
    .unwrap();
    if let Some(q) = q {
        f = f
            .with_process_noise(WhiteNoiseDerivative::new(2, 2, q).unwrap())
            .unwrap();
    }
    let mut t = 0.0;
    let mut out = Vec::new();
    for k in 0..40 {
        t += 0.2 + 0.1 * ((k * 5 % 7) as f64);
        let a = (k % 6 != 4).then_some(t + 0.3 * ((k as f64) * 1.3).sin());
        let b = (k % 4 != 1).then_some(-2.0 + 0.2 * t * t + 0.3 * ((k as f64) * 0.7).cos());
        let inn = f
            .update(&Measurement {
                time: t,
                values: vec![a, b],
                noise: NoiseCovariance::Full(m(2, 2, &[0.5, 0.1, 0.1, 0.3])),
            })
            .unwrap();
        out.push((
            f.state().clone(),
            f.covariance().clone(),
            inn.map(|i| i.gain),
        ));
    }
    out
}

/// Ch. 15 with `Q = 0` reproduces ch. 12: (15.4.11) differs from (12.2.16) only by `Q`, so
/// driving noise of density 0 gives the plain filter bit for bit (states, covariances, gains
/// after each of 40 updates). Continuity (§15.4: scaling the perturbation by α scales `Q` by α²,
/// α → 0 gives ch. 12): `S(q) − S(0)` is positive semidefinite (the Riccati map is monotone in
/// `Q`; smallest eigenvalue ≥ −1e-14 of `|S|`, q = 1e-6, 1e-7, 1e-8) and `S(q) = S(0) + q D +
/// O(q²)`: `(S(q) − S(0))/q` at q = 1e-7 and 1e-8 agree within 1e-3 relative (measured 5.0e-4)
/// and their difference is a tenth of that between 1e-6 and 1e-7 (ratio within 8..12: the
/// second-order term, not rounding); the same for the states (measured, printed).
#[test]
fn q_zero_reproduces_chapter_12() {
    let plain = driven_run(None);
    let zero = driven_run(Some(0.0));
    assert_eq!(plain, zero, "q = 0 is the plain filter, bit for bit");
    let qs = [1e-6, 1e-7, 1e-8];
    let runs: Vec<Trace> = qs.iter().map(|&q| driven_run(Some(q))).collect();
    // e[w]: the largest relative difference of (S(q) − S(0))/q (or of the state's) between
    // qs[w] and qs[w + 1] over the checked updates.
    let (mut es, mut exs) = ([0.0f64; 2], [0.0f64; 2]);
    for k in (4..40).step_by(5) {
        let (x0, s0, _) = &plain[k];
        for (w, run) in runs.iter().enumerate() {
            let diff = &run[k].1 - s0;
            let least = diff.clone().symmetric_eigenvalues().min();
            assert!(
                least >= -1e-14 * s0.amax(),
                "q {} update {k}: S(q) − S(0) has {least:e}",
                qs[w]
            );
        }
        for w in 0..2 {
            let d1 = (&runs[w][k].1 - s0) / qs[w];
            let d2 = (&runs[w + 1][k].1 - s0) / qs[w + 1];
            es[w] = es[w].max((&d1 - &d2).amax() / d1.amax());
            let dx1 = (&runs[w][k].0 - x0) / qs[w];
            let dx2 = (&runs[w + 1][k].0 - x0) / qs[w + 1];
            exs[w] = exs[w].max((&dx1 - &dx2).amax() / dx1.amax());
        }
    }
    println!("dS/dq differences {es:?}, dX/dq {exs:?}");
    for (what, e) in [("S", es), ("X", exs)] {
        assert!(
            e[1] < 1e-3,
            "{what}: (S(q) − S(0))/q does not settle: {e:?}"
        );
        let ratio = e[0] / e[1];
        assert!(
            (8.0..12.0).contains(&ratio),
            "{what}: not first order in q: {e:?}"
        );
    }
}

/// Diagonal driving noise `Q(ζ) = |ζ| diag(q)` (a diagonal positive `Q`, §15.5's usual practice).
#[derive(Debug)]
struct Diagonal(Vec<f64>);

impl ProcessNoise for Diagonal {
    fn dimension(&self) -> usize {
        self.0.len()
    }

    fn covariance(&self, t_a: f64, t_b: f64) -> Result<DMatrix<f64>, Error> {
        let z = (t_b - t_a).abs();
        Ok(DMatrix::from_diagonal(&DVector::from_iterator(
            self.0.len(),
            self.0.iter().map(|q| q * z),
        )))
    }
}

fn to_q(a: &DMatrix<f64>) -> DMatrix<Rational> {
    a.map(|v| Rational::from_float(v).unwrap())
}

fn perfect_x0(t: f64, y: f64) -> Measurement {
    meas(t, &[y], &[0.0])
}

/// §15.5 against §12.4's "once singular, always singular" (12.4.9), on Ex. 12.13: a degree-2
/// state with `S_{n,n−1} = ones(3, 3)` and a perfect observation of `x₀` gives `S_{n,n} = 0`.
/// Without driving noise it stays 0 through predictions and ordinary updates, and a second
/// perfect observation cannot be incorporated (`V = 0`, refused, the filter unchanged). With a
/// diagonal positive `Q = diag(1/2, 1/4, 1/8) ζ`, `S_{n+1,n} = Q` exactly, positive definite; a
/// second perfect observation is then taken (`S = diag(0, 1/4, 1/8)` exactly), and over 20
/// cycles of (predict, perfect observation) every `S_{n,n−1}` has its smallest eigenvalue at
/// least `λ_min(Q) = 1/8` (`Φ S Φᵀ ⪰ 0`) and equals the exact rational recursion within 1e-14
/// of `sqrt(S_ii S_jj)` (`S_{n,n}` within 1e-14 of the largest entry; measured, printed). The same from Ex. 12.12's singular
/// `S_{n,n} = [[0, 0], [0, c − b²/a]]` with the (non-diagonal, positive definite) white-noise
/// `Q` of a constant-velocity model.
#[test]
fn diagonal_q_restores_positive_definiteness() {
    // Without Q: once singular, always singular.
    let mut f = KalmanFilter::new(
        PolynomialDynamics::new(2, 1),
        LinearObservation::value_of(3),
        DVector::zeros(3),
        DMatrix::from_element(3, 3, 1.0),
        0.0,
    )
    .unwrap();
    f.update(&perfect_x0(0.0, 1.0)).unwrap();
    assert_eq!(f.covariance(), &DMatrix::zeros(3, 3), "Ex. 12.13: S = 0");
    f.update(&meas(1.0, &[2.0], &[1.0])).unwrap();
    assert_eq!(f.covariance(), &DMatrix::zeros(3, 3), "(12.4.9): stays 0");
    let before = f.state().clone();
    assert!(f.update(&perfect_x0(2.0, 3.0)).is_err(), "0/0 is refused");
    assert_eq!(
        (f.state(), f.time()),
        (&before, 1.0),
        "and the filter is unchanged"
    );

    // With a diagonal positive Q.
    let q = [0.5, 0.25, 0.125];
    let mut f = KalmanFilter::new(
        PolynomialDynamics::new(2, 1),
        LinearObservation::value_of(3),
        DVector::zeros(3),
        DMatrix::from_element(3, 3, 1.0),
        0.0,
    )
    .unwrap()
    .with_process_noise(Diagonal(q.to_vec()))
    .unwrap();
    f.update(&perfect_x0(0.0, 1.0)).unwrap();
    assert_eq!(f.covariance(), &DMatrix::zeros(3, 3));
    let mut predicted = f.clone();
    predicted.predict(1.0).unwrap();
    let qd = DMatrix::from_diagonal(&DVector::from_row_slice(&q));
    assert_eq!(predicted.covariance(), &qd, "S_{{n+1,n}} = Φ 0 Φᵀ + Q = Q");
    f.update(&perfect_x0(1.0, 2.0)).unwrap();
    let want = DMatrix::from_diagonal(&DVector::from_vec(vec![0.0, 0.25, 0.125]));
    // (I − H M) with H₀ = 1 from V's Cholesky factor: rounding leaves 6e-33 where 0 is exact.
    assert!(
        (f.covariance() - &want).amax() < 1e-16 * want.amax(),
        "a second perfect observation is taken: {}",
        f.covariance()
    );

    // 20 cycles against the exact recursion: S ← Φ S Φᵀ + Q, then (I − e₀ e₀ᵀ S/S₀₀) S.
    let phi = to_q(&PolynomialDynamics::new(2, 1).transition(1.0));
    let mut s = to_q(&want);
    let mut worst: f64 = 0.0;
    for n in 2..22 {
        let mut pred = mm(&mm(&phi, &s), &phi.transpose());
        for (i, qi) in q.iter().enumerate() {
            pred[(i, i)] += Rational::from_float(*qi).unwrap();
        }
        let mut p = f.clone();
        p.predict(n as f64).unwrap();
        let want_pred = to_f64(&pred);
        let e = cov_err(p.covariance(), &want_pred);
        worst = worst.max(e);
        assert!(e < 1e-14, "n {n}: S_{{n,n-1}} {e:e}");
        let least = p.covariance().clone().symmetric_eigenvalues().min();
        assert!(least >= 0.125 * (1.0 - 1e-12), "n {n}: λ_min {least}");
        assert!(p.covariance().clone().cholesky().is_some());
        f.update(&perfect_x0(n as f64, n as f64)).unwrap();
        // The exact perfect update: S − S e₀ e₀ᵀ S / S₀₀.
        let col = pred.columns(0, 1).clone_owned();
        let outer = mm(&col, &col.transpose()).map(|v| v / pred[(0, 0)].clone());
        s = pred.clone() - outer;
        assert!(s.row(0).iter().all(|v| v.is_zero()));
        let e = (f.covariance() - to_f64(&s)).amax() / want_pred.amax();
        worst = worst.max(e);
        assert!(e < 1e-14, "n {n}: S_{{n,n}} {e:e}");
    }

    // Ex. 12.12's singular S with the white-noise Q of a constant-velocity model.
    let (a, b, c) = (2.0, 1.0, 3.0);
    let mut f = KalmanFilter::new(
        PolynomialDynamics::new(1, 1),
        LinearObservation::value_of(2),
        DVector::zeros(2),
        m(2, 2, &[a, b, b, c]),
        0.0,
    )
    .unwrap()
    .with_process_noise(WhiteNoiseDerivative::new(1, 1, 0.1).unwrap())
    .unwrap();
    f.update(&perfect_x0(0.0, 1.0)).unwrap();
    let want = m(2, 2, &[0.0, 0.0, 0.0, c - b * b / a]);
    assert!(
        (f.covariance() - &want).amax() < 1e-15,
        "Ex. 12.12: {}",
        f.covariance()
    );
    let q_one = WhiteNoiseDerivative::new(1, 1, 0.1)
        .unwrap()
        .covariance(0.0, 1.0)
        .unwrap();
    let q_least = q_one.clone().symmetric_eigenvalues().min();
    assert!(q_least > 0.0);
    for n in 1..=10 {
        let mut p = f.clone();
        p.predict(n as f64).unwrap();
        let least = p.covariance().clone().symmetric_eigenvalues().min();
        assert!(
            least >= q_least * (1.0 - 1e-12),
            "n {n}: λ_min {least} < {q_least}"
        );
        f.update(&perfect_x0(n as f64, 1.0 + n as f64)).unwrap();
    }
    println!("worst: {worst:e}");
}
