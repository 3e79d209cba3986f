//! `kalman::unscented` and `kalman::unscented_smoother` against filterpy 2.0.0's
//! `UnscentedKalmanFilter` with `MerweScaledSigmaPoints` and its unscented RTS smoother
//! (`rts_smoother`) on stored fixtures, and against this crate's Kalman filter and RTS
//! smoother on a linear model (where the unscented filter is the Kalman filter: a second
//! oracle). The fixtures and the script that made them: tests/fixtures/unscented/
//! (`linear.csv`, `radar.csv`) and scripts/make_unscented_fixtures.py (versions and seed in each
//! file's first line).
//!
//! - `linear`: constant velocity on two axes observed in both positions with a full `R`
//!   (4 states, 2 components), `α = 0.5, β = 2, κ = 1` (a negative central weight);
//! - `radar`: constant velocity on three axes seen by a radar in range, azimuth and elevation
//!   (6 states, 3 components), the target crossing azimuth `π` (wrapped residuals), `α = 1,
//!   β = 2, κ = 0` (the library's default);
//!
//! each 150 steps `U(0.3, 1.7)` with driving noise, whole rows and single components missing.
//! Compared at every step, as `kalman_filterpy.rs` does: each state component `i` relative to
//! `max(|x_i|, σ_i)` and each covariance entry relative to `σ_i σ_j` (filterpy's `x` and
//! `σ_i = √P_ii`), the NIS relative to `max(NIS, 1)`; the filter after each update and the
//! smoother at every step; all within 1e-10.

use nalgebra::{DMatrix, DVector};
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::kalman::sigma_points::SigmaPoints;
use seqsmooth::kalman::{smooth, smooth_unscented, KalmanFilter, UnscentedKalmanFilter};
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
use seqsmooth::model::observation::{LinearObservation, Observation};
use seqsmooth::model::radar::Radar;
use seqsmooth::{Error, Param};
use std::collections::BTreeMap;

const TOL: f64 = 1e-10;

/// One fixture: its setup (`# key,values` lines) and its rows.
struct Fixture {
    setup: BTreeMap<String, Vec<f64>>,
    rows: Vec<Vec<f64>>,
}

