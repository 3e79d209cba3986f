//! Shared by the fixed-memory tests and the `accuracy_fixed_filter` example.

use super::exact_discounted_even;
use super::rational::*;
use nalgebra::DMatrix;
use num_traits::Signed;
use rand::Rng;
use seqsmooth::basis::DiscreteLegendre;
use seqsmooth::polynomial::fixed::{weights, FixedEngine, FixedMemory};
use seqsmooth::PolynomialFilter;

pub fn rows(r: &[Vec<Q>]) -> DMatrix<Q> {
    DMatrix::from_fn(r.len(), r[0].len(), |i, j| r[i][j].clone())
}

/// The leads used throughout: current, one-step, centre, a fractional lead, a retrodiction
/// before the window.
pub fn leads(l: i64) -> Vec<Q> {
    vec![z(0), z(1), fr(-l, 2), fr(5, 2), z(-l - 3)]
}

/// Relative error of derivative vectors with floors `scale / step^i` (the data scale carried to
/// each derivative's units).
pub fn rel_to_scale(got: &[f64], want: &[f64], scale: f64, step: f64) -> f64 {
    got.iter()
        .zip(want)
        .enumerate()
        .map(|(i, (a, b))| (a - b).abs() / (b.abs().max(scale / step.powi(i as i32))))
        .fold(0.0, f64::max)
}

/// `y_n` of the long runs: a slow large sine on an offset plus uniform noise, rounded to
/// multiples of 2⁻⁴⁰ (so the exact oracle can take them as integers).
pub fn long_run_value(n: usize, noise: f64) -> f64 {
    let y = 100.0 * (n as f64 * 2.0 * std::f64::consts::PI / 5000.0).sin() + 50.0 + noise;
    (y * 2f64.powi(40)).round() / 2f64.powi(40)
}

/// Sliding-engine runs `(m, window, total samples, check every, seed)` for
/// [`sliding_long_run`]: the acceptance run (10⁷ samples, m = 2, window 1001) ...
pub const SLIDING_ACCEPTANCE_RUN: (usize, usize, usize, usize, u64) =
    (2, 1001, 10_000_000, 9973, 1);
/// ... shorter runs at other degrees and windows (every sample checked for the short windows) ...
pub const SLIDING_SHORTER_RUNS: [(usize, usize, usize, usize, u64); 5] = [
    (2, 11, 1_000_000, 1, 2),
    (4, 11, 1_000_000, 1, 2),
    (8, 101, 300_000, 7, 2),
    (2, 10001, 1_000_000, 9973, 2),
    (10, 1001, 300_000, 997, 2),
];
/// ... and 10⁷ samples at m = 4 with the longest window of the bench (L = 10⁴) and at m = 6.
pub const SLIDING_HIGHER_DEGREE_RUNS: [(usize, usize, usize, usize, u64); 2] = [
    (4, 10001, 10_000_000, 99991, 3),
    (6, 101, 10_000_000, 99991, 3),
];

/// Runs the sliding engine over `total` samples; every `every` samples (and over the last
/// `window` samples) compares its current estimate (scaled: z_i = x^(i)/i!, unit step) with
/// W(0) applied to the stored window. Returns the worst error relative to the data scale.
pub fn sliding_long_run(m: usize, window: usize, total: usize, every: usize, seed: u64) -> f64 {
    let l = window - 1;
    let w = weights(m, l as u64, 0.0).unwrap();
    let mut filt = FixedMemory::new(m, window, FixedEngine::Sliding).unwrap();
    let mut ring = vec![0.0; window];
    let mut rng = super::rng(seed);
    let mut worst = 0.0f64;
    let mut scale = 0.0f64;
    let facts: Vec<f64> = (0..=m).map(|i| f(&fact(i))).collect();
    for n in 0..total {
        let y = long_run_value(n, rng.gen::<f64>() - 0.5);
        scale = scale.max(y.abs());
        filt.update(n as f64, y).unwrap();
        ring[n % window] = y;
        if n >= l && (n % every == 0 || n + window >= total) {
            let s = filt.estimate().unwrap();
            for i in 0..=m {
                let zr: f64 = (0..window)
                    .map(|k| w[(i, k)] * ring[(n - k) % window])
                    .sum();
                worst = worst.max((s.derivatives[i] / facts[i] - zr).abs());
            }
        }
    }
    // Final state against exact least squares (integer arithmetic).
    let ys: Vec<f64> = (0..window)
        .map(|k| ring[(total - window + k) % window])
        .collect();
    let u: Vec<i64> = (0..window).map(|k| k as i64 - l as i64).collect();
    let exact = exact_discounted_even(&u, &ys, 1, 1, m, 1.0);
    let s = filt.estimate().unwrap();
    for i in 0..=m {
        worst = worst.max((s.derivatives[i] - exact[i]).abs() / facts[i]);
    }
    worst / scale
}

