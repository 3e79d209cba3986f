//! `model::linear`: `Φ(ζ) = e^{ζA}` against Morrison ch. 4's transition matrices (the
//! polynomial models' `Φ_X`, `Φ_Z`, `Φ_V`, (4.6.42)-(4.6.51), Ex. 4.11, 4.12, 4.14), the exact
//! series in rationals for nilpotent `A`, the eigen-decomposition for diagonalisable `A`, the
//! group property, and refusals.

use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use seqsmooth::model::linear::LinearDynamics;
use seqsmooth::model::{phi, psi};
use seqsmooth::scalar::{rational_from_f64, Rational, Scalar};

fn rel_err(got: &DMatrix<f64>, want: &DMatrix<f64>) -> f64 {
    (got - want).amax() / want.amax()
}

#[test]
fn polynomial_models_are_the_nilpotent_case() {
    for m in 0..=14 {
        // X = (x, ẋ, ẍ, …): A the superdiagonal of ones, Φ_X(ζ) = Ψ(ζ) (4.2.5), Ex. 4.11.
        let a = DMatrix::from_fn(m + 1, m + 1, |i, j| if j == i + 1 { 1.0 } else { 0.0 });
        let d = LinearDynamics::new(a).unwrap();
        assert!(d.is_nilpotent(), "degree {m}");
        for zeta in [-3.5, -0.25, 0.0, 0.5, 2.0, 7.0] {
            let err = rel_err(&d.transition(zeta).unwrap(), &psi(m, zeta));
            assert!(err <= 4.0 * f64::EPSILON, "degree {m}, ζ {zeta}: {err:e}");
        }
        // Z = (x, τẋ, τ²ẍ/2!, …): dZ/dt = N Z/τ, N_{i,i+1} = i + 1, e^{hN} = Φ(h) (4.2.15).
        let n = DMatrix::from_fn(m + 1, m + 1, |i, j| if j == i + 1 { j as f64 } else { 0.0 });
        let d = LinearDynamics::new(n).unwrap();
        for h in [-2.0, 1.0, 3.0] {
            let err = rel_err(&d.transition(h).unwrap(), &phi(m, h));
            assert!(err <= 4.0 * f64::EPSILON, "degree {m}, h {h}: {err:e}");
        }
    }
}

#[test]
fn backward_difference_state_ex_4_12() {
    // m = 3, τ = 1: A_V = [[0,1,1,2],[0,0,2,3],[0,0,0,3],[0,0,0,0]] and Φ_V(h) rows
    // [1, h, h(h+1), h(h+1)(h+2)], [0, 1, 2h, 3h(h+1)], [0, 0, 1, 3h], [0, 0, 0, 1].
    let a = [
        0., 1., 1., 2., 0., 0., 2., 3., 0., 0., 0., 3., 0., 0., 0., 0.,
    ];
    let d = LinearDynamics::new(DMatrix::from_row_slice(4, 4, &a)).unwrap();
    for h in [-2.0, 1.0, 2.5] {
        let want = DMatrix::from_row_slice(
            4,
            4,
            &[
                1.0,
                h,
                h * (h + 1.0),
                h * (h + 1.0) * (h + 2.0),
                0.0,
                1.0,
                2.0 * h,
                3.0 * h * (h + 1.0),
                0.0,
                0.0,
                1.0,
                3.0 * h,
                0.0,
                0.0,
                0.0,
                1.0,
            ],
        );
        let err = rel_err(&d.transition(h).unwrap(), &want);
        assert!(err <= 4.0 * f64::EPSILON, "h {h}: {err:e}");
    }
}

#[test]
fn rotation_and_hyperbolic_4_6_51_and_ex_4_14() {
    let rot = LinearDynamics::new(DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -1.0, 0.0])).unwrap();
    let hyp = LinearDynamics::new(DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 1.0, 0.0])).unwrap();
    assert!(!rot.is_nilpotent() && !hyp.is_nilpotent());
    for z in [-20.0, -1.0, 0.1, 0.7, 3.0, 25.0] {
        let (c, s) = (f64::cos(z), f64::sin(z));
        let want = DMatrix::from_row_slice(2, 2, &[c, s, -s, c]);
        let err = rel_err(&rot.transition(z).unwrap(), &want);
        assert!(err <= 1e-13, "rotation ζ {z}: {err:e}");
        let (c, s) = (f64::cosh(z), f64::sinh(z));
        let want = DMatrix::from_row_slice(2, 2, &[c, s, s, c]);
        let err = rel_err(&hyp.transition(z).unwrap(), &want);
        assert!(err <= 1e-13, "cosh/sinh ζ {z}: {err:e}");
    }
}

