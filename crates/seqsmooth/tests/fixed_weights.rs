//! The fixed-memory weights `W(h)` (`seqsmooth::polynomial::fixed::weights`; Morrison (1969)
//! §7.3-7.4): Morrison's product `Φ(h) 𝒮 G C B` (7.4.16) in exact rationals, the worked example
//! (7.3.22) and exercises, the closed forms, Table 7.1, and the `f64` weights against Householder
//! QR and exact rationals.

mod common;

use common::fixed::*;
use common::rational::*;
use nalgebra::DMatrix;
use num_traits::{One, Signed, Zero};
use seqsmooth::basis::DiscreteLegendre;
use seqsmooth::calculus::{link_matrix, link_matrix_inverse};
use seqsmooth::estimate::PolynomialFit;
use seqsmooth::linalg::mul;
use seqsmooth::model::phi;
use seqsmooth::polynomial::fixed::{weights, weights_unscaled};

#[test]
fn fixed_memory_weights_from_basis_pieces_tv3_5_t7_06() {
    // Source: Morrison (7.4.16)-(7.4.17): W(h) = Φ(h) 𝒮 G C B with [B]_ij = p_i(L-j),
    // C = diag(1/c_j²); TV3.5 / T7-01 / T7-02 (m = 1, L = 4), T7-06 (m = 2, L = 4, ×1/35).
    let weights = book_weights;
    let tenth = |v: &[i64]| v.iter().map(|x| fr(*x, 10)).collect::<Vec<_>>();
    let w1 = weights(1, 4, z(1));
    assert_eq!(
        w1,
        rows_to_matrix(&[&tenth(&[8, 5, 2, -1, -4]), &tenth(&[2, 1, 0, -1, -2])])
    );
    let w0 = weights(1, 4, z(0));
    assert_eq!(
        w0,
        rows_to_matrix(&[&tenth(&[6, 4, 2, 0, -2]), &tenth(&[2, 1, 0, -1, -2])])
    );
    // T7-06, m = 2, L = 4 (multiply by 1/35).
    let r35 = |v: &[&str]| v.iter().map(|s| q(s) / z(35)).collect::<Vec<_>>();
    let want = rows_to_matrix(&[
        &r35(&["31", "9", "-3", "-5", "3"]),
        &r35(&["27", "-13/2", "-20", "-27/2", "13"]),
        &r35(&["5", "-5/2", "-5", "-5/2", "5"]),
    ]);
    assert_eq!(weights(2, 4, z(0)), want);
    let want_c = rows_to_matrix(&[
        &r35(&["-3", "12", "17", "12", "-3"]),
        &r35(&["7", "7/2", "0", "-7/2", "-7"]),
        &r35(&["5", "-5/2", "-5", "-5/2", "5"]),
    ]);
    assert_eq!(weights(2, 4, z(-2)), want_c);
}

fn scaled_row(v: &[&str], d: i64) -> Vec<Q> {
    v.iter().map(|s| q(s) / z(d)).collect()
}

/// Morrison's product `W(h) = Φ(h) 𝒮 G C B` (7.4.16), built in exact rationals from the library's
/// basis pieces: `G` (A1.7) from `end_differences`, `C = diag(1/c_j²)` (3.2.30), and
/// `[B]_ij = p_i(L-j)` from the explicit sum (3.2.20) in `DiscreteLegendre::value` — none of them
/// the recursion (A1.1) that `weights` uses; the products are this file's own (`mm`).
fn book_weights(m: usize, l: i64, h: Q) -> DMatrix<Q> {
    let b = DiscreteLegendre::new(z(l));
    let c = DMatrix::from_fn(m + 1, m + 1, |i, j| {
        if i == j {
            Q::one() / b.norm_sq(j)
        } else {
            Q::zero()
        }
    });
    let bm = DMatrix::from_fn(m + 1, (l + 1) as usize, |i, j| b.value(i, z(l - j as i64)));
    mm(
        &mm(
            &mm(&mm(&phi(m, h), &link_matrix::<Q>(m)), &b.end_differences(m)),
            &c,
        ),
        &bm,
    )
}

fn y_newest_first(y: &[Q]) -> DMatrix<Q> {
    DMatrix::from_fn(y.len(), 1, |i, _| y[i].clone())
}

