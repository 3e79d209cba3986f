//! Morrison ch. 10 (the Bayes filter) conformance: the exercises that `kalman_bayes.rs` does
//! not cover — Ex. 10.22 (a static state, three observation matrices), Ex. 10.23 (a
//! constant-velocity state in three axes observed in one or three positions), Ex. 10.24 (the
//! oscillator of Example 8.2 at ω = π/4 and ω = π), Ex. 10.9 (the time-varying `A(t)` whose
//! transition matrix is known in closed form), Ex. 10.4 (scale invariance), Ex. 10.13/10.14
//! (fusing independent estimates, one at a time or in one batch) and Ex. 10.8 (an almost
//! perfect estimate learns nothing from a new observation).
//!
//! Each runs the library's [`BayesFilter`] (square-root information form) and, where the
//! exercise is about the covariance recursion (10.2.51)-(10.2.55), also the [`KalmanFilter`]
//! (algebraically the same filter, (12.2.15)-(12.2.19)), against an oracle written here:
//! exact rational arithmetic where the exercise's numbers are exact, the book's closed form
//! otherwise, or a direct dense computation of (10.2.42) with the book's `Φ`.
//!
//! Misprints: none of the book's recorded misprints touches these exercises ((10.3.7)'s lower
//! block, (10.5.11) and the display matrices of (10.2.45)/(10.2.49) are not used here; the
//! prediction of a covariance is (10.5.9), `Φ S Φᵀ`). Ex. 10.22 prints the observation variance
//! as σ² in (a) and σ_ν² in (b): the same quantity. The book does not state `τ` or `R` for
//! Ex. 10.23; `τ = 1`, `R = 1` here (as for Figs. 10.1/10.2).

mod common;

use common::kalman::cov_err;
use common::rational::{eye, fr, inv, mm, to_f64, z, Q};
use nalgebra::{DMatrix, DVector};
use num_traits::Zero;
use seqsmooth::kalman::{BayesFilter, KalmanFilter};
use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
use seqsmooth::model::linear::LinearDynamics;
use seqsmooth::model::measurement::Measurement;
use seqsmooth::model::measurement::NoiseCovariance;
use seqsmooth::model::nonlinear::NonlinearDynamics;
use seqsmooth::model::observation::LinearObservation;
use std::f64::consts::PI;

fn m(rows: usize, cols: usize, v: &[f64]) -> DMatrix<f64> {
    DMatrix::from_row_slice(rows, cols, v)
}

fn qm(rows: usize, cols: usize, v: &[Q]) -> DMatrix<Q> {
    DMatrix::from_fn(rows, cols, |i, j| v[i * cols + j].clone())
}

fn meas(t: f64, values: &[f64], noise: NoiseCovariance) -> Measurement {
    Measurement {
        time: t,
        values: values.iter().map(|&v| Some(v)).collect(),
        noise,
    }
}

/// The exact Bayes filter in information form over the rationals ((10.2.51)-(10.2.55) as
/// (11.3.3)-(11.3.4)): `J ← Φ⁻ᵀ J Φ⁻¹`, `h ← Φ⁻ᵀ h` to predict, `J += Mᵀ R⁻¹ M`,
/// `h += Mᵀ R⁻¹ Y` to update; `S = J⁻¹`, `X = J⁻¹ h`. Written here, independent of the
/// library.
struct ExactBayes {
    j: DMatrix<Q>,
    h: DMatrix<Q>,
}

impl ExactBayes {
    fn new(x0: &DMatrix<Q>, s0: &DMatrix<Q>) -> Self {
        let j = inv(s0);
        let h = mm(&j, x0);
        Self { j, h }
    }

    /// Predict with `Φ⁻¹` (the book's `Ψ`, (11.3.3)).
    fn predict(&mut self, psi: &DMatrix<Q>) {
        let pt = psi.transpose();
        self.j = mm(&mm(&pt, &self.j), psi);
        self.h = mm(&pt, &self.h);
    }

    fn update(&mut self, obs: &DMatrix<Q>, r_inv: &DMatrix<Q>, y: &DMatrix<Q>) {
        let mtr = mm(&obs.transpose(), r_inv);
        self.j += mm(&mtr, obs);
        self.h += mm(&mtr, y);
    }

    fn covariance(&self) -> DMatrix<Q> {
        inv(&self.j)
    }

    fn estimate(&self) -> DMatrix<Q> {
        mm(&inv(&self.j), &self.h)
    }
}

/// Observations `y_k` for the static-state tests: dyadic, so that they are exact rationals.
fn y_value(k: usize) -> f64 {
    ((k * 37 % 23) as f64 - 11.0) / 8.0
}

