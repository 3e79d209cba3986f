//! `basis::Jacobi`, the recurrence of the polynomials orthonormal for a measure: the discrete
//! case against the Stieltjes procedure in exact rational arithmetic (monic polynomials,
//! `a_k = ⟨u p_k, p_k⟩/⟨p_k, p_k⟩`, `b_k = ⟨p_k, p_k⟩/⟨p_{k−1}, p_{k−1}⟩ = β_k²`),
//! orthonormality on 10⁴ irregular samples, degrees to 20, and the refusals.

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{ToPrimitive, Zero};
use seqsmooth::basis::{Jacobi, Weight};
use seqsmooth::Error;

fn q(n: i64, d: i64) -> BigRational {
    BigRational::new(BigInt::from(n), BigInt::from(d))
}

/// The exact `α_0..α_n` and `β_1²..β_n²` of `Σ w_j δ(u − u_j)` by Stieltjes' procedure.
fn stieltjes(
    u: &[BigRational],
    w: &[BigRational],
    n: usize,
) -> (Vec<BigRational>, Vec<BigRational>) {
    let inner = |p: &[BigRational], r: &[BigRational], x: bool| -> BigRational {
        let mut s = BigRational::zero();
        for j in 0..u.len() {
            let mut term = &w[j] * &p[j] * &r[j];
            if x {
                term *= &u[j];
            }
            s += term;
        }
        s
    };
    let mut prev: Vec<BigRational> = vec![BigRational::zero(); u.len()];
    let mut p: Vec<BigRational> = vec![q(1, 1); u.len()];
    let (mut alpha, mut beta2) = (Vec::new(), Vec::new());
    let mut norm_prev = BigRational::zero();
    for k in 0..=n {
        let norm = inner(&p, &p, false);
        let a = inner(&p, &p, true) / &norm;
        let b = if k > 0 {
            &norm / &norm_prev
        } else {
            BigRational::zero()
        };
        if k > 0 {
            beta2.push(b.clone());
        }
        alpha.push(a.clone());
        let next: Vec<BigRational> = (0..u.len())
            .map(|j| (&u[j] - &a) * &p[j] - &b * &prev[j])
            .collect();
        prev = p;
        p = next;
        norm_prev = norm;
    }
    (alpha, beta2)
}

#[test]
fn the_discrete_recurrence_is_stieltjes_in_exact_arithmetic() {
    // nine points on [-1, 1] (so u = t), unequal weights, degrees 0..=6
    let ut: [(i64, i64); 9] = [
        (-1, 1),
        (-7, 8),
        (-1, 2),
        (-1, 8),
        (0, 1),
        (3, 16),
        (1, 2),
        (13, 16),
        (1, 1),
    ];
    let wt: [(i64, i64); 9] = [
        (1, 1),
        (3, 2),
        (1, 4),
        (2, 1),
        (5, 3),
        (1, 1),
        (7, 8),
        (1, 2),
        (3, 1),
    ];
    let u: Vec<BigRational> = ut.iter().map(|&(a, b)| q(a, b)).collect();
    let w: Vec<BigRational> = wt.iter().map(|&(a, b)| q(a, b)).collect();
    let t: Vec<f64> = ut.iter().map(|&(a, b)| a as f64 / b as f64).collect();
    let wf: Vec<f64> = wt.iter().map(|&(a, b)| a as f64 / b as f64).collect();
    let n = 6;
    let (alpha, beta2) = stieltjes(&u, &w, n);
    let j = Jacobi::discrete(&t, &wf, n).unwrap();
    assert_eq!((j.centre, j.half), (0.0, 1.0));
    assert_eq!(
        (alpha.len(), j.alpha.len(), beta2.len(), j.beta.len()),
        (n + 1, n + 1, n, n)
    );
    for (k, (got, want)) in j.alpha.iter().zip(&alpha).enumerate() {
        let want = want.to_f64().unwrap();
        assert!((got - want).abs() <= 1e-14, "α_{k}: {got} {want}");
    }
    for (k, (got, want)) in j.beta.iter().zip(&beta2).enumerate() {
        let want = want.to_f64().unwrap().sqrt();
        assert!(
            (got - want).abs() <= 1e-14 * want.max(1.0),
            "β_{}: {got} {want}",
            k + 1
        );
    }
    let mass: f64 = wf.iter().sum();
    assert!((j.mass - mass).abs() <= 1e-15 * mass);
}

