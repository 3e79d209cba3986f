//! Fading-memory variance-reduction matrices (`seqsmooth::polynomial::fading::vrf`, Morrison (1969)
//! §13.6) against the printed Table 13.2, the full matrices (13.6.26), (13.6.34), the numeric
//! vectors at θ = 0.9 and 0.5, the θ → 1 limits of Table 13.3 and a Lyapunov iteration (13.6.41).

mod common;

use common::book::*;
use common::monte_carlo::*;
use common::rational::*;
use nalgebra::DMatrix;
use num_traits::Signed;
use seqsmooth::polynomial::fading::gains::fading_gains;
use seqsmooth::polynomial::fading::vrf::{fading_vrf, fading_vrf_limit};
use seqsmooth::polynomial::form::EstimateForm;
use seqsmooth::polynomial::form::GainForm;
use seqsmooth::scalar::rational_from_f64;
use seqsmooth::{Engine, FadingMemory};

/// Morrison Table 13.2 (m = 0..2 book; m = 3, 4 computed): unscaled
/// predictor diagonal with τ = 1, as (constant, numerator coefficients in θ, power of (1-θ));
/// denominator (1+θ)^(2m+1).
fn table_13_2(m: usize) -> Vec<(Q, &'static [i64], usize)> {
    match m {
        0 => vec![(z(1), &[1], 1)],
        1 => vec![(z(1), &[5, 4, 1], 1), (z(2), &[1], 3)],
        2 => vec![
            (z(1), &[19, 24, 16, 6, 1], 1),
            (fr(1, 2), &[49, 50, 13], 3),
            (z(6), &[1], 5),
        ],
        3 => vec![
            (z(1), &[69, 104, 97, 64, 29, 8, 1], 1),
            (fr(5, 18), &[581, 970, 762, 298, 53], 3),
            (z(2), &[63, 76, 23], 5),
            (z(20), &[1], 7),
        ],
        4 => vec![
            (z(1), &[251, 410, 446, 380, 256, 130, 46, 10, 1], 1),
            (
                fr(5, 72),
                &[12199, 25588, 28923, 21216, 10013, 2988, 449],
                3,
            ),
            (fr(7, 72), &[12521, 25144, 22746, 10144, 2021], 5),
            (fr(5, 2), &[253, 338, 113], 7),
            (z(70), &[1], 9),
        ],
        _ => unreachable!(),
    }
}

#[test]
fn fading_vrf_table_13_2_predictor_and_current_diagonals() {
    // Source: Morrison Table 13.2; current estimate = the reversed
    // numerator polynomial (an observation checked here; Reyneke §7.2 Q_m).
    for th in exact_thetas() {
        let om = z(1) - th.clone();
        for m in 0..=4usize {
            let pred = fading_vrf::<Q>(m, th.clone(), EstimateForm::Predictor).unwrap();
            let cur = fading_vrf::<Q>(m, th.clone(), EstimateForm::Current).unwrap();
            let den = qpow(&(z(1) + th.clone()), 2 * m + 1);
            for (i, (k, coeffs, p)) in table_13_2(m).into_iter().enumerate() {
                let w = fact(i) * fact(i);
                let want_p = k.clone() * qpow(&om, p) * poly(coeffs, &th) / den.clone();
                let want_c = k * qpow(&om, p) * rev_poly(coeffs, &th) / den.clone();
                assert_eq!(
                    pred[(i, i)].clone() * w.clone(),
                    want_p,
                    "pred m = {m}, i = {i}, θ = {th}"
                );
                assert_eq!(
                    cur[(i, i)].clone() * w,
                    want_c,
                    "current m = {m}, i = {i}, θ = {th}"
                );
            }
        }
        // Reyneke Q5 (m = 5 position, current estimate) and its reversal for the predictor.
        let q5: &[i64] = &[1, 12, 67, 232, 562, 1024, 1484, 1792, 1847, 1572, 923];
        let den = qpow(&(z(1) + th.clone()), 11);
        let cur = fading_vrf::<Q>(5, th.clone(), EstimateForm::Current).unwrap();
        let pred = fading_vrf::<Q>(5, th.clone(), EstimateForm::Predictor).unwrap();
        assert_eq!(cur[(0, 0)], om.clone() * poly(q5, &th) / den.clone());
        assert_eq!(pred[(0, 0)], om.clone() * rev_poly(q5, &th) / den);
    }
    assert!(fading_vrf::<f64>(1, 1.0, EstimateForm::Current).is_err());
    assert!(fading_vrf::<f64>(1, 0.0, EstimateForm::Current).is_err());
}

