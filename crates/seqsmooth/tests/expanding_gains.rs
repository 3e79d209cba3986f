//! Expanding-memory gains (`seqsmooth::polynomial::expanding::gains`, Morrison (1969) ch. 9) against the
//! printed Table 9.1 ((9.4.18)-(9.4.19)), Reyneke et al. (2012) §6.4 (degrees 4, 5), the small-n
//! vectors, the printed numerator polynomials and exact least-squares weights; the `f64` gains
//! against the exact ones.

mod common;

use common::book::*;
use common::rational::*;
use nalgebra::DMatrix;
use seqsmooth::polynomial::expanding::gains::{
    expanding_gain_numerators, expanding_gains, ExpandingGainSchedule,
};
use seqsmooth::polynomial::form::GainForm;

fn n_values() -> Vec<u64> {
    let mut v: Vec<u64> = (0..=60).collect();
    v.extend([99, 1000, 12345, 1_000_000, 1_000_000_007, 1_000_000_000_000]);
    v
}

/// The exact current-estimate gains of degrees `0..=max_degree` equal the printed formulas
/// ([`emp_book`]) at every n of [`n_values`].
fn assert_book_gains(max_degree: usize) {
    for m in 0..=max_degree {
        for n in n_values() {
            let got = expanding_gains::<Q>(m, n, GainForm::Current);
            assert_eq!(got, emp_book(m, &z(n as i64)), "m = {m}, n = {n}");
        }
    }
}

/// Gain `k` of degree `m` equals `c (2n+1) q(n) / (n+m+1)^(m+1)` for n = 0..60 (`q` lowest
/// power first): an alternative printed factorisation.
fn assert_factorised_gain(m: usize, k: usize, c: i64, q: &[i64]) {
    for n in 0..=60i64 {
        let nq = z(n);
        assert_eq!(
            z(c) * poly(&[1, 2], &nq) * poly(q, &nq) / ff(&(nq.clone() + z(m as i64 + 1)), m + 1),
            expanding_gains::<Q>(m, n as u64, GainForm::Current)[k],
            "m = {m}, k = {k}, n = {n}"
        );
    }
}

#[test]
fn expanding_gains_match_morrison_table_9_1() {
    // Source: Morrison Table 9.1, (9.4.18)-(9.4.19) (degrees 0-3).
    assert_book_gains(3);
    // Alternative printed factorisation of the m = 3 position gain: 8(2n+1)(n²+n+3).
    assert_factorised_gain(3, 0, 8, &[3, 1, 1]);
}

#[test]
fn expanding_gains_match_reyneke_section_6_4() {
    // Source: Reyneke et al. §6.4, degrees 0-5; m = 4 also derived from Morrison
    // (9.4.18); top gain (2m+1)!/(m!)² / (n+m+1)^(m+1); h_0(n) = 1 for n <= m.
    assert_book_gains(5);
    // Alternative factorisation of the m = 4 velocity gain: 50(2n+1)(3n²+3n+10).
    assert_factorised_gain(4, 1, 50, &[10, 3, 3]);
    for m in 0..=10usize {
        for n in [0u64, 1, 5, 17, 60, 1000] {
            let g = expanding_gains::<Q>(m, n, GainForm::Current);
            let top =
                fact(2 * m + 1) / (fact(m) * fact(m)) / ff(&z((n + m as u64 + 1) as i64), m + 1);
            assert_eq!(g[m], top, "top gain, m = {m}, n = {n}");
            if n as usize <= m {
                assert_eq!(g[0], z(1), "h_0(n) = 1 for n <= m (m = {m}, n = {n})");
            }
        }
    }
}