/// `Σ_j w_j b_i(t_j) b_k(t_j) = δ_ik` on 10⁴ irregular Unix-epoch samples with varying
/// weights, degrees to 20 (to 1e-12).
#[test]
fn the_discrete_polynomials_are_orthonormal() {
    let count = 10_000;
    let t: Vec<f64> = (0..count)
        .map(|j| 1.7e9 + j as f64 * 0.01 + ((j * 7) % 13) as f64 * 1e-3)
        .collect();
    let w: Vec<f64> = (0..count).map(|j| 0.5 + ((j * 17) % 23) as f64).collect();
    let n = 20;
    let jac = Jacobi::discrete(&t, &w, n).unwrap();
    let mut gram = vec![0.0; (n + 1) * (n + 1)];
    for (&s, &wj) in t.iter().zip(&w) {
        let b = jac.orthonormal_at_offset(s - jac.centre);
        for i in 0..=n {
            for k in 0..=n {
                gram[i * (n + 1) + k] += wj * b[i] * b[k];
            }
        }
    }
    let worst = (0..=n)
        .flat_map(|i| (0..=n).map(move |k| (i, k)))
        .map(|(i, k)| (gram[i * (n + 1) + k] - f64::from(u8::from(i == k))).abs())
        .fold(0.0, f64::max);
    assert!(worst <= 1e-12, "{worst:e}");
}

#[test]
fn bad_measures_are_refused_by_name() {
    let t = [0.0, 1.0, 2.0];
    assert!(matches!(
        Jacobi::discrete(&t, &[1.0; 3], 3),
        Err(Error::TooFewSamples { needed: 4, got: 3 })
    ));
    // repeated times count once
    assert!(matches!(
        Jacobi::discrete(&[0.0, 0.0, 1.0, 1.0], &[1.0; 4], 2),
        Err(Error::TooFewSamples { needed: 3, got: 2 })
    ));
    for w in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let e = Jacobi::discrete(&t, &[1.0, w, 1.0], 1).unwrap_err();
        assert!(e.to_string().contains("weight 1"), "{e}");
    }
    assert!(matches!(
        Jacobi::discrete(&[0.0, f64::NAN, 2.0], &[1.0; 3], 1),
        Err(Error::NonFinite { .. })
    ));
    assert!(Jacobi::discrete(&t, &[1.0; 2], 1).is_err());
    assert!(Jacobi::legendre(3, 1.0, 1.0).is_err());
    assert!(Jacobi::chebyshev(3, 2.0, f64::NAN).is_err());
    let e = Jacobi::continuous(Weight::Smooth(&|t| t), -1.0, 1.0, 2).unwrap_err();
    assert!(e.to_string().contains("must be finite and above 0"), "{e}");
    // 1/√|t| has a singularity inside: the discretisations do not settle, and it says so
    let e = Jacobi::continuous(Weight::Smooth(&|t: f64| 1.0 / t.abs().sqrt()), -1.0, 1.0, 4)
        .unwrap_err();
    assert!(e.to_string().contains("did not settle"), "{e}");
    // one time is a measure of degree 0: its node is that time
    let g = Jacobi::discrete(&[5.0, 5.0], &[1.0, 3.0], 0)
        .unwrap()
        .gauss()
        .unwrap();
    assert_eq!((g.nodes(), g.weights.clone()), (vec![5.0], vec![4.0]));
}
