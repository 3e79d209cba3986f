//! End-to-end tests of the `seqsmooth` command: each runs the built binary and checks its
//! output against published test vectors (Morrison 1969; Reyneke et al. 2012) or the library,
//! and its error messages and exit codes against the command-line contract.

use num_rational::BigRational;
use seqsmooth::polynomial::automatic::AutomaticFilter;
use seqsmooth::polynomial::fixed::{covariance, covariance_unscaled, smooth};
use seqsmooth::polynomial::gains::{expanding_gains, fading_gains, GainForm};
use seqsmooth::polynomial::vrf::{expanding_vrf, EstimateForm};
use seqsmooth::scalar::{parse_rational, ratio_to_f64, rational_from_f64, Rational};
use seqsmooth::{
    Engine, ExpandingMemory, FadingMemory, FixedEngine, FixedMemory, PolynomialFilter,
};
use std::path::PathBuf;

mod common;
use common::run;

/// Runs and asserts success.
fn ok(args: &[&str], stdin: &str) -> String {
    let o = run(args, stdin);
    assert_eq!(o.code, 0, "seqsmooth {args:?} failed: {}", o.stderr);
    o.stdout
}

/// Runs and asserts failure with `code` and every `parts` in stderr.
fn fails(args: &[&str], stdin: &str, code: i32, parts: &[&str]) {
    let o = run(args, stdin);
    assert_eq!(o.code, code, "seqsmooth {args:?}: stderr {}", o.stderr);
    assert!(
        o.stderr.starts_with("error: "),
        "message must start with 'error: ': {}",
        o.stderr
    );
    for p in parts {
        assert!(o.stderr.contains(p), "stderr lacks {p:?}: {}", o.stderr);
    }
    assert!(!o.stderr.contains("panicked"), "{}", o.stderr);
}

/// Splits CSV output (no quoting occurs in it) into the header and rows of cells.
fn table(text: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let mut lines = text.lines();
    let header = lines
        .next()
        .expect("header")
        .split(',')
        .map(String::from)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    (header, rows)
}

fn num(cell: &str) -> f64 {
    cell.parse()
        .unwrap_or_else(|_| panic!("{cell:?} is not a number"))
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + b.abs())
}

fn tmp(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name)
}

/// Morrison's running example (spec T9-02): samples 1, 3, 2, 5, 4 at n = 0..4.
const T9_02: &str = "t,y\n0,1\n1,3\n2,2\n3,5\n4,4\n";

// ---------------------------------------------------------------------------------------------
// filter

/// Morrison T9-02: the degree-1 expanding-memory estimate after samples 0..4 is
/// Z*_{4,4} = (23/5, 4/5); the first row (one sample, degree 1) has no estimate yet. Both
/// engines.
#[test]
fn filter_expanding_degree1_matches_t9_02() {
    for engine in ["exact", "gain"] {
        let out = ok(
            &[
                "filter",
                "--kind",
                "expanding",
                "--degree",
                "1",
                "--engine",
                engine,
            ],
            T9_02,
        );
        let (header, rows) = table(&out);
        assert_eq!(header, ["t", "y", "d0", "d1"]);
        assert_eq!(rows.len(), 5);
        assert_eq!(out.lines().nth(1), Some("0,1,,"), "{engine}");
        assert_eq!(rows[4][..2], ["4", "4"]);
        assert!(
            close(num(&rows[4][2]), 4.6, 1e-12),
            "{engine}: {:?}",
            rows[4]
        );
        assert!(
            close(num(&rows[4][3]), 0.8, 1e-12),
            "{engine}: {:?}",
            rows[4]
        );
    }
}

/// Morrison T9-02: the 1-step prediction Z*_{5,4} = (27/5, 4/5) with `--lead 1`; a negative
/// lead retrodicts (`--lead -10` at t = 4: 4.6 - 8 = -3.4). Both engines.
#[test]
fn filter_lead_predicts_and_retrodicts() {
    for engine in ["exact", "gain"] {
        let args = [
            "filter",
            "--kind",
            "expanding",
            "--degree",
            "1",
            "--engine",
            engine,
        ];
        let out = ok(&[&args[..], &["--lead", "1"]].concat(), T9_02);
        let (_, rows) = table(&out);
        assert!(
            close(num(&rows[4][2]), 5.4, 1e-12),
            "{engine}: {:?}",
            rows[4]
        );
        assert!(
            close(num(&rows[4][3]), 0.8, 1e-12),
            "{engine}: {:?}",
            rows[4]
        );
        let out = ok(&[&args[..], &["--lead", "-10"]].concat(), T9_02);
        let (_, rows) = table(&out);
        assert!(
            close(num(&rows[4][2]), -3.4, 1e-12),
            "{engine}: {:?}",
            rows[4]
        );
        assert_eq!(rows[4][..2], ["4", "4"]);
    }
}

