//! `model::nonlinear`: the state and the variational-equation transition matrix of
//! `dX/dt = F(X, t)` and `dX/dt = A(t) X` against Morrison's ch. 4 closed forms — Ex. 4.15's
//! time-varying `A(t)` (TV4.11: `Φ` from the fundamental solutions `e^{t²}`, `e^t`), Ex. 4.18
//! `ẋ = x²` (TV4.12: `x̄/(1 − ζx̄)`, `Φ = 1/(1 − ζx̄)²`; Ex. 4.22's printed `Φ(t, 1)`, TV4.14),
//! Ex. 4.19 / Ex. 11.14 `ẍ = ±kẋ²` (TV4.13 and Ex. 11.14 (II): `ẋ₀/(1 ∓ kẋ₀ζ)`, the logarithm,
//! their derivatives) — with the caller's Jacobian and with central differences, forwards and
//! backwards; against a fourth-order central-difference Jacobian of the integrated flow (drag,
//! a pendulum, a 3-D ballistic state with quadratic drag; the flow at tolerance 1e-13);
//! the group property and chain rule `Φ(t_b, t_a) = Φ(t_b, t_m) Φ(t_m, t_a)`; Unix-epoch times;
//! `Φ S Φᵀ` with the closed-form `Φ`; typed refusals of bad input and of bad `F`.

mod common;

use common::book::assert_printed;
use nalgebra::{DMatrix, DVector};
use seqsmooth::error::Param;
use seqsmooth::model::dynamics::Dynamics;
use seqsmooth::model::nonlinear::NonlinearDynamics;
use seqsmooth::Error;

fn rel(got: &DMatrix<f64>, want: &DMatrix<f64>) -> f64 {
    (got - want).amax() / want.amax()
}

fn v(a: &[f64]) -> DVector<f64> {
    DVector::from_vec(a.to_vec())
}

/// Ex. 4.19 / Ex. 11.14: `ẍ = s k ẋ²`, `X = (x, ẋ)` (`s = +1` Ex. 4.19, `−1` the drag of
/// Ex. 11.14); `A = [[0, 1], [0, 2 s k ẋ]]` when `analytic`.
fn quadratic_drag(s: f64, k: f64, analytic: bool) -> NonlinearDynamics {
    let d = NonlinearDynamics::new(2, move |_t, x: &DVector<f64>| {
        v(&[x[1], s * k * x[1] * x[1]])
    });
    if analytic {
        d.with_jacobian(move |_t, x: &DVector<f64>| {
            DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 2.0 * s * k * x[1]])
        })
    } else {
        d
    }
}

/// The closed form of `ẍ = s k ẋ²` from `(x₀, ẋ₀)` over `ζ`: with `c = 1 − s k ẋ₀ ζ`,
/// `ẋ = ẋ₀/c`, `x = x₀ − (s/k) ln c`; `Φ = [[1, ζ/c], [0, 1/c²]]`.
fn quadratic_drag_exact(
    s: f64,
    k: f64,
    x0: &DVector<f64>,
    zeta: f64,
) -> (DVector<f64>, DMatrix<f64>) {
    let c = 1.0 - s * k * x0[1] * zeta;
    let state = v(&[x0[0] - s / k * c.ln(), x0[1] / c]);
    let phi = DMatrix::from_row_slice(2, 2, &[1.0, zeta / c, 0.0, 1.0 / (c * c)]);
    (state, phi)
}

