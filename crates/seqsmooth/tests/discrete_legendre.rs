//! `seqsmooth::basis::DiscreteLegendre` against Morrison (1969) ch. 3 and Appendix I: the
//! explicit polynomials (3.2.20)-(3.2.21), orthogonality and norms (3.2.30), the recursion
//! (A1.1), the end differences (A1.7) with Table 7.1, and the inverse relation (A1.25)-(A1.26),
//! in exact rationals.

mod common;

use common::rational::*;
use num_traits::Zero;
use seqsmooth::basis::DiscreteLegendre;
use seqsmooth::calculus::link_matrix;

/// Morrison (3.2.20): p(x; j, L) = Σ_ν (-1)^ν C(j,ν) C(j+ν,ν) x^(ν) / L^(ν), built here.
fn legendre_explicit(j: usize, l: &Q) -> Vec<Q> {
    (0..=j).fold(vec![Q::zero()], |acc, nu| {
        let coef = sign(nu) * c(j as i64, nu as i64) * c((j + nu) as i64, nu as i64) / ff(l, nu);
        padd(&acc, &pscale(&falling_poly(nu), &coef))
    })
}

fn sample_points(l: i64) -> Vec<Q> {
    let mut xs: Vec<Q> = (0..=l).map(z).collect();
    xs.extend([fr(1, 2), z(-1), fr(7, 3), z(l + 1), fr(-5, 4)]);
    xs
}

#[test]
fn discrete_legendre_explicit_p0_to_p4_3_2_21() {
    // Source: Morrison (3.2.21) and the (derived) factored forms of p2, p3.
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
    // Source: derived from Morrison (3.2.20): p_j(0) = 1, p_j(L) = (-1)^j,
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
    // Source: Morrison Appendix I (A1.1)-(A1.6). Oracle: derivatives of the
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
            let e = f(&de[(j, i)]);
            assert!(
                (df[(j, i)] - e).abs() <= 1e-12 * e.abs().max(1e-3),
                "f64 ({j},{i})"
            );
        }
    }
}

/// Morrison Table 7.1: the integer parts (-1)^j C(j,i) C(j+i,i) of [G]_ij · L^(i), rows i,
/// columns j = i..10 (rebuilt from (7.4.14)).
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
