//! Whole-series smoothing (`seqsmooth::polynomial::fixed::smooth`; Morrison (1969) §7.3): exact
//! least squares on even and irregular times, the Savitzky-Golay coefficients, bad input.

mod common;

use common::fixed::*;
use common::{dyadic, exact_discounted_even, exact_ls_derivatives, jittered_times};
use rand::Rng;
use seqsmooth::polynomial::fixed::{
    smooth, smooth_detrended, smooth_into, weights_unscaled, Nominal,
};
use seqsmooth::polynomial::MAX_DEGREE;
use seqsmooth::{Error, Param};

/// The window rule of savgol's "interp" mode: the window of `w` samples centred on `n`
/// (`⌊(w-1)/2⌋` before it), clamped to the series.
fn savgol_window(n: usize, w: usize, len: usize) -> usize {
    n.saturating_sub((w - 1) / 2).min(len - w)
}

/// Largest `|got_k[i] - want_k[i]|` over the series, relative to the largest `|want_k[i]|`.
fn column_error(got: &[Vec<f64>], want: &[Vec<f64>], i: usize) -> f64 {
    let scale = want.iter().fold(0.0f64, |a, r| a.max(r[i].abs()));
    got.iter()
        .zip(want)
        .map(|(a, b)| (a[i] - b[i]).abs())
        .fold(0.0, f64::max)
        / scale
}

#[test]
fn smooth_even_spacing_equals_exact_least_squares() {
    // Every sample against the exact fit of its window (integer arithmetic), derivatives 0-2,
    // relative to each derivative's largest magnitude over the series. Measured worst 3.5e-14
    // (bound 1e-12).
    let step = 0.5;
    for (m, window, len) in [
        (0usize, 1usize, 40usize),
        (0, 7, 60),
        (1, 3, 60),
        (2, 5, 60),
        (2, 7, 200),
        (3, 21, 150),
        (3, 20, 90),
        (4, 51, 250),
        (5, 11, 100),
        (5, 6, 40),
        (2, 201, 420),
        (5, 201, 450),
    ] {
        let times: Vec<f64> = (0..len).map(|k| 10.0 + k as f64 * step).collect();
        let mut ys = common::noisy_polynomial(&times, 3, 40.0, 0.5, 21);
        for (y, t) in ys.iter_mut().zip(&times) {
            *y += 3.0 * (0.3 * t).sin();
        }
        let ys = dyadic(&ys);
        let got = smooth(&times, &ys, m, window).unwrap();
        let want: Vec<Vec<f64>> = (0..len)
            .map(|n| {
                let s = savgol_window(n, window, len);
                let u: Vec<i64> = (s..s + window).map(|k| k as i64 - n as i64).collect();
                exact_discounted_even(&u, &ys[s..s + window], 1, 1, m, step)
            })
            .collect();
        for i in 0..=m.min(2) {
            let e = column_error(&got, &want, i);
            assert!(
                e <= 1e-12,
                "m = {m}, window = {window}, derivative {i}: {e:.2e}"
            );
        }
    }
}

#[test]
fn smooth_matches_savgol_coefficients() {
    // savgol_coeffs(5, 2) = (-3, 12, 17, 12, -3)/35 (T7-06 W(-2) row 0); first derivative,
    // window 7, m = 2: Σ j y_{n+j} / (28 Δt); second derivative, window 5, m = 2:
    // (2, -1, -2, -1, 2)/(7 Δt²) (= 2 × T7-06 row z2).
    let dt = 0.1;
    let times: Vec<f64> = (0..30).map(|k| k as f64 * dt).collect();
    let mut rng = common::rng(8);
    let ys: Vec<f64> = (0..30).map(|_| rng.gen::<f64>()).collect();
    let s5 = smooth(&times, &ys, 2, 5).unwrap();
    let s7 = smooth(&times, &ys, 2, 7).unwrap();
    for n in 3..27 {
        let y = |j: i64| ys[(n as i64 + j) as usize];
        let v = (-3.0 * y(-2) + 12.0 * y(-1) + 17.0 * y(0) + 12.0 * y(1) - 3.0 * y(2)) / 35.0;
        let d2 = (2.0 * y(-2) - y(-1) - 2.0 * y(0) - y(1) + 2.0 * y(2)) / (7.0 * dt * dt);
        let d1 = (-3..=3).map(|j| j as f64 * y(j)).sum::<f64>() / (28.0 * dt);
        assert!((s5[n][0] - v).abs() < 1e-14);
        assert!((s5[n][2] - d2).abs() < 1e-11);
        assert!((s7[n][1] - d1).abs() < 1e-13);
    }
    // Edges ("interp"): the first full window's fit evaluated at samples 0 and 1.
    let w = weights_unscaled(2, 4, -4.0, dt).unwrap();
    let v: Vec<f64> = (0..3)
        .map(|i| (0..5).map(|k| w[(i, k)] * ys[4 - k]).sum())
        .collect();
    assert!(rel_to_scale(&s5[0], &v, 1.0, dt) < 1e-13);
}