#[test]
fn ex_4_15_time_varying_linear_closed_form() {
    // TV4.11: (1 − 2t)ẍ + (1 + 4t²)ẋ − (2 − 2t + 4t²)x = 0, solutions a e^{t²} + b e^t;
    // A(t) = [[0, 1], [(2 − 2t + 4t²)/(1 − 2t), −(1 + 4t²)/(1 − 2t)]] (singular at t = 1/2, so
    // no interval crosses it). With s = t + ζ, E = e^{s² − t²}:
    // Φ = [[E − 2t e^ζ, e^ζ − E], [2sE − 2t e^ζ, e^ζ − 2sE]]/(1 − 2t).
    let model = NonlinearDynamics::time_varying_linear(2, |t| {
        let w = 1.0 - 2.0 * t;
        DMatrix::from_row_slice(
            2,
            2,
            &[
                0.0,
                1.0,
                (2.0 - 2.0 * t + 4.0 * t * t) / w,
                -(1.0 + 4.0 * t * t) / w,
            ],
        )
    });
    assert!(model.has_jacobian());
    let phi = |t: f64, s: f64| {
        let (e, ez, w) = ((s * s - t * t).exp(), (s - t).exp(), 1.0 - 2.0 * t);
        DMatrix::from_row_slice(
            2,
            2,
            &[
                e - 2.0 * t * ez,
                ez - e,
                2.0 * s * e - 2.0 * t * ez,
                ez - 2.0 * s * e,
            ],
        ) / w
    };
    let (a, b) = (0.7, -1.3);
    let state = |t: f64| {
        let (e2, e1) = ((t * t).exp(), t.exp());
        v(&[a * e2 + b * e1, 2.0 * a * t * e2 + b * e1])
    };
    let mut worst: (f64, f64) = (0.0, 0.0);
    for (ta, tb) in [
        (0.0, 0.4),
        (0.4, -1.0),
        (-1.0, 0.3),
        (-0.5, 0.0),
        (1.0, 2.0),
        (2.0, 0.75),
        (0.6, 1.8),
    ] {
        let p = model.propagate(&state(ta), ta, tb).unwrap();
        let e_phi = rel(&p.transition, &phi(ta, tb));
        let e_x = (&p.state - state(tb)).amax() / state(tb).amax();
        worst = (worst.0.max(e_phi), worst.1.max(e_x));
        assert!(e_phi <= 1e-8, "Φ({tb}, {ta}): {e_phi:e}");
        assert!(e_x <= 1e-8, "X({tb}) from X({ta}): {e_x:e}");
    }
    eprintln!("Ex. 4.15: worst Φ {:e}, worst state {:e}", worst.0, worst.1);
}

#[test]
fn ex_4_18_and_ex_4_22_x_squared() {
    // TV4.12: ẋ = x², x(t_n + ζ) = x̄/(1 − ζx̄), Φ = 1/(1 − ζx̄)², A = 2x̄; analytic and
    // central-difference Jacobians, forwards and backwards.
    let plain = NonlinearDynamics::new(1, |_t, x: &DVector<f64>| x.map(|u| u * u));
    let analytic = plain
        .clone()
        .with_jacobian(|_t, x: &DVector<f64>| DMatrix::from_element(1, 1, 2.0 * x[0]));
    let mut worst: f64 = 0.0;
    for model in [&plain, &analytic] {
        for (xbar, zeta) in [
            (1.0, 0.5),
            (1.0, -3.0),
            (-2.0, 1.5),
            (0.5, 1.9),
            (3.0, -0.25),
        ] {
            let p = model.propagate(&v(&[xbar]), 4.0, 4.0 + zeta).unwrap();
            let c = 1.0 - zeta * xbar;
            let ex = (p.state[0] - xbar / c).abs() / (xbar / c).abs();
            let ephi = (p.transition[(0, 0)] - 1.0 / (c * c)).abs() * c * c;
            worst = worst.max(ex).max(ephi);
            assert!(
                ex <= 1e-9 && ephi <= 1e-9,
                "x̄ {xbar}, ζ {zeta}: {ex:e} {ephi:e}"
            );
        }
        // Ex. 4.22 (TV4.14): x(1) = 1, exact φ(t, 1) = 1/(2 − t)² along x = 1/(2 − t):
        // 1, 1.234568, 1.5625, 2.040816, 2.777778, 4 at t = 1.0, 1.1, …, 1.5.
        let printed = ["1", "1.234568", "1.5625", "2.040816", "2.777778", "4"];
        for (k, want) in printed.iter().enumerate() {
            let t = 1.0 + 0.1 * k as f64;
            let p = model.propagate(&v(&[1.0]), 1.0, t).unwrap();
            assert_printed(p.transition[(0, 0)], want, &format!("Ex. 4.22 φ({t}, 1)"));
        }
    }
    eprintln!("Ex. 4.18: worst relative error {worst:e}");
}

