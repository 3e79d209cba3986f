//! `track::RadarTracker` with each built-in motion model (`track::model`) on the trackers'
//! radar tracks ([`common::radar_tracks`]): landing.csv converted to radar plus noise, and
//! simulated tracks with two coordinated turns of 1.5-3 °/s. Each model runs with the kalman,
//! smooth and fading methods; per model, pooled over the runs: the NIS per degree of freedom of
//! the filter's updates and the position error (RMS of the 3-D error), on the straight legs and
//! through the turns (rows where the true heading turns faster than 0.5 °/s).
//!
//! The claim: with the same small driving noise (`q = 0.5 m²/s³`, right for the straight legs)
//! the coordinated turn follows the turns that constant velocity does not: its position error
//! through the turns is less than half constant velocity's, and its NIS there near 1 where
//! constant velocity's is many times it. At their defaults (the adaptive driving noise) every
//! model keeps its NIS near 1.

mod common;

use common::radar_tracks::{landing, landing_truth, turning, Track};
use rayon::prelude::*;
use seqsmooth::estimate::gauss_newton::GaussNewton;
use seqsmooth::model::radar::Radar;
use seqsmooth::track::{MotionModel, RadarTracker, TrackMethod, Tracked};

const TURNING_RUNS: u64 = 40;
const LANDING_RUNS: u64 = 10;

/// Sums over rows: the NIS and their degrees of freedom, squared position errors and rows,
/// on the legs (0) and in the turns (1).
#[derive(Clone, Copy, Debug, Default)]
struct Score {
    nis: [f64; 2],
    dof: [usize; 2],
    squared: [f64; 2],
    rows: [usize; 2],
}

impl Score {
    fn add(mut self, o: Score) -> Score {
        for k in 0..2 {
            self.nis[k] += o.nis[k];
            self.dof[k] += o.dof[k];
            self.squared[k] += o.squared[k];
            self.rows[k] += o.rows[k];
        }
        self
    }

    fn nis_per_dof(&self, k: usize) -> f64 {
        self.nis[k] / self.dof[k].max(1) as f64
    }

    fn rms(&self, k: usize) -> f64 {
        (self.squared[k] / self.rows[k].max(1) as f64).sqrt()
    }
}

/// Whether each row is in a turn: the true heading (from the neighbouring rows) turning
/// faster than 0.5 °/s.
fn in_turn(track: &Track) -> Vec<bool> {
    let p = &track.truth;
    let t: Vec<f64> = track.rows.iter().map(|m| m.time).collect();
    (0..p.len())
        .map(|k| {
            if k == 0 || k + 1 == p.len() {
                return false;
            }
            let h0 = (p[k][1] - p[k - 1][1]).atan2(p[k][0] - p[k - 1][0]);
            let h1 = (p[k + 1][1] - p[k][1]).atan2(p[k + 1][0] - p[k][0]);
            let mut d = h1 - h0;
            d -= std::f64::consts::TAU * (d / std::f64::consts::TAU).round();
            let dt = (t[k + 1] - t[k - 1]) / 2.0;
            (d / dt).abs() > 0.5f64.to_radians()
        })
        .collect()
}

fn run(model: MotionModel, method: TrackMethod, track: &Track) -> Score {
    let radar = Radar::new([0.0; 3], 6).unwrap();
    let mut tracker =
        RadarTracker::with_model(radar, method, model, GaussNewton::default()).unwrap();
    let turn = in_turn(track);
    let mut score = Score::default();
    let mut add = |row: usize, state: &[f64], nis: Option<f64>| {
        let k = usize::from(turn[row]);
        let truth = &track.truth[row];
        let e2: f64 = (0..3).map(|i| (state[i] - truth[i]).powi(2)).sum();
        assert!(e2.is_finite());
        score.squared[k] += e2;
        score.rows[k] += 1;
        if let Some(nis) = nis {
            let p = track.rows[row].values.iter().flatten().count();
            score.nis[k] += nis;
            score.dof[k] += p;
        }
    };
    for (row, m) in track.rows.iter().enumerate() {
        match tracker.push(m).unwrap() {
            Tracked::Estimate(e) => {
                assert_eq!(e.state.len(), model.dimension());
                add(row, e.state.as_slice(), e.nis)
            }
            Tracked::Smoothed { row, estimate, .. } => {
                add(row, estimate.state.as_slice(), estimate.nis)
            }
            Tracked::Undetermined | Tracked::Held => {}
        }
    }
    for (row, s, _) in tracker.finish().unwrap() {
        add(row, s.state.as_slice(), s.nis);
    }
    score
}