#[test]
fn fading_vrf_full_matrices_13_6_26_13_6_34_and_m2() {
    // Source: Morrison (13.6.26), (13.6.34) (m = 1), computed m = 2;
    // independent oracle: Cov = A⁻¹ B A⁻¹ with A_ij = Σ θ^k (-k)^(i+j), B_ij = Σ θ^(2k) (-k)^(i+j)
    // (Reyneke et al. §7.2), shifted by Φ(1) for the predictor, m <= 6.
    for th in exact_thetas() {
        let om = z(1) - th.clone();
        let op = z(1) + th.clone();
        let p = |cs: &[i64]| poly(cs, &th);
        let k1 = om.clone() / qpow(&op, 3);
        let pred1 = fading_vrf::<Q>(1, th.clone(), EstimateForm::Predictor).unwrap();
        let cur1 = fading_vrf::<Q>(1, th.clone(), EstimateForm::Current).unwrap();
        let wp = [
            [
                k1.clone() * p(&[5, 4, 1]),
                k1.clone() * om.clone() * p(&[3, 1]),
            ],
            [
                k1.clone() * om.clone() * p(&[3, 1]),
                k1.clone() * z(2) * om.clone() * om.clone(),
            ],
        ];
        let wc = [
            [
                k1.clone() * p(&[1, 4, 5]),
                k1.clone() * om.clone() * p(&[1, 3]),
            ],
            [
                k1.clone() * om.clone() * p(&[1, 3]),
                k1.clone() * z(2) * om.clone() * om.clone(),
            ],
        ];
        for i in 0..2 {
            for j in 0..2 {
                assert_eq!(pred1[(i, j)], wp[i][j], "(13.6.26) θ = {th}");
                assert_eq!(cur1[(i, j)], wc[i][j], "(13.6.34) θ = {th}");
            }
        }
        let d5 = qpow(&op, 5);
        let o = |k: usize| qpow(&om, k);
        let pred2 = fading_vrf::<Q>(2, th.clone(), EstimateForm::Predictor).unwrap();
        let cur2 = fading_vrf::<Q>(2, th.clone(), EstimateForm::Current).unwrap();
        let wp2 = [
            (0, 0, o(1) * p(&[19, 24, 16, 6, 1])),
            (0, 1, fr(3, 2) * o(2) * p(&[2, 1]) * p(&[7, 4, 1])),
            (0, 2, fr(1, 2) * o(3) * p(&[10, 5, 1])),
            (1, 1, fr(1, 2) * o(3) * p(&[49, 50, 13])),
            (1, 2, z(3) * o(4) * p(&[2, 1])),
            (2, 2, fr(3, 2) * o(5)),
        ];
        let wc2 = [
            (0, 0, o(1) * p(&[1, 6, 16, 24, 19])),
            (0, 1, fr(3, 2) * o(2) * p(&[1, 2]) * p(&[1, 4, 7])),
            (0, 2, fr(1, 2) * o(3) * p(&[1, 5, 10])),
            (1, 1, fr(1, 2) * o(3) * p(&[13, 50, 49])),
            (1, 2, z(3) * o(4) * p(&[1, 2])),
            (2, 2, fr(3, 2) * o(5)),
        ];
        for (i, j, w) in wp2 {
            assert_eq!(
                pred2[(i, j)],
                w.clone() / d5.clone(),
                "m = 2 pred ({i},{j}) θ = {th}"
            );
            assert_eq!(pred2[(j, i)], w / d5.clone());
        }
        for (i, j, w) in wc2 {
            assert_eq!(
                cur2[(i, j)],
                w.clone() / d5.clone(),
                "m = 2 current ({i},{j}) θ = {th}"
            );
            assert_eq!(cur2[(j, i)], w / d5.clone());
        }
    }
    for th in [fr(1, 2), fr(9, 10), fr(1, 3), fr(7, 8)] {
        let th2 = th.clone() * th.clone();
        let mom1: Vec<Q> = (0..=12)
            .map(|p| weighted_series_sum(|x| qpow(x, p), p, &th))
            .collect();
        let mom2: Vec<Q> = (0..=12)
            .map(|p| weighted_series_sum(|x| qpow(x, p), p, &th2))
            .collect();
        for m in 0..=6usize {
            let sgn = |i: usize, j: usize, v: &Q| {
                if (i + j).is_multiple_of(2) {
                    v.clone()
                } else {
                    -v.clone()
                }
            };
            let a = DMatrix::from_fn(m + 1, m + 1, |i, j| sgn(i, j, &mom1[i + j]));
            let b = DMatrix::from_fn(m + 1, m + 1, |i, j| sgn(i, j, &mom2[i + j]));
            let ai = inv(&a);
            let cov = mm(&mm(&ai, &b), &ai);
            assert_eq!(
                fading_vrf::<Q>(m, th.clone(), EstimateForm::Current).unwrap(),
                cov,
                "m = {m}, θ = {th}"
            );
            let p1 = pascal(m, &z(1));
            let pcov = mm(&mm(&p1, &cov), &p1.transpose());
            assert_eq!(
                fading_vrf::<Q>(m, th.clone(), EstimateForm::Predictor).unwrap(),
                pcov
            );
        }
    }
}

