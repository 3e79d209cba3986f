//! The fixed-memory covariance (`seqsmooth::polynomial::fixed::covariance`; Morrison (1969)
//! §7.5-7.6, §9.3): `W Wᵀ` and the window covariance in exact rationals, the closed-form VRFs,
//! the worked examples (7.5.16), (7.5.25), correlated errors (Ex 7.10), the asymptotic
//! Tables 7.2, 7.3 and 9.3 entry for entry (the design example: `fixed_design.rs`).

mod common;

use common::book::*;
use common::fixed::*;
use common::rational::*;
use nalgebra::DMatrix;
use num_traits::{One, Signed, Zero};
use seqsmooth::linalg::mul;
use seqsmooth::polynomial::expanding::vrf::expanding_vrf;
use seqsmooth::polynomial::fixed::{
    correlated_covariance, covariance, covariance_unscaled, vrf_limit, weights, FixedEngine,
    FixedMemory,
};
use seqsmooth::polynomial::fixed::{fixed_memory_vrf_limit, window_covariance};
use seqsmooth::polynomial::form::EstimateForm;
use seqsmooth::{Error, PolynomialFilter};

#[test]
fn fixed_memory_vrf_limit_tables_7_2_and_9_3() {
    // Source: Morrison Table 7.2 (closed form of its entries), Table 9.3 (m <= 3; m = 4 derived),
    // (7.6.12) and its closed forms.
    for m in 0..=10usize {
        let k = fixed_memory_vrf_limit(m);
        for i in 0..=m {
            for j in 0..=m {
                assert_eq!(k[(i, j)], kappa(m, i, j), "κ({i},{j}), m = {m}");
            }
            // λ_ii(m) = [(m+i+1)!]² / ((2i+1) (i!)² ((m-i)!)²).
            let diag = fact(m + i + 1) * fact(m + i + 1)
                / (z(2 * i as i64 + 1) * fact(i) * fact(i) * fact(m - i) * fact(m - i));
            assert_eq!(k[(i, i)], diag);
            // (The printed decimals of Table 7.2 are checked in tests/fixed_covariance.rs, through
            // fixed::vrf_limit, which equals this function exactly there.)
        }
    }
    // Table 9.3 and the listed exact entries.
    let t93: [&[i64]; 5] = [
        &[1],
        &[4, 12],
        &[9, 192, 720],
        &[16, 1200, 25920, 100800],
        &[25, 4800, 317520, 6451200, 25401600],
    ];
    for (m, row) in t93.iter().enumerate() {
        let k = fixed_memory_vrf_limit(m);
        for (i, v) in row.iter().enumerate() {
            assert_eq!(k[(i, i)], z(*v), "Table 9.3 m = {m}, i = {i}");
        }
    }
    assert_eq!(fixed_memory_vrf_limit(5)[(5, 5)], z(10059033600));
    assert_eq!(fixed_memory_vrf_limit(5)[(4, 4)], z(2540160000));
    let m2 = [[9, 36, 60], [36, 192, 360], [60, 360, 720]];
    let m3 = [
        [16, 120, 480, 840],
        [120, 1200, 5400, 10080],
        [480, 5400, 25920, 50400],
        [840, 10080, 50400, 100800],
    ];
    let k2 = fixed_memory_vrf_limit(2);
    let k3 = fixed_memory_vrf_limit(3);
    for i in 0..3 {
        for j in 0..3 {
            assert_eq!(k2[(i, j)], z(m2[i][j]));
        }
    }
    for i in 0..4 {
        for j in 0..4 {
            assert_eq!(k3[(i, j)], z(m3[i][j]));
        }
    }
    // Limit (7.6.12)/(Table 9.3): n^(i+j+1) i! j! S_ij(n) -> κ_ij, checked at n = 10^8.
    let n = 100_000_000u64;
    for m in [0usize, 1, 3, 6, 10] {
        let s = expanding_vrf::<Q>(m, n, EstimateForm::Predictor).unwrap();
        let k = fixed_memory_vrf_limit(m);
        for i in 0..=m {
            for j in 0..=m {
                let v = s[(i, j)].clone() * fact(i) * fact(j) * qpow(&z(n as i64), i + j + 1);
                assert!(
                    rel_err(f(&v), f(&k[(i, j)])) < 1e-4,
                    "EMP limit m = {m} ({i},{j}): {} vs {}",
                    f(&v),
                    f(&k[(i, j)])
                );
            }
        }
    }
}

