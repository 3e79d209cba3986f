//! Villien & Ostertag's Example 1 (§VI-A): a target flying past a CW Doppler radar at
//! constant velocity, seen as its radial velocity in hertz,
//!
//! `h(θ, t) = k v₀ (x₀ − v₀ t)/sqrt((x₀ − v₀ t)² + y₀²)` (eq. 38), `θ = (x₀, y₀, v₀)`, `k = 66`,
//!
//! with the zero-crossing jitter `σ²(t) = K (x₀ − v₀ t)⁴ + σ₀²`, `K = 1.6e4`, `σ₀ = 1.19 Hz`
//! (eq. 39), 1200 samples 4 µs apart, `x₀ = 10 m`, `v₀ = 1800 m/s`. The paper does not print
//! `y₀`, the miss distance: it is a parameter here. Shared by the PAML tests, the example
//! `paml_doppler` and the `paml` benchmark (included by path).

#![allow(dead_code)]

use nalgebra::{DMatrix, DVector};
use rand::Rng;
use rand_distr::StandardNormal;
use seqsmooth::estimate::curve::CurveModel;
use seqsmooth::kalman::KalmanFilter;
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::measurement::Measurement;
use seqsmooth::model::measurement::NoiseCovariance;
use seqsmooth::model::observation::NonlinearObservation;
use seqsmooth::Error;

/// The Doppler constant `k` (Hz s/m).
pub const K_DOPPLER: f64 = 66.0;
/// `K` of eq. 39 (s⁻² m⁻⁴).
pub const K_JITTER: f64 = 1.6e4;
/// `σ₀` of eq. 39 (Hz).
pub const SIGMA_FLOOR: f64 = 1.19;
/// The sampling interval (s).
pub const STEP: f64 = 4e-6;
/// Samples in the paper's run.
pub const SAMPLES: usize = 1200;

/// Eq. 38 with its analytic gradient.
#[derive(Clone, Copy, Debug)]
pub struct Doppler;

/// `h` and `∂h/∂θ` at one time.
pub fn doppler(th: &[f64], t: f64) -> (f64, [f64; 3]) {
    let (x0, y0, v0) = (th[0], th[1], th[2]);
    let x = x0 - v0 * t;
    let r2 = x * x + y0 * y0;
    let r = r2.sqrt();
    let cos = x / r;
    let h = K_DOPPLER * v0 * cos;
    // ∂cos/∂x = y₀²/r³, ∂cos/∂y₀ = −x y₀/r³
    let dcos_dx = y0 * y0 / (r2 * r);
    let dcos_dy = -x * y0 / (r2 * r);
    let g = [
        K_DOPPLER * v0 * dcos_dx,
        K_DOPPLER * v0 * dcos_dy,
        K_DOPPLER * cos - K_DOPPLER * v0 * dcos_dx * t,
    ];
    (h, g)
}

impl CurveModel for Doppler {
    fn parameters(&self) -> usize {
        3
    }
    fn values(&self, th: &[f64], times: &[f64]) -> Result<Vec<f64>, Error> {
        Ok(times.iter().map(|&t| doppler(th, t).0).collect())
    }
    fn jacobian(&self, th: &[f64], times: &[f64]) -> Option<Result<DMatrix<f64>, Error>> {
        let mut j = DMatrix::zeros(times.len(), 3);
        for (k, &t) in times.iter().enumerate() {
            let g = doppler(th, t).1;
            for c in 0..3 {
                j[(k, c)] = g[c];
            }
        }
        Some(Ok(j))
    }
}

/// The eq. 38 model differenced by the fit (no analytic Jacobian).
#[derive(Clone, Copy, Debug)]
pub struct DopplerDifferenced;

impl CurveModel for DopplerDifferenced {
    fn parameters(&self) -> usize {
        3
    }
    fn values(&self, th: &[f64], times: &[f64]) -> Result<Vec<f64>, Error> {
        Doppler.values(th, times)
    }
}

/// A run: its times, noise and truth.
#[derive(Clone, Debug)]
pub struct Scenario {
    pub truth: [f64; 3],
    pub times: Vec<f64>,
    pub sigmas: Vec<f64>,
}

impl Scenario {
    /// `samples` samples from `t = 0`, `STEP` apart, with the paper's `x₀`, `v₀` and the given
    /// miss distance; σ from eq. 39 at the truth (known to the estimators, as in eq. 1).
    pub fn new(y0: f64, samples: usize) -> Self {
        let truth = [10.0, y0, 1800.0];
        let times: Vec<f64> = (0..samples).map(|k| k as f64 * STEP).collect();
        let sigmas = times
            .iter()
            .map(|t| {
                let x = truth[0] - truth[2] * t;
                (K_JITTER * x.powi(4) + SIGMA_FLOOR * SIGMA_FLOOR).sqrt()
            })
            .collect();
        Self {
            truth,
            times,
            sigmas,
        }
    }

    /// One noisy run.
    pub fn measure(&self, rng: &mut impl Rng) -> Vec<f64> {
        self.times
            .iter()
            .zip(&self.sigmas)
            .map(|(&t, s)| doppler(&self.truth, t).0 + s * rng.sample::<f64, _>(StandardNormal))
            .collect()
    }

    /// The same scenario over its first `samples` samples.
    pub fn first(&self, samples: usize) -> Self {
        Self {
            truth: self.truth,
            times: self.times[..samples].to_vec(),
            sigmas: self.sigmas[..samples].to_vec(),
        }
    }
}

/// The prior knowledge the estimators start from: σ of `x₀`, `y₀`, `v₀`.
pub const PRIOR_SIGMA: [f64; 3] = [0.5, 0.3, 50.0];

/// A start drawn about the truth with [`PRIOR_SIGMA`].
pub fn prior(truth: &[f64; 3], rng: &mut impl Rng) -> [f64; 3] {
    let mut p = *truth;
    for (v, s) in p.iter_mut().zip(PRIOR_SIGMA) {
        *v += s * rng.sample::<f64, _>(StandardNormal);
    }
    p
}

/// The extended Kalman filter on the constant state `θ` (the library's `KalmanFilter` with
/// `Φ = I` and the observation eq. 38 at each sample's time), from `start` with covariance
/// `diag(PRIOR_SIGMA²)`: its estimate after every sample.
pub fn extended_kalman(
    scenario: &Scenario,
    values: &[f64],
    start: &[f64; 3],
) -> Result<DVector<f64>, Error> {
    let observation = NonlinearObservation::new(1, 3, |t, x: &DVector<f64>| {
        DVector::from_element(1, doppler(x.as_slice(), t).0)
    })
    .with_jacobian(|t, x: &DVector<f64>| {
        DMatrix::from_row_slice(1, 3, &doppler(x.as_slice(), t).1)
    });
    let p0 = DMatrix::from_diagonal(&DVector::from_iterator(
        3,
        PRIOR_SIGMA.iter().map(|s| s * s),
    ));
    let mut f = KalmanFilter::new(
        PolynomialDynamics::new(0, 3),
        observation,
        DVector::from_column_slice(start),
        p0,
        scenario.times[0],
    )?;
    for ((&t, &y), s) in scenario.times.iter().zip(values).zip(&scenario.sigmas) {
        f.update(&Measurement {
            time: t,
            values: vec![Some(y)],
            noise: NoiseCovariance::Variances(vec![s * s]),
        })?;
    }
    Ok(f.state().clone())
}
