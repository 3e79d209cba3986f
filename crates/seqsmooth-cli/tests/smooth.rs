//! End-to-end tests of `seqsmooth smooth`: the library and scipy's savgol_filter, the 1σ
//! columns, streaming, ISO-8601 times and a missing header.

use seqsmooth::polynomial::fixed::{smooth, smooth_with_sigma_into};
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
            // A window of M+1 has no residuals: its sigma must be given.
            let sigma = (window == degree + 1).then_some(0.25);
            let (d, w) = (degree.to_string(), window.to_string());
            let mut args = vec!["smooth", "--degree", &d, "--window", &w];
            if sigma.is_some() {
                args.extend(["--sigma", "0.25"]);
            }
            let out = ok(&args, &input);
            let (header, rows) = table(&out);
            let mut want_header = vec!["t".to_string(), "y".to_string()];
            want_header.extend((0..=degree).map(|k| format!("d{k}")));
            want_header.extend((0..=degree).map(|k| format!("s{k}")));
            assert_eq!(header, want_header);
            let want = smooth(&times, &values, degree, window).unwrap();
            let p = degree + 1;
            let (mut flat, mut sd) = (vec![0.0; 80 * p], vec![0.0; 80 * p]);
            smooth_with_sigma_into(&times, &values, degree, window, sigma, &mut flat, &mut sd)
                .unwrap();
            assert_eq!(rows.len(), want.len());
            for (k, (row, w)) in rows.iter().zip(&want).enumerate() {
                assert_eq!(num(&row[0]).to_bits(), times[k].to_bits());
                assert_eq!(num(&row[1]).to_bits(), values[k].to_bits());
                assert_eq!(row.len(), 2 + 2 * w.len());
                for (cell, v) in row[2..].iter().zip(w.iter().chain(&sd[k * p..(k + 1) * p])) {
                    assert_eq!(
                        num(cell).to_bits(),
                        v.to_bits(),
                        "{irregular} {degree} {window}"
                    );
                }
            }
        }
        // Without --sigma a window of M+1 is refused, naming the option.
        fails(
            &["smooth", "--degree", "1", "--window", "2"],
            &input,
            2,
            &["at least 3 samples", "--sigma"],
        );
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
    assert_eq!(header, ["t", "y", "d0", "d1", "d2", "s0", "s1", "s2"]);
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

/// Streams: more rows than a chunk (and windows that span chunks) give the library's rows bit
/// for bit, and the output is the same whether the input is read from a file or a pipe.
#[test]
fn smooth_streams_across_chunks() {
    let n = 20_000;
    let mut input = String::from("t,y\n");
    let (mut times, mut values) = (Vec::new(), Vec::new());
    for k in 0..n {
        let t = 0.01 * k as f64;
        let y = (0.7 * t).sin() + 0.01 * ((k * 7919 % 101) as f64);
        times.push(t);
        values.push(y);
        input += &format!("{t},{y}\n");
    }
    let path = tmp("smooth_stream.csv");
    std::fs::write(&path, &input).unwrap();
    for window in [5, 9001, 20_000] {
        let w = window.to_string();
        let out = ok(&["smooth", "--degree", "2", "--window", &w], &input);
        let from_file = ok(
            &[
                "smooth",
                path.to_str().unwrap(),
                "--degree",
                "2",
                "--window",
                &w,
            ],
            "",
        );
        assert_eq!(out, from_file);
        let (mut d, mut s) = (vec![0.0; n * 3], vec![0.0; n * 3]);
        smooth_with_sigma_into(&times, &values, 2, window, None, &mut d, &mut s).unwrap();
        let (_, rows) = table(&out);
        assert_eq!(rows.len(), n);
        for (k, row) in rows.iter().enumerate() {
            for j in 0..3 {
                assert_eq!(
                    num(&row[2 + j]).to_bits(),
                    d[k * 3 + j].to_bits(),
                    "row {k}"
                );
                assert_eq!(
                    num(&row[5 + j]).to_bits(),
                    s[k * 3 + j].to_bits(),
                    "row {k}"
                );
            }
        }
    }
}

/// ISO-8601 times (UTC `Z`, fractional seconds, offsets, a naive time read as UTC, a date
/// alone) are read as seconds since the Unix epoch and echoed as those seconds: the output
/// equals that of the same file with the seconds written as numbers.
#[test]
fn smooth_reads_iso_8601_times() {
    let iso = "t,y\n\
        2024-03-01T12:00:00Z,1\n\
        2024-03-01T12:00:00.5Z,2\n\
        2024-03-01T14:00:01+02:00,4\n\
        2024-03-01 12:00:01.5,3\n\
        2024-03-01T07:00:02-05:00,5\n\
        2024-03-02,6\n";
    let seconds = "t,y\n1709294400,1\n1709294400.5,2\n1709294401,4\n1709294401.5,3\n\
        1709294402,5\n1709337600,6\n";
    let args = ["smooth", "--degree", "1", "--window", "3"];
    assert_eq!(ok(&args, iso), ok(&args, seconds));
    // And `filter` reads them the same way.
    let filter = ["filter", "--kind", "expanding", "--degree", "1"];
    assert_eq!(ok(&filter, iso), ok(&filter, seconds));
    // A malformed one is named with its line, column and what is wrong.
    fails(
        &args,
        "t,y\n2024-03-01T12:00:00Z,1\n2024-02-30T00:00:00Z,2\n2024-03-03,3\n",
        1,
        &[
            "line 3, column 't'",
            "'2024-02-30T00:00:00Z' is not an ISO-8601 time",
            "day 30",
        ],
    );
    fails(
        &args,
        "t,y\n2024-03-01T12:00:60Z,1\n",
        1,
        &["line 2", "leap second"],
    );
    // A value column never takes dates.
    fails(
        &args,
        "t,y\n1,2024-03-01\n",
        1,
        &["column 'y'", "not a number"],
    );
}

/// A CSV without a header line: the first row is named as data, and the header the command
/// expects is given.
#[test]
fn missing_header_is_named() {
    let data = "0,-173184.4958\n1,-173180.1\n2,-173170.2\n";
    fails(
        &["smooth", "--degree", "1", "--window", "3"],
        data,
        1,
        &[
            "first row ('0,-173184.4958') looks like data, not a header",
            "'t,y'",
        ],
    );
    fails(
        &[
            "filter", "--kind", "fading", "--degree", "1", "--theta", "0.9",
        ],
        data,
        1,
        &["looks like data, not a header", "'t,y'"],
    );
    fails(
        &[
            "smooth",
            "--degree",
            "1",
            "--window",
            "3",
            "--time-col",
            "time",
        ],
        "2024-03-01T12:00:00Z,1\n",
        1,
        &["looks like data", "'time,y'"],
    );
}
