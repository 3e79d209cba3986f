//! Shared test helpers: reproducible data (time grids, noisy polynomials), independent oracles
//! (batch least squares by QR, exact rational and integer least squares), and, in the
//! submodules, the helpers of one group of tests each.
#![allow(dead_code, clippy::needless_range_loop)]

pub mod automatic;
pub mod bank;
pub mod batch;
pub mod book;
pub mod engine;
pub mod fixed;
pub mod kalman;
pub mod monte_carlo;
pub mod paml;
pub mod python_fixture;
pub mod radar_tracks;
pub mod rational;
pub mod smooth;
pub mod stats;

use num_traits::{One, Zero};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use seqsmooth::estimate::PolynomialFit;
use seqsmooth::scalar::{rational_from_f64, Rational, Scalar};

pub fn rng(seed: u64) -> StdRng {
    StdRng::seed_from_u64(seed)
}

/// Evenly spaced times `t0 + k·step`.
pub fn even_times(n: usize, t0: f64, step: f64) -> Vec<f64> {
    (0..n).map(|k| t0 + k as f64 * step).collect()
}

/// Jittered times: nominal step with ±`jitter`·step uniform perturbation of each step.
pub fn jittered_times(n: usize, step: f64, jitter: f64, seed: u64) -> Vec<f64> {
    let mut r = rng(seed);
    let mut t = 0.0;
    (0..n)
        .map(|_| {
            let v = t;
            t += step * (1.0 + jitter * (2.0 * r.gen::<f64>() - 1.0));
            v
        })
        .collect()
}

/// Random times: exponential gaps (a Poisson process) with the given mean step, no gap below
/// 1e-3 steps.
pub fn random_times(n: usize, mean_step: f64, seed: u64) -> Vec<f64> {
    let mut r = rng(seed);
    let mut t = 10.0;
    (0..n)
        .map(|_| {
            let v = t;
            let u: f64 = r.gen::<f64>();
            t += mean_step * (-(1.0 - u).ln()).max(1e-3);
            v
        })
        .collect()
}

/// A degree-`m` truth with O(1) coefficients on the time scale `span`, plus N(0, σ²) noise.
pub fn noisy_polynomial(times: &[f64], m: usize, span: f64, sigma: f64, seed: u64) -> Vec<f64> {
    let mut r = rng(seed);
    let coeffs: Vec<f64> = (0..=m).map(|_| 2.0 * r.gen::<f64>() - 1.0 + 0.5).collect();
    let noise = Normal::new(0.0, sigma).unwrap();
    let t0 = times[0];
    times
        .iter()
        .map(|&t| {
            let u = (t - t0) / span - 0.3;
            coeffs.iter().rev().fold(0.0, |acc, c| acc * u + c) + noise.sample(&mut r)
        })
        .collect()
}

/// Relative difference per derivative with a floor: `|a-b| / max(|b|, floor_k)`.
pub fn rel_err(a: &[f64], b: &[f64], floor: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .zip(floor)
        .map(|((x, y), f)| (x - y).abs() / y.abs().max(*f))
        .fold(0.0, f64::max)
}

/// Batch weighted least squares by QR on a Legendre basis (the library's batch fitter, a
/// different algorithm from the recursive engines), over the samples with non-negligible weight.
pub fn batch_fit(times: &[f64], ys: &[f64], weights: Option<&[f64]>, m: usize) -> PolynomialFit {
    match weights {
        None => PolynomialFit::new(times, ys, None, m).unwrap(),
        Some(w) => {
            // Drop samples whose weight is below 1e-40 of the newest: they change nothing in f64,
            // and keeping them would stretch the Legendre interval over an empty past.
            let keep: Vec<usize> = (0..times.len()).filter(|&k| w[k] > 1e-40).collect();
            let t: Vec<f64> = keep.iter().map(|&k| times[k]).collect();
            let y: Vec<f64> = keep.iter().map(|&k| ys[k]).collect();
            let ww: Vec<f64> = keep.iter().map(|&k| w[k]).collect();
            PolynomialFit::new(&t, &y, Some(&ww), m).unwrap()
        }
    }
}

