//! `estimate::sliding`: the sliding Gauss–Newton fit against independent fits of each window —
//! a cold start from the §8.5 radar nominal ([`bootstrap::radar`] then
//! [`GaussNewton::fit`]) for the radar model, and the fixed-memory filter (Morrison ch. 7,
//! another engine of the same least squares) for the polynomial model — and its refusals.

use nalgebra::DVector;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use seqsmooth::estimate::bootstrap;
use seqsmooth::estimate::gauss_newton::{Epoch, GaussNewton, Measurement};
use seqsmooth::estimate::sliding::{SlidingFit, Start};
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::measurement::NoiseCovariance;
use seqsmooth::model::observation::LinearObservation;
use seqsmooth::model::radar::Radar;
use seqsmooth::polynomial::fixed::{FixedEngine, FixedMemory};
use seqsmooth::polynomial::PolynomialFilter;
use seqsmooth::Error;

/// Noisy radar measurements of a constant-velocity target (10 m, 1 mrad), irregular times.
fn radar_rows(n: usize, seed: u64) -> Vec<Measurement> {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let (nr, na) = (
        Normal::new(0.0, 10.0).unwrap(),
        Normal::new(0.0, 1e-3).unwrap(),
    );
    let (x0, v) = ([12_000.0, 3_000.0, 1_500.0], [-150.0, -90.0, 4.0]);
    let mut t = 0.0;
    (0..n)
        .map(|_| {
            let p: Vec<f64> = (0..3).map(|i| x0[i] + v[i] * t).collect();
            let m = Measurement {
                time: t,
                values: vec![
                    Some((p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() + nr.sample(&mut rng)),
                    Some(p[1].atan2(p[0]) + na.sample(&mut rng)),
                    Some(p[2].atan2(p[0].hypot(p[1])) + na.sample(&mut rng)),
                ],
                noise: NoiseCovariance::Variances(vec![100.0, 1e-6, 1e-6]),
            };
            t += rng.gen_range(0.5..1.5);
            m
        })
        .collect()
}

/// Each window's warm-started fit equals a cold start from the bootstrap: the states within
/// 1e-4 of their σ (the tolerance 1e-6 σ on the last correction leaves that much), the
/// covariances within 1e-6 relative; windows of 2 to 60 rows, epochs end and centre.
#[test]
fn warm_starts_reach_the_cold_start_fit() {
    let rows = radar_rows(140, 4);
    let radar = Radar::new([0.0; 3], 6).unwrap();
    let dynamics = PolynomialDynamics::new(1, 3);
    for (window, epoch) in [(60, Epoch::End), (25, Epoch::Centre), (2, Epoch::End)] {
        let mut fit = SlidingFit::new(
            dynamics,
            radar,
            window,
            epoch,
            Start::Radar { radar, degree: 2 },
        )
        .unwrap();
        let mut worst: f64 = 0.0;
        for (i, m) in rows.iter().enumerate() {
            let got = fit.push(m.clone()).unwrap();
            let Some(got) = got else {
                assert_eq!(i, 0, "two rows determine the state");
                continue;
            };
            let w = &rows[(i + 1).saturating_sub(window)..=i];
            let times: Vec<f64> = w.iter().map(|m| m.time).collect();
            let measured: Vec<[f64; 3]> = w
                .iter()
                .map(|m| {
                    [
                        m.values[0].unwrap(),
                        m.values[1].unwrap(),
                        m.values[2].unwrap(),
                    ]
                })
                .collect();
            let t_c = epoch.time_for(&times);
            let nominal =
                bootstrap::radar(&radar, &times, &measured, t_c, 2.min(w.len() - 1)).unwrap();
            let cold = GaussNewton::default()
                .fit(&dynamics, &radar, w, Epoch::At(t_c), &nominal, None)
                .unwrap();
            assert_eq!(got.epoch, cold.epoch);
            for k in 0..6 {
                let s = cold.covariance[(k, k)].sqrt();
                let e = (got.state[k] - cold.state[k]).abs() / s;
                worst = worst.max(e);
                assert!(e < 1e-4, "window {window} row {i} state {k}: {e:e} sigma");
                let c = (got.covariance[(k, k)] / cold.covariance[(k, k)] - 1.0).abs();
                assert!(c < 1e-6, "window {window} row {i} S{k}{k}: {c:e}");
            }
            assert!(got.iterations.len() <= 10, "row {i}");
        }
        println!("window {window}: worst state difference {worst:e} sigma");
    }
}

/// The polynomial model of degree m: the fixed-memory filter's state and covariance (σ = 1)
/// on every row with a full window, irregular times, within 1e-10 of max(|value|, σ, 1) (at
/// degree 8 over 12 samples a fourth derivative near 0.3 has σ = 70: the two engines' rounding
/// differ by 3e-10 there, 4e-12 σ).
#[test]
fn the_polynomial_model_is_the_fixed_memory_filter() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(9);
    for (m, window) in [(0, 1), (2, 9), (4, 20), (8, 12)] {
        let mut fit = SlidingFit::new(
            PolynomialDynamics::new(m, 1),
            LinearObservation::value_of(m + 1),
            window,
            Epoch::End,
            Start::State(DVector::zeros(m + 1)),
        )
        .unwrap();
        let mut filter = FixedMemory::new(m, window, FixedEngine::Irregular)
            .unwrap()
            .with_noise_sigma(1.0)
            .unwrap();
        let mut t: f64 = 50.0;
        for i in 0..60 {
            let y = (0.2 * t).cos() * 3.0 + rng.gen_range(-0.5..0.5);
            let got = fit
                .push(Measurement {
                    time: t,
                    values: vec![Some(y)],
                    noise: NoiseCovariance::Variances(vec![1.0]),
                })
                .unwrap();
            filter.update(t, y).unwrap();
            assert_eq!(got.is_some(), i >= m, "row {i}");
            if i + 1 >= window {
                let (got, want) = (got.unwrap(), filter.estimate().unwrap());
                let s = want.covariance.unwrap();
                for k in 0..=m {
                    let sd = s[(k, k)].sqrt();
                    let close = |a: f64, b: f64| (a - b).abs() <= 1e-10 * b.abs().max(sd).max(1.0);
                    assert!(
                        close(got.state[k], want.derivatives[k]),
                        "m {m} row {i} d{k}: {} against {} (sigma {})",
                        got.state[k],
                        want.derivatives[k],
                        s[(k, k)].sqrt()
                    );
                    assert!(
                        close(got.covariance[(k, k)], s[(k, k)]),
                        "m {m} row {i} S{k}{k}"
                    );
                }
            }
            t += rng.gen_range(0.2..1.8);
        }
    }
}

