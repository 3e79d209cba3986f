//! `seqsmooth::calculus` against Morrison (1969) ch. 2 and 4: the Stirling matrices (Tables 2.1,
//! 2.2), the link matrices 𝒮 and 𝒮⁻¹ (Tables 4.1, 4.2), factorial functions, binomials, power
//! sums and differences, all in exact rationals against values printed in the book or computed
//! here independently of the library.

mod common;

use common::rational::*;
use nalgebra::DMatrix;
use num_traits::Zero;
use seqsmooth::calculus::{
    backward_difference, binomial, choose, factorial, falling_factorial, link_matrix,
    link_matrix_inverse, rising_factorial, stirling1, stirling2,
};
use seqsmooth::linalg::inverse_exact;

fn qrow(xs: &[&str]) -> Vec<Q> {
    xs.iter().map(|s| q(s)).collect()
}

/// Morrison Table 2.1 (signed Stirling numbers of the first kind), rows 0..10, as reconstructed
/// from (2.4.9) (the printed table is scrambled in the OCR).
const TABLE_2_1: [&[i64]; 11] = [
    &[1],
    &[0, 1],
    &[0, -1, 1],
    &[0, 2, -3, 1],
    &[0, -6, 11, -6, 1],
    &[0, 24, -50, 35, -10, 1],
    &[0, -120, 274, -225, 85, -15, 1],
    &[0, 720, -1764, 1624, -735, 175, -21, 1],
    &[0, -5040, 13068, -13132, 6769, -1960, 322, -28, 1],
    &[0, 40320, -109584, 118124, -67284, 22449, -4536, 546, -36, 1],
    &[
        0, -362880, 1026576, -1172700, 723680, -269325, 63273, -9450, 870, -45, 1,
    ],
];

/// Morrison Table 2.2 (Stirling numbers of the second kind), rows 0..10.
const TABLE_2_2: [&[i64]; 11] = [
    &[1],
    &[0, 1],
    &[0, 1, 1],
    &[0, 1, 3, 1],
    &[0, 1, 7, 6, 1],
    &[0, 1, 15, 25, 10, 1],
    &[0, 1, 31, 90, 65, 15, 1],
    &[0, 1, 63, 301, 350, 140, 21, 1],
    &[0, 1, 127, 966, 1701, 1050, 266, 28, 1],
    &[0, 1, 255, 3025, 7770, 6951, 2646, 462, 36, 1],
    &[0, 1, 511, 9330, 34105, 42525, 22827, 5880, 750, 45, 1],
];

fn lower_table(t: &[&[i64]; 11]) -> DMatrix<Q> {
    DMatrix::from_fn(11, 11, |i, j| if j <= i { z(t[i][j]) } else { Q::zero() })
}

#[test]
fn table_2_1_stirling_first_kind_rows_0_to_10() {
    // Source: Morrison Table 2.1 / (2.4.8)-(2.4.10).
    let want = lower_table(&TABLE_2_1);
    let got = stirling1::<Q>(10);
    assert_eq!(got, want);
    let got_f = stirling1::<f64>(10);
    for i in 0..=10 {
        for j in 0..=10 {
            assert_eq!(got_f[(i, j)], f(&want[(i, j)]), "S1[{i},{j}] in f64");
        }
    }
    // Ex 2.7a: x^(3) = x^3 - 3x^2 + 2x; x^(5) row = (0, 24, -50, 35, -10, 1).
    assert_eq!(TABLE_2_1[3], &[0, 2, -3, 1]);
    // Defining identity (2.4.8) beyond the printed rows: x^(i) = Σ_j S1_ij x^j, checked against an
    // independent product for i <= 16 at integer and non-integer x.
    let s = stirling1::<Q>(16);
    for x in [z(-3), z(0), z(5), z(12), fr(7, 2), fr(-5, 3)] {
        for i in 0..=16 {
            let sum = (0..=i).fold(Q::zero(), |a, j| a + s[(i, j)].clone() * qpow(&x, j));
            assert_eq!(sum, ff(&x, i), "(2.4.8) at i = {i}, x = {x}");
        }
    }
}