#[test]
fn covariance_is_w_wt_and_window_covariance_exactly() {
    // (7.5.22) Q(L+h)Q(L+h)ᵀ = W(h)W(h)ᵀ (7.5.26) = Φ(h) 𝒮 G C Gᵀ 𝒮ᵀ Φ(h)ᵀ (vrf::window_covariance).
    for m in 0..=4usize {
        for l in [m as i64, 4, 9] {
            if l < m as i64 {
                continue;
            }
            for h in leads(l) {
                let s = covariance(m, l as u64, h.clone()).unwrap();
                let w = weights(m, l as u64, h.clone()).unwrap();
                assert_eq!(s, mul(&w, &w.transpose()), "m = {m}, L = {l}, h = {h}");
                assert_eq!(s, window_covariance(m, l as u64, h.clone()));
            }
        }
    }
    // In f64 the recursion keeps full accuracy at the centre, where Φ(h) cancels: m = 8,
    // L = 1000, h = -500. Measured: 7.4e-16 relative per entry (bound 1e-12); the Φ(h)-product
    // form of vrf::window_covariance: 5.4e-13.
    let (recursion, _phi_product) = centre_covariance_errors();
    assert!(recursion <= 1e-12);
}

/// (L + a)(L + a - 1)…, the falling factorial (L+a)^(k).
fn lff(l: &Q, a: i64, k: usize) -> Q {
    ff(&(l.clone() + z(a)), k)
}

fn poly_in(l: &Q, c: &[i64]) -> Q {
    c.iter()
        .rev()
        .fold(Q::zero(), |acc, v| acc * l.clone() + z(*v))
}