/// Exact rational least squares (normal equations solved in exact arithmetic, so conditioning
/// is irrelevant): derivatives of the fitted polynomial at `at`, for f64 inputs taken exactly.
pub fn exact_ls_derivatives(
    times: &[f64],
    ys: &[f64],
    weights: Option<&[Rational]>,
    m: usize,
    at: f64,
) -> Vec<f64> {
    let c = rational_from_f64(at).unwrap();
    let p = m + 1;
    let mut a = vec![vec![Rational::zero(); p]; p];
    let mut b = vec![Rational::zero(); p];
    for k in 0..times.len() {
        let u = rational_from_f64(times[k]).unwrap() - c.clone();
        let y = rational_from_f64(ys[k]).unwrap();
        let w = weights.map_or_else(Rational::one, |w| w[k].clone());
        let mut pw = vec![Rational::one(); 2 * p];
        for i in 1..2 * p {
            pw[i] = pw[i - 1].clone() * u.clone();
        }
        for i in 0..p {
            b[i] += w.clone() * pw[i].clone() * y.clone();
            for j in 0..p {
                a[i][j] += w.clone() * pw[i + j].clone();
            }
        }
    }
    let coeffs = solve_rational(a, b);
    coeffs
        .into_iter()
        .enumerate()
        .map(|(k, c)| (c * seqsmooth::calculus::factorial::<Rational>(k)).to_f64())
        .collect()
}

/// Rounds values to multiples of 2⁻⁴⁰ so that `y·2⁴⁰` is an exact integer (for the fast exact
/// oracle below).
pub fn dyadic(ys: &[f64]) -> Vec<f64> {
    ys.iter()
        .map(|y| (y * 2f64.powi(40)).round() / 2f64.powi(40))
        .collect()
}

/// Exact discounted least squares on evenly spaced samples, in integer arithmetic: samples at
/// integer offsets `u_k` (in steps, relative to the evaluation point), values `y_k` multiples of
/// 2⁻⁴⁰, weights `θ^(n-k)` with `θ = p/q`, scaled by `q^n` to integers
/// `p^(n-k) q^k`. Returns the derivatives (per step unit `step`) at `u = 0`.
pub fn exact_discounted_even(
    u: &[i64],
    ys: &[f64],
    p: u64,
    q: u64,
    m: usize,
    step: f64,
) -> Vec<f64> {
    use num_bigint::BigInt;
    let n = u.len() - 1;
    let scale = 2f64.powi(40);
    let mut w = vec![BigInt::from(1); n + 1];
    // w_k = p^(n-k) q^k
    let mut pw = BigInt::from(1);
    for k in (0..=n).rev() {
        w[k] = pw.clone();
        pw *= p;
    }
    let mut qk = BigInt::from(1);
    for wk in w.iter_mut() {
        *wk *= &qk;
        qk *= q;
    }
    let dim = m + 1;
    let mut s = vec![BigInt::from(0); 2 * dim];
    let mut t = vec![BigInt::from(0); dim];
    for k in 0..=n {
        let y = BigInt::from((ys[k] * scale) as i64);
        let mut pu = w[k].clone();
        for j in 0..2 * dim {
            s[j] += &pu;
            if j < dim {
                t[j] += &pu * &y;
            }
            pu *= u[k];
        }
    }
    let a: Vec<Vec<Rational>> = (0..dim)
        .map(|i| {
            (0..dim)
                .map(|j| Rational::from_integer(s[i + j].clone()))
                .collect()
        })
        .collect();
    let b: Vec<Rational> = t.into_iter().map(Rational::from_integer).collect();
    let coeffs = solve_rational(a, b);
    coeffs
        .into_iter()
        .enumerate()
        .map(|(k, c)| {
            (c * seqsmooth::calculus::factorial::<Rational>(k)).to_f64()
                / scale
                / step.powi(k as i32)
        })
        .collect()
}

/// Solves the square system `a x = b` exactly (Gauss–Jordan over the rationals).
pub fn solve_rational(mut a: Vec<Vec<Rational>>, mut b: Vec<Rational>) -> Vec<Rational> {
    let p = b.len();
    for col in 0..p {
        let piv = (col..p).find(|&r| !a[r][col].is_zero()).expect("singular");
        a.swap(col, piv);
        b.swap(col, piv);
        for r in 0..p {
            if r != col && !a[r][col].is_zero() {
                let f = a[r][col].clone() / a[col][col].clone();
                for j in col..p {
                    let v = a[col][j].clone() * f.clone();
                    a[r][j] -= v;
                }
                let v = b[col].clone() * f;
                b[r] -= v;
            }
        }
    }
    (0..p).map(|k| b[k].clone() / a[k][k].clone()).collect()
}
