//! `model::dynamics`: the `Dynamics` trait on `PolynomialDynamics` and `LinearDynamics`.
//! Oracles: exact rationals for `Φ(ζ) = Ψ(ζ) ⊗ I_d` ((4.2.5)) and for the states of integer
//! polynomials on several axes; Morrison's ch. 4 transition examples as states (TV4.1 `Φ_Z(1)`
//! and its inverse (4.2.25) through `X = D(τ) Z` (4.2.18), Ex. 4.3 `Φ_Z(3) = Φ_Z(1)³`, TV4.4
//! Ex. 4.4, TV4.5 Ex. 4.5); the difference state's `Φ_U(h)` ((4.3.4)-(4.3.8), TV4.2, Ex. 4.7)
//! and TV4.6's `U_n` through `LinearDynamics` with the generator of Ex. 4.12's `A_V`; the
//! rotation of (4.6.51) in closed form; `Φ S Φᵀ` in exact rationals; the group property
//! (4.2.20)-(4.2.24) at times near zero and near the Unix epoch; typed refusals.

mod common;

use common::rational::*;
use nalgebra::{DMatrix, DVector};
use num_traits::Zero;
use rand::{Rng, SeedableRng};
use seqsmooth::error::Param;
use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
use seqsmooth::model::linear::LinearDynamics;
use seqsmooth::scalar::rational_from_f64;
use seqsmooth::Error;

fn qf(v: f64) -> Q {
    rational_from_f64(v).unwrap()
}

/// `[Ψ(ζ) ⊗ I_d]` built entry by entry in exact rationals: `ζ^(j−i)/(j−i)!` on matching axes.
fn exact_kron_psi(m: usize, d: usize, zeta: &Q) -> DMatrix<Q> {
    let n = (m + 1) * d;
    DMatrix::from_fn(n, n, |r, c| {
        let (i, a, j, b) = (r / d, r % d, c / d, c % d);
        if a != b || j < i {
            Q::zero()
        } else {
            qpow(zeta, j - i) / fact(j - i)
        }
    })
}

#[test]
fn polynomial_transition_is_psi_kronecker_identity() {
    // (4.2.5) on each axis, axes interleaved by derivative: every entry equals the correctly
    // rounded exact value (ζ dyadic, so ζ^k is exact and one division rounds).
    let zetas = [-3.5, -1.0, -0.125, 0.0, 0.5, 1.0, 2.0, 6.25];
    for m in 0..=8 {
        for d in 1..=3 {
            let model = PolynomialDynamics::new(m, d);
            assert_eq!(model.dimension(), (m + 1) * d);
            for &zeta in &zetas {
                let want = to_f64(&exact_kron_psi(m, d, &qf(zeta)));
                assert_eq!(model.transition(zeta), want, "m {m}, d {d}, ζ {zeta}");
                let p = model
                    .propagate(&DVector::zeros(model.dimension()), 10.0, 10.0 + zeta)
                    .unwrap();
                assert_eq!(p.transition, want, "propagate: m {m}, d {d}, ζ {zeta}");
            }
        }
    }
    // Zero axes is read as one.
    assert_eq!(PolynomialDynamics::new(2, 0).axes(), 1);
}