#[test]
fn exact_vrf_closed_forms_t7_10_t7_12_t7_13() {
    // Unscaled VRF diagonals (τ = 1: (i!)² [W Wᵀ]_ii) against closed forms derived from (7.5.x):
    // h = 1 = Table 9.2 with n -> L (book); h = 0 and centre (derived).
    type Form = fn(&Q) -> Q;
    let h1: [&[Form]; 4] = [
        &[|l| Q::one() / (l.clone() + z(1))],
        &[
            |l| z(2) * (z(2) * l.clone() + z(3)) / ((l.clone() + z(1)) * l.clone()),
            |l| z(12) / lff(l, 2, 3),
        ],
        &[
            |l| poly_in(l, &[24, 27, 9]) / lff(l, 1, 3),
            |l| poly_in(l, &[684, 744, 192]) / lff(l, 3, 5),
            |l| z(720) / lff(l, 3, 5),
        ],
        &[
            |l| poly_in(l, &[120, 152, 72, 16]) / lff(l, 1, 4),
            |l| poly_in(l, &[23200, 43800, 31800, 10200, 1200]) / lff(l, 4, 7),
            |l| poly_in(l, &[95040, 102240, 25920]) / lff(l, 4, 7),
            |l| z(100800) / lff(l, 4, 7),
        ],
    ];
    let h0: [&[Form]; 4] = [
        &[|l| Q::one() / (l.clone() + z(1))],
        &[
            |l| z(2) * (z(2) * l.clone() + z(1)) / ((l.clone() + z(1)) * (l.clone() + z(2))),
            |l| z(12) / (l.clone() * (l.clone() + z(1)) * (l.clone() + z(2))),
        ],
        &[
            |l| z(3) * poly_in(l, &[2, 3, 3]) / lff(l, 3, 3),
            |l| z(12) * poly_in(l, &[1, 2]) * poly_in(l, &[-3, 8]) / lff(l, 3, 5),
            |l| z(720) / lff(l, 3, 5),
        ],
        &[
            |l| z(8) * poly_in(l, &[1, 2]) * poly_in(l, &[3, 1, 1]) / lff(l, 4, 4),
            |l| z(200) * poly_in(l, &[2, -3, -3, -3, 6]) / lff(l, 4, 7),
            |l| z(1440) * poly_in(l, &[1, 2]) * poly_in(l, &[-4, 9]) / lff(l, 4, 7),
            |l| z(100800) / lff(l, 4, 7),
        ],
    ];
    let centre: [&[Form]; 4] = [
        &[|l| Q::one() / (l.clone() + z(1))],
        &[
            |l| Q::one() / (l.clone() + z(1)),
            |l| z(12) / (l.clone() * (l.clone() + z(1)) * (l.clone() + z(2))),
        ],
        &[
            |l| {
                z(3) * poly_in(l, &[-4, 6, 3])
                    / (z(4) * (l.clone() - z(1)) * (l.clone() + z(1)) * (l.clone() + z(3)))
            },
            |l| z(12) / (l.clone() * (l.clone() + z(1)) * (l.clone() + z(2))),
            |l| z(720) / lff(l, 3, 5),
        ],
        &[
            |l| {
                z(3) * poly_in(l, &[-4, 6, 3])
                    / (z(4) * (l.clone() - z(1)) * (l.clone() + z(1)) * (l.clone() + z(3)))
            },
            |l| z(25) * poly_in(l, &[16, -24, 0, 12, 3]) / lff(l, 4, 7),
            |l| z(720) / lff(l, 3, 5),
            |l| z(100800) / lff(l, 4, 7),
        ],
    ];
    for m in 0..=3usize {
        for l in [m as i64 + 1, m as i64 + 2, m as i64 + 5, 10, 25, 64, 101] {
            if m >= 2 && l < 3 {
                continue; // the centre form for m = 2 divides by L-1
            }
            let lq = z(l);
            for (name, h, forms) in [
                ("h = 1", z(1), &h1),
                ("h = 0", z(0), &h0),
                ("centre", fr(-l, 2), &centre),
            ] {
                let s = covariance_unscaled(m, l as u64, h, z(1)).unwrap();
                for i in 0..=m {
                    assert_eq!(
                        s[(i, i)],
                        forms[m][i](&lq),
                        "{name}, m = {m}, L = {l}, i = {i}"
                    );
                }
            }
        }
    }
    // τ scaling (7.5.27-28): [S_X]_ij = (i! j!/τ^(i+j)) [W Wᵀ]_ij.
    let tau = fr(1, 3);
    let s1 = covariance_unscaled(3, 12, z(1), z(1)).unwrap();
    let st = covariance_unscaled(3, 12, z(1), tau.clone()).unwrap();
    for i in 0..4 {
        for j in 0..4 {
            assert_eq!(st[(i, j)], s1[(i, j)].clone() / qpow(&tau, i + j));
        }
    }
}

