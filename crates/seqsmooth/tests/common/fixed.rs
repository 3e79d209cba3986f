//! Shared by the fixed-memory tests and the `accuracy_fixed_filter` example.

use super::exact_discounted_even;
use super::rational::*;
use nalgebra::DMatrix;
use num_traits::Signed;
use rand::Rng;
use seqsmooth::basis::legendre::{taylor_table, values as legendre_values};
use seqsmooth::basis::DiscreteLegendre;
use seqsmooth::calculus::link_matrix;
use seqsmooth::linalg::mul;
use seqsmooth::model::phi;
use seqsmooth::polynomial::fixed::covariance;
use seqsmooth::polynomial::fixed::window_covariance;
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

/// Weights by Householder QR (nalgebra) of the Legendre design matrix on `r = 0..L` mapped to
/// `[-1, 1]`: `coefficients = R⁻¹ Qᵀ y`, then Taylor coefficients (per sample) at `r = L+h`.
/// Columns newest first, like `weights`.
pub fn qr_weights(m: usize, l: usize, h: f64) -> DMatrix<f64> {
    let n = l + 1;
    let hw = (l as f64 / 2.0).max(0.5);
    let a = DMatrix::from_fn(n, m + 1, |r, j| {
        legendre_values(m, (r as f64 - l as f64 / 2.0) / hw)[j]
    });
    let qr = a.qr();
    let qm = qr.q();
    let rinv = qr.r().try_inverse().expect("full rank");
    let coef = rinv * qm.transpose();
    let tt = taylor_table(m, m, (l as f64 + h - l as f64 / 2.0) / hw);
    let jac = DMatrix::from_fn(m + 1, m + 1, |k, j| tt[(k, j)] / hw.powi(k as i32));
    let w = jac * coef;
    DMatrix::from_fn(m + 1, n, |i, k| w[(i, l - k)])
}

/// Largest over rows of `max_k |a_ik - b_ik| / max_k |b_ik|`.
pub fn row_rel(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (0..a.nrows())
        .map(|i| {
            let scale = b.row(i).iter().fold(0.0f64, |s, v| s.max(v.abs()));
            let d = (0..a.ncols()).fold(0.0f64, |s, k| s.max((a[(i, k)] - b[(i, k)]).abs()));
            d / scale
        })
        .fold(0.0, f64::max)
}

/// `f64` [`weights`] against [`qr_weights`] (Householder QR on a Legendre design matrix), per
/// degree, window and lead: `(m, L, h, largest row-relative difference)`.
pub fn weights_vs_qr() -> Vec<(usize, usize, f64, f64)> {
    let mut out = Vec::new();
    for m in [0usize, 1, 2, 4, 6, 8, 10] {
        for l in [m.max(1), 10, 100, 1000, 10000] {
            if l < m {
                continue;
            }
            let lf = l as f64;
            for h in [0.0, 1.0, -lf / 2.0, 2.5, -lf - 3.0] {
                let w = weights(m, l as u64, h).unwrap();
                out.push((m, l, h, row_rel(&w, &qr_weights(m, l, h))));
            }
        }
    }
    out
}

/// `f64` [`weights`] (recursion A1.1) against the exact rational weights:
/// `(m, L, h, row-relative difference, at m = 10, L = 300 also that of the book's product
/// Φ(h) 𝒮 G C B (7.4.16) evaluated in f64 with the explicit sums (3.2.20))`.
pub fn weights_vs_exact() -> Vec<(usize, i64, Q, f64, Option<f64>)> {
    let mut out = Vec::new();
    for (m, l) in [
        (4usize, 40i64),
        (8, 40),
        (10, 40),
        (4, 300),
        (8, 300),
        (10, 300),
    ] {
        for h in [z(0), fr(-l, 2), z(-l - 3)] {
            let exact = to_f64(&weights(m, l as u64, h.clone()).unwrap());
            let w = weights(m, l as u64, f(&h)).unwrap();
            let e = row_rel(&w, &exact);
            let book = (m == 10 && l == 300).then(|| {
                let hb = f(&h);
                let b = DiscreteLegendre::new(l as f64);
                let c =
                    DMatrix::from_fn(
                        m + 1,
                        m + 1,
                        |i, j| if i == j { 1.0 / b.norm_sq(j) } else { 0.0 },
                    );
                let bm = DMatrix::from_fn(m + 1, (l + 1) as usize, |i, j| {
                    b.value(i, (l - j as i64) as f64)
                });
                let book = mul(
                    &mul(
                        &mul(
                            &mul(&phi(m, hb), &link_matrix::<f64>(m)),
                            &b.end_differences(m),
                        ),
                        &c,
                    ),
                    &bm,
                );
                row_rel(&book, &exact)
            });
            out.push((m, l, h, e, book));
        }
    }
    out
}

/// Long windows, low degree, at the centre: `f64` [`weights`] against the exact weights,
/// `L = 10⁴`: `(m, row-relative difference)`.
pub fn weights_vs_exact_long_windows() -> Vec<(usize, f64)> {
    [1usize, 2]
        .into_iter()
        .map(|m| {
            let l = 10_000i64;
            let exact = to_f64(&weights(m, l as u64, fr(-l, 2)).unwrap());
            (
                m,
                row_rel(&weights(m, l as u64, -(l as f64) / 2.0).unwrap(), &exact),
            )
        })
        .collect()
}

/// The `f64` covariance at the centre (m = 8, L = 1000, h = -500) against the exact one,
/// largest entry error relative to `√(S_ii S_jj)`: `(the library's recursion, the Φ(h)-product
/// form of vrf::window_covariance)`.
pub fn centre_covariance_errors() -> (f64, f64) {
    let (m, l) = (8usize, 1000i64);
    let exact = to_f64(&covariance(m, l as u64, fr(-l, 2)).unwrap());
    let got = covariance(m, l as u64, -(l as f64) / 2.0).unwrap();
    let wc = window_covariance(m, l as u64, -(l as f64) / 2.0);
    let rel = |a: &DMatrix<f64>| {
        (0..=m)
            .flat_map(|i| (0..=m).map(move |j| (i, j)))
            .map(|(i, j)| {
                (a[(i, j)] - exact[(i, j)]).abs() / (exact[(i, i)] * exact[(j, j)]).sqrt()
            })
            .fold(0.0, f64::max)
    };
    (rel(&got), rel(&wc))
}