/// `Σ_ν (ζA)^ν/ν!` in exact rationals for a nilpotent `A`.
fn exact_series(a: &DMatrix<f64>, zeta: f64) -> DMatrix<f64> {
    let n = a.nrows();
    let q = a.map(|v| rational_from_f64(v).unwrap() * rational_from_f64(zeta).unwrap());
    let mut term = DMatrix::from_fn(n, n, |i, j| Rational::from_i64((i == j) as i64));
    let mut sum = term.clone();
    for nu in 1..=n {
        term = seqsmooth::linalg::mul(&term, &q).map(|v| v / Rational::from_i64(nu as i64));
        sum += &term;
    }
    sum.map(|v| v.to_f64())
}

#[test]
fn nilpotent_matrices_give_the_exact_series() {
    // A = S J S⁻¹ for a strictly upper triangular integer J and a unimodular integer S
    // (lower times upper unit triangular): an integer nilpotent matrix that is not triangular.
    let mut rng = rand::rngs::StdRng::seed_from_u64(4);
    for n in 2..=8 {
        let unit = |rng: &mut rand::rngs::StdRng, lower: bool| {
            DMatrix::from_fn(n, n, |i, j| match (i == j, (i > j) == lower && i != j) {
                (true, _) => 1.0,
                (false, true) => f64::from(rng.gen_range(-2..=2)),
                _ => 0.0,
            })
        };
        let s = unit(&mut rng, true) * unit(&mut rng, false);
        let s_inv = s.clone().try_inverse().unwrap().map(f64::round);
        assert_eq!(&s * &s_inv, DMatrix::identity(n, n), "S is unimodular");
        let j = DMatrix::from_fn(n, n, |i, k| {
            if k > i {
                f64::from(rng.gen_range(-2..=2))
            } else {
                0.0
            }
        });
        let a = &s * j * &s_inv;
        let d = LinearDynamics::new(a.clone()).unwrap();
        assert!(d.is_nilpotent(), "n {n}: {a}");
        for zeta in [-1.5, 0.25, 2.0] {
            let err = rel_err(&d.transition(zeta).unwrap(), &exact_series(&a, zeta));
            assert!(err <= 1e-15, "n {n}, ζ {zeta}: {err:e}");
        }
    }
}

#[test]
fn diagonalisable_matrices_match_their_eigen_decomposition() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(9);
    for n in 1..=8 {
        // V well conditioned (identity plus a small perturbation), eigenvalues in [-2, 1].
        let v = DMatrix::identity(n, n) + DMatrix::from_fn(n, n, |_, _| rng.gen_range(-0.3..0.3));
        let v_inv = v.clone().try_inverse().unwrap();
        let lambda = DVector::from_fn(n, |_, _| rng.gen_range(-2.0..1.0));
        let a = &v * DMatrix::from_diagonal(&lambda) * &v_inv;
        let d = LinearDynamics::new(a).unwrap();
        for zeta in [-1.0, 0.3, 2.0, 5.0] {
            let e = lambda.map(|l| (l * zeta).exp());
            let want = &v * DMatrix::from_diagonal(&e) * &v_inv;
            let err = rel_err(&d.transition(zeta).unwrap(), &want);
            assert!(err <= 1e-13, "n {n}, ζ {zeta}: {err:e}");
        }
    }
}

#[test]
fn group_property_and_inverse() {
    // (4.6.29), (4.6.34)-(4.6.41): Φ(a)Φ(b) = Φ(a + b), Φ(ζ)Φ(−ζ) = I.
    let a = DMatrix::from_row_slice(3, 3, &[-0.5, 1.0, 0.0, -1.0, -0.2, 0.3, 0.0, 0.4, -1.0]);
    let d = LinearDynamics::new(a).unwrap();
    for (x, y) in [(0.3, 0.9), (-1.2, 2.5), (4.0, -4.0)] {
        let product = d.transition(x).unwrap() * d.transition(y).unwrap();
        let err = rel_err(&product, &d.transition(x + y).unwrap());
        assert!(err <= 1e-13, "Φ({x})Φ({y}): {err:e}");
    }
    let identity = d.transition(1.7).unwrap() * d.transition(-1.7).unwrap();
    assert!(rel_err(&identity, &DMatrix::identity(3, 3)) <= 1e-14);
    assert_eq!(d.transition(0.0).unwrap(), DMatrix::identity(3, 3));
}

#[test]
fn refusals_name_the_value() {
    let message = |e: seqsmooth::Error| e.to_string();
    let e = LinearDynamics::new(DMatrix::zeros(2, 3)).unwrap_err();
    assert!(message(e).contains("2x3"));
    let mut a = DMatrix::identity(2, 2);
    a[(1, 0)] = f64::NAN;
    assert!(message(LinearDynamics::new(a).unwrap_err()).contains("entry [1, 0] = NaN"));
    let d = LinearDynamics::new(DMatrix::from_element(1, 1, 1000.0)).unwrap();
    assert!(message(d.transition(1.0).unwrap_err()).contains("beyond the double range"));
    assert!(message(d.transition(f64::NAN).unwrap_err()).contains("step NaN"));
    assert!(d.transition(0.5).unwrap()[(0, 0)].is_finite());
}
