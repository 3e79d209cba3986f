//! The Kalman filter's update and its Rauch–Tung–Striebel smoother against their floors, each
//! pair timed back to back and repeated (for a loaded machine: the ratio of each pair, its
//! spread over the repetitions, and each side's best):
//!
//! - `kalman3`: `KalmanFilter::update_stats` on the 3-state polynomial model (`benches/kalman.rs`'s
//!   data: 10⁵ irregular samples) against the hand-written loop of the same recursion
//!   (`benches/common/floor.rs`);
//! - `ekf6`: the 6-state radar extended filter over 64 tracks of 59 updates
//!   (`benches/common/kalman.rs`) against its hand-written loop, which reads flat arrays of
//!   times and values made beforehand (`ekf6 floor/library`) or the library's own input, the
//!   `Measurement` rows (`ekf6 rows-floor/library`);
//! - `rts3`, `rts6`: the forward filter alone against `smoother::smooth_flat_into` (the filter
//!   keeping its predictions, then the backward pass; its buffers reused from call to call)
//!   on the first 2·10⁴ samples and on the 64 tracks, and against `smooth_flat` (new buffers
//!   each call, the system's first touch of them included); the backward pass per step is the
//!   difference, reported against the forward step.
//!
//! Times are the thread's CPU time (`clock_gettime(CLOCK_THREAD_CPUTIME_ID)`), so that other processes on
//! a shared machine count less. Each side's run is checked against the other's before timing (the floors against the
//! library within 1e-9 and 1e-7 relative, as the bench does).
//! Run: `cargo run --release -p seqsmooth --example kalman_floor_pace -- [REPS] [PAIR]` (default
//! 15 repetitions, every pair; `PAIR` times only the pairs whose name starts with it, e.g.
//! `kalman3` under `valgrind --tool=callgrind` for instructions per update).

#[path = "common/pace.rs"]
mod pace;

#[path = "../benches/common/radar.rs"]
#[allow(dead_code)]
mod radar;

#[path = "../benches/common/kalman.rs"]
mod kalman_tracks;

#[path = "../benches/common/floor.rs"]
mod floor;

use pace::pair;
use seqsmooth::kalman::smoother::{smooth_flat, smooth_flat_into, SmoothedRun};
use seqsmooth::kalman::KalmanFilter;
use seqsmooth::model::dynamics::Dynamics;
use seqsmooth::model::measurement::Measurement;
use seqsmooth::model::observation::Observation;

/// The library's filter over every run by `update_stats`: the summed log-likelihood.
fn filter_runs<D: Dynamics + Clone, O: Observation + Clone>(
    filters: &[KalmanFilter<D, O>],
    runs: &[&[Measurement]],
) -> f64 {
    filters
        .iter()
        .zip(runs)
        .map(|(f, run)| {
            let mut f = f.clone();
            run.iter()
                .map(|m| f.update_stats(m).unwrap().map_or(0.0, |s| s.log_likelihood))
                .sum::<f64>()
        })
        .sum()
}

/// The smoother over every run, into `out` (its buffers reused from run to run, as for the
/// filter's, which has its own): the sum of the first smoothed state's entries.
fn smooth_runs<D: Dynamics + Clone, O: Observation + Clone>(
    filters: &[KalmanFilter<D, O>],
    runs: &[&[Measurement]],
    out: &mut SmoothedRun,
) -> f64 {
    filters
        .iter()
        .zip(runs)
        .map(|(f, run)| {
            smooth_flat_into(f.clone(), run, out).unwrap();
            out.states[0]
        })
        .sum()
}

