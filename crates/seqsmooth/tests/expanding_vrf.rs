//! Expanding-memory variance-reduction matrices (`seqsmooth::polynomial::expanding::vrf`, Morrison (1969)
//! ch. 9) against the printed Table 9.2, the m = 1 matrix (9.7.5), direct least squares and the
//! cross-checks with Lear (1977) and Reyneke et al. (2012) §7.2, in exact rationals.

mod common;

use common::book::*;
use common::monte_carlo::*;
use common::rational::*;
use nalgebra::DMatrix;
use seqsmooth::polynomial::expanding::gains::expanding_gains;
use seqsmooth::polynomial::expanding::vrf::expanding_vrf;
use seqsmooth::polynomial::fixed::window_covariance;
use seqsmooth::polynomial::form::GainForm;
use seqsmooth::polynomial::form::{unscale, EstimateForm};
use seqsmooth::{Engine, ExpandingMemory};

/// Morrison Table 9.2 (m = 0..3) and the derived m = 4 row: diagonal of
/// the unscaled 1-step-predictor VRF, τ = 1.
fn table_9_2(m: usize, n: &Q) -> Vec<Q> {
    let p = |cs: &[i64]| poly(cs, n);
    let d = |top: i64, k: usize| ff(&(n.clone() + z(top)), k);
    match m {
        0 => vec![z(1) / (n.clone() + z(1))],
        1 => vec![z(2) * p(&[3, 2]) / d(1, 2), z(12) / d(2, 3)],
        2 => vec![
            p(&[24, 27, 9]) / d(1, 3),
            p(&[684, 744, 192]) / d(3, 5),
            z(720) / d(3, 5),
        ],
        3 => vec![
            p(&[120, 152, 72, 16]) / d(1, 4),
            p(&[23200, 43800, 31800, 10200, 1200]) / d(4, 7),
            p(&[95040, 102240, 25920]) / d(4, 7),
            z(100800) / d(4, 7),
        ],
        4 => vec![
            z(5) * p(&[144, 210, 115, 30, 5]) / d(1, 5),
            z(100) * p(&[3, 2]) * p(&[3172, 5198, 3777, 1476, 297, 24]) / d(5, 9),
            z(35280) * p(&[185, 336, 239, 76, 9]) / d(5, 9),
            z(100800) * p(&[3, 2]) * p(&[79, 32]) / d(5, 9),
            z(25401600) / d(5, 9),
        ],
        _ => unreachable!(),
    }
}

#[test]
fn expanding_vrf_table_9_2_predictor_diagonal() {
    // Source: Morrison Table 9.2 (m = 0..3, book), m = 4 derived;
    // unscaled diagonal = (i!)² × scaled diagonal for τ = 1.
    for m in 0..=4usize {
        for n in m as u64..=40 {
            let s = expanding_vrf::<Q>(m, n, EstimateForm::Predictor).unwrap();
            let want = table_9_2(m, &z(n as i64));
            for i in 0..=m {
                assert_eq!(
                    s[(i, i)].clone() * fact(i) * fact(i),
                    want[i],
                    "Table 9.2 m = {m}, n = {n}, i = {i}"
                );
            }
        }
        if m > 0 {
            assert!(expanding_vrf::<Q>(m, m as u64 - 1, EstimateForm::Predictor).is_err());
        }
    }
}

#[test]
fn expanding_vrf_m1_matrix_9_7_5_and_t9_08() {
    // Source: Morrison (9.7.5)/(9.7.8) (τ = 1, scaled = unscaled for m = 1), T9-08.
    for n in 1..=40i64 {
        let s = expanding_vrf::<Q>(1, n as u64, EstimateForm::Predictor).unwrap();
        let nn = z(n);
        let want = [
            [
                z(2) * (z(2) * nn.clone() + z(3)) / ((nn.clone() + z(1)) * nn.clone()),
                z(6) / ((nn.clone() + z(1)) * nn.clone()),
            ],
            [
                z(6) / ((nn.clone() + z(1)) * nn.clone()),
                z(12) / ((nn.clone() + z(2)) * (nn.clone() + z(1)) * nn.clone()),
            ],
        ];
        for i in 0..2 {
            for j in 0..2 {
                assert_eq!(s[(i, j)], want[i][j], "(9.7.5) n = {n}");
            }
        }
    }
    let t908 = expanding_vrf::<Q>(1, 1, EstimateForm::Predictor).unwrap();
    assert_eq!(
        t908,
        DMatrix::from_row_slice(2, 2, &[z(5), z(3), z(3), z(2)])
    );
    let s22 = expanding_vrf::<Q>(2, 2, EstimateForm::Predictor).unwrap();
    assert_eq!(s22[(0, 0)], z(19), "T9-08 m = 2, n = 2");
    // Unscaled with τ: (9.7.8) entries /τ, /τ².
    let s = unscale(
        &expanding_vrf::<f64>(1, 5, EstimateForm::Predictor).unwrap(),
        0.5,
    );
    assert!((s[(0, 1)] - 2.0 * 6.0 / 30.0).abs() < 1e-15);
    assert!((s[(1, 1)] - 4.0 * 12.0 / 210.0).abs() < 1e-15);
}