#[test]
fn fading_vrf_numeric_vectors_theta_0_9_and_0_5() {
    // Source: numeric fading-memory vectors computed from Morrison (13.6.x), (13.7.1) (scaled z, σ = 1).
    type Row = (usize, EstimateForm, &'static [&'static str]);
    use EstimateForm::{Current as C, Predictor as P};
    let nine: [Row; 9] = [
        (0, P, &["0.052631579"]),
        (1, P, &["0.13719201", "0.00029158769"]),
        (2, P, &["0.23662261", "0.0021107799", "6.0579161e-07"]),
        (
            3,
            P,
            &[
                "0.34916448",
                "0.0072196391",
                "8.3921436e-06",
                "6.2151596e-10",
            ],
        ),
        (
            4,
            P,
            &[
                "0.47496853",
                "0.017796452",
                "4.6922594e-05",
                "1.3961082e-08",
                "3.7661113e-13",
            ],
        ),
        (1, C, &["0.12611168", "0.00029158769"]),
        (2, C, &["0.19919195", "0.0019726594", "6.0579161e-07"]),
        (
            3,
            C,
            &[
                "0.26857107",
                "0.0062982691",
                "7.9670267e-06",
                "6.2151596e-10",
            ],
        ),
        (
            4,
            C,
            &[
                "0.33330973",
                "0.014479962",
                "4.2270731e-05",
                "1.3388633e-08",
                "3.7661113e-13",
            ],
        ),
    ];
    let half: [Row; 9] = [
        (0, P, &["0.33333333"]),
        (1, P, &["1.0740741", "0.074074074"]),
        (2, P, &["2.3580247", "0.63580247", "0.0061728395"]),
        (
            3,
            P,
            &["4.5454961", "2.6359041", "0.097622314", "0.00025402632"],
        ),
        (
            4,
            P,
            &[
                "8.2701316",
                "8.0389627",
                "0.6356774",
                "0.0063541861",
                "6.1742508e-06",
            ],
        ),
        (1, C, &["0.62962963", "0.074074074"]),
        (2, C, &["0.80246914", "0.41358025", "0.0061728395"]),
        (
            3,
            C,
            &["0.89666209", "1.1178428", "0.070187471", "0.00025402632"],
        ),
        (
            4,
            C,
            &[
                "0.94655286",
                "2.2345672",
                "0.33005198",
                "0.0048723659",
                "6.1742508e-06",
            ],
        ),
    ];
    for (th, rows) in [(0.9, &nine), (0.5, &half)] {
        for (m, form, vals) in rows.iter() {
            let s = fading_vrf::<f64>(*m, th, *form).unwrap();
            for (i, v) in vals.iter().enumerate() {
                assert_printed(
                    s[(i, i)],
                    v,
                    &format!("θ = {th}, m = {m}, {form:?}, i = {i}"),
                );
            }
        }
    }
    assert_eq!(
        fading_vrf::<Q>(0, fr(1, 2), EstimateForm::Predictor).unwrap()[(0, 0)],
        fr(1, 3)
    );
    // Full matrices at θ = 0.9.
    let full: [(usize, EstimateForm, &[&[&str]]); 3] = [
        (
            1,
            P,
            &[
                &["0.137192010", "0.005685960"],
                &["0.005685960", "0.000291588"],
            ],
        ),
        (
            1,
            C,
            &[
                &["0.126111678", "0.005394372"],
                &["0.005394372", "0.000291588"],
            ],
        ),
        (
            2,
            C,
            &[
                &["0.19919195", "0.017420144", "0.00027462553"],
                &["0.017420144", "0.0019726594", "3.3924330e-5"],
                &["0.00027462553", "3.3924330e-5", "6.0579161e-7"],
            ],
        ),
    ];
    for (m, form, rows) in full {
        let s = fading_vrf::<f64>(m, 0.9, form).unwrap();
        for (i, row) in rows.iter().enumerate() {
            for (j, v) in row.iter().enumerate() {
                assert_printed(
                    s[(i, j)],
                    v,
                    &format!("θ = 0.9 full m = {m} {form:?} ({i},{j})"),
                );
            }
        }
    }
}