fn main() {
    let reps: usize = std::env::args()
        .nth(1)
        .map_or(15, |a| a.parse().expect("REPS a count"));
    let (filter, rows) = floor::polynomial_case(100_000);
    let ts: Vec<f64> = rows.iter().map(|m| m.time).collect();
    let ys: Vec<f64> = rows.iter().map(|m| m.values[0].unwrap()).collect();
    let s0 = [[1e4, 0.0, 0.0], [0.0, 1e4, 0.0], [0.0, 0.0, 1e4]];
    let floor3 = || {
        floor::kalman3(
            [0.0; 3],
            s0,
            0.0,
            floor::Q3,
            floor::SIGMA3.powi(2),
            &ts,
            &ys,
        )
        .2
    };
    let lib3 = || filter_runs(std::slice::from_ref(&filter), &[&rows]);
    let (want, got) = (lib3(), floor3());
    assert!(
        (want - got).abs() <= 1e-9 * want.abs(),
        "kalman3 floor {got} library {want}"
    );

    let tracks = kalman_tracks::tracks(radar::SEED, 64);
    let filters: Vec<_> = tracks.iter().map(|t| t.filter()).collect();
    let runs: Vec<&[Measurement]> = tracks.iter().map(|t| t.measurements.as_slice()).collect();
    let updates: usize = runs.iter().map(|r| r.len()).sum();
    let r = [
        radar::SIGMA_RANGE.powi(2),
        radar::SIGMA_ANGLE.powi(2),
        radar::SIGMA_ANGLE.powi(2),
    ];
    let hand: Vec<_> = tracks
        .iter()
        .map(|t| {
            let x: [f64; 6] = std::array::from_fn(|i| t.state[i]);
            let s: [[f64; 6]; 6] =
                std::array::from_fn(|i| std::array::from_fn(|j| t.covariance[(i, j)]));
            let ts: Vec<f64> = t.measurements.iter().map(|m| m.time).collect();
            let zs: Vec<[f64; 3]> = t
                .measurements
                .iter()
                .map(|m| std::array::from_fn(|c| m.values[c].unwrap()))
                .collect();
            (x, s, t.time, ts, zs)
        })
        .collect();
    let floor6 = || {
        hand.iter()
            .map(|(x, s, t0, ts, zs)| floor::ekf6(*x, *s, *t0, kalman_tracks::Q, r, ts, zs).2)
            .sum::<f64>()
    };
    let lib6 = || filter_runs(&filters, &runs);
    let (want, got) = (lib6(), floor6());
    assert!(
        (want - got).abs() <= 1e-7 * want.abs(),
        "ekf6 floor {got} library {want}"
    );
    // The same loop reading the library's input (the `Measurement` rows) instead of arrays.
    let floor6_rows = || {
        hand.iter()
            .zip(&runs)
            .map(|((x, s, t0, _, _), run)| floor::ekf6_rows(*x, *s, *t0, kalman_tracks::Q, run).2)
            .sum::<f64>()
    };
    assert_eq!(
        floor6_rows(),
        got,
        "the floor on rows is the floor on arrays"
    );

    let short = &rows[..20_000];
    let f3 = std::slice::from_ref(&filter);
    let per = |s: f64, count: usize| s / count as f64 * 1e9;
    println!("pair,steps,reps,a_best_ns,b_best_ns,ratio_min,ratio_median,ratio_max");
    let only = std::env::args().nth(2);
    let want = |name: &str| only.as_deref().is_none_or(|o| name.starts_with(o));
    let show = |name: &str, steps: usize, p: [f64; 5]| {
        println!(
            "{name},{steps},{reps},{:.1},{:.1},{:.3},{:.3},{:.3}",
            per(p[0], steps),
            per(p[1], steps),
            p[2],
            p[3],
            p[4]
        );
    };
    if want("kalman3 floor/library") {
        show(
            "kalman3 floor/library",
            rows.len(),
            pair(reps, floor3, lib3),
        );
    }
    if want("ekf6 floor/library") {
        show("ekf6 floor/library", updates, pair(reps, floor6, lib6));
    }
    if want("ekf6 rows-floor/library") {
        show(
            "ekf6 rows-floor/library",
            updates,
            pair(reps, floor6_rows, lib6),
        );
    }
    let mut out = SmoothedRun::new();
    if want("rts3 filter/smooth_flat_into") {
        show(
            "rts3 filter/smooth_flat_into",
            short.len(),
            pair(
                reps,
                || filter_runs(f3, &[short]),
                || smooth_runs(f3, &[short], &mut out),
            ),
        );
    }
    if want("rts3 filter/smooth_flat") {
        show(
            "rts3 filter/smooth_flat",
            short.len(),
            pair(
                reps,
                || filter_runs(f3, &[short]),
                || smooth_flat(filter.clone(), short).unwrap().states[0],
            ),
        );
    }
    if want("rts6 filter/smooth_flat_into") {
        show(
            "rts6 filter/smooth_flat_into",
            updates,
            pair(
                reps,
                || filter_runs(&filters, &runs),
                || smooth_runs(&filters, &runs, &mut out),
            ),
        );
    }
}
