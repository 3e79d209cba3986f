//! `model::observation`: `LinearObservation` (`G = M X`, (8.2.2)) against the product in exact
//! rationals; `NonlinearObservation` against the observation matrices Morrison derives in
//! closed form — Ex. 11.1 (range `sqrt(d² + x²)`), Ex. 11.7 (range and azimuth of `(x, d)`,
//! `M = [[x/g, d/g], [d/g², −x/g²]]`), Ex. 11.13 (the range rate of a moving body at time `t`,
//! `M = k⁻³ [d² ẋ, d²(x + 2tẋ) + (x + tẋ)³]`) — its central-difference Jacobian within 1e-7
//! relative of them, the caller's Jacobian passed through; the unwrapped default residual; typed
//! refusals of bad shapes and non-finite values.

mod common;

use common::rational::*;
use nalgebra::{DMatrix, DVector};
use num_traits::Zero;
use rand::{Rng, SeedableRng};
use seqsmooth::error::Param;
use seqsmooth::model::observation::{LinearObservation, NonlinearObservation, Observation};
use seqsmooth::scalar::rational_from_f64;
use seqsmooth::Error;

fn v(a: &[f64]) -> DVector<f64> {
    DVector::from_vec(a.to_vec())
}

#[test]
fn linear_observation_is_m_x() {
    // Random dyadic M and X: each value is the exact sum rounded once or a few times; the
    // bound is the sum of the magnitudes of the terms times (columns) ε.
    let mut rng = rand::rngs::StdRng::seed_from_u64(3);
    for (rows, cols) in [(1, 1), (1, 4), (2, 6), (3, 3), (4, 9)] {
        let m = DMatrix::from_fn(rows, cols, |_, _| {
            f64::from(rng.gen_range(-999..=999)) / 64.0
        });
        let x = DVector::from_fn(cols, |_, _| f64::from(rng.gen_range(-999..=999)) / 8.0);
        let obs = LinearObservation::new(m.clone()).unwrap();
        assert_eq!((obs.components(), obs.state_dimension()), (rows, cols));
        assert_eq!(obs.matrix(), &m);
        let p = obs.predict(&x, 17.0).unwrap();
        assert_eq!(p.jacobian, m);
        for r in 0..rows {
            let exact = (0..cols).fold(Q::zero(), |s, c| {
                s + rational_from_f64(m[(r, c)]).unwrap() * rational_from_f64(x[c]).unwrap()
            });
            let terms: f64 = (0..cols).map(|c| (m[(r, c)] * x[c]).abs()).sum();
            let err = (p.value[r] - f(&exact)).abs();
            assert!(
                err <= cols as f64 * f64::EPSILON * terms,
                "{rows}x{cols} row {r}: {err:e}"
            );
        }
    }
    // (8.3.5): the first component of a polynomial state.
    let first = LinearObservation::value_of(4);
    assert_eq!(
        first.matrix(),
        &DMatrix::from_row_slice(1, 4, &[1.0, 0.0, 0.0, 0.0])
    );
    let p = first.predict(&v(&[2.5, -1.0, 7.0, 3.0]), 0.0).unwrap();
    assert_eq!(p.value.as_slice(), &[2.5]);
    assert_eq!(LinearObservation::value_of(0).state_dimension(), 1);
    assert_eq!(first.residual(0, 3.0, 2.5), 0.5);
}

/// `‖got − want‖_max / ‖want‖_max`.
fn rel(got: &DMatrix<f64>, want: &DMatrix<f64>) -> f64 {
    (got - want).amax() / want.amax()
}

