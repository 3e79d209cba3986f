//! `smooth` on the sliding engine against the exact-weight convolution: the measurement that
//! `tests/fixed_sliding_smooth.rs` asserts on and `examples/accuracy_smooth.rs` prints.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use seqsmooth::polynomial::fixed::{smooth, weights};
use seqsmooth::scalar::{Rational, Scalar};

/// `a + b = s + e` exactly (Knuth's two-sum).
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

/// `Σ a_k b_k`, accurate to about one rounding of the result (Ogita, Rump & Oishi's `Dot2`).
fn dot2(a: &[f64], b: &[f64]) -> f64 {
    let (mut s, mut c) = (0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        let p = x * y;
        let pe = x.mul_add(*y, -p);
        let (t, e) = two_sum(s, p);
        s = t;
        c += e + pe;
    }
    s + c
}

/// The exact weights of the fit of degree `m` over span `L` at window position `r`
/// (`h = r - L`), rounded to `f64`, as rows `i = 0..=m` of unscaled derivatives for samples
/// `step` apart, oldest sample first.
fn exact_kernels(m: usize, span: usize, r: usize, step: f64) -> Vec<Vec<f64>> {
    let h = Rational::from_i64(r as i64 - span as i64);
    let w = weights(m, span as u64, h).unwrap();
    (0..=m)
        .map(|i| {
            let scale = seqsmooth::calculus::factorial::<f64>(i) / step.powi(i as i32);
            (0..=span)
                .rev()
                .map(|k| w[(i, k)].to_f64() * scale)
                .collect()
        })
        .collect()
}

/// A cubic trend, a sine and uniform noise: `|y| ≲ 100`.
fn series(len: usize, step: f64, seed: u64) -> (Vec<f64>, Vec<f64>) {
    let mut rng = StdRng::seed_from_u64(seed);
    let times: Vec<f64> = (0..len).map(|k| k as f64 * step).collect();
    let tl = times[len - 1];
    let ys = times
        .iter()
        .map(|&t| {
            let u = t / tl - 0.4;
            40.0 * (1.0 + u - 2.0 * u * u + 3.0 * u * u * u)
                + 5.0 * (7.0 * u).sin()
                + 0.5 * (2.0 * rng.gen::<f64>() - 1.0)
        })
        .collect();
    (times, ys)
}

/// The worst error of `smooth` against the exact convolution, per derivative `0..=min(m, 2)`,
/// relative to that derivative's largest magnitude over the rows checked.
pub fn worst_error(m: usize, window: usize, len: usize) -> Vec<f64> {
    let step = 0.5;
    let (times, ys) = series(len, step, 7 + m as u64 + window as u64);
    let got = smooth(&times, &ys, m, window).unwrap();
    let span = window - 1;
    let half = span / 2;
    let last = len - window;
    // (row, window start, position r in that window)
    let mut rows: Vec<(usize, usize, usize)> =
        (half..=last + half).map(|n| (n, n - half, half)).collect();
    for r in [0, 1, half.saturating_sub(1)] {
        if r < half {
            rows.push((r, 0, r));
            rows.push((last + span - r, last, span - r));
        }
    }
    let mut kernels = std::collections::BTreeMap::new();
    let mut want = Vec::with_capacity(rows.len());
    for &(n, s, r) in &rows {
        let k = kernels
            .entry(r)
            .or_insert_with(|| exact_kernels(m, span, r, step));
        want.push((
            n,
            k.iter()
                .map(|row| dot2(row, &ys[s..s + window]))
                .collect::<Vec<f64>>(),
        ));
    }
    (0..=m.min(2))
        .map(|i| {
            let scale = want.iter().fold(0.0f64, |a, (_, w)| a.max(w[i].abs()));
            want.iter()
                .map(|(n, w)| (got[*n][i] - w[i]).abs())
                .fold(0.0, f64::max)
                / scale
        })
        .collect()
}

/// The runs `(degree, window, samples)`: each series runs through several refresh periods of
/// the sliding engine.
pub const SMOOTH_RUNS: [(usize, usize, usize); 19] = [
    (0, 1, 50),
    (0, 11, 400),
    (1, 2, 60),
    (1, 101, 500),
    (2, 3, 60),
    (2, 11, 400),
    (2, 12, 400),
    (2, 101, 800),
    (2, 1001, 4000),
    (2, 10001, 25000),
    (3, 101, 600),
    (4, 11, 300),
    (4, 1001, 4000),
    (5, 6, 100),
    (5, 201, 1000),
    (6, 101, 600),
    (8, 11, 300),
    (8, 301, 1500),
    (10, 1001, 3500),
];
