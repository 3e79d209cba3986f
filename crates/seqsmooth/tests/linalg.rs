//! `seqsmooth::linalg` in exact rationals: the congruence W R Wᵀ of Morrison (5.2.37)-(5.2.41)
//! and the exact inverse of (5.5.42)-(5.5.52).

mod common;

use common::rational::*;
use nalgebra::DMatrix;
use seqsmooth::linalg::{congruence, inverse_exact, mul};
use seqsmooth::model::phi;

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