#[test]
fn weights_equal_morrisons_product_exactly_7_4_16() {
    // W(h) = Φ(h) 𝒮 G C B (7.4.16) entry for entry, and the exactness property of (7.4.14)
    // (T7-09): W(h) T_(L) = Φ(h) with [T]_{k,i} = (-k)^i (a degree-m input passes unchanged).
    for m in 0..=5usize {
        for l in [m as i64, 5, 8, 13] {
            if l < m as i64 {
                continue;
            }
            for h in leads(l) {
                let w = weights(m, l as u64, h.clone()).unwrap();
                assert_eq!(
                    w,
                    book_weights(m, l, h.clone()),
                    "m = {m}, L = {l}, h = {h}"
                );
                let t = DMatrix::from_fn((l + 1) as usize, m + 1, |k, i| qpow(&z(-(k as i64)), i));
                assert_eq!(mul(&w, &t), phi(m, h.clone()), "exactness m = {m}, L = {l}");
            }
        }
    }
}

#[test]
fn worked_example_7_3_22_and_exercises_7_1_to_7_3() {
    // (7.3.22), m = 1, L = 4: weight of y_{n-L+k} at r: 1/5 + (2/5)(1 - k/2)(1 - r/2) for the
    // position, -(1/5)(1 - k/2) for τx' (column L-k of W(h), h = r - L).
    let mut rs: Vec<Q> = (0..=6).map(z).collect();
    rs.push(fr(5, 2));
    for r in rs {
        let w = weights(1, 4, r.clone() - z(4)).unwrap();
        for k in 0..=4i64 {
            let pos = fr(1, 5) + fr(2, 5) * (z(1) - fr(k, 2)) * (z(1) - r.clone() / z(2));
            assert_eq!(w[(0, (4 - k) as usize)], pos, "(7.3.22) r = {r}, k = {k}");
            assert_eq!(w[(1, (4 - k) as usize)], -fr(1, 5) * (z(1) - fr(k, 2)));
        }
    }
    // Ex 7.1 (any L, r): w(k) = 1/(L+1) + 3(L-2k)(L-2r)/(L(L+1)(L+2)); Ex 7.3a: τx' weight
    // (12k - 6L)/(L(L+1)(L+2)); Ex 7.1c (r = L): (2 - 2L + 6k)/((L+2)(L+1)); Ex 7.3c: at the
    // centre the m = 1 position estimate is the window mean, like the degree-0 filter (Ex 7.3d).
    for l in [3i64, 7, 10] {
        let lq = z(l);
        let den = lq.clone() * (lq.clone() + z(1)) * (lq.clone() + z(2));
        for r in [z(0), fr(l, 2), z(l), z(l + 1), fr(7, 3)] {
            let w = weights(1, l as u64, r.clone() - lq.clone()).unwrap();
            for k in 0..=l {
                let col = (l - k) as usize;
                let want = Q::one() / (lq.clone() + z(1))
                    + z(3) * (lq.clone() - z(2 * k)) * (lq.clone() - z(2) * r.clone())
                        / den.clone();
                assert_eq!(w[(0, col)], want, "Ex 7.1, L = {l}");
                assert_eq!(w[(1, col)], (z(12 * k) - z(6 * l)) / den.clone(), "Ex 7.3a");
            }
        }
        let w0 = weights(1, l as u64, z(0)).unwrap();
        let wc = weights(1, l as u64, fr(-l, 2)).unwrap();
        let w00 = weights(0, l as u64, fr(-l, 2)).unwrap();
        for k in 0..=l {
            let col = (l - k) as usize;
            assert_eq!(
                w0[(0, col)],
                z(2 - 2 * l + 6 * k) / z((l + 2) * (l + 1)),
                "Ex 7.1c"
            );
            assert_eq!(wc[(0, col)], fr(1, l + 1), "Ex 7.3c");
            assert_eq!(w00[(0, col)], fr(1, l + 1), "Ex 7.3d");
        }
    }
}

