//! Fading-memory gains (`seqsmooth::polynomial::fading::gains`, Morrison (1969) ch. 13) against the
//! printed Table 13.1, Reyneke et al. (2012) §6.6, exact discounted least-squares weights, and
//! the single eigenvalue θ of the recursion (13.5.38); the `f64` gains against the exact ones.

mod common;

use common::book::*;
use common::rational::*;
use nalgebra::DMatrix;
use num_traits::{One, Zero};
use seqsmooth::polynomial::fading::gains::fading_gains;
use seqsmooth::polynomial::form::GainForm;
use seqsmooth::scalar::rational_from_f64;

#[test]
fn fading_gains_match_table_13_1_and_reyneke_section_6_6() {
    // Source: Morrison Table 13.1 (13.5.26)-(13.5.33) degrees 0-4 (degree 3 reconstructed;
    // reconstructed), Reyneke §6.6 degrees 0-5.
    for th in exact_thetas() {
        for m in 0..=5 {
            let got = fading_gains::<Q>(m, th.clone(), GainForm::Current);
            assert_eq!(got, fmp_book(m, &th), "m = {m}, θ = {th}");
            // Predictor form: Φ(1) H (Morrison (13.5.35)-(13.5.37)); m = 1 gives the (13.3.14)
            // coefficient 2(1-θ) of y_n in the position prediction.
            let hp = mm(
                &pascal(m, &z(1)),
                &DMatrix::from_column_slice(m + 1, 1, &fmp_book(m, &th)),
            );
            let gotp = fading_gains::<Q>(m, th.clone(), GainForm::Predictor);
            for i in 0..=m {
                assert_eq!(gotp[i], hp[(i, 0)]);
            }
            if m == 1 {
                assert_eq!(gotp[0], z(2) * (z(1) - th.clone()));
            }
        }
    }
}

#[test]
fn fading_gain_test_vectors_and_position_gain() {
    // Source: Reyneke §6.6 test vectors θ = 1/2 (exact) and θ = 0.9 (decimals);
    // Morrison Table 13.1 note G0 = 1 - θ^(m+1); "H = (0.271, 0.0285,
    // 0.0005)".
    let half: [&[&str]; 6] = [
        &["1/2"],
        &["3/4", "1/4"],
        &["7/8", "9/16", "1/16"],
        &["15/16", "83/96", "3/16", "1/96"],
        &["31/32", "145/128", "275/768", "5/128", "1/768"],
        &[
            "63/64",
            "5237/3840",
            "285/512",
            "137/1536",
            "3/512",
            "1/7680",
        ],
    ];
    for (m, row) in half.iter().enumerate() {
        let want: Vec<Q> = row.iter().map(|s| q(s)).collect();
        assert_eq!(
            fading_gains::<Q>(m, fr(1, 2), GainForm::Current),
            want,
            "θ = 1/2, m = {m}"
        );
    }
    let nine: [(usize, &[&str]); 3] = [
        (2, &["0.271", "0.0285", "0.0005"]),
        (3, &["0.3439", "0.0541833333", "0.0019", "1.6666667e-05"]),
        (
            5,
            &[
                "0.468559",
                "0.1226272833",
                "0.008585625",
                "2.2570833e-04",
                "2.375e-06",
                "8.333333e-09",
            ],
        ),
    ];
    for (m, row) in nine {
        let exact = fading_gains::<Q>(m, q("0.9"), GainForm::Current);
        let float = fading_gains::<f64>(m, 0.9, GainForm::Current);
        for (k, s) in row.iter().enumerate() {
            assert_printed(f(&exact[k]), s, &format!("θ = 0.9 exact m = {m} h_{k}"));
            assert_printed(float[k], s, &format!("θ = 0.9 f64 m = {m} h_{k}"));
        }
    }
    // Exactly printed decimals at θ = 0.9.
    let e2 = fading_gains::<Q>(2, q("0.9"), GainForm::Current);
    assert_eq!(e2, vec![q("0.271"), q("0.0285"), q("0.0005")]);
    for th in exact_thetas() {
        for m in 0..=10 {
            let g = fading_gains::<Q>(m, th.clone(), GainForm::Current);
            assert_eq!(g[0], z(1) - qpow(&th, m + 1), "h_0, m = {m}, θ = {th}");
            assert_eq!(
                g[m],
                qpow(&(z(1) - th.clone()), m + 1) / fact(m),
                "h_m, m = {m}"
            );
        }
    }
}

#[test]
fn fading_gains_equal_discounted_least_squares_weights() {
    // Oracle: the steady-state discounted least-squares weight of the newest sample,
    // H = A(θ)⁻¹ e0 with A_ij = Σ_{k>=0} θ^k (-k)^(i+j) summed exactly in closed form
    // (Reyneke et al. §6.6; Morrison (13.2.1)). Any degree m <= 10.
    for th in [fr(1, 2), fr(9, 10), fr(99, 100), fr(1, 3), fr(7, 8)] {
        let moments: Vec<Q> = (0..=20)
            .map(|p| weighted_series_sum(|x| qpow(x, p), p, &th))
            .collect();
        for m in 0..=10usize {
            let a = DMatrix::from_fn(m + 1, m + 1, |i, j| {
                let s = moments[i + j].clone();
                if (i + j) % 2 == 0 {
                    s
                } else {
                    -s
                }
            });
            let h = inv(&a).column(0).into_owned();
            let got = fading_gains::<Q>(m, th.clone(), GainForm::Current);
            for i in 0..=m {
                assert_eq!(
                    got[i], h[i],
                    "discounted LS gain m = {m}, θ = {th}, i = {i}"
                );
            }
        }
    }
}