#[test]
fn tv4_1_phi_z_and_its_inverse_through_the_scaling() {
    // TV4.1 (m = 3): Φ_Z(1) = [[1,1,1,1],[0,1,2,3],[0,0,1,3],[0,0,0,1]] and its inverse (4.2.25)
    // [[1,-1,1,-1],[0,1,-2,3],[0,0,1,-3],[0,0,0,1]]; Ex. 4.3: Φ_Z(3) = Φ_Z(1)³. With
    // Z = (x, τẋ, τ²ẍ/2!, τ³x⃛/3!) and X = D(τ) Z, D(2) = diag(1, 1/2, 1/2, 3/4) (TV4.5), so
    // Φ_Z(h) = D⁻¹ Φ_X(hτ) D: the unscaled transition at τ = 2 read in scaled coordinates.
    let tau = 2.0;
    let dd = DMatrix::from_diagonal(&DVector::from_vec(vec![1.0, 0.5, 0.5, 0.75]));
    let dd_inv = DMatrix::from_diagonal(&DVector::from_vec(vec![1.0, 2.0, 2.0, 4.0 / 3.0]));
    let model = PolynomialDynamics::new(3, 1);
    let scaled = |h: f64| &dd_inv * model.transition(h * tau) * &dd;
    let phi1 = DMatrix::from_row_slice(
        4,
        4,
        &[
            1., 1., 1., 1., 0., 1., 2., 3., 0., 0., 1., 3., 0., 0., 0., 1.,
        ],
    );
    let phi1_inv = DMatrix::from_row_slice(
        4,
        4,
        &[
            1., -1., 1., -1., 0., 1., -2., 3., 0., 0., 1., -3., 0., 0., 0., 1.,
        ],
    );
    let close =
        |a: &DMatrix<f64>, b: &DMatrix<f64>| (a - b).amax() <= 4.0 * f64::EPSILON * b.amax();
    assert!(close(&scaled(1.0), &phi1), "{}", scaled(1.0));
    assert!(close(&scaled(-1.0), &phi1_inv), "{}", scaled(-1.0));
    assert!(close(&scaled(3.0), &(&phi1 * &phi1 * &phi1)), "Ex. 4.3");
}

#[test]
fn tv4_4_and_tv4_5_cubic_states() {
    let model = PolynomialDynamics::new(3, 1);
    let v = |a: [f64; 4]| DVector::from_vec(a.to_vec());
    // TV4.4 (Ex. 4.4): x = t³, X(0) = (0, 0, 0, 6) → X(ζ) = (ζ³, 3ζ², 6ζ, 6), and X(2) = Φ(1) X(1).
    for zeta in [-2.5, -1.0, 0.5, 1.0, 3.0] {
        let p = model.propagate(&v([0., 0., 0., 6.]), 0.0, zeta).unwrap();
        let want = v([zeta.powi(3), 3.0 * zeta * zeta, 6.0 * zeta, 6.0]);
        assert_eq!(p.state, want, "ζ {zeta}");
    }
    let x1 = model
        .propagate(&v([0., 0., 0., 6.]), 0.0, 1.0)
        .unwrap()
        .state;
    let x2 = model.propagate(&x1, 1.0, 2.0).unwrap().state;
    assert_eq!(x2, v([8., 12., 12., 6.]));
    // TV4.5 (Ex. 4.5, τ = 2): X_n = (8n³, 12n², 12n, 6) at t = 2n; forwards n = 1 → 2 and
    // backwards n = 2 → 0.
    let xn = |n: f64| v([8.0 * n.powi(3), 12.0 * n * n, 12.0 * n, 6.0]);
    assert_eq!(model.propagate(&xn(1.0), 2.0, 4.0).unwrap().state, xn(2.0));
    assert_eq!(model.propagate(&xn(2.0), 4.0, 0.0).unwrap().state, xn(0.0));
    assert_eq!(
        model.propagate(&xn(-1.0), -2.0, 6.0).unwrap().state,
        xn(3.0)
    );
}