fn read(name: &str) -> Fixture {
    let path = format!(
        "{}/tests/fixtures/unscented/{name}.csv",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let (mut setup, mut header, mut rows) = (BTreeMap::new(), Vec::<String>::new(), Vec::new());
    for line in text.lines() {
        if let Some(comment) = line.strip_prefix('#') {
            let mut cells = comment.trim().split(',');
            let key = cells.next().unwrap().to_string();
            if let Ok(values) = cells.map(str::parse::<f64>).collect::<Result<Vec<_>, _>>() {
                setup.insert(key, values);
            }
        } else if header.is_empty() {
            header = line.split(',').map(String::from).collect();
        } else {
            let row: Vec<f64> = line.split(',').map(|c| c.parse().unwrap()).collect();
            assert_eq!(row.len(), header.len(), "{path}: {line}");
            rows.push(row);
        }
    }
    Fixture { setup, rows }
}

/// A fixture's setup as the library's pieces.
struct Setup {
    n: usize,
    p: usize,
    dynamics: PolynomialDynamics,
    noise: WhiteNoiseDerivative,
    x0: DVector<f64>,
    p0: DMatrix<f64>,
    t0: f64,
    r: DMatrix<f64>,
    points: SigmaPoints,
}

fn setup(fx: &Fixture) -> Setup {
    let one = |k: &str| fx.setup[k][0];
    let (m, d) = (one("degree") as usize, one("axes") as usize);
    let n = (m + 1) * d;
    let r = &fx.setup["R"];
    let p = (r.len() as f64).sqrt() as usize;
    let sigma = &fx.setup["sigma"];
    Setup {
        n,
        p,
        dynamics: PolynomialDynamics::new(m, d),
        noise: WhiteNoiseDerivative::new(m, d, one("q")).unwrap(),
        x0: DVector::from_column_slice(&fx.setup["x0"]),
        p0: DMatrix::from_row_slice(n, n, &fx.setup["P0"]),
        t0: one("t0"),
        r: DMatrix::from_row_slice(p, p, r),
        points: SigmaPoints::new(sigma[0], sigma[1], sigma[2]).unwrap(),
    }
}

fn measurements(fx: &Fixture, s: &Setup) -> Vec<Measurement> {
    fx.rows
        .iter()
        .map(|row| Measurement {
            time: row[0],
            values: row[1..1 + s.p]
                .iter()
                .map(|&v| (!v.is_nan()).then_some(v))
                .collect(),
            noise: NoiseCovariance::Full(s.r.clone()),
        })
        .collect()
}

fn ukf<O: Observation>(s: &Setup, observation: O) -> UnscentedKalmanFilter<PolynomialDynamics, O> {
    UnscentedKalmanFilter::new(s.dynamics, observation, s.x0.clone(), s.p0.clone(), s.t0)
        .unwrap()
        .with_sigma_points(s.points)
        .unwrap()
        .with_process_noise(s.noise)
        .unwrap()
}

/// The worst relative difference of states and covariances (`x` relative to `max(|x_i|, σ_i)`,
/// `P` relative to `σ_i σ_j`, with `want`'s `x` and `σ`).
fn worst(
    got_x: &DVector<f64>,
    got_s: &DMatrix<f64>,
    want_x: &[f64],
    want_s: &DMatrix<f64>,
) -> (f64, f64) {
    let n = want_x.len();
    let sigma: Vec<f64> = (0..n).map(|i| want_s[(i, i)].sqrt()).collect();
    let x = (0..n)
        .map(|i| (got_x[i] - want_x[i]).abs() / want_x[i].abs().max(sigma[i]))
        .fold(0.0, f64::max);
    let s = (0..n * n)
        .map(|k| {
            let (i, j) = (k % n, k / n);
            (got_s[(i, j)] - want_s[(i, j)]).abs() / (sigma[i] * sigma[j])
        })
        .fold(0.0, f64::max);
    (x, s)
}

/// Runs the unscented filter and smoother on a fixture; the worst differences from filterpy:
/// (filter state, filter covariance, NIS, smoother state, smoother covariance).
fn against_filterpy<O: Observation + Clone>(name: &str, observation: O) -> [f64; 5] {
    let fx = read(name);
    let s = setup(&fx);
    let (n, p) = (s.n, s.p);
    let rows = measurements(&fx, &s);
    let mut filter = ukf(&s, observation.clone());
    let mut out = [0.0_f64; 5];
    let (mut updates, mut partial) = (0, 0);
    for (step, (row, m)) in fx.rows.iter().zip(&rows).enumerate() {
        let update = filter.update(m).unwrap();
        let want_nis = row[1 + p + n + n * n];
        assert_eq!(update.is_none(), want_nis.is_nan(), "{name} step {step}");
        if let Some(i) = &update {
            updates += 1;
            partial += (i.components.len() < p) as usize;
            out[2] = out[2].max((i.nis - want_nis).abs() / want_nis.max(1.0));
        }
        let want_x = &row[1 + p..1 + p + n];
        let want_s = DMatrix::from_row_slice(n, n, &row[1 + p + n..1 + p + n + n * n]);
        let (x, c) = worst(filter.state(), filter.covariance(), want_x, &want_s);
        out[0] = out[0].max(x);
        out[1] = out[1].max(c);
    }
    assert!(
        updates > 100 && partial > 5,
        "{name}: {updates} updates, {partial} partial"
    );
    let smoothed = smooth_unscented(ukf(&s, observation), &rows).unwrap();
    assert_eq!(smoothed.len(), fx.rows.len());
    for (row, sm) in fx.rows.iter().zip(&smoothed) {
        let base = 2 + p + n + n * n;
        let want_x = &row[base..base + n];
        let want_s = DMatrix::from_row_slice(n, n, &row[base + n..base + n + n * n]);
        let (x, c) = worst(&sm.state, &sm.covariance, want_x, &want_s);
        out[3] = out[3].max(x);
        out[4] = out[4].max(c);
    }
    println!(
        "{name}: filter x {:.1e} P {:.1e} NIS {:.1e}; smoother x {:.1e} P {:.1e}",
        out[0], out[1], out[2], out[3], out[4]
    );
    out
}

fn positions(p: usize, n: usize) -> LinearObservation {
    LinearObservation::new(DMatrix::from_fn(p, n, |i, j| f64::from(u8::from(i == j)))).unwrap()
}

#[test]
fn linear_model_matches_filterpy() {
    let worst = against_filterpy("linear", positions(2, 4));
    assert!(worst.iter().all(|&w| w <= TOL), "{worst:?}");
}

#[test]
fn radar_through_azimuth_pi_matches_filterpy() {
    let fx = read("radar");
    let site = &fx.setup["site"];
    let radar = Radar::new([site[0], site[1], site[2]], 6).unwrap();
    let worst = against_filterpy("radar", radar);
    assert!(worst.iter().all(|&w| w <= TOL), "{worst:?}");
}

/// On a linear model the unscented transform is exact: the unscented filter and smoother are
/// the Kalman filter and the RTS smoother (this crate's, Joseph form and Cholesky gain).
#[test]
fn linear_model_is_the_kalman_filter_and_its_smoother() {
    let fx = read("linear");
    let s = setup(&fx);
    let rows = measurements(&fx, &s);
    let kalman = || {
        KalmanFilter::new(
            s.dynamics,
            positions(2, 4),
            s.x0.clone(),
            s.p0.clone(),
            s.t0,
        )
        .unwrap()
        .with_process_noise(s.noise)
        .unwrap()
    };
    let (mut k, mut u) = (kalman(), ukf(&s, positions(2, 4)));
    let mut most = [0.0_f64; 3];
    for m in &rows {
        let (a, b) = (k.update(m).unwrap(), u.update(m).unwrap());
        let want = k.state().as_slice().to_vec();
        let (x, c) = worst(u.state(), u.covariance(), &want, k.covariance());
        most[0] = most[0].max(x);
        most[1] = most[1].max(c);
        if let (Some(a), Some(b)) = (a, b) {
            most[2] = most[2].max((a.nis - b.nis).abs() / a.nis.max(1.0));
        }
    }
    let (ks, us) = (
        smooth(kalman(), &rows).unwrap(),
        smooth_unscented(ukf(&s, positions(2, 4)), &rows).unwrap(),
    );
    let mut smoothed = [0.0_f64; 2];
    for (a, b) in ks.iter().zip(&us) {
        let (x, c) = worst(&b.state, &b.covariance, a.state.as_slice(), &a.covariance);
        smoothed[0] = smoothed[0].max(x);
        smoothed[1] = smoothed[1].max(c);
        assert_eq!(a.nis.is_some(), b.nis.is_some());
    }
    println!("against the Kalman filter: {most:?}, smoother {smoothed:?}");
    assert!(
        most.iter().chain(&smoothed).all(|&w| w <= TOL),
        "{most:?} {smoothed:?}"
    );
}

/// A covariance that has no Cholesky factor is refused with its sample's index, the filter
/// unchanged: a prior made singular by a perfect measurement of every state.
#[test]
fn a_covariance_without_sigma_points_is_refused_naming_its_sample() {
    let f = UnscentedKalmanFilter::new(
        PolynomialDynamics::new(0, 1),
        LinearObservation::value_of(1),
        DVector::zeros(1),
        DMatrix::identity(1, 1),
        0.0,
    )
    .unwrap();
    let row = |t: f64, variance: f64| Measurement {
        time: t,
        values: vec![Some(1.0)],
        noise: NoiseCovariance::Variances(vec![variance]),
    };
    // A perfect measurement would leave S = 0, a covariance without sigma points: the update
    // that makes it is refused (not the next one), and the filter keeps the row before.
    let rows = [row(1.0, 1.0), row(2.0, 0.0), row(3.0, 1.0)];
    let e = smooth_unscented(f.clone(), &rows).unwrap_err();
    match e {
        Error::InBatch { index: 1, source } => assert!(
            matches!(
                *source,
                Error::InvalidParameter {
                    name: Param::Covariance,
                    ..
                }
            ),
            "{source:?}"
        ),
        other => panic!("{other:?}"),
    }
    let mut g = f;
    g.update(&rows[0]).unwrap();
    let before = (g.state().clone(), g.covariance().clone(), g.time());
    assert!(g.update(&rows[1]).is_err());
    assert_eq!(
        (g.state().clone(), g.covariance().clone(), g.time()),
        before
    );
    // It goes on from there with the next row.
    g.update(&rows[2]).unwrap();
}

/// Non-finite input is refused and nothing non-finite comes out: a NaN measurement, an
/// infinite noise variance, a prediction that overflows.
#[test]
fn non_finite_input_and_output_are_refused() {
    let mut f = UnscentedKalmanFilter::new(
        PolynomialDynamics::new(1, 1),
        LinearObservation::value_of(2),
        DVector::from_vec(vec![0.0, 1e300]),
        DMatrix::identity(2, 2),
        0.0,
    )
    .unwrap();
    let m = |t: f64, v: f64, r: f64| Measurement {
        time: t,
        values: vec![Some(v)],
        noise: NoiseCovariance::Variances(vec![r]),
    };
    assert!(matches!(
        f.update(&m(1.0, f64::NAN, 1.0)),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        f.update(&m(1.0, 1.0, f64::INFINITY)),
        Err(Error::NonFinite { .. })
    ));
    assert!(f.update(&m(1e10, 1.0, 1.0)).is_err()); // x + ζ v overflows
    assert_eq!(f.time(), 0.0);
    assert!(f
        .state()
        .iter()
        .chain(f.covariance().iter())
        .all(|v| v.is_finite()));
}

/// The smoother's last row is the filter's, its gains are those of the backward pass, and the
/// smoothed covariance is no larger than the filtered one (the smoother uses more data).
#[test]
fn smoother_rows_hold_their_parts() {
    let fx = read("radar");
    let s = setup(&fx);
    let site = &fx.setup["site"];
    let radar = Radar::new([site[0], site[1], site[2]], 6).unwrap();
    let rows = measurements(&fx, &s);
    let out = smooth_unscented(ukf(&s, radar), &rows).unwrap();
    let last = out.last().unwrap();
    assert_eq!(last.state, last.filtered_state);
    assert!(last.gain.is_none() && out[0].gain.is_some());
    for r in &out {
        for i in 0..6 {
            assert!(r.covariance[(i, i)] <= r.filtered_covariance[(i, i)] * (1.0 + 1e-12));
        }
    }
}

/// Sigma points with a negative central covariance weight (α 0.2, β −1, κ −3 on six states:
/// W₀ᶜ = −49.04) can make the updated covariance indefinite: the update is refused, naming the
/// weight, and the filter keeps its estimate — never a covariance whose σ would read as zero.
/// (Without the check this update was accepted with a diagonal of −2620, −290, … and every
/// later step refused.)
#[test]
fn an_indefinite_update_is_refused_and_the_filter_kept() {
    let build = |points: SigmaPoints| {
        let p0 = DMatrix::from_diagonal(&DVector::from_vec(vec![
            400.0, 400.0, 400.0, 25.0, 25.0, 25.0,
        ]));
        let x0 = DVector::from_vec(vec![20.0, 5.0, 0.0, 1.0, 0.0, 0.0]);
        let radar = Radar::new([0.0; 3], 6).unwrap();
        UnscentedKalmanFilter::new(PolynomialDynamics::new(1, 3), radar, x0, p0, 0.0)
            .unwrap()
            .with_process_noise(WhiteNoiseDerivative::new(1, 3, 1.0).unwrap())
            .unwrap()
            .with_sigma_points(points)
            .unwrap()
    };
    let m = Measurement {
        time: 1.0,
        values: vec![Some(20.0), Some(0.2), Some(0.0)],
        noise: NoiseCovariance::Variances(vec![4.0, 0.0025, 0.0025]),
    };
    let mut f = build(SigmaPoints::new(0.2, -1.0, -3.0).unwrap());
    let before = (f.state().clone(), f.covariance().clone(), f.time());
    let e = f.update(&m).unwrap_err();
    assert!(
        matches!(&e, Error::InvalidParameter { name: Param::Covariance, reason, .. }
            if reason.contains("W0c") && reason.contains("negative")),
        "{e}"
    );
    assert_eq!(
        (f.state().clone(), f.covariance().clone(), f.time()),
        before
    );
    // The same update with the default weights is accepted, its covariance positive definite.
    let mut g = build(SigmaPoints::default());
    g.update(&m).unwrap();
    assert!(nalgebra::Cholesky::new(g.covariance().clone()).is_some());
}

/// 10⁴ seeded random calls with bad and extreme numbers (NaN, ±∞, ±1e300, 1e-300, wrong
/// lengths, asymmetric or indefinite matrices, negative variances): no panic; a refused update
/// leaves the filter as it was; an accepted one leaves only finite numbers.
#[test]
fn random_bad_calls_never_panic_and_leave_the_filter_whole() {
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};
    let pool = [
        0.0,
        1.0,
        -1.0,
        2.5,
        1e300,
        -1e300,
        1e-300,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ];
    let mut r = StdRng::seed_from_u64(0x0b5e_55ed);
    let pick = |r: &mut StdRng, bad: f64| {
        if r.gen::<f64>() < bad {
            pool[r.gen_range(0..pool.len())]
        } else {
            r.gen_range(-3.0..3.0)
        }
    };
    let (mut built, mut accepted, mut refused) = (0, 0, 0);
    for _ in 0..10_000 {
        let n = 6;
        let len = if r.gen::<f64>() < 0.05 { 5 } else { n };
        let x = DVector::from_fn(len, |_, _| pick(&mut r, 0.05) * 1e3);
        let a = DMatrix::from_fn(n, n, |_, _| pick(&mut r, 0.02));
        let mut s = &a * a.transpose() + DMatrix::identity(n, n) * 0.1;
        if r.gen::<f64>() < 0.05 {
            s[(0, 1)] += 1.0; // asymmetric
        }
        if r.gen::<f64>() < 0.05 {
            s[(2, 2)] = -1.0; // indefinite
        }
        let radar = Radar::new([0.0; 3], n).unwrap();
        let Ok(f) = UnscentedKalmanFilter::new(PolynomialDynamics::new(1, 3), radar, x, s, 0.0)
        else {
            continue;
        };
        // A third of the filters with random sigma points, negative central weights included.
        let mut f = if r.gen::<f64>() < 0.3 {
            let points = SigmaPoints::new(
                r.gen_range(0.05..1.5),
                r.gen_range(-2.0..3.0),
                r.gen_range(-5.0..3.0),
            );
            match points.and_then(|p| f.with_sigma_points(p)) {
                Ok(f) => f,
                Err(_) => continue,
            }
        } else {
            f
        };
        built += 1;
        for k in 0..4 {
            let values: Vec<Option<f64>> = (0..if r.gen::<f64>() < 0.05 { 2 } else { 3 })
                .map(|_| (r.gen::<f64>() > 0.2).then(|| pick(&mut r, 0.05) * 1e3))
                .collect();
            let variances = (0..3).map(|_| pick(&mut r, 0.05).abs() + 1e-6).collect();
            let noise = if r.gen::<f64>() < 0.1 {
                NoiseCovariance::Full(DMatrix::from_fn(3, 3, |_, _| pick(&mut r, 0.2)))
            } else {
                NoiseCovariance::Variances(variances)
            };
            let time = k as f64 + 1.0 + pick(&mut r, 0.05).abs() * 0.1;
            let m = Measurement {
                time,
                values,
                noise,
            };
            let before = (f.state().clone(), f.covariance().clone(), f.time());
            match f.update(&m) {
                Ok(i) => {
                    accepted += 1;
                    assert!(f
                        .state()
                        .iter()
                        .chain(f.covariance().iter())
                        .all(|v| v.is_finite()));
                    assert!(i.is_none_or(|i| i.nis.is_finite() && i.nis >= 0.0));
                    // An accepted covariance has its Cholesky factor: its σ are never zero.
                    assert!(nalgebra::Cholesky::new(f.covariance().clone()).is_some());
                }
                Err(_) => {
                    refused += 1;
                    assert_eq!(
                        (f.state().clone(), f.covariance().clone(), f.time()),
                        before
                    );
                }
            }
        }
    }
    println!("{built} filters built, {accepted} updates accepted, {refused} refused");
    assert!(built > 5_000 && accepted > 1_000 && refused > 1_000);
}