#[test]
fn smooth_irregular_spacing_equals_exact_least_squares() {
    // Irregular times (detected: a step off by more than 1e-9 relative) use per-sample QR fits.
    // Measured worst 1.3e-13 relative to each derivative's scale (bound 1e-10).
    let times = jittered_times(120, 0.1, 0.3, 12);
    let ys = common::noisy_polynomial(&times, 4, 3.0, 0.1, 13);
    for (m, window) in [(1usize, 5usize), (2, 9), (3, 15), (4, 31), (2, 120)] {
        let got = smooth(&times, &ys, m, window).unwrap();
        let want: Vec<Vec<f64>> = (0..times.len())
            .map(|n| {
                let s = savgol_window(n, window, times.len());
                exact_ls_derivatives(&times[s..s + window], &ys[s..s + window], None, m, times[n])
            })
            .collect();
        for i in 0..=m.min(2) {
            let e = column_error(&got, &want, i);
            assert!(
                e <= 1e-10,
                "m = {m}, window = {window}, derivative {i}: {e:.2e}"
            );
        }
    }
    // Nearly even times (one step off by 1e-6 relative) are irregular: the fit uses the true
    // times, not an assumed grid.
    let mut t: Vec<f64> = (0..40).map(|k| k as f64).collect();
    t[20] += 1e-6;
    let y: Vec<f64> = t.iter().map(|t| t * t).collect();
    let s = smooth(&t, &y, 1, 5).unwrap();
    let want = exact_ls_derivatives(&t[18..23], &y[18..23], None, 1, t[20]);
    assert!((s[20][0] - want[0]).abs() < 1e-12 && (s[20][1] - want[1]).abs() < 1e-12);
}

#[test]
fn smooth_rejects_bad_input() {
    let t = [0.0, 1.0, 2.0, 3.0];
    let y = [1.0, 2.0, 3.0, 4.0];
    assert!(matches!(
        smooth(&t, &y, 1, 5),
        Err(Error::TooFewSamplesFor {
            param: Param::Window,
            needed: 5,
            got: 4
        })
    ));
    assert!(matches!(
        smooth(&t, &y, 2, 2),
        Err(Error::InvalidParameter {
            name: Param::Window,
            ..
        })
    ));
    assert!(matches!(
        smooth(&t, &y[..3], 1, 3),
        Err(Error::InvalidParameter { .. })
    ));
    assert!(matches!(
        smooth(&[0.0, 1.0, 1.0, 2.0], &y, 1, 3),
        Err(Error::TimeNotIncreasing { .. })
    ));
    assert!(matches!(
        smooth(&t, &[1.0, f64::NAN, 3.0, 4.0], 1, 3),
        Err(Error::NonFinite { what: "value", .. })
    ));
    assert!(matches!(
        smooth(&t, &y, MAX_DEGREE + 1, 30),
        Err(Error::DegreeOutOfRange { .. })
    ));
    let rows = vec![vec![0.0]; 3];
    assert!(smooth_detrended(&t, &y, 1, 3, Nominal::Samples(&rows)).is_err());
    let bad = |_: f64| vec![f64::NAN];
    assert!(smooth_detrended(&t, &y, 1, 3, Nominal::Function(&bad)).is_err());
}

#[test]
fn smooth_into_writes_the_rows_of_smooth() {
    // The flat form is the same computation: bit for bit the rows of `smooth`, on even and on
    // irregular times, degrees 0-10.
    let mut rng = common::rng(11);
    for m in 0..=10usize {
        let window = 2 * m + 5;
        let len = 3 * window;
        let even: Vec<f64> = (0..len).map(|k| 0.25 * k as f64).collect();
        let uneven = jittered_times(len, 0.25, 0.3, 5 + m as u64);
        let y: Vec<f64> = (0..len).map(|_| rng.gen_range(-1.0..1.0)).collect();
        for t in [&even, &uneven] {
            let rows = smooth(t, &y, m, window).unwrap();
            let mut flat = vec![f64::NAN; len * (m + 1)];
            smooth_into(t, &y, m, window, &mut flat).unwrap();
            assert_eq!(flat, rows.concat(), "m = {m}");
        }
    }
}

#[test]
fn smooth_rejects_bad_input_anywhere_in_long_series() {
    // The first bad sample is the error, wherever it is (the check runs over blocks).
    let len = 2000;
    let t: Vec<f64> = (0..len).map(|k| k as f64).collect();
    let y = vec![1.0; len];
    for k in [0, 1, 255, 256, 257, 1999] {
        let mut yb = y.clone();
        yb[k] = f64::INFINITY;
        assert_eq!(
            smooth(&t, &yb, 2, 11),
            Err(Error::NonFinite {
                what: "value",
                value: f64::INFINITY
            })
        );
        if k > 0 {
            let mut tb = t.clone();
            tb[k] = tb[k - 1];
            assert_eq!(
                smooth(&tb, &y, 2, 11),
                Err(Error::TimeNotIncreasing {
                    time: tb[k],
                    previous: tb[k - 1]
                })
            );
        }
    }
    let mut short = vec![0.0; len * 3 - 1];
    assert!(matches!(
        smooth_into(&t, &y, 2, 11, &mut short),
        Err(Error::InvalidParameter {
            name: Param::EstimatesLength,
            ..
        })
    ));
}

/// A derivative beyond the double range is refused with its sample, even and irregular
/// times alike: values near 1e308 at steps of 1e-3 have first derivatives near 1e311. The
/// same values at unit steps are in range and returned.
#[test]
fn smooth_refuses_derivatives_beyond_the_double_range() {
    let mut y = vec![1.0; 10];
    (y[3], y[4]) = (1e308, -1e308);
    let even: Vec<f64> = (0..10).map(|k| 1e-3 * k as f64).collect();
    let irregular: Vec<f64> = even.iter().map(|t| t * (1.0 + 0.01 * t)).collect();
    for t in [&even, &irregular] {
        match smooth(t, &y, 2, 5) {
            Err(Error::InBatch { index, source }) => {
                assert!(index < 10);
                assert!(
                    matches!(*source, Error::EstimateOutOfRange { ref what } if what.starts_with('d')),
                    "{source}"
                );
            }
            other => panic!("expected an error, got {other:?}"),
        }
    }
    let unit: Vec<f64> = (0..10).map(f64::from).collect();
    let rows = smooth(&unit, &y, 2, 5).unwrap();
    assert!(rows.iter().flatten().all(|v| v.is_finite()));
}