#[test]
fn table_2_2_stirling_second_kind_rows_0_to_10() {
    // Source: Morrison Table 2.2 / (2.4.13)-(2.4.15).
    let want = lower_table(&TABLE_2_2);
    assert_eq!(stirling2::<Q>(10), want);
    let got_f = stirling2::<f64>(10);
    for i in 0..=10 {
        for j in 0..=10 {
            assert_eq!(got_f[(i, j)], f(&want[(i, j)]), "S2[{i},{j}] in f64");
        }
    }
    // Defining identity (2.4.13): x^i = Σ_j S2_ij x^(j), for i <= 16.
    let s = stirling2::<Q>(16);
    for x in [z(-4), z(3), z(11), fr(9, 4), fr(-1, 7)] {
        for i in 0..=16 {
            let sum = (0..=i).fold(Q::zero(), |a, j| a + s[(i, j)].clone() * ff(&x, j));
            assert_eq!(sum, qpow(&x, i), "(2.4.13) at i = {i}, x = {x}");
        }
    }
}

#[test]
fn stirling_matrices_are_mutual_inverses() {
    // Source: Morrison (2.4.13) "S2 = S1^-1" (11×11).
    // Printed tables: their product is the identity.
    let t1 = lower_table(&TABLE_2_1);
    let t2 = lower_table(&TABLE_2_2);
    assert_eq!(mm(&t1, &t2), eye(11));
    // Library matrices, also beyond the printed order.
    for order in [10, 20] {
        let s1 = stirling1::<Q>(order);
        let s2 = stirling2::<Q>(order);
        assert_eq!(mm(&s1, &s2), eye(order + 1));
        assert_eq!(mm(&s2, &s1), eye(order + 1));
    }
    // The library's exact inverse of the printed Table 2.1 is the printed Table 2.2.
    assert_eq!(inverse_exact(&t1).unwrap(), t2);
}

/// Morrison Table 4.1 (link matrix 𝒮), row i lists columns j = i..10 (row 0 lists j = 0..10).
/// Row 4, column 8 is printed 6169 in the OCR; the correct value is 6769 (from (4.4.5)).
const TABLE_4_1: [&[i64]; 11] = [
    &[1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0],
    &[1, 1, 2, 6, 24, 120, 720, 5040, 40320, 362880],
    &[1, 3, 11, 50, 274, 1764, 13068, 109584, 1026576],
    &[1, 6, 35, 225, 1624, 13132, 118124, 1172700],
    &[1, 10, 85, 735, 6769, 67284, 723680],
    &[1, 15, 175, 1960, 22449, 269325],
    &[1, 21, 322, 4536, 63273],
    &[1, 28, 546, 9450],
    &[1, 36, 870],
    &[1, 45],
    &[1],
];

/// Morrison Table 4.2 (𝒮⁻¹), row i lists columns j = i..10 (row-1 signs regenerated from (4.4.5)).
const TABLE_4_2: [&[i64]; 11] = [
    &[1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0],
    &[1, -1, 1, -1, 1, -1, 1, -1, 1, -1],
    &[1, -3, 7, -15, 31, -63, 127, -255, 511],
    &[1, -6, 25, -90, 301, -966, 3025, -9330],
    &[1, -10, 65, -350, 1701, -7770, 34105],
    &[1, -15, 140, -1050, 6951, -42525],
    &[1, -21, 266, -2646, 22827],
    &[1, -28, 462, -5880],
    &[1, -36, 750],
    &[1, -45],
    &[1],
];

fn upper_table(t: &[&[i64]; 11]) -> DMatrix<Q> {
    DMatrix::from_fn(11, 11, |i, j| {
        if j < i {
            Q::zero()
        } else if i == 0 {
            z(t[0][j])
        } else {
            z(t[i][j - i])
        }
    })
}

