//! End-to-end tests of `seqsmooth gains` and `seqsmooth vrf`: published tables (Morrison 1969; Reyneke et al. 2012)
//! and exact rationals.

use num_rational::BigRational;
use seqsmooth::polynomial::expanding::gains::expanding_gains;
use seqsmooth::polynomial::fading::gains::fading_gains;
use seqsmooth::polynomial::fixed::covariance;
use seqsmooth::polynomial::form::GainForm;
use seqsmooth::scalar::{parse_rational, ratio_to_f64, rational_from_f64, Rational};

mod common;
use common::*;

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

// errors: input data (exit code 1), with line, column and value
