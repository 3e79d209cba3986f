//! Morrison ch. 12 (the Kalman filter) conformance beyond `kalman_filter.rs`'s T12-1 to T12-6:
//! T12-7 (Ex. 12.8: the minimum-variance estimate of `C X` is `C X*`), and the index's
//! "Joseph(H_opt) == (I − HM)S" (Ex. 12.5/12.6: with the optimal gain (12.2.17) Joseph's
//! covariance (12.3.7) is (12.2.18) = (12.2.20), and any other gain adds
//! `(H − H_opt) V (H − H_opt)ᵀ ≥ 0`).
//!
//! Misprints: the book's recorded ch. 12 misprints ((12.3.15)'s garbled display, (12.4.21)'s
//! "b₂" for b₁, Ex. 12.16's 4-digit Bayes inverse) do not touch these items; (12.2.17)-(12.2.20)
//! and (12.3.7) are used as printed.

mod common;

use common::kalman::cov_err;
use common::rational::{eye, inv, mm, to_f64, z, Q};
use nalgebra::{DMatrix, DVector};
use num_traits::Zero;
use seqsmooth::kalman::noise::{ProcessNoise, WhiteNoiseDerivative};
use seqsmooth::kalman::{BayesFilter, KalmanFilter};
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::linear::LinearDynamics;
use seqsmooth::model::measurement::Measurement;
use seqsmooth::model::measurement::NoiseCovariance;
use seqsmooth::model::observation::LinearObservation;
use seqsmooth::Error;

fn m(rows: usize, cols: usize, v: &[f64]) -> DMatrix<f64> {
    DMatrix::from_row_slice(rows, cols, v)
}

fn to_q(a: &DMatrix<f64>) -> DMatrix<Q> {
    a.map(|v| Q::from_float(v).unwrap())
}

/// The driving noise of the transformed state `Λ = C X`: `C Q Cᵀ` ((15.2.23) with `C D`).
#[derive(Debug)]
struct Mapped {
    c: DMatrix<f64>,
    inner: WhiteNoiseDerivative,
}

impl ProcessNoise for Mapped {
    fn dimension(&self) -> usize {
        self.c.nrows()
    }

    fn covariance(&self, t_a: f64, t_b: f64) -> Result<DMatrix<f64>, Error> {
        Ok(&self.c * self.inner.covariance(t_a, t_b)? * self.c.transpose())
    }
}

