//! End-to-end tests of `seqsmooth smooth`: the library and scipy's savgol_filter.

use seqsmooth::polynomial::fixed::smooth;
use std::path::PathBuf;

mod common;
use common::*;

fn savgol_fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../seqsmooth/tests/fixtures/savgol")
        .join(name)
}

/// `smooth` writes t,y,d0..dM with the library's `fixed::smooth` values bit for bit, on evenly
/// spaced and on irregular times, one row per input row with t and y echoed.
#[test]
fn smooth_equals_library() {
    for irregular in [false, true] {
        let mut input = String::from("t,y\n");
        let (mut times, mut values) = (Vec::new(), Vec::new());
        let mut t = 0.0;
        for k in 0..80 {
            t += if irregular {
                0.1 + 0.03 * ((k * 5 % 7) as f64)
            } else {
                0.1
            };
            let y = (1.3 * t).cos() * 5.0 + 0.2 * ((k * 11 % 9) as f64);
            times.push(t);
            values.push(y);
            input += &format!("{t},{y}\n");
        }
        for (degree, window) in [(0, 1), (2, 11), (3, 12), (4, 80)] {
            let out = ok(
                &[
                    "smooth",
                    "--degree",
                    &degree.to_string(),
                    "--window",
                    &window.to_string(),
                ],
                &input,
            );
            let (header, rows) = table(&out);
            let mut want_header = vec!["t".to_string(), "y".to_string()];
            want_header.extend((0..=degree).map(|k| format!("d{k}")));
            assert_eq!(header, want_header);
            let want = smooth(&times, &values, degree, window).unwrap();
            assert_eq!(rows.len(), want.len());
            for (k, (row, w)) in rows.iter().zip(&want).enumerate() {
                assert_eq!(num(&row[0]).to_bits(), times[k].to_bits());
                assert_eq!(num(&row[1]).to_bits(), values[k].to_bits());
                assert_eq!(row.len(), 2 + w.len());
                for (cell, v) in row[2..].iter().zip(w) {
                    assert_eq!(
                        num(cell).to_bits(),
                        v.to_bits(),
                        "{irregular} {degree} {window}"
                    );
                }
            }
        }
    }
}

/// `smooth --degree 2 --window 11` on the stored scipy fixture (400 evenly spaced samples)
/// matches `scipy.signal.savgol_filter(y, 11, 2, deriv=k, delta=0.05, mode="interp")` for
/// k = 0, 1 (and 2) within 1e-8 relative to the largest magnitude of each column (the
/// library's savgol test tolerance).
#[test]
fn smooth_matches_scipy_savgol_fixture() {
    let input = savgol_fixture("input.csv");
    let out = ok(
        &[
            "smooth",
            input.to_str().unwrap(),
            "--degree",
            "2",
            "--window",
            "11",
        ],
        "",
    );
    let (header, rows) = table(&out);
    assert_eq!(header, ["t", "y", "d0", "d1", "d2"]);
    assert_eq!(rows.len(), 400);
    let cases = std::fs::read_to_string(savgol_fixture("cases.csv")).unwrap();
    for deriv in 0..=2 {
        let want: Vec<(usize, f64)> = cases
            .lines()
            .skip(1)
            .map(|l| l.split(',').collect::<Vec<_>>())
            .filter(|f| f[0] == "2" && f[1] == "11" && f[2] == deriv.to_string())
            .map(|f| (f[3].parse().unwrap(), num(f[4])))
            .collect();
        assert_eq!(want.len(), 400, "deriv {deriv}");
        let scale = want.iter().fold(0.0f64, |a, (_, v)| a.max(v.abs()));
        for (i, w) in want {
            let got = num(&rows[i][2 + deriv]);
            assert!(
                (got - w).abs() <= 1e-8 * scale,
                "deriv {deriv}, sample {i}: {got} vs scipy {w}"
            );
        }
    }
}
