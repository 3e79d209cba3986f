//! `estimate::gauss_newton`: Morrison's ch. 11 range-only example (T11-1: the iterates of
//! (11.2.27)/(VI), the covariance, the stationarity condition (11.4.26)), the polynomial model
//! against the fixed-memory filter on even (T8-02: `W(0)`) and irregular times, epochs and time
//! origins, missing components, the §8.9 observability cases, and the typed errors.

use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use seqsmooth::estimate::gauss_newton::{Epoch, GaussNewton, Measurement, Prior};
use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
use seqsmooth::model::measurement::NoiseCovariance;
use seqsmooth::model::nonlinear::NonlinearDynamics;
use seqsmooth::model::observation::{LinearObservation, NonlinearObservation};
use seqsmooth::model::radar::Radar;
use seqsmooth::polynomial::fixed::{FixedEngine, FixedMemory};
use seqsmooth::polynomial::PolynomialFilter;
use seqsmooth::Error;

fn scalar(t: f64, y: f64, variance: f64) -> Measurement {
    Measurement {
        time: t,
        values: vec![Some(y)],
        noise: NoiseCovariance::Variances(vec![variance]),
    }
}

/// Ex. 11.1: range `sqrt(d² + x²)` of a body at `x` from a sensor at distance `d`.
fn range_only(d: f64) -> NonlinearObservation {
    NonlinearObservation::new(1, 1, move |_t, x: &DVector<f64>| {
        DVector::from_vec(vec![(d * d + x[0] * x[0]).sqrt()])
    })
    .with_jacobian(move |_t, x: &DVector<f64>| {
        DMatrix::from_element(1, 1, x[0] / (d * d + x[0] * x[0]).sqrt())
    })
}

#[test]
fn t11_1_iterates_covariance_and_stationarity() {
    // T11-1: d = 3, x_{1,0} = 4, a² = 1, s_ρ² = 0.01, ρ₁ = 5.2; Φ = 1 (a degree-0 state).
    let (d, x0, a2, s2, rho) = (3.0, 4.0, 1.0, 0.01, 5.2);
    let prior = Prior {
        state: DVector::from_vec(vec![x0]),
        covariance: DMatrix::from_element(1, 1, a2),
    };
    let fit = GaussNewton {
        tolerance: 1e-9,
        ..GaussNewton::default()
    }
    .fit(
        &PolynomialDynamics::new(0, 1),
        &range_only(d),
        &[scalar(0.0, rho, s2)],
        Epoch::End,
        &prior.state,
        Some(&prior),
    )
    .unwrap();
    let want = [
        4.246153846154,
        4.243698707460,
        4.243697780837,
        4.243697780575,
    ];
    for (k, w) in want.iter().enumerate() {
        let got = fit.iterations[k].state[0];
        assert!(
            (got - w).abs() < 5e-13,
            "iterate {}: {got} against {w}",
            k + 1
        );
        assert_eq!(fit.iterations[k].step, 1.0, "no halving");
    }
    assert!(fit.iterations.len() <= want.len() + 1);
    let x = fit.state[0];
    assert!((x - 4.243697780575).abs() < 5e-13);
    // s at convergence (II) at x̄ = x_inf: a² s² / (s² + a² x²/(d² + x²)).
    assert!((fit.covariance[(0, 0)] - 0.014775907527).abs() < 5e-13);
    let m = x / (d * d + x * x).sqrt();
    let closed = a2 * s2 / (s2 + a2 * m * m);
    assert!((fit.covariance[(0, 0)] - closed).abs() < 1e-15 * closed.max(1.0) * 10.0);
    // (11.4.26): (1/a²)(x0 − x) + x (ρ − g)/(s² g) = 0 (Ex. 11.4/11.5).
    let g = (d * d + x * x).sqrt();
    let stationarity = (x0 - x) / a2 + x * (rho - g) / (s2 * g);
    assert!(stationarity.abs() < 1e-13, "{stationarity:e}");
    // The first linearisation, at x̄ = x_{1,0}: h = 1.230769230769, s = 0.015384615385 (II, III).
    let first = GaussNewton {
        max_iterations: 1,
        tolerance: 1e3,
        ..GaussNewton::default()
    }
    .fit(
        &PolynomialDynamics::new(0, 1),
        &range_only(d),
        &[scalar(0.0, rho, s2)],
        Epoch::End,
        &prior.state,
        Some(&prior),
    )
    .unwrap();
    assert!((first.covariance[(0, 0)] - 0.015384615385).abs() < 5e-13);
    // x = x0 + h (ρ − 5) at x̄ = x0, so h = (x − x0)/(ρ − 5).
    let h = (first.state[0] - x0) / (rho - 5.0);
    assert!((h - 1.230769230769).abs() < 5e-12, "{h}");
}