/// Any `Dynamics` and `Observation`: constant velocity written as an ODE `dX/dt = F(X)`
/// (`NonlinearDynamics`, integrated) and observed through a closure (`NonlinearObservation`,
/// `G` without its differenced Jacobian) gives the Kalman filter's numbers on the closed-form
/// model, to the integrator's tolerance.
#[test]
fn ode_dynamics_and_closure_observation_give_the_kalman_filter() {
    use seqsmooth::model::nonlinear::NonlinearDynamics;
    use seqsmooth::model::observation::NonlinearObservation;
    let fx = read("linear");
    let s = setup(&fx);
    let rows = measurements(&fx, &s);
    let ode = NonlinearDynamics::new(4, |_t, x: &DVector<f64>| {
        DVector::from_vec(vec![x[2], x[3], 0.0, 0.0])
    })
    .with_tolerances(1e-12, 1e-12)
    .unwrap();
    let seen = NonlinearObservation::new(2, 4, |_t, x: &DVector<f64>| {
        DVector::from_vec(vec![x[0], x[1]])
    });
    let mut u = UnscentedKalmanFilter::new(ode, seen, s.x0.clone(), s.p0.clone(), s.t0)
        .unwrap()
        .with_process_noise(s.noise)
        .unwrap();
    let mut k = KalmanFilter::new(
        s.dynamics,
        positions(2, 4),
        s.x0.clone(),
        s.p0.clone(),
        s.t0,
    )
    .unwrap()
    .with_process_noise(s.noise)
    .unwrap();
    let mut most = (0.0_f64, 0.0_f64);
    for m in &rows {
        u.update(m).unwrap();
        k.update(m).unwrap();
        let want = k.state().as_slice().to_vec();
        let (x, c) = worst(u.state(), u.covariance(), &want, k.covariance());
        most = (most.0.max(x), most.1.max(c));
    }
    println!("ODE and closure against the Kalman filter: {most:?}");
    assert!(most.0 <= 1e-9 && most.1 <= 1e-9, "{most:?}");
}