/// T10-3, Ex. 10.22: `Φ = I`, observations of variance σ², prior `S_{0,0} = diag(α², β²)` (α² =
/// 2, β² = 3, σ² = 1/2, prior state (1, −2)), cycling (10.2.52)-(10.2.53) n = 1..2000 times:
/// (a) `M = (1, 0)`: `S_{n,n} = diag(1/(1/α² + n/σ²), β²)` — x₁ never improves;
/// (b) `M = (1, 1)`: `S_{n,n}⁻¹ = [[1/α² + n/σ², n/σ²], [n/σ², 1/β² + n/σ²]]`, so
/// `S_{n,n} → [[1, −1], [−1, 1]]/(1/α² + 1/β²)`: the uncertainty never disappears;
/// (c) `M = I`: `S_{n,n} → 0`.
/// Oracle: the exercise's closed forms in exact rationals (and the estimate, exact, from the
/// same information). Both filters; covariance within 1e-12 of `sqrt(S_ii S_jj)`, the estimate
/// within 1e-12 of its σ (measured 3.9e-15 Bayes, 1.9e-14 Kalman, printed).
#[test]
fn t10_3_ex_10_22_static_state() {
    let (a2, b2, s2) = (z(2), z(3), fr(1, 2));
    let x0 = qm(2, 1, &[z(1), z(-2)]);
    let s0 = qm(2, 2, &[a2.clone(), z(0), z(0), b2.clone()]);
    let cases: [(&str, DMatrix<f64>); 3] = [
        ("(a) M = (1, 0)", m(1, 2, &[1.0, 0.0])),
        ("(b) M = (1, 1)", m(1, 2, &[1.0, 1.0])),
        ("(c) M = I", DMatrix::identity(2, 2)),
    ];
    let checkpoints = [1, 2, 3, 5, 10, 50, 100, 500, 1000, 2000];
    let (mut worst_bayes, mut worst_kalman): (f64, f64) = (0.0, 0.0);
    for (name, obs) in cases {
        let p = obs.nrows();
        let noise = NoiseCovariance::Variances(vec![0.5; p]);
        let x0f = DVector::from_vec(vec![1.0, -2.0]);
        let s0f = m(2, 2, &[2.0, 0.0, 0.0, 3.0]);
        let mut bayes = BayesFilter::new(
            PolynomialDynamics::new(0, 2),
            LinearObservation::new(obs.clone()).unwrap(),
            0.0,
        )
        .unwrap()
        .with_prior(&x0f, &s0f)
        .unwrap();
        let mut kalman = KalmanFilter::new(
            PolynomialDynamics::new(0, 2),
            LinearObservation::new(obs.clone()).unwrap(),
            x0f,
            s0f,
            0.0,
        )
        .unwrap();
        let obs_q = obs.map(|v| z(v as i64));
        let r_inv = eye(p) * (z(1) / s2.clone());
        let mut exact = ExactBayes::new(&x0, &s0);
        let mut ys = Q::zero();
        for n in 1..=2000usize {
            let y: Vec<f64> = (0..p).map(|c| y_value(n * p + c)).collect();
            let yq = DMatrix::from_fn(p, 1, |i, _| Q::from_float(y[i]).unwrap());
            ys += yq[(0, 0)].clone();
            exact.update(&obs_q, &r_inv, &yq);
            bayes.update(&meas(n as f64, &y, noise.clone())).unwrap();
            kalman.update(&meas(n as f64, &y, noise.clone())).unwrap();
            if !checkpoints.contains(&n) {
                continue;
            }
            let nq = z(n as i64);
            // The exercise's closed form of the information (10.2.42).
            let info = match p {
                1 if obs[(0, 1)] == 0.0 => qm(
                    2,
                    2,
                    &[
                        z(1) / a2.clone() + nq.clone() / s2.clone(),
                        z(0),
                        z(0),
                        z(1) / b2.clone(),
                    ],
                ),
                1 => {
                    let c = nq.clone() / s2.clone();
                    qm(
                        2,
                        2,
                        &[
                            z(1) / a2.clone() + c.clone(),
                            c.clone(),
                            c.clone(),
                            z(1) / b2.clone() + c,
                        ],
                    )
                }
                _ => qm(
                    2,
                    2,
                    &[
                        z(1) / a2.clone() + nq.clone() / s2.clone(),
                        z(0),
                        z(0),
                        z(1) / b2.clone() + nq.clone() / s2.clone(),
                    ],
                ),
            };
            assert_eq!(info, exact.j, "{name}: the closed form is the recursion");
            let want_s = to_f64(&inv(&info));
            let want_x = to_f64(&exact.estimate());
            if p == 1 && obs[(0, 1)] == 0.0 {
                // (a): x₀ = (x₀,prior/α² + Σy/σ²)/(1/α² + n/σ²), x₁ stays at its prior.
                let x = (z(1) / a2.clone() + ys.clone() / s2.clone())
                    / (z(1) / a2.clone() + nq.clone() / s2.clone());
                assert_eq!(x, exact.estimate()[(0, 0)]);
                assert_eq!(exact.estimate()[(1, 0)], z(-2));
            }
            for (who, s, x, worst) in [
                (
                    "Bayes",
                    bayes.covariance().unwrap(),
                    bayes.estimate().unwrap(),
                    &mut worst_bayes,
                ),
                (
                    "Kalman",
                    kalman.covariance().clone(),
                    kalman.state().clone(),
                    &mut worst_kalman,
                ),
            ] {
                let e = cov_err(&s, &want_s);
                let ex = (0..2)
                    .map(|i| (x[i] - want_x[(i, 0)]).abs() / want_s[(i, i)].sqrt())
                    .fold(0.0, f64::max);
                *worst = worst.max(e).max(ex);
                assert!(
                    e < 1e-12,
                    "{name} {who} n {n}: S {s} against {want_s} ({e:e})"
                );
                assert!(
                    ex < 1e-12,
                    "{name} {who} n {n}: X {x} against {want_x} ({ex:e})"
                );
            }
            if n == 2000 {
                let s = bayes.covariance().unwrap();
                match name.as_bytes()[1] {
                    b'a' => {
                        assert!(s[(0, 0)] < 3e-4 && (s[(1, 1)] - 3.0).abs() < 1e-12, "{s}")
                    }
                    b'b' => {
                        // → [[1, −1], [−1, 1]]/(1/2 + 1/3) = 1.2 [[1, −1], [−1, 1]]; the
                        // distance at n is O(1/n): exact 6e-4 here.
                        let limit = m(2, 2, &[1.2, -1.2, -1.2, 1.2]);
                        let gap = (&want_s - &limit).amax();
                        assert!(gap < 1e-3, "the oracle's approach {gap}");
                        assert!((&s - &limit).amax() < gap * (1.0 + 1e-9), "{s}");
                        assert!(
                            s[(0, 0)] > 1.19 && s[(1, 1)] > 1.19,
                            "never disappears: {s}"
                        );
                    }
                    _ => assert!(s.amax() < 3e-4, "→ 0: {s}"),
                }
            }
        }
    }
    println!("worst: Bayes {worst_bayes:e}, Kalman {worst_kalman:e}");
}

