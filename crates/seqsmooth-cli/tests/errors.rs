//! End-to-end tests of Error messages and exit codes of every subcommand against the command-line contract,
//! and the help texts.

mod common;
use common::*;

const EXP1: [&str; 5] = ["filter", "--kind", "expanding", "--degree", "1"];

/// A NaN value names the line, the column and the value.
#[test]
fn error_nan_value() {
    fails(
        &EXP1,
        "t,y\n0,1\n1,3\n2,2\n3,NaN\n",
        1,
        &["line 5, column 'y': value NaN is not finite"],
    );
}

/// An infinite time names the line, the column and the value.
#[test]
fn error_infinite_time() {
    fails(
        &EXP1,
        "t,y\n0,1\n1,3\n2,2\ninf,1\n",
        1,
        &["line 5, column 't': time inf is not finite"],
    );
}

/// A value that overflows to infinity is not finite either.
#[test]
fn error_overflowing_value() {
    fails(
        &EXP1,
        "t,y\n0,1\n1,1e999\n",
        1,
        &["line 3", "'y'", "1e999", "not finite"],
    );
}

/// Unsorted times name both lines and both times.
#[test]
fn error_unsorted_times() {
    let mut input = String::from("t,y\n");
    for t in [0, 1, 2, 3, 5, 6, 4] {
        input += &format!("{t},1\n");
    }
    fails(
        &EXP1,
        &input,
        1,
        &["line 8: time 4 is not after the previous time 6 (line 7)"],
    );
}

/// Duplicate times are rejected the same way.
#[test]
fn error_duplicate_times() {
    fails(
        &EXP1,
        "t,y\n0,1\n1,3\n1,2\n",
        1,
        &[
            "line 4: time 1 is not after the previous time 1 (line 3)",
            "duplicate",
        ],
    );
}

/// An error after the first 101 rows (streaming part) is reported with its line too.
#[test]
fn error_late_in_stream() {
    let mut input = String::from("t,y\n");
    for k in 0..300 {
        input += &format!("{k},{}\n", if k == 250 { "oops" } else { "1" });
    }
    fails(
        &EXP1,
        &input,
        1,
        &["line 252, column 'y': 'oops' is not a number"],
    );
}

/// A missing column lists the columns there are.
#[test]
fn error_missing_column() {
    fails(
        &EXP1,
        "t,x\n0,1\n1,2\n",
        1,
        &["column 'y' not found in the header; columns are: t, x"],
    );
    fails(
        &[&EXP1[..], &["--time-col", "time"]].concat(),
        "t,y\n0,1\n1,2\n",
        1,
        &["column 'time' not found", "columns are: t, y"],
    );
}

/// A non-numeric cell names line, column and the text.
#[test]
fn error_non_numeric_cell() {
    fails(
        &EXP1,
        "t,y\n0,1\n1,3\nabc,2\n",
        1,
        &["line 4, column 't': 'abc' is not a number"],
    );
    fails(
        &EXP1,
        "t,y\n0,1\n1,3\n2,abc\n",
        1,
        &["line 4, column 'y': 'abc' is not a number"],
    );
    fails(&EXP1, "t,y\n0,1\n1,\n", 1, &["line 3, column 'y'", "empty"]);
}

/// Ragged rows are malformed CSV, with the line.
#[test]
fn error_ragged_row() {
    fails(
        &EXP1,
        "t,y\n0,1\n1,3,7\n",
        1,
        &["line 3", "malformed CSV", "3 fields"],
    );
    fails(
        &EXP1,
        "t,y\n0,1\n1,3\n2\n",
        1,
        &["line 4", "malformed CSV", "1 field"],
    );
}

/// Empty input and too few data rows for the degree.
#[test]
fn error_too_few_samples() {
    fails(&EXP1, "", 1, &["too few samples", "empty", "degree 1"]);
    fails(
        &EXP1,
        "t,y\n",
        1,
        &["too few samples", "0 data rows", "at least 2"],
    );
    fails(
        &[
            "filter", "--kind", "fading", "--degree", "3", "--theta", "0.9",
        ],
        "t,y\n0,1\n1,2\n2,3\n",
        1,
        &["too few samples", "3 data rows", "degree 3", "at least 4"],
    );
}

/// A missing input file is a file error (exit 1) naming the file.
#[test]
fn error_missing_file() {
    fails(
        &[&EXP1[..], &["no/such/file.csv"]].concat(),
        "",
        1,
        &["cannot open input file 'no/such/file.csv'"],
    );
}