/// Refusals: a time not after the previous one and a malformed measurement are errors and are
/// not kept; a window that does not determine the state is `Ok(None)` while it fills and an
/// error once full; bad settings are refused by name.
#[test]
fn refusals() {
    let scalar = |t: f64, y: f64| Measurement {
        time: t,
        values: vec![Some(y)],
        noise: NoiseCovariance::Variances(vec![1.0]),
    };
    let mut fit = SlidingFit::new(
        PolynomialDynamics::new(1, 1),
        LinearObservation::value_of(2),
        3,
        Epoch::End,
        Start::State(DVector::zeros(2)),
    )
    .unwrap();
    assert!(fit.push(scalar(0.0, 1.0)).unwrap().is_none());
    assert!(matches!(
        fit.push(scalar(0.0, 2.0)),
        Err(Error::InvalidParameter { name: "time", .. })
    ));
    assert!(matches!(
        fit.push(scalar(1.0, f64::NAN)),
        Err(Error::InBatch { index: 1, .. })
    ));
    assert_eq!(fit.measurements().count(), 1, "refused rows are not kept");
    let c = fit.push(scalar(1.0, 3.0)).unwrap().unwrap();
    assert!((c.state[1] - 2.0).abs() < 1e-12);

    // Range only: never determined; Ok(None) until the window (4) is full, then the error.
    let radar = Radar::new([0.0; 3], 6).unwrap();
    let mut fit = SlidingFit::new(
        PolynomialDynamics::new(1, 3),
        radar,
        4,
        Epoch::End,
        Start::Radar { radar, degree: 2 },
    )
    .unwrap();
    for k in 0..3 {
        let m = Measurement {
            time: k as f64,
            values: vec![Some(1000.0 + k as f64), None, None],
            noise: NoiseCovariance::Variances(vec![1.0, 1.0, 1.0]),
        };
        assert!(fit.push(m).unwrap().is_none());
    }
    let m = Measurement {
        time: 3.0,
        values: vec![Some(1003.0), None, None],
        noise: NoiseCovariance::Variances(vec![1.0, 1.0, 1.0]),
    };
    assert!(matches!(fit.push(m), Err(Error::TooFewSamples { .. })));

    // Settings.
    let d = PolynomialDynamics::new(1, 1);
    let o = LinearObservation::value_of(2);
    assert!(SlidingFit::new(d, o.clone(), 0, Epoch::End, Start::State(DVector::zeros(2))).is_err());
    assert!(SlidingFit::new(d, o.clone(), 3, Epoch::End, Start::State(DVector::zeros(3))).is_err());
    assert!(SlidingFit::new(
        d,
        o.clone(),
        3,
        Epoch::At(f64::NAN),
        Start::State(DVector::zeros(2))
    )
    .is_err());
    assert!(SlidingFit::new(
        d,
        LinearObservation::value_of(3),
        3,
        Epoch::End,
        Start::State(DVector::zeros(2))
    )
    .is_err());
    assert!(SlidingFit::new(
        PolynomialDynamics::new(1, 3),
        radar,
        3,
        Epoch::End,
        Start::Radar { radar, degree: 0 }
    )
    .is_err());
}

