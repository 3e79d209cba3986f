//! Switching from expanding to fading memory (`seqsmooth::polynomial::fading::switch`, Morrison
//! (1969) §13.8): the memory-length constants of Table 13.4, Reyneke et al. (2012) Table 1, the
//! switch rules of Ex 13.21 and the exact crossover.

mod common;

use common::book::*;
use common::rational::*;
use nalgebra::DMatrix;
use seqsmooth::polynomial::fading::switch::{memory_length_constant, switch_constant, SwitchRule};
use seqsmooth::polynomial::fixed::fixed_memory_vrf_limit;

/// Table 13.4 as printed (rows i, columns m = i..10).
const TABLE_13_4: [&[&str]; 11] = [
    &[
        "2.00", "3.20", "4.36", "5.51", "6.63", "7.75", "8.85", "9.96", "11.0", "12.1", "13.2",
    ],
    &[
        "3.63", "4.79", "5.92", "7.04", "8.15", "9.25", "10.4", "11.4", "12.5", "13.6",
    ],
    &[
        "5.21", "6.34", "7.46", "8.56", "9.66", "10.8", "11.8", "12.9", "14.0",
    ],
    &[
        "6.76", "7.87", "8.98", "10.1", "11.2", "12.3", "13.3", "14.4",
    ],
    &["8.29", "9.40", "10.5", "11.6", "12.7", "13.7", "14.8"],
    &["9.82", "10.9", "12.0", "13.1", "14.2", "15.2"],
    &["11.3", "12.4", "13.5", "14.6", "15.7"],
    &["12.8", "13.9", "15.0", "16.1"],
    &["14.4", "15.4", "16.5"],
    &["15.8", "16.9"],
    &["17.4"],
];

/// Ex 13.15 λ = G B Gᵀ, [G]_ij = C(j,i), [B]_ij = C(i+j,i)/2^(i+j+1), computed here.
fn lambda_ex_13_15(m: usize) -> DMatrix<Q> {
    let g = DMatrix::from_fn(m + 1, m + 1, |i, j| c(j, i));
    let b = DMatrix::from_fn(m + 1, m + 1, |i, j| c(i + j, i) / qpow(&z(2), i + j + 1));
    mm(&mm(&g, &b), &g.transpose())
}

#[test]
fn table_13_4_memory_length_constants() {
    // Source: Morrison Table 13.4, (13.7.9)-(13.7.14) (higher-precision
    // rows, column means). Oracle: c_im = (κ_ii/λ_ii)^(1/(2i+1)) from the closed-form κ and the
    // Ex 13.15 λ, both computed here.
    for m in 0..=10usize {
        let lam = lambda_ex_13_15(m);
        for i in 0..=m {
            let c_im = memory_length_constant(i, m);
            let want = (f(&kappa(m, i, i)) / f(&lam[(i, i)])).powf(1.0 / (2 * i + 1) as f64);
            assert!(rel_err(c_im, want) < 1e-13, "c({i},{m}) = {c_im} vs {want}");
            let printed = TABLE_13_4[i][m - i];
            if (i, m) == (0, 7) {
                // Book prints 9.96; the exact constant 64/λ_00(7) = 9.95496 rounds to 9.95 (9.955 to
                // three figures, then 9.96): a double-rounding in the book.
                assert!((c_im - 9.95496).abs() < 1e-5, "c(0,7) = {c_im}");
                assert!((c_im - 9.96).abs() <= 0.01);
            } else if (i, m) == (9, 9) {
                // Book prints 15.8; the exact constant is 15.858: a
                // truncation in the printed table, not a rounding.
                assert!((c_im - 15.858).abs() < 5e-4, "c(9,9) = {c_im}");
                assert!((c_im - 15.8).abs() > 0.05);
            } else {
                assert_printed(c_im, printed, &format!("Table 13.4 ({i},{m})"));
            }
        }
    }
    let hp: [&[&str]; 5] = [
        &[
            "2", "3.2", "4.3636", "5.5054", "6.6321", "7.7478", "8.8548", "9.955", "11.049",
            "12.139", "13.224",
        ],
        &[
            "3.6342", "4.7873", "5.9209", "7.0412", "8.1516", "9.2543", "10.351", "11.442",
            "12.528", "13.611",
        ],
        &[
            "5.2103", "6.3396", "7.4558", "8.5626", "9.662", "10.755", "11.844", "12.928", "14.009",
        ],
        &[
            "6.76", "7.8741", "8.9785", "10.076", "11.167", "12.253", "13.335", "14.414",
        ],
        &[
            "8.2943", "9.3976", "10.493", "11.583", "12.668", "13.749", "14.826",
        ],
    ];
    for (i, row) in hp.iter().enumerate() {
        for (k, s) in row.iter().enumerate() {
            assert_printed(
                memory_length_constant(i, i + k),
                s,
                &format!("c({i},{}) hi-prec", i + k),
            );
        }
    }
    let means = [
        "2.0000", "3.4171", "4.7871", "6.1315", "7.4595", "8.7761", "10.0841", "11.3855",
        "12.6816", "13.9732", "15.2611",
    ];
    for (m, s) in means.iter().enumerate() {
        let mean = (0..=m).map(|i| memory_length_constant(i, m)).sum::<f64>() / (m + 1) as f64;
        assert_printed(mean, s, &format!("column mean m = {m}"));
    }
    // (13.7.9)-(13.7.14): m = 1, θ = 0.9 -> L = 32 (position) or 36 (velocity).
    assert!((memory_length_constant(0, 1) / 0.1 - 32.0).abs() < 1e-9);
    assert_eq!((memory_length_constant(1, 1) / 0.1).round(), 36.0);
    // Ex 13.20: θ = 0.99, m = 2 -> about 500 τ (436 / 479 / 521).
    let t: Vec<f64> = (0..=2)
        .map(|i| memory_length_constant(i, 2) / 0.01)
        .collect();
    assert_eq!(
        t.iter().map(|v| v.round() as i64).collect::<Vec<_>>(),
        vec![436, 479, 521]
    );
}