// errors: command line (exit code 2), naming the value

/// Degree above MAX_DEGREE (24) or negative.
#[test]
fn error_degree_out_of_range() {
    fails(
        &["filter", "--kind", "expanding", "--degree", "25"],
        T9_02,
        2,
        &["degree 25 is out of range", "24"],
    );
    fails(
        &["gains", "--kind", "expanding", "--degree", "-1", "--n", "3"],
        "",
        2,
        &["degree -1 is out of range"],
    );
}

/// θ outside (0, 1), for the filter and the tables.
#[test]
fn error_theta_out_of_range() {
    fails(
        &[
            "filter", "--kind", "fading", "--degree", "1", "--theta", "1.5",
        ],
        T9_02,
        2,
        &["theta 1.5 is out of range"],
    );
    fails(
        &[
            "gains", "--kind", "fading", "--degree", "1", "--theta", "-1/2", "--exact",
        ],
        "",
        2,
        &["theta -1/2 is out of range"],
    );
    fails(
        &["vrf", "--kind", "fading", "--degree", "1", "--theta", "abc"],
        "",
        2,
        &["theta 'abc' is not a number"],
    );
    // A huge exponent is refused at once, not expanded exactly (a fuzz campaign's time-outs).
    for theta in ["5e6999999", "104E7161213", "1e-401"] {
        fails(
            &[
                "filter", "--kind", "auto", "--degree", "5", "--theta", theta,
            ],
            T9_02,
            2,
            &[
                &format!("theta {theta} is out of range"),
                "exponent from -400 to 400",
            ],
        );
    }
}

/// τ must be positive and finite.
#[test]
fn error_tau_out_of_range() {
    for tau in ["0", "-2", "inf"] {
        fails(
            &[
                "filter", "--kind", "fading", "--degree", "1", "--theta", "0.9", "--tau", tau,
            ],
            T9_02,
            2,
            &[&format!("tau {tau} is out of range")],
        );
    }
}

/// σ must be positive and finite.
#[test]
fn error_sigma_out_of_range() {
    for sigma in ["0", "-1", "NaN"] {
        fails(
            &[&EXP1[..], &["--sigma", sigma]].concat(),
            T9_02,
            2,
            &[&format!("sigma {sigma} is out of range")],
        );
    }
}

/// `--kind fading` without `--theta`.
#[test]
fn error_fading_without_theta() {
    fails(
        &["filter", "--kind", "fading", "--degree", "1"],
        T9_02,
        2,
        &["--kind fading needs --theta"],
    );
    fails(
        &["gains", "--kind", "fading", "--degree", "1"],
        "",
        2,
        &["--kind fading needs --theta"],
    );
}

/// `--n` missing for expanding-memory gains and vrf.
#[test]
fn error_expanding_tables_without_n() {
    for cmd in ["gains", "vrf"] {
        fails(
            &[cmd, "--kind", "expanding", "--degree", "1"],
            "",
            2,
            &["--kind expanding needs --n"],
        );
    }
}

/// The expanding-memory VRF needs n ≥ m.
#[test]
fn error_vrf_n_below_degree() {
    fails(
        &["vrf", "--kind", "expanding", "--degree", "3", "--n", "2"],
        "",
        2,
        &["error: --n 2 is invalid: too small for degree 3: the expanding-memory variance-reduction \
           matrix needs n >= 3 (at least 4 samples)\n"],
    );
}

/// A fixed-memory VRF at a lead so far out that its variances overflow a double is refused,
/// naming the entry, where it printed NaN and inf with exit 0; `--exact` still gives it.
#[test]
fn error_vrf_lead_beyond_the_double_range() {
    fails(
        &[
            "vrf", "--kind", "fixed", "--degree", "2", "--window", "10", "--lead", "1e200",
        ],
        "",
        1,
        &[
            "error: the estimate's covariance of d0, d0 at the lead 1e200 is beyond the double \
           range (about 1.8e308) in these units",
        ],
    );
    let exact = run(
        &[
            "vrf", "--kind", "fixed", "--degree", "2", "--window", "10", "--lead", "1e200",
            "--exact",
        ],
        "",
    );
    assert_eq!(exact.code, 0, "{}", exact.stderr);
    assert!(!exact.stdout.contains("inf") && !exact.stdout.contains("NaN"));
}