#[test]
fn f64_fading_vrf_matches_exact() {
    // Oracle: the exact rational VRF at the exact value of the f64 θ (checked above against
    // the printed Table 13.2 and the direct A⁻¹BA⁻¹ formula).
    for th in [0.01, 0.3, 0.5, 0.9, 0.99, 0.999] {
        let thq = rational_from_f64(th).unwrap();
        for m in 0..=6usize {
            for form in [EstimateForm::Current, EstimateForm::Predictor] {
                let e = fading_vrf::<Q>(m, thq.clone(), form).unwrap();
                let g = fading_vrf::<f64>(m, th, form).unwrap();
                for i in 0..=m {
                    for j in 0..=m {
                        assert!(
                            rel_err(g[(i, j)], f(&e[(i, j)])) < 1e-12,
                            "θ = {th}, m = {m}, {form:?}, ({i},{j})"
                        );
                    }
                }
            }
        }
    }
}

/// Table 13.3 as printed (λ_ii(m), rows i, columns m = i..10).
const TABLE_13_3: [&[&str]; 11] = [
    &[
        "0.5000", "1.2500", "2.0625", "2.90625", "3.76953", "4.64648", "5.53369", "6.42896",
        "7.33076", "8.23803", "9.14993",
    ],
    &[
        "0.2500", "1.7500", "5.78125", "13.7500", "27.1387", "47.4824", "76.3557", "115.364",
        "166.137", "230.326",
    ],
    &[
        "0.1875", "2.53125", "13.7812", "49.0547", "135.751", "317.692", "659.416", "1250.61",
        "2210.64",
    ],
    &[
        "0.15625", "3.43750", "27.7734", "137.695", "506.964", "1524.64", "3957.72", "9184.07",
    ],
    &[
        "0.136719", "4.44336", "49.8169", "327.570", "1545.73", "5800.32", "18385.9",
    ],
    &[
        "0.123047", "5.53711", "82.1799", "691.431", "4065.13", "18603.0",
    ],
    &["0.112793", "6.71118", "127.315", "1333.35", "9551.90"],
    &["0.104736", "7.95996", "187.845", "2395.69"],
    &["0.0981903", "9.27898", "266.550"],
    &["0.0927353", "10.6646"],
    &["0.0880985"],
];

