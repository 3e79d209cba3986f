//! Conformance tests for the exact foundations: discrete calculus (Morrison ch. 2), discrete
//! orthogonal polynomials (ch. 3, Appendix I), transition and link matrices (ch. 4), and the
//! classical Legendre basis.
//!
//! Oracles are the printed tables and formulas of Morrison (1969), transcribed here by hand (see
//! /work/shared/spec/ch02-06.md, ch07-09.md), or independent computations written in this file
//! (brute-force sums, explicit polynomials built from the book's defining formulas, own matrix
//! products). Every comparison is exact (`BigRational`) unless the API is `f64`-only.

use nalgebra::DMatrix;
use num_bigint::BigInt;
use num_traits::{One, Signed, Zero};
use seqsmooth::basis::{legendre, DiscreteLaguerre, DiscreteLegendre};
use seqsmooth::calculus::{
    backward_difference, binomial, choose, factorial, falling_factorial, link_matrix,
    link_matrix_inverse, rising_factorial, stirling1, stirling2,
};
use seqsmooth::linalg::{congruence, inverse_exact, mul};
use seqsmooth::model::{
    derivatives_to_scaled, phi, psi, scaled_to_derivatives, scaling, shift_scaled, PolynomialState,
};
use seqsmooth::scalar::{parse_rational, Rational};

type Q = Rational;

// ---------------------------------------------------------------------------------------------
// Independent helpers (deliberately not the library's).
// ---------------------------------------------------------------------------------------------

fn z(v: i64) -> Q {
    Q::from_integer(BigInt::from(v))
}

fn fr(n: i64, d: i64) -> Q {
    Q::new(BigInt::from(n), BigInt::from(d))
}

fn q(s: &str) -> Q {
    parse_rational(s).unwrap_or_else(|| panic!("bad rational literal {s}"))
}

fn qpow(x: &Q, k: usize) -> Q {
    let mut a = Q::one();
    for _ in 0..k {
        a *= x.clone();
    }
    a
}

fn sign(k: usize) -> Q {
    if k % 2 == 0 {
        Q::one()
    } else {
        -Q::one()
    }
}

/// x (x-1) ... (x-k+1), computed here.
fn ff(x: &Q, k: usize) -> Q {
    (0..k).fold(Q::one(), |a, i| a * (x.clone() - z(i as i64)))
}

/// x (x+1) ... (x+k-1), computed here.
fn rf(x: &Q, k: usize) -> Q {
    (0..k).fold(Q::one(), |a, i| a * (x.clone() + z(i as i64)))
}

fn fact(k: usize) -> Q {
    (1..=k).fold(Q::one(), |a, i| a * z(i as i64))
}

/// Binomial C(x, k) for any rational x (Morrison (2.5.1)), computed here.
fn bin(x: &Q, k: usize) -> Q {
    ff(x, k) / fact(k)
}

/// Integer binomial C(n, k), zero outside 0 <= k <= n.
fn c(n: i64, k: i64) -> Q {
    if k < 0 || n < 0 || k > n {
        Q::zero()
    } else {
        bin(&z(n), k as usize)
    }
}

// Dense polynomials, lowest power first.
fn padd(a: &[Q], b: &[Q]) -> Vec<Q> {
    let n = a.len().max(b.len());
    (0..n)
        .map(|k| {
            a.get(k).cloned().unwrap_or_else(Q::zero) + b.get(k).cloned().unwrap_or_else(Q::zero)
        })
        .collect()
}

fn pmul(a: &[Q], b: &[Q]) -> Vec<Q> {
    let mut out = vec![Q::zero(); a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            out[i + j] = out[i + j].clone() + x.clone() * y.clone();
        }
    }
    out
}

fn pscale(a: &[Q], s: &Q) -> Vec<Q> {
    a.iter().map(|x| x.clone() * s.clone()).collect()
}

fn peval(a: &[Q], x: &Q) -> Q {
    a.iter()
        .rev()
        .fold(Q::zero(), |acc, c| acc * x.clone() + c.clone())
}

/// i-th derivative.
fn pderiv(a: &[Q], i: usize) -> Vec<Q> {
    if i >= a.len() {
        return vec![Q::zero()];
    }
    (i..a.len())
        .map(|k| a[k].clone() * ff(&z(k as i64), i))
        .collect()
}

/// The falling factorial x^(k) as a power-basis polynomial.
fn falling_poly(k: usize) -> Vec<Q> {
    (0..k).fold(vec![Q::one()], |p, i| pmul(&p, &[z(-(i as i64)), Q::one()]))
}

/// Morrison (3.2.20): p(x; j, L) = Σ_ν (-1)^ν C(j,ν) C(j+ν,ν) x^(ν) / L^(ν), built here.
fn legendre_explicit(j: usize, l: &Q) -> Vec<Q> {
    (0..=j).fold(vec![Q::zero()], |acc, nu| {
        let coef = sign(nu) * c(j as i64, nu as i64) * c((j + nu) as i64, nu as i64) / ff(l, nu);
        padd(&acc, &pscale(&falling_poly(nu), &coef))
    })
}

fn mm(a: &DMatrix<Q>, b: &DMatrix<Q>) -> DMatrix<Q> {
    assert_eq!(a.ncols(), b.nrows());
    DMatrix::from_fn(a.nrows(), b.ncols(), |i, j| {
        (0..a.ncols()).fold(Q::zero(), |s, k| s + a[(i, k)].clone() * b[(k, j)].clone())
    })
}

fn eye(n: usize) -> DMatrix<Q> {
    DMatrix::from_fn(n, n, |i, j| if i == j { Q::one() } else { Q::zero() })
}

fn rows_to_matrix(rows: &[&[Q]]) -> DMatrix<Q> {
    DMatrix::from_fn(rows.len(), rows[0].len(), |i, j| rows[i][j].clone())
}

fn qrow(xs: &[&str]) -> Vec<Q> {
    xs.iter().map(|s| q(s)).collect()
}

// ---------------------------------------------------------------------------------------------
// Chapter 2: Stirling matrices (Tables 2.1, 2.2)
// ---------------------------------------------------------------------------------------------

/// Morrison Table 2.1 (signed Stirling numbers of the first kind), rows 0..10, as reconstructed
/// from (2.4.9) in spec ch02-06.md §1.3 (the printed table is scrambled in the OCR).
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

