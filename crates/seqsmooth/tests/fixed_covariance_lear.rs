//! Lear (1977), "Least squares polynomial fits and their accuracy" (NASA JSC / TRW), reproduced
//! through the fixed-memory filter of `seqsmooth::polynomial::fixed`.
//!
//! Source: Lear (1977), closed forms eqs 18-51 and Tables 1-3, with reconstructions where the
//! scan is unreadable and one apparent error in the paper (below).
//!
//! Lear fits `y = a_0 + a_1 n + … + a_M n^M` to `N` evenly spaced samples `n = 1..N`. That is
//! the fixed-memory fit with `L = N - 1`: sample `n` sits at `r = n - 1` on Morrison's window
//! axis, i.e. at the lead `h = n - N` from the newest sample; the coefficients `a_k` are the
//! Taylor coefficients at `n = 0` (`h = -N`), so `(PᵀP)⁻¹ = W(-N) W(-N)ᵀ` (unit step), and the
//! variance of the fit at `n` is `σ² [W(h) W(h)ᵀ]_00` — for derivatives, unscaled with
//! `τ = ΔT`. All comparisons with closed forms are exact (`BigRational`).
//!
//! Lear's misprints and their reconstructions, cited where they matter below:
//! - the preface corrects eq 13's `n²` coefficient from `C22 + 2C12` to `C22 + 2C13`;
//! - eq 28 `(PᵀP)⁻¹` of Table 3: the OCR reads "94" and "1301" (exact: 4290 scale, 5174, 130);
//! - A33 of eq 39: the OCR reads "(2K,-1)", the factor is `(2N+1)`;
//! - eq 42: OCR "RN3-3N2+7N-3" = `2N³-3N²+7N-3`; eq 44: the OCR's last denominator factor
//!   `(N²-1)` is `(N²-9)` (denominator D3);
//! - S8 (power sums, p. 5): OCR "15N6" is `15N⁵` (not used here: no power sums are formed);
//! - Table 2 (midpoint, large N) is unreadable in the OCR and was rebuilt from eqs 25, 31, 34,
//!   43, 46, 49, 50;
//! - Table 3: `Pᵀy*` first entry OCR "61.500" is 61.600 (the data sum to 61.600; only it gives
//!   a0 = 1.3083); ŷ_5 OCR "3.763" is 3.768; residual 9 OCR "1.08" is 1.108;
//! - an apparent error: the noise estimate `√(Σr²/N)` = 0.9115 is biased; the unbiased
//!   `√(Σr²/(N-M-1))` = 1.0689.

mod common;

use common::rational::*;
use nalgebra::DMatrix;
use num_traits::{One, Zero};
use seqsmooth::polynomial::expanding::gains::expanding_gains;
use seqsmooth::polynomial::fixed::{
    covariance, covariance_unscaled, smooth, vrf_limit, weights, Design, Lead,
};
use seqsmooth::polynomial::form::GainForm;

/// Σ c_k x^k, integer coefficients lowest first.
fn poly(x: &Q, c: &[i64]) -> Q {
    c.iter().rev().fold(Q::zero(), |a, v| a * x.clone() + z(*v))
}

fn sym(rows: &[&[Q]]) -> DMatrix<Q> {
    DMatrix::from_fn(rows.len(), rows.len(), |i, j| {
        rows[i.min(j)][i.max(j) - i.min(j)].clone()
    })
}