#[test]
fn table_4_1_link_matrix_with_6769_correction() {
    // Source: Morrison Table 4.1 and the Chapter 4 notes.
    let want = upper_table(&TABLE_4_1);
    let sa = link_matrix::<Q>(10);
    assert_eq!(sa, want);
    // The OCR misprint 6169 must not be reproduced; the correct entry is 6769 (row 4, column 8).
    assert_eq!(sa[(4, 8)], z(6769));
    assert_ne!(sa[(4, 8)], z(6169));
    // Worked example of the Chapter 4 notes: [𝒮]_{5,8} = [𝒮]_{4,7} + 7 [𝒮]_{5,7} = 735 + 1225 = 1960.
    assert_eq!(sa[(5, 8)], z(1960));
    assert_eq!(sa[(4, 7)].clone() + z(7) * sa[(5, 7)].clone(), z(1960));
    // The notes' recursion [𝒮]_{i,j} = [𝒮]_{i-1,j-1} + (j-1)[𝒮]_{i,j-1} on a larger order.
    let big = link_matrix::<Q>(14);
    for i in 1..=14 {
        for j in 1..=14 {
            let r = big[(i - 1, j - 1)].clone() + z(j as i64 - 1) * big[(i, j - 1)].clone();
            assert_eq!(big[(i, j)], r, "link recursion at ({i},{j})");
        }
    }
    // (4.4.10), m = 3.
    let m3 = rows_to_matrix(&[
        &[z(1), z(0), z(0), z(0)],
        &[z(0), z(1), z(1), z(2)],
        &[z(0), z(0), z(1), z(3)],
        &[z(0), z(0), z(0), z(1)],
    ]);
    assert_eq!(link_matrix::<Q>(3), m3);
    // f64 instantiation.
    let sf = link_matrix::<f64>(10);
    assert_eq!(sf[(4, 8)], 6769.0);
    assert_eq!(sf[(1, 10)], 362880.0);
}

#[test]
fn table_4_2_inverse_link_matrix_and_identity() {
    // Source: Morrison Table 4.2, (4.4.5), (4.4.9).
    let want = upper_table(&TABLE_4_2);
    assert_eq!(link_matrix_inverse::<Q>(10), want);
    // Formula (4.4.5), evaluated here: [𝒮⁻¹]_ij = (1/i!) Σ_ν (-1)^ν C(i,ν) (-ν)^j (0^0 = 1).
    let si = link_matrix_inverse::<Q>(13);
    for i in 0..=13usize {
        for j in 0..=13usize {
            let s = (0..=i).fold(Q::zero(), |a, nu| {
                a + sign(nu) * c(i as i64, nu as i64) * qpow(&z(-(nu as i64)), j)
            }) / fact(i);
            assert_eq!(si[(i, j)], s, "(4.4.5) at ({i},{j})");
        }
    }
    // (4.4.9), m = 3.
    let m3 = rows_to_matrix(&[
        &[z(1), z(0), z(0), z(0)],
        &[z(0), z(1), z(-1), z(1)],
        &[z(0), z(0), z(1), z(-3)],
        &[z(0), z(0), z(0), z(1)],
    ]);
    assert_eq!(link_matrix_inverse::<Q>(3), m3);
    // 𝒮 𝒮⁻¹ = I, for the printed tables and for the library beyond them.
    assert_eq!(mm(&upper_table(&TABLE_4_1), &want), eye(11));
    for m in [10, 18] {
        assert_eq!(
            mm(&link_matrix::<Q>(m), &link_matrix_inverse::<Q>(m)),
            eye(m + 1)
        );
    }
}

