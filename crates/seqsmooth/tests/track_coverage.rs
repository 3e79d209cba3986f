//! Monte Carlo of `track::RadarTracker` at its defaults (every method): is the σ of
//! every row it does not flag honest? (`seqsmooth fit --model radar`, the command's sliding fit
//! without the tracker's gate, has its own run over the same tracks in
//! `seqsmooth-cli/tests/fit_coverage.rs`.)
//!
//! Two sets of tracks ([`common::radar_tracks`]), each method run on every track: landing.csv
//! plus noise of a seed per run, and simulated turning tracks with 5 % of rows missing and 2 %
//! with an outlier of 5-10 σ.
//!
//! For each method, pooled over all runs: the rows without a flag cover the truth within 3σ
//! on at least 97 % of east, north and up each; the rows flagged are counted (on landing well
//! under half). The negative control: the old default of the Kalman method (no driving noise,
//! `q = 0`, no adaptation) fails one of the two. Tolerance: the pooled rates hold over 10⁴ rows
//! per axis (standard error about 0.2 % at 97 %).

mod common;

use common::radar_tracks::{
    landing, landing_truth, report, turning, Tally, Track, LANDING_RUNS, TURNING_RUNS,
};
use rayon::prelude::*;
use seqsmooth::model::radar::Radar;
use seqsmooth::track::{RadarTracker, TrackMethod, Tracked, DEFAULT_WINDOW};

/// One method over one track: every row pushed, the smoother's rows as it releases them and
/// at the end.
fn run(method: TrackMethod, track: &Track) -> Tally {
    let radar = Radar::new([0.0; 3], 6).unwrap();
    let mut tracker = RadarTracker::new(radar, method).unwrap();
    let mut tally = Tally::default();
    let sigma = |c: &nalgebra::DMatrix<f64>| [0, 1, 2].map(|k| c[(k, k)].sqrt());
    for (m, truth) in track.rows.iter().zip(&track.truth) {
        match tracker.push(m).unwrap() {
            Tracked::Estimate(e) => {
                tally.score(e.state.as_slice(), sigma(e.covariance), truth, e.flag)
            }
            // The smoother's row `lag` back, as it is released.
            Tracked::Smoothed {
                row,
                estimate: s,
                flag,
            } => tally.score(
                s.state.as_slice(),
                sigma(&s.covariance),
                &track.truth[row],
                flag,
            ),
            Tracked::Undetermined | Tracked::Held => {}
        }
    }
    for (row, s, flag) in tracker.finish().unwrap() {
        tally.score(
            s.state.as_slice(),
            sigma(&s.covariance),
            &track.truth[row],
            flag,
        );
    }
    tally
}

/// The tallies of `method` over the landing runs and the turning runs.
fn monte_carlo(method: TrackMethod) -> (Tally, Tally) {
    let truth = landing_truth();
    let landing = (0..LANDING_RUNS)
        .into_par_iter()
        .map(|seed| run(method, &landing(&truth, 1000 + seed)))
        .reduce(Tally::default, |mut a, b| {
            a.add(&b);
            a
        });
    let turning = (0..TURNING_RUNS)
        .into_par_iter()
        .map(|seed| run(method, &turning(5000 + seed)))
        .reduce(Tally::default, |mut a, b| {
            a.add(&b);
            a
        });
    (landing, turning)
}

/// Every method at its defaults: the unflagged rows' 3σ coverage at least 97 % per axis
/// pooled over both sets; at most a third of landing's rows flagged.
#[test]
fn defaults_cover_or_flag() {
    let mut failures = Vec::new();
    for name in ["kalman", "fading", "smooth", "window"] {
        let method = TrackMethod::named(name).unwrap();
        let (landing, turning) = monte_carlo(method);
        report(name, "landing", &landing);
        report(name, "turning", &turning);
        let mut pooled = landing;
        pooled.add(&turning);
        report(name, "pooled", &pooled);
        for (set, t) in [
            ("landing", &landing),
            ("turning", &turning),
            ("pooled", &pooled),
        ] {
            for (axis, c) in ["east", "north", "up"].iter().zip(t.coverage()) {
                if c < 0.97 {
                    failures.push(format!("{name} {set} {axis}: {:.2}% within 3σ", 100.0 * c));
                }
            }
        }
        if landing.flagged() > 1.0 / 3.0 {
            failures.push(format!(
                "{name}: {:.1}% of landing's rows flagged",
                100.0 * landing.flagged()
            ));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
    assert_eq!(
        TrackMethod::named("window"),
        Some(TrackMethod::Window {
            window: DEFAULT_WINDOW
        })
    );
}

/// The control: the Kalman method without driving noise (the old default) fails the test,
/// either its coverage or its share of flagged rows.
#[test]
fn no_driving_noise_fails() {
    let (landing, turning) = monte_carlo(TrackMethod::Kalman { q: Some(0.0) });
    report("q=0", "landing", &landing);
    report("q=0", "turning", &turning);
    let covered = landing.coverage().iter().all(|&c| c >= 0.97);
    assert!(!covered || landing.flagged() > 1.0 / 3.0);
}
