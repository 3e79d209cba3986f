//! The radar Gauss–Newton fit against its floor, the pair timed back to back and repeated (for
//! a loaded machine: the ratio of each pair, its spread over the repetitions, and each side's
//! best): `GaussNewton::fit` (`Epoch::End`, its default limits) from the bootstrap nominal on
//! the 60-sample windows of `benches/common/radar.rs` (`benches/gauss_newton.rs`'s
//! `radar60/fit_from_nominal`) against the same algorithm written by hand for the model
//! (`benches/common/gauss_newton_floor.rs`). Before timing, each window's fit is compared with
//! the floor's: the same number of linearisations, the states within 1e-6 of the fit's σ.
//!
//! Times are the thread's CPU time (`clock_gettime(CLOCK_THREAD_CPUTIME_ID)`), so that other
//! processes on a shared machine count less.
//! Run: `cargo run --release -p seqsmooth --example gauss_newton_floor_pace -- [REPS] [WINDOWS]`
//! (default 15 and 64); `-- library N` runs the library's fits alone N times (for callgrind).

#[path = "common/pace.rs"]
mod pace;

#[path = "../benches/common/radar.rs"]
#[allow(dead_code)]
mod radar;

#[path = "../benches/common/gauss_newton_floor.rs"]
mod floor;

use pace::pair;
use seqsmooth::estimate::gauss_newton::GaussNewton;
use std::hint::black_box;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let library_only = args.first().is_some_and(|a| a == "library");
    let number =
        |i: usize, default: usize| args.get(i).map_or(default, |a| a.parse().expect("a count"));
    let (reps, count) = if library_only {
        (number(1, 100), 64)
    } else {
        (number(0, 15), number(1, 64))
    };
    let (dynamics, radar) = radar::models();
    let windows = radar::windows(radar::SEED, count);
    let rows: Vec<_> = windows.iter().map(|w| w.measurements()).collect();
    let nominals: Vec<_> = windows.iter().map(|w| w.nominal(&radar).unwrap()).collect();
    let sigma = [radar::SIGMA_RANGE, radar::SIGMA_ANGLE, radar::SIGMA_ANGLE];
    let limits = GaussNewton::default();
    let library = || {
        rows.iter()
            .zip(&nominals)
            .map(|(r, x0)| radar::fit(&dynamics, &radar, r, x0).unwrap().state[0])
            .sum::<f64>()
    };
    if library_only {
        for _ in 0..reps {
            black_box(library());
        }
        return;
    }
    let mut work = floor::FloorWork::new(radar::SAMPLES);
    let mut hand = |w: &radar::Window, x0: &nalgebra::DVector<f64>| {
        floor::radar_fit(
            &mut work,
            &w.times,
            &w.measured,
            sigma,
            std::array::from_fn(|i| x0[i]),
            limits.tolerance,
            limits.max_iterations,
            limits.max_halvings,
        )
        .expect("the floor converges")
    };
    let mut worst = 0.0_f64;
    for ((w, r), x0) in windows.iter().zip(&rows).zip(&nominals) {
        let fit = radar::fit(&dynamics, &radar, r, x0).unwrap();
        let (state, covariance, iterations) = hand(w, x0);
        assert_eq!(iterations, fit.iterations.len(), "linearisations");
        for i in 0..6 {
            let sigma = fit.covariance[(i, i)].sqrt();
            worst = worst.max((state[i] - fit.state[i]).abs() / sigma);
            let cov = (covariance[i][i] - fit.covariance[(i, i)]).abs() / fit.covariance[(i, i)];
            assert!(cov < 1e-6, "covariance {i}: {cov}");
        }
    }
    assert!(
        worst < 1e-6,
        "the floor's state is {worst} σ from the fit's"
    );
    let floor_fits = || {
        windows
            .iter()
            .zip(&nominals)
            .map(|(w, x0)| hand(w, x0).0[0])
            .sum::<f64>()
    };
    let p = pair(reps, floor_fits, library);
    let per = |s: f64| s / count as f64 * 1e6;
    println!("largest state difference {worst:.2e} σ");
    println!("pair,fits,reps,a_best_us,b_best_us,ratio_min,ratio_median,ratio_max");
    println!(
        "radar60 floor/library,{count},{reps},{:.2},{:.2},{:.3},{:.3},{:.3}",
        per(p[0]),
        per(p[1]),
        p[2],
        p[3],
        p[4]
    );
}