#[test]
fn window_covariance_equals_direct_least_squares() {
    // Oracle: exact LS covariance Φ(h) (TᵀT)⁻¹ Φ(h)ᵀ solved here (Morrison (6.6.33), (7.5.4));
    // the library uses the orthogonal-polynomial route (7.4.16).
    for m in 0..=6usize {
        for l in m as u64..=(m as u64 + 18) {
            let s0 = inv(&ls_normal_matrix(m, l));
            for h in [z(0), z(1), fr(-(l as i64), 2), fr(5, 2), z(-(l as i64))] {
                let p = pascal(m, &h);
                let want = mm(&mm(&p, &s0), &p.transpose());
                assert_eq!(
                    window_covariance::<Q>(m, l, h.clone()),
                    want,
                    "m = {m}, L = {l}, h = {h}"
                );
            }
            let cur = expanding_vrf::<Q>(m, l, EstimateForm::Current).unwrap();
            assert_eq!(cur, s0);
        }
    }
    // Ex 7.21 (derived): L = 4, m = 2: [S]_00(h) = (5h⁴+40h³+107h²+108h+62)/70.
    for h in [z(0), z(1), z(-2), z(6), z(-10), fr(1, 3)] {
        let s = window_covariance::<Q>(2, 4, h.clone());
        assert_eq!(s[(0, 0)], poly(&[62, 108, 107, 40, 5], &h) / z(70));
    }
}

#[test]
fn expanding_current_vrf_cross_checks_lear_and_reyneke() {
    // Source: Lear (1977) and Reyneke et al. §7.2 (Lear end-point variance = EMP position gain; Reyneke
    // current-estimate derivative VRFs and one-step predictor position VRFs, Phi-normalised).
    for m in 0..=6usize {
        for n in m as u64..=40 {
            let s = expanding_vrf::<Q>(m, n, EstimateForm::Current).unwrap();
            let h = expanding_gains::<Q>(m, n, GainForm::Current);
            assert_eq!(s[(0, 0)], h[0], "position VRF = h_0(n), m = {m}, n = {n}");
        }
    }
    for n in 5..=40i64 {
        let nq = z(n);
        let ni = |k: i64| nq.clone() + z(k);
        let cur = |m: usize| expanding_vrf::<Q>(m, n as u64, EstimateForm::Current).unwrap();
        let pred = |m: usize| expanding_vrf::<Q>(m, n as u64, EstimateForm::Predictor).unwrap();
        // Current, derivatives.
        assert_eq!(cur(1)[(1, 1)], z(12) / (nq.clone() * ni(1) * ni(2)));
        let d2 = nq.clone() * ni(-1) * ni(1) * ni(2) * ni(3);
        assert_eq!(
            cur(2)[(1, 1)],
            z(12) * poly(&[1, 2], &nq) * poly(&[-3, 8], &nq) / d2.clone()
        );
        assert_eq!(cur(2)[(2, 2)], z(180) / d2);
        let d3 = nq.clone() * ni(-1) * ni(-2) * ni(1) * ni(2) * ni(3) * ni(4);
        assert_eq!(
            cur(3)[(1, 1)],
            z(200) * poly(&[2, -3, -3, -3, 6], &nq) / d3.clone()
        );
        assert_eq!(
            cur(3)[(2, 2)],
            z(360) * poly(&[1, 2], &nq) * poly(&[-4, 9], &nq) / d3.clone()
        );
        assert_eq!(cur(3)[(3, 3)], z(2800) / d3);
        // One-step predictor, position.
        let p = |cs: &[i64]| poly(cs, &nq);
        assert_eq!(pred(1)[(0, 0)], z(2) * p(&[3, 2]) / (nq.clone() * ni(1)));
        assert_eq!(
            pred(2)[(0, 0)],
            z(3) * p(&[8, 9, 3]) / (nq.clone() * ni(-1) * ni(1))
        );
        assert_eq!(
            pred(3)[(0, 0)],
            z(8) * p(&[3, 2]) * p(&[5, 3, 1]) / (nq.clone() * ni(-1) * ni(-2) * ni(1))
        );
        assert_eq!(
            pred(4)[(0, 0)],
            z(5) * p(&[144, 210, 115, 30, 5]) / (nq.clone() * ni(-1) * ni(-2) * ni(-3) * ni(1))
        );
        assert_eq!(
            pred(5)[(0, 0)],
            z(6) * p(&[3, 2]) * p(&[280, 258, 113, 18, 3])
                / (nq.clone() * ni(-1) * ni(-2) * ni(-3) * ni(-4) * ni(1))
        );
    }
}

#[test]
fn expanding_memory_vrf_matches_monte_carlo() {
    // Morrison §9.7 / Table 9.2: the expanding-memory VRF at n (0-based index of the newest
    // sample), current estimate and 1-step prediction; both engines (the same estimator on
    // even samples) at two sample counts.
    let mut r = common::rng(20_000);
    for m in 0..=4 {
        for (engine, n) in [(Engine::Gain, m + 3), (Engine::Exact, 25)] {
            simulate_and_check(
                &mut r,
                || Box::new(ExpandingMemory::new(m, engine).unwrap()),
                n,
                &expanding_vrf(m, n as u64, EstimateForm::Current).unwrap(),
                &expanding_vrf(m, n as u64, EstimateForm::Predictor).unwrap(),
                &format!("expanding {engine:?} m={m} n={n}"),
            );
        }
    }
}
