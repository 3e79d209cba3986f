//! `kalman::unscented_fixed_lag` against its definition: with lag `L` the estimate of
//! measurement `k` is the unscented RTS smoother's (Särkkä 2008, `kalman::unscented_smoother`)
//! over measurements `0..=k+L`, read at `k` — checked directly, smoother run by smoother run,
//! for several `L` on a radar track (constant velocity on three axes, range, azimuth and
//! elevation, irregular times, whole rows and single components missing, driving noise); a lag
//! at least the run's length gives the whole-interval smoother; on a linear model it is the
//! Kalman filter's fixed-lag smoother (`kalman::fixed_lag`, a second oracle: the unscented
//! transform is exact for a linear model). Every comparison: each state component relative to
//! `max(|x_i|, σ_i)` and each covariance entry relative to `σ_i σ_j` (the oracle's).

use nalgebra::{DMatrix, DVector};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::kalman::unscented_fixed_lag::UnscentedFixedLagSmoother;
use seqsmooth::kalman::unscented_smoother::UnscentedSmoothed;
use seqsmooth::kalman::{smooth_unscented, FixedLagSmoother, KalmanFilter, UnscentedKalmanFilter};
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
use seqsmooth::model::observation::{LinearObservation, Observation};
use seqsmooth::model::radar::Radar;
use seqsmooth::Error;

const Q: f64 = 0.05;

/// The worst relative difference of `(x, s)` from the oracle's `(want_x, want_s)`.
fn worst(x: &DVector<f64>, s: &DMatrix<f64>, want_x: &DVector<f64>, want_s: &DMatrix<f64>) -> f64 {
    let n = x.len();
    let sigma: Vec<f64> = (0..n).map(|i| want_s[(i, i)].sqrt()).collect();
    let mut w: f64 = 0.0;
    for i in 0..n {
        w = w.max((x[i] - want_x[i]).abs() / want_x[i].abs().max(sigma[i]));
        for j in 0..n {
            w = w.max((s[(i, j)] - want_s[(i, j)]).abs() / (sigma[i] * sigma[j]));
        }
    }
    w
}

/// A target at constant velocity about 10 km out seen by a radar at the origin: `count` rows
/// `U(0.3, 1.7)` apart, σ 5 m in range and 1 mrad in angle, one row in 15 wholly missing and
/// one component in 10 missing.
fn radar_rows(count: usize, seed: u64) -> Vec<Measurement> {
    let mut rng = StdRng::seed_from_u64(seed);
    let (sr, sa) = (5.0, 1e-3);
    let noise = |s: f64| Normal::new(0.0, s).unwrap();
    let (mut t, mut p): (f64, [f64; 3]) = (0.0, [8000.0, -6000.0, 3000.0]);
    let v = [-150.0, 120.0, 10.0];
    (0..count)
        .map(|k| {
            let dt = rng.gen_range(0.3..1.7);
            t += dt;
            for i in 0..3 {
                p[i] += v[i] * dt;
            }
            let range = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            let truth = [range, p[1].atan2(p[0]), (p[2] / range).asin()];
            let values = truth
                .iter()
                .enumerate()
                .map(|(i, &y)| {
                    let y = y + noise(if i == 0 { sr } else { sa }).sample(&mut rng);
                    let gone = k % 15 == 7 || rng.gen_range(0.0..1.0_f64) < 0.1;
                    (!gone).then_some(y)
                })
                .collect();
            Measurement {
                time: t,
                values,
                noise: NoiseCovariance::Variances(vec![sr * sr, sa * sa, sa * sa]),
            }
        })
        .collect()
}

fn radar_filter() -> UnscentedKalmanFilter<PolynomialDynamics, Radar> {
    let x0 = DVector::from_vec(vec![8000.0, -6000.0, 3000.0, -150.0, 120.0, 10.0]);
    let p0 = DMatrix::from_diagonal(&DVector::from_vec(vec![
        400.0, 400.0, 400.0, 100.0, 100.0, 100.0,
    ]));
    UnscentedKalmanFilter::new(
        PolynomialDynamics::new(1, 3),
        Radar::new([0.0; 3], 6).unwrap(),
        x0,
        p0,
        0.0,
    )
    .unwrap()
    .with_process_noise(WhiteNoiseDerivative::new(1, 3, Q).unwrap())
    .unwrap()
}

/// Every estimate of the unscented fixed-lag smoother of lag `lag` over `rows`, in order,
/// checking the memory bound (at most `lag` held) after each push.
fn fixed_lag<D, O>(
    filter: UnscentedKalmanFilter<D, O>,
    rows: &[Measurement],
    lag: usize,
) -> Vec<UnscentedSmoothed>
where
    D: seqsmooth::model::dynamics::Dynamics + Clone,
    O: Observation + Clone,
{
    let mut s = UnscentedFixedLagSmoother::new(filter, lag);
    let mut out = Vec::new();
    for (k, m) in rows.iter().enumerate() {
        let given = s.push(m).unwrap();
        assert_eq!(given.is_some(), k >= lag, "row {k}, lag {lag}");
        out.extend(given);
        assert!(s.held() <= lag && s.held() == (k + 1).min(lag));
    }
    out.extend(s.finish().unwrap());
    assert_eq!(out.len(), rows.len());
    out
}