#[test]
fn fading_vrf_limit_table_13_3() {
    // Source: Morrison Table 13.3 (reconstructed via Ex 13.15d), exact
    // columns m <= 4, Ex 13.15e/13.16 full λ for m = 2, computed m = 3, Reyneke c_F
    // (§7.2); Morrison p. 528 position VRFs 0.5, 1.25, 2.06, 2.9 (×(1-θ)).
    for m in 0..=10usize {
        let l = fading_vrf_limit(m);
        for i in 0..=m {
            assert_printed(
                f(&l[(i, i)]),
                TABLE_13_3[i][m - i],
                &format!("Table 13.3 ({i},{m})"),
            );
        }
    }
    let exact: [&[&str]; 5] = [
        &["1/2"],
        &["5/4", "1/4"],
        &["33/16", "7/4", "3/16"],
        &["93/32", "185/32", "81/32", "5/32"],
        &["965/256", "55/4", "441/32", "55/16", "35/256"],
    ];
    for (m, col) in exact.iter().enumerate() {
        let l = fading_vrf_limit(m);
        for (i, s) in col.iter().enumerate() {
            assert_eq!(l[(i, i)], q(s), "Table 13.3 exact ({i},{m})");
        }
    }
    let k2 = [
        ["33/16", "27/16", "1/2"],
        ["27/16", "7/4", "9/16"],
        ["1/2", "9/16", "3/16"],
    ];
    let l2 = fading_vrf_limit(2);
    for i in 0..3 {
        for j in 0..3 {
            assert_eq!(l2[(i, j)], q(k2[i][j]), "Ex 13.15e ({i},{j})");
        }
    }
    let k3 = [
        ["93/32", "29/8", "69/32", "1/2"],
        ["29/8", "185/32", "15/4", "29/32"],
        ["69/32", "15/4", "81/32", "5/8"],
        ["1/2", "29/32", "5/8", "5/32"],
    ];
    let l3 = fading_vrf_limit(3);
    for i in 0..4 {
        for j in 0..4 {
            assert_eq!(l3[(i, j)], q(k3[i][j]), "λ(3) ({i},{j})");
        }
    }
    for (m, s) in ["1/2", "5/4", "33/16", "93/32", "965/256", "2379/512"]
        .iter()
        .enumerate()
    {
        assert_eq!(fading_vrf_limit(m)[(0, 0)], q(s), "Reyneke c_F, m = {m}");
    }
}

#[test]
fn fading_vrf_approaches_table_13_3_near_theta_one() {
    // Source: Morrison (13.6.36)-(13.6.37): [S_X]_ij ≈ λ_ij (1-θ)^(i+j+1)/τ^(i+j) as θ -> 1;
    // checked at θ = 1 - 10^-6 exactly, relative 1e-4, against the printed Table 13.3 diagonal
    // (6 s.f.) and the library's exact λ for the full matrix.
    let th = q("0.999999");
    let om = z(1) - th.clone();
    for m in 0..=10usize {
        let s = fading_vrf::<Q>(m, th.clone(), EstimateForm::Predictor).unwrap();
        let lam = fading_vrf_limit(m);
        for i in 0..=m {
            for j in 0..=m {
                let v = s[(i, j)].clone() * fact(i) * fact(j) / qpow(&om, i + j + 1);
                // Exact relative comparison (converting these large rationals to f64 is slow).
                let close = |w: &Q| (v.clone() - w.clone()).abs() < w.abs() * fr(1, 10_000);
                assert!(
                    close(&lam[(i, j)]),
                    "limit m = {m} ({i},{j}): {} vs {}",
                    f(&v),
                    f(&lam[(i, j)])
                );
                if i == j {
                    assert!(
                        close(&q(TABLE_13_3[i][m - i])),
                        "vs printed Table 13.3 ({i},{m})"
                    );
                }
            }
        }
    }
}

