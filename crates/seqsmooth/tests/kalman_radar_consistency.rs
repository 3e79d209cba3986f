//! Consistency of the window, Kalman, fading and smoothed estimates on simulated radar passes
//! with irregular steps and missing rows, by Monte Carlo: for each
//! method the mean NEES and mean NIS lie inside their 99% chi-squared intervals
//! ([`ConsistencyTest`]) and the 3σ coverage of each state component is at least 97%.
//!
//! **What is simulated.** As in `estimate_gauss_newton_radar.rs`: a radar at the origin
//! measures range, azimuth and elevation with `σ_ρ = 10 m`, `σ_ψ = σ_θ = 1 mrad`; each pass has
//! 80 rows at steps `U(0.5, 1.5)` s; the geometry at the pass's middle is drawn as there
//! (horizontal distance `U(3, 40)` km, altitude `U(0.5, 10)` km, speed `U(100, 300)` m/s, any
//! heading, climb `U(−20, 20)` m/s; redrawn if the path comes within 2 km horizontally of the
//! site or below 100 m). The truth is constant velocity (`PolynomialDynamics::new(1, 3)`)
//! driven by white acceleration of spectral density `q` on each axis: each step's perturbation
//! is drawn exactly from `N(0, Q(ζ))` of `WhiteNoiseDerivative::new(1, 3, q)`, so the Kalman
//! filter's model is the truth's. 5% of rows are missing entirely (every value `None`) and, in
//! the other rows, each component independently with probability 2%.
//!
//! **The methods.** Each run of each method draws its own pass (one seed per method).
//! - *window*: `SlidingFit` (window 20, `Epoch::End`, `Start::Radar` degree 2), its estimate at
//!   each row's time. Its model has no driving noise, so it runs on a `q = 0` truth. (Measured
//!   with this seed: on a `q = 1` truth its mean NEES is ~230 and velocity coverage 61%; at
//!   `q = 0.01` 8.3 and 8.1; at `q = 0.001` the middle row's 6.29 is still outside
//!   `[5.84, 6.16]`: no `q > 0` is "small enough" at this precision, so `q = 0` it is.)
//! - *kalman*: from the first determined window fit (its state, covariance and epoch, the row
//!   at which it was determined: after 2-3 rows), `KalmanFilter` on the same model and the
//!   radar `.with_process_noise(WhiteNoiseDerivative::new(1, 3, 1))`, `update` with each later
//!   row; truth `q = 1` m²/s³ (a velocity random walk of ~9 m/s over a pass).
//! - *fading*: the same start, `.with_fading(Discount::PerTime(0.95))`, no driving noise; it
//!   reports the true covariance of its estimate only when its model holds, so truth `q = 0`.
//!   (Measured on a `q = 1` truth: mean NEES ~3,200 at the middle row, ~25,000 at the last.)
//! - *smooth*: `kalman::smooth` of the Kalman filter above (same start, same driving noise)
//!   over every row after the start; truth `q = 1`.
//!
//! **Independence.** The NEES of one run at successive times are correlated (the window fits
//! overlap; the filters carry their memory), so the interval `χ²(6N)/N` of a mean over all
//! times would be too narrow. Each NEES test takes one value per run at one row, so its `N`
//! values are independent: the middle row (40) and the last (79) for window, kalman and
//! fading; for the smoother the first row after the start and the middle row (at the last row
//! the smoothed estimate is the filtered one, checked equal). Two rows give two tests, each
//! over independent runs. The mean NEES over every time is printed, not tested.
//!
//! NIS: the Kalman filter's innovations are independent across updates when its model holds,
//! so every update's NIS goes in, with as many degrees of freedom as components present
//! (`push_with_dof`). The smoother has no innovations of its own: its NIS are its forward
//! pass's, which is the Kalman filter (checked: the forward states equal those of a separate
//! `KalmanFilter` run bit for bit, and each row's NIS equals that run's `Innovation::nis`), so
//! its test is on every forward update's NIS, from that run's `Innovation`s. The fading filter
//! is not optimal, so its innovations are not white: each NIS is `χ²(p)` (its `V` is
//! `M S Mᵀ + R` with the true `S`), but their sum is not `χ²` of the summed degrees of
//! freedom; it takes one NIS per run at each of two rows (the first row with a component at or
//! after the middle, and the last such row: chosen by the missing pattern, independent of the
//! values). The window fit has no innovation; its NIS is that of the one-step prediction of the
//! previous window (which does not hold the row): `ν = Y − G(Φ X)`, `V = M Φ S Φᵀ Mᵀ + R`, at
//! the same two rows.
//!
//! Coverage (`|e_i| ≤ 3 √S_ii`) is counted over every estimate after the start (a proportion:
//! the correlation in time does not bias it). It is the weaker test: a Kalman filter given half
//! the truth's `q` has mean NEES ~8.8 and NIS 3.15 (both far outside) but coverage still ≥ 98%.
//!
//! **Tolerances.** 99% two-sided intervals from `ConsistencyTest::interval` (for 3000 NEES of
//! 6 states `[5.838, 6.164]`; for the Kalman filter's ~222,000 NIS of ~652,000 dof
//! `[2.927, 2.954]` against 2.941 dof per update); coverage ≥ 97% against a nominal 99.73%. The
//! seeds are fixed, so the test is deterministic; with 14 interval tests at 99% a different
//! seed would fail one by chance with probability ~13%.
//!
//! **Measured** (release, 3000 runs per method, one thread; at least 1000 are asked):
//!
//! | method | NEES (rows) | NIS | 3σ coverage | time |
//! |---|---|---|---|---|
//! | window | 5.918, 6.049 (middle, last) | 2.860, 3.015 (middle, last; ~2.94 dof) | 99.72-99.76% | 7.8 s |
//! | kalman | 6.030, 5.978 (middle, last) | 2.9441 every update (2.941 dof) | 99.73-99.77% | 0.9 s |
//! | fading | 6.056, 5.946 (middle, last) | 2.965, 2.925 (middle, last) | 99.71-99.75% | 1.4 s |
//! | smooth | 5.981, 6.002 (first, middle) | 2.9358 every forward update | 99.71-99.74% | 2.0 s |
//!
//! The starts (2-3 rows, nearly or exactly determined) have mean NEES 5.96-6.06. The whole
//! file: 12.4 s with the default test threads, 12.1-13.6 s on one thread (a shared two-core
//! machine; the per-method times above vary by ~20% between runs).

