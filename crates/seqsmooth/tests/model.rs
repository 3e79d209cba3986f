//! `seqsmooth::model` against Morrison (1969) ch. 4: the transition matrices Φ and Ψ and their
//! group properties (4.2.15)-(4.2.25), the state scaling D(τ) (4.2.18), Φ(ζ) = exp(ζA) (4.6.24),
//! the Taylor shift and the state conversions, in exact rationals.

mod common;

use common::rational::*;
use nalgebra::DMatrix;
use num_traits::Zero;
use seqsmooth::linalg::inverse_exact;
use seqsmooth::model::{
    derivatives_to_scaled, phi, psi, scaled_to_derivatives, scaling, shift_scaled, PolynomialState,
};

#[test]
fn transition_matrix_group_properties_4_2_20_to_4_2_24() {
    // Source: Morrison (4.2.15), (4.2.20), (4.2.23), (4.2.24).
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
            assert_eq!(pf[(i, j)], f(&pe[(i, j)]));
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
    // Source: Morrison (4.2.5), (4.2.13)-(4.2.19); derived: Φ_Z(h) = D(τ)⁻¹ Φ_X(hτ) D(τ),
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
    // Source: Morrison (4.6.24)-(4.6.28): Φ(ζ) = exp(ζA); derived:
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
            assert_eq!(got[i], f(&exact[(i, 0)]), "component {i}");
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