#[test]
fn covariance_examples_7_5_16_7_5_25_ex_7_11_ex_7_21() {
    for l in [2i64, 5, 17] {
        let lq = z(l);
        let d = (lq.clone() + z(2)) * (lq.clone() + z(1));
        // (7.5.16): S*_{n,n}
        let s0 = covariance(1, l as u64, z(0)).unwrap();
        assert_eq!(s0[(0, 0)], z(2) * (z(2) * lq.clone() + z(1)) / d.clone());
        assert_eq!(s0[(0, 1)], z(6) / d.clone());
        assert_eq!(s0[(1, 1)], z(12) / (d.clone() * lq.clone()));
        // (7.5.25): S*_{n+1,n}
        let s1 = covariance(1, l as u64, z(1)).unwrap();
        let e = (lq.clone() + z(1)) * lq.clone();
        assert_eq!(s1[(0, 0)], z(2) * (z(2) * lq.clone() + z(3)) / e.clone());
        assert_eq!(s1[(0, 1)], z(6) / e.clone());
        assert_eq!(s1[(1, 1)], z(12) / (e * (lq.clone() + z(2))));
        // m = 1, general h (derived), and Ex 7.11: diagonal at the centre.
        for h in [z(-7), fr(-1, 3), z(3), fr(-l, 2)] {
            let s = covariance(1, l as u64, h.clone()).unwrap();
            let den = lq.clone() * d.clone();
            assert_eq!(
                s[(0, 0)],
                Q::one() / (lq.clone() + z(1))
                    + z(3) * qpow(&(lq.clone() + z(2) * h.clone()), 2) / den.clone()
            );
            assert_eq!(
                s[(0, 1)],
                z(6) * (lq.clone() + z(2) * h.clone()) / den.clone()
            );
            assert_eq!(s[(1, 1)], z(12) / den);
        }
        assert!(covariance(1, l as u64, fr(-l, 2)).unwrap()[(0, 1)].is_zero());
    }
    // Ex 7.21 (T7-12), L = 4: [S*]_00(h) polynomials; symmetric about h = -2.
    for h in -10..=6i64 {
        let hq = z(h);
        assert_eq!(covariance(0, 4, hq.clone()).unwrap()[(0, 0)], fr(1, 5));
        assert_eq!(
            covariance(1, 4, hq.clone()).unwrap()[(0, 0)],
            poly_in(&hq, &[6, 4, 1]) / z(10)
        );
        assert_eq!(
            covariance(2, 4, hq.clone()).unwrap()[(0, 0)],
            poly_in(&hq, &[62, 108, 107, 40, 5]) / z(70)
        );
    }
    assert_eq!(covariance(2, 4, z(0)).unwrap()[(0, 0)], fr(31, 35));
    assert_eq!(covariance(2, 4, z(6)).unwrap()[(0, 0)], fr(9841, 35));
}

#[test]
fn impulse_response_gives_the_covariance_ex_7_6_and_dies_after_one_window_ex_7_5a() {
    // Ex 7.6: feed a Kronecker delta; Σ_n out_i(n) out_j(n) = [S]_ij for unit white noise.
    // Ex 7.5a: the response is exactly zero once the delta has left the window.
    let (m, window) = (2usize, 11usize);
    let l = window - 1;
    let step = 0.5;
    let want = covariance_unscaled(m, l as u64, 0.0, step).unwrap();
    for engine in [FixedEngine::Direct, FixedEngine::Sliding] {
        let mut filt = FixedMemory::new(m, window, engine).unwrap();
        let mut sum = DMatrix::<f64>::zeros(m + 1, m + 1);
        let start = 40;
        for n in 0..start + 3 * window {
            let y = if n == start { 1.0 } else { 0.0 };
            filt.update(3.0 + n as f64 * step, y).unwrap();
            let Some(s) = filt.estimate() else { continue };
            let x = DMatrix::from_column_slice(m + 1, 1, &s.derivatives);
            sum += &x * x.transpose();
            if n >= start + window {
                assert!(
                    s.derivatives.iter().all(|v| v.abs() <= 1e-15),
                    "{engine:?} n = {n}"
                );
            }
        }
        for i in 0..=m {
            for j in 0..=m {
                let scale = (want[(i, i)] * want[(j, j)]).sqrt();
                assert!(
                    (sum[(i, j)] - want[(i, j)]).abs() <= 1e-13 * scale,
                    "{engine:?} ({i},{j})"
                );
            }
        }
    }
}

