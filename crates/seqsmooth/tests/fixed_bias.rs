//! The fixed-memory bias (`seqsmooth::polynomial::fixed::bias`; Morrison (1969) §7.7-7.8): the
//! bias of a truth of degree m+1 and beyond by the weights and by the power-series route
//! (7.12.14), the dominant-bias bound and the book's Ex 7.26 table (the balance: `fixed_design.rs`), the quadratic fit
//! to a sine (Ex 7.8).

mod common;

use common::fixed::*;
use common::rational::*;
use nalgebra::DMatrix;
use num_traits::{Signed, Zero};
use rand::Rng;
use seqsmooth::basis::DiscreteLegendre;
use seqsmooth::linalg::mul;
use seqsmooth::polynomial::fixed::{
    bias, covariance_unscaled, dominant_bias, end_point_bias_bound, weights, weights_unscaled,
};

/// Bias as truth minus estimate (7.10.1), computed here from the weights: the truth's
/// derivatives at r = L+h minus W(h, τ) applied to its error-free samples (an independent route
/// from the power-series formulas (7.12.14) that `bias` uses).
fn bias_by_weights(m: usize, l: i64, h: &Q, tau: &Q, a: &[Q]) -> Vec<Q> {
    let eval = |t: &Q, d: usize| -> Q {
        // d-th derivative of Σ a_k t^k
        a.iter().enumerate().skip(d).fold(Q::zero(), |s, (k, c)| {
            s + c.clone() * ff(&z(k as i64), d) * qpow(t, k - d)
        })
    };
    let w = weights_unscaled(m, l as u64, h.clone(), tau.clone()).unwrap();
    let y = DMatrix::from_fn((l + 1) as usize, 1, |k, _| {
        eval(&(z(l - k as i64) * tau.clone()), 0)
    });
    let est = mul(&w, &y);
    let at = (z(l) + h.clone()) * tau.clone();
    (0..=m)
        .map(|i| eval(&at, i) - est[(i, 0)].clone())
        .collect()
}

#[test]
fn bias_t7_19_to_t7_21() {
    // T7-19 (Ex 7.24), m = 0, π = t (τ = 1), window starting at n - L: b*(r) = (-L/2)(1 - 2r/L),
    // b*(L) = L/2, centre 0, estimate x0* = n - L/2.
    for l in [4i64, 7, 10] {
        let n = 25i64;
        let truth = [z(n - l), z(1)];
        for r in [z(0), fr(l, 2), z(l), z(l + 1), fr(3, 2)] {
            let b = bias(0, l as u64, r.clone() - z(l), z(1), &truth).unwrap();
            assert_eq!(
                b[0],
                -fr(l, 2) * (z(1) - z(2) * r.clone() / z(l)),
                "T7-19 L = {l}"
            );
        }
        assert_eq!(bias(0, l as u64, z(0), z(1), &truth).unwrap()[0], fr(l, 2));
        let y = DMatrix::from_fn((l + 1) as usize, 1, |k, _| z(n - k as i64));
        assert_eq!(
            mul(&weights(0, l as u64, z(0)).unwrap(), &y)[(0, 0)],
            z(n) - fr(l, 2)
        );
    }
    // T7-20 (Ex 7.25), m = 1, π = t² (absolute time: the window starts at n - L):
    // b*(r) = (L(L-1)/6) p2(r); b*(L) = L(L-1)/6, b*(L/2) = -L(L+2)/12: L = 4: 2, -2;
    // L = 7: 7, -21/4; L = 10: 15, -10. Velocity bias at the end point a2 τ L (L = 4: 4).
    for (l, end, mid) in [
        (4i64, z(2), z(-2)),
        (7, z(7), fr(-21, 4)),
        (10, z(15), z(-10)),
    ] {
        for n in [10i64, 33] {
            let truth = [z((n - l) * (n - l)), z(2 * (n - l)), z(1)];
            let b = |h: Q| bias(1, l as u64, h, z(1), &truth).unwrap();
            assert_eq!(b(z(0))[0], end);
            assert_eq!(b(fr(-l, 2))[0], mid);
            let basis = DiscreteLegendre::new(z(l));
            for r in [z(0), z(1), fr(5, 3), z(l + 2)] {
                assert_eq!(
                    b(r.clone() - z(l))[0],
                    z(l * (l - 1)) / z(6) * basis.value(2, r)
                );
            }
            assert_eq!(b(z(0))[1], z(l)); // a2 τ L with a2 = τ = 1
        }
    }
    let tau = fr(1, 2);
    assert_eq!(
        bias(1, 4, z(0), tau.clone(), &[z(0), z(0), z(3)]).unwrap()[1],
        z(3) * tau * z(4)
    );
    // T7-21 (Ex 7.25d), m = 0, π = t²: b*(L) = L(6n - 2L - 1)/6 and the full b*(r).
    for l in [4i64, 7] {
        for n in [10i64, 25] {
            let truth = [z((n - l) * (n - l)), z(2 * (n - l)), z(1)];
            assert_eq!(
                bias(0, l as u64, z(0), z(1), &truth).unwrap()[0],
                z(l * (6 * n - 2 * l - 1)) / z(6)
            );
            let basis = DiscreteLegendre::new(z(l));
            for r in [z(0), fr(l, 2), z(l + 1)] {
                let want = -fr(l, 2) * z(2 * n - l) * basis.value(1, r.clone())
                    + z(l * (l - 1)) / z(6) * basis.value(2, r.clone());
                assert_eq!(bias(0, l as u64, r - z(l), z(1), &truth).unwrap()[0], want);
            }
        }
    }
}

