//! Whole-series smoothing against `scipy.signal.savgol_filter(..., mode="interp")` on stored
//! fixtures: degrees 0-5, windows 5-201, derivatives 0-2, 400 evenly
//! spaced samples. The fixtures and the script that made them: tests/fixtures/savgol/ and
//! scripts/make_savgol_fixtures.py (numpy/scipy versions in versions.txt).
//!
//! Tolerance 1e-8 relative to the largest magnitude of each output column: scipy itself solves
//! the window's least-squares problem in a monomial basis by `lstsq`, and its own error reaches
//! ~5e-9 at window 201, degree 5 (measured against exact rational fits).

use seqsmooth::polynomial::fixed::smooth;
use std::collections::BTreeMap;

fn fixture(name: &str) -> String {
    let path = format!(
        "{}/tests/fixtures/savgol/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

#[test]
fn smooth_matches_scipy_savgol_filter_interp_mode() {
    let input = fixture("input.csv");
    let (mut t, mut y) = (Vec::new(), Vec::new());
    for line in input.lines().skip(1) {
        let (a, b) = line.split_once(',').unwrap();
        t.push(a.parse::<f64>().unwrap());
        y.push(b.parse::<f64>().unwrap());
    }
    // (degree, window, deriv) -> values by index
    let mut cases: BTreeMap<(usize, usize, usize), Vec<f64>> = BTreeMap::new();
    for line in fixture("cases.csv").lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let key = (
            f[0].parse().unwrap(),
            f[1].parse().unwrap(),
            f[2].parse().unwrap(),
        );
        let v: f64 = f[4].parse().unwrap();
        cases.entry(key).or_default().push(v);
    }
    assert_eq!(
        cases.len(),
        6 * 6 * 3 - 3,
        "every (degree, window, deriv) case is stored"
    );
    for (&(m, window, deriv), want) in &cases {
        let got = smooth(&t, &y, m, window).unwrap();
        let scale = want.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        for (i, w) in want.iter().enumerate() {
            // savgol returns zeros for deriv > degree; the polynomial has no such derivative.
            let g = got[i].get(deriv).copied().unwrap_or(0.0);
            let err = if scale > 0.0 {
                (g - w).abs() / scale
            } else {
                (g - w).abs()
            };
            assert!(err <= 1e-8, "degree {m}, window {window}, deriv {deriv}, sample {i}: {g} vs scipy {w} ({err:e})");
        }
    }
}