#[test]
fn link_matrices_convert_difference_and_derivative_states() {
    // Source: Morrison (4.4.6)-(4.4.8) Z = 𝒮 V, (4.4.14) Z = S1ᵀ V^f; TV4.6 (Ex 4.7/4.9).
    // TV4.6: x = t^3, τ = 2: V_1 = (8, 8, 0, 8) -> Z_1 = 𝒮 V_1 = (8, 24, 24, 8).
    let v1 = DMatrix::from_column_slice(4, 1, &[z(8), z(8), z(0), z(8)]);
    let z1 = mm(&link_matrix::<Q>(3), &v1);
    assert_eq!(z1.as_slice(), &[z(8), z(24), z(24), z(8)]);
    // (derived) x = n^3 at n = 0, τ = 1: V^f = (0,1,3,1), V = (0,1,-3,1), Z = (0,0,0,1) from both.
    let vf = DMatrix::from_column_slice(4, 1, &[z(0), z(1), z(3), z(1)]);
    let v = DMatrix::from_column_slice(4, 1, &[z(0), z(1), z(-3), z(1)]);
    let zz = vec![z(0), z(0), z(0), z(1)];
    assert_eq!(
        mm(&stirling1::<Q>(3).transpose(), &vf).as_slice(),
        zz.as_slice()
    );
    assert_eq!(mm(&link_matrix::<Q>(3), &v).as_slice(), zz.as_slice());
    // General degree-m polynomial (τ = 1): V_k = ∇^k x_n / k! (with the library's backward
    // difference), Z_k = x^(k)(n)/k! (Taylor coefficient, computed here); Z = 𝒮 V, V = 𝒮⁻¹ Z.
    let poly = qrow(&["3", "-1/2", "2", "5/7", "-1", "1/3", "2"]); // degree 6
    let m = poly.len() - 1;
    for n in [-3i64, 0, 4, 11] {
        let samples: Vec<Q> = (0..=m as i64)
            .rev()
            .map(|k| peval(&poly, &z(n - k)))
            .collect();
        let vv = DMatrix::from_fn(m + 1, 1, |k, _| {
            backward_difference(&samples, k).unwrap() / fact(k)
        });
        let want = DMatrix::from_fn(m + 1, 1, |k, _| peval(&pderiv(&poly, k), &z(n)) / fact(k));
        assert_eq!(mm(&link_matrix::<Q>(m), &vv), want, "Z = 𝒮 V at n = {n}");
        assert_eq!(
            mm(&link_matrix_inverse::<Q>(m), &want),
            vv,
            "V = 𝒮⁻¹ Z at n = {n}"
        );
    }
}

#[test]
fn factorial_function_identities_2_4_19_and_2_4_20() {
    // Source: Morrison (2.4.1)-(2.4.3), (2.4.19), (2.4.20), Ex 2.10, Ex 2.7a.
    let xs = [z(7), z(10), z(-3), z(0), fr(5, 2), fr(-7, 3), fr(1, 10)];
    for x in &xs {
        for m in 0..=9usize {
            assert_eq!(falling_factorial(x.clone(), m), ff(x, m), "x^({m}) at {x}");
            assert_eq!(rising_factorial(x.clone(), m), rf(x, m), "x^[{m}] at {x}");
            // (2.4.20): x^(m) = (-1)^m (-x)^[m]; Ex 2.10: x^[m] = (-1)^m (-x)^(m).
            assert_eq!(
                falling_factorial(x.clone(), m),
                sign(m) * rising_factorial(-x.clone(), m)
            );
            assert_eq!(
                rising_factorial(x.clone(), m),
                sign(m) * falling_factorial(-x.clone(), m)
            );
            // (2.4.19): x^(m) = x^(r) (x-r)^(m-r).
            for r in 0..=m {
                assert_eq!(
                    falling_factorial(x.clone(), m),
                    falling_factorial(x.clone(), r)
                        * falling_factorial(x.clone() - z(r as i64), m - r),
                    "(2.4.19) x = {x}, m = {m}, r = {r}"
                );
            }
        }
    }
    for k in 0..=12usize {
        // k^(k) = k!, x^(k) = 0 for integer 0 <= x < k, (-1)^(k) = (-1)^k k! (Ex 2.7a).
        assert_eq!(falling_factorial(z(k as i64), k), fact(k));
        assert_eq!(factorial::<Q>(k), fact(k));
        for x in 0..k {
            assert!(falling_factorial(z(x as i64), k).is_zero());
        }
        assert_eq!(falling_factorial(z(-1), k), sign(k) * fact(k));
    }
    // f64 instantiation on exactly representable values.
    assert_eq!(falling_factorial(7.0, 3), 210.0);
    assert_eq!(rising_factorial(3.0, 3), 60.0);
    assert_eq!(factorial::<f64>(10), 3628800.0);
    // (2.4.17): ∇^m x^(k) = k^(m) (x-m)^(k-m), via the library's backward difference.
    for k in 0..=6usize {
        for m in 0..=k {
            for x in [4i64, 9, -2] {
                let seq: Vec<Q> = (0..=m as i64).rev().map(|d| ff(&z(x - d), k)).collect();
                let lhs = backward_difference(&seq, m).unwrap();
                let rhs = ff(&z(k as i64), m) * ff(&z(x - m as i64), k - m);
                assert_eq!(lhs, rhs, "(2.4.17) k = {k}, m = {m}, x = {x}");
            }
        }
    }
}