#[test]
fn ex_4_19_and_ex_11_14_quadratic_drag_closed_form() {
    // TV4.13 (s = +1, exact Φ₂₂ = 1/(1 − kζẋ)²) and Ex. 11.14 (s = −1, (II):
    // x = x₀ + (1/k) ln(1 + kẋ₀t)); every case with c = 1 − s k ẋ₀ ζ > 0.
    let mut worst: f64 = 0.0;
    for (s, k, xdot, zetas) in [
        (1.0, 0.5, 1.0, [-3.0, -1.0, 0.5, 1.5]),
        (-1.0, 0.5, 2.0, [-0.4, -0.25, 1.0, 5.0]),
        (-1.0, 2e-3, -300.0, [0.5, 1.5, -0.3, -1.0]),
    ] {
        for analytic in [true, false] {
            let model = quadratic_drag(s, k, analytic);
            let x0 = v(&[10.0, xdot]);
            for &zeta in &zetas {
                let p = model.propagate(&x0, -7.0, -7.0 + zeta).unwrap();
                let (x, phi) = quadratic_drag_exact(s, k, &x0, zeta);
                let e = rel(&p.transition, &phi).max((&p.state - &x).amax() / x.amax());
                worst = worst.max(e);
                assert!(
                    e <= 1e-9,
                    "s {s}, k {k}, ẋ {xdot}, ζ {zeta}, analytic {analytic}: {e:e}"
                );
            }
        }
    }
    eprintln!("quadratic drag: worst relative error {worst:e}");
}

/// `∂X(t_b)/∂X(t_a)` of the flow of `model` by fourth-order central differences,
/// `[X(x − 2h) − 8X(x − h) + 8X(x + h) − X(x + 2h)]/(12h)`, `h_j = 10⁻³ max(|x_j|, 1)`.
fn flow_jacobian(model: &NonlinearDynamics, x: &DVector<f64>, ta: f64, tb: f64) -> DMatrix<f64> {
    let n = x.len();
    let flow = |probe: &DVector<f64>| model.propagate(probe, ta, tb).unwrap().state;
    let mut out = DMatrix::zeros(n, n);
    for c in 0..n {
        let h = (x[c] + 1e-3 * x[c].abs().max(1.0)) - x[c];
        let at = |m: f64| {
            let mut p = x.clone();
            p[c] += m * h;
            flow(&p)
        };
        let col = (at(-2.0) - at(-1.0) * 8.0 + at(1.0) * 8.0 - at(2.0)) / (12.0 * h);
        out.set_column(c, &col);
    }
    out
}

/// An undamped pendulum `θ̈ = −4 sin θ`, `X = (θ, θ̇)`.
fn pendulum(analytic: bool) -> NonlinearDynamics {
    let d = NonlinearDynamics::new(2, |_t, x: &DVector<f64>| v(&[x[1], -4.0 * x[0].sin()]));
    if analytic {
        d.with_jacobian(|_t, x: &DVector<f64>| {
            DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -4.0 * x[0].cos(), 0.0])
        })
    } else {
        d
    }
}