/// T10-6, Ex. 10.23: `X = (x, y, z, ẋ, ẏ, ż)`, `dX/dt = (ẋ, ẏ, ż, 0, 0, 0)`, `S_{1,0} = I`,
/// one observation per unit step. (a) `M = (0, 0, 1, 0, 0, 0)`: z and ż become known exactly,
/// x and y deteriorate without bound; (b) `M = [I₃ | 0]`: `S_{n,n} → 0`.
/// Oracle: the information recursion in exact rationals (`Φ(1)⁻¹ = Φ(−1)`); and the closed
/// forms it must agree with: for an unobserved axis `S = [[1 + (n−1)², n−1], [n−1, 1]]`
/// ((10.5.9) with `Φ(n−1)`); for an observed one, `J_n = Φ(1−n)ᵀΦ(1−n) + Σ_{j<n} (1, −j)ᵀ(1, −j)`
/// (Fig. 10.2's sequence (1/2, 1), (3/5, 3/5), (2/3, 4/15), …). Both filters, n = 1..200,
/// within 1e-12 of `sqrt(S_ii S_jj)` (measured 8.5e-16 Bayes, 4.9e-15 Kalman, printed);
/// cross-axis covariances stay exactly 0 in the oracle.
#[test]
fn t10_6_ex_10_23_constant_velocity_in_three_axes() {
    // The library's state order is derivative-major: (x, y, z, ẋ, ẏ, ż), as the exercise's.
    let dynamics = PolynomialDynamics::new(1, 3);
    let phi = dynamics.transition(1.0);
    let phi_inv_q = to_q(&dynamics.transition(-1.0));
    assert_eq!(
        phi,
        m(
            6,
            6,
            &[
                1., 0., 0., 1., 0., 0., //
                0., 1., 0., 0., 1., 0., //
                0., 0., 1., 0., 0., 1., //
                0., 0., 0., 1., 0., 0., //
                0., 0., 0., 0., 1., 0., //
                0., 0., 0., 0., 0., 1.,
            ]
        )
    );
    let mut zm = DMatrix::zeros(1, 6);
    zm[(0, 2)] = 1.0;
    let mut xyz = DMatrix::zeros(3, 6);
    for a in 0..3 {
        xyz[(a, a)] = 1.0;
    }
    let (mut worst_bayes, mut worst_kalman): (f64, f64) = (0.0, 0.0);
    for (name, obs) in [("(a) z only", zm), ("(b) x, y, z", xyz)] {
        let p = obs.nrows();
        let noise = NoiseCovariance::Variances(vec![1.0; p]);
        let mut bayes =
            BayesFilter::new(dynamics, LinearObservation::new(obs.clone()).unwrap(), 1.0)
                .unwrap()
                .with_prior(&DVector::zeros(6), &DMatrix::identity(6, 6))
                .unwrap();
        let mut kalman = KalmanFilter::new(
            dynamics,
            LinearObservation::new(obs.clone()).unwrap(),
            DVector::zeros(6),
            DMatrix::identity(6, 6),
            1.0,
        )
        .unwrap();
        let mut exact = ExactBayes::new(&DMatrix::from_element(6, 1, z(0)), &eye(6));
        let obs_q = to_q(&obs);
        for n in 1..=200usize {
            if n > 1 {
                exact.predict(&phi_inv_q);
            }
            let y = vec![0.0; p];
            exact.update(&obs_q, &eye(p), &DMatrix::from_element(p, 1, z(0)));
            bayes.update(&meas(n as f64, &y, noise.clone())).unwrap();
            kalman.update(&meas(n as f64, &y, noise.clone())).unwrap();
            if !(n <= 10 || n % 50 == 0 || n == 199) {
                continue;
            }
            let sq = exact.covariance();
            // The closed forms, per axis (indices a and a + 3).
            let k = z(n as i64 - 1);
            let observed_axis = |a: usize| obs.row_iter().any(|r| r[a] != 0.0);
            for a in 0..3 {
                let block = qm(
                    2,
                    2,
                    &[
                        sq[(a, a)].clone(),
                        sq[(a, a + 3)].clone(),
                        sq[(a + 3, a)].clone(),
                        sq[(a + 3, a + 3)].clone(),
                    ],
                );
                let want = if observed_axis(a) {
                    let pr = qm(2, 2, &[z(1), -k.clone(), z(0), z(1)]); // Φ(1 − n)
                    let mut j = mm(&pr.transpose(), &pr);
                    for jj in 0..n as i64 {
                        let row = qm(1, 2, &[z(1), z(-jj)]);
                        j += mm(&row.transpose(), &row);
                    }
                    inv(&j)
                } else {
                    qm(
                        2,
                        2,
                        &[z(1) + k.clone() * k.clone(), k.clone(), k.clone(), z(1)],
                    )
                };
                assert_eq!(block, want, "{name} n {n} axis {a}: the closed form");
                for b in 0..3 {
                    if b != a {
                        for (i, j) in [(a, b), (a, b + 3), (a + 3, b), (a + 3, b + 3)] {
                            assert!(sq[(i, j)].is_zero());
                        }
                    }
                }
            }
            let want = to_f64(&sq);
            if n <= 5 && observed_axis(2) {
                // Fig. 10.2 (the notes' T10-2, M = (1, 0)): (S_zz, S_żż).
                let fig = [
                    (1.0 / 2.0, 1.0),
                    (3.0 / 5.0, 3.0 / 5.0),
                    (2.0 / 3.0, 4.0 / 15.0),
                    (8.0 / 13.0, 5.0 / 39.0),
                    (47.0 / 86.0, 3.0 / 43.0),
                ];
                assert_eq!((want[(2, 2)], want[(5, 5)]), fig[n - 1], "n {n}");
            }
            for (who, s, worst) in [
                ("Bayes", bayes.covariance().unwrap(), &mut worst_bayes),
                ("Kalman", kalman.covariance().clone(), &mut worst_kalman),
            ] {
                let e = cov_err(&s, &want);
                *worst = worst.max(e);
                assert!(e < 1e-12, "{name} {who} n {n}: {e:e}\n{s}\nagainst\n{want}");
            }
            if n == 200 {
                let s = bayes.covariance().unwrap();
                assert!(
                    s[(2, 2)] < 0.02 && s[(5, 5)] < 2e-6,
                    "{name}: z, ż → 0: {s}"
                );
                if observed_axis(0) {
                    assert!(s.diagonal().amax() < 0.02, "{name}: S → 0: {s}");
                } else {
                    // 1 + 199²: x and y deteriorate without bound.
                    assert!((s[(0, 0)] / 39602.0 - 1.0).abs() < 1e-11, "{name}: {s}");
                    assert!((s[(1, 1)] / 39602.0 - 1.0).abs() < 1e-11, "{name}: {s}");
                }
            }
        }
    }
    println!("worst: Bayes {worst_bayes:e}, Kalman {worst_kalman:e}");
}