#[test]
fn each_estimate_is_the_unscented_smoother_over_the_rows_to_lag_after() {
    let rows = radar_rows(90, 11);
    let mut overall: f64 = 0.0;
    for lag in [0, 1, 3, 8, 25] {
        let got = fixed_lag(radar_filter(), &rows, lag);
        for (k, g) in got.iter().enumerate() {
            let end = (k + lag).min(rows.len() - 1);
            let want = &smooth_unscented(radar_filter(), &rows[..=end]).unwrap()[k];
            assert_eq!(g.time, want.time);
            assert_eq!(g.filtered_state, want.filtered_state);
            let w = worst(&g.state, &g.covariance, &want.state, &want.covariance);
            overall = overall.max(w);
            assert!(w <= 1e-12, "lag {lag}, row {k}: {w:e}");
        }
        // The smoothing is real: a lag of 8 shrinks the position σ below the filter's.
        if lag == 8 {
            let k = 40;
            assert!(got[k].covariance[(0, 0)] < 0.9 * got[k].filtered_covariance[(0, 0)]);
        }
    }
    eprintln!("worst relative difference from the smoother over the rows to k + L: {overall:e}");
}

#[test]
fn a_lag_of_the_run_or_more_is_the_whole_interval_smoother() {
    let rows = radar_rows(60, 12);
    let want = smooth_unscented(radar_filter(), &rows).unwrap();
    for lag in [rows.len() - 1, rows.len(), 10_000, usize::MAX] {
        let got = fixed_lag(radar_filter(), &rows, lag);
        for (g, w) in got.iter().zip(&want) {
            let d = worst(&g.state, &g.covariance, &w.state, &w.covariance);
            assert!(d <= 1e-12, "lag {lag}: {d:e}");
            assert_eq!(g.gain.is_some(), w.gain.is_some());
        }
    }
}

#[test]
fn on_a_linear_model_it_is_the_kalman_fixed_lag_smoother() {
    // Constant acceleration on two axes observed in both positions, irregular times, missing
    // components.
    let (degree, axes) = (2, 2);
    let n = (degree + 1) * axes;
    let dynamics = PolynomialDynamics::new(degree, axes);
    let observe = LinearObservation::new(DMatrix::from_fn(2, n, |i, j| f64::from(i == j))).unwrap();
    let noise = WhiteNoiseDerivative::new(degree, axes, 0.3).unwrap();
    let (x0, p0) = (
        DVector::zeros(n),
        DMatrix::from_diagonal_element(n, n, 100.0),
    );
    let mut rng = StdRng::seed_from_u64(3);
    let mut t = 0.0;
    let rows: Vec<Measurement> = (0..80)
        .map(|k| {
            t += rng.gen_range(0.2..2.0);
            let values = (0..2)
                .map(|i| {
                    let y = (t * (0.3 + i as f64)).sin() * 10.0 + rng.gen_range(-1.0..1.0);
                    (k % 9 != 4 && k % 7 != i).then_some(y)
                })
                .collect();
            Measurement {
                time: t,
                values,
                noise: NoiseCovariance::Variances(vec![0.5, 2.0]),
            }
        })
        .collect();
    let ukf = UnscentedKalmanFilter::new(dynamics, observe.clone(), x0.clone(), p0.clone(), 0.0)
        .unwrap()
        .with_process_noise(noise)
        .unwrap();
    let kf = KalmanFilter::new(dynamics, observe, x0, p0, 0.0)
        .unwrap()
        .with_process_noise(noise)
        .unwrap();
    let mut overall: f64 = 0.0;
    for lag in [0, 2, 5, 30] {
        let got = fixed_lag(ukf.clone(), &rows, lag);
        let mut s = FixedLagSmoother::new(kf.clone(), lag);
        let mut want = Vec::new();
        for m in &rows {
            want.extend(s.push(m).unwrap());
        }
        want.extend(s.finish().unwrap());
        for (k, (g, w)) in got.iter().zip(&want).enumerate() {
            let d = worst(&g.state, &g.covariance, &w.state, &w.covariance);
            overall = overall.max(d);
            assert!(d <= 1e-9, "lag {lag}, row {k}: {d:e}");
        }
    }
    eprintln!("worst relative difference from the Kalman fixed-lag smoother: {overall:e}");
}

#[test]
fn a_refused_push_leaves_the_smoother_as_it_was() {
    let rows = radar_rows(30, 13);
    let want = fixed_lag(radar_filter(), &rows, 4);
    let mut s = UnscentedFixedLagSmoother::new(radar_filter(), 4);
    let mut got = Vec::new();
    for (k, m) in rows.iter().enumerate() {
        if k == 10 {
            let early = Measurement {
                time: rows[k - 1].time - 1.0,
                ..m.clone()
            };
            assert!(matches!(
                s.push(&early),
                Err(Error::InvalidParameter { .. })
            ));
            let wrong = Measurement {
                values: vec![Some(1.0)],
                ..m.clone()
            };
            assert!(s.push(&wrong).is_err());
            assert_eq!((s.pushed(), s.held()), (10, 4));
        }
        got.extend(s.push(m).unwrap());
    }
    assert_eq!((s.lag(), s.pushed()), (4, rows.len()));
    got.extend(s.finish().unwrap());
    assert_eq!(got, want);
}