/// A ballistic state `(x, y, z, ẋ, ẏ, ż)` under gravity and quadratic drag,
/// `dv/dt = −k |v| v − g e_z`; `∂(dv/dt)/∂v = −k (|v| I + v vᵀ/|v|)`.
fn ballistic(analytic: bool) -> NonlinearDynamics {
    const K: f64 = 1e-3;
    const G: f64 = 9.81;
    let d = NonlinearDynamics::new(6, |_t, x: &DVector<f64>| {
        let vel = x.rows(3, 3);
        let speed = vel.norm();
        let mut f = DVector::zeros(6);
        f.rows_mut(0, 3).copy_from(&vel);
        f.rows_mut(3, 3).copy_from(&(vel * (-K * speed)));
        f[5] -= G;
        f
    });
    if analytic {
        d.with_jacobian(|_t, x: &DVector<f64>| {
            let vel = x.rows(3, 3).into_owned();
            let speed = vel.norm();
            let mut j = DMatrix::zeros(6, 6);
            for i in 0..3 {
                j[(i, 3 + i)] = 1.0;
            }
            let dv = (DMatrix::identity(3, 3) * speed + &vel * vel.transpose() / speed) * -K;
            j.view_mut((3, 3), (3, 3)).copy_from(&dv);
            j
        })
    } else {
        d
    }
}

#[test]
fn variational_phi_matches_differences_of_the_flow() {
    // Φ at the default tolerances (1e-10) against the flow's own derivative, differenced on
    // the flow integrated at 1e-13: agreement within 1e-7 of the largest entry, forwards and
    // backwards, with the caller's Jacobian and with central differences.
    type Case = (
        &'static str,
        fn(bool) -> NonlinearDynamics,
        DVector<f64>,
        f64,
        f64,
    );
    let cases: Vec<Case> = vec![
        (
            "drag",
            |a| quadratic_drag(-1.0, 0.1, a),
            v(&[1.0, 2.0]),
            0.0,
            3.0,
        ),
        (
            "drag",
            |a| quadratic_drag(-1.0, 0.1, a),
            v(&[1.0, 2.0]),
            3.0,
            -0.5,
        ),
        ("pendulum", pendulum, v(&[2.5, 0.3]), 1.0, 4.0),
        ("pendulum", pendulum, v(&[-1.0, 2.0]), 1.0, -2.0),
        (
            "ballistic",
            ballistic,
            v(&[1000.0, 2000.0, 50.0, 150.0, -80.0, 200.0]),
            0.0,
            12.0,
        ),
        (
            "ballistic",
            ballistic,
            v(&[-500.0, 300.0, 900.0, -60.0, 120.0, -40.0]),
            20.0,
            17.0,
        ),
    ];
    let mut worst: f64 = 0.0;
    for (name, make, x, ta, tb) in &cases {
        let tight = make(true).with_tolerances(1e-13, 1e-13).unwrap();
        let oracle = flow_jacobian(&tight, x, *ta, *tb);
        for analytic in [true, false] {
            let model = make(analytic);
            assert_eq!(model.has_jacobian(), analytic);
            let p = model.propagate(x, *ta, *tb).unwrap();
            let e = rel(&p.transition, &oracle);
            worst = worst.max(e);
            assert!(e <= 1e-7, "{name} {ta} → {tb}, analytic {analytic}: {e:e}");
        }
    }
    // The pendulum's energy θ̇²/2 − 4 cos θ is conserved along the integrated state.
    let energy = |x: &DVector<f64>| x[1] * x[1] / 2.0 - 4.0 * x[0].cos();
    let x = v(&[2.5, 0.3]);
    let p = pendulum(false).propagate(&x, 0.0, 10.0).unwrap();
    assert!((energy(&p.state) - energy(&x)).abs() <= 1e-8 * energy(&x).abs());
    eprintln!("Φ against the differenced flow: worst relative error {worst:e}");
}