/// `--sigma S` adds s0..sM: for Morrison's example at n = 4 (τ = 1, so scaled = unscaled)
/// s_k = S·sqrt(VRF_kk) with the expanding-memory VRF of Table 9.2 (`expanding_vrf(1, 4)`).
#[test]
fn filter_sigma_columns_match_vrf() {
    let sigma = 0.5;
    let vrf = expanding_vrf::<f64>(1, 4, EstimateForm::Current).unwrap();
    for engine in ["exact", "gain"] {
        let out = ok(
            &[
                "filter",
                "--kind",
                "expanding",
                "--degree",
                "1",
                "--engine",
                engine,
                "--sigma",
                "0.5",
            ],
            T9_02,
        );
        let (header, rows) = table(&out);
        assert_eq!(header, ["t", "y", "d0", "d1", "s0", "s1"]);
        assert_eq!(out.lines().nth(1), Some("0,1,,,,"));
        assert!(
            close(num(&rows[4][4]), sigma * vrf[(0, 0)].sqrt(), 1e-12),
            "{engine}"
        );
        assert!(
            close(num(&rows[4][5]), sigma * vrf[(1, 1)].sqrt(), 1e-12),
            "{engine}"
        );
    }
}

/// A fading-memory filter is exact on a polynomial (Morrison ch. 13): y = 2 + 0.5 t for 300
/// evenly spaced rows gives x = 151.5, x' = 0.5 at t = 299, on both engines.
#[test]
fn filter_fading_exact_on_long_polynomial() {
    let mut input = String::from("t,y\n");
    for k in 0..300 {
        input += &format!("{k},{}\n", 2.0 + 0.5 * k as f64);
    }
    for engine in ["exact", "gain"] {
        let out = ok(
            &[
                "filter", "--kind", "fading", "--degree", "1", "--theta", "0.9", "--engine", engine,
            ],
            &input,
        );
        let (_, rows) = table(&out);
        assert_eq!(rows.len(), 300);
        let last = &rows[299];
        assert!(close(num(&last[2]), 151.5, 1e-12), "{engine}: {last:?}");
        assert!(close(num(&last[3]), 0.5, 1e-10), "{engine}: {last:?}");
    }
}

/// The exact engine is least squares on any timestamps, so a quadratic on irregular times is
/// reproduced exactly, derivatives included (value 1 + t + t²: x' = 1 + 2t, x'' = 2).
#[test]
fn filter_exact_engine_on_irregular_quadratic() {
    let mut input = String::from("t,y\n");
    let mut t = 0.0;
    for k in 0..200 {
        t += 0.05 + 0.1 * ((k * 7 % 5) as f64);
        input += &format!("{t},{}\n", 1.0 + t + t * t);
    }
    let out = ok(
        &[
            "filter", "--kind", "fading", "--degree", "2", "--theta", "9/10",
        ],
        &input,
    );
    let (_, rows) = table(&out);
    let last = &rows[199];
    let t = num(&last[0]);
    assert!(close(num(&last[2]), 1.0 + t + t * t, 1e-9), "{last:?}");
    assert!(close(num(&last[3]), 1.0 + 2.0 * t, 1e-9), "{last:?}");
    assert!(close(num(&last[4]), 2.0, 1e-7), "{last:?}");
}

/// Every number written parses back to the identical f64 the library computed (round-trip
/// output), including values far from 1 that need an exponent (1e-300 must not print 300
/// digits).
#[test]
fn filter_output_round_trips_library_values() {
    let mut input = String::from("t,y\n");
    let mut samples = Vec::new();
    for k in 0..60 {
        let t = 1e-3 * k as f64 + 1e-4 * ((k * 3 % 7) as f64);
        let y = 1e-300 * (1.0 + 0.1 * ((k * 5 % 11) as f64)) + 3e-301 * t;
        samples.push((t, y));
        input += &format!("{t:e},{y:e}\n");
    }
    for engine in [Engine::Exact, Engine::Gain] {
        let name = if engine == Engine::Exact {
            "exact"
        } else {
            "gain"
        };
        let out = ok(
            &[
                "filter", "--kind", "fading", "--degree", "2", "--theta", "0.8", "--tau", "1e-3",
                "--sigma", "1e-150", "--lead", "2e-3", "--engine", name,
            ],
            &input,
        );
        let mut f = FadingMemory::new(2, 0.8, 1e-3, engine)
            .unwrap()
            .with_noise_sigma(1e-150)
            .unwrap();
        let (_, rows) = table(&out);
        for (row, &(t, y)) in rows.iter().zip(&samples) {
            f.update(t, y).unwrap();
            assert_eq!(num(&row[0]).to_bits(), t.to_bits());
            assert_eq!(num(&row[1]).to_bits(), y.to_bits());
            match f.estimate_at(t + 2e-3) {
                None => assert!(row[2..].iter().all(String::is_empty), "{row:?}"),
                Some(s) => {
                    let sd = s.std_devs().unwrap();
                    let want = s.derivatives.iter().chain(&sd);
                    for (cell, w) in row[2..].iter().zip(want) {
                        assert_eq!(num(cell).to_bits(), w.to_bits(), "{cell} vs {w:e}");
                        assert!(cell.len() <= 24, "{cell} is not the shortest form");
                    }
                }
            }
        }
    }
}