#[test]
fn correlated_errors_ex_7_10() {
    // Ex 7.10 (T7-11): R = tridiag(1, 2, 1), W = W(0), m = 1, L = 4: S = W R Wᵀ =
    // [[46/25, 14/25], [14/25, 7/25]]. The book prints the diagonal as "1.76 and 0.28"
    // (a misprint: 1.84 is the exact value; the velocity agrees).
    let r = DMatrix::from_fn(5, 5, |i, j| match i.abs_diff(j) {
        0 => z(2),
        1 => z(1),
        _ => z(0),
    });
    let s = correlated_covariance(&weights(1, 4, z(0)).unwrap(), &r).unwrap();
    assert_eq!(
        s,
        rows(&[vec![fr(46, 25), fr(14, 25)], vec![fr(14, 25), fr(7, 25)]])
    );
    // With R = σ² I it is σ² W Wᵀ.
    let sig2 = fr(9, 4);
    let ri = DMatrix::from_fn(7, 7, |i, j| if i == j { sig2.clone() } else { z(0) });
    let s2 = correlated_covariance(&weights(2, 6, z(1)).unwrap(), &ri).unwrap();
    assert_eq!(
        s2,
        covariance(2, 6, z(1)).unwrap().map(|v| v * sig2.clone())
    );
    assert!(matches!(
        correlated_covariance(&weights(1, 4, z(0)).unwrap(), &ri),
        Err(Error::InvalidParameter { .. })
    ));
}

/// Table 7.2 as printed (rows i, columns m = i..10), mantissa and exponent.
const TABLE_7_2: [&[(&str, i32)]; 11] = [
    &[
        ("1.0", 0),
        ("4.0", 0),
        ("9.00", 0),
        ("1.600", 1),
        ("2.500", 1),
        ("3.600", 1),
        ("4.900", 1),
        ("6.400", 1),
        ("8.100", 1),
        ("1.000", 2),
        ("1.210", 2),
    ],
    &[
        ("1.2", 1),
        ("1.92", 2),
        ("1.200", 3),
        ("4.800", 3),
        ("1.470", 4),
        ("3.763", 4),
        ("8.467", 4),
        ("1.728", 5),
        ("3.267", 5),
        ("5.808", 5),
    ],
    &[
        ("7.2", 2),
        ("2.592", 4),
        ("3.175", 5),
        ("2.258", 6),
        ("1.143", 7),
        ("4.572", 7),
        ("1.537", 8),
        ("4.516", 8),
        ("1.193", 9),
    ],
    &[
        ("1.008", 5),
        ("6.451", 6),
        ("1.306", 8),
        ("1.452", 9),
        ("1.098", 10),
        ("6.323", 10),
        ("2.968", 11),
        ("1.187", 12),
    ],
    &[
        ("2.540", 7),
        ("2.540", 9),
        ("7.684", 10),
        ("1.229", 12),
        ("1.299", 13),
        ("1.018", 14),
        ("6.363", 14),
    ],
    &[
        ("1.006", 10),
        ("1.449", 12),
        ("6.120", 13),
        ("1.333", 15),
        ("1.874", 16),
        ("1.919", 17),
    ],
    &[
        ("5.754", 12),
        ("1.128", 15),
        ("6.344", 16),
        ("1.804", 18),
        ("3.259", 19),
    ],
    &[("4.488", 15), ("1.149", 18), ("8.301", 19), ("2.988", 21)],
    &[("4.578", 18), ("1.483", 21), ("1.339", 23)],
    &[("5.914", 21), ("2.366", 24)],
    &[("9.439", 24)],
];