#[test]
fn tv4_2_and_tv4_6_difference_state_through_linear_dynamics() {
    // The backward-difference state U_n = (x_n, ∇x_n, ∇²x_n, ∇³x_n) of a cubic moves by
    // [Φ_U(h)]_ij = C(h + j − i − 1, j − i) (4.3.4)-(4.3.6), with Φ_U = F Φ_V F⁻¹, F = diag(i!),
    // so its generator is A_U = F A_V F⁻¹ with Ex. 4.12's A_V (τ = 1).
    let a_v = DMatrix::from_row_slice(
        4,
        4,
        &[
            0., 1., 1., 2., 0., 0., 2., 3., 0., 0., 0., 3., 0., 0., 0., 0.,
        ],
    );
    let f_diag = [1.0, 1.0, 2.0, 6.0];
    let a_u = DMatrix::from_fn(4, 4, |i, j| f_diag[i] * a_v[(i, j)] / f_diag[j]);
    let model = LinearDynamics::new(a_u).unwrap();
    let binomial = |x: f64, k: usize| (0..k).fold(1.0, |p, r| p * (x - r as f64) / (r + 1) as f64);
    let phi_u = |h: f64| {
        DMatrix::from_fn(4, 4, |i, j| {
            if j < i {
                0.0
            } else {
                binomial(h + (j - i) as f64 - 1.0, j - i)
            }
        })
    };
    let close = |a: &DMatrix<f64>, b: &DMatrix<f64>| (a - b).amax() <= 1e-14 * b.amax();
    let zero = DVector::zeros(4);
    let phi = |h: f64| {
        Dynamics::propagate(&model, &zero, 0.0, h)
            .unwrap()
            .transition
    };
    // TV4.2: Φ_U(1) is the upper triangle of ones, Φ_U(−1) = I − the superdiagonal,
    // Φ_U(2) = Φ_U(1)², and Ex. 4.7's Φ_U(h).
    let ones = DMatrix::from_fn(4, 4, |i, j| if j >= i { 1.0 } else { 0.0 });
    assert!(close(&phi(1.0), &ones), "{}", phi(1.0));
    let back = DMatrix::from_fn(4, 4, |i, j| match j as i64 - i as i64 {
        0 => 1.0,
        1 => -1.0,
        _ => 0.0,
    });
    assert!(close(&phi(-1.0), &back), "{}", phi(-1.0));
    assert!(close(&phi(2.0), &(&ones * &ones)));
    for h in [-2.5, -1.0, 0.5, 3.0, 7.0] {
        let ex47 = DMatrix::from_row_slice(
            4,
            4,
            &[
                1.0,
                h,
                (h * h + h) / 2.0,
                (h * h * h + 3.0 * h * h + 2.0 * h) / 6.0,
                0.0,
                1.0,
                h,
                (h * h + h) / 2.0,
                0.0,
                0.0,
                1.0,
                h,
                0.0,
                0.0,
                0.0,
                1.0,
            ],
        );
        assert!(close(&phi(h), &ex47), "Ex. 4.7 h {h}");
        assert!(close(&phi(h), &phi_u(h)), "(4.3.6) h {h}");
    }
    // TV4.6 (Ex. 4.7/4.9, x = t³, τ = 2): U_n = (8n³, 24n² − 24n + 8, 48n − 48, 48);
    // Φ_U(1) U_0 = U_1 = (8, 8, 0, 48), Φ_U(h) U_0 = U_h, and backwards.
    let u = |n: f64| {
        DVector::from_vec(vec![
            8.0 * n.powi(3),
            24.0 * n * n - 24.0 * n + 8.0,
            48.0 * n - 48.0,
            48.0,
        ])
    };
    assert_eq!(u(0.0).as_slice(), &[0.0, 8.0, -48.0, 48.0]);
    for (a, b) in [(0.0, 1.0), (0.0, 2.5), (3.0, -1.0), (1.0, 5.0)] {
        let got = Dynamics::propagate(&model, &u(a), a, b).unwrap().state;
        let err = (&got - u(b)).amax() / u(b).amax();
        assert!(err <= 1e-14, "U_{a} → U_{b}: {got} ({err:e})");
    }
}

#[test]
fn states_of_integer_polynomials_on_several_axes() {
    // Each axis an integer polynomial of degree ≤ m; the state at t_b, the exact derivatives
    // rounded, against propagate from the exact state at t_a (dyadic times).
    let mut rng = rand::rngs::StdRng::seed_from_u64(11);
    let mut worst: f64 = 0.0;
    for m in 0..=6 {
        for d in 1..=3 {
            let model = PolynomialDynamics::new(m, d);
            let polys: Vec<Vec<Q>> = (0..d)
                .map(|_| (0..=m).map(|_| z(rng.gen_range(-9..=9))).collect())
                .collect();
            let state_at = |t: &Q| {
                DVector::from_fn((m + 1) * d, |r, _| {
                    let (i, a) = (r / d, r % d);
                    f(&peval(&pderiv(&polys[a], i), t))
                })
            };
            for _ in 0..4 {
                let ta = f64::from(rng.gen_range(-64..=64)) / 16.0;
                let tb = f64::from(rng.gen_range(-64..=64)) / 16.0;
                let xa = state_at(&qf(ta));
                let p = model.propagate(&xa, ta, tb).unwrap();
                let want = state_at(&qf(tb));
                // Each entry relative to the sum of the magnitudes of its terms, Σ_j |Φ_rj x_j|.
                let terms = p.transition.abs() * xa.abs();
                let err = (0..want.len())
                    .map(|r| (p.state[r] - want[r]).abs() / terms[r].max(f64::MIN_POSITIVE))
                    .fold(0.0, f64::max);
                worst = worst.max(err);
                assert!(
                    err <= (m + 2) as f64 * f64::EPSILON,
                    "m {m}, d {d}, {ta} → {tb}: {err:e}"
                );
            }
        }
    }
    eprintln!("polynomial states: worst scaled error {worst:e}");
}

