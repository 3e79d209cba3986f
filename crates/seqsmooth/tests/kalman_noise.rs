//! `kalman::noise`: the polynomial model's driving-noise covariance against (15.2.23) integrated
//! in exact rationals (the integrand is a polynomial in `l`), its composition over two steps,
//! and its refusals.

mod common;

use common::rational::{f, fact, fr, qpow, z};
use nalgebra::DMatrix;
use num_traits::Zero;
use seqsmooth::kalman::noise::{ProcessNoise, WhiteNoiseDerivative};
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::scalar::Rational;

/// `∫_0^ζ [Ψ(s) e_m]_i [Ψ(s) e_m]_j ds = ∫ s^(2m−i−j) / ((m−i)!(m−j)!) ds`, term by term in exact
/// rationals: `ζ^(p+1)/(p+1)` with `p = 2m − i − j`.
fn exact_q(m: usize, zeta: &Rational, q: &Rational) -> Vec<Vec<Rational>> {
    (0..=m)
        .map(|i| {
            (0..=m)
                .map(|j| {
                    let p = 2 * m - i - j;
                    q.clone() * qpow(zeta, p + 1) / (fact(m - i) * fact(m - j) * z(p as i64 + 1))
                })
                .collect()
        })
        .collect()
}

/// Degrees 0-8, one to three axes, steps 1/4 to 7/2 (exact in binary): every entry within
/// 4 ulp of the exact rational integral; zero between axes.
#[test]
fn closed_form_equals_the_integral_in_exact_rationals() {
    let mut worst: f64 = 0.0;
    for m in 0..=8 {
        for axes in 1..=3 {
            for (num, den) in [(1, 4), (1, 1), (7, 2)] {
                let zeta = fr(num, den);
                let q = fr(3, 2);
                let want = exact_q(m, &zeta, &q);
                let got = WhiteNoiseDerivative::new(m, axes, 1.5)
                    .unwrap()
                    .covariance(10.0, 10.0 + f(&zeta))
                    .unwrap();
                for row in 0..got.nrows() {
                    for col in 0..got.ncols() {
                        let g = got[(row, col)];
                        if row % axes != col % axes {
                            assert_eq!(g, 0.0);
                            continue;
                        }
                        let w = f(&want[row / axes][col / axes]);
                        let e = (g - w).abs() / (w.abs() * f64::EPSILON);
                        worst = worst.max(e);
                        assert!(
                            e <= 4.0,
                            "m {m} axes {axes} ζ {num}/{den} [{row},{col}]: {g} against {w}"
                        );
                    }
                }
                assert!(!want[0][0].is_zero());
            }
        }
    }
    println!("worst: {worst} ulp");
}

/// The noise of two steps is the first carried through the second plus the second's:
/// `Q(ζ₁ + ζ₂) = Φ(ζ₂) Q(ζ₁) Φ(ζ₂)ᵀ + Q(ζ₂)` (from (15.2.23)); a step backwards has the
/// noise of the interval.
#[test]
fn composition_over_two_steps() {
    for m in 0..=5 {
        let noise = WhiteNoiseDerivative::new(m, 2, 0.7).unwrap();
        let phi = PolynomialDynamics::new(m, 2).transition(1.25);
        let q1 = noise.covariance(0.0, 0.5).unwrap();
        let q2 = noise.covariance(0.5, 1.75).unwrap();
        let both = noise.covariance(0.0, 1.75).unwrap();
        let composed: DMatrix<f64> = &phi * &q1 * phi.transpose() + &q2;
        for (a, b) in composed.iter().zip(both.iter()) {
            assert!(
                (a - b).abs() <= 1e-14 * b.abs().max(1.0),
                "m {m}: {a} against {b}"
            );
        }
        assert_eq!(noise.covariance(1.75, 0.0).unwrap(), both);
    }
}

#[test]
fn refusals() {
    assert!(WhiteNoiseDerivative::new(1, 1, f64::NAN).is_err());
    assert!(WhiteNoiseDerivative::new(1, 1, -1.0).is_err());
    assert!(WhiteNoiseDerivative::new(1, 0, 1.0).is_err());
    let n = WhiteNoiseDerivative::new(3, 1, 1.0).unwrap();
    assert!(n.covariance(0.0, f64::INFINITY).is_err());
    assert!(n.covariance(0.0, 1e300).is_err(), "ζ⁷ overflows");
    assert_eq!(n.dimension(), 4);
    assert_eq!(
        WhiteNoiseDerivative::new(3, 1, 0.0)
            .unwrap()
            .covariance(0.0, 5.0)
            .unwrap(),
        DMatrix::zeros(4, 4)
    );
}