#[test]
fn binomial_coefficients_for_negative_and_real_arguments() {
    // Source: Morrison (2.5.1)-(2.5.7), Ex 2.11, (2.6.15), Ex 2.18.
    // Ex 2.11: C(5,3) = C(5,2) = 10, C(5,4) = C(5,1) = 5, C(5,6) = 0, C(-1,j) = (-1)^j.
    assert_eq!(binomial(z(5), 3), z(10));
    assert_eq!(binomial(z(5), 2), z(10));
    assert_eq!(binomial(z(5), 4), z(5));
    assert_eq!(binomial(z(5), 1), z(5));
    assert_eq!(binomial(z(5), 6), z(0));
    assert_eq!(choose::<Q>(5, 6), z(0));
    assert_eq!(choose::<f64>(20, 10), 184756.0);
    for j in 0..=12 {
        assert_eq!(binomial(z(-1), j), sign(j), "C(-1,{j})");
        // C(-n, k) = (-1)^k C(n+k-1, k) (from (2.5.1) with (2.4.20)).
        for n in 1..=6i64 {
            assert_eq!(binomial(z(-n), j), sign(j) * c(n + j as i64 - 1, j as i64));
        }
    }
    // C(1/2, k) = 1, 1/2, -1/8, 1/16, -5/128, 7/256 (the (1+y)^(1/2) series, (2.5.8) extended).
    let half = ["1", "1/2", "-1/8", "1/16", "-5/128", "7/256"];
    for (k, s) in half.iter().enumerate() {
        assert_eq!(binomial(fr(1, 2), k), q(s), "C(1/2,{k})");
    }
    assert_eq!(binomial(-1.0_f64, 3), -1.0);
    assert_eq!(binomial(0.5_f64, 2), -0.125);
    // choose(n,k) agrees with binomial(n,k) and with the symmetric/closed form m!/(k!(m-k)!).
    for n in 0..=25usize {
        for k in 0..=27usize {
            let want = if k <= n {
                fact(n) / (fact(k) * fact(n - k))
            } else {
                Q::zero()
            };
            assert_eq!(choose::<Q>(n, k), want, "C({n},{k})");
            assert_eq!(binomial(z(n as i64), k), want);
        }
    }
    let xs = [fr(7, 3), fr(-5, 2), z(-4), z(6), fr(1, 9)];
    for x in &xs {
        for k in 1..=8usize {
            // Pascal (2.5.5): C(x+1,k) = C(x,k) + C(x,k-1).
            assert_eq!(
                binomial(x.clone() + z(1), k),
                binomial(x.clone(), k) + binomial(x.clone(), k - 1)
            );
            // (2.5.6): ∇_x C(x,k) = C(x-1,k-1); (2.5.7): Δ_x C(x,k) = C(x,k-1).
            assert_eq!(
                binomial(x.clone(), k) - binomial(x.clone() - z(1), k),
                binomial(x.clone() - z(1), k - 1)
            );
            assert_eq!(
                binomial(x.clone() + z(1), k) - binomial(x.clone(), k),
                binomial(x.clone(), k - 1)
            );
        }
    }
    // Vandermonde (2.6.15) and Ex 2.18a/b.
    for m in 0..=12usize {
        for j in 0..=m {
            for k in 0..=m {
                let s = (0..=k).fold(Q::zero(), |a, nu| {
                    a + choose::<Q>(j, nu) * choose::<Q>(m - j, k - nu)
                });
                assert_eq!(s, choose::<Q>(m, k), "(2.6.15) m={m}, j={j}, k={k}");
            }
        }
    }
    assert_eq!(choose::<Q>(6, 3), z(20));
    for i in 0..=10usize {
        for j in 0..=10usize {
            let s = (0..=j).fold(Q::zero(), |a, nu| {
                a + choose::<Q>(i, nu) * choose::<Q>(j, nu)
            });
            assert_eq!(s, choose::<Q>(i + j, i), "Ex 2.18b");
        }
    }
}