#[test]
fn central_differences_match_the_books_observation_matrices() {
    let mut worst: f64 = 0.0;
    // Ex. 11.1: ρ = sqrt(d² + x²), m(x) = x/sqrt(d² + x²) (d = 3).
    let range = NonlinearObservation::new(1, 1, |_t, x: &DVector<f64>| {
        v(&[(9.0 + x[0] * x[0]).sqrt()])
    });
    for x in [-40.0, -4.0, 0.0, 0.5, 4.0, 1e3] {
        let p = range.predict(&v(&[x]), 0.0).unwrap();
        let g = (9.0 + x * x).sqrt();
        assert_eq!(p.value[0], g);
        let want = DMatrix::from_element(1, 1, x / g);
        // m(0) = 0: measured absolutely against the unit slope scale.
        let e = (&p.jacobian - &want).amax() / want.amax().max(1.0);
        worst = worst.max(e);
        assert!(e <= 1e-7, "Ex. 11.1 x {x}: {e:e}");
    }
    // Ex. 11.7: X = (x, d), ρ = g = sqrt(d² + x²), ψ = arctan(x/d).
    let range_azimuth = NonlinearObservation::new(2, 2, |_t, s: &DVector<f64>| {
        v(&[(s[0] * s[0] + s[1] * s[1]).sqrt(), (s[0] / s[1]).atan()])
    });
    for (x, d) in [(4.0, 3.0), (-2.0, 7.5), (1e3, 20.0), (0.01, 0.02)] {
        let p = range_azimuth.predict(&v(&[x, d]), 0.0).unwrap();
        let g = (x * x + d * d).sqrt();
        let want = DMatrix::from_row_slice(2, 2, &[x / g, d / g, d / (g * g), -x / (g * g)]);
        for r in 0..2 {
            let e = rel(
                &p.jacobian.rows(r, 1).into_owned(),
                &want.rows(r, 1).into_owned(),
            );
            worst = worst.max(e);
            assert!(e <= 1e-7, "Ex. 11.7 ({x}, {d}) row {r}: {e:e}");
        }
    }
    // Ex. 11.13: X = (x, ẋ) at t = 0, observed at t: ρ̇ = (x + tẋ) ẋ / k, k = sqrt(d² + (x + tẋ)²).
    let d = 5.0;
    let rate = NonlinearObservation::new(1, 2, move |t, s: &DVector<f64>| {
        let u = s[0] + t * s[1];
        v(&[u * s[1] / (d * d + u * u).sqrt()])
    });
    for (t, x, xdot) in [
        (0.0, 3.0, 2.0),
        (1.5, -20.0, 4.0),
        (10.0, 100.0, -7.0),
        (0.25, 0.0, 1.0),
    ] {
        let p = rate.predict(&v(&[x, xdot]), t).unwrap();
        let u = x + t * xdot;
        let k = (d * d + u * u).sqrt();
        assert!((p.value[0] - u * xdot / k).abs() <= 1e-15 * (u * xdot / k).abs().max(1.0));
        let want = DMatrix::from_row_slice(
            1,
            2,
            &[
                d * d * xdot / k.powi(3),
                (d * d * (x + 2.0 * t * xdot) + u.powi(3)) / k.powi(3),
            ],
        );
        let e = rel(&p.jacobian, &want);
        worst = worst.max(e);
        assert!(e <= 1e-7, "Ex. 11.13 t {t}, ({x}, {xdot}): {e:e}");
    }
    eprintln!("central differences against the book's M: worst relative error {worst:e}");
}

#[test]
fn the_callers_jacobian_is_used_and_agrees_with_differences() {
    // G(X) = (x y, sin x + z², e^{y/4}) with its Jacobian; the analytic one is returned as
    // given, and the differenced one (no Jacobian) agrees with it within 1e-7 relative.
    let g =
        |_t: f64, s: &DVector<f64>| v(&[s[0] * s[1], s[0].sin() + s[2] * s[2], (s[1] / 4.0).exp()]);
    let jac = |_t: f64, s: &DVector<f64>| {
        DMatrix::from_row_slice(
            3,
            3,
            &[
                s[1],
                s[0],
                0.0,
                s[0].cos(),
                0.0,
                2.0 * s[2],
                0.0,
                (s[1] / 4.0).exp() / 4.0,
                0.0,
            ],
        )
    };
    let analytic = NonlinearObservation::new(3, 3, g).with_jacobian(jac);
    let differenced = NonlinearObservation::new(3, 3, g);
    let mut rng = rand::rngs::StdRng::seed_from_u64(8);
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        let s = DVector::from_fn(3, |_, _| rng.gen_range(-30.0..30.0));
        let a = analytic.predict(&s, 1.0).unwrap();
        assert_eq!(a.jacobian, jac(1.0, &s));
        assert_eq!(a.value, g(1.0, &s));
        let b = differenced.predict(&s, 1.0).unwrap();
        assert_eq!(b.value, a.value);
        let e = rel(&b.jacobian, &a.jacobian);
        worst = worst.max(e);
        assert!(e <= 1e-7, "{s}: {e:e}");
    }
    // Through a reference and a trait object.
    let obs: &dyn Observation = &analytic;
    assert_eq!((obs.components(), obs.state_dimension()), (3, 3));
    assert_eq!(obs.residual(2, 1.0, 4.0), -3.0);
    assert_eq!((&obs).residual(1, 7.0, -7.0), 14.0); // no wrapping by default
    eprintln!("differenced against analytic: worst relative error {worst:e}");
}