use nalgebra::{Cholesky, DMatrix, DVector};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal, StandardNormal};
use seqsmooth::estimate::gauss_newton::{Correction, Epoch, Measurement};
use seqsmooth::estimate::sliding::{SlidingFit, Start};
use seqsmooth::kalman::noise::{ProcessNoise, WhiteNoiseDerivative};
use seqsmooth::kalman::{smooth, Discount, KalmanFilter};
use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
use seqsmooth::model::measurement::NoiseCovariance;
use seqsmooth::model::observation::Observation;
use seqsmooth::model::radar::{wrap, Radar};
use seqsmooth::stats::consistency::{nees, ConsistencyTest};
use std::f64::consts::{PI, TAU};

const RUNS: usize = 3000;
const ROWS: usize = 80;
const MIDDLE: usize = ROWS / 2;
const LAST: usize = ROWS - 1;
const WINDOW: usize = 20;
const SIGMA_RANGE: f64 = 10.0;
const SIGMA_ANGLE: f64 = 1e-3;
/// The truth's white-noise acceleration PSD on each axis for the Kalman filter and smoother,
/// m²/s³.
const Q: f64 = 1.0;
/// The fading filter's discount per second.
const BETA: f64 = 0.95;
const MISSING_ROW: f64 = 0.05;
const MISSING_COMPONENT: f64 = 0.02;
const CONFIDENCE: f64 = 0.99;
const MIN_COVERAGE: f64 = 0.97;

/// One simulated pass: the rows (measurements) and the true state at each row's time.
struct Pass {
    rows: Vec<Measurement>,
    truth: Vec<DVector<f64>>,
}

fn noise() -> NoiseCovariance {
    NoiseCovariance::Variances(vec![
        SIGMA_RANGE * SIGMA_RANGE,
        SIGMA_ANGLE * SIGMA_ANGLE,
        SIGMA_ANGLE * SIGMA_ANGLE,
    ])
}

