//! Simulated radar passes for the Gauss–Newton bench (`benches/gauss_newton.rs`) and the peer
//! comparison (`examples/peers.rs`, which writes the same windows for `scripts/peers.py`), so
//! both time the same data. Included by path (`#[path = ...] mod radar;`), not through
//! `common/mod.rs`, so the other benches do not compile it.
//!
//! Window `w` of seed `s`: a 6-state constant-velocity target `(x, y, z, vx, vy, vz)` seen by a
//! radar at the origin, `SAMPLES` measurements of range, azimuth and elevation at irregular
//! times (steps `U(0.5, 1.5)` s from `t = 0`), Gaussian errors of σ 10 m and 1 mrad (azimuth
//! wrapped to `(−π, π]`). At `t = 0` the target is at range `U(20, 80)` km, azimuth `U(−π, π)`,
//! elevation `U(0.02, 0.5)` rad, flying at `U(100, 300)` m/s on a heading `U(−π, π)`, climbing at
//! `U(−10, 10)` m/s. Every number comes from a splitmix64 stream seeded by `(s, w)`, so the
//! windows are the same on every machine and in every target that includes this file.

use nalgebra::DVector;
use seqsmooth::estimate::bootstrap;
use seqsmooth::estimate::gauss_newton::{Correction, Epoch, GaussNewton, Measurement};
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::measurement::NoiseCovariance;
use seqsmooth::model::radar::{wrap, Radar};
use seqsmooth::Error;
use std::f64::consts::PI;

/// Samples per window.
pub const SAMPLES: usize = 60;
/// σ of the range errors, metres.
pub const SIGMA_RANGE: f64 = 10.0;
/// σ of the azimuth and elevation errors, radians.
pub const SIGMA_ANGLE: f64 = 1e-3;
/// The degree of the bootstrap's polynomial fits (range is not linear in time).
pub const BOOTSTRAP_DEGREE: usize = 2;
/// The seed of the bench and of the peer run.
pub const SEED: u64 = 20_260_415;

/// One window of a simulated pass.
pub struct Window {
    /// The measurement times, increasing, from 0.
    pub times: Vec<f64>,
    /// `(ρ, ψ, θ)` at each time.
    pub measured: Vec<[f64; 3]>,
    /// The true state at `t = 0` (the bench checks the fits against it; the peer run does not
    /// read it).
    #[allow(dead_code)]
    pub truth: [f64; 6],
}

/// splitmix64: a tiny, well-mixed, reproducible stream.
struct Stream(u64);

impl Stream {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform on `[0, 1)`.
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// Standard normal (Box–Muller, one of the pair).
    fn normal(&mut self) -> f64 {
        let u = 1.0 - self.unit(); // (0, 1]
        let v = self.unit();
        (-2.0 * u.ln()).sqrt() * (2.0 * PI * v).cos()
    }
}

/// Window `index` of the passes of `seed`.
pub fn window(seed: u64, index: u64) -> Window {
    let mut s = Stream(seed ^ index.wrapping_mul(0xD134_2543_DE82_EF95));
    let (rho, az, el) = (
        s.uniform(20e3, 80e3),
        s.uniform(-PI, PI),
        s.uniform(0.02, 0.5),
    );
    let (speed, heading, climb) = (
        s.uniform(100.0, 300.0),
        s.uniform(-PI, PI),
        s.uniform(-10.0, 10.0),
    );
    let truth = [
        rho * el.cos() * az.cos(),
        rho * el.cos() * az.sin(),
        rho * el.sin(),
        speed * heading.cos(),
        speed * heading.sin(),
        climb,
    ];
    let mut times = Vec::with_capacity(SAMPLES);
    let mut measured = Vec::with_capacity(SAMPLES);
    let mut t = 0.0;
    for k in 0..SAMPLES {
        if k > 0 {
            t += s.uniform(0.5, 1.5);
        }
        let p = [
            truth[0] + truth[3] * t,
            truth[1] + truth[4] * t,
            truth[2] + truth[5] * t,
        ];
        let h = p[0].hypot(p[1]);
        let r = (h * h + p[2] * p[2]).sqrt();
        times.push(t);
        measured.push([
            r + SIGMA_RANGE * s.normal(),
            wrap(p[1].atan2(p[0]) + SIGMA_ANGLE * s.normal()),
            p[2].atan2(h) + SIGMA_ANGLE * s.normal(),
        ]);
    }
    Window {
        times,
        measured,
        truth,
    }
}

/// The first `count` windows of `seed`.
pub fn windows(seed: u64, count: usize) -> Vec<Window> {
    (0..count as u64).map(|w| window(seed, w)).collect()
}

/// The dynamics and the radar of every window.
pub fn models() -> (PolynomialDynamics, Radar) {
    (
        PolynomialDynamics::new(1, 3),
        Radar::new([0.0; 3], 6).expect("a finite site, 6 states"),
    )
}

impl Window {
    /// The measurements as the Gauss–Newton fit takes them.
    pub fn measurements(&self) -> Vec<Measurement> {
        let variances = vec![
            SIGMA_RANGE.powi(2),
            SIGMA_ANGLE.powi(2),
            SIGMA_ANGLE.powi(2),
        ];
        self.times
            .iter()
            .zip(&self.measured)
            .map(|(&time, m)| Measurement {
                time,
                values: m.iter().map(|&v| Some(v)).collect(),
                noise: NoiseCovariance::Variances(variances.clone()),
            })
            .collect()
    }

    /// The epoch of the fits: the last time (`Epoch::End`).
    pub fn epoch(&self) -> f64 {
        Epoch::End.time_for(&self.times)
    }

    /// The bootstrap nominal (Morrison §8.5) at the epoch.
    pub fn nominal(&self, radar: &Radar) -> Result<DVector<f64>, Error> {
        bootstrap::radar(
            radar,
            &self.times,
            &self.measured,
            self.epoch(),
            BOOTSTRAP_DEGREE,
        )
    }
}

/// The Gauss–Newton fit (default limits) of `measurements` from `nominal`, at the last time.
pub fn fit(
    dynamics: &PolynomialDynamics,
    radar: &Radar,
    measurements: &[Measurement],
    nominal: &DVector<f64>,
) -> Result<Correction, Error> {
    GaussNewton::default().fit(dynamics, radar, measurements, Epoch::End, nominal, None)
}