#[test]
fn group_property_and_chain_rule() {
    let mut worst: (f64, f64, f64) = (0.0, 0.0, 0.0);
    let cases: Vec<(NonlinearDynamics, DVector<f64>)> = vec![
        (quadratic_drag(-1.0, 0.1, true), v(&[1.0, 2.0])),
        (pendulum(false), v(&[2.5, 0.3])),
        (
            ballistic(true),
            v(&[1000.0, 2000.0, 50.0, 150.0, -80.0, 200.0]),
        ),
    ];
    for (model, x) in &cases {
        for (ta, tm, tb) in [(0.0, 1.5, 4.0), (2.0, -1.0, 0.5), (1.0, 3.0, -0.5)] {
            // Forwards then backwards returns the state; Φ(t_a, t_b) Φ(t_b, t_a) = I.
            let ab = model.propagate(x, ta, tb).unwrap();
            let ba = model.propagate(&ab.state, tb, ta).unwrap();
            let e_back = (&ba.state - x).amax() / x.amax();
            let n = x.len();
            let e_inv = rel(&(&ba.transition * &ab.transition), &DMatrix::identity(n, n));
            // Φ(t_b, t_a) = Φ(t_b, t_m) Φ(t_m, t_a) along the one trajectory.
            let am = model.propagate(x, ta, tm).unwrap();
            let mb = model.propagate(&am.state, tm, tb).unwrap();
            let e_chain = rel(&(&mb.transition * &am.transition), &ab.transition)
                .max((&mb.state - &ab.state).amax() / ab.state.amax());
            worst = (
                worst.0.max(e_back),
                worst.1.max(e_inv),
                worst.2.max(e_chain),
            );
            assert!(e_back <= 1e-8, "{model:?} {ta} ⇄ {tb}: {e_back:e}");
            assert!(e_inv <= 1e-8, "{model:?} {ta} ⇄ {tb}: {e_inv:e}");
            assert!(e_chain <= 1e-8, "{model:?} {ta} → {tm} → {tb}: {e_chain:e}");
        }
    }
    eprintln!(
        "there and back {:e}, Φ⁻¹Φ {:e}, chain {:e}",
        worst.0, worst.1, worst.2
    );
}

#[test]
fn unix_epoch_times() {
    let epoch = 1.7e9;
    // An autonomous F: the step t_b − t_a is exact at both origins and the integration runs
    // in ζ = t − t_a, so the results are identical.
    let drag = quadratic_drag(-1.0, 0.1, false);
    let x = v(&[1.0, 2.0]);
    for (ta, tb) in [(0.5, 3.0), (2.25, -1.0)] {
        let near = drag.propagate(&x, ta, tb).unwrap();
        let far = drag.propagate(&x, epoch + ta, epoch + tb).unwrap();
        assert_eq!(near, far, "{ta} → {tb}");
    }
    // A time-varying F sees the absolute time, resolved to ulp(1.7e9)/2 = 1.2e-7: ẋ = cos(t − t₀) x,
    // Φ = exp(sin(t_b − t₀) − sin(t_a − t₀)), so ln Φ is off by at most |t_b − t_a| · 1.2e-7.
    // Given as A(t) and as F(X, t) with central differences.
    let models = |t0: f64| {
        [
            NonlinearDynamics::time_varying_linear(1, move |t| {
                DMatrix::from_element(1, 1, (t - t0).cos())
            }),
            NonlinearDynamics::new(1, move |t, x: &DVector<f64>| x * (t - t0).cos()),
        ]
    };
    for (t0, model) in [0.0, epoch]
        .into_iter()
        .flat_map(|t0| models(t0).map(|m| (t0, m)))
    {
        for (ta, tb) in [(0.5, 3.0), (2.25, -1.0)] {
            let p = model.propagate(&v(&[2.0]), t0 + ta, t0 + tb).unwrap();
            let want = (tb.sin() - ta.sin()).exp();
            let e = (p.transition[(0, 0)] / want).ln().abs();
            let bound = 1e-9 + (tb - ta).abs() * 0.5 * (t0 + 4.0) * f64::EPSILON;
            let _ = model.has_jacobian();
            assert!(e <= bound, "t₀ {t0}, {ta} → {tb}: {e:e} > {bound:e}");
            assert!((p.state[0] - 2.0 * p.transition[(0, 0)]).abs() <= 1e-9 * p.state[0].abs());
            eprintln!("t₀ {t0}, {ta} → {tb}: ln Φ off by {e:e} (bound {bound:e})");
        }
    }
}