#[test]
fn power_sums_at_l_10_and_by_the_stirling_route_2_7_14() {
    // Source: Morrison (2.7.14), (2.7.17), values at L = 10.
    let printed: [i64; 11] = [
        11,
        55,
        385,
        3025,
        25333,
        220825,
        1978405,
        18080425,
        167731333,
        1574304985,
        14914341925,
    ];
    let s1 = stirling1::<Q>(10);
    let s2 = stirling2::<Q>(10);
    for l in 0..=30i64 {
        let lq = z(l);
        for k in 0..=10usize {
            // Brute force Σ_{n=0}^{L} n^k.
            let brute = (0..=l).fold(Q::zero(), |a, n| a + qpow(&z(n), k));
            if l == 10 {
                assert_eq!(brute, z(printed[k]), "printed S_{k}(10)");
            }
            // (2.7.14): S_k(L) = (L+1) Σ_j [S2]_kj (1/(j+1)) Σ_ν [S1]_jν L^ν, with the library's
            // Stirling matrices.
            let route = (z(l) + z(1))
                * (0..=k).fold(Q::zero(), |a, j| {
                    let inner =
                        (0..=j).fold(Q::zero(), |b, nu| b + s1[(j, nu)].clone() * qpow(&lq, nu));
                    a + s2[(k, j)].clone() * inner / z(j as i64 + 1)
                });
            assert_eq!(route, brute, "S_{k}({l}) by (2.7.14)");
        }
        // (2.7.10)/(2.7.13): Σ_{n=0}^{L} n^(j) = (L+1)^(j+1)/(j+1), with the library's factorial.
        for j in 0..=8usize {
            let brute = (0..=l).fold(Q::zero(), |a, n| a + ff(&z(n), j));
            let closed = falling_factorial(z(l + 1), j + 1) / z(j as i64 + 1);
            assert_eq!(closed, brute, "(2.7.10) L = {l}, j = {j}");
        }
    }
}