fn to_q(a: &DMatrix<f64>) -> DMatrix<Q> {
    a.map(|v| Q::from_float(v).unwrap())
}

/// The oscillator of Example 8.2, `ẍ = −ω² x`, `X = (x, ẋ)`:
/// `Φ(ζ) = [[cos ωζ, sin(ωζ)/ω], [−ω sin ωζ, cos ωζ]]` (the book's form, Ex. 10.21).
fn oscillator_phi(w: f64, zeta: f64) -> DMatrix<f64> {
    let (s, c) = (w * zeta).sin_cos();
    m(2, 2, &[c, s / w, -w * s, c])
}

/// T10-7, Ex. 10.24: the oscillator of Example 8.2 with ω = π/4, ζ = 1, `S_{1,0} = I`, `R = 1`.
/// (a) `M = (1, 0)` and (b) `M = (0, 1)` both give `S_{n,n} → 0`; (c) with ω = π (`Φ(1) = −I`)
/// neither does; (d) `M = I` does.
/// Oracles: (1) a direct dense computation of (10.2.42) in information form with the book's
/// `Φ` (cos/sin, not the library's `e^{ζA}`) at every n; (2) the closed form at n = 8j + 1 for
/// ω = π/4 (`Φ(−8j) = I`, and the rows `M Φ(−k)` over a period sum to `4 diag(1, 1/ω²)` for
/// `M = (1, 0)` and `4 diag(ω², 1)` for `M = (0, 1)`, cross terms zero):
/// `S = diag(1/(2 + 4j), 1/(1 + 4j/ω²))` and `diag(1/(1 + 4jω²), 1/(2 + 4j))`; for ω = π,
/// `J = diag(n + 1, 1)`, `diag(1, n + 1)`, `(n + 1) I`. Both filters, n = 1..401, within 1e-11
/// of `sqrt(S_ii S_jj)` (measured 1.4e-12, printed: the library's `e^{ζA}` and the book's
/// cos/sin differ by rounding, which 400 predictions accumulate) and the closed forms within
/// 1e-10 relative.
#[test]
fn t10_7_ex_10_24_oscillator() {
    let (mut worst_bayes, mut worst_kalman): (f64, f64) = (0.0, 0.0);
    let cases: [(f64, [f64; 4], &str); 5] = [
        (PI / 4.0, [1.0, 0.0, 0.0, 0.0], "(a) ω = π/4, M = (1, 0)"),
        (PI / 4.0, [0.0, 1.0, 0.0, 0.0], "(b) ω = π/4, M = (0, 1)"),
        (PI, [1.0, 0.0, 0.0, 0.0], "(c) ω = π, M = (1, 0)"),
        (PI, [0.0, 1.0, 0.0, 0.0], "(c) ω = π, M = (0, 1)"),
        (PI, [1.0, 0.0, 0.0, 1.0], "(d) ω = π, M = I"),
    ];
    for (w, mrow, name) in cases {
        let obs = if mrow[3] == 1.0 {
            DMatrix::identity(2, 2)
        } else {
            m(1, 2, &mrow[..2])
        };
        let p = obs.nrows();
        let noise = NoiseCovariance::Variances(vec![1.0; p]);
        let a = m(2, 2, &[0.0, 1.0, -w * w, 0.0]);
        let dynamics = LinearDynamics::new(a).unwrap();
        let mut bayes = BayesFilter::new(
            dynamics.clone(),
            LinearObservation::new(obs.clone()).unwrap(),
            1.0,
        )
        .unwrap()
        .with_prior(&DVector::zeros(2), &DMatrix::identity(2, 2))
        .unwrap();
        let mut kalman = KalmanFilter::new(
            dynamics,
            LinearObservation::new(obs.clone()).unwrap(),
            DVector::zeros(2),
            DMatrix::identity(2, 2),
            1.0,
        )
        .unwrap();
        // Oracle (1): J ← Φ(−1)ᵀ J Φ(−1), J += MᵀM.
        let back = oscillator_phi(w, -1.0);
        let mut info = DMatrix::<f64>::identity(2, 2);
        for n in 1..=401usize {
            if n > 1 {
                info = back.transpose() * &info * &back;
            }
            info += obs.transpose() * &obs;
            bayes
                .update(&meas(n as f64, &vec![0.0; p], noise.clone()))
                .unwrap();
            kalman
                .update(&meas(n as f64, &vec![0.0; p], noise.clone()))
                .unwrap();
            let dense = info.clone().try_inverse().unwrap();
            for (who, s, worst) in [
                ("Bayes", bayes.covariance().unwrap(), &mut worst_bayes),
                ("Kalman", kalman.covariance().clone(), &mut worst_kalman),
            ] {
                let e = cov_err(&s, &dense);
                *worst = worst.max(e);
                assert!(e < 1e-11, "{name} {who} n {n}: {s} against {dense} ({e:e})");
            }
            // Oracle (2): the closed forms.
            let closed = if w == PI / 4.0 {
                if n % 8 != 1 {
                    continue;
                }
                let j = ((n - 1) / 8) as f64;
                if mrow[0] == 1.0 {
                    [1.0 / (2.0 + 4.0 * j), 1.0 / (1.0 + 4.0 * j / (w * w))]
                } else {
                    [1.0 / (1.0 + 4.0 * j * w * w), 1.0 / (2.0 + 4.0 * j)]
                }
            } else {
                let k = 1.0 / (n as f64 + 1.0);
                [
                    if mrow[0] == 1.0 { k } else { 1.0 },
                    if mrow[1] == 1.0 || mrow[3] == 1.0 {
                        k
                    } else {
                        1.0
                    },
                ]
            };
            let s = bayes.covariance().unwrap();
            let sk = kalman.covariance();
            for i in 0..2 {
                for (who, got) in [("Bayes", s[(i, i)]), ("Kalman", sk[(i, i)])] {
                    assert!(
                        (got / closed[i] - 1.0).abs() < 1e-10,
                        "{name} {who} n {n} S{i}{i}: {got} against {}",
                        closed[i]
                    );
                }
                assert!(s[(0, 1)].abs() < 1e-10 * (s[(0, 0)] * s[(1, 1)]).sqrt());
            }
        }
        let s = bayes.covariance().unwrap();
        match name.as_bytes()[1] {
            b'a' | b'b' | b'd' => assert!(s.diagonal().amax() < 0.03, "{name}: → 0: {s}"),
            _ => assert!(
                (s.diagonal().amax() - 1.0).abs() < 1e-10,
                "{name}: stays: {s}"
            ),
        }
    }
    println!("worst against the dense oracle: Bayes {worst_bayes:e}, Kalman {worst_kalman:e}");
}

