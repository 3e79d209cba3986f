//! Consistency of the unscented Kalman filter and its smoother by Monte Carlo, on a
//! coordinated-turn target seen by a radar in range, azimuth and elevation, on irregular steps
//! with missing rows and missing components: the mean NEES and mean NIS inside their 99 %
//! chi-squared intervals ([`ConsistencyTest`]).
//!
//! **The model.** The state `(x, y, z, x′, y′, z′, ω)`: a turn at rate `ω` in the horizontal
//! plane, constant vertical velocity (written here as a [`Dynamics`]: the closed-form turn over
//! a step and its analytic `Φ`, which the unscented filter does not use), with
//! additive driving noise `Q(ζ)`: white acceleration of density `q = 0.5 m²/s³` on each axis
//! (the constant-velocity block of `WhiteNoiseDerivative::new(1, 3, q)`) and a random walk of
//! `ω` of density `q_ω = 1e-6 rad²/s³`. The truth is drawn from the same model: each step the
//! turn, then a perturbation drawn exactly from `N(0, Q(ζ))`; so the filter's model is the
//! truth's, and what is tested is the unscented approximation of the nonlinear turn and
//! radar.
//!
//! **The runs.** Each run draws the start from the filter's prior (position σ 100 m at about
//! 25 km, velocity σ 15 m/s about 200 m/s, `ω` σ 0.005 about 0.03 rad/s, i.e. 6 m/s²), 60 steps
//! `U(0.5, 1.5)` s, a radar at the origin with `σ_ρ = 10 m`, `σ_ψ = σ_θ = 2 mrad`; 5 % of rows
//! missing entirely and each component of the others with probability 5 %. The filter starts
//! at the prior's mean and covariance; [`smooth_unscented`] smooths each run.
//!
//! **Independence.** The NEES of one run at successive steps are correlated, so each NEES test
//! takes one value per run at one step (the middle step 30 and the last 59 for the filter;
//! the first step and the middle step for the smoother): `RUNS` independent values each. The
//! filter's innovations are white when its model holds, so every update's NIS goes in, with
//! as many degrees of freedom as components present.
//!
//! Measured (`cargo test --release -p seqsmooth --test kalman_unscented_consistency --
//! --nocapture`, 2,000 runs, 7 s on one core): mean NEES 7.059 and 7.129 for the filter at
//! steps 30 and 59, 7.125 and 7.110 for the smoother at steps 0 and 30, interval
//! [6.786, 7.217]; mean NIS 1.0002 per degree of freedom over 114,123 updates, interval
//! [0.9935, 1.0063] per degree of freedom. The filter given half the driving noise fails every
//! one of them (NEES 10.6-10.9, NIS 1.041 per degree of freedom).

use nalgebra::{DMatrix, DVector};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use seqsmooth::kalman::noise::{ProcessNoise, WhiteNoiseDerivative};
use seqsmooth::kalman::{smooth_unscented, UnscentedKalmanFilter};
use seqsmooth::model::dynamics::{Dynamics, Propagation};
use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
use seqsmooth::model::observation::Observation;
use seqsmooth::model::radar::Radar;
use seqsmooth::stats::consistency::{nees, ConsistencyTest};
use seqsmooth::Error;

const RUNS: usize = 2000;
const STEPS: usize = 60;
const Q: f64 = 0.5;
const Q_OMEGA: f64 = 1e-6;

/// The coordinated turn in `x-y`, constant velocity in `z`, `ω` constant.
#[derive(Clone, Copy, Debug)]
struct CoordinatedTurn;

fn turn(x: &DVector<f64>, zeta: f64) -> DVector<f64> {
    let w = x[6];
    let (s, c) = (w * zeta).sin_cos();
    // sin(ωζ)/ω and (1 − cos ωζ)/ω, with their limits ζ and ωζ²/2 for a small ω.
    let (a, b) = if (w * zeta).abs() < 1e-8 {
        (zeta, w * zeta * zeta / 2.0)
    } else {
        (s / w, (1.0 - c) / w)
    };
    let (vx, vy) = (x[3], x[4]);
    DVector::from_vec(vec![
        x[0] + a * vx - b * vy,
        x[1] + b * vx + a * vy,
        x[2] + zeta * x[5],
        c * vx - s * vy,
        s * vx + c * vy,
        x[5],
        w,
    ])
}