/// A pass of `ROWS` rows at steps `U(0.5, 1.5)` s; the truth is constant velocity driven by
/// white acceleration of PSD `q` per axis, each step's perturbation drawn from `N(0, Q(ζ))` of
/// `WhiteNoiseDerivative::new(1, 3, q)` (exact: the filter's own model).
fn simulate(r: &mut StdRng, q: f64) -> Pass {
    let dynamics = PolynomialDynamics::new(1, 3);
    let driving = WhiteNoiseDerivative::new(1, 3, q).unwrap();
    let mut times = Vec::with_capacity(ROWS);
    let mut t = r.gen_range(0.0..1000.0);
    for _ in 0..ROWS {
        times.push(t);
        t += r.gen_range(0.5..1.5);
    }
    let (t0, mid) = (times[0], 0.5 * (times[0] + times[ROWS - 1]));
    let truth = loop {
        let d = r.gen_range(3_000.0..40_000.0);
        let psi = r.gen_range(-PI..PI);
        let z = r.gen_range(500.0..10_000.0);
        let speed = r.gen_range(100.0..300.0);
        let heading = psi + r.gen_range(0.0..TAU);
        let climb = r.gen_range(-20.0..20.0);
        let v = [speed * heading.cos(), speed * heading.sin(), climb];
        let back = t0 - mid;
        let mut x = DVector::from_vec(vec![
            d * psi.cos() + v[0] * back,
            d * psi.sin() + v[1] * back,
            z + v[2] * back,
            v[0],
            v[1],
            v[2],
        ]);
        let mut states = Vec::with_capacity(ROWS);
        states.push(x.clone());
        for k in 1..ROWS {
            x = dynamics
                .propagate(&x, times[k - 1], times[k])
                .unwrap()
                .state;
            if q > 0.0 {
                let l = Cholesky::new(driving.covariance(times[k - 1], times[k]).unwrap())
                    .unwrap()
                    .unpack();
                let w = DVector::from_fn(6, |_, _| r.sample::<f64, _>(StandardNormal));
                x += l * w;
            }
            states.push(x.clone());
        }
        let ok = states
            .iter()
            .all(|s| s[0].hypot(s[1]) >= 2_000.0 && s[2] >= 100.0);
        if ok {
            break states;
        }
    };
    let range_noise = Normal::new(0.0, SIGMA_RANGE).unwrap();
    let angle_noise = Normal::new(0.0, SIGMA_ANGLE).unwrap();
    let rows = times
        .iter()
        .zip(&truth)
        .map(|(&time, s)| {
            let h = s[0].hypot(s[1]);
            let clean = [
                h.hypot(s[2]) + range_noise.sample(r),
                wrap(s[1].atan2(s[0]) + angle_noise.sample(r)),
                s[2].atan2(h) + angle_noise.sample(r),
            ];
            let row_missing = r.gen_bool(MISSING_ROW);
            let values = clean
                .iter()
                .map(|&v| (!row_missing && !r.gen_bool(MISSING_COMPONENT)).then_some(v))
                .collect();
            Measurement {
                time,
                values,
                noise: noise(),
            }
        })
        .collect();
    Pass { rows, truth }
}

