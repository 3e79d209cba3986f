//! Radar tracks for the trackers' Monte Carlo (`tests/track_coverage.rs`, and through
//! `#[path]` the command's `fit --model radar` in `seqsmooth-cli/tests/fit_coverage.rs`), and the
//! tally of what a method made of them: how many rows it estimated, flagged, and covered within 3σ.
//!
//! - the approach and landing of `tests/data/landing.csv` (474 rows, 2.72 s steps, a turn and a
//!   descent; its azimuth is a bearing), its range, bearing and elevation plus N(0, 10 m) and
//!   N(0, 1 mrad) noise of a seed per run, turned into rows by [`radar_row`] (bearing);
//! - simulated turning tracks: a target at 20-60 km, 120-250 m/s, straight legs and two
//!   coordinated turns of 1.5-3 °/s (a climb or descent through one of them), steps U(1, 3) s,
//!   5 % of rows missing, 2 % of rows with one component off by 5-10 σ.
//!
//! Every row's azimuth is from +x towards +y (a bearing is turned by [`radar_row`]); the truth
//! is x east, y north, z up.
#![allow(dead_code)]

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use seqsmooth::model::measurement::Measurement;
use seqsmooth::track::{radar_row, TrackFlag};

pub const SIGMA_RANGE: f64 = 10.0;
pub const SIGMA_ANGLE: f64 = 1e-3;

/// Runs of each set.
pub const LANDING_RUNS: u64 = 100;
pub const TURNING_RUNS: u64 = 100;

/// Rows of a simulated track.
pub const TURNING_ROWS: usize = 160;

/// One track: its rows and the truth (x east, y north, z up) at each.
pub struct Track {
    pub rows: Vec<Measurement>,
    pub truth: Vec<[f64; 3]>,
}

/// landing.csv's rows: time, (east, north, up), (range, bearing, elevation).
pub fn landing_truth() -> Vec<(f64, [f64; 3], [f64; 3])> {
    include_str!("../data/landing.csv")
        .lines()
        .skip(1)
        .map(|line| {
            let c: Vec<f64> = line.split(',').map(|v| v.parse().unwrap()).collect();
            // time,east,north,up,azimuth,elevation,range
            (c[0], [c[1], c[2], c[3]], [c[6], c[4], c[5]])
        })
        .collect()
}

/// landing.csv with the run's noise.
pub fn landing(truth: &[(f64, [f64; 3], [f64; 3])], seed: u64) -> Track {
    let mut rng = StdRng::seed_from_u64(seed);
    let (nr, na) = (
        Normal::new(0.0, SIGMA_RANGE).unwrap(),
        Normal::new(0.0, SIGMA_ANGLE).unwrap(),
    );
    let rows = truth
        .iter()
        .map(|(t, _, polar)| {
            let v = [
                Some(polar[0] + nr.sample(&mut rng)),
                Some(polar[1] + na.sample(&mut rng)),
                Some(polar[2] + na.sample(&mut rng)),
            ];
            radar_row(*t, v, Some(SIGMA_RANGE), Some(SIGMA_ANGLE), true).unwrap()
        })
        .collect();
    Track {
        rows,
        truth: truth.iter().map(|(_, enu, _)| *enu).collect(),
    }
}