/// `Φ = ∂X(t + ζ)/∂X(t)` of [`turn`], analytic: with `a = sin(ωζ)/ω`, `b = (1 − cos ωζ)/ω`,
/// `∂a/∂ω = (ζ cos ωζ − a)/ω`, `∂b/∂ω = (ζ sin ωζ − b)/ω` (limits `−ωζ³/3` and `ζ²/2`).
fn turn_transition(x: &DVector<f64>, zeta: f64) -> DMatrix<f64> {
    let w = x[6];
    let (s, c) = (w * zeta).sin_cos();
    let (a, b, da, db) = if (w * zeta).abs() < 1e-8 {
        (
            zeta,
            w * zeta * zeta / 2.0,
            -w * zeta.powi(3) / 3.0,
            zeta * zeta / 2.0,
        )
    } else {
        let (a, b) = (s / w, (1.0 - c) / w);
        (a, b, (zeta * c - a) / w, (zeta * s - b) / w)
    };
    let (vx, vy) = (x[3], x[4]);
    let mut phi = DMatrix::identity(7, 7);
    phi[(0, 3)] = a;
    phi[(0, 4)] = -b;
    phi[(0, 6)] = vx * da - vy * db;
    phi[(1, 3)] = b;
    phi[(1, 4)] = a;
    phi[(1, 6)] = vx * db + vy * da;
    phi[(2, 5)] = zeta;
    phi[(3, 3)] = c;
    phi[(3, 4)] = -s;
    phi[(3, 6)] = -zeta * (s * vx + c * vy);
    phi[(4, 3)] = s;
    phi[(4, 4)] = c;
    phi[(4, 6)] = zeta * (c * vx - s * vy);
    phi
}

impl Dynamics for CoordinatedTurn {
    fn dimension(&self) -> usize {
        7
    }

    fn propagate(&self, state: &DVector<f64>, t_a: f64, t_b: f64) -> Result<Propagation, Error> {
        let zeta = t_b - t_a;
        let out = turn(state, zeta);
        let transition = turn_transition(state, zeta);
        match out.iter().chain(transition.iter()).find(|v| !v.is_finite()) {
            Some(&value) => Err(Error::NonFinite {
                what: "propagated state entry",
                value,
            }),
            None => Ok(Propagation {
                state: out,
                transition,
            }),
        }
    }
}

/// The analytic `Φ` is the central difference of the turn (so the model is what it says).
#[test]
fn the_turn_transition_is_its_derivative() {
    for w in [0.03, -0.2, 1e-12] {
        let x = DVector::from_vec(vec![1e3, -2e3, 5e2, -150.0, 130.0, 2.0, w]);
        let zeta = 1.3;
        let phi = turn_transition(&x, zeta);
        for col in 0..7 {
            let h = 1e-6 * x[col].abs().max(1e-3);
            let (mut up, mut down) = (x.clone(), x.clone());
            up[col] += h;
            down[col] -= h;
            let d = (turn(&up, zeta) - turn(&down, zeta)) / (2.0 * h);
            for row in 0..7 {
                let scale = phi[(row, col)].abs().max(1.0);
                assert!(
                    (d[row] - phi[(row, col)]).abs() < 1e-5 * scale,
                    "ω {w}: ({row}, {col}) {} vs {}",
                    d[row],
                    phi[(row, col)]
                );
            }
        }
    }
}

/// `Q(ζ)`: white acceleration on the three axes, a random walk of `ω`.
#[derive(Clone, Copy, Debug)]
struct TurnNoise;

impl ProcessNoise for TurnNoise {
    fn dimension(&self) -> usize {
        7
    }