/// Morrison §9.5 (9.5.3)-(9.5.10): the sliding recursion μ' = M(μ − y_old 𝟙) + y_new s run
/// alone (no refreshes) and the sliding engine, m = 2, L = 100, over 10⁵ samples of
/// [`long_run_value`]: the errors of their position estimates against W(0) applied to the last
/// window, relative to the data scale 150, `(naive, engine)`.
pub fn naive_sliding_drift() -> (f64, f64) {
    let (m, l) = (2usize, 100usize);
    let window = l + 1;
    let basis = DiscreteLegendre::new(z(l as i64));
    // M from p_j(x-1) = Σ_l M_jl p_l(x), by exact polynomial algebra.
    let polys: Vec<_> = (0..=m).map(|j| basis.polynomial(j)).collect();
    let mut shift = vec![vec![0.0; m + 1]; m + 1];
    for j in 0..=m {
        let mut c: Vec<Q> = (0..=j)
            .map(|i| polys[j].taylor_coefficient(i, &z(-1)))
            .collect();
        for k in (0..=j).rev() {
            let g = c[k].clone() / polys[k].coeffs[k].clone();
            for (i, ci) in c.iter_mut().enumerate().take(k + 1) {
                *ci = ci.clone() - g.clone() * polys[k].coeffs[i].clone();
            }
            shift[j][k] = f(&g);
        }
    }
    let bf = DiscreteLegendre::new(l as f64);
    let table: Vec<Vec<f64>> = (0..window)
        .map(|x| (0..=m).map(|j| bf.value(j, x as f64)).collect())
        .collect();
    let t_end = bf.derivatives_by_recursion(m, 0, &(l as f64));
    let w = weights(m, l as u64, 0.0).unwrap();
    let mut rng = super::rng(4);
    let mut ring = vec![0.0; window];
    let mut mu = vec![0.0; m + 1];
    let mut filt = FixedMemory::new(m, window, FixedEngine::Sliding).unwrap();
    let total = 100_000;
    for n in 0..total {
        let y = long_run_value(n, rng.gen::<f64>() - 0.5);
        filt.update(n as f64, y).unwrap();
        let old = ring[n % window];
        ring[n % window] = y;
        if n == l {
            for x in 0..window {
                for j in 0..=m {
                    mu[j] += ring[x] * table[x][j];
                }
            }
        } else if n > l {
            let s: Vec<f64> = mu.iter().map(|v| v - old).collect();
            for j in 0..=m {
                let a: f64 = (0..=j).map(|k| shift[j][k] * s[k]).sum();
                mu[j] = if j % 2 == 0 { a + y } else { a - y };
            }
        }
    }
    let n = total - 1;
    let exact: f64 = (0..window)
        .map(|k| w[(0, k)] * ring[(n - k) % window])
        .sum();
    let naive: f64 = (0..=m).map(|j| t_end[(j, 0)] * mu[j] / bf.norm_sq(j)).sum();
    let engine = filt.estimate().unwrap().derivatives[0];
    (
        (naive - exact).abs() / 150.0,
        (engine - exact).abs() / 150.0,
    )
}