#[test]
fn linear_dynamics_through_the_trait() {
    // (4.6.51): ẍ = −x, X = (x, ẋ), Φ(ζ) = [[cos ζ, sin ζ], [−sin ζ, cos ζ]]; x = sin(t + 0.3).
    let rot = LinearDynamics::new(DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -1.0, 0.0])).unwrap();
    let model: &dyn Dynamics = &rot;
    assert_eq!(model.dimension(), 2);
    let state = |t: f64| DVector::from_vec(vec![(t + 0.3).sin(), (t + 0.3).cos()]);
    for (ta, tb) in [(0.0, 1.0), (2.0, -3.5), (-1.0, 7.25), (5.0, 5.0)] {
        let p = model.propagate(&state(ta), ta, tb).unwrap();
        let (c, s) = ((tb - ta).cos(), (tb - ta).sin());
        let phi = DMatrix::from_row_slice(2, 2, &[c, s, -s, c]);
        assert!((&p.transition - &phi).amax() <= 1e-14, "{ta} → {tb}");
        assert!((&p.state - state(tb)).amax() <= 1e-14, "{ta} → {tb}");
    }
}

#[test]
fn covariance_is_phi_s_phi_transpose_exactly() {
    // S_b = Φ S Φᵀ in exact rationals (dyadic ζ and S), against propagate_covariance.
    let mut rng = rand::rngs::StdRng::seed_from_u64(5);
    let mut worst: f64 = 0.0;
    for (m, d) in [(0, 1), (1, 3), (2, 2), (3, 1), (4, 3)] {
        let model = PolynomialDynamics::new(m, d);
        let n = model.dimension();
        // S = L Lᵀ with small dyadic L: symmetric positive definite, exact.
        let l = DMatrix::from_fn(n, n, |i, j| {
            if j < i {
                f64::from(rng.gen_range(-8..=8)) / 8.0
            } else if i == j {
                f64::from(rng.gen_range(1..=8)) / 4.0
            } else {
                0.0
            }
        });
        let s = &l * l.transpose();
        for zeta in [-2.5, 0.75, 4.0] {
            let (x, sb) = model
                .propagate_covariance(&DVector::from_element(n, 1.0), &s, 1.0, 1.0 + zeta)
                .unwrap();
            assert_eq!(x.len(), n);
            let phi = exact_kron_psi(m, d, &qf(zeta));
            let sq = s.map(qf);
            let want = to_f64(&mm(&mm(&phi, &sq), &phi.transpose()));
            let err = (&sb - &want).amax() / want.amax();
            worst = worst.max(err);
            assert!(err <= 1e-15, "m {m}, d {d}, ζ {zeta}: {err:e}");
            assert_eq!(sb, sb.transpose(), "symmetric");
        }
    }
    eprintln!("Φ S Φᵀ: worst relative error {worst:e}");
}

#[test]
fn group_property_and_epoch_times() {
    let model = PolynomialDynamics::new(4, 2);
    let x = DVector::from_vec((0..10).map(|k| f64::from(k) - 4.5).collect());
    // (4.2.20)-(4.2.24): Φ(t_b, t_a) = Φ(t_b, t_m) Φ(t_m, t_a); there and back returns X.
    let (ta, tm, tb) = (0.5, 2.25, -1.75);
    let ab = model.propagate(&x, ta, tb).unwrap();
    let am = model.propagate(&x, ta, tm).unwrap();
    let mb = model.propagate(&am.state, tm, tb).unwrap();
    let chain = &mb.transition * &am.transition;
    assert!((&chain - &ab.transition).amax() <= 1e-13 * ab.transition.amax());
    assert!((&mb.state - &ab.state).amax() <= 1e-13 * ab.state.amax());
    let back = model.propagate(&ab.state, tb, ta).unwrap();
    assert!((&back.state - &x).amax() <= 1e-13 * ab.state.amax());
    // Unix-epoch times: the same step gives the same Φ and state as near zero (exactly, as the
    // step t_b − t_a is exact for these times).
    let epoch = 1.7e9;
    let near = model.propagate(&x, 0.25, 3.75).unwrap();
    let far = model.propagate(&x, epoch + 0.25, epoch + 3.75).unwrap();
    assert_eq!(near, far);
}