/// Lear's (PᵀP)⁻¹ for M = 0..3 (eqs 18, 21, 28, 39), upper triangle row by row.
fn lear_inverse(m: usize, n: &Q) -> DMatrix<Q> {
    let p = |c: &[i64]| poly(n, c);
    let (n1, n2, n3) = (n.clone() + z(1), n.clone() + z(2), n.clone() + z(3));
    let d1 = n.clone() * (n.clone() * n.clone() - z(1));
    let d2 = d1.clone() * (n.clone() * n.clone() - z(4));
    let d3 = d2.clone() * (n.clone() * n.clone() - z(9));
    match m {
        0 => sym(&[&[Q::one() / n.clone()]]),
        1 => {
            let s = z(2) / d1;
            sym(&[
                &[s.clone() * n1.clone() * p(&[1, 2]), s.clone() * z(-3) * n1],
                &[s * z(6)],
            ])
        }
        2 => {
            let s = z(3) / d2;
            let a = n1.clone() * n2.clone();
            sym(&[
                &[
                    s.clone() * a.clone() * p(&[2, 3, 3]),
                    s.clone() * z(-6) * a.clone() * p(&[1, 2]),
                    s.clone() * z(10) * a,
                ],
                &[
                    s.clone() * z(4) * p(&[1, 2]) * p(&[11, 8]),
                    s.clone() * z(-60) * n1,
                ],
                &[s * z(60)],
            ])
        }
        3 => {
            let s = Q::one() / d3;
            let a = n1.clone() * n2 * n3;
            sym(&[
                &[
                    s.clone() * z(8) * a.clone() * p(&[1, 2]) * p(&[3, 1, 1]),
                    s.clone() * z(-20) * a.clone() * p(&[5, 6, 6]),
                    s.clone() * z(120) * a.clone() * p(&[1, 2]),
                    s.clone() * z(-140) * a,
                ],
                &[
                    s.clone() * z(200) * p(&[11, 30, 42, 27, 6]),
                    s.clone() * z(-300) * n1.clone() * p(&[2, 3]) * p(&[5, 3]),
                    s.clone() * z(280) * p(&[11, 15, 6]),
                ],
                // A33 = 360(2N+1)(9N+13): the OCR's "(2K,-1)" read as (2N+1).
                &[
                    s.clone() * z(360) * p(&[1, 2]) * p(&[13, 9]),
                    s.clone() * z(-4200) * n1,
                ],
                &[s * z(2800)],
            ])
        }
        _ => unreachable!(),
    }
}

#[test]
fn lear_inverse_normal_matrices_eqs_18_21_28_39() {
    // (PᵀP)⁻¹ is the covariance of the Taylor coefficients at n = 0, i.e. W(-N) W(-N)ᵀ.
    for m in 0..=3usize {
        for n in [m as i64 + 1, m as i64 + 2, 7, 11, 30, 101] {
            let got = covariance(m, (n - 1) as u64, z(-n)).unwrap();
            assert_eq!(got, lear_inverse(m, &z(n)), "M = {m}, N = {n}");
        }
    }
}