/// A simulated turning track (azimuth from +x): legs of constant velocity and coordinated
/// turns, integrated in small steps between the rows.
pub fn turning(seed: u64) -> Track {
    let mut rng = StdRng::seed_from_u64(seed);
    let range = rng.gen_range(20e3..60e3);
    let bearing: f64 = rng.gen_range(0.0..std::f64::consts::TAU);
    let mut p = [
        range * bearing.cos(),
        range * bearing.sin(),
        rng.gen_range(3e3..9e3),
    ];
    let speed = rng.gen_range(120.0..250.0);
    let mut heading: f64 = rng.gen_range(0.0..std::f64::consts::TAU);
    // Two turns: start time, duration, rate (rad/s, either side); the first with a climb or
    // descent.
    let mut turns = Vec::new();
    let mut start = rng.gen_range(40.0..90.0);
    for k in 0..2 {
        let duration = rng.gen_range(25.0..70.0);
        let rate =
            rng.gen_range(1.5f64..3.0).to_radians() * if rng.gen_bool(0.5) { 1.0 } else { -1.0 };
        let vz = if k == 0 {
            rng.gen_range(-15.0..15.0)
        } else {
            0.0
        };
        turns.push((start, start + duration, rate, vz));
        start += duration + rng.gen_range(30.0..80.0);
    }
    let (nr, na) = (
        Normal::new(0.0, SIGMA_RANGE).unwrap(),
        Normal::new(0.0, SIGMA_ANGLE).unwrap(),
    );
    let (mut t, mut rows, mut truth) = (0.0, Vec::new(), Vec::new());
    for _ in 0..TURNING_ROWS {
        let step = rng.gen_range(1.0..3.0);
        let sub = 20;
        for _ in 0..sub {
            let dt = step / sub as f64;
            let turn = turns.iter().find(|(a, b, ..)| t >= *a && t < *b);
            let (rate, vz) = turn.map_or((0.0, 0.0), |(_, _, r, v)| (*r, *v));
            heading += rate * dt;
            p[0] += speed * heading.cos() * dt;
            p[1] += speed * heading.sin() * dt;
            p[2] += vz * dt;
            t += dt;
        }
        let r = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        let mut v = [
            r + nr.sample(&mut rng),
            p[1].atan2(p[0]) + na.sample(&mut rng),
            (p[2] / r).asin() + na.sample(&mut rng),
        ];
        if rng.gen_bool(0.02) {
            let k = rng.gen_range(0..3);
            let sigma = if k == 0 { SIGMA_RANGE } else { SIGMA_ANGLE };
            let sign = if rng.gen_bool(0.5) { 1.0 } else { -1.0 };
            v[k] += sign * rng.gen_range(5.0..10.0) * sigma;
        }
        let values = if rng.gen_bool(0.05) {
            [None; 3]
        } else {
            v.map(Some)
        };
        rows.push(radar_row(t, values, Some(SIGMA_RANGE), Some(SIGMA_ANGLE), false).unwrap());
        truth.push(p);
    }
    Track { rows, truth }
}

/// What one method gave over some rows.
#[derive(Clone, Copy, Debug, Default)]
pub struct Tally {
    /// Rows with an estimate.
    pub estimated: usize,
    /// Of them, flagged outlier and misfit.
    pub outlier: usize,
    pub misfit: usize,
    /// Unflagged rows, and of them the ones within 3σ per axis.
    pub unflagged: usize,
    pub covered: [usize; 3],
}

impl Tally {
    pub fn add(&mut self, o: &Tally) {
        self.estimated += o.estimated;
        self.outlier += o.outlier;
        self.misfit += o.misfit;
        self.unflagged += o.unflagged;
        for k in 0..3 {
            self.covered[k] += o.covered[k];
        }
    }

    pub fn coverage(&self) -> [f64; 3] {
        self.covered
            .map(|c| c as f64 / self.unflagged.max(1) as f64)
    }

    pub fn flagged(&self) -> f64 {
        (self.outlier + self.misfit) as f64 / self.estimated.max(1) as f64
    }

    pub fn score(&mut self, state: &[f64], sigma: [f64; 3], truth: &[f64; 3], flag: TrackFlag) {
        self.estimated += 1;
        match flag {
            TrackFlag::Outlier => self.outlier += 1,
            TrackFlag::Misfit => self.misfit += 1,
            TrackFlag::None => {
                self.unflagged += 1;
                for k in 0..3 {
                    assert!(state[k].is_finite() && sigma[k].is_finite() && sigma[k] > 0.0);
                    self.covered[k] += usize::from((state[k] - truth[k]).abs() <= 3.0 * sigma[k]);
                }
            }
        }
    }
}

pub fn report(name: &str, set: &str, t: &Tally) {
    let c = t.coverage();
    println!(
        "{name:8} {set:8} rows {:6}  unflagged 3σ coverage east {:.2}% north {:.2}% up {:.2}%  \
         flagged {:.1}% (outlier {}, misfit {})",
        t.estimated,
        100.0 * c[0],
        100.0 * c[1],
        100.0 * c[2],
        100.0 * t.flagged(),
        t.outlier,
        t.misfit
    );
}