fn models() -> [MotionModel; 4] {
    MotionModel::NAMES.map(|n| MotionModel::named(n).unwrap())
}

fn pooled(model: MotionModel, method: TrackMethod, tracks: &[Track]) -> Score {
    tracks
        .par_iter()
        .map(|t| run(model, method, t))
        .reduce(Score::default, Score::add)
}

fn print(set: &str, method: &str, model: MotionModel, s: &Score) {
    println!(
        "{set:8} {method:14} {:22} legs: NIS/dof {:6.2} RMS {:7.1} m ({} rows)  turns: NIS/dof {:6.2} RMS {:7.1} m ({} rows)",
        model.name(),
        s.nis_per_dof(0),
        s.rms(0),
        s.rows[0],
        s.nis_per_dof(1),
        s.rms(1),
        s.rows[1]
    );
}

/// The coordinated turn follows the turns that constant velocity, with the same small driving
/// noise, does not.
#[test]
fn the_turn_model_follows_a_turn_that_constant_velocity_does_not() {
    let tracks: Vec<Track> = (0..TURNING_RUNS).map(|k| turning(0x7a_0000 + k)).collect();
    let method = TrackMethod::Kalman { q: Some(0.5) };
    let mut scores = Vec::new();
    for model in models() {
        if matches!(model, MotionModel::Singer { .. }) {
            continue; // its driving noise is its variance, not q
        }
        let s = pooled(model, method, &tracks);
        print("turning", "kalman q 0.5", model, &s);
        scores.push((model, s));
    }
    let cv = scores[0].1;
    let turn = scores[2].1;
    assert!(
        turn.rms(1) < 0.5 * cv.rms(1),
        "through the turns: {} m against {} m",
        turn.rms(1),
        cv.rms(1)
    );
    assert!(turn.nis_per_dof(1) < 2.0 && cv.nis_per_dof(1) > 4.0);
    // On the legs the turn model does not lose what constant velocity has.
    assert!(turn.rms(0) < 1.5 * cv.rms(0));
    // At their defaults (the adaptive driving noise, which raises constant velocity's `q` in
    // a turn) the turn model still follows the turns more closely, by less.
    let adaptive = TrackMethod::Kalman { q: None };
    let cv = pooled(models()[0], adaptive, &tracks);
    let turn = pooled(models()[3], adaptive, &tracks);
    print("turning", "kalman", models()[0], &cv);
    print("turning", "kalman", models()[3], &turn);
    assert!(
        turn.rms(1) < 0.9 * cv.rms(1),
        "{} m against {} m",
        turn.rms(1),
        cv.rms(1)
    );
    assert!(turn.nis_per_dof(1) < cv.nis_per_dof(1));
}

/// Every model with every Kalman method at its defaults on landing.csv and on the turning
/// tracks: a finite estimate of the model's dimension on every determined row, the NIS per
/// degree of freedom reported (within [0.5, 2] for the kalman method's adaptive memory).
#[test]
fn every_model_runs_with_every_kalman_method() {
    let truth = landing_truth();
    let landings: Vec<Track> = (0..LANDING_RUNS)
        .map(|k| landing(&truth, 0x1a_0000 + k))
        .collect();
    let turnings: Vec<Track> = (0..TURNING_RUNS / 4)
        .map(|k| turning(0x7b_0000 + k))
        .collect();
    for (set, tracks) in [("landing", &landings), ("turning", &turnings)] {
        for model in models() {
            for (name, method) in [
                ("kalman", TrackMethod::Kalman { q: None }),
                ("smooth", TrackMethod::Smooth { q: None, lag: 20 }),
                ("fading", TrackMethod::Fading(None)),
            ] {
                let s = pooled(model, method, tracks);
                print(set, name, model, &s);
                let all = s.add(Score::default());
                let nis = (all.nis[0] + all.nis[1]) / (all.dof[0] + all.dof[1]) as f64;
                if name == "kalman" {
                    assert!(
                        (0.5..2.0).contains(&nis),
                        "{set} {name} {}: {nis}",
                        model.name()
                    );
                }
            }
        }
    }
}
