//! The Kalman filter's fixed-size radar update (`kalman::filter::radar`, taken without being
//! asked for `PolynomialDynamics::new(1, 3)` seen by a `Radar`) against the general recursion
//! on the same model: the radar wrapped in an observation of the caller's own type, which the
//! filter cannot recognise, so it runs the general path. Every update's statistics, state and
//! covariance (and `update`'s `Innovation`) are equal as numbers, over random tracks with
//! irregular steps, missing components, `R` by variances, the identity or in full, with and
//! without driving noise, gated updates, and the RTS smoother over the filter.

use nalgebra::{DMatrix, DVector};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use seqsmooth::error::Error;
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::kalman::smoother::smooth_flat;
use seqsmooth::kalman::KalmanFilter;
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
use seqsmooth::model::observation::{Observation, Predicted};
use seqsmooth::model::radar::{wrap, Radar};

/// The radar as an observation the filter does not recognise (`as_radar` is `None`).
#[derive(Clone, Debug)]
struct Plain(Radar);

impl Observation for Plain {
    fn components(&self) -> usize {
        self.0.components()
    }
    fn state_dimension(&self) -> usize {
        self.0.state_dimension()
    }
    fn predict(&self, state: &DVector<f64>, t: f64) -> Result<Predicted, Error> {
        self.0.predict(state, t)
    }
    fn predict_into(
        &self,
        state: &DVector<f64>,
        t: f64,
        value: &mut DVector<f64>,
        jacobian: &mut DMatrix<f64>,
    ) -> Result<(), Error> {
        self.0.predict_into(state, t, value, jacobian)
    }
    fn residual(&self, component: usize, measured: f64, predicted: f64) -> f64 {
        self.0.residual(component, measured, predicted)
    }
}

/// A random track: the two filters (fixed-size and general) at the same prior, and its
/// measurements.
fn track(
    rng: &mut StdRng,
) -> (
    KalmanFilter<PolynomialDynamics, Radar>,
    KalmanFilter<PolynomialDynamics, Plain>,
    Vec<Measurement>,
) {
    let site = [0.0; 3].map(|_| rng.gen_range(-500.0..500.0));
    let truth: Vec<f64> = (0..6)
        .map(|i| {
            if i < 3 {
                site[i] + rng.gen_range(2e4..6e4) * if rng.gen() { 1.0 } else { -1.0 }
            } else {
                rng.gen_range(-250.0..250.0)
            }
        })
        .collect();
    let dynamics = PolynomialDynamics::new(1, 3);
    let radar = Radar::of_polynomial(site, &dynamics).unwrap();
    let mut prior = DMatrix::from_diagonal_element(6, 6, 300.0_f64.powi(2));
    for a in 0..3 {
        prior[(a, a)] = 1e4;
    }
    let state = DVector::from_iterator(
        6,
        truth
            .iter()
            .enumerate()
            .map(|(i, v)| if i < 3 { v + 50.0 } else { 0.0 }),
    );
    let q = rng.gen_range(0.0..4.0);
    let with_noise = rng.gen_bool(0.75);
    let fixed = KalmanFilter::new(dynamics, radar, state.clone(), prior.clone(), 0.0).unwrap();
    let general = KalmanFilter::new(dynamics, Plain(radar), state, prior, 0.0).unwrap();
    let (fixed, general) = if with_noise {
        let noise = WhiteNoiseDerivative::new(1, 3, q).unwrap();
        (
            fixed.with_process_noise(noise).unwrap(),
            general.with_process_noise(noise).unwrap(),
        )
    } else {
        (fixed, general)
    };
    let mut t = 0.0;
    let measurements = (0..60)
        .map(|_| {
            t += rng.gen_range(0.2..2.0);
            let p: Vec<f64> = (0..3)
                .map(|a| truth[a] + truth[a + 3] * t - site[a])
                .collect();
            let h = p[0].hypot(p[1]);
            let rho = (h * h + p[2] * p[2]).sqrt();
            let mut values: Vec<Option<f64>> = vec![
                Some(rho + rng.gen_range(-20.0..20.0)),
                Some(wrap(p[1].atan2(p[0]) + rng.gen_range(-2e-3..2e-3))),
                Some(p[2].atan2(h) + rng.gen_range(-2e-3..2e-3)),
            ];
            for v in values.iter_mut() {
                if rng.gen_bool(0.1) {
                    *v = None;
                }
            }
            let noise = match rng.gen_range(0..10) {
                0 => NoiseCovariance::Identity,
                1 => NoiseCovariance::Full(DMatrix::from_row_slice(
                    3,
                    3,
                    &[100.0, 1e-3, 0.0, 1e-3, 1e-6, 0.0, 0.0, 0.0, 1e-6],
                )),
                _ => NoiseCovariance::Variances(vec![100.0, 1e-6, 4e-6]),
            };
            Measurement {
                time: t,
                values,
                noise,
            }
        })
        .collect();
    (fixed, general, measurements)
}

#[test]
fn every_update_equals_the_general_paths() {
    let mut rng = StdRng::seed_from_u64(33);
    for _ in 0..100 {
        let (mut a, mut b, measurements) = track(&mut rng);
        for (k, m) in measurements.iter().enumerate() {
            match k % 3 {
                0 => {
                    let (x, y) = (a.update_stats(m).unwrap(), b.update_stats(m).unwrap());
                    assert_eq!(x, y);
                }
                1 => {
                    let (x, y) = (a.update(m).unwrap(), b.update(m).unwrap());
                    assert_eq!(x, y);
                }
                _ => {
                    let gate = |s: &seqsmooth::kalman::filter::InnovationStats| s.nis < 7.0;
                    let (x, y) = (
                        a.update_gated(m, gate).unwrap(),
                        b.update_gated(m, gate).unwrap(),
                    );
                    assert_eq!(x, y);
                }
            }
            assert_eq!(a.state(), b.state(), "update {k}");
            assert_eq!(a.covariance(), b.covariance(), "update {k}");
            assert_eq!(a.time(), b.time());
        }
    }
}

#[test]
fn the_smoother_over_it_equals_the_general_paths() {
    let mut rng = StdRng::seed_from_u64(34);
    for _ in 0..20 {
        let (a, b, measurements) = track(&mut rng);
        let (x, y) = (
            smooth_flat(a, &measurements).unwrap(),
            smooth_flat(b, &measurements).unwrap(),
        );
        assert_eq!(x.states, y.states);
        assert_eq!(x.covariances, y.covariances);
    }
}