/// `--time-col`/`--value-col` pick the columns by name; other columns are ignored; the output
/// header stays `t,y,d…` and the t and y cells echo the input cells as written.
#[test]
fn filter_custom_columns_with_extra_columns() {
    let input = "id,time,note,pos\na,0.0,x,1\nb,1.0,y,3\nc,2.0,z,2\nd,3.0,w,5\ne,4.0,v,4.00\n";
    let out = ok(
        &[
            "filter",
            "--kind",
            "expanding",
            "--degree",
            "1",
            "--time-col",
            "time",
            "--value-col",
            "pos",
        ],
        input,
    );
    let (header, rows) = table(&out);
    assert_eq!(header, ["t", "y", "d0", "d1"]);
    assert_eq!(rows[4][..2], ["4.0", "4.00"]);
    assert!(close(num(&rows[4][2]), 4.6, 1e-12));
}

/// INPUT `-`, INPUT omitted and a file name read the same data; `-o` writes the same CSV.
#[test]
fn filter_reads_stdin_and_files_and_writes_output_file() {
    let args = ["filter", "--kind", "expanding", "--degree", "1"];
    let from_stdin = ok(&[&args[..], &["-"]].concat(), T9_02);
    assert_eq!(ok(&args, T9_02), from_stdin);
    let input = tmp("t9_02.csv");
    std::fs::write(&input, T9_02).unwrap();
    let input = input.to_str().unwrap();
    assert_eq!(ok(&[&args[..], &[input]].concat(), ""), from_stdin);
    let output = tmp("t9_02_out.csv");
    let output = output.to_str().unwrap();
    assert_eq!(ok(&[&args[..], &[input, "-o", output]].concat(), ""), "");
    assert_eq!(std::fs::read_to_string(output).unwrap(), from_stdin);
}

/// Without `--tau`, τ is the median time step of the first rows, so θ is the discount per
/// typical sample: a series with steps mostly 0.5 gives the same output as `--tau 0.5`.
#[test]
fn filter_default_tau_is_median_step() {
    let mut input = String::from("t,y\n");
    let mut t = 0.0;
    for k in 0..40 {
        t += if k % 4 == 3 { 0.9 } else { 0.5 };
        input += &format!("{t},{}\n", (k * 13 % 7) as f64);
    }
    let args = [
        "filter", "--kind", "fading", "--degree", "1", "--theta", "0.8",
    ];
    let default = ok(&args, &input);
    assert_eq!(
        ok(&[&args[..], &["--tau", "0.5"]].concat(), &input),
        default
    );
    assert_ne!(ok(&[&args[..], &["--tau", "1"]].concat(), &input), default);
}