#[test]
fn bias_power_series_route_equals_truth_minus_estimate_7_12_14() {
    // (7.12.14)/(7.10.18) against truth − W(h,τ)Ỹ, exact, for truths of degree m+1..m+4 and
    // (fallback path) of degree above L.
    let mut rng = common::rng(3);
    for m in 0..=4usize {
        for l in [m as i64 + 1, m as i64 + 4, 12] {
            for d in m + 1..=m + 4 {
                let truth: Vec<Q> = (0..=d)
                    .map(|_| fr(rng.gen_range(-9..=9), rng.gen_range(1..=5)))
                    .collect();
                for tau in [z(1), fr(3, 7)] {
                    for h in leads(l) {
                        let got = bias(m, l as u64, h.clone(), tau.clone(), &truth).unwrap();
                        let want = bias_by_weights(m, l, &h, &tau, &truth);
                        assert_eq!(got, want, "m = {m}, L = {l}, d = {d}, h = {h}");
                    }
                }
            }
        }
    }
    // A truth of degree ≤ m passes without bias.
    assert!(bias(3, 9, z(2), z(1), &[z(1), z(2), z(3), z(4)])
        .unwrap()
        .iter()
        .all(Zero::is_zero));
}

#[test]
fn dominant_bias_is_exact_for_degree_m_plus_1_t7_22() {
    // (7.13.5)-(7.13.6) with the sign (-1)^(m+1) (the book's "to within sign"), exact when the
    // truth has degree m+1; end point (7.13.9) a τ^(m+1) L^(m+1)/C(2m+2, m+1) and the bound
    // (7.13.10).
    let a = fr(5, 3);
    for m in 0..=5usize {
        for l in [m as i64, m as i64 + 1, m as i64 + 4, 20] {
            for tau in [z(1), fr(3, 7)] {
                let mut truth = vec![fr(1, 2); m + 2];
                truth[m + 1] = a.clone();
                for h in leads(l) {
                    let got =
                        dominant_bias(m, l as u64, h.clone(), tau.clone(), a.clone()).unwrap();
                    assert_eq!(
                        got,
                        bias_by_weights(m, l, &h, &tau, &truth),
                        "m = {m}, L = {l}, h = {h}"
                    );
                }
                let end = a.clone() * qpow(&tau, m + 1) * ff(&z(l), m + 1) / c(2 * m + 2, m + 1);
                assert_eq!(
                    dominant_bias(m, l as u64, z(0), tau.clone(), a.clone()).unwrap()[0],
                    end
                );
                assert_eq!(
                    end_point_bias_bound(m, l as u64, tau.clone(), -a.clone()).unwrap(),
                    end.abs()
                );
            }
        }
    }
    // (7.13.7), m = 1: b*(r) = a2 τ² L(L-1)/6 · p2(r).
    let basis = DiscreteLegendre::new(z(9));
    for r in [z(0), z(4), fr(9, 2), z(11)] {
        assert_eq!(
            dominant_bias(1, 9, r.clone() - z(9), z(2), z(3)).unwrap()[0],
            z(3) * z(4) * z(72) / z(6) * basis.value(2, r)
        );
    }
}