#[test]
fn ex_11_2_the_linear_case_is_the_weighted_mean() {
    // d = 0: s = a²s²/(a² + s²), x = (x0/a² + ρ/s²)/(1/a² + 1/s²).
    let (x0, a2, s2, rho) = (4.0, 2.0, 0.5, 5.0);
    let prior = Prior {
        state: DVector::from_vec(vec![x0]),
        covariance: DMatrix::from_element(1, 1, a2),
    };
    let fit = GaussNewton::default()
        .fit(
            &PolynomialDynamics::new(0, 1),
            &LinearObservation::value_of(1),
            &[scalar(0.0, rho, s2)],
            Epoch::End,
            &prior.state,
            Some(&prior),
        )
        .unwrap();
    let want = (x0 / a2 + rho / s2) / (1.0 / a2 + 1.0 / s2);
    assert!((fit.state[0] - want).abs() < 1e-14);
    assert!((fit.covariance[(0, 0)] - a2 * s2 / (a2 + s2)).abs() < 1e-15);
    assert_eq!(fit.degrees_of_freedom, 1);
}

/// The fixed-memory filter's estimate after `times`, `values` (its window the whole run).
fn fixed_memory(
    m: usize,
    times: &[f64],
    values: &[f64],
    engine: FixedEngine,
) -> (Vec<f64>, DMatrix<f64>) {
    let mut f = FixedMemory::new(m, times.len(), engine)
        .unwrap()
        .with_noise_sigma(1.0)
        .unwrap();
    for (&t, &y) in times.iter().zip(values) {
        f.update(t, y).unwrap();
    }
    let e = f.estimate().unwrap();
    (e.derivatives, e.covariance.unwrap())
}

fn polynomial_fit(
    m: usize,
    times: &[f64],
    values: &[f64],
    epoch: Epoch,
) -> seqsmooth::estimate::gauss_newton::Correction {
    let rows: Vec<Measurement> = times
        .iter()
        .zip(values)
        .map(|(&t, &y)| scalar(t, y, 1.0))
        .collect();
    GaussNewton::default()
        .fit(
            &PolynomialDynamics::new(m, 1),
            &LinearObservation::value_of(m + 1),
            &rows,
            epoch,
            &DVector::zeros(m + 1),
            None,
        )
        .unwrap()
}

fn close(got: f64, want: f64, tol: f64) -> bool {
    (got - want).abs() <= tol * want.abs().max(1.0)
}

#[test]
fn t8_02_the_polynomial_model_is_the_fixed_memory_filter() {
    // Even steps (W(0), the Direct engine) and irregular ones (the Irregular engine), degrees
    // 0-8: the state at the window's end and its covariance (σ = 1) within 1e-10.
    let mut rng = rand::rngs::StdRng::seed_from_u64(11);
    let mut worst: f64 = 0.0;
    for m in 0..=8 {
        for irregular in [false, true] {
            let n = 3 * m + 12;
            let mut t: f64 = 100.0;
            let mut times = Vec::new();
            for _ in 0..n {
                times.push(t);
                t += if irregular {
                    rng.gen_range(0.2..1.8)
                } else {
                    0.5
                };
            }
            let values: Vec<f64> = times
                .iter()
                .map(|&t: &f64| (0.3 * t).sin() * 10.0 + rng.gen_range(-1.0..1.0))
                .collect();
            let engine = if irregular {
                FixedEngine::Irregular
            } else {
                FixedEngine::Direct
            };
            let (d, s) = fixed_memory(m, &times, &values, engine);
            let fit = polynomial_fit(m, &times, &values, Epoch::End);
            for k in 0..=m {
                worst = worst.max((fit.state[k] - d[k]).abs() / d[k].abs().max(1.0));
                assert!(
                    close(fit.state[k], d[k], 1e-10),
                    "m {m} irregular {irregular} d{k}: {} against {}",
                    fit.state[k],
                    d[k]
                );
                for j in 0..=m {
                    assert!(
                        close(fit.covariance[(k, j)], s[(k, j)], 1e-10),
                        "m {m} S[{k},{j}]"
                    );
                }
            }
            assert!(
                fit.iterations.len() <= 2,
                "linear: one correction and a check"
            );
        }
    }
    println!("worst state difference relative to max(|value|, 1): {worst:e}");
}