#[test]
fn difference_table_tv2_1_and_annihilation_2_5_17() {
    // Source: Morrison p. 18-19 difference tables (TV2.1), (2.5.13), (2.5.17)-(2.5.21), TV2.4.
    // f_n = n^3 - 2n, n = -2..3.
    let f: Vec<Q> = (-2i64..=3).map(|n| z(n * n * n - 2 * n)).collect();
    assert_eq!(f, vec![z(-4), z(1), z(0), z(-1), z(4), z(21)]);
    // Backward table, row n: f, ∇f, ∇²f, ... (as many as the data allow).
    let rows: [(i64, &[i64]); 5] = [
        (-1, &[1, 5]),
        (0, &[0, -1, -6]),
        (1, &[-1, -1, 0, 6]),
        (2, &[4, 5, 6, 6, 0]),
        (3, &[21, 17, 12, 6, 0]),
    ];
    for (n, want) in rows {
        let idx = (n + 2) as usize;
        for (k, w) in want.iter().enumerate() {
            assert_eq!(
                backward_difference(&f[..=idx], k),
                Some(z(*w)),
                "∇^{k} f_{n}"
            );
        }
        assert_eq!(backward_difference(&f[..=idx], idx + 1), None);
    }
    // Forward table: Δ^k f_n = ∇^k f_{n+k}. Row n = -2: Δ..Δ^4 = 5, -6, 6, 0; n = -1: -1, 0, 6, 0.
    let fwd: [(i64, &[i64]); 2] = [(-2, &[5, -6, 6, 0]), (-1, &[-1, 0, 6, 0])];
    for (n, want) in fwd {
        for (k0, w) in want.iter().enumerate() {
            let k = k0 + 1;
            let end = (n + 2) as usize + k;
            assert_eq!(
                backward_difference(&f[..=end], k),
                Some(z(*w)),
                "Δ^{k} f_{n}"
            );
        }
    }
    // f64 version.
    let ff64: Vec<f64> = (-2i32..=3).map(|n| (n * n * n - 2 * n) as f64).collect();
    assert_eq!(backward_difference(&ff64, 3), Some(6.0));
    // TV2.4 (2.6.4): 49 - 3·64 + 3·81 - 100 = 0 (∇³ of n² at n = 10); Ex 2.15: n²-2n+4.
    let sq: Vec<Q> = [49, 64, 81, 100].iter().map(|v| z(*v)).collect();
    assert_eq!(backward_difference(&sq, 3), Some(z(0)));
    let ex215: Vec<Q> = (0..=5i64).map(|n| z(n * n - 2 * n + 4)).collect();
    assert_eq!(ex215, vec![z(4), z(3), z(4), z(7), z(12), z(19)]);
    assert_eq!(backward_difference(&ex215, 2), Some(z(2)));
    assert_eq!(backward_difference(&ex215, 3), Some(z(0)));
    assert_eq!(backward_difference(&ex215, 4), Some(z(0)));
    // (2.5.17): ∇^m annihilates every polynomial of degree < m; ∇^d of degree d gives d!·lead.
    let poly = qrow(&["2", "-3/4", "5", "1/6", "-2", "7/5", "1"]); // degree 6, leading 1
    for m in 0..=9usize {
        let seq: Vec<Q> = (0..=m as i64).map(|n| peval(&poly, &z(n - 3))).collect();
        let d = backward_difference(&seq, m).unwrap();
        match m.cmp(&6) {
            std::cmp::Ordering::Greater => assert!(d.is_zero(), "∇^{m} of a sextic"),
            std::cmp::Ordering::Equal => assert_eq!(d, fact(6)),
            std::cmp::Ordering::Less => {}
        }
    }
}

#[test]
fn newton_backward_interpolation_tv2_3() {
    // Source: Morrison (2.5.23)-(2.5.29), TV2.3: f_n = 1.5^n, differences at n = 4.
    let f: Vec<Q> = (0..=4).map(|n| qpow(&fr(3, 2), n)).collect();
    let want = ["5.0625", "1.6875", "0.5625", "0.1875", "0.0625"];
    let d: Vec<Q> = (0..=4)
        .map(|k| backward_difference(&f, k).unwrap())
        .collect();
    for (k, w) in want.iter().enumerate() {
        assert_eq!(d[k], q(w), "∇^{k} f_4");
    }
    // f_{n-h} = Σ_k (-1)^k C(h,k) ∇^k f_n with the library's binomial at h = 1/2 and h = -1.
    let newton = |h: Q, order: usize| {
        (0..=order).fold(Q::zero(), |a, k| {
            a + sign(k) * binomial(h.clone(), k) * d[k].clone()
        })
    };
    assert_eq!(newton(fr(1, 2), 2), q("4.1484375"));
    assert_eq!(newton(fr(1, 2), 3), q("4.13671875"));
    assert_eq!(newton(fr(1, 2), 4), q("4.13427734375"));
    assert_eq!(newton(z(-1), 4), q("7.5625"));
}