#[test]
fn bias_versus_random_error_ex_7_26_t7_23() {
    // Ex 7.26: m = 1, σ_ν = 200 ft, R'' = 32 ft/s² (a2 = 16), τ = 1 s. The book's σ column is
    // the one-step formula (7.5.25) although the text says "updated" (misprint register
    // the book's Ex 7.26a says "updated" 'updated' but formula is the 1-step one"); both are checked.
    let table = [
        (5u64, 186.2, 144.7, 53.3),
        (10, 129.3, 112.8, 240.0),
        (15, 104.9, 95.5, 560.0),
        (20, 90.5, 84.3, 1013.3),
    ];
    let sd = |l: u64, h: f64| 200.0 * covariance_unscaled(1, l, h, 1.0).unwrap()[(0, 0)].sqrt();
    for (l, one_step, updated, bound) in table {
        assert!((sd(l, 1.0) - one_step).abs() < 0.05, "L = {l}");
        assert!((sd(l, 0.0) - updated).abs() < 0.05, "L = {l}");
        let b = end_point_bias_bound(1, l, 1.0, 16.0).unwrap();
        assert!((b - bound).abs() < 0.05, "L = {l}: {b}");
        assert!((dominant_bias(1, l, 0.0, 1.0, 16.0).unwrap()[0] - b).abs() < 1e-9);
    }
    // "Equality near L ≈ 8 (L = 8: σ 145.3 vs bias 149.3)".
    assert!((sd(8, 1.0) - 145.3).abs() < 0.05);
    assert!((end_point_bias_bound(1, 8, 1.0, 16.0).unwrap() - 149.3).abs() < 0.05);
}

#[test]
fn quadratic_fit_to_a_sine_ex_7_8_t7_24() {
    // T7-24 (derived): m = 2, L = 4, Y = (sin 90°, sin 67.5°, sin 45°, sin 22.5°, sin 0°),
    // r = θ/22.5°: p*(r) = -0.008473346 + 0.4600557607 r - 0.05148403766 r² — the Taylor
    // coefficients at r = 0, i.e. W(-L) Y; max |p* - sin| on a 1° grid = 0.01777 at 20°.
    let y: Vec<f64> = (0..=4)
        .map(|k| (f64::to_radians(90.0 - 22.5 * k as f64)).sin())
        .collect();
    let w = weights(2, 4, -4.0).unwrap();
    let c: Vec<f64> = (0..3)
        .map(|i| (0..5).map(|k| w[(i, k)] * y[k]).sum())
        .collect();
    for (got, want) in c.iter().zip([-0.008473346, 0.4600557607, -0.05148403766]) {
        assert!((got - want).abs() < 5e-10, "{got} vs {want}");
    }
    let (mut worst, mut at) = (0.0f64, 0);
    for deg in 0..=90 {
        let r = deg as f64 / 22.5;
        let e = (c[0] + c[1] * r + c[2] * r * r - (deg as f64).to_radians().sin()).abs();
        if e > worst {
            (worst, at) = (e, deg);
        }
    }
    assert!(
        (worst - 0.01777).abs() < 5e-6 && at == 20,
        "{worst} at {at}"
    );
}