/// Arguments of the other kind are rejected rather than silently ignored.
#[test]
fn error_argument_of_other_kind() {
    fails(
        &[&EXP1[..], &["--theta", "0.9"]].concat(),
        T9_02,
        2,
        &["--theta applies only to --kind fading"],
    );
    fails(
        &[&EXP1[..], &["--tau", "2"]].concat(),
        T9_02,
        2,
        &["--tau applies only to --kind fading"],
    );
}

/// A window shorter than M+1 is a command-line error naming the window (filter, smooth, vrf).
#[test]
fn error_window_below_degree() {
    let message = "window 2 is too small for degree 2: a degree-2 fit needs a window of at least 3";
    fails(
        &[
            "filter", "--kind", "fixed", "--degree", "2", "--window", "2",
        ],
        T7_08,
        2,
        &[message],
    );
    fails(
        &["smooth", "--degree", "2", "--window", "2"],
        T7_08,
        2,
        &[message],
    );
    fails(
        &["vrf", "--kind", "fixed", "--degree", "2", "--window", "2"],
        "",
        2,
        &[message],
    );
    fails(
        &["smooth", "--degree", "1", "--window", "0"],
        T7_08,
        2,
        &["error: invalid value '0' for '--window <W>': --window 0 is invalid: must hold at least 1 sample\n"],
    );
}

/// A window longer than the data is a data error (exit 1) naming the window and the row count.
#[test]
fn error_window_longer_than_data() {
    for cmd in [
        &["smooth", "--degree", "1", "--window", "6"][..],
        &[
            "filter", "--kind", "fixed", "--degree", "1", "--window", "6",
        ][..],
    ] {
        fails(
            cmd,
            T7_08,
            1,
            &["too few samples: the input has 5 data rows, window 6 needs at least 6"],
        );
        fails(cmd, "", 1, &["too few samples", "empty", "window 6"]);
    }
}

/// `--window` is required by fixed memory and smooth (clap names the missing argument for
/// smooth), and refused by the other kinds.
#[test]
fn error_missing_or_misplaced_window() {
    fails(
        &["filter", "--kind", "fixed", "--degree", "1"],
        T7_08,
        2,
        &["--kind fixed needs --window W", "at least M+1 = 2"],
    );
    fails(
        &["smooth", "--degree", "1"],
        T7_08,
        2,
        &["required", "--window <W>"],
    );
    fails(
        &["vrf", "--kind", "fixed", "--degree", "1"],
        "",
        2,
        &["--kind fixed needs --window W"],
    );
    fails(
        &[&EXP1[..], &["--window", "3"]].concat(),
        T7_08,
        2,
        &["--window applies only to --kind fixed"],
    );
    fails(
        &[
            "vrf",
            "--kind",
            "expanding",
            "--degree",
            "1",
            "--n",
            "4",
            "--window",
            "3",
        ],
        "",
        2,
        &["--window applies only to --kind fixed"],
    );
}

/// `--kind auto` needs `--theta`; the fixed-memory filter takes no θ, τ or gain engine; the
/// fixed-memory VRF takes `--lead`, not `--form`, and the others not `--lead`.
#[test]
fn error_arguments_of_fixed_and_auto() {
    fails(
        &["filter", "--kind", "auto", "--degree", "1"],
        T7_08,
        2,
        &["--kind auto needs --theta T"],
    );
    let fixed = [
        "filter", "--kind", "fixed", "--degree", "1", "--window", "3",
    ];
    fails(
        &[&fixed[..], &["--theta", "0.9"]].concat(),
        T7_08,
        2,
        &["--theta applies only to --kind fading and auto"],
    );
    fails(
        &[&fixed[..], &["--tau", "1"]].concat(),
        T7_08,
        2,
        &["--tau applies only to --kind fading and auto"],
    );
    fails(
        &[&fixed[..], &["--engine", "gain"]].concat(),
        T7_08,
        2,
        &["--engine gain applies only to --kind expanding, fading and auto"],
    );
    assert_eq!(
        ok(&[&fixed[..], &["--engine", "exact"]].concat(), T7_08),
        ok(&fixed, T7_08)
    );
    let vrf = ["vrf", "--kind", "fixed", "--degree", "1", "--window", "5"];
    fails(
        &[&vrf[..], &["--form", "predictor"]].concat(),
        "",
        2,
        &[
            "--form applies only to --kind expanding and fading",
            "--lead H",
        ],
    );
    fails(
        &[&vrf[..], &["--lead", "1/0"]].concat(),
        "",
        2,
        &["lead '1/0' is not a number"],
    );
    fails(
        &[
            "vrf",
            "--kind",
            "expanding",
            "--degree",
            "1",
            "--n",
            "4",
            "--lead",
            "1",
        ],
        "",
        2,
        &["--lead applies only to --kind fixed"],
    );
    fails(
        &["gains", "--kind", "fixed", "--degree", "1"],
        "",
        2,
        &["invalid value 'fixed'", "expanding, fading"],
    );
}