/// Table 7.3 as printed (centre, rows i, columns m = i..10).
const TABLE_7_3: [&[(&str, i32)]; 11] = [
    &[
        ("1.0", 0),
        ("1.0", 0),
        ("2.25", 0),
        ("2.250", 0),
        ("3.516", 0),
        ("3.516", 0),
        ("4.785", 0),
        ("4.785", 0),
        ("6.056", 0),
        ("6.056", 0),
        ("7.328", 0),
    ],
    &[
        ("1.2", 1),
        ("1.20", 1),
        ("7.500", 1),
        ("7.500", 1),
        ("2.297", 2),
        ("2.297", 2),
        ("5.168", 2),
        ("5.168", 2),
        ("9.771", 2),
        ("9.771", 2),
    ],
    &[
        ("7.20", 2),
        ("7.200", 2),
        ("8.820", 3),
        ("8.820", 3),
        ("4.465", 4),
        ("4.465", 4),
        ("1.501", 5),
        ("1.501", 5),
        ("3.963", 5),
    ],
    &[
        ("1.008", 5),
        ("1.008", 5),
        ("2.041", 6),
        ("2.041", 6),
        ("1.544", 7),
        ("1.544", 7),
        ("7.247", 7),
        ("7.247", 7),
    ],
    &[
        ("2.540", 7),
        ("2.540", 7),
        ("7.684", 8),
        ("7.684", 8),
        ("8.116", 9),
        ("8.116", 9),
        ("5.073", 10),
    ],
    &[
        ("1.006", 10),
        ("1.006", 10),
        ("4.250", 11),
        ("4.250", 11),
        ("5.977", 12),
        ("5.977", 12),
    ],
    &[
        ("5.754", 12),
        ("5.754", 12),
        ("3.237", 14),
        ("3.237", 14),
        ("5.846", 15),
    ],
    &[("4.488", 15), ("4.488", 15), ("3.243", 17), ("3.243", 17)],
    &[("4.578", 18), ("4.578", 18), ("4.131", 20)],
    &[("5.914", 21), ("5.914", 21)],
    &[("9.439", 24)],
];

/// Printed values whose last digit is one unit off the exact value (book rounding):
/// Table 7.3 (5, m = 9, 10): exact 5.97648e12 printed 5.977; (6, m = 8, 9):
/// exact 3.23649e14 printed 3.237.
const TABLE_7_3_ROUNDING: [(usize, usize); 4] = [(5, 9), (5, 10), (6, 8), (6, 9)];

fn assert_printed(got: f64, printed: &str, exp: i32, ulps: f64, what: &str) {
    let want: f64 = printed.parse().unwrap();
    let decimals = printed.split('.').nth(1).map_or(0, str::len) as i32;
    let unit = 10f64.powi(-decimals);
    let g = got / 10f64.powi(exp);
    assert!(
        (g - want).abs() <= ulps * unit * (1.0 + 1e-9),
        "{what}: computed {g:.6}e{exp}, printed {printed}e{exp}"
    );
}