#[test]
fn covariance_is_phi_s_phi_transpose_with_the_closed_form_phi() {
    let s = DMatrix::from_row_slice(2, 2, &[4.0, -0.6, -0.6, 0.25]);
    let x0 = v(&[3.0, 2.0]);
    for zeta in [-0.5, 2.0] {
        let (x, sb) = quadratic_drag(-1.0, 0.5, false)
            .propagate_covariance(&x0, &s, 1.0, 1.0 + zeta)
            .unwrap();
        let (xe, phi) = quadratic_drag_exact(-1.0, 0.5, &x0, zeta);
        let want = &phi * &s * phi.transpose();
        let e = rel(&sb, &want);
        assert!(e <= 1e-9, "ζ {zeta}: {e:e}");
        assert!((&x - &xe).amax() <= 1e-9 * xe.amax());
        assert_eq!(sb, sb.transpose());
    }
}

#[test]
fn bad_input_and_bad_fields_are_refused_by_type() {
    let drag = quadratic_drag(-1.0, 0.5, false);
    let x = v(&[1.0, 2.0]);
    let dynamics_error = |e: &Error| {
        matches!(
            e,
            Error::InvalidParameter {
                name: Param::Dynamics,
                ..
            }
        )
    };
    // The caller's input.
    let e = drag.propagate(&v(&[1.0]), 0.0, 1.0).unwrap_err();
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
    let e = drag.propagate(&v(&[1.0, f64::NAN]), 0.0, 1.0).unwrap_err();
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
        let e = drag.propagate(&x, ta, tb).unwrap_err();
        assert!(matches!(e, Error::NonFinite { what: "time", .. }), "{e}");
    }
    let e = drag
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
    for (rel_tol, abs_tol) in [
        (0.0, 1e-9),
        (1e-9, -1.0),
        (f64::NAN, 1e-9),
        (1e-9, f64::INFINITY),
    ] {
        let e = drag.clone().with_tolerances(rel_tol, abs_tol).unwrap_err();
        assert!(matches!(e, Error::InvalidParameter { .. }), "{e}");
    }
    // F with a NaN, of the wrong size, at the start or later; a Jacobian of the wrong size or
    // with a NaN; A(t) of the wrong size; each also over a zero step where F is checked.
    let models: Vec<(&str, NonlinearDynamics)> = vec![
        (
            "F NaN",
            NonlinearDynamics::new(2, |_t, _x: &DVector<f64>| v(&[1.0, f64::NAN])),
        ),
        (
            "F short",
            NonlinearDynamics::new(2, |_t, _x: &DVector<f64>| v(&[1.0])),
        ),
        (
            "F long",
            NonlinearDynamics::new(2, |_t, x: &DVector<f64>| v(&[x[1], 0.0, 0.0])),
        ),
        (
            "Jacobian 1x2",
            NonlinearDynamics::new(2, |_t, x: &DVector<f64>| x.clone())
                .with_jacobian(|_t, _x: &DVector<f64>| DMatrix::zeros(1, 2)),
        ),
        (
            "Jacobian NaN",
            NonlinearDynamics::new(2, |_t, x: &DVector<f64>| x.clone())
                .with_jacobian(|_t, _x: &DVector<f64>| DMatrix::from_element(2, 2, f64::NAN)),
        ),
        (
            "A(t) 3x3",
            NonlinearDynamics::time_varying_linear(2, |_t| DMatrix::identity(3, 3)),
        ),
    ];
    for (what, model) in &models {
        for tb in [1.0, -1.0] {
            let e = model.propagate(&x, 0.0, tb).unwrap_err();
            assert!(dynamics_error(&e), "{what}, t_b {tb}: {e}");
        }
    }
    for (what, model) in &models[..3] {
        let e = model.propagate(&x, 0.0, 0.0).unwrap_err();
        assert!(dynamics_error(&e), "{what}, zero step: {e}");
    }
    // F that turns NaN at t > 0.5 only: refused, the message at the time it failed.
    let late = NonlinearDynamics::new(
        1,
        |t, x: &DVector<f64>| {
            if t > 0.5 {
                v(&[f64::NAN])
            } else {
                x.clone()
            }
        },
    );
    assert!(late.propagate(&v(&[1.0]), 0.0, 0.25).is_ok());
    let e = late.propagate(&v(&[1.0]), 0.0, 2.0).unwrap_err();
    assert!(dynamics_error(&e), "{e}");
    // Finite-time blow-up: ẋ = x² from x = 1 is infinite at ζ = 1.
    for analytic in [false, true] {
        let mut blow = NonlinearDynamics::new(1, |_t, x: &DVector<f64>| x.map(|u| u * u));
        if analytic {
            blow =
                blow.with_jacobian(|_t, x: &DVector<f64>| DMatrix::from_element(1, 1, 2.0 * x[0]));
        }
        let e = blow.propagate(&v(&[1.0]), 0.0, 2.0).unwrap_err();
        assert!(dynamics_error(&e), "blow-up: {e}");
    }
    // An empty state: whatever the answer, no panic.
    let empty = NonlinearDynamics::new(0, |_t, x: &DVector<f64>| x.clone());
    if let Ok(p) = empty.propagate(&DVector::zeros(0), 0.0, 1.0) {
        assert_eq!((p.state.len(), p.transition.shape()), (0, (0, 0)));
    }
    // A stiff system beyond the step budget.
    let stiff = NonlinearDynamics::time_varying_linear(2, |_t| {
        DMatrix::from_row_slice(2, 2, &[-1e7, 0.0, 0.0, -1.0])
    });
    let e = stiff.propagate(&x, 0.0, 1e3).unwrap_err();
    assert!(dynamics_error(&e), "stiff: {e}");
}