#[test]
fn reyneke_table_1_switch_constants() {
    // Source: Reyneke et al. Table 1: N_s(1-θ) = c_E/c_F = 2, 16/5, 48/11,
    // 512/93, 1280/193, 6144/793 with c_E = (m+1)², c_F = 1/2, 5/4, 33/16, 93/32, 965/256,
    // 2379/512; decimals 2, 3.2, 4.3636, 5.5054, 6.6321, 7.7478.
    let table1 = ["2", "16/5", "48/11", "512/93", "1280/193", "6144/793"];
    let cf = ["1/2", "5/4", "33/16", "93/32", "965/256", "2379/512"];
    let dec = ["2", "3.2", "4.3636", "5.5054", "6.6321", "7.7478"];
    for m in 0..=5usize {
        assert_eq!(switch_constant(m), q(table1[m]), "Table 1, m = {m}");
        let ce = z(((m + 1) * (m + 1)) as i64);
        assert_eq!(q(table1[m]), ce.clone() / q(cf[m]));
        assert_eq!(fixed_memory_vrf_limit(m)[(0, 0)], ce);
        assert_printed(f(&switch_constant(m)), dec[m], "Table 1 decimal");
        assert!(rel_err(memory_length_constant(0, m), f(&q(table1[m]))) < 1e-15);
    }
}

#[test]
fn switch_rules_position_and_derivative() {
    // Source: Morrison (13.8.8) (m = 1, θ = 0.9 -> n_0 = 32), (13.7.13)-(13.7.14) (velocity ->
    // 36), Figs. 13.3/13.5 (m = 2, θ = 0.942 -> 75; m = 3, θ = 0.945 -> 100).
    assert_eq!(SwitchRule::Position.switch_index(1, 0.9).unwrap(), 32);
    assert_eq!(SwitchRule::default(), SwitchRule::Position);
    assert_eq!(SwitchRule::Derivative(1).switch_index(1, 0.9).unwrap(), 36);
    assert_eq!(SwitchRule::Derivative(0).switch_index(1, 0.9).unwrap(), 32);
    assert_eq!(SwitchRule::Position.switch_index(2, 0.942).unwrap(), 75);
    assert_eq!(SwitchRule::Position.switch_index(3, 0.945).unwrap(), 100);
    assert!(SwitchRule::Derivative(3).switch_index(2, 0.9).is_err());
    assert!(SwitchRule::Position.switch_index(1, 1.0).is_err());
    assert_eq!(SwitchRule::AtSample(50).switch_index(2, 0.9).unwrap(), 50);
    // "Never less than m + 1" (the expanding start must determine the state).
    assert_eq!(SwitchRule::AtSample(0).switch_index(2, 0.9).unwrap(), 3);
    assert_eq!(SwitchRule::Position.switch_index(4, 0.1).unwrap(), 7);
}