/// NEES and 3σ coverage of the estimates of one method.
struct Tally {
    name: &'static str,
    /// One NEES per run at each of two well-separated rows (labels, tests).
    nees: [(&'static str, ConsistencyTest); 2],
    /// NIS: all updates (Kalman) or one per run at each of two rows.
    nis: Vec<(&'static str, ConsistencyTest)>,
    /// Every estimate after the start: NEES sum and count (diagnostic: correlated in time).
    all_nees: (f64, usize),
    inside: [usize; 6],
    /// The start's NEES (the first determined window fit), sum and count.
    start_nees: (f64, usize),
}

impl Tally {
    fn new(name: &'static str, at: [&'static str; 2], nis: &[&'static str]) -> Self {
        Self {
            name,
            nees: at.map(|a| (a, ConsistencyTest::new(6).unwrap())),
            nis: nis
                .iter()
                .map(|&a| (a, ConsistencyTest::new(3).unwrap()))
                .collect(),
            all_nees: (0.0, 0),
            inside: [0; 6],
            start_nees: (0.0, 0),
        }
    }

    /// An estimate at a row: its NEES, coverage; returns the NEES.
    fn estimate(&mut self, x: &DVector<f64>, s: &DMatrix<f64>, truth: &DVector<f64>) -> f64 {
        let v = nees(x, s, truth).unwrap_or_else(|e| panic!("{}: NEES: {e}", self.name));
        self.all_nees.0 += v;
        self.all_nees.1 += 1;
        for i in 0..6 {
            if (x[i] - truth[i]).abs() <= 3.0 * s[(i, i)].sqrt() {
                self.inside[i] += 1;
            }
        }
        v
    }

    fn report_and_check(&self, elapsed: f64) {
        println!("{}: {RUNS} runs in {elapsed:.2} s", self.name);
        let (s, n) = self.start_nees;
        println!(
            "  start (first determined window fit): NEES mean {:.4} over {n}",
            s / n as f64
        );
        let mut failures = Vec::new();
        let tests = self.nees.iter().map(|(l, t)| ("NEES", l, t));
        for (what, label, t) in tests.chain(self.nis.iter().map(|(l, t)| ("NIS", l, t))) {
            let (lo, hi) = t.interval(CONFIDENCE).unwrap();
            let mean = t.mean().unwrap();
            let dof_per = t.total_dof() as f64 / t.runs() as f64;
            println!(
                "  {what} {label}: mean {mean:.4} in [{lo:.4}, {hi:.4}] ({} values, {} dof, \
                 {dof_per:.3} per value)",
                t.runs(),
                t.total_dof()
            );
            if !t.contains(CONFIDENCE).unwrap() {
                failures.push(format!("{what} {label} mean {mean} outside [{lo}, {hi}]"));
            }
        }
        let (s, n) = self.all_nees;
        println!(
            "  NEES over every estimate (correlated in time, not tested): mean {:.4} over {n}",
            s / n as f64
        );
        let coverage = self.inside.map(|c| c as f64 / n as f64);
        println!("  3σ coverage (x, y, z, ẋ, ẏ, ż) over {n}: {coverage:.4?}");
        for (i, c) in coverage.iter().enumerate() {
            if *c < MIN_COVERAGE {
                failures.push(format!("3σ coverage of component {i} is {c}"));
            }
        }
        assert!(failures.is_empty(), "{}: {failures:#?}", self.name);
    }
}

fn sliding_fit(radar: Radar) -> SlidingFit<PolynomialDynamics, Radar> {
    SlidingFit::new(
        PolynomialDynamics::new(1, 3),
        radar,
        WINDOW,
        Epoch::End,
        Start::Radar { radar, degree: 2 },
    )
    .unwrap()
}

/// The first determined window fit: its row's index and the correction (epoch that row's time).
fn start(radar: Radar, pass: &Pass) -> (usize, Correction) {
    let mut fit = sliding_fit(radar);
    for (k, row) in pass.rows.iter().enumerate() {
        if let Some(c) = fit.push(row.clone()).unwrap() {
            assert_eq!(c.epoch, row.time);
            return (k, c);
        }
    }
    panic!("no window fit determined the state");
}

/// The rows whose NIS is tested when one per run is taken: the first row at or after the middle
/// with a component present, and the last such row (chosen by the missing pattern alone, which
/// is independent of the measured values).
fn nis_rows(pass: &Pass) -> [usize; 2] {
    let present = |k: &usize| pass.rows[*k].values.iter().any(Option::is_some);
    [
        (MIDDLE..ROWS).find(present).unwrap(),
        (MIDDLE..ROWS).rev().find(present).unwrap(),
    ]
}

/// `νᵀ V⁻¹ ν` of a measurement's present components against the prediction `x` with
/// covariance `s`, `V = M S Mᵀ + R`.
fn nis_of(radar: &Radar, row: &Measurement, x: &DVector<f64>, s: &DMatrix<f64>) -> (f64, usize) {
    let predicted = radar.predict(x, row.time).unwrap();
    let present: Vec<usize> = (0..3).filter(|&i| row.values[i].is_some()).collect();
    let k = present.len();
    let r = [
        SIGMA_RANGE * SIGMA_RANGE,
        SIGMA_ANGLE * SIGMA_ANGLE,
        SIGMA_ANGLE * SIGMA_ANGLE,
    ];
    let m = DMatrix::from_fn(k, 6, |i, j| predicted.jacobian[(present[i], j)]);
    let v =
        &m * s * m.transpose() + DMatrix::from_diagonal(&DVector::from_fn(k, |i, _| r[present[i]]));
    let nu = DVector::from_fn(k, |i, _| {
        radar.residual(
            present[i],
            row.values[present[i]].unwrap(),
            predicted.value[present[i]],
        )
    });
    let chol = Cholesky::new(v).unwrap();
    (nu.dot(&chol.solve(&nu)), k)
}

#[test]
fn window_fit_is_consistent_on_a_constant_velocity_truth() {
    let started = std::time::Instant::now();
    let mut r = StdRng::seed_from_u64(0x5eed_1261);
    let radar = Radar::new([0.0; 3], 6).unwrap();
    let dynamics = PolynomialDynamics::new(1, 3);
    let mut tally = Tally::new(
        "window (SlidingFit, W = 20, q = 0 truth)",
        ["at the middle row", "at the last row"],
        &["at the middle row", "at the last row"],
    );
    for _ in 0..RUNS {
        let pass = simulate(&mut r, 0.0);
        let nis_at = nis_rows(&pass);
        let mut fit = sliding_fit(radar);
        let mut previous: Option<Correction> = None;
        for (k, row) in pass.rows.iter().enumerate() {
            if let (Some(j), Some(p)) = (nis_at.iter().position(|&a| a == k), &previous) {
                // The one-step prediction of the previous window, which does not hold this row.
                let carried = dynamics.propagate(&p.state, p.epoch, row.time).unwrap();
                let phi = &carried.transition;
                let s = phi * &p.covariance * phi.transpose();
                let (v, dof) = nis_of(&radar, row, &carried.state, &s);
                tally.nis[j].1.push_with_dof(v, dof).unwrap();
            }
            let c = fit.push(row.clone()).unwrap();
            match &c {
                Some(c) => {
                    assert_eq!(c.epoch, row.time);
                    let v = tally.estimate(&c.state, &c.covariance, &pass.truth[k]);
                    if previous.is_none() {
                        tally.start_nees.0 += v;
                        tally.start_nees.1 += 1;
                    }
                    if k == MIDDLE {
                        tally.nees[0].1.push(v).unwrap();
                    } else if k == LAST {
                        tally.nees[1].1.push(v).unwrap();
                    }
                }
                None => assert!(
                    previous.is_none(),
                    "a determined window became undetermined"
                ),
            }
            if c.is_some() {
                previous = c;
            }
        }
    }
    tally.report_and_check(started.elapsed().as_secs_f64());
}

/// A Kalman filter on the constant-velocity model and the radar from a window fit.
fn filter_from(radar: Radar, c: &Correction) -> KalmanFilter<PolynomialDynamics, Radar> {
    KalmanFilter::new(
        PolynomialDynamics::new(1, 3),
        radar,
        c.state.clone(),
        c.covariance.clone(),
        c.epoch,
    )
    .unwrap()
}

fn driven(radar: Radar, c: &Correction) -> KalmanFilter<PolynomialDynamics, Radar> {
    filter_from(radar, c)
        .with_process_noise(WhiteNoiseDerivative::new(1, 3, Q).unwrap())
        .unwrap()
}

#[test]
fn kalman_filter_is_consistent_on_a_driven_truth() {
    let started = std::time::Instant::now();
    let mut r = StdRng::seed_from_u64(0x5eed_1262);
    let radar = Radar::new([0.0; 3], 6).unwrap();
    let mut tally = Tally::new(
        "kalman (driving noise q = 1 m²/s³, truth q = 1)",
        ["at the middle row", "at the last row"],
        &["of every update"],
    );
    for _ in 0..RUNS {
        let pass = simulate(&mut r, Q);
        let (k0, c) = start(radar, &pass);
        assert!(k0 < MIDDLE);
        let v = nees(&c.state, &c.covariance, &pass.truth[k0]).unwrap();
        tally.start_nees.0 += v;
        tally.start_nees.1 += 1;
        let mut f = driven(radar, &c);
        for k in k0 + 1..ROWS {
            if let Some(i) = f.update(&pass.rows[k]).unwrap() {
                tally.nis[0]
                    .1
                    .push_with_dof(i.nis, i.components.len())
                    .unwrap();
            }
            let v = tally.estimate(f.state(), f.covariance(), &pass.truth[k]);
            if k == MIDDLE {
                tally.nees[0].1.push(v).unwrap();
            } else if k == LAST {
                tally.nees[1].1.push(v).unwrap();
            }
        }
    }
    tally.report_and_check(started.elapsed().as_secs_f64());
}

#[test]
fn fading_filter_is_consistent_on_a_constant_velocity_truth() {
    let started = std::time::Instant::now();
    let mut r = StdRng::seed_from_u64(0x5eed_1263);
    let radar = Radar::new([0.0; 3], 6).unwrap();
    let mut tally = Tally::new(
        "fading (β = 0.95 per s, no driving noise, truth q = 0)",
        ["at the middle row", "at the last row"],
        &["at the middle row", "at the last row"],
    );
    let mut every_update = ConsistencyTest::new(3).unwrap();
    for _ in 0..RUNS {
        let pass = simulate(&mut r, 0.0);
        let nis_at = nis_rows(&pass);
        let (k0, c) = start(radar, &pass);
        assert!(k0 < MIDDLE);
        let v = nees(&c.state, &c.covariance, &pass.truth[k0]).unwrap();
        tally.start_nees.0 += v;
        tally.start_nees.1 += 1;
        let mut f = filter_from(radar, &c)
            .with_fading(Discount::PerTime(BETA))
            .unwrap();
        for k in k0 + 1..ROWS {
            if let Some(i) = f.update(&pass.rows[k]).unwrap() {
                let dof = i.components.len();
                every_update.push_with_dof(i.nis, dof).unwrap();
                if let Some(j) = nis_at.iter().position(|&a| a == k) {
                    tally.nis[j].1.push_with_dof(i.nis, dof).unwrap();
                }
            }
            let v = tally.estimate(f.state(), f.covariance(), &pass.truth[k]);
            if k == MIDDLE {
                tally.nees[0].1.push(v).unwrap();
            } else if k == LAST {
                tally.nees[1].1.push(v).unwrap();
            }
        }
    }
    let (lo, hi) = every_update.interval(CONFIDENCE).unwrap();
    println!(
        "  (NIS of every update, correlated: the fading filter is not optimal, so its innovations \
         are not white; not tested: mean {:.4}, the independent-values interval [{lo:.4}, {hi:.4}])",
        every_update.mean().unwrap()
    );
    tally.report_and_check(started.elapsed().as_secs_f64());
}

#[test]
fn smoother_is_consistent_on_a_driven_truth() {
    let started = std::time::Instant::now();
    let mut r = StdRng::seed_from_u64(0x5eed_1264);
    let radar = Radar::new([0.0; 3], 6).unwrap();
    let mut tally = Tally::new(
        "smooth (RTS, driving noise q = 1 m²/s³, truth q = 1)",
        ["at the first row after the start", "at the middle row"],
        &["of every forward update"],
    );
    let mut worst_forward: f64 = 0.0;
    for _ in 0..RUNS {
        let pass = simulate(&mut r, Q);
        let (k0, c) = start(radar, &pass);
        assert!(k0 + 1 < MIDDLE);
        let v = nees(&c.state, &c.covariance, &pass.truth[k0]).unwrap();
        tally.start_nees.0 += v;
        tally.start_nees.1 += 1;
        let rows = &pass.rows[k0 + 1..];
        let smoothed = smooth(driven(radar, &c), rows).unwrap();
        // The smoother has no NIS of its own: its forward pass is the Kalman filter, whose
        // innovations (with their degrees of freedom) are taken from that filter, checked equal.
        let mut forward = driven(radar, &c);
        for (j, (row, s)) in rows.iter().zip(&smoothed).enumerate() {
            let k = k0 + 1 + j;
            let i = forward.update(row).unwrap();
            assert_eq!(i.as_ref().map(|i| i.nis), s.nis);
            if let Some(i) = i {
                tally.nis[0]
                    .1
                    .push_with_dof(i.nis, i.components.len())
                    .unwrap();
            }
            let scale = forward.state().amax();
            worst_forward = worst_forward.max((forward.state() - &s.filtered_state).amax() / scale);
            let v = tally.estimate(&s.state, &s.covariance, &pass.truth[k]);
            if k == k0 + 1 {
                tally.nees[0].1.push(v).unwrap();
            } else if k == MIDDLE {
                tally.nees[1].1.push(v).unwrap();
            }
        }
        let last = smoothed.last().unwrap();
        assert_eq!(last.state, last.filtered_state);
    }
    println!(
        "  the smoother's forward states equal the Kalman filter's within {worst_forward:.1e}"
    );
    assert!(worst_forward == 0.0);
    tally.report_and_check(started.elapsed().as_secs_f64());
}
