//! Consistency of the unscented and the extended Kalman filters and their smoothers by Monte
//! Carlo, on a coordinated-turn target seen by a radar in range, azimuth and elevation, on
//! irregular steps with missing rows and missing components: the mean NEES and mean NIS inside
//! their 99 % chi-squared intervals ([`ConsistencyTest`]).
//!
//! **The model.** The library's [`CoordinatedTurn`] with its rate estimated: the state
//! `(x, y, z, x′, y′, z′, ω)`, a turn at rate `ω` in the horizontal plane, constant vertical
//! velocity, in closed form with its analytic `Φ` (which the extended filter and the RTS
//! smoother use, the unscented filter not), with additive driving noise `Q(ζ)`: white
//! acceleration of density `q = 0.5 m²/s³` on each axis and a random walk of `ω` of density
//! `q_ω = 1e-6 rad²/s³`. The truth is drawn from the same model: each step the turn, then a
//! perturbation drawn exactly from `N(0, Q(ζ))`; so the filter's model is the truth's, and
//! what is tested is each filter's approximation of the nonlinear turn and radar (sigma
//! points; first-order linearisation, §12.5).
//!
//! **The runs.** Each run draws the start from the filters' prior (position σ 100 m at about
//! 25 km, velocity σ 15 m/s about 200 m/s, `ω` σ 0.005 about 0.03 rad/s, i.e. 6 m/s²), 60 steps
//! `U(0.5, 1.5)` s, a radar at the origin with `σ_ρ = 10 m`, `σ_ψ = σ_θ = 2 mrad`; 5 % of rows
//! missing entirely and each component of the others with probability 5 %. Both filters start
//! at the prior's mean and covariance on the same rows; [`smooth_unscented`] and
//! [`smoother::smooth`] (Rauch–Tung–Striebel over the extended filter) smooth each run.
//!
//! **Independence.** The NEES of one run at successive steps are correlated, so each NEES test
//! takes one value per run at one step (the middle step 30 and the last 59 for the filter;
//! the first step and the middle step for the smoother): `RUNS` independent values each. The
//! filter's innovations are white when its model holds, so every update's NIS goes in, with
//! as many degrees of freedom as components present.
//!
//! Measured (`cargo test --release -p seqsmooth --test kalman_unscented_consistency --
//! --nocapture`, 2,000 runs, 10 s on two cores for both filters), 99 % interval of the mean
//! NEES [6.786, 7.217], of the NIS per degree of freedom [0.9935, 1.0063]:
//!
//! | | filter NEES step 30 | step 59 | smoother NEES step 0 | step 30 | NIS per dof (114,123 updates) |
//! |---|---|---|---|---|---|
//! | unscented | 7.059 | 7.129 | 7.125 | 7.110 | 1.0002 |
//! | extended | 7.064 | 7.132 | 7.130 | 7.111 | 1.0002 |
//!
//! Each filter given half the driving noise fails every one of them (the extended: NEES
//! 10.6-10.9, NIS 1.041 per degree of freedom).

use nalgebra::{DMatrix, DVector};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use seqsmooth::kalman::noise::ProcessNoise;
use seqsmooth::kalman::{smooth_unscented, smoother, KalmanFilter, UnscentedKalmanFilter};
use seqsmooth::model::coordinated_turn::CoordinatedTurn;
use seqsmooth::model::dynamics::Dynamics;
use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
use seqsmooth::model::observation::Observation;
use seqsmooth::model::radar::Radar;
use seqsmooth::stats::consistency::{nees, ConsistencyTest};
use std::sync::OnceLock;

const RUNS: usize = 2000;
const STEPS: usize = 60;
const Q: f64 = 0.5;
const Q_OMEGA: f64 = 1e-6;

/// The model: the library's coordinated turn with its rate estimated, its driving noise
/// white acceleration on each axis and a random walk of `ω`.
fn model() -> CoordinatedTurn {
    CoordinatedTurn::estimated(Q, Q_OMEGA).unwrap()
}

fn prior() -> (DVector<f64>, DMatrix<f64>) {
    let x = DVector::from_vec(vec![20e3, 15e3, 3e3, -150.0, 130.0, 2.0, 0.03]);
    let s = DMatrix::from_diagonal(&DVector::from_vec(vec![
        1e4, 1e4, 1e4, 225.0, 225.0, 25.0, 2.5e-5,
    ]));
    (x, s)
}