/// Irregular-time checks also hold for smooth: a NaN value names line and column; unsorted
/// times name both lines.
#[test]
fn error_smooth_bad_rows() {
    let args = ["smooth", "--degree", "1", "--window", "3"];
    fails(
        &args,
        "t,y
0,1
1,NaN
2,3
",
        1,
        &["line 3, column 'y': value NaN is not finite"],
    );
    fails(
        &args,
        "t,y
0,1
2,2
1,3
",
        1,
        &["line 4: time 1 is not after the previous time 2 (line 3)"],
    );
}

/// The help lists the new commands and kinds and documents the new output columns.
#[test]
fn help_documents_fixed_auto_and_smooth() {
    let top = ok(&["--help"], "");
    assert!(
        top.contains("smooth  Smooth and differentiate a CSV time series"),
        "{top}"
    );
    let filter = ok(&["filter", "--help"], "");
    for word in [
        "fixed:",
        "auto:",
        "t,y,d0..dM,window",
        "noise,outlier,misfit",
        "--window <W>",
    ] {
        assert!(filter.contains(word), "filter --help lacks {word}");
    }
    let smooth = ok(&["smooth", "--help"], "");
    assert!(smooth.contains("streams"), "{smooth}");
    assert!(smooth.contains("s0..sM"), "{smooth}");
    assert!(smooth.contains("savgol_filter"), "{smooth}");
}

/// Writing the output over the input file is refused (it would truncate the input mid-read).
#[test]
fn error_output_is_input() {
    let path = tmp("same.csv");
    std::fs::write(&path, T9_02).unwrap();
    let p = path.to_str().unwrap();
    fails(
        &[&EXP1[..], &[p, "-o", p]].concat(),
        "",
        2,
        &["is the input file"],
    );
    assert_eq!(std::fs::read_to_string(&path).unwrap(), T9_02);
}

/// Unknown arguments are clap errors with exit code 2.
#[test]
fn error_unknown_argument() {
    fails(&[&EXP1[..], &["--bogus"]].concat(), T9_02, 2, &["--bogus"]);
}

/// A huge cell is quoted cut to its first characters with its length; a NUL is shown.
#[test]
fn error_messages_shorten_and_escape_cells() {
    let huge = "9".repeat(100_000) + "x";
    let r = run(&EXP1, &format!("t,y\n0,1\n1,{huge}\n"));
    assert_eq!(r.code, 1);
    assert!(r.stderr.len() < 300, "{} bytes", r.stderr.len());
    assert!(
        r.stderr.contains(&format!(
            "'{}… (100001 bytes)' is not a number",
            "9".repeat(40)
        )),
        "{}",
        r.stderr
    );
    let r = run(&EXP1, "t,y\n0,1\n1,2\u{0}3\n");
    assert_eq!(r.code, 1);
    assert!(r.stderr.contains("'2\\03' is not a number"), "{}", r.stderr);
    let r = run(
        &[&EXP1[..], &["--value-col", "v\u{200b}"]].concat(),
        "t,y\n0,1\n",
    );
    assert_eq!(r.code, 1);
    assert!(
        r.stderr.contains("column 'v\\u{200b}' not found"),
        "{}",
        r.stderr
    );
}

/// A whole-number argument that is not a number says so (not "out of range"), and
/// `plot --derivative` is named as a derivative, not a degree.
#[test]
fn error_whole_number_arguments_name_themselves() {
    fails(
        &["filter", "--kind", "fading", "--degree", "abc"],
        "",
        2,
        &["degree 'abc' is not a whole number; it must be one from 0 to 24"],
    );
    fails(
        &["plot", "-o", "x.png", "--derivative", "-1"],
        "",
        2,
        &["derivative -1 is out of range: it must be a whole number from 0 to 24"],
    );
    fails(
        &["gains", "--kind", "expanding", "--degree", "1", "--n", "q"],
        "",
        2,
        &["n 'q' is not a whole number"],
    );
}