/// Ex. 10.9 (I)-(II): `A(t) = (1/(1 + sin t + cos t)) [[0, 1 + sin t + cos t], [−1, cos t − sin t]]`.
fn ex_10_9_a(t: f64) -> DMatrix<f64> {
    let d = 1.0 + t.sin() + t.cos();
    m(2, 2, &[0.0, 1.0, -1.0 / d, (t.cos() - t.sin()) / d])
}

/// Ex. 10.9 (IV): `P(t) = (1/2)[[1 + cos t, 1 + 2 sin t − cos t], [−sin t, 2 cos t + sin t]]`.
fn ex_10_9_p(t: f64) -> DMatrix<f64> {
    let (s, c) = t.sin_cos();
    m(2, 2, &[1.0 + c, 1.0 + 2.0 * s - c, -s, 2.0 * c + s]) * 0.5
}

/// T10-8, Ex. 10.9/10.10: the transition matrix of the time-varying `A(t)` from the library's
/// variational integration (`NonlinearDynamics::time_varying_linear`, DOP853) equals the
/// book's `Φ(t_n + ζ, t_n) = P(t_n + ζ) P(t_n)⁻¹` (V), forwards and backwards, on
/// `[0, 2.6]` (`A` is singular where `1 + sin t + cos t = 0`, t = π). The closed form is first
/// checked against its own definition (`dP/dt = A P` by central differences, `P(0) = I`).
/// At tolerances 1e-13/1e-15: within 1e-10 relative (measured, printed); the notes' computed
/// `Φ(1.5, 1.0)` to its 12 printed digits.
#[test]
fn t10_8_ex_10_9_time_varying_transition() {
    assert!((ex_10_9_p(0.0) - DMatrix::identity(2, 2)).amax() < 1e-16);
    for t in [0.1, 0.7, 1.3, 2.2] {
        let h = 1e-5;
        let dp = (ex_10_9_p(t + h) - ex_10_9_p(t - h)) / (2.0 * h);
        let e = (&dp - ex_10_9_a(t) * ex_10_9_p(t)).amax();
        assert!(e < 1e-9, "dP/dt = A P at {t}: {e:e}");
    }
    let dynamics = NonlinearDynamics::time_varying_linear(2, ex_10_9_a)
        .with_tolerances(1e-13, 1e-15)
        .unwrap();
    let mut worst: f64 = 0.0;
    let pairs = [
        (1.0, 1.5),
        (1.5, 1.0),
        (0.0, 1.0),
        (0.3, 2.6),
        (2.6, 0.3),
        (2.0, 2.05),
        (0.0, 2.5),
    ];
    for (ta, tb) in pairs {
        let x = DVector::from_vec(vec![0.7, -1.1]);
        let p = dynamics.propagate(&x, ta, tb).unwrap();
        let want = ex_10_9_p(tb) * ex_10_9_p(ta).try_inverse().unwrap();
        let e = (&p.transition - &want).amax() / want.amax();
        worst = worst.max(e);
        assert!(
            e < 1e-10,
            "Φ({tb}, {ta}): {} against {want} ({e:e})",
            p.transition
        );
        let ex = (&p.state - &want * &x).amax() / x.amax();
        assert!(ex < 1e-10, "X({tb}) from X({ta}): {ex:e}");
    }
    let p = dynamics
        .propagate(&DVector::zeros(2), 1.0, 1.5)
        .unwrap()
        .transition;
    let printed = [
        0.948602396967,
        0.463946190398,
        -0.201289325261,
        0.816960521717,
    ];
    for (k, want) in printed.iter().enumerate() {
        assert!(
            (p[(k / 2, k % 2)] - want).abs() < 5e-13 + 1e-12,
            "Φ(1.5, 1.0)[{k}]"
        );
    }
    println!("worst relative difference from P(t_b) P(t_a)⁻¹: {worst:e}");
}