#[test]
fn refusals_are_typed() {
    let model = PolynomialDynamics::new(1, 2);
    let x = DVector::from_element(4, 1.0);
    let e = model.propagate(&DVector::zeros(3), 0.0, 1.0).unwrap_err();
    assert!(
        matches!(
            e,
            Error::InvalidParameter {
                name: Param::State,
                ..
            }
        ),
        "{e}"
    );
    let mut bad = x.clone();
    bad[2] = f64::NAN;
    let e = model.propagate(&bad, 0.0, 1.0).unwrap_err();
    assert!(
        matches!(
            e,
            Error::NonFinite {
                what: "state entry",
                ..
            }
        ),
        "{e}"
    );
    for (ta, tb) in [
        (f64::NAN, 1.0),
        (0.0, f64::INFINITY),
        (f64::NEG_INFINITY, 0.0),
    ] {
        let e = model.propagate(&x, ta, tb).unwrap_err();
        assert!(matches!(e, Error::NonFinite { what: "time", .. }), "{e}");
    }
    // A step whose Φ overflows, and a state that overflows though Φ does not.
    let e = model.propagate(&x, -1.7e308, 1.7e308).unwrap_err();
    assert!(matches!(e, Error::NonFinite { .. }), "{e}");
    let e = model
        .propagate(&DVector::from_element(4, 1e308), 0.0, 10.0)
        .unwrap_err();
    assert!(
        matches!(
            e,
            Error::NonFinite {
                what: "propagated state entry",
                ..
            }
        ),
        "{e}"
    );
    // Covariances of the wrong shape or with a non-finite entry.
    let e = model
        .propagate_covariance(&x, &DMatrix::identity(3, 3), 0.0, 1.0)
        .unwrap_err();
    assert!(
        matches!(
            e,
            Error::InvalidParameter {
                name: Param::Covariance,
                ..
            }
        ),
        "{e}"
    );
    let mut s = DMatrix::identity(4, 4);
    s[(1, 2)] = f64::INFINITY;
    let e = model.propagate_covariance(&x, &s, 0.0, 1.0).unwrap_err();
    assert!(
        matches!(
            e,
            Error::NonFinite {
                what: "covariance entry",
                ..
            }
        ),
        "{e}"
    );
    let e = model
        .propagate_covariance(&x, &DMatrix::from_element(4, 4, 1e300), 0.0, 1e10)
        .unwrap_err();
    assert!(matches!(e, Error::NonFinite { .. }), "{e}");
    // LinearDynamics through the trait: the same checks, and its own overflow.
    let growth = LinearDynamics::new(DMatrix::from_element(1, 1, 1000.0)).unwrap();
    let e = growth.propagate(&DVector::zeros(2), 0.0, 1.0).unwrap_err();
    assert!(
        matches!(
            e,
            Error::InvalidParameter {
                name: Param::State,
                ..
            }
        ),
        "{e}"
    );
    let e =
        Dynamics::propagate(&growth, &DVector::from_element(1, 1.0), 0.0, f64::NAN).unwrap_err();
    assert!(matches!(e, Error::NonFinite { what: "time", .. }), "{e}");
    assert!(Dynamics::propagate(&growth, &DVector::from_element(1, 1.0), 0.0, 1.0).is_err());
    let e = Dynamics::propagate(&growth, &DVector::from_element(1, 1e300), 0.0, 0.5).unwrap_err();
    assert!(
        matches!(
            e,
            Error::NonFinite {
                what: "propagated state entry",
                ..
            }
        ),
        "{e}"
    );
}