#[test]
fn expanding_gains_small_n_t9_01_and_n_10_vector() {
    // Source: Morrison Table 9.1 at n = 0..4, m = 0..4, and Reyneke §6.4 test vector at n = 10.
    let t901: [&[&[&str]]; 5] = [
        &[&["1"], &["1/2"], &["1/3"], &["1/4"], &["1/5"]],
        &[
            &["1", "3"],
            &["1", "1"],
            &["5/6", "1/2"],
            &["7/10", "3/10"],
            &["3/5", "1/5"],
        ],
        &[
            &["1", "3", "5"],
            &["1", "9/4", "5/4"],
            &["1", "3/2", "1/2"],
            &["19/20", "21/20", "1/4"],
            &["31/35", "27/35", "1/7"],
        ],
        &[
            &["1", "25/6", "5", "35/6"],
            &["1", "17/6", "3", "7/6"],
            &["1", "41/18", "5/3", "7/18"],
            &["1", "11/6", "1", "1/6"],
            &["69/70", "125/84", "9/14", "1/12"],
        ],
        &[
            &["1", "25/6", "35/4", "35/6", "21/4"],
            &["1", "10/3", "35/8", "35/12", "7/8"],
            &["1", "25/9", "35/12", "25/18", "1/4"],
            &["1", "115/48", "65/32", "35/48", "3/32"],
            &["1", "25/12", "35/24", "5/12", "1/24"],
        ],
    ];
    for (m, rows) in t901.iter().enumerate() {
        for (n, row) in rows.iter().enumerate() {
            let want: Vec<Q> = row.iter().map(|s| q(s)).collect();
            assert_eq!(
                expanding_gains::<Q>(m, n as u64, GainForm::Current),
                want,
                "T9-01 m = {m}, n = {n}"
            );
        }
    }
    let n10: [&[&str]; 6] = [
        &["1/11"],
        &["7/22", "1/22"],
        &["83/143", "63/286", "5/286"],
        &["113/143", "475/858", "15/143", "5/858"],
        &["131/143", "425/429", "185/572", "35/858", "1/572"],
        &[
            "557/572",
            "16507/11440",
            "245/352",
            "667/4576",
            "63/4576",
            "1/2080",
        ],
    ];
    for (m, row) in n10.iter().enumerate() {
        let want: Vec<Q> = row.iter().map(|s| q(s)).collect();
        assert_eq!(
            expanding_gains::<Q>(m, 10, GainForm::Current),
            want,
            "n = 10, m = {m}"
        );
    }
    // Ex 2.3 / TV2.8: m = 1 gains (α_n, β_n) = (h_1, h_0); α_n + β_n = 4/(n+1).
    for n in 0..=40u64 {
        let g = expanding_gains::<Q>(1, n, GainForm::Current);
        assert_eq!(g[0].clone() + g[1].clone(), fr(4, n as i64 + 1));
    }
}

#[test]
fn expanding_gains_equal_exact_least_squares_weights() {
    // Oracle: exact least squares solved here (Morrison §9.2: the EMP at n is the LS fit over
    // y_0..y_n; its gain is the weight of y_n in the current estimate, and Φ(1)·H the weight in
    // the 1-step prediction (GainForm::Predictor, (13.5.35)-(13.5.37)).
    for m in 0..=8usize {
        let mut ns: Vec<u64> = (m as u64..=m as u64 + 30).collect();
        ns.extend([97, 250]);
        for n in ns {
            let a = ls_normal_matrix(m, n);
            let h = inv(&a).column(0).into_owned();
            let got = expanding_gains::<Q>(m, n, GainForm::Current);
            for i in 0..=m {
                assert_eq!(got[i], h[i], "LS gain m = {m}, n = {n}, i = {i}");
            }
            let hp = mm(
                &pascal(m, &z(1)),
                &DMatrix::from_column_slice(m + 1, 1, h.as_slice()),
            );
            let gotp = expanding_gains::<Q>(m, n, GainForm::Predictor);
            for i in 0..=m {
                assert_eq!(
                    gotp[i],
                    hp[(i, 0)],
                    "predictor gain m = {m}, n = {n}, i = {i}"
                );
            }
        }
    }
}

#[test]
fn expanding_gain_numerators_match_printed_polynomials() {
    // Source: Morrison Table 9.1 / Reyneke §6.4 numerators over the common denominator
    // (n+m+1)^(m+1): the polynomial coefficients, exactly (lowest power first).
    let printed: [&[&[i64]]; 5] = [
        &[&[1]],
        &[&[2, 4], &[6, 0]],
        &[&[6, 9, 9], &[18, 36, 0], &[30, 0, 0]],
        &[
            &[24, 56, 24, 16],
            &[100, 120, 120, 0],
            &[120, 240, 0, 0],
            &[140, 0, 0, 0],
        ],
        &[
            &[120, 250, 275, 50, 25],
            &[500, 1150, 450, 300, 0],
            &[1050, 1050, 1050, 0, 0],
            &[700, 1400, 0, 0, 0],
            &[630, 0, 0, 0, 0],
        ],
    ];
    for (m, rows) in printed.iter().enumerate() {
        let num = expanding_gain_numerators(m);
        for (k, row) in rows.iter().enumerate() {
            let want: Vec<Q> = row.iter().map(|v| z(*v)).collect();
            assert_eq!(num[k].coeffs, want, "numerator m = {m}, k = {k}");
        }
    }
    // m = 5 from the printed factored forms: compare as polynomials at 7 points (degree <= 5).
    let num = expanding_gain_numerators(5);
    for n in 0..=6i64 {
        let den = ff(&z(n + 6), 6);
        let book = emp_book(5, &z(n));
        for k in 0..=5 {
            assert_eq!(
                num[k].eval(&z(n)),
                book[k].clone() * den.clone(),
                "m = 5, k = {k}"
            );
        }
    }
}