/// A noise σ whose square is not a normal double is an argument error that says to rescale.
#[test]
fn error_sigma_out_of_the_variance_range() {
    for s in ["1e-300", "1e300"] {
        fails(
            &[&EXP1[..], &["--sigma", s]].concat(),
            T9_02,
            2,
            &[&format!("sigma {s} is out of range"), "rescale the values"],
        );
    }
}

/// Extreme scales are right or refused, never empty or non-finite cells with exit 0: times
/// near 1e300 with steps of 1e300 are filtered (every kind and engine gives finite cells from
/// the row that determines the fit); a derivative beyond the double range (steps of 1e-200 at
/// degree 2, a lead of 1e308) and a fit that is never determined (τ far shorter than the steps)
/// are errors naming the line and what to change.
#[test]
fn extreme_scales_are_right_or_refused() {
    let big = "t,y\n1e300,1\n2e300,2\n3e300,3\n4e300,4\n5e300,5\n";
    for args in [
        &[
            "filter", "--kind", "fading", "--degree", "2", "--theta", "0.9",
        ][..],
        &[
            "filter", "--kind", "fading", "--degree", "2", "--theta", "0.9", "--engine", "gain",
        ],
        &["filter", "--kind", "expanding", "--degree", "2"],
        &[
            "filter",
            "--kind",
            "expanding",
            "--degree",
            "2",
            "--engine",
            "gain",
        ],
        &[
            "filter", "--kind", "fixed", "--degree", "2", "--window", "3",
        ],
    ] {
        let out = ok(args, big);
        let (head, rows) = table(&out);
        assert_eq!(rows.len(), 5, "{args:?}");
        let d0 = head.iter().position(|c| c == "d0").unwrap();
        for row in &rows[2..] {
            for cell in &row[d0..d0 + 3] {
                assert!(num(cell).is_finite(), "{args:?}: {out}");
            }
        }
        assert_eq!(num(&rows[4][d0]), 5.0, "{args:?}: {out}");
    }
    // The automatic filter settles its degree as it does at t = 1 … 5: the same cells.
    let auto = [
        "filter", "--kind", "auto", "--degree", "2", "--theta", "0.9",
    ];
    let cells = |text: &str| -> Vec<Vec<String>> {
        table(text).1.iter().map(|r| r[2..].to_vec()).collect()
    };
    assert_eq!(
        cells(&ok(&auto, big)),
        cells(&ok(&auto, "t,y\n1,1\n2,2\n3,3\n4,4\n5,5\n"))
    );
    fails(
        &[
            "filter", "--kind", "fixed", "--degree", "2", "--window", "3",
        ],
        "t,y\n0,1\n1e-200,2\n2e-200,3\n3e-200,5\n4e-200,5\n",
        1,
        // Rows 2–4 are linear (d2 = 0); the first curved window ends at line 5.
        &["line 5", "d2 is too large for a double", "larger unit"],
    );
    fails(
        &[
            "filter", "--kind", "fading", "--degree", "2", "--theta", "0.9", "--lead", "1e308",
        ],
        "t,y\n0,1\n1,2\n2,3\n3,5\n4,5\n",
        1,
        &["line 4", "too large for a double", "shorter --lead"],
    );
    fails(
        &[
            "filter", "--kind", "fading", "--degree", "2", "--theta", "0.9", "--tau", "1e-300",
        ],
        "t,y\n0,1\n1,2\n2,3\n3,5\n4,5\n",
        1,
        &["line 4", "no estimate for this row", "use a larger --tau"],
    );
    let rows: String = (0..13).map(|i| format!("{i},{}\n", i * i)).collect();
    fails(
        &[
            "filter", "--kind", "fading", "--degree", "11", "--theta", "0.9", "--engine", "gain",
        ],
        &format!("t,y\n{rows}"),
        2,
        &[
            "degree 11 is too high for the gain engine",
            "supported to degree 10",
            "exact engine",
        ],
    );
    fails(
        &[
            "filter",
            "--kind",
            "expanding",
            "--degree",
            "1",
            "--engine",
            "gain",
        ],
        "t,y\n0,1\n1,1e300\n2,3\n",
        1,
        &["line 3", "beyond the gain engine's range", "exact engine"],
    );
}
