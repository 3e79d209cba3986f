//! Whole-series smoothing ([`smooth`]) on evenly spaced samples runs the sliding moment engine
//! of the fixed-memory filter (`O(m²)` per sample at any window). Oracle: the convolution with
//! the exact weights `D(τ) W(h)` (Morrison (7.4.9)-(7.4.16), computed in rationals and rounded
//! once), summed with error-free transformations (two-sum, two-product), so the oracle's own
//! error is a few ulps of each output. Every interior sample (`h = -L/2`, the centre) and, at
//! both ends ("interp" mode), the samples evaluated off-centre in the first and last window at
//! `r = 0, 1, ⌊L/2⌋ - 1` (and the mirrored `r` in the last window).

mod common;

use common::smooth::{worst_error, SMOOTH_RUNS};
use seqsmooth::polynomial::fixed::smooth;

#[test]
fn smooth_equals_exact_convolution_at_any_window() {
    // Bound 1e-11 relative to each derivative's scale (measured: ACCURACY.md, `cargo run
    // --release -p seqsmooth --example accuracy_smooth`).
    for (m, window, len) in SMOOTH_RUNS {
        let e = worst_error(m, window, len);
        for (i, e) in e.iter().enumerate() {
            assert!(
                *e <= 1e-11,
                "m = {m}, window = {window}, derivative {i}: {e:.2e}"
            );
        }
    }
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
        for d in 0..=m {
            let scale = times.iter().map(|&t| poly(t, d).abs()).fold(0.0, f64::max);
            for (row, &t) in got.iter().zip(&times) {
                let e = (row[d] - poly(t, d)).abs() / scale;
                assert!(
                    e <= 1e-10,
                    "m = {m}, window = {window}, t = {t}, derivative {d}: {e:.2e}"
                );
            }
        }
    }
}