/// A draw from `N(0, S)`.
fn gaussian(r: &mut StdRng, s: &DMatrix<f64>) -> DVector<f64> {
    let l = s.clone().cholesky().expect("positive definite").l();
    let z = DVector::from_fn(s.nrows(), |_, _| StandardNormal.sample(r));
    l * z
}

/// One filter's and its smoother's numbers in one run: the filter's NEES at steps 30 and
/// 59, its NIS with their degrees of freedom, the smoother's NEES at steps 0 and 30.
struct Pass {
    filter_nees: [f64; 2],
    nis: Vec<(f64, usize)>,
    smoother_nees: [f64; 2],
    /// The smoother's covariance trace over the filter's at step 30.
    shrink: f64,
}

/// One run: the unscented and the extended filter (with their smoothers) on the same rows.
struct Run {
    unscented: Pass,
    extended: Pass,
}

/// The rows of one run and the truth at each.
fn simulate(r: &mut StdRng) -> (Vec<Measurement>, Vec<DVector<f64>>) {
    let (x0, s0) = prior();
    let radar = Radar::new([0.0; 3], 7).unwrap();
    let noise = NoiseCovariance::Variances(vec![100.0, 4e-6, 4e-6]);
    let turn = model();
    let mut truth = &x0 + gaussian(r, &s0);
    let (mut t, mut truths, mut rows) = (0.0, Vec::new(), Vec::new());
    for _ in 0..STEPS {
        let zeta = r.gen_range(0.5..1.5);
        let q = turn.covariance(t, t + zeta).unwrap();
        truth = turn.propagate_state(&truth, t, t + zeta).unwrap() + gaussian(r, &q);
        t += zeta;
        let seen = radar.predict(&truth, t).unwrap().value;
        let sd = [10.0, 2e-3, 2e-3];
        let whole = r.gen::<f64>() < 0.05;
        let values = (0..3)
            .map(|c| {
                let e: f64 = StandardNormal.sample(r);
                let y = seen[c] + sd[c] * e;
                (!whole && r.gen::<f64>() >= 0.05).then_some(y)
            })
            .collect();
        truths.push(truth.clone());
        rows.push(Measurement {
            time: t,
            values,
            noise: noise.clone(),
        });
    }
    (rows, truths)
}

/// A filter's forward pass over `rows` (`update` gives each update's NIS and degrees of
/// freedom, and the state and covariance after it): its NEES at steps 30 and 59, and every
/// update's NIS.
#[allow(clippy::type_complexity)]
fn forward(
    rows: &[Measurement],
    truths: &[DVector<f64>],
    mut update: impl FnMut(&Measurement) -> (Option<(f64, usize)>, DVector<f64>, DMatrix<f64>),
) -> ([f64; 2], Vec<(f64, usize)>) {
    let (mut nis, mut filter_nees) = (Vec::new(), [0.0; 2]);
    for (k, m) in rows.iter().enumerate() {
        let (i, x, s) = update(m);
        nis.extend(i);
        for (slot, at) in [30, STEPS - 1].into_iter().enumerate() {
            if k == at {
                filter_nees[slot] = nees(&x, &s, &truths[k]).unwrap();
            }
        }
    }
    (filter_nees, nis)
}

fn run(seed: u64) -> Run {
    let mut r = StdRng::seed_from_u64(seed);
    let (rows, truths) = simulate(&mut r);
    let (x0, s0) = prior();
    let radar = Radar::new([0.0; 3], 7).unwrap();
    let unscented_filter = || {
        UnscentedKalmanFilter::new(model(), radar, x0.clone(), s0.clone(), 0.0)
            .unwrap()
            .with_process_noise(model())
            .unwrap()
    };
    let mut f = unscented_filter();
    let (filter_nees, nis) = forward(&rows, &truths, |m| {
        let i = f.update(m).unwrap().map(|i| (i.nis, i.components.len()));
        (i, f.state().clone(), f.covariance().clone())
    });
    let smoothed = smooth_unscented(unscented_filter(), &rows).unwrap();
    let at = |k: usize| {
        (
            &smoothed[k].state,
            &smoothed[k].covariance,
            &smoothed[k].filtered_covariance,
        )
    };
    let unscented = pass(filter_nees, nis, &at, &truths);
    // The extended Kalman filter (§12.5) with the model's analytic Φ, and its RTS smoother.
    let extended_filter = || {
        KalmanFilter::new(model(), radar, x0.clone(), s0.clone(), 0.0)
            .unwrap()
            .with_process_noise(model())
            .unwrap()
    };
    let mut f = extended_filter();
    let (filter_nees, nis) = forward(&rows, &truths, |m| {
        let i = f.update(m).unwrap().map(|i| (i.nis, i.components.len()));
        (i, f.state().clone(), f.covariance().clone())
    });
    let smoothed = smoother::smooth(extended_filter(), &rows).unwrap();
    let at = |k: usize| {
        (
            &smoothed[k].state,
            &smoothed[k].covariance,
            &smoothed[k].filtered_covariance,
        )
    };
    let extended = pass(filter_nees, nis, &at, &truths);
    Run {
        unscented,
        extended,
    }
}