#[test]
fn asymptotic_tables_7_2_and_7_3_entry_for_entry() {
    let half = fr(1, 2);
    for m in 0..=10usize {
        let end = vrf_limit(m, z(1)).unwrap();
        let centre = vrf_limit(m, half.clone()).unwrap();
        // ρ = 1 is vrf::fixed_memory_vrf_limit (κ = V H⁻¹ Vᵀ, an independent formula) exactly.
        assert_eq!(end, fixed_memory_vrf_limit(m), "m = {m}");
        for i in 0..=m {
            // End-point closed forms of (7.6.12).
            for j in 0..=m {
                let want = (i.max(j)..=m).fold(Q::zero(), |s, k| {
                    s + z(2 * k as i64 + 1) * fact(k + i) * fact(k + j)
                        / (fact(i) * fact(j) * fact(k - i) * fact(k - j))
                });
                assert_eq!(end[(i, j)], want);
            }
            assert_eq!(
                end[(i, i)],
                fact(m + i + 1) * fact(m + i + 1)
                    / (z(2 * i as i64 + 1) * fact(i) * fact(i) * fact(m - i) * fact(m - i))
            );
            let (mant, e) = TABLE_7_2[i][m - i];
            assert_printed(
                f(&end[(i, i)]),
                mant,
                e,
                0.5,
                &format!("Table 7.2 ({i}, m = {m})"),
            );
            let (mant, e) = TABLE_7_3[i][m - i];
            let ulps = if TABLE_7_3_ROUNDING.contains(&(i, m)) {
                1.0
            } else {
                0.5
            };
            assert_printed(
                f(&centre[(i, i)]),
                mant,
                e,
                ulps,
                &format!("Table 7.3 ({i}, m = {m})"),
            );
            // Entries repeat in pairs: at the centre d^i φ_k/dr^i = 0 when i + k is odd (7.7.7),
            // so raising m by one adds nothing to λ_ii when m - i is odd.
            if (m - i) % 2 == 1 {
                assert_eq!(
                    centre[(i, i)],
                    vrf_limit(m - 1, half.clone()).unwrap()[(i, i)]
                );
            }
        }
    }
    // Exact Table 7.3 rows.
    let exact_centre: [&[&str]; 5] = [
        &[
            "1",
            "1",
            "9/4",
            "9/4",
            "225/64",
            "225/64",
            "1225/256",
            "1225/256",
            "99225/16384",
            "99225/16384",
            "480249/65536",
        ],
        &[
            "12",
            "12",
            "75",
            "75",
            "3675/16",
            "3675/16",
            "33075/64",
            "33075/64",
            "4002075/4096",
            "4002075/4096",
        ],
        &[
            "720",
            "720",
            "8820",
            "8820",
            "178605/4",
            "178605/4",
            "2401245/16",
            "2401245/16",
            "405810405/1024",
        ],
        &[
            "100800",
            "100800",
            "2041200",
            "2041200",
            "15436575",
            "15436575",
            "289864575/4",
            "289864575/4",
        ],
        &[
            "25401600",
            "25401600",
            "768398400",
            "768398400",
            "8116208100",
            "8116208100",
            "50726300625",
        ],
    ];
    for (i, row) in exact_centre.iter().enumerate() {
        for (c, v) in row.iter().enumerate() {
            let m = i + c;
            assert_eq!(
                vrf_limit(m, half.clone()).unwrap()[(i, i)],
                q(v),
                "Table 7.3 exact ({i}, m = {m})"
            );
        }
    }
    // The two entries the book rounds up (exact values).
    for m in [9usize, 10] {
        assert_eq!(
            vrf_limit(m, half.clone()).unwrap()[(5, 5)],
            z(5976480510000)
        );
        assert_eq!(
            vrf_limit(m - 1, half.clone()).unwrap()[(6, 6)],
            z(323649406080000)
        );
    }
}