#[test]
fn lear_variance_profiles_eqs_13_22_29_41() {
    // E(n)/σ² at any n (interior, ends, extrapolated, fractional) = [W(n-N) W(n-N)ᵀ]_00.
    for m in 0..=3usize {
        for n_samples in [m as i64 + 2, 9, 11, 40] {
            let nq = z(n_samples);
            let l = (n_samples - 1) as u64;
            let c = lear_inverse(m, &nq);
            let d1 = nq.clone() * (nq.clone() * nq.clone() - z(1));
            let d2 = d1.clone() * (nq.clone() * nq.clone() - z(4));
            let d3 = d2.clone() * (nq.clone() * nq.clone() - z(9));
            let mut points: Vec<Q> = (0..=n_samples + 1).map(z).collect();
            points.extend([fr(1, 3), fr(2 * n_samples + 1, 4), fr(n_samples + 1, 2)]);
            for n in points {
                let s = covariance(m, l, n.clone() - nq.clone()).unwrap()[(0, 0)].clone();
                // v(n)ᵀ C v(n) with v = (1, n, …, n^M) (eq 13 in general).
                let v: Vec<Q> = (0..=m)
                    .map(|k| (0..k).fold(Q::one(), |a, _| a * n.clone()))
                    .collect();
                let quad = (0..=m).fold(Q::zero(), |a, i| {
                    (0..=m).fold(a, |a, j| {
                        a + v[i].clone() * c[(i, j)].clone() * v[j].clone()
                    })
                });
                assert_eq!(s, quad, "M = {m}, N = {n_samples}, n = {n}");
                let e = match m {
                    0 => Q::one() / nq.clone(),
                    // eq 22
                    1 => {
                        z(2) / d1.clone()
                            * ((nq.clone() + z(1)) * poly(&nq, &[1, 2])
                                - z(6) * (nq.clone() + z(1)) * n.clone()
                                + z(6) * n.clone() * n.clone())
                    }
                    // eq 29
                    2 => {
                        let a = (nq.clone() + z(1)) * (nq.clone() + z(2));
                        z(3) / d2.clone()
                            * (a.clone() * poly(&nq, &[2, 3, 3])
                                - z(12) * a * poly(&nq, &[1, 2]) * n.clone()
                                + z(12) * poly(&nq, &[7, 15, 7]) * n.clone() * n.clone()
                                - z(120) * (nq.clone() + z(1)) * n.clone() * n.clone() * n.clone()
                                + z(60) * n.clone() * n.clone() * n.clone() * n.clone())
                    }
                    // eq 41
                    _ => {
                        let a = (nq.clone() + z(1)) * (nq.clone() + z(2)) * (nq.clone() + z(3));
                        let pw = |k: usize| (0..k).fold(Q::one(), |x, _| x * n.clone());
                        z(8) / d3.clone()
                            * (a.clone() * poly(&nq, &[1, 2]) * poly(&nq, &[3, 1, 1])
                                - z(5) * a * poly(&nq, &[5, 6, 6]) * pw(1)
                                + z(5) * poly(&nq, &[91, 288, 378, 213, 42]) * pw(2)
                                - z(10) * (nq.clone() + z(1)) * poly(&nq, &[96, 175, 71]) * pw(3)
                                + z(5) * poly(&nq, &[271, 525, 246]) * pw(4)
                                - z(1050) * (nq.clone() + z(1)) * pw(5)
                                + z(350) * pw(6))
                    }
                };
                assert_eq!(s, e, "closed form, M = {m}, N = {n_samples}, n = {n}");
            }
            // Eq 13 for M = 2 with the preface's correction: the n² coefficient is C22 + 2C13
            // (as printed, C22 + 2C12, it fails).
            if m == 2 {
                let n = z(3);
                let at = |c13_or_c12: &Q| {
                    c[(0, 0)].clone()
                        + z(2) * c[(0, 1)].clone() * n.clone()
                        + (c[(1, 1)].clone() + z(2) * c13_or_c12.clone()) * n.clone() * n.clone()
                        + z(2) * c[(1, 2)].clone() * n.clone() * n.clone() * n.clone()
                        + c[(2, 2)].clone() * n.clone() * n.clone() * n.clone() * n.clone()
                };
                let s = covariance(2, l, n.clone() - nq.clone()).unwrap()[(0, 0)].clone();
                assert_eq!(at(&c[(0, 2)]), s);
                assert_ne!(at(&c[(0, 1)]), s);
            }
        }
    }
}

