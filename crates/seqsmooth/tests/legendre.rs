//! `seqsmooth::basis::legendre` (classical Legendre polynomials on [-1, 1]): the Taylor table
//! against the explicit polynomials, in exact rationals.

mod common;

use common::rational::*;
use num_traits::{Signed, Zero};
use seqsmooth::basis::legendre;

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
                let want = f(&(peval(&d, &uq) / fact(k)));
                let absd: Vec<Q> = d.iter().map(|v| v.abs()).collect();
                let scale = f(&(peval(&absd, &uq.abs()) / fact(k))).max(1.0);
                assert!(
                    (t[(k, j)] - want).abs() <= 1e-13 * scale,
                    "P_{j}^({k})(u)/{k}! at u = {u}: {} vs {want}",
                    t[(k, j)]
                );
            }
            let want = f(&peval(p, &uq));
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