#[test]
fn the_epoch_and_the_time_origin_do_not_change_the_answer() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(3);
    let m = 3;
    let times: Vec<f64> = (0..40)
        .map(|k| k as f64 * 0.7 + rng.gen_range(0.0..0.3))
        .collect();
    let values: Vec<f64> = times
        .iter()
        .map(|&t| 2.0 + t - 0.1 * t * t + rng.gen_range(-0.5..0.5))
        .collect();
    let end = polynomial_fit(m, &times, &values, Epoch::End);
    for epoch in [Epoch::Centre, Epoch::At(-5.0), Epoch::At(12.25)] {
        let other = polynomial_fit(m, &times, &values, epoch);
        let moved = PolynomialDynamics::new(m, 1)
            .propagate_covariance(&other.state, &other.covariance, other.epoch, end.epoch)
            .unwrap();
        for k in 0..=m {
            assert!(close(moved.0[k], end.state[k], 1e-9), "{epoch:?} d{k}");
            assert!(
                close(moved.1[(k, k)], end.covariance[(k, k)], 1e-9),
                "{epoch:?} S{k}{k}"
            );
        }
        assert!(close(other.chi_squared, end.chi_squared, 1e-10));
    }
    // Unix-epoch times: the same fit.
    let shifted: Vec<f64> = times.iter().map(|t| t + 1.7e9).collect();
    let unix = polynomial_fit(m, &shifted, &values, Epoch::End);
    assert_eq!(unix.epoch, end.epoch + 1.7e9);
    for k in 0..=m {
        assert!(
            close(unix.state[k], end.state[k], 1e-6),
            "unix d{k}: {} against {}",
            unix.state[k],
            end.state[k]
        );
    }
}

#[test]
fn missing_components_drop_their_rows() {
    // Two linear components of a constant-velocity state, (x, x + ẋ), with a full R; every other
    // measurement lacks its second component. The same as fitting those measurements with the
    // first component alone where the second is missing.
    let m2 = LinearObservation::new(DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 1.0, 1.0])).unwrap();
    let m1 = LinearObservation::value_of(2);
    let r = DMatrix::from_row_slice(2, 2, &[2.0, 0.5, 0.5, 1.0]);
    let mut with_gaps = Vec::new();
    let mut rng = rand::rngs::StdRng::seed_from_u64(5);
    let (mut full_rows, mut one_rows) = (Vec::new(), Vec::new());
    for k in 0..12 {
        let t = k as f64;
        let y = [
            1.0 + 0.5 * t + rng.gen_range(-1.0..1.0),
            1.5 + 0.5 * t + rng.gen_range(-1.0..1.0),
        ];
        let missing = k % 2 == 1;
        with_gaps.push(Measurement {
            time: t,
            values: vec![Some(y[0]), if missing { None } else { Some(y[1]) }],
            noise: NoiseCovariance::Full(r.clone()),
        });
        if missing {
            one_rows.push(scalar(t, y[0], 2.0));
        } else {
            full_rows.push(Measurement {
                time: t,
                values: vec![Some(y[0]), Some(y[1])],
                noise: NoiseCovariance::Full(r.clone()),
            });
        }
    }
    let dynamics = PolynomialDynamics::new(1, 1);
    let gaps = GaussNewton::default()
        .fit(
            &dynamics,
            &m2,
            &with_gaps,
            Epoch::End,
            &DVector::zeros(2),
            None,
        )
        .unwrap();
    // The oracle: the information of the two groups added, (Σ Tᵀ R⁻¹ T)⁻¹, by separate fits.
    let a = GaussNewton::default()
        .fit(
            &dynamics,
            &m2,
            &full_rows,
            Epoch::At(11.0),
            &DVector::zeros(2),
            None,
        )
        .unwrap();
    let b = GaussNewton::default()
        .fit(
            &dynamics,
            &m1,
            &one_rows,
            Epoch::At(11.0),
            &DVector::zeros(2),
            None,
        )
        .unwrap();
    let (ia, ib) = (
        a.covariance.clone().try_inverse().unwrap(),
        b.covariance.clone().try_inverse().unwrap(),
    );
    let s = (&ia + &ib).try_inverse().unwrap();
    let x = &s * (&ia * &a.state + &ib * &b.state);
    for k in 0..2 {
        assert!(close(gaps.state[k], x[k], 1e-12), "x{k}");
        assert!(close(gaps.covariance[(k, k)], s[(k, k)], 1e-12), "S{k}{k}");
    }
    assert_eq!(gaps.degrees_of_freedom, 12 + 6 - 2);
}