#[test]
fn lear_end_midpoint_and_derivative_variances_eqs_24_to_50() {
    // Ends n = 1 and N, midpoint (N+1)/2; derivatives unscaled with τ = ΔT (checked at
    // ΔT = 1 and 3/2: Var(y^(d)) ∝ 1/ΔT^(2d), eqs 14-17).
    for dt in [z(1), fr(3, 2)] {
        let dt2 = dt.clone() * dt.clone();
        for n in [5i64, 6, 11, 20, 57] {
            let nq = z(n);
            let l = (n - 1) as u64;
            let d1 = nq.clone() * (nq.clone() * nq.clone() - z(1));
            let d2 = d1.clone() * (nq.clone() * nq.clone() - z(4));
            let d3 = d2.clone() * (nq.clone() * nq.clone() - z(9));
            let (n1, n2, n3) = (nq.clone() + z(1), nq.clone() + z(2), nq.clone() + z(3));
            let s =
                |m: usize, at: Q| covariance_unscaled(m, l, at - nq.clone(), dt.clone()).unwrap();
            let mid = fr(n + 1, 2);
            for end in [z(1), nq.clone()] {
                // M = 1: eq 24 ends, eq 26 velocity.
                assert_eq!(
                    s(1, end.clone())[(0, 0)],
                    z(2) * (z(2) * nq.clone() - z(1)) / (nq.clone() * n1.clone())
                );
                // M = 2: eq 30 ends, eq 33 velocity at the ends, eq 35 acceleration.
                let s2 = s(2, end.clone());
                assert_eq!(
                    s2[(0, 0)],
                    z(3) * poly(&nq, &[2, -3, 3]) / (nq.clone() * n1.clone() * n2.clone())
                );
                assert_eq!(
                    s2[(1, 1)],
                    z(12) * poly(&nq, &[11, -30, 16]) / (dt2.clone() * d2.clone())
                );
                assert_eq!(
                    s2[(2, 2)],
                    z(720) / (dt2.clone() * dt2.clone() * d2.clone())
                );
                // M = 3: eq 42 ends ("RN3" = 2N³), eq 45 velocity, eq 48 acceleration, eq 50 jerk.
                let s3 = s(3, end.clone());
                assert_eq!(
                    s3[(0, 0)],
                    z(8) * poly(&nq, &[-3, 7, -3, 2])
                        / (nq.clone() * n1.clone() * n2.clone() * n3.clone())
                );
                assert_eq!(
                    s3[(1, 1)],
                    z(200) * poly(&nq, &[11, -30, 42, -27, 6]) / (dt2.clone() * d3.clone())
                );
                assert_eq!(
                    s3[(2, 2)],
                    z(1440) * poly(&nq, &[-1, 2]) * poly(&nq, &[-13, 9])
                        / (dt2.clone() * dt2.clone() * d3.clone())
                );
                assert_eq!(
                    s3[(3, 3)],
                    z(100800) / (dt2.clone() * dt2.clone() * dt2.clone() * d3.clone())
                );
            }
            // Midpoints: eq 25, eq 31 (= eq 43 for M = 3), eq 34 (= eq 26), eq 46, eq 49.
            assert_eq!(s(0, mid.clone())[(0, 0)], Q::one() / nq.clone());
            assert_eq!(s(1, mid.clone())[(0, 0)], Q::one() / nq.clone());
            let pos_mid = z(3) * poly(&nq, &[-7, 0, 3])
                / (z(4) * nq.clone() * (nq.clone() * nq.clone() - z(4)));
            assert_eq!(s(2, mid.clone())[(0, 0)], pos_mid);
            assert_eq!(s(3, mid.clone())[(0, 0)], pos_mid);
            let vel1 = z(12) / (dt2.clone() * d1.clone());
            assert_eq!(s(1, z(3))[(1, 1)], vel1); // eq 26: the same at every n
            assert_eq!(s(2, mid.clone())[(1, 1)], vel1);
            assert_eq!(
                s(3, mid.clone())[(1, 1)],
                z(25) * poly(&nq, &[31, 0, -18, 0, 3]) / (dt2.clone() * d3.clone())
            );
            assert_eq!(
                s(3, mid.clone())[(2, 2)],
                z(720) / (dt2.clone() * dt2.clone() * d2.clone())
            );
            // General n: eq 32 (M = 2 velocity), eq 44 (M = 3 velocity, denominator D3 — the OCR
            // shows (N²-1)), eq 47 (M = 3 acceleration).
            for at in [z(2), fr(7, 3), z(n + 3)] {
                let a = at.clone();
                let a2 = a.clone() * a.clone();
                assert_eq!(
                    s(2, a.clone())[(1, 1)],
                    z(12) / (dt2.clone() * d2.clone())
                        * (poly(&nq, &[1, 2]) * poly(&nq, &[11, 8])
                            - z(60) * n1.clone() * a.clone()
                            + z(60) * a2.clone())
                );
                assert_eq!(
                    s(3, a.clone())[(1, 1)],
                    z(40) / (dt2.clone() * d3.clone())
                        * (z(5) * poly(&nq, &[11, 30, 42, 27, 6])
                            - z(30)
                                * n1.clone()
                                * poly(&nq, &[2, 3])
                                * poly(&nq, &[5, 3])
                                * a.clone()
                            + z(6) * poly(&nq, &[155, 315, 150]) * a2.clone()
                            - z(1260) * n1.clone() * a2.clone() * a.clone()
                            + z(630) * a2.clone() * a2.clone())
                );
                assert_eq!(
                    s(3, a.clone())[(2, 2)],
                    z(1440) / (dt2.clone() * dt2.clone() * d3.clone())
                        * (poly(&nq, &[1, 2]) * poly(&nq, &[13, 9])
                            - z(70) * n1.clone() * a.clone()
                            + z(70) * a2)
                );
            }
        }
    }
    // Cross-identity between Lear (1977) and Morrison ch. 9: Lear's end-point variance with N = n+1 is the
    // expanding-memory position gain h_0(n) (the current-estimate VRF).
    for m in 0..=3usize {
        for n in [m as u64 + 1, 10, 33] {
            let alpha = expanding_gains::<Q>(m, n, GainForm::Current)[0].clone();
            assert_eq!(
                covariance(m, n, z(0)).unwrap()[(0, 0)],
                alpha,
                "M = {m}, n = {n}"
            );
        }
    }
}