/// Ex. 10.11 asks for the Bayes filter (p. 386) on the model of Ex. 10.9, which is linear
/// (`dX/dt = A(t) X`, (10.2.1)): the filter must take it.
#[test]
fn ex_10_11_bayes_filter_on_a_time_varying_linear_model() {
    let dynamics = NonlinearDynamics::time_varying_linear(2, ex_10_9_a)
        .with_tolerances(1e-13, 1e-15)
        .unwrap();
    assert!(dynamics.is_linear(), "dX/dt = A(t) X is linear");
    let mut bayes = BayesFilter::new(dynamics, LinearObservation::value_of(2), 0.0)
        .unwrap()
        .with_prior(&DVector::zeros(2), &DMatrix::identity(2, 2))
        .unwrap();
    bayes
        .update(&meas(0.5, &[1.0], NoiseCovariance::Variances(vec![1.0])))
        .unwrap();
    // (10.2.41)-(10.2.42) with the closed-form Φ(0.5, 0).
    let phi = ex_10_9_p(0.5);
    let pred = &phi * phi.transpose();
    let want = (pred.try_inverse().unwrap() + m(2, 2, &[1.0, 0.0, 0.0, 0.0]))
        .try_inverse()
        .unwrap();
    assert!(cov_err(&bayes.covariance().unwrap(), &want) < 1e-10);
}

/// A random-looking but fixed problem: a degree-2 model observed in position and acceleration
/// (full `R`), irregular times, with a prior; `lambda2` multiplies every `R` and the prior
/// covariance.
fn scaled_run(lambda2: f64, bayes: bool) -> (DVector<f64>, DMatrix<f64>) {
    let dynamics = PolynomialDynamics::new(2, 1);
    let obs = LinearObservation::new(m(2, 3, &[1.0, 0.0, 0.0, 0.0, 0.0, 1.0])).unwrap();
    let x0 = DVector::from_vec(vec![0.5, -1.0, 0.25]);
    let s0 = m(3, 3, &[4.0, 1.0, 0.5, 1.0, 2.0, 0.25, 0.5, 0.25, 1.0]) * lambda2;
    let r = m(2, 2, &[0.7, 0.2, 0.2, 0.4]) * lambda2;
    let mut kalman = KalmanFilter::new(dynamics, obs.clone(), x0.clone(), s0.clone(), 0.0).unwrap();
    let mut bf = BayesFilter::new(dynamics, obs, 0.0)
        .unwrap()
        .with_prior(&x0, &s0)
        .unwrap();
    let mut t = 0.0;
    for k in 0..30 {
        t += 0.3 + 0.05 * ((k * 7 % 11) as f64);
        let y0 = 0.5 * t * t - t + 0.3 * ((k as f64) * 1.7).sin();
        let second = (k % 3 != 0).then_some(0.8 + 0.4 * ((k as f64) * 0.9).cos());
        let z = Measurement {
            time: t,
            values: vec![Some(y0), second],
            noise: NoiseCovariance::Full(r.clone()),
        };
        if bayes {
            bf.update(&z).unwrap();
        } else {
            kalman.update(&z).unwrap();
        }
    }
    if bayes {
        (bf.estimate().unwrap(), bf.covariance().unwrap())
    } else {
        (kalman.state().clone(), kalman.covariance().clone())
    }
}