/// One value with unit variance at `t`.
fn value(t: f64, y: f64) -> Measurement {
    Measurement {
        time: t,
        values: vec![Some(y)],
        noise: NoiseCovariance::Variances(vec![1.0]),
    }
}

/// An epoch ~1e200 from the times: the QR factor of the linearised system overflows; the
/// window is an error, never nalgebra's panic on NaN singular values (`seqsmooth fit --epoch
/// 1e200` panicked so).
#[test]
fn an_epoch_far_from_the_times_is_an_error_not_a_panic() {
    for epoch in [1e200, -1e250, 1e300] {
        let mut fit =
            SlidingFit::polynomial(1, 3, Epoch::At(epoch), GaussNewton::default()).unwrap();
        let mut refused = 0;
        for (t, y) in [(0.0, 0.0), (1.0, 1.0), (2.0, 2.5), (3.0, 3.0)] {
            if fit.push_finite(value(t, y)).is_err() {
                refused += 1;
            }
        }
        assert!(refused > 0, "epoch {epoch}");
    }
}

/// The constructors of `seqsmooth fit`'s two models: the settings refused, and the polynomial
/// model the same fit as `SlidingFit::new` with its parts.
#[test]
fn the_command_models() {
    let solver = GaussNewton::default();
    assert!(SlidingFit::radar([0.0; 3], 0, 5, Epoch::End, solver).is_err());
    assert!(SlidingFit::radar([0.0, f64::NAN, 0.0], 1, 5, Epoch::End, solver).is_err());
    assert!(SlidingFit::radar([0.0; 3], 2, 0, Epoch::End, solver).is_err());
    assert!(SlidingFit::polynomial(1, 1, Epoch::End, solver).is_err());
    assert!(SlidingFit::polynomial(1, 2, Epoch::At(f64::INFINITY), solver).is_err());
    // A window of 2^62 rows holds no memory ahead of the rows.
    assert!(SlidingFit::polynomial(1, 1 << 62, Epoch::End, solver).is_ok());
    let mut a = SlidingFit::polynomial(2, 6, Epoch::Centre, solver).unwrap();
    let mut b = SlidingFit::new(
        PolynomialDynamics::new(2, 1),
        LinearObservation::value_of(3),
        6,
        Epoch::Centre,
        Start::State(DVector::zeros(3)),
    )
    .unwrap();
    for k in 0..20 {
        let t = 1.7e9 + k as f64 * 1.25;
        let y = (k as f64 * 0.7).sin();
        let (x, z) = (
            a.push_finite(value(t, y)).unwrap(),
            b.push(value(t, y)).unwrap(),
        );
        assert_eq!(x, z);
    }
}