/// T12-7, Ex. 12.8 (with Ex. 12.7): the minimum-variance estimate of `Λ = C X` is `C X*`. A
/// degree-2 state `X = (x, ẋ, ẍ)` (`A` nilpotent) observed in `x` and `ẍ` (full `R`, some
/// components missing), irregular times, with a prior, with and without driving noise; and the
/// same filter run on `Λ = C X` directly: `dΛ/dt = C A C⁻¹ Λ` (the library's `LinearDynamics`,
/// `e^{ζ C A C⁻¹}`), `M' = M C⁻¹`, prior `C X₀`, `C S₀ Cᵀ`, driving noise `C Q Cᵀ`, where
/// `C = [[1, 1, 0], [2, 3, 1], [1, 2, 2]]` (det 1, so `C⁻¹` and `C A C⁻¹` are integers and the
/// transformed `A` is exactly nilpotent). Oracle: the filter on `X`, mapped by `C`. The
/// estimate within 1e-11 of max(|Λ_i|, σ_i) and the covariance within 1e-11 of
/// `sqrt(S_ii S_jj)` after every update, Kalman (q = 0 and q = 0.3) and Bayes (measured
/// 7.2e-13 Kalman at q = 0, the covariance form's rounding; 7.6e-14 at q = 0.3; 3.8e-14
/// Bayes; printed).
#[test]
fn t12_7_ex_12_8_estimate_of_a_linear_map() {
    let c = m(3, 3, &[1.0, 1.0, 0.0, 2.0, 3.0, 1.0, 1.0, 2.0, 2.0]);
    let c_inv_q = inv(&to_q(&c));
    let c_inv = to_f64(&c_inv_q);
    assert_eq!(mm(&to_q(&c), &c_inv_q), eye(3));
    let a = m(3, 3, &[0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]);
    let a_prime = &c * &a * &c_inv;
    let obs = m(2, 3, &[1.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
    let obs_prime = &obs * &c_inv;
    let x0 = DVector::from_vec(vec![0.5, -1.0, 0.25]);
    let s0 = m(3, 3, &[4.0, 1.0, 0.5, 1.0, 2.0, 0.25, 0.5, 0.25, 1.0]);
    let r = NoiseCovariance::Full(m(2, 2, &[0.7, 0.2, 0.2, 0.4]));
    let dyn_x = PolynomialDynamics::new(2, 1);
    let dyn_l = LinearDynamics::new(a_prime.clone()).unwrap();
    assert!(dyn_l.is_nilpotent(), "C A C⁻¹ = {a_prime}");
    let lin = |o: &DMatrix<f64>| LinearObservation::new(o.clone()).unwrap();
    for q in [0.0, 0.3] {
        let noise = WhiteNoiseDerivative::new(2, 1, q).unwrap();
        let mut fx = KalmanFilter::new(dyn_x, lin(&obs), x0.clone(), s0.clone(), 0.0)
            .unwrap()
            .with_process_noise(noise)
            .unwrap();
        let mut fl = KalmanFilter::new(
            dyn_l.clone(),
            lin(&obs_prime),
            &c * &x0,
            &c * &s0 * c.transpose(),
            0.0,
        )
        .unwrap()
        .with_process_noise(Mapped {
            c: c.clone(),
            inner: noise,
        })
        .unwrap();
        let mut bx = BayesFilter::new(dyn_x, lin(&obs), 0.0)
            .unwrap()
            .with_prior(&x0, &s0)
            .unwrap();
        let mut bl = BayesFilter::new(dyn_l.clone(), lin(&obs_prime), 0.0)
            .unwrap()
            .with_prior(&(&c * &x0), &(&c * &s0 * c.transpose()))
            .unwrap();
        let (mut worst_k, mut worst_b): (f64, f64) = (0.0, 0.0);
        let mut t = 0.0;
        for k in 0..40 {
            t += 0.3 + 0.05 * ((k * 7 % 11) as f64);
            let first = (k % 5 != 2).then_some(0.5 * t * t - t + 0.3 * ((k as f64) * 1.7).sin());
            let second = (k % 3 != 0).then_some(0.8 + 0.4 * ((k as f64) * 0.9).cos());
            let z = Measurement {
                time: t,
                values: vec![first, second],
                noise: r.clone(),
            };
            fx.update(&z).unwrap();
            fl.update(&z).unwrap();
            let mut pairs = vec![(
                "Kalman",
                &c * fx.state(),
                &c * fx.covariance() * c.transpose(),
                fl.state().clone(),
                fl.covariance().clone(),
            )];
            if q == 0.0 {
                bx.update(&z).unwrap();
                bl.update(&z).unwrap();
                let (xb, sb) = (bx.estimate().unwrap(), bx.covariance().unwrap());
                pairs.push((
                    "Bayes",
                    &c * xb,
                    &c * sb * c.transpose(),
                    bl.estimate().unwrap(),
                    bl.covariance().unwrap(),
                ));
            }
            for (who, want_x, want_s, got_x, got_s) in pairs {
                let ex = (0..3)
                    .map(|i| {
                        (got_x[i] - want_x[i]).abs() / want_x[i].abs().max(want_s[(i, i)].sqrt())
                    })
                    .fold(0.0, f64::max);
                let es = cov_err(&got_s, &want_s);
                let worst = if who == "Kalman" {
                    &mut worst_k
                } else {
                    &mut worst_b
                };
                *worst = worst.max(ex).max(es);
                assert!(
                    ex < 1e-11,
                    "q {q} {who} step {k}: Λ {got_x} against C X* {want_x} ({ex:e})"
                );
                assert!(
                    es < 1e-11,
                    "q {q} {who} step {k}: S_Λ against C S Cᵀ ({es:e})"
                );
            }
        }
        println!("q {q}: worst Kalman {worst_k:e}, Bayes {worst_b:e}");
    }
}

/// Joseph(H_opt) == (I − HM)S, Ex. 12.5/12.6, (12.3.7) against (12.2.18) and (12.2.20): with
/// `S_{n,n−1} = [[4, 1, 1/2], [1, 2, 1/4], [1/2, 1/4, 1]]`, `M = [[1, 0, 0], [0, 1, 1]]`,
/// `R = [[1, 1/2], [1/2, 2]]` (and `R = 0`, a perfect observation, Ex. 12.12), the library's
/// gain is `H = S Mᵀ (R + M S Mᵀ)⁻¹` and its (Joseph-form) covariance is `(I − H M) S` =
/// `S − S Mᵀ (R + M S Mᵀ)⁻¹ M S`, all three equal as exact rationals (the oracle); within
/// 8e-16 relative (gain) and 8e-16 of `sqrt(S_ii S_jj)` (covariance; a zero variance left by
/// the perfect observation within 8e-16 of the largest prior entry): measured 2.1e-16, printed.
/// Ex. 12.6: for any other gain `H = H_opt + Δ` (Δ from a fixed list of rationals) Joseph's
/// covariance is `A + Δ V Δᵀ` exactly, so every diagonal element is least at `H_opt`, and
/// (Ex. 12.7) so is `Tr(Γ S)` for `Γ = diag(1, 2, 3)`.
#[test]
fn joseph_with_the_optimal_gain_is_i_minus_hm_s() {
    let s_f = m(3, 3, &[4.0, 1.0, 0.5, 1.0, 2.0, 0.25, 0.5, 0.25, 1.0]);
    let obs_f = m(2, 3, &[1.0, 0.0, 0.0, 0.0, 1.0, 1.0]);
    let (s, obs) = (to_q(&s_f), to_q(&obs_f));
    let mut worst: f64 = 0.0;
    for r_f in [m(2, 2, &[1.0, 0.5, 0.5, 2.0]), DMatrix::zeros(2, 2)] {
        let r = to_q(&r_f);
        let v = mm(&mm(&obs, &s), &obs.transpose()) + r.clone();
        let h = mm(&mm(&s, &obs.transpose()), &inv(&v));
        let i_hm = eye(3) - mm(&h, &obs);
        let short = mm(&i_hm, &s); // (12.2.18)
        let long = s.clone() - mm(&mm(&mm(&s, &obs.transpose()), &inv(&v)), &mm(&obs, &s)); // (12.2.20)
        let joseph = |g: &DMatrix<Q>| {
            let a = eye(3) - mm(g, &obs);
            mm(&mm(&a, &s), &a.transpose()) + mm(&mm(g, &r), &g.transpose())
        };
        assert_eq!(joseph(&h), short, "(12.3.7) with H_opt is (12.2.18)");
        assert_eq!(short, long, "(12.2.18) is (12.2.20)");
        // Ex. 12.6: Joseph(H_opt + Δ) = Joseph(H_opt) + Δ V Δᵀ, diagonal and Tr(ΓS) least at H_opt.
        let gamma = DMatrix::from_fn(
            3,
            3,
            |i, j| if i == j { z(i as i64 + 1) } else { Q::zero() },
        );
        let trace = |a: &DMatrix<Q>| (0..3).fold(Q::zero(), |acc, i| acc + a[(i, i)].clone());
        for k in 1..=12i64 {
            let delta = DMatrix::from_fn(3, 2, |i, j| {
                Q::new(
                    (((k * 5 + i as i64 * 3 + j as i64 * 7) % 9) - 4).into(),
                    8.into(),
                )
            });
            let other = joseph(&(h.clone() + delta.clone()));
            let b = mm(&mm(&delta, &v), &delta.transpose());
            assert_eq!(other, short.clone() + b.clone(), "A + B, Δ {k}");
            for i in 0..3 {
                assert!(b[(i, i)] >= Q::zero(), "B_ii ≥ 0");
            }
            assert!(trace(&mm(&gamma, &other)) >= trace(&mm(&gamma, &short)));
        }
        // The library.
        let mut f = KalmanFilter::new(
            PolynomialDynamics::new(0, 3),
            LinearObservation::new(obs_f.clone()).unwrap(),
            DVector::zeros(3),
            s_f.clone(),
            0.0,
        )
        .unwrap();
        let inn = f
            .update(&Measurement {
                time: 0.0,
                values: vec![Some(1.0), Some(-2.0)],
                noise: NoiseCovariance::Full(r_f.clone()),
            })
            .unwrap()
            .unwrap();
        let (want_h, want_s) = (to_f64(&h), to_f64(&short));
        let eh = (&inn.gain - &want_h).amax() / want_h.amax();
        let got = f.covariance();
        // A perfect observation leaves zero variances: compare those entries absolutely.
        let mut es: f64 = 0.0;
        for i in 0..3 {
            for j in 0..3 {
                let scale = (want_s[(i, i)] * want_s[(j, j)])
                    .sqrt()
                    .max(f64::MIN_POSITIVE);
                let d = (got[(i, j)] - want_s[(i, j)]).abs();
                es = es.max(if scale > f64::MIN_POSITIVE {
                    d / scale
                } else {
                    d / s_f.amax()
                });
            }
        }
        worst = worst.max(eh).max(es);
        assert!(
            eh < 8e-16,
            "R {r_f}: H {} against {want_h} ({eh:e})",
            inn.gain
        );
        assert!(es < 8e-16, "R {r_f}: S {got} against {want_s} ({es:e})");
        // The state moves by H ν exactly as the oracle's gain says.
        let nu = DVector::from_vec(vec![1.0, -2.0]);
        assert!((f.state() - &want_h * nu).amax() < 1e-15);
    }
    println!("worst: {worst:e}");
}
