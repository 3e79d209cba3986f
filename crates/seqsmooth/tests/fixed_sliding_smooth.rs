//! Whole-series smoothing ([`smooth`]) on evenly spaced samples runs the sliding moment engine
//! of the fixed-memory filter (`O(m²)` per sample at any window). Oracle: the convolution with
//! the exact weights `D(τ) W(h)` (Morrison (7.4.9)-(7.4.16), computed in rationals and rounded
//! once), summed with error-free transformations (two-sum, two-product), so the oracle's own
//! error is a few ulps of each output. Every interior sample (`h = -L/2`, the centre) and, at
//! both ends ("interp" mode), the samples evaluated off-centre in the first and last window at
//! `r = 0, 1, ⌊L/2⌋ - 1` (and the mirrored `r` in the last window).

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
fn worst_error(m: usize, window: usize, len: usize) -> Vec<f64> {
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

#[test]
fn smooth_equals_exact_convolution_at_any_window() {
    // Each series runs through several refresh periods of the sliding engine. Bound 1e-11
    // relative to each derivative's scale (measured worst 2.6e-12, m = 4, window 1001,
    // second derivative).
    let mut report = Vec::new();
    for (m, window, len) in [
        (0usize, 1usize, 50usize),
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
    ] {
        let e = worst_error(m, window, len);
        let shown: Vec<String> = e.iter().map(|v| format!("{v:.1e}")).collect();
        report.push(format!(
            "| {m} | {window} | {len} | {} |",
            shown.join(" | ")
        ));
        for (i, e) in e.iter().enumerate() {
            assert!(
                *e <= 1e-11,
                "m = {m}, window = {window}, derivative {i}: {e:.2e}"
            );
        }
    }
    println!("smooth vs exact convolution:\n{}", report.join("\n"));
}

#[test]
fn smooth_is_exact_on_polynomials_of_its_degree() {
    // A degree-m polynomial is its own least-squares fit: every row reproduces it and its
    // derivatives, at the centre and at the ends (times in [-1, 2], so every derivative is of
    // order one). Error relative to each derivative's largest magnitude over the series.
    let c = [1.5, -0.5, 0.25, -0.125, 0.0625];
    for (m, window) in [(1usize, 7usize), (2, 101), (3, 64), (4, 1001)] {
        let len = 3 * window;
        let step = 1.0 / window as f64;
        let times: Vec<f64> = (0..len)
            .map(|k| (k as f64 - window as f64) * step)
            .collect();
        let poly = |t: f64, d: usize| -> f64 {
            (d..=m)
                .map(|k| {
                    let falling: f64 = (0..d).map(|j| (k - j) as f64).product();
                    c[k] * falling * t.powi((k - d) as i32)
                })
                .sum()
        };
        let ys: Vec<f64> = times.iter().map(|&t| poly(t, 0)).collect();
        let got = smooth(&times, &ys, m, window).unwrap();
        let mut worst = 0.0f64;
        for d in 0..=m {
            let scale = times.iter().map(|&t| poly(t, d).abs()).fold(0.0, f64::max);
            for (row, &t) in got.iter().zip(&times) {
                let e = (row[d] - poly(t, d)).abs() / scale;
                assert!(
                    e <= 1e-10,
                    "m = {m}, window = {window}, t = {t}, derivative {d}: {e:.2e}"
                );
                worst = worst.max(e);
            }
        }
        println!("m = {m}, window = {window}: worst {worst:.1e}");
    }
}