#[test]
fn refusals_are_typed() {
    // LinearObservation: empty or non-finite M; a state of the wrong length or non-finite; an
    // overflowing product.
    let e = LinearObservation::new(DMatrix::zeros(0, 3)).unwrap_err();
    assert!(
        matches!(
            e,
            Error::InvalidParameter {
                name: Param::ObservationMatrixM,
                ..
            }
        ),
        "{e}"
    );
    let e = LinearObservation::new(DMatrix::from_element(2, 2, f64::INFINITY)).unwrap_err();
    assert!(matches!(e, Error::NonFinite { .. }), "{e}");
    let m = LinearObservation::new(DMatrix::from_element(1, 2, 1e308)).unwrap();
    let e = m.predict(&v(&[1.0]), 0.0).unwrap_err();
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
    let e = m.predict(&v(&[1.0, f64::NAN]), 0.0).unwrap_err();
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
    let e = m.predict(&v(&[1.5, 1.5]), 0.0).unwrap_err();
    assert!(
        matches!(
            e,
            Error::NonFinite {
                what: "predicted observation",
                ..
            }
        ),
        "{e}"
    );
    // NonlinearObservation: G of the wrong length or non-finite (at the state, or only at a
    // difference probe), the caller's Jacobian of the wrong shape or non-finite.
    let bad = |e: &Error| {
        matches!(
            e,
            Error::InvalidParameter {
                name: Param::ObservationModel,
                ..
            }
        )
    };
    let x = v(&[1.0, 2.0]);
    let cases: Vec<(&str, NonlinearObservation)> = vec![
        (
            "short",
            NonlinearObservation::new(2, 2, |_t, s: &DVector<f64>| v(&[s[0]])),
        ),
        (
            "long",
            NonlinearObservation::new(1, 2, |_t, s: &DVector<f64>| s.clone()),
        ),
        (
            "NaN",
            NonlinearObservation::new(1, 2, |_t, _s: &DVector<f64>| v(&[f64::NAN])),
        ),
        (
            "NaN at a probe",
            NonlinearObservation::new(1, 2, |_t, s: &DVector<f64>| {
                v(&[if s[0] > 1.0 { f64::NAN } else { s[0] }])
            }),
        ),
        (
            "Jacobian 2x2",
            NonlinearObservation::new(1, 2, |_t, s: &DVector<f64>| v(&[s[0]]))
                .with_jacobian(|_t, _s: &DVector<f64>| DMatrix::zeros(2, 2)),
        ),
        (
            "Jacobian NaN",
            NonlinearObservation::new(1, 2, |_t, s: &DVector<f64>| v(&[s[0]]))
                .with_jacobian(|_t, _s: &DVector<f64>| DMatrix::from_element(1, 2, f64::NAN)),
        ),
    ];
    for (what, obs) in &cases {
        let e = obs.predict(&x, 0.0).unwrap_err();
        assert!(bad(&e), "{what}: {e}");
    }
    let ok = &cases[4].1;
    let e = ok.predict(&v(&[1.0]), 0.0).unwrap_err();
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
    let e = ok.predict(&v(&[f64::NEG_INFINITY, 0.0]), 0.0).unwrap_err();
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
}