#[test]
fn test_vectors_t7_01_to_t7_08() {
    let tenth = |v: &[&str]| scaled_row(v, 10);
    // T7-01 (7.3.23, 7.4.17), T7-02 (7.3.27), T7-03 (Ex 7.3b).
    let w1 = rows(&[
        tenth(&["8", "5", "2", "-1", "-4"]),
        tenth(&["2", "1", "0", "-1", "-2"]),
    ]);
    let w0 = rows(&[
        tenth(&["6", "4", "2", "0", "-2"]),
        tenth(&["2", "1", "0", "-1", "-2"]),
    ]);
    let wc = rows(&[
        tenth(&["2", "2", "2", "2", "2"]),
        tenth(&["2", "1", "0", "-1", "-2"]),
    ]);
    assert_eq!(weights(1, 4, z(1)).unwrap(), w1);
    assert_eq!(weights(1, 4, z(0)).unwrap(), w0);
    assert_eq!(weights(1, 4, z(-2)).unwrap(), wc);
    // T7-04 (7.3.32-33), unscaled one-step weights, τ = 3/2: x' row = (2, 1, 0, -1, -2)/(10τ).
    let tau = fr(3, 2);
    let wu = weights_unscaled(1, 4, z(1), tau.clone()).unwrap();
    for k in 0..5 {
        assert_eq!(wu[(0, k)], w1[(0, k)].clone());
        assert_eq!(wu[(1, k)], w1[(1, k)].clone() / tau.clone());
    }
    // T7-05 (7.3.28): Φ(-1) W(1) = W(0).
    assert_eq!(mul(&phi(1, z(-1)), &w1), w0);
    // T7-06 (Ex 7.4), m = 2, L = 4, ×1/35.
    let r35 = |v: &[&str]| scaled_row(v, 35);
    let z2 = r35(&["5", "-5/2", "-5", "-5/2", "5"]);
    let cases = [
        (
            z(0),
            rows(&[
                r35(&["31", "9", "-3", "-5", "3"]),
                r35(&["27", "-13/2", "-20", "-27/2", "13"]),
                z2.clone(),
            ]),
        ),
        (
            z(1),
            rows(&[
                r35(&["63", "0", "-28", "-21", "21"]),
                r35(&["37", "-23/2", "-30", "-37/2", "23"]),
                z2.clone(),
            ]),
        ),
        (
            z(-2),
            rows(&[
                r35(&["-3", "12", "17", "12", "-3"]),
                r35(&["7", "7/2", "0", "-7/2", "-7"]),
                z2,
            ]),
        ),
    ];
    for (h, want) in cases {
        assert_eq!(weights(2, 4, h.clone()).unwrap(), want, "T7-06 h = {h}");
    }
    // T7-07 (Ex 7.5b), L = 10, rows of W(0) = impulse responses, y_n first.
    let w = weights(1, 10, z(0)).unwrap();
    let m1z0 = [
        "7/22", "3/11", "5/22", "2/11", "3/22", "1/11", "1/22", "0", "-1/22", "-1/11", "-3/22",
    ];
    let m1z1 = [
        "1/22", "2/55", "3/110", "1/55", "1/110", "0", "-1/110", "-1/55", "-3/110", "-2/55",
        "-1/22",
    ];
    let w2 = weights(2, 10, z(0)).unwrap();
    let m2z0 = [
        "83/143", "54/143", "30/143", "1/13", "-3/143", "-12/143", "-16/143", "-15/143", "-9/143",
        "2/143", "18/143",
    ];
    let m2z2 = [
        "5/286", "1/143", "-1/858", "-1/143", "-3/286", "-5/429", "-3/286", "-1/143", "-1/858",
        "1/143", "5/286",
    ];
    for k in 0..11 {
        assert_eq!(w[(0, k)], q(m1z0[k]), "T7-07 m=1 z0");
        assert_eq!(w[(1, k)], q(m1z1[k]), "T7-07 m=1 z1");
        assert_eq!(w2[(0, k)], q(m2z0[k]), "T7-07 m=2 z0");
        assert_eq!(w2[(2, k)], q(m2z2[k]), "T7-07 m=2 z2");
    }
    // T7-08: Y = (5, 3, 4, 2, 1), L = 4.
    let y = y_newest_first(&[z(5), z(3), z(4), z(2), z(1)]);
    let apply = |m: usize, h: Q| -> Vec<Q> {
        mul(&weights(m, 4, h).unwrap(), &y)
            .iter()
            .cloned()
            .collect()
    };
    assert_eq!(apply(1, z(0)), vec![fr(24, 5), fr(9, 10)]);
    assert_eq!(apply(1, z(1)), vec![fr(57, 10), fr(9, 10)]);
    assert_eq!(apply(1, z(-2)), vec![z(3), fr(9, 10)]);
    assert_eq!(apply(2, z(0)), vec![fr(163, 35), fr(43, 70), fr(-1, 14)]);
    assert_eq!(apply(2, z(1)), vec![fr(26, 5), fr(33, 70), fr(-1, 14)]);
    assert_eq!(apply(2, z(-2)), vec![fr(22, 7), fr(9, 10), fr(-1, 14)]);
}