#[test]
fn switch_rule_column_mean_ex_13_21() {
    // Source: Morrison Ex 13.21 a-c: (m, θ) = (2, 0.93) -> 68, (3, 0.81) -> 32, (1, 0.98) -> 170
    // (column means of Table 13.4: 68.4, 32.3, 170.9). The three book
    // answers (and 32, 75, 100 of §13.8) are consistent with truncating c/(1-θ), not rounding.
    assert_eq!(SwitchRule::ColumnMean.switch_index(2, 0.93).unwrap(), 68);
    assert_eq!(SwitchRule::ColumnMean.switch_index(3, 0.81).unwrap(), 32);
    assert_eq!(SwitchRule::ColumnMean.switch_index(1, 0.98).unwrap(), 170);
}

#[test]
fn switch_rule_column_mean_ex_13_21_a_b() {
    // Source: Morrison Ex 13.21 a, b (the two parts not affected by the rounding question above).
    assert_eq!(SwitchRule::ColumnMean.switch_index(2, 0.93).unwrap(), 68);
    assert_eq!(SwitchRule::ColumnMean.switch_index(3, 0.81).unwrap(), 32);
}

#[test]
fn switch_rule_exact_crossover() {
    // Definition (Reyneke et al. §7.2): the first n >= m with
    // VRF_EMP,current(n)[0,0] = h_0(n) <= VRF_FMP,current(θ)[0,0], evaluated here exactly with the
    // printed Table 9.1/Reyneke §6.4 h_0(n) and the Reyneke/Table 13.2 current position VRF
    // (1-θ) Q_m(θ)/(1+θ)^(2m+1), at θ = the decimal the caller typed. The library answer is
    // then max(n, m+1).
    let q_current: [&[i64]; 6] = [
        &[1],
        &[1, 4, 5],
        &[1, 6, 16, 24, 19],
        &[1, 8, 29, 64, 97, 104, 69],
        &[1, 10, 46, 130, 256, 380, 446, 410, 251],
        &[1, 12, 67, 232, 562, 1024, 1484, 1792, 1847, 1572, 923],
    ];
    let oracle = |m: usize, th: &Q| -> u64 {
        let target =
            (z(1) - th.clone()) * poly(q_current[m], th) / qpow(&(z(1) + th.clone()), 2 * m + 1);
        let mut n = m as u64;
        while emp_book(m, &z(n as i64))[0] > target {
            n += 1;
        }
        n.max(m as u64 + 1)
    };
    for th in ["0.9", "0.95", "0.99", "0.8", "0.5", "0.97", "0.3"] {
        let thq = q(th);
        let thf: f64 = th.parse().unwrap();
        for m in 0..=5usize {
            let want = oracle(m, &thq);
            let got = SwitchRule::ExactCrossover.switch_index(m, thf).unwrap();
            assert_eq!(got, want, "exact crossover m = {m}, θ = {th}");
        }
    }
    // Spec values n* (θ = 0.9: 18.000 / 29.193 / 40.051 / 50.709; 0.95: 38.000 / 61.186 / 83.674 /
    // 105.741; 0.99: 198.000 / 317.181 / 432.755 / 546.156): the first integer n >= n*.
    let expected: [(f64, [u64; 4]); 3] = [
        (0.9, [18, 30, 41, 51]),
        (0.95, [38, 62, 84, 106]),
        (0.99, [198, 318, 433, 547]),
    ];
    for (th, ns) in expected {
        for (m, n) in ns.iter().enumerate() {
            assert_eq!(
                SwitchRule::ExactCrossover.switch_index(m, th).unwrap(),
                *n,
                "m = {m}, θ = {th}"
            );
        }
    }
    // m = 0: n* = 2θ/(1-θ) exactly (a tie at θ = 0.9, which the rule includes).
    assert_eq!(
        emp_book(0, &z(18))[0],
        (z(1) - q("0.9")) / (z(1) + q("0.9"))
    );
}