    fn covariance(&self, t_a: f64, t_b: f64) -> Result<DMatrix<f64>, Error> {
        let cv = WhiteNoiseDerivative::new(1, 3, Q)?.covariance(t_a, t_b)?;
        let mut q = DMatrix::zeros(7, 7);
        q.view_mut((0, 0), (6, 6)).copy_from(&cv);
        q[(6, 6)] = Q_OMEGA * (t_b - t_a).abs();
        Ok(q)
    }
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

/// One run: the filter's NEES at steps 30 and 59, its NIS with their degrees of freedom, the
/// smoother's NEES at steps 0 and 30.
struct Run {
    filter_nees: [f64; 2],
    nis: Vec<(f64, usize)>,
    smoother_nees: [f64; 2],
    /// The smoother's covariance trace over the filter's at step 30.
    shrink: f64,
}

fn run(seed: u64) -> Run {
    let mut r = StdRng::seed_from_u64(seed);
    let (x0, s0) = prior();
    let radar = Radar::new([0.0; 3], 7).unwrap();
    let noise = NoiseCovariance::Variances(vec![100.0, 4e-6, 4e-6]);
    let mut truth = &x0 + gaussian(&mut r, &s0);
    let (mut t, mut truths, mut rows) = (0.0, Vec::new(), Vec::new());
    for _ in 0..STEPS {
        let zeta = r.gen_range(0.5..1.5);
        truth = turn(&truth, zeta) + gaussian(&mut r, &TurnNoise.covariance(t, t + zeta).unwrap());
        t += zeta;
        let seen = radar.predict(&truth, t).unwrap().value;
        let sd = [10.0, 2e-3, 2e-3];
        let whole = r.gen::<f64>() < 0.05;
        let values = (0..3)
            .map(|c| {
                let e: f64 = StandardNormal.sample(&mut r);
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
    let filter = || {
        UnscentedKalmanFilter::new(CoordinatedTurn, radar, x0.clone(), s0.clone(), 0.0)
            .unwrap()
            .with_process_noise(TurnNoise)
            .unwrap()
    };
    let mut f = filter();
    let (mut nis, mut filter_nees) = (Vec::new(), [0.0; 2]);
    for (k, m) in rows.iter().enumerate() {
        if let Some(i) = f.update(m).unwrap() {
            nis.push((i.nis, i.components.len()));
        }
        for (slot, at) in [30, STEPS - 1].into_iter().enumerate() {
            if k == at {
                filter_nees[slot] = nees(f.state(), f.covariance(), &truths[k]).unwrap();
            }
        }
    }
    let smoothed = smooth_unscented(filter(), &rows).unwrap();
    let smoother_nees =
        [0, 30].map(|k| nees(&smoothed[k].state, &smoothed[k].covariance, &truths[k]).unwrap());
    let shrink = smoothed[30].covariance.trace() / smoothed[30].filtered_covariance.trace();
    Run {
        filter_nees,
        nis,
        smoother_nees,
        shrink,
    }
}

#[test]
fn unscented_filter_and_smoother_are_consistent_on_a_coordinated_turn() {
    let runs: Vec<Run> = (0..RUNS as u64)
        .into_par_iter()
        .map(|k| run(0x0ce5_7000 + k))
        .collect();
    let mut tests: Vec<(&str, ConsistencyTest)> = Vec::new();
    for (name, pick) in [
        (
            "filter NEES at step 30",
            (|r: &Run| r.filter_nees[0]) as fn(&Run) -> f64,
        ),
        ("filter NEES at step 59", |r: &Run| r.filter_nees[1]),
        ("smoother NEES at step 0", |r: &Run| r.smoother_nees[0]),
        ("smoother NEES at step 30", |r: &Run| r.smoother_nees[1]),
    ] {
        let mut c = ConsistencyTest::new(7).unwrap();
        for r in &runs {
            c.push(pick(r)).unwrap();
        }
        tests.push((name, c));
    }
    let mut nis = ConsistencyTest::new(3).unwrap();
    for r in &runs {
        for &(v, dof) in &r.nis {
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
            "{name}: {} values, mean {mean:.4} (per dof {per_dof:.4}), 99 % interval [{lo:.4}, {hi:.4}]",
            c.runs()
        );
        if !c.contains(0.99).unwrap() {
            failed.push(*name);
        }
    }
    // The smoother's NEES tests mean something only if it smooths: a smoother that returned
    // the filter's estimates would pass them (the filter is consistent at every step).
    let shrink = runs.iter().map(|r| r.shrink).sum::<f64>() / RUNS as f64;
    println!("smoother covariance trace / filter's at step 30: {shrink:.3} (mean)");
    assert!(shrink < 0.8, "{shrink}");
    assert!(failed.is_empty(), "outside the 99 % interval: {failed:?}");
}