#[test]
fn closed_form_weights_of_spec_1_4() {
    // Closed forms derived from (7.4.16), weight on y_{n-j}.
    for l in [4i64, 9, 16] {
        let lq = z(l);
        let (l1, l2, l3, lm1) = (
            lq.clone() + z(1),
            lq.clone() + z(2),
            lq.clone() + z(3),
            lq.clone() - z(1),
        );
        for h in [z(0), z(1), z(-3), fr(7, 2)] {
            let w = weights(1, l as u64, h.clone()).unwrap();
            for j in 0..=l {
                let jq = z(j);
                let z0 = Q::one() / l1.clone()
                    + z(3) * (lq.clone() - z(2) * jq.clone()) * (lq.clone() + z(2) * h.clone())
                        / (lq.clone() * l1.clone() * l2.clone());
                let z1 = z(6) * (lq.clone() - z(2) * jq.clone())
                    / (lq.clone() * l1.clone() * l2.clone());
                assert_eq!(w[(0, j as usize)], z0);
                assert_eq!(w[(1, j as usize)], z1);
            }
        }
        let w0 = weights(2, l as u64, z(0)).unwrap();
        let w1 = weights(2, l as u64, z(1)).unwrap();
        let big = lq.clone() * lm1.clone() * l1.clone() * l2.clone() * l3.clone();
        for j in 0..=l {
            let jq = z(j);
            let (ll, jj) = (lq.clone(), jq.clone());
            let p = |c: &[(i64, u32, u32)]| -> Q {
                c.iter().fold(Q::zero(), |s, (k, a, b)| {
                    s + z(*k) * qpow(&ll, *a as usize) * qpow(&jj, *b as usize)
                })
            };
            let a0 =
                z(3) * p(&[
                    (3, 2, 0),
                    (-12, 1, 1),
                    (3, 1, 0),
                    (10, 0, 2),
                    (-6, 0, 1),
                    (2, 0, 0),
                ]) / (l1.clone() * l2.clone() * l3.clone());
            let a1 =
                z(6) * p(&[
                    (6, 3, 0),
                    (-32, 2, 1),
                    (-3, 2, 0),
                    (30, 1, 2),
                    (-4, 1, 1),
                    (-3, 1, 0),
                    (6, 0, 1),
                ]) / big.clone();
            let a2 = z(30) * p(&[(1, 2, 0), (-6, 1, 1), (-1, 1, 0), (6, 0, 2)]) / big.clone();
            let b0 = z(3) * p(&[(3, 2, 0), (-12, 1, 1), (-3, 1, 0), (10, 0, 2), (2, 0, 1)])
                / (lq.clone() * lm1.clone() * l1.clone());
            let b1 =
                z(6) * p(&[
                    (6, 3, 0),
                    (-32, 2, 1),
                    (7, 2, 0),
                    (30, 1, 2),
                    (-64, 1, 1),
                    (-13, 1, 0),
                    (60, 0, 2),
                    (6, 0, 1),
                ]) / big.clone();
            let col = j as usize;
            assert_eq!(w0[(0, col)], a0, "m=2 h=0 z0 L={l} j={j}");
            assert_eq!(w0[(1, col)], a1, "m=2 h=0 z1");
            assert_eq!(w0[(2, col)], a2.clone(), "m=2 h=0 z2");
            assert_eq!(w1[(0, col)], b0, "m=2 h=1 z0");
            assert_eq!(w1[(1, col)], b1, "m=2 h=1 z1");
            assert_eq!(w1[(2, col)], a2, "z2 row is the same for all h");
        }
    }
}