#[test]
fn f64_fading_gains_match_exact() {
    // Oracle: exact rational gains at the exact rational value of each f64 θ.
    let grid = [
        0.001,
        0.01,
        0.1,
        0.2,
        1.0 / 3.0,
        0.5,
        0.75,
        0.8,
        0.9,
        0.93,
        0.95,
        0.98,
        0.99,
        0.999,
        0.9999,
        0.999999,
    ];
    for &th in &grid {
        let thq = rational_from_f64(th).unwrap();
        for m in 0..=10usize {
            for form in [GainForm::Current, GainForm::Predictor] {
                let exact = fading_gains::<Q>(m, thq.clone(), form);
                let g = fading_gains::<f64>(m, th, form);
                for k in 0..=m {
                    let e = f(&exact[k]);
                    assert!(
                        rel_err(g[k], e) <= 1e-14,
                        "fading f64 m={m} θ={th} k={k} {form:?}: {} vs {e}",
                        g[k]
                    );
                }
            }
        }
    }
}

/// Faddeev-LeVerrier: coefficients c_0..c_n of det(λI - A) = Σ c_k λ^k (c_n = 1), exact.
fn char_poly(a: &DMatrix<Q>) -> Vec<Q> {
    let n = a.nrows();
    let mut coeffs = vec![Q::zero(); n + 1];
    coeffs[n] = Q::one();
    let mut mk = DMatrix::from_element(n, n, Q::zero());
    for k in 1..=n {
        let mut next = mm(a, &mk);
        for i in 0..n {
            next[(i, i)] = next[(i, i)].clone() + coeffs[n - k + 1].clone();
        }
        mk = next;
        let am = mm(a, &mk);
        let tr = (0..n).fold(Q::zero(), |s, i| s + am[(i, i)].clone());
        coeffs[n - k] = -tr / z(k as i64);
    }
    coeffs
}

#[test]
fn fading_recursion_has_single_eigenvalue_theta_13_5_38() {
    // Source: Morrison §13.4, (13.5.35)-(13.5.43), Ex 13.11: B = Φ(1)(I - H M), M = e0ᵀ, has the
    // single eigenvalue θ of multiplicity m+1. Proved exactly: (B - θI)^(m+1) = 0,
    // (B - θI)^m != 0 (one Jordan block), and det(λI - B) = (λ - θ)^(m+1) by Faddeev-LeVerrier.
    for th in [fr(1, 2), fr(9, 10), fr(99, 100)] {
        for m in 0..=10usize {
            let n = m + 1;
            let h = fading_gains::<Q>(m, th.clone(), GainForm::Current);
            let mut ihm = eye(n);
            for i in 0..n {
                ihm[(i, 0)] = ihm[(i, 0)].clone() - h[i].clone();
            }
            let b = mm(&pascal(m, &z(1)), &ihm);
            let mut nmat = b.clone();
            for i in 0..n {
                nmat[(i, i)] = nmat[(i, i)].clone() - th.clone();
            }
            let mut pw = eye(n);
            for _ in 0..m {
                pw = mm(&pw, &nmat);
            }
            assert!(
                pw.iter().any(|v| !v.is_zero()),
                "(B-θI)^m = 0 for m = {m}, θ = {th}"
            );
            let last = mm(&pw, &nmat);
            assert!(
                last.iter().all(|v| v.is_zero()),
                "(B-θI)^(m+1) != 0, m = {m}, θ = {th}"
            );
            let cp = char_poly(&b);
            for (k, got) in cp.iter().enumerate() {
                let want = c(n, k) * qpow(&(-th.clone()), n - k);
                assert_eq!(*got, want, "char poly coefficient λ^{k}, m = {m}, θ = {th}");
            }
        }
    }
    // Ex 13.11, m = 1: homogeneous z1' = z1 - (1-θ)² z0, z0' = θ² z0 + z1'.
    let th = fr(9, 10);
    let h = fading_gains::<Q>(1, th.clone(), GainForm::Current);
    let mut ihm = eye(2);
    ihm[(0, 0)] = z(1) - h[0].clone();
    ihm[(1, 0)] = -h[1].clone();
    let b = mm(&pascal(1, &z(1)), &ihm);
    let om2 = (z(1) - th.clone()) * (z(1) - th.clone());
    assert_eq!(b[(1, 0)], -om2.clone());
    assert_eq!(b[(1, 1)], z(1));
    assert_eq!(b[(0, 0)], th.clone() * th.clone() - om2);
    assert_eq!(b[(0, 1)], z(1));
}