#[test]
fn lear_large_n_tables_1_and_2_and_profiles_eqs_36_to_38_51() {
    // Tables 1 (ends) and 2 (midpoint, rebuilt from eqs 25, 31, 34, 43, 46, 49, 50):
    // Var ≈ c σ²/(T^(2d) N) with T = N ΔT, i.e. Morrison's λ_dd(M) at ρ = 1 and ρ = 1/2.
    let table1: [&[i64]; 4] = [&[1], &[4, 12], &[9, 192, 720], &[16, 1200, 25920, 100800]];
    let table2: [&[&str]; 4] = [
        &["1"],
        &["1", "12"],
        &["9/4", "12", "720"],
        &["9/4", "75", "720", "100800"],
    ];
    for m in 0..=3usize {
        let end = vrf_limit(m, z(1)).unwrap();
        let mid = vrf_limit(m, fr(1, 2)).unwrap();
        for d in 0..=m {
            assert_eq!(
                end[(d, d)],
                z(table1[m][d]),
                "Table 1, M = {m}, derivative {d}"
            );
            assert_eq!(
                mid[(d, d)],
                q(table2[m][d]),
                "Table 2, M = {m}, derivative {d}"
            );
        }
        // Eq 51: end-point position (M+1)².
        assert_eq!(end[(0, 0)], z(((m + 1) * (m + 1)) as i64));
        // The exact variances converge to the tables: N·T^(2d)·Var at N = 10⁵ (ΔT = 1),
        // relative difference ≤ 1e-3 (it is O(M²/N)).
        let n = 100_000i64;
        for (h, table) in [(0.0, &end), (-((n - 1) as f64) / 2.0, &mid)] {
            let s = covariance_unscaled(m, (n - 1) as u64, h, 1.0).unwrap();
            for d in 0..=m {
                let got = s[(d, d)] * (n as f64).powi(2 * d as i32 + 1);
                let want = f(&table[(d, d)]);
                assert!(
                    ((got - want) / want).abs() < 1e-3,
                    "M = {m}, d = {d}: {got} vs {want}"
                );
            }
        }
    }
    // Eq 36: M = 2, N·E ≈ 9[20x⁴ - 2x² + 1/4], x = n/N - 1/2: the midpoint is a local MAXIMUM
    // 9/4 (eq 37) and the minima 9/5 lie at x² = 1/20 (eq 38). M = 3: N·E ≈ 2800u⁶ - 660u⁴ +
    // 45u² + 9/4: a local minimum 9/4 at the midpoint, maxima 3.2 at u = ±√5/10, minima 2.939 at
    // u = ±√21/14 (the large-N profile of Lear eq 41).
    for k in -8..=8i64 {
        let x = fr(k, 16);
        let x2 = x.clone() * x.clone();
        let rho = x.clone() + fr(1, 2);
        let e2 = z(9) * (z(20) * x2.clone() * x2.clone() - z(2) * x2.clone() + fr(1, 4));
        assert_eq!(vrf_limit(2, rho.clone()).unwrap()[(0, 0)], e2);
        let e3 = z(2800) * x2.clone() * x2.clone() * x2.clone() - z(660) * x2.clone() * x2.clone()
            + z(45) * x2
            + fr(9, 4);
        assert_eq!(vrf_limit(3, rho).unwrap()[(0, 0)], e3);
    }
    let p2 = |x: f64| vrf_limit(2, 0.5 + x).unwrap()[(0, 0)];
    let p3 = |u: f64| vrf_limit(3, 0.5 + u).unwrap()[(0, 0)];
    let r5 = 5f64.sqrt() / 10.0;
    assert!((p2(r5) - 1.8).abs() < 1e-12 && p2(r5) < p2(r5 + 1e-3) && p2(r5) < p2(r5 - 1e-3));
    assert!(p2(0.0) > p2(1e-3) && (p2(0.0) - 2.25).abs() < 1e-15);
    assert!((p3(r5) - 3.2).abs() < 1e-12 && p3(r5) > p3(r5 + 1e-3) && p3(r5) > p3(r5 - 1e-3));
    let r21 = 21f64.sqrt() / 14.0;
    assert!((p3(r21) - 2.939).abs() < 5e-4 && p3(r21) < p3(r21 + 1e-3) && p3(r21) < p3(r21 - 1e-3));
    assert!(p3(0.0) < p3(1e-3));
}