/// `propagate_state` integrates the trajectory alone: Ex. 11.14's drag state
/// (`ẋ₀/(1 + kẋ₀ζ)`, `(1/k) ln(1 + kẋ₀ζ)`) within 1e-9 forwards and backwards, equal to
/// `propagate`'s state within the tolerance, with at most a third of the evaluations of `F`
/// (no differenced variational equations: `2n = 4` fewer per stage).
#[test]
fn propagate_state_integrates_the_trajectory_alone() {
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::Arc;
    let calls = Arc::new(AtomicUsize::new(0));
    let counted = Arc::clone(&calls);
    let k = 0.5;
    let drag = NonlinearDynamics::new(2, move |_t, x: &DVector<f64>| {
        counted.fetch_add(1, Ordering::Relaxed);
        v(&[x[1], -k * x[1] * x[1]])
    });
    let x0 = v(&[0.3, 2.0]);
    for zeta in [1.0, 3.5, -0.4] {
        calls.store(0, Ordering::Relaxed);
        let full = drag.propagate(&x0, 0.0, zeta).unwrap();
        let with_phi = calls.swap(0, Ordering::Relaxed);
        let alone = drag.propagate_state(&x0, 0.0, zeta).unwrap();
        let without = calls.load(Ordering::Relaxed);
        let speed = 2.0 / (1.0 + k * 2.0 * zeta);
        let position = 0.3 + (1.0 + k * 2.0 * zeta).ln() / k;
        assert!((alone[1] - speed).abs() < 1e-9 && (alone[0] - position).abs() < 1e-9);
        assert!((&alone - &full.state).amax() < 1e-9, "{zeta}");
        assert!(3 * without <= with_phi, "{without} against {with_phi}");
    }
    // A field that fails is refused as by `propagate`.
    let bad = NonlinearDynamics::new(
        1,
        |t, x: &DVector<f64>| {
            if t > 0.5 {
                v(&[f64::NAN])
            } else {
                x.clone()
            }
        },
    );
    let e = bad.propagate_state(&v(&[1.0]), 0.0, 1.0).unwrap_err();
    assert!(
        matches!(
            e,
            Error::InvalidParameter {
                name: Param::Dynamics,
                ..
            }
        ),
        "{e}"
    );
}
