//! `basis::GaussRule` (Golub–Welsch on `basis::Jacobi`): the classical rules against
//! independent computations — Gauss–Legendre against Newton's iteration on `P_{n+1}` (weights
//! `2/((1 − x²) P'_{n+1}(x)²)`) and the 15-digit tables, Gauss–Chebyshev against its closed
//! form — and, for any positive measure, exactness on every polynomial of degree `≤ 2n+1`
//! (Villien & Ostertag 2009, Lemma 3, eq. 26), on a continuous weight and on the discrete
//! inner product of 10⁵ irregular samples with varying variances.

use seqsmooth::basis::{GaussRule, Jacobi, Weight};
use std::f64::consts::PI;

/// The `m`-point Gauss–Legendre rule by Newton's iteration on the Legendre recurrence.
fn legendre_by_newton(m: usize) -> (Vec<f64>, Vec<f64>) {
    let mut rule: Vec<(f64, f64)> = (0..m)
        .map(|k| {
            let mut x = (PI * (k as f64 + 0.75) / (m as f64 + 0.5)).cos();
            let mut dp = 0.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                if m == 1 {
                    p0 = 1.0;
                    p1 = x;
                } else {
                    for j in 1..m {
                        let p2 = ((2 * j + 1) as f64 * x * p1 - j as f64 * p0) / (j + 1) as f64;
                        p0 = p1;
                        p1 = p2;
                    }
                }
                dp = m as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-17 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect();
    rule.sort_by(|a, b| a.0.total_cmp(&b.0));
    rule.into_iter().unzip()
}

fn max_difference(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Chebyshev `T_0(u) … T_d(u)`.
fn chebyshev_t(d: usize, u: f64) -> Vec<f64> {
    let mut t = vec![1.0, u];
    while t.len() <= d {
        let k = t.len();
        t.push(2.0 * u * t[k - 1] - t[k - 2]);
    }
    t.truncate(d + 1);
    t
}

#[test]
fn gauss_legendre_equals_newtons_rule_and_the_tables() {
    let mut worst: f64 = 0.0;
    for n in 0..=30 {
        let g = Jacobi::legendre(n, -1.0, 1.0).unwrap().gauss().unwrap();
        let (x, w) = legendre_by_newton(n + 1);
        worst = worst
            .max(max_difference(&g.nodes(), &x))
            .max(max_difference(&g.weights, &w));
    }
    assert!(worst <= 1e-13, "{worst:e}");
    // The 15-digit tables (n = 5 and 7: 6 and 8 nodes).
    let g = Jacobi::legendre(5, -1.0, 1.0).unwrap().gauss().unwrap();
    let x = [0.932469514203152, 0.661209386466264, 0.238619186083197];
    let w = [0.171324492379170, 0.360761573048139, 0.467913934572691];
    for i in 0..3 {
        assert!((g.nodes()[5 - i] - x[i]).abs() < 1e-14 && (g.nodes()[i] + x[i]).abs() < 1e-14);
        assert!((g.weights[5 - i] - w[i]).abs() < 1e-14 && (g.weights[i] - w[i]).abs() < 1e-14);
    }
    let g = Jacobi::legendre(7, -1.0, 1.0).unwrap().gauss().unwrap();
    let x = [
        0.183434642495650,
        0.525532409916329,
        0.796666477413627,
        0.960289856497536,
    ];
    let w = [
        0.362683783378362,
        0.313706645877887,
        0.222381034453374,
        0.101228536290377,
    ];
    for i in 0..4 {
        assert!((g.nodes()[4 + i] - x[i]).abs() < 1e-14, "{i}");
        assert!((g.weights[4 + i] - w[i]).abs() < 1e-14, "{i}");
    }
}

#[test]
fn gauss_chebyshev_equals_its_closed_form() {
    let mut worst: f64 = 0.0;
    for n in 0..=30 {
        let g = Jacobi::chebyshev(n, -1.0, 1.0).unwrap().gauss().unwrap();
        let m = (n + 1) as f64;
        let mut x: Vec<f64> = (0..=n)
            .map(|k| ((2 * k + 1) as f64 * PI / (2.0 * m)).cos())
            .collect();
        x.reverse();
        worst = worst
            .max(max_difference(&g.nodes(), &x))
            .max(max_difference(&g.weights, &vec![PI / m; n + 1]));
    }
    assert!(worst <= 1e-13, "{worst:e}");
}

/// The continuous construction (the weight discretised, then Lanczos) gives the classical
/// rules for `ω = 1` and `ω = 1/√((t − a)(b − t))`, also on an interval of Unix-epoch times
/// (the nodes' offsets from the centre over the half-width; weights scaled by the half-width
/// for Legendre).
#[test]
fn continuous_weights_give_the_classical_rules() {
    for (a, b) in [(-1.0, 1.0), (1.7e9, 1.7e9 + 10.0)] {
        let h = (b - a) / 2.0;
        for n in [0, 1, 5, 12, 30] {
            let got = Jacobi::continuous(Weight::Smooth(&|_| 1.0), a, b, n)
                .unwrap()
                .gauss()
                .unwrap();
            let want = Jacobi::legendre(n, -1.0, 1.0).unwrap().gauss().unwrap();
            let u: Vec<f64> = got.offsets.iter().map(|o| o / h).collect();
            let w: Vec<f64> = got.weights.iter().map(|w| w / h).collect();
            let tol = 1e-13;
            assert!(max_difference(&u, &want.nodes()) <= tol, "{a} n {n}");
            assert!(max_difference(&w, &want.weights) <= 1e-13, "{a} n {n}");
            let got = Jacobi::continuous(Weight::ChebyshevEnds(&|_| 1.0), a, b, n)
                .unwrap()
                .gauss()
                .unwrap();
            let want = Jacobi::chebyshev(n, -1.0, 1.0).unwrap().gauss().unwrap();
            let u: Vec<f64> = got.offsets.iter().map(|o| o / h).collect();
            assert!(max_difference(&u, &want.nodes()) <= tol, "{a} n {n}");
            assert!(
                max_difference(&got.weights, &want.weights) <= 1e-13,
                "{a} n {n}"
            );
        }
    }
}

/// A non-classical weight, `ω(t) = 1 + t² + e^t/4` on `[-1, 2]`: the rule of `n+1` nodes
/// integrates `T_d(u)`, `d ≤ 2n+1`, as a 200-point Gauss–Legendre rule (Newton's) of
/// `T_d ω` does, to `1e-13` of `∫|T_d| ω`.
#[test]
fn a_continuous_rule_is_exact_to_degree_2n_plus_1() {
    let omega = |t: f64| 1.0 + t * t + t.exp() / 4.0;
    let (a, b) = (-1.0, 2.0);
    let (c, h) = ((a + b) / 2.0, (b - a) / 2.0);
    let (x, w) = legendre_by_newton(200);
    for n in [1, 4, 10, 20] {
        let g = Jacobi::continuous(Weight::Smooth(&omega), a, b, n)
            .unwrap()
            .gauss()
            .unwrap();
        for d in 0..=2 * n + 1 {
            let f = |t: f64| chebyshev_t(d, (t - c) / h)[d];
            let exact: f64 = x
                .iter()
                .zip(&w)
                .map(|(&u, w)| h * w * f(c + h * u) * omega(c + h * u))
                .sum();
            let scale: f64 = x
                .iter()
                .zip(&w)
                .map(|(&u, w)| h * w * f(c + h * u).abs() * omega(c + h * u))
                .sum();
            let err = (g.integrate(f) - exact).abs() / scale;
            assert!(err <= 1e-13, "n {n} d {d}: {err:e}");
        }
    }
}

/// The discrete measure of `N` samples (irregular times from 1.7e9 with exponential-like
/// gaps, variances varying by 10⁴): `Σ_k λ_k f(t_k) = Σ_j w_j f(t_j)` for `f = T_d`,
/// `d ≤ 2n+1`, to `1e-12` of `Σ_j w_j |f(t_j)|` (Lemma 3 on the discrete inner product), up to
/// `N = 10⁵` and `n = 20`, few samples for the degree included (`N = 25`, `100` at `n = 20`:
/// 3.4e-12 when the recurrence ran in `f64`).
#[test]
fn the_discrete_rule_is_exact_on_the_samples_inner_product() {
    for (count, n) in [
        (50usize, 3usize),
        (25, 20),
        (100, 10),
        (100, 20),
        (200, 20),
        (1_000, 10),
        (1_000, 20),
        (100_000, 20),
    ] {
        let mut t = Vec::with_capacity(count);
        let mut now = 1.7e9;
        for j in 0..count {
            now += 0.001 * (1.0 + ((j * 7919) % 97) as f64 / 10.0);
            t.push(now);
        }
        let w: Vec<f64> = (0..count)
            .map(|j| 1.0 / (1e-2 + ((j * 31) % 101) as f64))
            .collect();
        let jacobi = Jacobi::discrete(&t, &w, n).unwrap();
        let g = jacobi.gauss().unwrap();
        assert_eq!(g.offsets.len(), n + 1);
        assert!(g.offsets.windows(2).all(|p| p[0] < p[1]));
        let (c, h) = (jacobi.centre, jacobi.half);
        assert!(g.offsets[0] > t[0] - c && g.offsets[n] < t[count - 1] - c);
        let mut worst: f64 = 0.0;
        for d in 0..=2 * n + 1 {
            // f(t) = T_d((t − c)/h), given the offset t − c (exact for these times)
            let f = |o: f64| chebyshev_t(d, o / h)[d];
            let exact: f64 = t.iter().zip(&w).map(|(&s, w)| w * f(s - c)).sum();
            let scale: f64 = t.iter().zip(&w).map(|(&s, w)| w * f(s - c).abs()).sum();
            worst = worst.max((g.integrate_offsets(f) - exact).abs() / scale);
        }
        assert!(worst <= 1e-12, "N {count} n {n}: {worst:e}");
    }
}

/// The same samples with their times shifted (exactly) or rescaled: the nodes' offsets move
/// with them and the weights do not, to rounding.
#[test]
fn the_rule_does_not_depend_on_the_time_origin_or_unit() {
    let x: Vec<f64> = (0..200)
        .map(|j| j as f64 * 0.5 + ((j * 13) % 7) as f64 * 0.125) // multiples of 1/8: exact after the shift to 1.7e9 (ulp 2⁻²²)
        .collect();
    let w: Vec<f64> = (0..200).map(|j| 1.0 + (j % 5) as f64).collect();
    let base = Jacobi::discrete(&x, &w, 6).unwrap().gauss().unwrap();
    for (origin, unit) in [(1.7e9, 1.0), (0.0, 1e-3), (-5.0, 3600.0)] {
        let t: Vec<f64> = x.iter().map(|x| origin + x * unit).collect();
        let g = Jacobi::discrete(&t, &w, 6).unwrap().gauss().unwrap();
        // the nodes back in the original units, from their offsets (c + o − origin exactly
        // enough: c − origin is the shifted centre)
        let back: Vec<f64> = g
            .offsets
            .iter()
            .map(|o| (g.centre - origin + o) / unit)
            .collect();
        let tol = 1e-12 * 100.0 + 4.0 * f64::EPSILON * origin.abs() / unit;
        assert!(
            max_difference(&back, &base.nodes()) <= tol,
            "{origin} {unit}"
        );
        assert!(
            max_difference(&g.weights, &base.weights) <= 1e-12 * 30.0,
            "{origin} {unit}"
        );
    }
}

#[test]
fn a_rule_integrates_with_its_weights_summing_to_the_mass() {
    let j = Jacobi::discrete(&[0.0, 1.0, 3.0, 7.0], &[1.0, 2.0, 0.5, 4.0], 2).unwrap();
    let g = GaussRule::new(&j).unwrap();
    let total: f64 = g.weights.iter().sum();
    assert!((total - 7.5).abs() < 1e-13 * 7.5);
    assert!((j.mass - 7.5).abs() < 1e-15);
}