/// The library's answer for the same run equals the command's (gain engine, fading memory,
/// irregular then even times; exact engine, expanding memory): the binary is a thin layer. Without 1σ
/// columns or a lead it feeds each series' rows of a chunk through `update_many_into`, so that
/// is the reference, equal to the end (every row); the per-sample `update` + `estimate` path
/// agrees up to the batch kernels' rounding.
#[test]
fn filter_agrees_with_library() {
    let mut input = String::from("t,y\n");
    let (mut ts, mut ys) = (Vec::new(), Vec::new());
    // Irregular, then evenly spaced from row 60 on (long enough for the fading gain engine's
    // typical step to settle, so its steady batch kernel runs).
    for k in 0..1200 {
        let t = k as f64
            + if k < 60 {
                0.3 * ((k * 7 % 3) as f64)
            } else {
                0.3
            };
        let y = (k as f64 * 0.37).sin() * 10.0;
        input += &format!("{t},{y}\n");
        ts.push(t);
        ys.push(y);
    }
    type Make = fn() -> Box<dyn PolynomialFilter>;
    let filters: [(&[&str], Make); 2] = [
        (
            &[
                "filter", "--kind", "fading", "--degree", "2", "--theta", "0.95", "--tau", "1",
                "--engine", "gain",
            ],
            || Box::new(FadingMemory::new(2, 0.95, 1.0, Engine::Gain).unwrap()),
        ),
        (&["filter", "--kind", "expanding", "--degree", "2"], || {
            Box::new(ExpandingMemory::new(2, Engine::Exact).unwrap())
        }),
    ];
    for (args, make) in filters {
        let (mut f, mut one) = (make(), make());
        let mut est = vec![0.0; ts.len() * 3];
        f.update_many_into(&ts, &ys, &mut est).unwrap();
        let (_, rows) = table(&ok(args, &input));
        for (k, row) in rows.iter().enumerate() {
            one.update(ts[k], ys[k]).unwrap();
            for (d, cell) in row[2..].iter().enumerate() {
                let want = est[3 * k + d];
                if want.is_nan() {
                    assert_eq!(cell, "", "{args:?} row {k}");
                    continue;
                }
                assert_eq!(num(cell), want, "{args:?} row {k}");
                let single = one.estimate().unwrap().derivatives[d];
                assert!(
                    close(want, single, 1e-11),
                    "{args:?} row {k}: {want} vs {single}"
                );
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// filter --kind fixed

/// Morrison T7-08 (spec ch07-09 §5): Y = (y_n, …, y_{n-4}) = (5, 3, 4, 2, 1), newest first, so
/// the CSV (oldest first) is y = 1, 2, 4, 3, 5 at t = 0..4.
const T7_08: &str = "t,y\n0,1\n1,2\n2,4\n3,3\n4,5\n";

fn exact_f64(text: &str) -> f64 {
    ratio_to_f64(&parse_rational(text).unwrap())
}

/// Morrison T7-08, L = 4 (`--window 5`): m = 1, h = 0 gives Z* = (24/5, 9/10); h = 1 (`--lead 1`)
/// the prediction (57/10, 9/10); h = -2 the centre (3, 9/10); m = 2, h = 0 gives
/// (163/35, 43/70, -1/14) scaled, so x'' = 2!·(-1/14) = -1/7 (τ = 1). Only the last row has an
/// estimate: the four before it have empty d cells and say so in the window column.
#[test]
fn filter_fixed_t7_08() {
    let cases: [(&str, &str, &[&str]); 4] = [
        ("1", "0", &["24/5", "9/10"]),
        ("1", "1", &["57/10", "9/10"]),
        ("1", "-2", &["3", "9/10"]),
        ("2", "0", &["163/35", "43/70", "-1/7"]),
    ];
    for (degree, lead, want) in cases {
        let args = [
            "filter", "--kind", "fixed", "--degree", degree, "--window", "5", "--lead", lead,
        ];
        let out = ok(&args, T7_08);
        let (header, rows) = table(&out);
        let mut want_header = vec!["t".to_string(), "y".to_string()];
        want_header.extend((0..want.len()).map(|k| format!("d{k}")));
        want_header.push("window".into());
        assert_eq!(header, want_header);
        assert_eq!(rows.len(), 5);
        for (k, row) in rows[..4].iter().enumerate() {
            assert!(
                row[2..2 + want.len()].iter().all(String::is_empty),
                "{row:?}"
            );
            assert_eq!(row[2 + want.len()], (k + 1).to_string(), "{row:?}");
        }
        let last = &rows[4];
        assert_eq!(last[..2], ["4", "5"]);
        for (cell, w) in last[2..].iter().zip(want) {
            assert!(
                close(num(cell), exact_f64(w), 1e-14),
                "degree {degree}, lead {lead}: {cell} vs {w}"
            );
        }
        assert_eq!(last[2 + want.len()], "5");
    }
}

/// Rows before the window fills: empty d and s cells, the window column counting the rows so
/// far (1, 2, …, W-1), then W on every row with an estimate — also for a window longer than
/// the 101 rows `filter` otherwise reads ahead (W = 150). `--sigma S` adds s0..sM before the
/// window column: S·sqrt of the diagonal of Morrison's (7.5.27) covariance `D W(0) W(0)ᵀ D`
/// (m = 1, L = 149, τ = 0.5). The values equal the library's FixedMemory bit for bit.
#[test]
fn filter_fixed_rows_before_window_fills() {
    let mut input = String::from("t,y\n");
    let mut samples = Vec::new();
    for k in 0..300 {
        let t = 0.5 * k as f64;
        let y = 3.0 - 0.25 * t + ((k * 17 % 13) as f64 - 6.0) * 0.1;
        samples.push((t, y));
        input += &format!("{t},{y}\n");
    }
    let out = ok(
        &[
            "filter", "--kind", "fixed", "--degree", "1", "--window", "150", "--sigma", "0.3",
        ],
        &input,
    );
    let (header, rows) = table(&out);
    assert_eq!(header, ["t", "y", "d0", "d1", "s0", "s1", "window"]);
    assert_eq!(rows.len(), 300);
    let mut f = FixedMemory::new(1, 150, FixedEngine::Sliding)
        .unwrap()
        .with_noise_sigma(0.3)
        .unwrap();
    let cov = covariance_unscaled(1, 149, 0.0, 0.5).unwrap();
    for (k, (row, &(t, y))) in rows.iter().zip(&samples).enumerate() {
        f.update(t, y).unwrap();
        if k < 149 {
            assert!(row[2..6].iter().all(String::is_empty), "{row:?}");
            assert_eq!(row[6], (k + 1).to_string());
            continue;
        }
        assert_eq!(row[6], "150");
        let s = f.estimate().unwrap();
        let sd = s.std_devs().unwrap();
        for (cell, w) in row[2..6].iter().zip(s.derivatives.iter().chain(&sd)) {
            assert_eq!(num(cell).to_bits(), w.to_bits(), "row {k}: {cell} vs {w:e}");
        }
        assert!(close(num(&row[4]), 0.3 * cov[(0, 0)].sqrt(), 1e-12));
        assert!(close(num(&row[5]), 0.3 * cov[(1, 1)].sqrt(), 1e-12));
    }
    // A window longer than the input is refused before any output.
    let o = run(
        &[
            "filter", "--kind", "fixed", "--degree", "1", "--window", "301",
        ],
        &input,
    );
    assert_eq!(o.code, 1, "{}", o.stderr);
    assert_eq!(o.stdout, "");
    assert!(o
        .stderr
        .contains("too few samples: the input has 300 data rows, window 301 needs at least 301"));
}

/// Irregular times: the fixed-memory filter is least squares over the window at the actual
/// times, so a quadratic (1 + t + t²) is reproduced with its derivatives (x' = 1 + 2t, x'' = 2),
/// and the output is the library's irregular engine's bit for bit. A series that turns
/// irregular half-way (the sliding engine hands over at the first uneven step) agrees with the
/// irregular engine throughout.
#[test]
fn filter_fixed_irregular_times() {
    let mut input = String::from("t,y\n");
    let mut samples = Vec::new();
    let mut t = 0.0;
    for k in 0..120 {
        t += 0.05 + 0.1 * ((k * 7 % 5) as f64);
        let y = 1.0 + t + t * t;
        samples.push((t, y));
        input += &format!("{t},{y}\n");
    }
    let out = ok(
        &[
            "filter", "--kind", "fixed", "--degree", "2", "--window", "9", "--sigma", "0.1",
            "--lead", "0.25",
        ],
        &input,
    );
    let (header, rows) = table(&out);
    assert_eq!(
        header,
        ["t", "y", "d0", "d1", "d2", "s0", "s1", "s2", "window"]
    );
    let mut f = FixedMemory::new(2, 9, FixedEngine::Irregular)
        .unwrap()
        .with_noise_sigma(0.1)
        .unwrap();
    for (k, (row, &(t, y))) in rows.iter().zip(&samples).enumerate() {
        f.update(t, y).unwrap();
        match f.estimate_at(t + 0.25) {
            None => {
                assert!(k < 8);
                assert!(row[2..8].iter().all(String::is_empty), "{row:?}");
            }
            Some(s) => {
                let sd = s.std_devs().unwrap();
                for (cell, w) in row[2..8].iter().zip(s.derivatives.iter().chain(&sd)) {
                    assert_eq!(num(cell).to_bits(), w.to_bits(), "row {k}: {cell} vs {w:e}");
                }
                let h = t + 0.25;
                assert!(close(num(&row[2]), 1.0 + h + h * h, 1e-9), "{row:?}");
                assert!(close(num(&row[3]), 1.0 + 2.0 * h, 1e-9), "{row:?}");
                assert!(close(num(&row[4]), 2.0, 1e-7), "{row:?}");
            }
        }
        assert_eq!(row[8], (k + 1).min(9).to_string());
    }

    // Even for 50 rows, then irregular.
    let mut input = String::from("t,y\n");
    let mut f = FixedMemory::new(2, 9, FixedEngine::Irregular).unwrap();
    let mut want = Vec::new();
    let mut t = 0.0;
    for k in 0..100 {
        t += if k < 50 {
            0.5
        } else {
            0.3 + 0.1 * ((k * 3 % 4) as f64)
        };
        let y = (0.3 * t).sin() * 4.0;
        input += &format!("{t},{y}\n");
        f.update(t, y).unwrap();
        want.push(f.estimate());
    }
    let (_, rows) = table(&ok(
        &[
            "filter", "--kind", "fixed", "--degree", "2", "--window", "9",
        ],
        &input,
    ));
    for (row, w) in rows.iter().zip(&want) {
        match w {
            None => assert!(row[2..5].iter().all(String::is_empty), "{row:?}"),
            Some(s) => {
                for (cell, w) in row[2..5].iter().zip(&s.derivatives) {
                    assert!(close(num(cell), *w, 1e-9), "{row:?} vs {w}");
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// filter --kind auto

/// A line y = 2 + 0.5 t with bounded noise (uniform, σ = 0.2) and an outlier of 20σ at row
/// 120, through `--kind auto --degree 1 --theta 0.9` (τ = the median step, 1).
fn auto_input(outlier_at: Option<usize>) -> (String, Vec<(f64, f64)>) {
    let mut state = 0x2545_F491_4F6C_DD1D_u64;
    let mut input = String::from("t,y\n");
    let mut samples = Vec::new();
    for k in 0..200 {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let u = (state >> 11) as f64 / (1u64 << 53) as f64; // [0, 1)
        let noise = 0.2 * 3f64.sqrt() * (2.0 * u - 1.0); // uniform, σ = 0.2, |noise| < 1.74σ
        let t = k as f64;
        let y = 2.0 + 0.5 * t + noise + if Some(k) == outlier_at { 4.0 } else { 0.0 };
        samples.push((t, y));
        input += &format!("{t},{y}\n");
    }
    (input, samples)
}

/// `--kind auto`: the columns t,y,d0,d1,s0,s1,noise,outlier,misfit; the 20σ outlier is flagged
/// on its row only (the row's estimate is the prediction across it, not pulled towards the
/// outlier), the noise column is positive once estimated and near σ = 0.2; every cell equals
/// the library's AutomaticFilter (the binary is a thin layer).
#[test]
fn filter_auto_flags_outlier() {
    let (input, samples) = auto_input(Some(120));
    let out = ok(
        &[
            "filter", "--kind", "auto", "--degree", "1", "--theta", "0.9",
        ],
        &input,
    );
    let (header, rows) = table(&out);
    assert_eq!(
        header,
        ["t", "y", "d0", "d1", "s0", "s1", "noise", "outlier", "misfit"]
    );
    assert_eq!(rows.len(), 200);
    let flagged: Vec<usize> = (0..200).filter(|&k| rows[k][7] == "1").collect();
    assert_eq!(flagged, [120]);
    assert!(rows.iter().all(|r| r[7] == "0" || r[7] == "1"));
    assert!(rows.iter().all(|r| r[8] == "0" || r[8] == "1"));
    let noise = num(&rows[120][6]);
    assert!(noise > 0.0 && (noise - 0.2).abs() < 0.05, "{:?}", rows[120]);
    assert!((num(&rows[120][2]) - 62.0).abs() < 0.3, "{:?}", rows[120]);
    assert!(rows[199][4..7].iter().all(|c| num(c) > 0.0));

    let mut f = AutomaticFilter::with_defaults(1, 0.9, 1.0).unwrap();
    for (row, &(t, y)) in rows.iter().zip(&samples) {
        let o = f.update(t, y).unwrap();
        let d = o.derivatives().unwrap_or(&[]);
        let sd = o.std_devs().unwrap_or_default();
        for k in 0..2 {
            match d.get(k) {
                Some(w) => assert_eq!(num(&row[2 + k]).to_bits(), w.to_bits(), "{row:?}"),
                None => assert_eq!(row[2 + k], "", "{row:?}"),
            }
            match sd.get(k) {
                Some(w) => assert_eq!(num(&row[4 + k]).to_bits(), w.to_bits(), "{row:?}"),
                None => assert_eq!(row[4 + k], "", "{row:?}"),
            }
        }
        match o.noise_sigma {
            Some(w) => assert_eq!(num(&row[6]).to_bits(), w.to_bits(), "{row:?}"),
            None => assert_eq!(row[6], "", "{row:?}"),
        }
        assert_eq!(row[7], if o.outlier { "1" } else { "0" });
        assert_eq!(row[8], if o.misfit { "1" } else { "0" });
    }
}

/// `--kind auto --sigma S`: the noise column is S on every row and s0..sM come from it; a
/// manoeuvre (the slope turns from 0.5 to -1.5 at t = 150) raises the misfit flag, as the
/// library's filter does row for row.
#[test]
fn filter_auto_given_sigma_and_misfit() {
    let (input, _) = auto_input(None);
    let mut bent = String::from("t,y\n");
    let mut samples = Vec::new();
    for line in input.lines().skip(1) {
        let (t, y) = line.split_once(',').unwrap();
        let (t, mut y): (f64, f64) = (t.parse().unwrap(), y.parse().unwrap());
        if t > 150.0 {
            y -= 2.0 * (t - 150.0);
        }
        samples.push((t, y));
        bent += &format!("{t},{y}\n");
    }
    let out = ok(
        &[
            "filter", "--kind", "auto", "--degree", "1", "--theta", "0.9", "--sigma", "0.2",
        ],
        &bent,
    );
    let (_, rows) = table(&out);
    assert!(
        rows.iter().all(|r| r[6] == "0.2"),
        "noise column is the given sigma"
    );
    let mut config = seqsmooth::polynomial::automatic::AutoConfig::new(1, 0.9, 1.0);
    config.noise_sigma = Some(0.2);
    let mut f = AutomaticFilter::new(config).unwrap();
    for (row, &(t, y)) in rows.iter().zip(&samples) {
        let o = f.update(t, y).unwrap();
        assert_eq!(row[7], if o.outlier { "1" } else { "0" }, "{row:?}");
        assert_eq!(row[8], if o.misfit { "1" } else { "0" }, "{row:?}");
    }
    assert!(
        rows[..150].iter().all(|r| r[8] == "0"),
        "no misfit on the line"
    );
    assert!(
        rows[150..].iter().any(|r| r[8] == "1"),
        "misfit after the manoeuvre"
    );
}

// ---------------------------------------------------------------------------------------------
// smooth

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

// ---------------------------------------------------------------------------------------------
// gains

/// Reyneke §6.4 test vector: degree-2 expanding-memory gains at n = 10 are
/// (83/143, 63/286, 5/286).
#[test]
fn gains_expanding_exact_reyneke_6_4() {
    let out = ok(
        &[
            "gains",
            "--kind",
            "expanding",
            "--degree",
            "2",
            "--n",
            "10",
            "--exact",
        ],
        "",
    );
    assert_eq!(out, "k,gain\n0,83/143\n1,63/286\n2,5/286\n");
}

/// Reyneke §6.6 test vector: degree-2 fading-memory gains at θ = 1/2 are (7/8, 9/16, 1/16);
/// `0.5` is parsed exactly as 1/2.
#[test]
fn gains_fading_exact_reyneke_6_6() {
    for theta in ["1/2", "0.5"] {
        let out = ok(
            &[
                "gains", "--kind", "fading", "--degree", "2", "--theta", theta, "--exact",
            ],
            "",
        );
        assert_eq!(out, "k,gain\n0,7/8\n1,9/16\n2,1/16\n");
    }
    // Morrison Table 13.1 at θ = 0.9, degree 2: 1 - θ³ = 0.271 exactly.
    let out = ok(
        &[
            "gains", "--kind", "fading", "--degree", "2", "--theta", "0.9", "--exact",
        ],
        "",
    );
    assert_eq!(out, "k,gain\n0,271/1000\n1,57/2000\n2,1/2000\n");
}

/// The f64 gains parse back equal to the exact rationals within 1e-15 relative: Reyneke's
/// vectors (§6.4, §6.6) and higher degrees. Without `--exact` θ is rounded to the nearest double
/// first (`9/10` and `0.9` alike), so the reference there is the rational gain at that double.
#[test]
fn gains_f64_agree_with_rationals() {
    let theta_09 = rational_from_f64(0.9).unwrap();
    let cases: [(&[&str], Vec<Rational>); 5] = [
        (
            &["--kind", "expanding", "--degree", "2", "--n", "10"],
            expanding_gains::<Rational>(2, 10, GainForm::Current),
        ),
        (
            &["--kind", "fading", "--degree", "2", "--theta", "1/2"],
            fading_gains::<Rational>(2, parse_rational("1/2").unwrap(), GainForm::Current),
        ),
        (
            &["--kind", "expanding", "--degree", "5", "--n", "17"],
            expanding_gains::<Rational>(5, 17, GainForm::Current),
        ),
        (
            &["--kind", "fading", "--degree", "4", "--theta", "9/10"],
            fading_gains::<Rational>(4, theta_09.clone(), GainForm::Current),
        ),
        (
            &["--kind", "fading", "--degree", "4", "--theta", "0.9"],
            fading_gains::<Rational>(4, theta_09, GainForm::Current),
        ),
    ];
    for (args, want) in cases {
        let (header, rows) = table(&ok(&[&["gains"], args].concat(), ""));
        assert_eq!(header, ["k", "gain"]);
        assert_eq!(rows.len(), want.len());
        for (k, (row, w)) in rows.iter().zip(&want).enumerate() {
            assert_eq!(row[0], k.to_string());
            let w = ratio_to_f64(w);
            assert!(
                (num(&row[1]) - w).abs() <= 1e-15 * w.abs(),
                "{args:?} k = {k}"
            );
        }
    }
    // With --exact, 9/10 and 0.9 are the same exact θ.
    let a = ok(
        &[
            "gains", "--kind", "fading", "--degree", "4", "--theta", "9/10", "--exact",
        ],
        "",
    );
    let b = ok(
        &[
            "gains", "--kind", "fading", "--degree", "4", "--theta", "0.9", "--exact",
        ],
        "",
    );
    assert_eq!(a, b);
    let (_, rows) = table(&a);
    let want = fading_gains::<Rational>(4, parse_rational("9/10").unwrap(), GainForm::Current);
    for (row, w) in rows.iter().zip(&want) {
        assert_eq!(parse_rational(&row[1]).unwrap(), *w);
    }
}

/// The f64 expanding-memory VRF is the exact matrix rounded to nearest, also where an f64
/// evaluation would overflow (degree 20, n = 10^15: the (0,0) entry is 4.41e-13).
#[test]
fn vrf_expanding_f64_is_rounded_exact() {
    let args = [
        "vrf",
        "--kind",
        "expanding",
        "--degree",
        "20",
        "--n",
        "1000000000000000",
    ];
    let (_, rows) = table(&ok(&args, ""));
    let (_, exact) = table(&ok(&[&args[..], &["--exact"]].concat(), ""));
    assert_eq!(rows.len(), 21 * 21);
    for (a, b) in rows.iter().zip(&exact) {
        let r = ratio_to_f64(&parse_rational(&b[2]).unwrap());
        assert_eq!(num(&a[2]).to_bits(), r.to_bits(), "{a:?}");
    }
    assert!(close(num(&rows[0][2]), 4.41e-13, 1e-3));
}

// ---------------------------------------------------------------------------------------------
// vrf

/// Morrison T9-08: the degree-1 expanding-memory 1-step-prediction VRF at n = 1 is
/// [[5, 3], [3, 2]], written row-major as i,j,value; exactly with `--exact`.
#[test]
fn vrf_expanding_predictor_t9_08() {
    let args = [
        "vrf",
        "--kind",
        "expanding",
        "--degree",
        "1",
        "--n",
        "1",
        "--form",
        "predictor",
    ];
    let out = ok(&args, "");
    let (header, rows) = table(&out);
    assert_eq!(header, ["i", "j", "value"]);
    let want = [
        ("0", "0", 5.0),
        ("0", "1", 3.0),
        ("1", "0", 3.0),
        ("1", "1", 2.0),
    ];
    assert_eq!(rows.len(), 4);
    for (r, (i, j, v)) in rows.iter().zip(want) {
        assert_eq!((r[0].as_str(), r[1].as_str()), (i, j));
        assert!(close(num(&r[2]), v, 1e-14), "{r:?}");
    }
    let exact = ok(&[&args[..], &["--exact"]].concat(), "");
    assert_eq!(exact, "i,j,value\n0,0,5\n0,1,3\n1,0,3\n1,1,2\n");
}

/// Morrison (13.7.1): the degree-1 fading-memory 1-step-prediction position VRF at θ = 0.9 is
/// 0.137192010…; the exact form agrees.
#[test]
fn vrf_fading_predictor_13_7_1() {
    let args = [
        "vrf",
        "--kind",
        "fading",
        "--degree",
        "1",
        "--theta",
        "0.9",
        "--form",
        "predictor",
    ];
    let (_, rows) = table(&ok(&args, ""));
    assert_eq!(rows.len(), 4);
    assert!((num(&rows[0][2]) - 0.137192010).abs() < 1e-9);
    assert_eq!(rows[1][2], rows[2][2], "symmetric");
    let (_, exact) = table(&ok(&[&args[..], &["--exact"]].concat(), ""));
    for (a, b) in rows.iter().zip(&exact) {
        let r: BigRational = parse_rational(&b[2]).unwrap();
        let r = ratio_to_f64(&r);
        assert!(close(num(&a[2]), r, 1e-14), "{a:?} vs {b:?}");
    }
}

/// Morrison (7.3.27)/(7.5.16): the fixed-memory VRF W(0)W(0)ᵀ for m = 1, L = 4 (`--window 5
/// --lead 0`) is [[3/5, 1/5], [1/5, 1/10]]; (7.5.25) at L = 4 gives the 1-step prediction
/// (`--lead 1`): 2(2L+3)/((L+1)L) = 11/10, 6/((L+1)L) = 3/10, 12/((L+2)(L+1)L) = 1/10; the centre
/// (h = -L/2 = -2, Ex 7.11) is diag(1/(L+1), 12/(L(L+1)(L+2))) = diag(1/5, 1/10). The lead is
/// parsed exactly (-5/2 = -2.5), and the f64 matrices agree with the exact ones.
#[test]
fn vrf_fixed_matches_morrison() {
    let base = ["vrf", "--kind", "fixed", "--degree", "1", "--window", "5"];
    let cases = [
        ("0", "i,j,value\n0,0,3/5\n0,1,1/5\n1,0,1/5\n1,1,1/10\n"),
        ("1", "i,j,value\n0,0,11/10\n0,1,3/10\n1,0,3/10\n1,1,1/10\n"),
        ("-2", "i,j,value\n0,0,1/5\n0,1,0\n1,0,0\n1,1,1/10\n"),
    ];
    for (lead, want) in cases {
        let args = [&base[..], &["--lead", lead]].concat();
        assert_eq!(
            ok(&[&args[..], &["--exact"]].concat(), ""),
            want,
            "lead {lead}"
        );
        let (header, rows) = table(&ok(&args, ""));
        let (_, exact) = table(want);
        assert_eq!(header, ["i", "j", "value"]);
        for (a, b) in rows.iter().zip(&exact) {
            assert_eq!(a[..2], b[..2]);
            assert!(close(num(&a[2]), exact_f64(&b[2]), 1e-15), "{a:?} vs {b:?}");
        }
    }
    // --lead defaults to 0.
    assert_eq!(
        ok(&[&base[..], &["--exact"]].concat(), ""),
        cases[0].1,
        "default lead"
    );
    // Exact parsing of the lead, and the library's covariance at it.
    let a = ok(&[&base[..], &["--lead", "-5/2", "--exact"]].concat(), "");
    let b = ok(&[&base[..], &["--lead", "-2.5", "--exact"]].concat(), "");
    assert_eq!(a, b);
    let want = covariance::<Rational>(1, 4, parse_rational("-5/2").unwrap()).unwrap();
    let (_, rows) = table(&a);
    for r in rows {
        let (i, j): (usize, usize) = (r[0].parse().unwrap(), r[1].parse().unwrap());
        assert_eq!(parse_rational(&r[2]).unwrap(), want[(i, j)]);
    }
}

/// `--format table` prints aligned text for gains and vrf.
#[test]
fn table_format_is_aligned_text() {
    let out = ok(
        &[
            "gains", "--kind", "fading", "--degree", "2", "--theta", "1/2", "--exact", "--format",
            "table",
        ],
        "",
    );
    assert_eq!(out, "k  gain\n0   7/8\n1  9/16\n2  1/16\n");
    let out = ok(
        &[
            "vrf",
            "--kind",
            "expanding",
            "--degree",
            "1",
            "--n",
            "1",
            "--form",
            "predictor",
            "--exact",
            "--format",
            "table",
        ],
        "",
    );
    assert_eq!(out, "     j=0  j=1\ni=0    5    3\ni=1    3    2\n");
}

// ---------------------------------------------------------------------------------------------
// errors: input data (exit code 1), with line, column and value

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

// ---------------------------------------------------------------------------------------------
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
        &["n 2 is too small for degree 3", "n >= 3"],
    );
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
        &["window 0 is out of range"],
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
        top.contains("smooth  Smooth and differentiate a whole CSV time series"),
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
    assert!(smooth.contains("reads the whole input first"), "{smooth}");
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

// ---------------------------------------------------------------------------------------------
// demo

/// The demo runs on built-in data, exits 0 and prints a summary of all four filters; `-o`
/// writes one filter's CSV.
#[test]
fn demo_runs() {
    // (the plot itself is tested in tests/plot.rs; keep the crate directory clean)
    let out = ok(&["demo", "--no-plot"], "");
    assert!(!out.is_empty());
    for word in ["expanding", "fading", "exact", "gain"] {
        assert!(out.contains(word), "{out}");
    }
    let path = tmp("demo.csv");
    let path = path.to_str().unwrap();
    let again = ok(&["demo", "--no-plot", "-o", path], "");
    assert_eq!(again, out, "deterministic");
    let csv = std::fs::read_to_string(path).unwrap();
    let (header, rows) = table(&csv);
    assert_eq!(header, ["t", "y", "d0", "d1", "d2", "s0", "s1", "s2"]);
    assert_eq!(rows.len(), 400);
}