/// The smoother's state, covariance and the filter's covariance at a step.
type Smoothed<'a> = &'a dyn Fn(usize) -> (&'a DVector<f64>, &'a DMatrix<f64>, &'a DMatrix<f64>);

fn pass(
    filter_nees: [f64; 2],
    nis: Vec<(f64, usize)>,
    smoothed: Smoothed<'_>,
    truths: &[DVector<f64>],
) -> Pass {
    let smoother_nees = [0, 30].map(|k| {
        let (x, s, _) = smoothed(k);
        nees(x, s, &truths[k]).unwrap()
    });
    let (_, s, filtered) = smoothed(30);
    let shrink = s.trace() / filtered.trace();
    Pass {
        filter_nees,
        nis,
        smoother_nees,
        shrink,
    }
}

/// The runs, made once for both tests.
fn runs() -> &'static [Run] {
    static RUNS_MADE: OnceLock<Vec<Run>> = OnceLock::new();
    RUNS_MADE.get_or_init(|| {
        (0..RUNS as u64)
            .into_par_iter()
            .map(|k| run(0x0ce5_7000 + k))
            .collect()
    })
}

/// The five tests of one filter over the runs; the names of those outside their 99 %
/// interval, and the smoother's mean covariance shrink at step 30.
fn check(which: &str, pick: fn(&Run) -> &Pass) -> (Vec<&'static str>, f64) {
    let runs = runs();
    let mut tests: Vec<(&'static str, ConsistencyTest)> = Vec::new();
    for (name, value) in [
        (
            "filter NEES at step 30",
            (|p: &Pass| p.filter_nees[0]) as fn(&Pass) -> f64,
        ),
        ("filter NEES at step 59", |p: &Pass| p.filter_nees[1]),
        ("smoother NEES at step 0", |p: &Pass| p.smoother_nees[0]),
        ("smoother NEES at step 30", |p: &Pass| p.smoother_nees[1]),
    ] {
        let mut c = ConsistencyTest::new(7).unwrap();
        for r in runs {
            c.push(value(pick(r))).unwrap();
        }
        tests.push((name, c));
    }
    let mut nis = ConsistencyTest::new(3).unwrap();
    for r in runs {
        for &(v, dof) in &pick(r).nis {
            nis.push_with_dof(v, dof).unwrap();
        }
    }
    tests.push(("filter NIS, every update", nis));
    let mut failed = Vec::new();
    for (name, c) in &tests {
        let (lo, hi) = c.interval(0.99).unwrap();
        let mean = c.mean().unwrap();
        let per_dof = c.sum() / c.total_dof() as f64;
        println!(
            "{which} {name}: {} values, mean {mean:.4} (per dof {per_dof:.4}), 99 % interval [{lo:.4}, {hi:.4}]",
            c.runs()
        );
        if !c.contains(0.99).unwrap() {
            failed.push(*name);
        }
    }
    // The smoother's NEES tests mean something only if it smooths: a smoother that returned
    // the filter's estimates would pass them (the filter is consistent at every step).
    let shrink = runs.iter().map(|r| pick(r).shrink).sum::<f64>() / RUNS as f64;
    println!("{which} smoother covariance trace / filter's at step 30: {shrink:.3} (mean)");
    (failed, shrink)
}

#[test]
fn unscented_filter_and_smoother_are_consistent_on_a_coordinated_turn() {
    let (failed, shrink) = check("unscented", |r| &r.unscented);
    assert!(shrink < 0.8, "{shrink}");
    assert!(failed.is_empty(), "outside the 99 % interval: {failed:?}");
}

#[test]
fn extended_filter_and_smoother_are_consistent_on_a_coordinated_turn() {
    let (failed, shrink) = check("extended", |r| &r.extended);
    assert!(shrink < 0.8, "{shrink}");
    assert!(failed.is_empty(), "outside the 99 % interval: {failed:?}");
}