#[test]
fn f64_expanding_gains_match_exact() {
    // Oracle: the exact rational gains (verified above against the printed tables and LS).
    let mut ns: Vec<u64> = (0..200).collect();
    ns.extend([
        1_000, 1_234, 10_000, 54_321, 100_000, 999_999, 1_000_000, 3_000_000, 9_999_991, 10_000_000,
    ]);
    for m in 0..=10usize {
        let sched = ExpandingGainSchedule::new(m);
        assert_eq!(sched.degree(), m);
        // Exact reference: the exact numerators over (n+m+1)^(m+1) (equal to `expanding_gains`
        // exactly, checked on a subset; recomputing the numerators per call would be slow).
        let num = expanding_gain_numerators(m);
        let p1 = pascal(m, &z(1));
        let mut buf = vec![0.0; m + 1];
        for (idx, &n) in ns.iter().enumerate() {
            let nq = z(n as i64);
            let den = ff(&(nq.clone() + z(m as i64 + 1)), m + 1);
            let exact: Vec<Q> = num.iter().map(|p| p.eval(&nq) / den.clone()).collect();
            if idx % 37 == 0 {
                assert_eq!(exact, expanding_gains::<Q>(m, n, GainForm::Current));
            }
            sched.gains(n, &mut buf);
            let v = sched.gains_vec(n);
            // The generic f64 instantiation rebuilds the exact numerators on every call (slow),
            // so it is sampled: every 5th small n and all the large ones.
            if idx % 5 == 0 || n >= 1000 {
                let exact_p = mm(&p1, &DMatrix::from_column_slice(m + 1, 1, &exact));
                let g = expanding_gains::<f64>(m, n, GainForm::Current);
                let gp = expanding_gains::<f64>(m, n, GainForm::Predictor);
                for k in 0..=m {
                    let e = f(&exact[k]);
                    assert!(
                        rel_err(g[k], e) <= 1e-14,
                        "expanding_gains f64 m={m} n={n} k={k}"
                    );
                    assert!(
                        rel_err(gp[k], f(&exact_p[(k, 0)])) <= 1e-14,
                        "predictor f64 m={m} n={n} k={k}"
                    );
                }
            }
            for k in 0..=m {
                let e = f(&exact[k]);
                assert!(
                    rel_err(buf[k], e) <= 1e-14,
                    "schedule m={m} n={n} k={k}: {} vs {e}",
                    buf[k]
                );
                assert_eq!(v[k], buf[k]);
            }
        }
    }
}

/// `position_gain` (written in `1/(n+1)` so that it holds for any `n`) equals the exact
/// rational `h_0(n)` to 1e-14 relative at every degree to `MAX_DEGREE`, from `n = m` to
/// `n = 10¹⁸`, where `Π (n+j)` is far beyond the double range for high degrees.
#[test]
fn position_gain_matches_exact_for_any_n() {
    let ns: Vec<u64> = (0..40)
        .chain([
            1_000,
            123_457,
            10_000_000,
            1 << 40,
            999_999_999_999,
            1 << 60,
        ])
        .chain([1_000_000_000_000_000_000])
        .collect();
    for m in 0..=seqsmooth::polynomial::MAX_DEGREE {
        let sched = ExpandingGainSchedule::new(m);
        let num = expanding_gain_numerators(m);
        for &n in ns.iter().filter(|&&n| n >= m as u64) {
            let nq = z(n as i64);
            let den = ff(&(nq.clone() + z(m as i64 + 1)), m + 1);
            let exact = f(&(num[0].eval(&nq) / den));
            let got = sched.position_gain(n);
            assert!(
                rel_err(got, exact) <= 1e-14,
                "m={m} n={n}: {got:e} against {exact:e}"
            );
        }
    }
}