#[test]
fn lear_table_3_worked_example() {
    // N = 11, y_n = 1 + 0.1 n², σ_q = 1, M = 2; y* = y + q as printed.
    let y_star = [
        "2.503", "1.046", "1.266", "3.297", "2.814", "5.975", "6.685", "6.437", "9.859", "9.218",
        "12.500",
    ];
    let y_hat_printed = [
        "1.465", "1.790", "2.282", "2.941", "3.768", "4.762", "5.924", "7.254", "8.751", "10.415",
        "12.247",
    ];
    let resid_printed = [
        "1.038", "-.744", "-1.016", ".356", "-.954", "1.213", ".761", "-.817", "1.108", "-1.197",
        ".253",
    ];
    let err_printed = [
        ".365", ".390", ".382", ".341", ".268", ".162", ".024", "-.146", "-.349", "-.585", "-.853",
    ];
    let n = 11usize;
    let ys: Vec<Q> = y_star.iter().map(|s| q(s)).collect();
    let y_newest_first = DMatrix::from_fn(n, 1, |k, _| ys[n - 1 - k].clone());
    // Pᵀy* = [61.600, 488.203, 4328.695] (OCR "61.500"; the data sum to 61.600).
    let pty: Vec<Q> = (0..3)
        .map(|k| {
            (1..=n).fold(Q::zero(), |a, i| {
                a + ys[i - 1].clone() * z((i as i64).pow(k))
            })
        })
        .collect();
    assert_eq!(pty, vec![q("61.600"), q("488.203"), q("4328.695")]);
    // (PᵀP)⁻¹ = (1/4290)[[5174, -1794, 130], [-1794, 759, -60], [130, -60, 5]] (the OCR reads
    // "94" and "1301"), exactly the covariance of the coefficients at n = 0.
    let c = covariance(2, 10, z(-11)).unwrap();
    let want = [[5174i64, -1794, 130], [-1794, 759, -60], [130, -60, 5]];
    for i in 0..3 {
        for j in 0..3 {
            assert_eq!(c[(i, j)], fr(want[i][j], 4290));
        }
    }
    // x̂ = (PᵀP)⁻¹ Pᵀy* = W(-N) y*: [1.3083 ± 1.1, 0.0732 ± 0.42, 0.08375 ± 0.034]; exact values
    // 1.308291, 0.073188, 0.083752, sd 1.0982, 0.4206, 0.03414.
    let xhat: Vec<Q> = (0..3)
        .map(|i| {
            (0..n).fold(Q::zero(), |a, k| {
                a + weights(2, 10, z(-11)).unwrap()[(i, k)].clone() * y_newest_first[(k, 0)].clone()
            })
        })
        .collect();
    let from_normal: Vec<Q> = (0..3)
        .map(|i| (0..3).fold(Q::zero(), |a, j| a + c[(i, j)].clone() * pty[j].clone()))
        .collect();
    assert_eq!(xhat, from_normal);
    for (got, want) in xhat.iter().zip([1.308291, 0.073188, 0.083752]) {
        assert!((f(got) - want).abs() < 5e-7, "{} vs {want}", f(got));
    }
    for (i, (sd, printed)) in [(1.0982, "1.1"), (0.4206, ".42"), (0.03414, ".034")]
        .iter()
        .enumerate()
    {
        let s = f(&c[(i, i)]).sqrt();
        assert!(
            (s - sd).abs() < 5e-5
                && (s - printed.parse::<f64>().unwrap()).abs() < 0.05 * s.max(0.1)
        );
    }
    // ŷ_n at every n (W(n - N) y*), residuals y* - ŷ and errors ŷ - y, to the printed 3
    // decimals (reconstructed: ŷ_5 3.768, not the OCR's 3.763; residual 9 1.108, not 1.08).
    let mut resid = Vec::new();
    for i in 1..=n {
        let w = weights(2, 10, z(i as i64 - 11)).unwrap();
        let yh = (0..n).fold(Q::zero(), |a, k| {
            a + w[(0, k)].clone() * y_newest_first[(k, 0)].clone()
        });
        let truth = z(1) + fr(1, 10) * z((i * i) as i64);
        let close = |x: &Q, p: &str| (f(x) - p.parse::<f64>().unwrap()).abs() <= 5e-4 + 1e-12;
        assert!(close(&yh, y_hat_printed[i - 1]), "ŷ_{i} = {}", f(&yh));
        assert!(
            close(&(ys[i - 1].clone() - yh.clone()), resid_printed[i - 1]),
            "residual {i}"
        );
        assert!(
            close(&(yh.clone() - truth), err_printed[i - 1]),
            "error {i}"
        );
        resid.push(ys[i - 1].clone() - yh);
    }
    // The same fitted values from the whole-series smoother (one window covers the series).
    let times: Vec<f64> = (1..=n).map(|i| i as f64).collect();
    let yf: Vec<f64> = ys.iter().map(f).collect();
    let s = smooth(&times, &yf, 2, n).unwrap();
    for i in 0..n {
        assert!((s[i][0] - (yf[i] - f(&resid[i]))).abs() < 1e-12);
    }
    // Σ(y* - ŷ) is printed as .001 (rounding of the printed residuals); exactly 0.
    assert!(resid.iter().fold(Q::zero(), |a, r| a + r.clone()).is_zero());
    // σ̂_q = √(Σr²/N) = 0.9115 ("off by 9%"); the unbiased √(Σr²/(N-M-1)) = 1.0689.
    let ss = f(&resid
        .iter()
        .fold(Q::zero(), |a, r| a + r.clone() * r.clone()));
    assert!(((ss / 11.0).sqrt() - 0.9115).abs() < 5e-5);
    assert!(((ss / 8.0).sqrt() - 1.0689).abs() < 5e-5);
    // Eqs 30-31 at N = 11: sd at the ends 0.7619 ("±.76"), at the midpoint 0.4555 ("±.46").
    let sd = |h: f64| covariance_unscaled(2, 10, h, 1.0).unwrap()[(0, 0)].sqrt();
    assert!((sd(0.0) - 0.7619).abs() < 5e-5 && (sd(-10.0) - 0.7619).abs() < 5e-5);
    assert!((sd(-5.0) - 0.4555).abs() < 5e-5);
    // "A 10x sd reduction at the ends needs 9/N = 0.01, so N ~ 900": exactly eq 30 needs N = 896
    // (L = 895).
    assert_eq!(
        Design {
            degree: 2,
            lead: Lead::Steps(0.0),
            tau: 1.0,
            sigma_nu: 1.0
        }
        .min_span_for_sigma(0, 0.1)
        .unwrap(),
        895
    );
}