/// T10-9, Ex. 10.4: multiplying every observation covariance and the prior covariance by λ²
/// leaves `X*_{n,n}` unchanged (and multiplies `S*_{n,n}` by λ²). Oracle: the same run at
/// λ² = 1. λ² = 4 (a power of two: every operation scales exactly) and λ² = 7.3, 1e-6, 1e6:
/// the estimate within 1e-13 of max(|x|, σ), `S/λ²` within 1e-13 of `sqrt(S_ii S_jj)`
/// (measured, printed), Bayes and Kalman.
#[test]
fn t10_9_ex_10_4_scale_invariance() {
    for bayes in [true, false] {
        let who = if bayes { "Bayes" } else { "Kalman" };
        let (x1, s1) = scaled_run(1.0, bayes);
        let mut worst: f64 = 0.0;
        for lambda2 in [4.0, 7.3, 1e-6, 1e6] {
            let (x, s) = scaled_run(lambda2, bayes);
            let ex = (0..3)
                .map(|i| (x[i] - x1[i]).abs() / x1[i].abs().max(s1[(i, i)].sqrt()))
                .fold(0.0, f64::max);
            let es = cov_err(&(&s / lambda2), &s1);
            worst = worst.max(ex).max(es);
            assert!(
                ex < 1e-13,
                "{who} λ² {lambda2}: X {x} against {x1} ({ex:e})"
            );
            assert!(es < 1e-13, "{who} λ² {lambda2}: S/λ² {es:e}");
        }
        println!("{who}: worst {worst:e}");
    }
}

/// T10-9, Ex. 10.13/10.14 (sequential versus batch, (10.4.12)-(10.4.13)): independent
/// estimates `X_i = X + N_i` of one state, fed to the Bayes filter (p. 389) as observations with
/// `M = I`, `R = S_i`, give `S = (Σ S_i⁻¹)⁻¹`, `X = S Σ S_i⁻¹ X_i`, (a) one at a time in any
/// order, from no information or from the first as the prior, and (b) in two batches (p. 386:
/// `T = [I; I]`, `R = blockdiag(S_B, S_C)`). Oracle: the formula in exact rationals; within
/// 1e-13 of σ (measured, printed).
#[test]
fn t10_9_ex_10_14_fusing_estimates() {
    let xs = [
        [1.0, 2.0, -0.5],
        [1.25, 1.5, 0.0],
        [0.75, 2.5, -1.0],
        [1.5, 1.75, -0.25],
    ];
    let ss = [
        m(3, 3, &[2.0, 0.5, 0.0, 0.5, 1.0, 0.25, 0.0, 0.25, 3.0]),
        m(3, 3, &[1.0, -0.25, 0.5, -0.25, 4.0, 0.0, 0.5, 0.0, 1.5]),
        m(3, 3, &[0.5, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.5]),
        m(3, 3, &[3.0, 1.0, 1.0, 1.0, 3.0, 1.0, 1.0, 1.0, 3.0]),
    ];
    let mut info = DMatrix::from_element(3, 3, z(0));
    let mut h = DMatrix::from_element(3, 1, z(0));
    for (x, s) in xs.iter().zip(&ss) {
        let si = inv(&to_q(s));
        h += mm(&si, &to_q(&m(3, 1, x)));
        info += si;
    }
    let want_s = to_f64(&inv(&info));
    let want_x = to_f64(&mm(&inv(&info), &h));
    let mut worst: f64 = 0.0;
    let mut check = |what: &str, x: DVector<f64>, s: DMatrix<f64>| {
        let ex = (0..3)
            .map(|i| (x[i] - want_x[(i, 0)]).abs() / want_s[(i, i)].sqrt())
            .fold(0.0, f64::max);
        let es = cov_err(&s, &want_s);
        worst = worst.max(ex).max(es);
        assert!(ex < 1e-13 && es < 1e-13, "{what}: X {ex:e}, S {es:e}");
    };
    let static3 = || PolynomialDynamics::new(0, 3);
    for order in [[0, 1, 2, 3], [3, 1, 0, 2], [2, 3, 1, 0]] {
        let mut f = BayesFilter::new(
            static3(),
            LinearObservation::new(DMatrix::identity(3, 3)).unwrap(),
            0.0,
        )
        .unwrap();
        for &i in &order {
            f.update(&meas(0.0, &xs[i], NoiseCovariance::Full(ss[i].clone())))
                .unwrap();
        }
        check(
            &format!("one at a time {order:?}"),
            f.estimate().unwrap(),
            f.covariance().unwrap(),
        );
        // The first as the prior (Kalman and Bayes).
        let first = order[0];
        let x0 = DVector::from_row_slice(&xs[first]);
        let mut k = KalmanFilter::new(
            static3(),
            LinearObservation::new(DMatrix::identity(3, 3)).unwrap(),
            x0.clone(),
            ss[first].clone(),
            0.0,
        )
        .unwrap();
        let mut b = BayesFilter::new(
            static3(),
            LinearObservation::new(DMatrix::identity(3, 3)).unwrap(),
            0.0,
        )
        .unwrap()
        .with_prior(&x0, &ss[first])
        .unwrap();
        for &i in &order[1..] {
            let z = meas(0.0, &xs[i], NoiseCovariance::Full(ss[i].clone()));
            k.update(&z).unwrap();
            b.update(&z).unwrap();
        }
        check(
            &format!("Kalman from {first}"),
            k.state().clone(),
            k.covariance().clone(),
        );
        check(
            &format!("Bayes from {first}"),
            b.estimate().unwrap(),
            b.covariance().unwrap(),
        );
    }
    // (b) Two batches of two: T = [I; I], R = blockdiag(S_i, S_j).
    let stacked = LinearObservation::new(DMatrix::from_fn(6, 3, |i, j| {
        f64::from(u8::from(i % 3 == j))
    }))
    .unwrap();
    let mut f = BayesFilter::new(static3(), stacked, 0.0).unwrap();
    for (i, j) in [(0, 2), (3, 1)] {
        let mut r = DMatrix::zeros(6, 6);
        r.view_mut((0, 0), (3, 3)).copy_from(&ss[i]);
        r.view_mut((3, 3), (3, 3)).copy_from(&ss[j]);
        let y: Vec<f64> = xs[i].iter().chain(&xs[j]).copied().collect();
        f.update(&meas(0.0, &y, NoiseCovariance::Full(r))).unwrap();
    }
    check(
        "two batches",
        f.estimate().unwrap(),
        f.covariance().unwrap(),
    );
    println!("worst: {worst:e}");
}