#[test]
fn table_7_1_recovered_from_the_weights() {
    // W(0) = 𝒮 G C B and B Bᵀ = C⁻¹ (7.5.8) give G = 𝒮⁻¹ W(0) Bᵀ: the matrix G of Table 7.1
    // comes back out of the weights, exactly. (G itself, (7.4.13)-(7.4.14), is checked entry
    // for entry against the printed Table 7.1 in tests/discrete_legendre.rs.)
    for l in [10i64, 12, 20] {
        let m = 10;
        let basis = DiscreteLegendre::new(z(l));
        let b = DMatrix::from_fn(m + 1, (l + 1) as usize, |i, k| {
            basis.value(i, z(l - k as i64))
        });
        let g = mul(
            &mul(
                &link_matrix_inverse::<Q>(m),
                &weights(m, l as u64, z(0)).unwrap(),
            ),
            &b.transpose(),
        );
        assert_eq!(g, basis.end_differences(m), "Table 7.1 matrix G, L = {l}");
        // The book's examples: [G]_{3,5} = -560/L^(3), [G]_{7,8} = 51480/L^(7).
        assert_eq!(g[(3, 5)], z(-560) / ff(&z(l), 3));
        assert_eq!(g[(7, 8)], z(51480) / ff(&z(l), 7));
    }
}

#[test]
fn f64_weights_match_a_householder_qr_fit_up_to_l_10000() {
    // W(h) in f64 against the least-squares fit of the unit vectors by Householder QR on a
    // Legendre design matrix, relative to each row's largest weight. Required ≤ 1e-10 (m ≤ 8;
    // also run at m = 10); measured ≤ 2.2e-12, the worst at the centre, m = 1, L = 10⁴, where
    // the QR oracle is the less accurate of the two: there `weights` is within 2.2e-16 of the
    // exact rational weights and the QR 2.1e-12 (next test).
    for (m, l, h, e) in weights_vs_qr() {
        assert!(e <= 1e-10, "m = {m}, L = {l}, h = {h}: {e:.2e}");
    }
    // The library's batch fitter on a few unit vectors (a second, independent QR code path).
    let (m, l, h) = (4usize, 1000usize, 2.5);
    let w = weights(m, l as u64, h).unwrap();
    let times: Vec<f64> = (0..=l).map(|r| r as f64).collect();
    for k in [0usize, 333, 1000] {
        let mut y = vec![0.0; l + 1];
        y[l - k] = 1.0; // column k multiplies y_{n-k}, at r = L - k
        let fit = PolynomialFit::new(&times, &y, None, m).unwrap();
        let d = fit.derivatives_at(l as f64 + h);
        for i in 0..=m {
            let scale = w.row(i).iter().fold(0.0f64, |s, v| s.max(v.abs()));
            let zi = d[i] / f(&fact(i));
            assert!(
                (zi - w[(i, k)]).abs() <= 1e-10 * scale,
                "PolynomialFit k = {k}, i = {i}"
            );
        }
    }
}

#[test]
fn f64_weights_match_exact_rationals_where_the_explicit_sums_cancel() {
    // f64 `weights` (recursion A1.1) against the exact rational weights: measured ≤ 5e-15
    // (bound 1e-13). The book's product Φ(h) 𝒮 G C B evaluated in f64 with the explicit sums
    // (3.2.20) loses digits to cancellation: measured 7e-10 at m = 10, L = 300 — the reason for
    // the recursion.
    let mut worst: f64 = 0.0;
    let mut book_m10: f64 = 0.0;
    for (m, l, h, e, book) in weights_vs_exact() {
        assert!(e <= 1e-13, "m = {m}, L = {l}, h = {h}: {e:.2e}");
        worst = worst.max(e);
        if let Some(b) = book {
            book_m10 = book_m10.max(b);
        }
    }
    // Long windows, low degree, at the centre: measured ≤ 1e-15 against the exact weights, where
    // the QR oracle of the previous test is off by 2e-12 (m = 1, L = 10⁴).
    for (m, e) in weights_vs_exact_long_windows() {
        assert!(e <= 1e-13, "m = {m}, L = 10⁴: {e:.2e}");
        worst = worst.max(e);
    }
    assert!(
        book_m10 > 1e3 * worst,
        "the explicit sums were expected to cancel"
    );
}