#[test]
fn undeterminable_windows_are_typed_errors() {
    // The polynomial model of degree 2 with samples at only 2 distinct times.
    let rows: Vec<Measurement> = (0..10)
        .map(|k| scalar((k % 2) as f64, k as f64, 1.0))
        .collect();
    let e = GaussNewton::default().fit(
        &PolynomialDynamics::new(2, 1),
        &LinearObservation::value_of(3),
        &rows,
        Epoch::End,
        &DVector::zeros(3),
        None,
    );
    assert!(
        matches!(
            e,
            Err(Error::Unobservable {
                rank: 2,
                states: 3,
                ..
            })
        ),
        "{e:?}"
    );
    // A radar observing range only, constant-velocity 3-D model: rank 3 of 6 (the range is
    // unchanged by any rotation about the site).
    let radar = Radar::new([0.0; 3], 6).unwrap();
    let truth = DVector::from_vec(vec![8_000.0, 3_000.0, 1_000.0, -50.0, 120.0, 10.0]);
    let dynamics = PolynomialDynamics::new(1, 3);
    let rows: Vec<Measurement> = (0..30)
        .map(|k| {
            let t = k as f64;
            let x = dynamics.propagate(&truth, 0.0, t).unwrap().state;
            let rho = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
            Measurement {
                time: t,
                values: vec![Some(rho), None, None],
                noise: NoiseCovariance::Variances(vec![100.0, 1e-6, 1e-6]),
            }
        })
        .collect();
    let e = GaussNewton::default().fit(&dynamics, &radar, &rows, Epoch::Centre, &truth, None);
    assert!(
        matches!(
            e,
            Err(Error::Unobservable {
                rank: 3,
                states: 6,
                ..
            })
        ),
        "{e:?}"
    );
    // With the angles it is determined.
    let rows: Vec<Measurement> = rows
        .into_iter()
        .map(|mut r| {
            let x = dynamics.propagate(&truth, 0.0, r.time).unwrap().state;
            r.values[1] = Some(x[1].atan2(x[0]));
            r.values[2] = Some(x[2].atan2(x[0].hypot(x[1])));
            r
        })
        .collect();
    let fit = GaussNewton::default()
        .fit(&dynamics, &radar, &rows, Epoch::Centre, &truth, None)
        .unwrap();
    let at_centre = dynamics.propagate(&truth, 0.0, fit.epoch).unwrap().state;
    assert!((&fit.state - at_centre).amax() < 1e-6);
}

#[test]
fn divergence_and_non_convergence_are_typed_errors() {
    let rows = [scalar(0.0, 5.2, 0.01)];
    // A model that fails away from its starting state: no fraction of any step is usable.
    let start = 4.0;
    let brittle = NonlinearDynamics::new(1, move |_t, x: &DVector<f64>| {
        if x[0] == start {
            DVector::zeros(1)
        } else {
            DVector::from_element(1, f64::NAN)
        }
    })
    .with_jacobian(|_t, _x: &DVector<f64>| DMatrix::zeros(1, 1));
    let e = GaussNewton::default().fit(
        &brittle,
        &range_only(3.0),
        &[scalar(0.0, 5.2, 0.01), scalar(1.0, 5.2, 0.01)],
        Epoch::At(0.0),
        &DVector::from_vec(vec![start]),
        None,
    );
    assert!(
        matches!(e, Err(Error::Diverged { iteration: 1, .. })),
        "{e:?}"
    );
    // One iteration is not enough for a nonlinear model.
    let e = GaussNewton {
        max_iterations: 1,
        ..GaussNewton::default()
    }
    .fit(
        &PolynomialDynamics::new(0, 1),
        &range_only(3.0),
        &rows,
        Epoch::End,
        &DVector::from_vec(vec![1.0]),
        None,
    );
    assert!(
        matches!(e, Err(Error::NotConverged { iterations: 1, .. })),
        "{e:?}"
    );
    // Bad input, named.
    let bad = [
        Measurement {
            time: f64::NAN,
            values: vec![Some(1.0)],
            noise: NoiseCovariance::Identity,
        },
        Measurement {
            time: 0.0,
            values: vec![Some(f64::INFINITY)],
            noise: NoiseCovariance::Identity,
        },
        Measurement {
            time: 0.0,
            values: vec![Some(1.0), Some(2.0)],
            noise: NoiseCovariance::Identity,
        },
        Measurement {
            time: 0.0,
            values: vec![Some(1.0)],
            noise: NoiseCovariance::Variances(vec![-1.0]),
        },
    ];
    for b in bad {
        let e = GaussNewton::default().fit(
            &PolynomialDynamics::new(0, 1),
            &LinearObservation::value_of(1),
            std::slice::from_ref(&b),
            Epoch::End,
            &DVector::zeros(1),
            None,
        );
        assert!(
            matches!(e, Err(Error::InBatch { index: 0, .. })),
            "{b:?}: {e:?}"
        );
    }
    let e = GaussNewton::default().fit(
        &PolynomialDynamics::new(1, 1),
        &LinearObservation::value_of(2),
        &[],
        Epoch::End,
        &DVector::zeros(2),
        None,
    );
    assert!(matches!(e, Err(Error::TooFewSamples { .. })), "{e:?}");
    let e = GaussNewton::default().fit(
        &PolynomialDynamics::new(1, 1),
        &LinearObservation::value_of(2),
        &[scalar(0.0, 1.0, 1.0), scalar(1.0, 1.0, 1.0)],
        Epoch::End,
        &DVector::from_vec(vec![0.0, f64::NAN]),
        None,
    );
    assert!(matches!(e, Err(Error::NonFinite { .. })), "{e:?}");
}