/// T10-10, Ex. 10.8: with `S_{n,n} = εQ` (ε small), (10.2.53) gives `S_{n+1,n+1} = S_{n+1,n}`:
/// an estimate already (almost) perfect learns nothing from a new observation. Here a
/// constant-velocity model (`Φ(1)`), `Q = [[2, 1], [1, 3]]`, `M = (1, 0)`, `R = 1`, ε = 2⁻¹⁰ …
/// 2⁻⁴⁰. Oracle: `S_{n+1,n+1}`, `S_{n+1,n}` and the gain in exact rationals. The filters
/// agree with the exact values within 1e-12 of `sqrt(S_ii S_jj)` (the gain within 1e-12
/// relative); and the relative change `|S_{n+1,n+1} − S_{n+1,n}| / |S_{n+1,n}|` is
/// `7ε/(1 + 7ε)` (the oracle's, checked against that closed form): the filters' within a
/// factor (1 ± 1e-6).
#[test]
fn t10_10_ex_10_8_an_almost_perfect_estimate() {
    let phi = qm(2, 2, &[z(1), z(1), z(0), z(1)]);
    let q0 = qm(2, 2, &[z(2), z(1), z(1), z(3)]);
    let obs = qm(1, 2, &[z(1), z(0)]);
    let mut worst: f64 = 0.0;
    for k in [10, 20, 30, 40] {
        let eps = fr(1, 1i64 << k);
        let s = q0.clone() * eps.clone();
        let pred = mm(&mm(&phi, &s), &phi.transpose());
        let v = mm(&mm(&obs, &pred), &obs.transpose())[(0, 0)].clone() + z(1);
        let gain = mm(&pred, &obs.transpose()) / v.clone();
        let upd = pred.clone() - mm(&gain, &mm(&obs, &pred));
        let rel = |a: &DMatrix<Q>| to_f64(a).amax();
        let change = rel(&(upd.clone() - pred.clone())) / rel(&pred);
        let eps_f = 2f64.powi(-k);
        // `S_{n+1,n} = ε [[7, 4], [4, 3]]`: the change is `ε² [[49, 28], [28, 16]]/(1 + 7ε)`,
        // `7ε/(1 + 7ε)` of the largest entry.
        let want_change = 7.0 * eps_f / (1.0 + 7.0 * eps_f);
        assert!(
            (change / want_change - 1.0).abs() < 1e-14,
            "ε = 2^-{k}: the oracle's change {change:e}"
        );
        let (want_pred, want_upd, want_gain) = (to_f64(&pred), to_f64(&upd), to_f64(&gain));
        let s_f = to_f64(&s);
        let mut kal = KalmanFilter::new(
            PolynomialDynamics::new(1, 1),
            LinearObservation::value_of(2),
            DVector::from_vec(vec![1.0, 0.5]),
            s_f.clone(),
            0.0,
        )
        .unwrap();
        let mut bay = BayesFilter::new(
            PolynomialDynamics::new(1, 1),
            LinearObservation::value_of(2),
            0.0,
        )
        .unwrap()
        .with_prior(&DVector::from_vec(vec![1.0, 0.5]), &s_f)
        .unwrap();
        let z1 = meas(1.0, &[3.0], NoiseCovariance::Variances(vec![1.0]));
        let mut predicted = kal.clone();
        predicted.predict(1.0).unwrap();
        assert!(cov_err(predicted.covariance(), &want_pred) < 1e-14);
        let inn = kal.update(&z1).unwrap().unwrap();
        bay.update(&z1).unwrap();
        let eg = (&inn.gain - &want_gain).amax() / want_gain.amax();
        for (who, got) in [
            ("Kalman", kal.covariance().clone()),
            ("Bayes", bay.covariance().unwrap()),
        ] {
            let e = cov_err(&got, &want_upd);
            worst = worst.max(e);
            assert!(
                e < 1e-12,
                "ε = 2^-{k} {who}: {got} against {want_upd} ({e:e})"
            );
            let got_change = (&got - &want_pred).amax() / want_pred.amax();
            assert!(
                (got_change / change - 1.0).abs() < 1e-6,
                "ε = 2^-{k} {who}: change {got_change:e} against {change:e}"
            );
        }
        worst = worst.max(eg);
        assert!(
            eg < 1e-12,
            "ε = 2^-{k}: gain {} against {want_gain}",
            inn.gain
        );
        // The estimate moves by H ν = O(ε): the prediction (1.5, 0.5) plus the exact gain times 1.5.
        let x = kal.state();
        let want_x = [1.5 + want_gain[(0, 0)] * 1.5, 0.5 + want_gain[(1, 0)] * 1.5];
        assert!((x[0] - want_x[0]).abs() < 1e-15 && (x[1] - want_x[1]).abs() < 1e-15);
        let xb = bay.estimate().unwrap();
        assert!(
            (xb[0] - want_x[0]).abs() < 4e-15 && (xb[1] - want_x[1]).abs() < 4e-15,
            "Bayes {xb}"
        );
    }
    println!("worst: {worst:e}");
}