/// Morrison Table 2.2 (Stirling numbers of the second kind), rows 0..10 (spec ch02-06.md §1.3).
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
    // Source: Morrison Table 2.1 / (2.4.8)-(2.4.10); spec ch02-06.md §1.3 (TV2.2).
    let want = lower_table(&TABLE_2_1);
    let got = stirling1::<Q>(10);
    assert_eq!(got, want);
    let got_f = stirling1::<f64>(10);
    for i in 0..=10 {
        for j in 0..=10 {
            assert_eq!(
                got_f[(i, j)],
                crate_f64(&want[(i, j)]),
                "S1[{i},{j}] in f64"
            );
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

fn crate_f64(v: &Q) -> f64 {
    seqsmooth::scalar::ratio_to_f64(v)
}

#[test]
fn table_2_2_stirling_second_kind_rows_0_to_10() {
    // Source: Morrison Table 2.2 / (2.4.13)-(2.4.15); spec ch02-06.md §1.3.
    let want = lower_table(&TABLE_2_2);
    assert_eq!(stirling2::<Q>(10), want);
    let got_f = stirling2::<f64>(10);
    for i in 0..=10 {
        for j in 0..=10 {
            assert_eq!(
                got_f[(i, j)],
                crate_f64(&want[(i, j)]),
                "S2[{i},{j}] in f64"
            );
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
    // Source: Morrison (2.4.13) "S2 = S1^-1"; spec ch02-06.md §1.3 "Sst1 * Sst2 = I (11x11)".
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

// ---------------------------------------------------------------------------------------------
// Chapter 4: link matrices (Tables 4.1, 4.2)
// ---------------------------------------------------------------------------------------------

/// Morrison Table 4.1 (link matrix 𝒮), row i lists columns j = i..10 (row 0 lists j = 0..10).
/// Row 4, column 8 is printed 6169 in the OCR; the correct value is 6769 (spec ch02-06.md §4.3).
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
    // Source: Morrison Table 4.1 and the Chapter 4 notes; spec ch02-06.md §4.3, T7-27.
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
    // Source: Morrison Table 4.2, (4.4.5), (4.4.9); spec ch02-06.md §4.3, check 5 of §8.
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
    // [DERIVED] x = n^3 at n = 0, τ = 1: V^f = (0,1,3,1), V = (0,1,-3,1), Z = (0,0,0,1) from both.
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

// ---------------------------------------------------------------------------------------------
// Chapter 2: factorials, binomials, sums, differences
// ---------------------------------------------------------------------------------------------

#[test]
fn factorial_function_identities_2_4_19_and_2_4_20() {
    // Source: Morrison (2.4.1)-(2.4.3), (2.4.19), (2.4.20), Ex 2.10, Ex 2.7a; spec ch02-06.md §1.3.
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
    // Source: Morrison (2.5.1)-(2.5.7), Ex 2.11, (2.6.15), Ex 2.18; spec ch02-06.md §1.4-1.5, TV2.5.
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
    // Source: Morrison (2.7.14), (2.7.17); spec ch02-06.md §1.6 values at L = 10, TV2.6.
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

// ---------------------------------------------------------------------------------------------
// Chapter 3 and Appendix I: discrete Legendre polynomials
// ---------------------------------------------------------------------------------------------

fn sample_points(l: i64) -> Vec<Q> {
    let mut xs: Vec<Q> = (0..=l).map(z).collect();
    xs.extend([fr(1, 2), z(-1), fr(7, 3), z(l + 1), fr(-5, 4)]);
    xs
}

#[test]
fn discrete_legendre_explicit_p0_to_p4_3_2_21() {
    // Source: Morrison (3.2.21) and the [DERIVED] factored forms of p2, p3 (spec ch02-06.md §2.1).
    for l in [4i64, 5, 7, 10, 13] {
        let lq = z(l);
        let b = DiscreteLegendre::new(lq.clone());
        for x in sample_points(l) {
            let r = |k: usize| ff(&x, k) / ff(&lq, k);
            let book = [
                z(1),
                z(1) - z(2) * x.clone() / lq.clone(),
                z(1) - z(6) * r(1) + z(6) * r(2),
                z(1) - z(12) * r(1) + z(30) * r(2) - z(20) * r(3),
                z(1) - z(20) * r(1) + z(90) * r(2) - z(140) * r(3) + z(70) * r(4),
            ];
            for (j, want) in book.iter().enumerate() {
                assert_eq!(b.value(j, x.clone()), *want, "p_{j}({x}; L = {l})");
                assert_eq!(
                    b.polynomial(j).eval(&x),
                    *want,
                    "polynomial p_{j}({x}; L = {l})"
                );
            }
            let p2 = (lq.clone() * lq.clone() - z(6) * lq.clone() * x.clone() - lq.clone()
                + z(6) * x.clone() * x.clone())
                / (lq.clone() * (lq.clone() - z(1)));
            let p3 = (lq.clone() - z(2) * x.clone())
                * (lq.clone() * lq.clone() - z(10) * lq.clone() * x.clone() - z(3) * lq.clone()
                    + z(10) * x.clone() * x.clone()
                    + z(2))
                / (lq.clone() * (lq.clone() - z(1)) * (lq.clone() - z(2)));
            assert_eq!(b.value(2, x.clone()), p2);
            assert_eq!(b.value(3, x.clone()), p3);
        }
    }
    // TV3.1 printed values p_j(r), r = 0..L, and c_j².
    let tv: [(i64, usize, &[&str], &str); 11] = [
        (2, 0, &["1", "1", "1"], "3"),
        (2, 1, &["1", "0", "-1"], "2"),
        (2, 2, &["1", "-2", "1"], "6"),
        (3, 1, &["1", "1/3", "-1/3", "-1"], "20/9"),
        (3, 2, &["1", "-1", "-1", "1"], "4"),
        (3, 3, &["1", "-3", "3", "-1"], "20"),
        (4, 2, &["1", "-1/2", "-1", "-1/2", "1"], "7/2"),
        (4, 4, &["1", "-4", "6", "-4", "1"], "70"),
        (5, 2, &["1", "-1/5", "-4/5", "-4/5", "-1/5", "1"], "84/25"),
        (5, 3, &["1", "-7/5", "-4/5", "4/5", "7/5", "-1"], "36/5"),
        (5, 5, &["1", "-5", "10", "-10", "5", "-1"], "252"),
    ];
    for (l, j, vals, norm) in tv {
        let b = DiscreteLegendre::new(z(l));
        for (r, v) in vals.iter().enumerate() {
            assert_eq!(b.value(j, z(r as i64)), q(v), "TV3.1 p_{j}({r}; {l})");
        }
        assert_eq!(b.norm_sq(j), q(norm), "TV3.1 c_{j}²(L = {l})");
    }
}

#[test]
fn discrete_legendre_orthogonality_and_norms_3_2_30() {
    // Source: Morrison (3.2.1), (3.2.20), (3.2.30), (3.2.31); TV3.1 L = 10 norms.
    for l in 1..=14i64 {
        let lq = z(l);
        let b = DiscreteLegendre::new(lq.clone());
        let jmax = (l as usize).min(8);
        // Values from the library, checked against the explicit polynomial built here.
        let vals: Vec<Vec<Q>> = (0..=jmax)
            .map(|j| {
                let explicit = legendre_explicit(j, &lq);
                (0..=l)
                    .map(|x| {
                        let v = b.value(j, z(x));
                        assert_eq!(v, peval(&explicit, &z(x)), "(3.2.20) p_{j}({x}; {l})");
                        v
                    })
                    .collect()
            })
            .collect();
        for i in 0..=jmax {
            for j in 0..=jmax {
                let s = (0..=l as usize).fold(Q::zero(), |a, x| {
                    a + vals[i][x].clone() * vals[j][x].clone()
                });
                if i == j {
                    // (3.2.30): c_j² = (L+j+1)^(j+1) / ((2j+1) L^(j)).
                    let cj = ff(&(lq.clone() + z(j as i64 + 1)), j + 1)
                        / (z(2 * j as i64 + 1) * ff(&lq, j));
                    assert_eq!(s, cj, "Σ p_{j}² for L = {l}");
                    assert_eq!(b.norm_sq(j), cj, "norm_sq({j}) for L = {l}");
                } else {
                    assert!(s.is_zero(), "Σ p_{i} p_{j} = {s} for L = {l}");
                }
            }
        }
        // (3.2.31): c0..c4² explicitly (each defined only for j <= L).
        let c31 = |j: usize| match j {
            0 => lq.clone() + z(1),
            1 => (lq.clone() + z(2)) * (lq.clone() + z(1)) / (z(3) * lq.clone()),
            2 => {
                (lq.clone() + z(3)) * (lq.clone() + z(2)) * (lq.clone() + z(1))
                    / (z(5) * lq.clone() * (lq.clone() - z(1)))
            }
            3 => rf(&(lq.clone() + z(1)), 4) / (z(7) * ff(&lq, 3)),
            _ => rf(&(lq.clone() + z(1)), 5) / (z(9) * ff(&lq, 4)),
        };
        for j in 0..=jmax.min(4) {
            assert_eq!(b.norm_sq(j), c31(j), "(3.2.31) c_{j}², L = {l}");
        }
    }
    let b10 = DiscreteLegendre::new(z(10));
    for (j, s) in ["11", "22/5", "286/75", "143/30", "143/18"]
        .iter()
        .enumerate()
    {
        assert_eq!(b10.norm_sq(j), q(s), "TV3.1 L = 10, c_{j}²");
    }
}

#[test]
fn discrete_legendre_end_values_symmetry_and_leading_coefficient() {
    // Source: spec ch02-06.md §2.1 [DERIVED, verified]: p_j(0) = 1, p_j(L) = (-1)^j,
    // p_j(L-x) = (-1)^j p_j(x); Morrison (3.2.26) leading coefficient (-1)^j C(2j,j)/L^(j).
    for l in 1..=15i64 {
        let lq = z(l);
        let b = DiscreteLegendre::new(lq.clone());
        for j in 0..=(l as usize).min(10) {
            assert_eq!(b.value(j, z(0)), z(1));
            assert_eq!(b.value(j, lq.clone()), sign(j), "p_{j}(L) for L = {l}");
            for x in [z(1), fr(1, 3), fr(-7, 2), z(l + 3)] {
                assert_eq!(
                    b.value(j, lq.clone() - x.clone()),
                    sign(j) * b.value(j, x.clone()),
                    "symmetry, j = {j}, L = {l}, x = {x}"
                );
            }
            let poly = b.polynomial(j);
            let lead = poly.coeffs.get(j).cloned().unwrap_or_else(Q::zero);
            assert_eq!(
                lead,
                sign(j) * c(2 * j as i64, j as i64) / ff(&lq, j),
                "(3.2.26)"
            );
            assert!(poly.coeffs.iter().skip(j + 1).all(|v| v.is_zero()));
        }
    }
}

#[test]
fn appendix_recursion_a1_1_matches_explicit_derivatives() {
    // Source: Morrison Appendix I (A1.1)-(A1.6); spec ch02-06.md §3. Oracle: derivatives of the
    // explicit (3.2.20) polynomial built in this file.
    for l in [z(8), z(9), z(12), z(20), fr(25, 2)] {
        let b = DiscreteLegendre::new(l.clone());
        let explicit: Vec<Vec<Q>> = (0..=8).map(|j| legendre_explicit(j, &l)).collect();
        for x in [
            z(0),
            l.clone(),
            l.clone() / z(2),
            fr(7, 3),
            z(-1),
            l.clone() + z(1),
        ] {
            let d = b.derivatives_by_recursion(8, 3, &x);
            assert_eq!((d.nrows(), d.ncols()), (9, 4));
            for (j, p) in explicit.iter().enumerate() {
                for i in 0..=3 {
                    let want = peval(&pderiv(p, i), &x);
                    assert_eq!(d[(j, i)], want, "d^{i} p_{j}({x}; L = {l})");
                }
            }
        }
    }
    // f64 instantiation agrees with the exact one.
    let bf = DiscreteLegendre::new(20.0_f64);
    let be = DiscreteLegendre::new(z(20));
    let df = bf.derivatives_by_recursion(8, 3, &20.0);
    let de = be.derivatives_by_recursion(8, 3, &z(20));
    for j in 0..=8 {
        for i in 0..=3 {
            let e = crate_f64(&de[(j, i)]);
            assert!(
                (df[(j, i)] - e).abs() <= 1e-12 * e.abs().max(1e-3),
                "f64 ({j},{i})"
            );
        }
    }
}

/// Morrison Table 7.1: the integer parts (-1)^j C(j,i) C(j+i,i) of [G]_ij · L^(i), rows i,
/// columns j = i..10 (spec ch07-09.md §1.4, rebuilt from (7.4.14)).
const TABLE_7_1: [&[i64]; 11] = [
    &[1, -1, 1, -1, 1, -1, 1, -1, 1, -1, 1],
    &[-2, 6, -12, 20, -30, 42, -56, 72, -90, 110],
    &[6, -30, 90, -210, 420, -756, 1260, -1980, 2970],
    &[-20, 140, -560, 1680, -4200, 9240, -18480, 34320],
    &[70, -630, 3150, -11550, 34650, -90090, 210210],
    &[-252, 2772, -16632, 72072, -252252, 756756],
    &[924, -12012, 84084, -420420, 1681680],
    &[-3432, 51480, -411840, 2333760],
    &[12870, -218790, 1969110],
    &[-48620, 923780],
    &[184756],
];

#[test]
fn end_differences_a1_7_match_backward_differences_and_table_7_1() {
    // Source: Morrison (A1.7)/(A1.18), (7.4.13)-(7.4.14), Table 7.1; T7-25.
    // Oracle: (1/i!) ∇^i p_j(x) at x = L by the difference sum (2.5.13) over the explicit
    // polynomial built here.
    for l in [8i64, 10, 15, 31] {
        let lq = z(l);
        let g = DiscreteLegendre::new(lq.clone()).end_differences(8);
        for j in 0..=8usize {
            let p = legendre_explicit(j, &lq);
            for i in 0..=8usize {
                let nabla = (0..=i).fold(Q::zero(), |a, k| {
                    a + sign(k) * c(i as i64, k as i64) * peval(&p, &(lq.clone() - z(k as i64)))
                });
                assert_eq!(g[(i, j)], nabla / fact(i), "G[{i},{j}] for L = {l}");
            }
        }
    }
    // Table 7.1 integers: [G]_ij L^(i) for i, j <= 10 (upper triangle; zero below).
    for l in [10i64, 13] {
        let lq = z(l);
        let g = DiscreteLegendre::new(lq.clone()).end_differences(10);
        for i in 0..=10usize {
            for j in 0..=10usize {
                let want = if j < i {
                    Q::zero()
                } else {
                    z(TABLE_7_1[i][j - i])
                };
                assert_eq!(g[(i, j)].clone() * ff(&lq, i), want, "Table 7.1 ({i},{j})");
            }
        }
    }
    // Book examples: [G]_{3,5} = -560/L^(3), [G]_{7,8} = 51480/L^(7).
    let g = DiscreteLegendre::new(z(12)).end_differences(8);
    assert_eq!(g[(3, 5)], z(-560) / ff(&z(12), 3));
    assert_eq!(g[(7, 8)], z(51480) / ff(&z(12), 7));
}

#[test]
fn taylor_matrix_p_equals_link_times_g_7_4_15() {
    // Source: Morrison (7.4.4), (7.4.15): [P]_ij = (1/i!) d^i p_j/dr^i at r = L equals (𝒮 G)_ij
    // (T7-09). Oracle: Taylor coefficients of the explicit polynomial built here.
    for l in [6i64, 9, 14, 40] {
        let lq = z(l);
        let b = DiscreteLegendre::new(lq.clone());
        let m = 6;
        let p = mm(&link_matrix::<Q>(m), &b.end_differences(m));
        for j in 0..=m {
            let e = legendre_explicit(j, &lq);
            for i in 0..=m {
                let want = peval(&pderiv(&e, i), &lq) / fact(i);
                assert_eq!(p[(i, j)], want, "P[{i},{j}] for L = {l}");
                assert_eq!(b.taylor(i, j, &lq), want, "taylor({i},{j}) at L = {l}");
            }
        }
    }
}

#[test]
fn inverse_relation_a1_25_and_a1_26() {
    // Source: Morrison (A1.25): x^(j) = (L^(j)/C(2j,j)) Σ_ν (-1)^ν ((2ν+1)/(2j+1)) C(2j+1,j-ν) p_ν(x);
    // (A1.26): x^(2) = L^(2) [p0/3 - p1/2 + p2/6]; TV3.4.
    for l in [6i64, 9, 16] {
        let lq = z(l);
        let b = DiscreteLegendre::new(lq.clone());
        for j in 0..=6usize {
            for x in [z(0), z(3), fr(5, 2), z(-2), z(l)] {
                let s = (0..=j).fold(Q::zero(), |a, nu| {
                    a + sign(nu) * z(2 * nu as i64 + 1) / z(2 * j as i64 + 1)
                        * c(2 * j as i64 + 1, (j - nu) as i64)
                        * b.value(nu, x.clone())
                });
                let rhs = ff(&lq, j) / c(2 * j as i64, j as i64) * s;
                assert_eq!(rhs, ff(&x, j), "(A1.25) j = {j}, L = {l}, x = {x}");
            }
            let x = fr(11, 3);
            let a126 = ff(&lq, 2)
                * (b.value(0, x.clone()) / z(3) - b.value(1, x.clone()) / z(2)
                    + b.value(2, x.clone()) / z(6));
            assert_eq!(a126, ff(&x, 2));
        }
    }
}

#[test]
fn fixed_memory_weights_from_basis_pieces_tv3_5_t7_06() {
    // Source: Morrison (7.4.16)-(7.4.17): W(h) = Φ(h) 𝒮 G C B with [B]_ij = p_i(L-j),
    // C = diag(1/c_j²); TV3.5 / T7-01 / T7-02 (m = 1, L = 4), T7-06 (m = 2, L = 4, ×1/35).
    let weights = |m: usize, l: i64, h: Q| {
        let b = DiscreteLegendre::new(z(l));
        let cm = DMatrix::from_fn(m + 1, m + 1, |i, j| {
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
                &cm,
            ),
            &bm,
        )
    };
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

// ---------------------------------------------------------------------------------------------
// Chapter 3: discrete Laguerre polynomials
// ---------------------------------------------------------------------------------------------

/// Morrison (3.3.9): p(x; j, θ) = Σ_ν (-1)^(j-ν) C(j,ν) θ^ν C(x+ν, j).
fn laguerre_3_3_9(j: usize, th: &Q, x: &Q) -> Q {
    (0..=j).fold(Q::zero(), |a, nu| {
        a + sign(j - nu)
            * c(j as i64, nu as i64)
            * qpow(th, nu)
            * bin(&(x.clone() + z(nu as i64)), j)
    })
}

/// Morrison (3.3.10): p(x; j, θ) = θ^j Σ_ν (-1)^ν C(j,ν) ((1-θ)/θ)^ν C(x,ν).
fn laguerre_3_3_10(j: usize, th: &Q, x: &Q) -> Q {
    let a = (z(1) - th.clone()) / th.clone();
    qpow(th, j)
        * (0..=j).fold(Q::zero(), |s, nu| {
            s + sign(nu) * c(j as i64, nu as i64) * qpow(&a, nu) * bin(x, nu)
        })
}

const THETAS: [(i64, i64); 6] = [(1, 2), (9, 10), (1, 3), (3, 5), (7, 8), (99, 100)];

#[test]
fn discrete_laguerre_explicit_forms_3_3_9_and_3_3_10() {
    // Source: Morrison (3.3.9), (3.3.10), (3.3.11), (13.2.2).
    for (n, d) in THETAS {
        let th = fr(n, d);
        let b = DiscreteLaguerre::new(th.clone());
        assert_eq!(b.theta(), &th);
        let mut xs: Vec<Q> = (0..=10).map(z).collect();
        xs.extend([z(-1), fr(5, 2), fr(-7, 3), z(37)]);
        for j in 0..=8usize {
            for x in &xs {
                let a = laguerre_3_3_9(j, &th, x);
                let b10 = laguerre_3_3_10(j, &th, x);
                assert_eq!(a, b10, "(3.3.9) vs (3.3.10), j = {j}, θ = {th}, x = {x}");
                assert_eq!(b.value(j, x.clone()), a, "value({j}, {x}), θ = {th}");
                assert_eq!(b.polynomial(j).eval(x), a);
            }
        }
        // (3.3.11) first members: p1 = θ[1 - a x], p2 = θ²[1 - 2ax + a² x(x-1)/2].
        let a = (z(1) - th.clone()) / th.clone();
        for x in &xs {
            assert_eq!(
                b.value(1, x.clone()),
                th.clone() * (z(1) - a.clone() * x.clone())
            );
            assert_eq!(
                b.value(2, x.clone()),
                th.clone()
                    * th.clone()
                    * (z(1) - z(2) * a.clone() * x.clone()
                        + a.clone() * a.clone() * ff(x, 2) / z(2))
            );
        }
    }
}

#[test]
fn discrete_laguerre_printed_values_tv3_2() {
    // Source: spec ch02-06.md TV3.2 [DERIVED from (3.3.10)], x = 0..5.
    let cases: [(&str, usize, [&str; 6]); 5] = [
        ("1/2", 1, ["1/2", "0", "-1/2", "-1", "-3/2", "-2"]),
        ("1/2", 2, ["1/4", "-1/4", "-1/2", "-1/2", "-1/4", "1/4"]),
        ("1/2", 3, ["1/8", "-1/4", "-1/4", "0", "3/8", "3/4"]),
        ("9/10", 1, ["9/10", "4/5", "7/10", "3/5", "1/2", "2/5"]),
        (
            "9/10",
            2,
            ["81/100", "63/100", "23/50", "3/10", "3/20", "1/100"],
        ),
    ];
    for (th, j, vals) in cases {
        let b = DiscreteLaguerre::new(q(th));
        for (x, v) in vals.iter().enumerate() {
            assert_eq!(b.value(j, z(x as i64)), q(v), "TV3.2 p_{j}({x}; {th})");
        }
    }
    let b = DiscreteLaguerre::new(fr(1, 2));
    for (j, s) in ["2", "1", "1/2", "1/4"].iter().enumerate() {
        assert_eq!(b.norm_sq(j), q(s));
    }
    let b = DiscreteLaguerre::new(fr(9, 10));
    for (j, s) in ["10", "9", "81/10", "729/100"].iter().enumerate() {
        assert_eq!(b.norm_sq(j), q(s));
    }
}

/// Σ_{x>=0} f(x) θ^x for a polynomial f of degree <= deg, exactly: by Newton's forward series
/// f(x) = Σ_ν Δ^ν f(0) C(x,ν) (Ex 2.14) and Σ_x C(x,ν) θ^x = θ^ν/(1-θ)^(ν+1) (Ex 3.11, (3.3.15)).
fn weighted_series_sum(f: impl Fn(&Q) -> Q, deg: usize, th: &Q) -> Q {
    let mut vals: Vec<Q> = (0..=deg).map(|x| f(&z(x as i64))).collect();
    let om = z(1) - th.clone();
    let mut total = Q::zero();
    for nu in 0..=deg {
        total += vals[0].clone() * qpow(th, nu) / qpow(&om, nu + 1);
        vals = vals
            .windows(2)
            .map(|w| w[1].clone() - w[0].clone())
            .collect();
    }
    total
}

#[test]
fn discrete_laguerre_orthogonality_and_norms_3_3_16() {
    // Source: Morrison (3.3.1), (3.3.12), (3.3.16): Σ_{x>=0} p_i p_j θ^x = δ_ij θ^j/(1-θ);
    // spec others.md §4.1 (θ = 1/3 and 3/5); TV3.2.
    // (a) Exact infinite sums by the closed form of `weighted_series_sum`, j <= 6.
    for (n, d) in THETAS {
        let th = fr(n, d);
        let b = DiscreteLaguerre::new(th.clone());
        for i in 0..=6usize {
            for j in 0..=6usize {
                let s = weighted_series_sum(
                    |x| b.value(i, x.clone()) * b.value(j, x.clone()),
                    i + j,
                    &th,
                );
                let want = if i == j {
                    qpow(&th, j) / (z(1) - th.clone())
                } else {
                    Q::zero()
                };
                assert_eq!(s, want, "θ = {th}, ({i},{j})");
                if i == j {
                    assert_eq!(b.norm_sq(j), want);
                }
            }
        }
    }
    // (b) Brute-force partial sums to x = 400 in exact arithmetic, θ = 1/3 and 3/5, j <= 4.
    // Tail bound: |p_j(x)| <= Σ_ν C(j,ν) θ^(j-ν) (1-θ)^ν x^ν/ν! <= (1+x)^j, so the tail beyond 400
    // is below Σ_{x>400} (1+x)^8 θ^x < 401^8 θ^401 / (1 - θ(402/401)^8) < 1e-60.
    for th in [fr(1, 3), fr(3, 5)] {
        let b = DiscreteLaguerre::new(th.clone());
        let mut sums = vec![vec![Q::zero(); 5]; 5];
        let mut w = Q::one();
        for x in 0..=400i64 {
            let p: Vec<Q> = (0..=4).map(|j| b.value(j, z(x))).collect();
            for (i, row) in sums.iter_mut().enumerate() {
                for (j, cell) in row.iter_mut().enumerate().skip(i) {
                    *cell += p[i].clone() * p[j].clone() * w.clone();
                }
            }
            w *= th.clone();
        }
        let eps = fr(1, 1) / Q::from_integer(num_traits::pow(BigInt::from(10), 60));
        for (i, row) in sums.iter().enumerate() {
            for (j, sum) in row.iter().enumerate().skip(i) {
                let want = if i == j {
                    qpow(&th, j) / (z(1) - th.clone())
                } else {
                    Q::zero()
                };
                let err = (sum.clone() - want).abs();
                assert!(
                    err < eps,
                    "θ = {th}, ({i},{j}): partial-sum error too large"
                );
            }
        }
    }
}

#[test]
fn discrete_laguerre_end_values_13_5_1_and_leading_coefficient_3_3_14() {
    // Source: Morrison (13.5.1) p_j(-1) = 1; p(0; j, θ) = θ^j (3.3.11 note); (3.3.14) the
    // coefficient of x^(j) is (-1)^j (1-θ)^j / j!.
    for (n, d) in THETAS {
        let th = fr(n, d);
        let b = DiscreteLaguerre::new(th.clone());
        for j in 0..=12usize {
            assert_eq!(b.value(j, z(-1)), z(1), "p_{j}(-1), θ = {th}");
            assert_eq!(b.value(j, z(0)), qpow(&th, j));
            let poly = b.polynomial(j);
            let lead = poly.coeffs.get(j).cloned().unwrap_or_else(Q::zero);
            assert_eq!(
                lead,
                sign(j) * qpow(&(z(1) - th.clone()), j) / fact(j),
                "(3.3.14)"
            );
            assert!(poly.coeffs.iter().skip(j + 1).all(|v| v.is_zero()));
            // Taylor coefficients, used by the fading VRF (13.6.17), against the explicit form.
            let ex: Vec<Q> = (0..=j).fold(vec![Q::zero()], |acc, nu| {
                let a = (z(1) - th.clone()) / th.clone();
                let coef =
                    qpow(&th, j) * sign(nu) * c(j as i64, nu as i64) * qpow(&a, nu) / fact(nu);
                padd(&acc, &pscale(&falling_poly(nu), &coef))
            });
            for i in 0..=j {
                for x in [z(0), z(-1), fr(3, 2)] {
                    assert_eq!(b.taylor(i, j, &x), peval(&pderiv(&ex, i), &x) / fact(i));
                }
            }
        }
    }
    let bf = DiscreteLaguerre::new(0.5_f64);
    assert_eq!(bf.value(3, -1.0), 1.0);
}

#[test]
fn laguerre_inverse_relation_13_9_17() {
    // Source: Morrison (13.9.17) / Ex 13.22:
    // r^(i) = i! (θ/(1-θ))^i Σ_j (-1)^j C(i,j) p_j(r)/θ^j.
    for (n, d) in THETAS {
        let th = fr(n, d);
        let b = DiscreteLaguerre::new(th.clone());
        let ratio = th.clone() / (z(1) - th.clone());
        for i in 0..=7usize {
            for r in [z(0), z(4), fr(-3, 2), z(11)] {
                let s = (0..=i).fold(Q::zero(), |a, j| {
                    a + sign(j) * c(i as i64, j as i64) * b.value(j, r.clone()) / qpow(&th, j)
                });
                assert_eq!(
                    fact(i) * qpow(&ratio, i) * s,
                    ff(&r, i),
                    "i = {i}, θ = {th}, r = {r}"
                );
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Chapter 4: transition matrices and state scaling
// ---------------------------------------------------------------------------------------------

#[test]
fn transition_matrix_group_properties_4_2_20_to_4_2_24() {
    // Source: Morrison (4.2.15), (4.2.20), (4.2.23), (4.2.24); spec ch02-06.md §8 check 3.
    let hs = [z(1), z(-1), fr(1, 2), z(3), fr(-7, 3), z(0)];
    for m in 0..=7usize {
        assert_eq!(phi(m, z(0)), eye(m + 1));
        for h in &hs {
            // Entry definition (4.2.15), built here: C(j,i) h^(j-i).
            let want = DMatrix::from_fn(m + 1, m + 1, |i, j| {
                if j < i {
                    Q::zero()
                } else {
                    c(j as i64, i as i64) * qpow(h, j - i)
                }
            });
            assert_eq!(phi(m, h.clone()), want);
            assert_eq!(
                mm(&phi(m, h.clone()), &phi(m, -h.clone())),
                eye(m + 1),
                "Φ(h)Φ(-h)"
            );
            for k in &hs {
                assert_eq!(
                    mm(&phi(m, h.clone()), &phi(m, k.clone())),
                    phi(m, h.clone() + k.clone()),
                    "Φ({h})Φ({k})"
                );
            }
            // (4.2.24): Φ(h)^k = Φ(kh).
            let mut p = eye(m + 1);
            for k in 1..=4i64 {
                p = mm(&p, &phi(m, h.clone()));
                assert_eq!(p, phi(m, h.clone() * z(k)));
            }
        }
    }
    // f64 agrees with exact on dyadic h.
    let pf = phi(4, 0.5_f64);
    let pe = phi(4, fr(1, 2));
    for i in 0..5 {
        for j in 0..5 {
            assert_eq!(pf[(i, j)], crate_f64(&pe[(i, j)]));
        }
    }
}

#[test]
fn transition_matrix_examples_4_2_17_and_4_2_25() {
    // Source: Morrison (4.2.17) m = 2, h = 1; (4.2.25) Φ(1)⁻¹ for m = 3; TV4.1; (7.3.29).
    let p2 = rows_to_matrix(&[
        &[z(1), z(1), z(1)],
        &[z(0), z(1), z(2)],
        &[z(0), z(0), z(1)],
    ]);
    assert_eq!(phi(2, z(1)), p2);
    let inv = rows_to_matrix(&[
        &[z(1), z(-1), z(1), z(-1)],
        &[z(0), z(1), z(-2), z(3)],
        &[z(0), z(0), z(1), z(-3)],
        &[z(0), z(0), z(0), z(1)],
    ]);
    assert_eq!(phi(3, z(-1)), inv);
    assert_eq!(inverse_exact(&phi(3, z(1))).unwrap(), inv);
    let p3 = phi(3, z(1));
    assert_eq!(mm(&mm(&p3, &p3), &p3), phi(3, z(3)), "Ex 4.3");
    assert_eq!(
        phi(1, z(-1)),
        rows_to_matrix(&[&[z(1), z(-1)], &[z(0), z(1)]])
    );
}

#[test]
fn scaled_and_unscaled_transitions_related_by_scaling_4_2_18() {
    // Source: Morrison (4.2.5), (4.2.13)-(4.2.19); spec [DERIVED] Φ_Z(h) = D(τ)⁻¹ Φ_X(hτ) D(τ),
    // with Φ_X = psi (Reyneke eq. 7); TV4.5 D(2) = diag(1, 1/2, 1/2, 3/4).
    assert_eq!(
        scaling(3, z(2)),
        DMatrix::from_fn(4, 4, |i, j| if i == j {
            [z(1), fr(1, 2), fr(1, 2), fr(3, 4)][i].clone()
        } else {
            Q::zero()
        })
    );
    for m in 0..=6usize {
        for tau in [z(2), fr(1, 10), fr(3, 7)] {
            let d = scaling(m, tau.clone());
            // D(τ) built here: k!/τ^k.
            for k in 0..=m {
                assert_eq!(d[(k, k)], fact(k) / qpow(&tau, k));
            }
            let di = inverse_exact(&d).unwrap();
            for h in [z(1), fr(-5, 2), z(4)] {
                let lhs = phi(m, h.clone());
                let rhs = mm(&mm(&di, &psi(m, h.clone() * tau.clone())), &d);
                assert_eq!(lhs, rhs, "m = {m}, τ = {tau}, h = {h}");
            }
        }
        // (4.2.5) entry definition of Φ_X(ζ) = psi(ζ): ζ^(j-i)/(j-i)!.
        let zeta = fr(-3, 4);
        let want = DMatrix::from_fn(m + 1, m + 1, |i, j| {
            if j < i {
                Q::zero()
            } else {
                qpow(&zeta, j - i) / fact(j - i)
            }
        });
        assert_eq!(psi(m, zeta.clone()), want);
    }
    // TV4.4 (Ex 4.4): x = t^3, X(0) = (0,0,0,6) -> X(ζ) = (ζ³, 3ζ², 6ζ, 6).
    let x0 = DMatrix::from_column_slice(4, 1, &[z(0), z(0), z(0), z(6)]);
    for zeta in [z(2), fr(1, 3)] {
        let x = mm(&psi(3, zeta.clone()), &x0);
        let want = [
            qpow(&zeta, 3),
            z(3) * qpow(&zeta, 2),
            z(6) * zeta.clone(),
            z(6),
        ];
        assert_eq!(x.as_slice(), &want);
    }
    // TV4.5 (Ex 4.5): x = t^3, τ = 2: Z_n = (8n³, 24n², 24n, 8); Φ(1) Z_1 = Z_2; Φ(h) Z_0 = Z_h.
    let zn = |n: &Q| {
        DMatrix::from_column_slice(
            4,
            1,
            &[
                z(8) * qpow(n, 3),
                z(24) * qpow(n, 2),
                z(24) * n.clone(),
                z(8),
            ],
        )
    };
    assert_eq!(mm(&phi(3, z(1)), &zn(&z(1))), zn(&z(2)));
    for h in [z(3), fr(1, 2), z(-2)] {
        assert_eq!(mm(&phi(3, h.clone()), &zn(&z(0))), zn(&h));
    }
    // X = D(2) Z: X_1 = (8, 12, 12, 6) (TV4.6).
    assert_eq!(
        mm(&scaling(3, z(2)), &zn(&z(1))).as_slice(),
        &[z(8), z(12), z(12), z(6)]
    );
}

#[test]
fn transition_matrices_are_matrix_exponentials_4_6_24() {
    // Source: Morrison (4.6.24)-(4.6.28): Φ(ζ) = exp(ζA); spec ch02-06.md §4.5 [DERIVED]:
    // for X, A = superdiagonal of ones (exp(ζA) = psi(ζ)); for Z, N_{i,i+1} = i+1 (exp(hN) = Φ(h)),
    // TV4.9 (Ex 4.11). Both A, N are nilpotent, so the series is finite (m+1 terms).
    let expm = |a: &DMatrix<Q>, t: &Q| {
        let n = a.nrows();
        let at = a.map(|v| v * t.clone());
        let mut term = eye(n);
        let mut sum = eye(n);
        for k in 1..=n {
            term = mm(&term, &at).map(|v| v / z(k as i64));
            sum += &term;
        }
        sum
    };
    for m in 0..=7usize {
        let a = DMatrix::from_fn(
            m + 1,
            m + 1,
            |i, j| if j == i + 1 { z(1) } else { Q::zero() },
        );
        let nmat = DMatrix::from_fn(m + 1, m + 1, |i, j| {
            if j == i + 1 {
                z(i as i64 + 1)
            } else {
                Q::zero()
            }
        });
        for t in [z(1), fr(-2, 3), fr(5, 2)] {
            assert_eq!(psi(m, t.clone()), expm(&a, &t), "psi = exp(ζA), m = {m}");
            assert_eq!(phi(m, t.clone()), expm(&nmat, &t), "Φ = exp(hN), m = {m}");
        }
    }
    // Ex 4.11 Z state, m = 2: exp(hN) = [[1, h, h²], [0, 1, 2h], [0, 0, 1]].
    let h = fr(3, 4);
    let want = rows_to_matrix(&[
        &[z(1), h.clone(), h.clone() * h.clone()],
        &[z(0), z(1), z(2) * h.clone()],
        &[z(0), z(0), z(1)],
    ]);
    assert_eq!(phi(2, h), want);
}

#[test]
fn shift_scaled_equals_phi_times_z() {
    // Source: Morrison (4.2.16) Z_{n+h} = Φ(h) Z_n; oracle: exact Φ(h) z in rationals. With
    // dyadic data of few bits, every intermediate of the f64 shift is exact, so equality is exact.
    let cases: [(&[f64], f64); 4] = [
        (&[1.0, 2.0, 3.0], 1.0),
        (&[0.5, -1.25, 3.0, 0.75, -2.0], 0.5),
        (&[4.0, 0.0, -1.0, 2.0, 0.25, 1.0, -0.5], -1.5),
        (&[7.0], 3.0),
    ];
    for (zv, h) in cases {
        let m = zv.len() - 1;
        let mut got = zv.to_vec();
        shift_scaled(&mut got, h);
        let exact = mm(
            &phi(m, seqsmooth::scalar::rational_from_f64(h).unwrap()),
            &DMatrix::from_fn(m + 1, 1, |i, _| {
                seqsmooth::scalar::rational_from_f64(zv[i]).unwrap()
            }),
        );
        for i in 0..=m {
            assert_eq!(got[i], crate_f64(&exact[(i, 0)]), "component {i}");
        }
    }
    // Arbitrary data: agrees with the f64 matrix product to rounding.
    let zv = [0.3, -1.7, 2.9, 0.11, -0.07, 0.013];
    for h in [0.1, 1.0, -2.3, 7.5] {
        let mut got = zv.to_vec();
        shift_scaled(&mut got, h);
        let p = phi(5, h);
        for i in 0..=5 {
            let want: f64 = (0..=5).map(|j| p[(i, j)] * zv[j]).sum();
            let scale: f64 = (0..=5).map(|j| (p[(i, j)] * zv[j]).abs()).sum();
            assert!((got[i] - want).abs() <= 1e-14 * scale, "h = {h}, i = {i}");
        }
    }
}

#[test]
fn state_conversions_and_propagation_tv4_4_to_tv4_6() {
    // Source: Morrison (4.2.18) X = D(τ) Z; TV4.5/TV4.6 (x = t^3, τ = 2: Z_1 = (8,24,24,8),
    // X_1 = (8,12,12,6)); (5.5.21) X(t+ζ) = Φ_X(ζ) X(t).
    assert_eq!(
        scaled_to_derivatives(&[8.0, 24.0, 24.0, 8.0], 2.0),
        vec![8.0, 12.0, 12.0, 6.0]
    );
    assert_eq!(
        derivatives_to_scaled(&[8.0, 12.0, 12.0, 6.0], 2.0),
        vec![8.0, 24.0, 24.0, 8.0]
    );
    // x = t^3 at t = 1: (1, 3, 6, 6) -> at t = 2: (8, 12, 12, 6); back to t = 0: (0, 0, 0, 6).
    let s = PolynomialState::new(1.0, vec![1.0, 3.0, 6.0, 6.0]);
    assert_eq!(s.degree(), 3);
    let p = s.at(2.0);
    assert_eq!(p.time, 2.0);
    assert_eq!(p.derivatives, vec![8.0, 12.0, 12.0, 6.0]);
    assert_eq!(s.at(0.0).derivatives, vec![0.0, 0.0, 0.0, 6.0]);
    // Covariance propagation S(t+ζ) = Φ S Φᵀ (5.5.22), TV5.5: S = (1/100)[[70,30],[30,20]] ->
    // S_{n+1,n} = (1/100)[[150,50],[50,20]].
    let mut s2 = PolynomialState::new(0.0, vec![0.0, 0.0]);
    s2.covariance = Some(DMatrix::from_row_slice(2, 2, &[0.70, 0.30, 0.30, 0.20]));
    let c = s2.at(1.0).covariance.unwrap();
    let want = [1.50, 0.50, 0.50, 0.20];
    for (k, w) in want.iter().enumerate() {
        assert!((c[(k / 2, k % 2)] - w).abs() < 1e-15);
    }
    let sd = s2.std_devs().unwrap();
    assert!((sd[0] - 0.7_f64.sqrt()).abs() < 1e-15);
}

#[test]
fn congruence_and_exact_inverse_tv5_1_tv5_5() {
    // Source: Morrison (5.2.37)-(5.2.41) TV5.1; (5.5.42)-(5.5.52) TV5.5; inverse Hilbert matrix.
    let w = rows_to_matrix(&[&[z(2), z(-1), z(1)], &[z(3), z(-1), z(-1)]]);
    let r = rows_to_matrix(&[
        &[z(1), z(1), z(1)],
        &[z(1), z(2), z(1)],
        &[z(1), z(1), z(3)],
    ]);
    assert_eq!(
        congruence(&w, &r),
        rows_to_matrix(&[&[z(7), z(1)], &[z(1), z(4)]])
    );
    let w0 = rows_to_matrix(&[
        &[fr(7, 10), fr(4, 10), fr(1, 10), fr(-2, 10)],
        &[fr(3, 10), fr(1, 10), fr(-1, 10), fr(-3, 10)],
    ]);
    assert_eq!(
        congruence(&w0, &eye(4)),
        rows_to_matrix(&[&[fr(70, 100), fr(30, 100)], &[fr(30, 100), fr(20, 100)]])
    );
    let w1 = mul(&phi(1, z(1)), &w0);
    assert_eq!(
        w1,
        rows_to_matrix(&[
            &[fr(10, 10), fr(5, 10), z(0), fr(-5, 10)],
            &[fr(3, 10), fr(1, 10), fr(-1, 10), fr(-3, 10)]
        ])
    );
    // Hilbert 4x4 inverse (classical closed form, entries (-1)^(i+j)(i+j+1) C(n+i,n-j-1) C(n+j,n-i-1) C(i+j,i)^2).
    let n = 4i64;
    let h = DMatrix::from_fn(4, 4, |i, j| fr(1, (i + j + 1) as i64));
    let hi = inverse_exact(&h).unwrap();
    for i in 0..4i64 {
        for j in 0..4i64 {
            let want = sign((i + j) as usize)
                * z(i + j + 1)
                * c(n + i, n - j - 1)
                * c(n + j, n - i - 1)
                * c(i + j, i)
                * c(i + j, i);
            assert_eq!(hi[(i as usize, j as usize)], want);
        }
    }
    assert!(inverse_exact(&DMatrix::from_element(2, 2, z(1))).is_none());
}

// ---------------------------------------------------------------------------------------------
// Classical Legendre polynomials
// ---------------------------------------------------------------------------------------------

/// P_j(u) = 2^-j Σ_k (-1)^k C(j,k) C(2j-2k, j) u^(j-2k) (Rodrigues' formula expanded), built here.
fn classical_legendre(j: usize) -> Vec<Q> {
    let mut p = vec![Q::zero(); j + 1];
    for k in 0..=j / 2 {
        p[j - 2 * k] =
            sign(k) * c(j as i64, k as i64) * c((2 * j - 2 * k) as i64, j as i64) / qpow(&z(2), j);
    }
    p
}

#[test]
fn classical_legendre_taylor_table_matches_explicit_polynomials() {
    // Source: classical Legendre polynomials (Rodrigues' formula), the limit basis of Morrison
    // Ex 7.22; oracle: exact derivatives of the explicit P_j, compared in f64 with a tolerance
    // scaled by the sum of absolute terms (the evaluation's condition).
    let us = [-1.0, -0.75, -0.3, 0.0, 0.125, 0.5, 0.9, 1.0, 1.5];
    let degree = 10;
    let order = 10;
    let polys: Vec<Vec<Q>> = (0..=degree).map(classical_legendre).collect();
    for &u in &us {
        let uq = seqsmooth::scalar::rational_from_f64(u).unwrap();
        let t = legendre::taylor_table(degree, order, u);
        assert_eq!((t.nrows(), t.ncols()), (order + 1, degree + 1));
        let vals = legendre::values(degree, u);
        for (j, p) in polys.iter().enumerate() {
            for k in 0..=order {
                let d = pderiv(p, k);
                let want = crate_f64(&(peval(&d, &uq) / fact(k)));
                let absd: Vec<Q> = d.iter().map(|v| v.abs()).collect();
                let scale = crate_f64(&(peval(&absd, &uq.abs()) / fact(k))).max(1.0);
                assert!(
                    (t[(k, j)] - want).abs() <= 1e-13 * scale,
                    "P_{j}^({k})(u)/{k}! at u = {u}: {} vs {want}",
                    t[(k, j)]
                );
            }
            let want = crate_f64(&peval(p, &uq));
            assert!(
                (vals[j] - want).abs() <= 1e-14 * 4.0f64.max(want.abs()),
                "P_{j}({u})"
            );
        }
    }
    // Exact anchors: P_j(1) = 1, P_j(-1) = (-1)^j, P_j'(1) = j(j+1)/2.
    let t = legendre::taylor_table(10, 1, 1.0);
    for j in 0..=10 {
        assert_eq!(t[(0, j)], 1.0);
        assert!((t[(1, j)] - (j * (j + 1)) as f64 / 2.0).abs() < 1e-12);
    }
}
