//! End-to-end tests of the `seqsmooth` command: each runs the built binary and checks its
//! output against published test vectors (Morrison 1969; Reyneke et al. 2012) or the library,
//! and its error messages and exit codes against the command-line contract.

use num_rational::BigRational;
use seqsmooth::polynomial::gains::{expanding_gains, fading_gains, GainForm};
use seqsmooth::polynomial::vrf::{expanding_vrf, EstimateForm};
use seqsmooth::scalar::{parse_rational, ratio_to_f64, rational_from_f64, Rational};
use seqsmooth::{Engine, ExpandingMemory, FadingMemory, PolynomialFilter};
use std::io::Write;
use std::path::PathBuf;
use std::process::{Command, Stdio};

/// The outcome of one run of the binary.
struct Out {
    code: i32,
    stdout: String,
    stderr: String,
}

/// Runs `seqsmooth args…` with `stdin` as standard input.
fn run(args: &[&str], stdin: &str) -> Out {
    let mut child = Command::new(env!("CARGO_BIN_EXE_seqsmooth"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn seqsmooth");
    let mut input = child.stdin.take().unwrap();
    let data = stdin.as_bytes().to_vec();
    // Write from a thread: the child may exit (on an error) before reading everything.
    let writer = std::thread::spawn(move || {
        let _ = input.write_all(&data);
    });
    let out = child.wait_with_output().expect("wait for seqsmooth");
    writer.join().unwrap();
    Out {
        code: out.status.code().expect("exit code"),
        stdout: String::from_utf8(out.stdout).unwrap(),
        stderr: String::from_utf8(out.stderr).unwrap(),
    }
}

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
/// irregular times): the binary is a thin layer.
#[test]
fn filter_agrees_with_library() {
    let mut input = String::from("t,y\n");
    let mut f = FadingMemory::new(2, 0.95, 1.0, Engine::Gain).unwrap();
    let mut e = ExpandingMemory::new(2, Engine::Exact).unwrap();
    let mut last = (None, None);
    for k in 0..120 {
        let t = k as f64 + 0.3 * ((k * 7 % 3) as f64);
        let y = (k as f64 * 0.37).sin() * 10.0;
        input += &format!("{t},{y}\n");
        f.update(t, y).unwrap();
        e.update(t, y).unwrap();
        last = (f.estimate(), e.estimate());
    }
    let out = ok(
        &[
            "filter", "--kind", "fading", "--degree", "2", "--theta", "0.95", "--tau", "1",
            "--engine", "gain",
        ],
        &input,
    );
    let (_, rows) = table(&out);
    let want = last.0.unwrap().derivatives;
    for (cell, w) in rows[119][2..].iter().zip(&want) {
        assert_eq!(num(cell), *w);
    }
    let out = ok(&["filter", "--kind", "expanding", "--degree", "2"], &input);
    let (_, rows) = table(&out);
    let want = last.1.unwrap().derivatives;
    for (cell, w) in rows[119][2..].iter().zip(&want) {
        assert_eq!(num(cell), *w);
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
    let out = ok(&["demo"], "");
    assert!(!out.is_empty());
    for word in ["expanding", "fading", "exact", "gain"] {
        assert!(out.contains(word), "{out}");
    }
    let path = tmp("demo.csv");
    let path = path.to_str().unwrap();
    let again = ok(&["demo", "-o", path], "");
    assert_eq!(again, out, "deterministic");
    let csv = std::fs::read_to_string(path).unwrap();
    let (header, rows) = table(&csv);
    assert_eq!(header, ["t", "y", "d0", "d1", "d2", "s0", "s1", "s2"]);
    assert_eq!(rows.len(), 400);
}