#[test]
fn asymptotic_matrices_worked_examples_and_misprints() {
    let half = fr(1, 2);
    let mat = |v: &[&[i64]]| DMatrix::from_fn(v.len(), v.len(), |i, j| z(v[i][j]));
    // Full λ matrices (derived from (7.6.12)).
    assert_eq!(
        vrf_limit(2, z(1)).unwrap(),
        mat(&[&[9, 36, 60], &[36, 192, 360], &[60, 360, 720]])
    );
    assert_eq!(
        vrf_limit(3, z(1)).unwrap(),
        mat(&[
            &[16, 120, 480, 840],
            &[120, 1200, 5400, 10080],
            &[480, 5400, 25920, 50400],
            &[840, 10080, 50400, 100800]
        ])
    );
    let c2 = vrf_limit(2, half.clone()).unwrap();
    assert_eq!(c2[(0, 0)], fr(9, 4));
    assert_eq!(
        (c2[(0, 1)].clone(), c2[(0, 2)].clone(), c2[(1, 1)].clone()),
        (z(0), z(-30), z(12))
    );
    let c3 = vrf_limit(3, half.clone()).unwrap();
    assert_eq!(
        (c3[(1, 1)].clone(), c3[(1, 3)].clone(), c3[(3, 3)].clone()),
        (z(75), z(-2520), z(100800))
    );
    // (7.8.1)-(7.8.5), m = 4: end point 25, 4800, 317520 — the book prints 317500 (misprint
    // a misprint: "(7.8.1) 317500 -> 317520", a 4-figure rounding of Table 7.2's
    // 3.175e5); centre 3.516 (= 225/64), 75, and 8820 for x'' — the book prints 720 in
    // (7.8.4)-(7.8.5), the m = 2/3 value ("(7.8.4-5) 720 -> 8820"; Table 7.3 has 8.820e3).
    let e4 = vrf_limit(4, z(1)).unwrap();
    assert_eq!(
        (e4[(0, 0)].clone(), e4[(1, 1)].clone(), e4[(2, 2)].clone()),
        (z(25), z(4800), z(317520))
    );
    assert_ne!(e4[(2, 2)], z(317500));
    let c4 = vrf_limit(4, half.clone()).unwrap();
    assert_eq!(
        (c4[(0, 0)].clone(), c4[(1, 1)].clone(), c4[(2, 2)].clone()),
        (fr(225, 64), z(75), z(8820))
    );
    assert_ne!(c4[(2, 2)], z(720));
    // Ex 7.23: (a) m = 2 end x' 192; (b) m = 3 one-step x'' 25920 (Table 7.2 serves h = 1);
    // (c) at the centre 12 and 720. Radar example (7.9.2): m = 2 position 9/L.
    assert_eq!(vrf_limit(2, z(1)).unwrap()[(1, 1)], z(192));
    assert_eq!(vrf_limit(3, z(1)).unwrap()[(2, 2)], z(25920));
    assert_eq!(vrf_limit(2, half.clone()).unwrap()[(1, 1)], z(12));
    assert_eq!(vrf_limit(3, half.clone()).unwrap()[(2, 2)], z(720));
    // Ex 7.22: L[S]_00(ρ) = 1 + 3(1-2ρ)² + 5(1-6ρ+6ρ²)² (m = 2), + 7(1-12ρ+30ρ²-20ρ³)² (m = 3).
    for rho in [z(0), fr(1, 4), fr(1, 3), half.clone(), z(1), fr(3, 2)] {
        let r = rho.clone();
        let a = z(1)
            + z(3) * qpow(&(z(1) - z(2) * r.clone()), 2)
            + z(5) * qpow(&(z(1) - z(6) * r.clone() + z(6) * r.clone() * r.clone()), 2);
        let b = a.clone()
            + z(7)
                * qpow(
                    &(z(1) - z(12) * r.clone() + z(30) * qpow(&r, 2) - z(20) * qpow(&r, 3)),
                    2,
                );
        assert_eq!(vrf_limit(2, rho.clone()).unwrap()[(0, 0)], a);
        assert_eq!(vrf_limit(3, rho).unwrap()[(0, 0)], b);
    }
    // The limits are the limits of the exact covariance: L^(i+j+1) [S_X]_ij(L) -> λ_ij, with a
    // relative correction O(m²/L): at L = 10⁶, measured ≤ 1.3e-5 (bound 1e-4).
    let l = 1_000_000i64;
    let mut worst = 0.0f64;
    for m in 0..=4usize {
        for (h, rho) in [(z(0), z(1)), (z(1), z(1)), (fr(-l, 2), half.clone())] {
            let s = covariance_unscaled(m, l as u64, h, z(1)).unwrap();
            let lam = vrf_limit(m, rho).unwrap();
            for i in 0..=m {
                let got = f(&(s[(i, i)].clone() * qpow(&z(l), 2 * i + 1)));
                let want = f(&lam[(i, i)]);
                assert!(
                    ((got - want) / want).abs() <= 1e-4,
                    "m = {m}, i = {i}: {got} vs {want}"
                );
                worst = worst.max(((got - want) / want).abs());
            }
        }
    }
}