#[test]
fn fading_vrf_equals_lyapunov_iteration_13_6_41() {
    // Source: Morrison (13.6.41)-(13.6.51), Ex 13.19, method (a):
    // J <- B J Bᵀ + G Gᵀ, B = Φ(1)(I - H M), G = Φ(1) H, M = e0ᵀ, from J = 0, converges to the
    // 1-step-predictor VRF. Gains from the printed Table 13.1 / Reyneke §6.6 (transcribed here).
    for (thf, thq) in [(0.5, fr(1, 2)), (0.9, fr(9, 10))] {
        for m in 0..=5usize {
            let h: Vec<f64> = fmp_book(m, &thq).iter().map(f).collect();
            let n = m + 1;
            let phi1 = DMatrix::from_fn(n, n, |i, j| if j < i { 0.0 } else { f(&c(j, i)) });
            let mut ihm = DMatrix::<f64>::identity(n, n);
            for i in 0..n {
                ihm[(i, 0)] -= h[i];
            }
            let b = &phi1 * ihm;
            let g = &phi1 * DMatrix::from_column_slice(n, 1, &h);
            let ggt = &g * g.transpose();
            let mut j = DMatrix::<f64>::zeros(n, n);
            for _ in 0..4000 {
                j = &b * &j * b.transpose() + &ggt;
            }
            let s = fading_vrf::<f64>(m, thf, EstimateForm::Predictor).unwrap();
            for a in 0..n {
                for bb in 0..n {
                    let scale = (s[(a, a)] * s[(bb, bb)]).sqrt();
                    assert!(
                        (j[(a, bb)] - s[(a, bb)]).abs() <= 1e-11 * scale,
                        "Lyapunov θ = {thf}, m = {m}, ({a},{bb}): {} vs {}",
                        j[(a, bb)],
                        s[(a, bb)]
                    );
                }
            }
        }
    }
    // Ex 13.17/13.18 impulse response, m = 0: x_n = θ^(n-1)(1-θ), Σ x_n² = (1-θ)/(1+θ).
    let th = 0.9;
    let g = fading_gains::<f64>(0, th, GainForm::Current)[0];
    let (mut zst, mut sum) = (0.0, 0.0);
    for n in 0..2000 {
        let y = if n == 0 { 1.0 } else { 0.0 };
        zst += g * (y - zst); // Z_{n+1,n}
        sum += zst * zst;
    }
    assert!(
        (sum - fading_vrf::<f64>(0, th, EstimateForm::Predictor).unwrap()[(0, 0)]).abs() < 1e-14
    );
}

#[test]
fn fading_memory_vrf_matches_monte_carlo() {
    // Morrison (13.6.20), Tables 13.2: steady-state fading-memory VRF at θ = 0.8, current and
    // 1-step prediction, after the start-up has decayed (θ^n n^m < 1e-12 at n = 250, m ≤ 4).
    let mut r = common::rng(20_001);
    let theta = 0.8;
    let n = 250;
    for m in 0..=4 {
        for engine in [Engine::Gain, Engine::Exact] {
            simulate_and_check(
                &mut r,
                || Box::new(FadingMemory::new(m, theta, 1.0, engine).unwrap()),
                n,
                &fading_vrf(m, theta, EstimateForm::Current).unwrap(),
                &fading_vrf(m, theta, EstimateForm::Predictor).unwrap(),
                &format!("fading {engine:?} m={m}"),
            );
        }
    }
}
