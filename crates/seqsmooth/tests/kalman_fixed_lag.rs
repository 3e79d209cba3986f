//! `kalman::fixed_lag`: the fixed-lag smoother's `X_{k|k+L}` and `S_{k|k+L}` against the
//! posterior of the states given the prior and measurements `0..=k+L`, solved directly (the
//! dense information matrix of the whole linear-Gaussian chain: prior, transitions with their
//! driving noise, measurements), on irregular steps with missing components, lags 0 (the
//! filter) to beyond the input (the whole-interval smoother); against the whole-interval
//! smoother run over rows `0..=k+L`; a Monte Carlo check of its covariance (NEES); and its
//! refusals.

use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use seqsmooth::error::Param;
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::kalman::{smooth, FixedLagSmoother, KalmanFilter, Smoothed};
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::measurement::Measurement;
use seqsmooth::model::measurement::NoiseCovariance;
use seqsmooth::model::observation::LinearObservation;
use seqsmooth::Error;

/// The observation: the position, and the position plus the velocity.
fn h() -> DMatrix<f64> {
    DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 1.0, 1.0])
}

/// The measurement noise's covariance (correlated components).
fn r() -> DMatrix<f64> {
    DMatrix::from_row_slice(2, 2, &[1.5, 0.3, 0.3, 0.8])
}

/// `Φ(ζ)` of the constant-velocity model, and `Q(ζ)` of white noise `q` on the velocity.
fn phi_q(zeta: f64, q: f64) -> (DMatrix<f64>, DMatrix<f64>) {
    let phi = DMatrix::from_row_slice(2, 2, &[1.0, zeta, 0.0, 1.0]);
    let z2 = zeta * zeta;
    let qm = DMatrix::from_row_slice(2, 2, &[z2 * zeta / 3.0, z2 / 2.0, z2 / 2.0, zeta]) * q;
    (phi, qm)
}

/// The prior (mean, covariance at `T0`) and the filter over it with driving noise `q`.
const T0: f64 = 1.0;
fn filter(q: f64) -> KalmanFilter<PolynomialDynamics, LinearObservation> {
    let (x0, p0) = prior();
    KalmanFilter::new(
        PolynomialDynamics::new(1, 1),
        LinearObservation::new(h()).unwrap(),
        x0,
        p0,
        T0,
    )
    .unwrap()
    .with_process_noise(WhiteNoiseDerivative::new(1, 1, q).unwrap())
    .unwrap()
}

fn prior() -> (DVector<f64>, DMatrix<f64>) {
    (
        DVector::from_vec(vec![0.5, -0.2]),
        DMatrix::from_row_slice(2, 2, &[4.0, 0.5, 0.5, 2.0]),
    )
}

/// Random measurements at irregular steps from `T0`: every third misses its second
/// component, every seventh its first (every 21st is empty).
fn rows(rng: &mut rand::rngs::StdRng, count: usize) -> Vec<Measurement> {
    let mut t = T0;
    (0..count)
        .map(|k| {
            t += rng.gen_range(0.1..1.5);
            let first = (k % 7 != 3).then(|| rng.gen_range(-5.0..5.0));
            let second = (k % 3 != 0).then(|| rng.gen_range(-5.0..5.0));
            Measurement {
                time: t,
                values: vec![first, second],
                noise: NoiseCovariance::Full(r()),
            }
        })
        .collect()
}

/// The posterior of the states at the times of `rows` given the prior at `T0` and every row,
/// from the dense information matrix of the chain `T0 → t_0 → t_1 → …`: its mean and
/// covariance at row `k`.
fn posterior(rows: &[Measurement], q: f64, k: usize) -> (DVector<f64>, DMatrix<f64>) {
    let n = rows.len() + 1; // node 0 is the prior's time
    let mut j = DMatrix::zeros(2 * n, 2 * n);
    let mut b = DVector::zeros(2 * n);
    let (x0, p0) = prior();
    let p0i = p0.try_inverse().unwrap();
    j.view_mut((0, 0), (2, 2)).copy_from(&p0i);
    b.rows_mut(0, 2).copy_from(&(&p0i * x0));
    let mut t = T0;
    for (i, m) in rows.iter().enumerate() {
        let (phi, qm) = phi_q(m.time - t, q);
        t = m.time;
        let qi = qm.try_inverse().unwrap();
        // −log p(x_b | x_a) = ½ (x_b − Φ x_a)ᵀ Q⁻¹ (x_b − Φ x_a).
        let (a, c) = (2 * i, 2 * i + 2);
        let mut add = |r0: usize, c0: usize, m: &DMatrix<f64>| {
            let mut v = j.view_mut((r0, c0), (2, 2));
            v += m;
        };
        add(a, a, &(phi.transpose() * &qi * &phi));
        add(a, c, &(-(phi.transpose() * &qi)));
        add(c, a, &(-(&qi * &phi)));
        add(c, c, &qi);
        let present: Vec<usize> = (0..2).filter(|&c| m.values[c].is_some()).collect();
        if present.is_empty() {
            continue;
        }
        let hp = DMatrix::from_fn(present.len(), 2, |i, col| h()[(present[i], col)]);
        let rp = DMatrix::from_fn(present.len(), present.len(), |i, col| {
            r()[(present[i], present[col])]
        });
        let y = DVector::from_fn(present.len(), |i, _| m.values[present[i]].unwrap());
        let ri = rp.try_inverse().unwrap();
        let mut v = j.view_mut((c, c), (2, 2));
        v += hp.transpose() * &ri * &hp;
        let mut w = b.rows_mut(c, 2);
        w += hp.transpose() * &ri * y;
    }
    let cov = j.try_inverse().unwrap();
    let mean = &cov * b;
    let at = 2 * k + 2;
    (
        mean.rows(at, 2).into_owned(),
        cov.view((at, at), (2, 2)).into_owned(),
    )
}

/// Every row's estimate from the fixed-lag smoother of lag `lag`: those given by `push` (each
/// `lag` rows late) and by `finish`.
fn fixed_lag(q: f64, lag: usize, rows: &[Measurement]) -> Vec<Smoothed> {
    let mut s = FixedLagSmoother::new(filter(q), lag);
    let mut out = Vec::new();
    for (k, m) in rows.iter().enumerate() {
        let given = s.push(m).unwrap();
        assert_eq!(given.is_some(), k >= lag, "row {k}, lag {lag}");
        assert_eq!(s.held(), lag.min(k + 1));
        out.extend(given);
    }
    out.extend(s.finish().unwrap());
    assert_eq!(out.len(), rows.len());
    out
}

/// `X_{k|k+L}` and `S_{k|k+L}` equal the direct posterior given rows `0..=k+L` (the last
/// `L` rows: given every row), within 1e-9 of σ and of `σ_i σ_j`; and equal the whole-interval
/// smoother run over rows `0..=k+L` to rounding (1e-12).
#[test]
fn fixed_lag_equals_the_posterior_of_the_rows_up_to_k_plus_lag() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(30);
    let q = 0.3;
    let rows = rows(&mut rng, 40);
    let n = rows.len();
    let (mut worst, mut worst_rts): (f64, f64) = (0.0, 0.0);
    for lag in [0, 1, 2, 5, 13, n - 1, n, usize::MAX] {
        let out = fixed_lag(q, lag, &rows);
        for (k, s) in out.iter().enumerate() {
            let end = k.saturating_add(lag).min(n - 1);
            let (mean, cov) = posterior(&rows[..=end], q, k);
            let rts = &smooth(filter(q), &rows[..=end]).unwrap()[k];
            assert_eq!(s.time, rows[k].time);
            for i in 0..2 {
                let si = cov[(i, i)].sqrt();
                let e = (s.state[i] - mean[i]).abs() / si;
                worst = worst.max(e);
                assert!(
                    e <= 1e-9,
                    "lag {lag} row {k} x{i}: {} against {}",
                    s.state[i],
                    mean[i]
                );
                let e = (s.state[i] - rts.state[i]).abs() / si;
                worst_rts = worst_rts.max(e);
                assert!(
                    e <= 1e-12,
                    "lag {lag} row {k} x{i} against the RTS over 0..={end}"
                );
                for jj in 0..2 {
                    let scale = si * cov[(jj, jj)].sqrt();
                    let e = (s.covariance[(i, jj)] - cov[(i, jj)]).abs() / scale;
                    worst = worst.max(e);
                    assert!(e <= 1e-9, "lag {lag} row {k} S[{i},{jj}]");
                    let e = (s.covariance[(i, jj)] - rts.covariance[(i, jj)]).abs() / scale;
                    worst_rts = worst_rts.max(e);
                    assert!(e <= 1e-12, "lag {lag} row {k} S[{i},{jj}] against the RTS");
                }
            }
            assert_eq!(s.nis, rts.nis);
        }
    }
    println!("worst: against the posterior {worst:e}, against the RTS {worst_rts:e}");
}

/// Lag 0 is the filter: every row's estimate is the forward filter's, given at its own push.
#[test]
fn lag_zero_is_the_filter() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(31);
    let rows = rows(&mut rng, 30);
    let mut f = filter(0.3);
    for (m, s) in rows.iter().zip(fixed_lag(0.3, 0, &rows)) {
        let nis = f.update(m).unwrap().map(|i| i.nis);
        assert_eq!(
            (&s.state, &s.covariance, s.nis),
            (f.state(), f.covariance(), nis)
        );
        assert_eq!(
            (&s.filtered_state, &s.filtered_covariance),
            (&s.state, &s.covariance)
        );
    }
}

/// Monte Carlo: on tracks drawn from the model itself (prior, driving noise, measurement
/// noise), the NEES `eᵀ S⁻¹ e` of `X_{k|k+L}` at a row is χ² with 2 degrees of freedom: its
/// mean over 4000 independent runs is 2 within 4 standard errors (`2·sqrt(2/4000)·… ≈ 0.13`),
/// at rows early (little data before) and late, lags 3 and 10.
#[test]
fn nees_of_the_fixed_lag_estimate_is_chi_squared() {
    let q = 0.5;
    let runs = 4000;
    let count = 40;
    let at = [2, 25];
    for lag in [3, 10] {
        let mut sums = [0.0; 2];
        for run in 0..runs {
            let mut rng = rand::rngs::StdRng::seed_from_u64(1000 + run as u64);
            let mut normal = |n: usize| DVector::from_fn(n, |_, _| StandardNormal.sample(&mut rng));
            let (x0, p0) = prior();
            let mut x = x0 + p0.cholesky().unwrap().l() * normal(2);
            let mut t = T0;
            let mut truth = Vec::new();
            let mut measured = Vec::new();
            let lr = r().cholesky().unwrap().l();
            let steps: Vec<f64> = {
                let mut g = rand::rngs::StdRng::seed_from_u64(7 + run as u64);
                (0..count).map(|_| g.gen_range(0.1..1.5)).collect()
            };
            for (k, dt) in steps.into_iter().enumerate() {
                let (phi, qm) = phi_q(dt, q);
                x = phi * x + qm.cholesky().unwrap().l() * normal(2);
                t += dt;
                let y = h() * &x + &lr * normal(2);
                truth.push(x.clone());
                measured.push(Measurement {
                    time: t,
                    values: vec![(k % 5 != 1).then_some(y[0]), (k % 3 != 0).then_some(y[1])],
                    noise: NoiseCovariance::Full(r()),
                });
            }
            let mut s = FixedLagSmoother::new(filter(q), lag);
            let mut given = Vec::new();
            for m in &measured[..at[1] + lag + 1] {
                given.extend(s.push(m).unwrap());
            }
            for (i, &k) in at.iter().enumerate() {
                let e = &given[k].state - &truth[k];
                let nees = e.dot(&(given[k].covariance.clone().try_inverse().unwrap() * &e));
                sums[i] += nees;
            }
        }
        for (i, &k) in at.iter().enumerate() {
            let mean = sums[i] / runs as f64;
            let se = (4.0 / runs as f64).sqrt();
            println!(
                "lag {lag}, row {k}: mean NEES {mean:.4} (2 ± {:.4})",
                4.0 * se
            );
            assert!(
                (mean - 2.0).abs() <= 4.0 * se,
                "lag {lag} row {k}: mean NEES {mean}"
            );
        }
    }
}

/// Refusals: a time before the previous one, a failing update, and a gain that cannot be
/// formed (no prior uncertainty and no driving noise: `S_{k+1|k}` is 0) name their
/// measurement and leave the smoother as it was.
/// The smoother's saved form (`persist`): everything it holds but its filter's scratch
/// buffers, which a refused push may have written.
fn saved<D, O>(s: &FixedLagSmoother<D, O>) -> Vec<u8>
where
    FixedLagSmoother<D, O>: seqsmooth::persist::Persist,
    D: seqsmooth::model::dynamics::Dynamics,
    O: seqsmooth::model::observation::Observation,
{
    seqsmooth::persist::to_bytes(s).unwrap()
}

#[test]
fn refusals_leave_the_smoother_unchanged() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(32);
    let rows = rows(&mut rng, 6);
    let mut s = FixedLagSmoother::new(filter(0.3), 2);
    for m in &rows[..3] {
        s.push(m).unwrap();
    }
    let reference = saved(&s);
    let mut bad = rows[3].clone();
    bad.time = rows[1].time;
    assert!(matches!(
        s.push(&bad),
        Err(Error::InvalidParameter {
            name: Param::Time,
            ..
        })
    ));
    bad.time = f64::NAN;
    assert!(s.push(&bad).is_err());
    assert_eq!(saved(&s), reference);
    let certain = KalmanFilter::new(
        PolynomialDynamics::new(1, 1),
        LinearObservation::new(h()).unwrap(),
        DVector::zeros(2),
        DMatrix::zeros(2, 2),
        T0,
    );
    let Ok(certain) = certain else {
        return; // a singular prior refused up front is as good
    };
    let mut s = FixedLagSmoother::new(certain, 1);
    assert!(s.push(&rows[0]).unwrap().is_none());
    let reference = saved(&s);
    for _ in 0..2 {
        let e = s.push(&rows[1]);
        assert!(matches!(e, Err(Error::InBatch { index: 1, .. })), "{e:?}");
        assert_eq!(saved(&s), reference);
    }
}

/// The radar tracker's smoother at lag `lag` on `rows`: every row's σ (the six components), `None`
/// for the rows before the smoother's.
fn tracker_sigmas(rows: &[Measurement], q: Option<f64>, lag: usize) -> Vec<Option<[f64; 6]>> {
    use seqsmooth::model::radar::Radar;
    use seqsmooth::track::{RadarTracker, TrackMethod, Tracked};
    let radar = Radar::new([0.0; 3], 6).unwrap();
    let mut t = RadarTracker::new(radar, TrackMethod::Smooth { q, lag }).unwrap();
    let mut out = vec![None; rows.len()];
    let sigma = |s: &Smoothed| std::array::from_fn(|i| s.covariance[(i, i)].sqrt());
    for m in rows {
        if let Tracked::Smoothed { row, estimate, .. } = t.push(m).unwrap() {
            out[row] = Some(sigma(estimate));
        }
    }
    for (row, s, _) in t.finish().unwrap() {
        out[row] = Some(sigma(&s));
    }
    out
}

/// landing.csv (bearing convention) with N(0, 10 m) range and N(0, 1 mrad) angle noise, seed
/// fixed: 474 rows 2.72 s apart at 11-200 km.
fn landing_rows() -> Vec<Measurement> {
    use seqsmooth::track::radar_row;
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/landing.csv");
    let text = std::fs::read_to_string(path).unwrap();
    let mut rng = rand::rngs::StdRng::seed_from_u64(2026);
    let mut g = || -> f64 { StandardNormal.sample(&mut rng) };
    text.lines()
        .skip(1)
        .map(|line| {
            let c: Vec<f64> = line.split(',').map(|v| v.parse().unwrap()).collect();
            // time,east,north,up,azimuth,elevation,range
            let v = [c[6] + 10.0 * g(), c[4] + 1e-3 * g(), c[5] + 1e-3 * g()];
            radar_row(c[0], v.map(Some), Some(10.0), Some(1e-3), true).unwrap()
        })
        .collect()
}

/// The straight pass of `scripts/track_memory.sh`: from (20, −15, 3) km at (−40, 25, −1) m/s,
/// steps U(0.05, 0.15) s, σ 10 m and 1 mrad.
fn straight_rows(n: usize) -> Vec<Measurement> {
    use seqsmooth::track::radar_row;
    let mut rng = rand::rngs::StdRng::seed_from_u64(2027);
    let mut t: f64 = 0.0;
    (0..n)
        .map(|_| {
            let (x, y, z) = (2e4 - 40.0 * t, -1.5e4 + 25.0 * t, 3e3 - t);
            let g: [f64; 3] = std::array::from_fn(|_| StandardNormal.sample(&mut rng));
            let v = [
                (x * x + y * y + z * z).sqrt() + 10.0 * g[0],
                y.atan2(x) + 1e-3 * g[1],
                z.atan2(x.hypot(y)) + 1e-3 * g[2],
            ];
            let m = radar_row(t, v.map(Some), Some(10.0), Some(1e-3), false).unwrap();
            t += rng.gen_range(0.05..0.15);
            m
        })
        .collect()
}

/// The default lag's σ are within 1 % of the whole-interval smoother's on every row and
/// component, on landing.csv with q = 10 m²/s³ (the help's setting for an airliner) and on
/// the memory script's straight pass with q = 1 and q = 0.1, and on both with the tracker's
/// default adaptive q (the forward filter's q raised on misfits and lowered in quiet
/// stretches, the same run at every lag); printed: the worst excess for other lags (how
/// `DEFAULT_LAG` was chosen).
#[test]
fn the_default_lag_is_within_one_percent_of_the_whole_smoother() {
    use seqsmooth::track::DEFAULT_LAG;
    let cases = [
        ("landing.csv, q 10", landing_rows(), Some(10.0)),
        ("straight pass, q 1", straight_rows(3000), Some(1.0)),
        ("straight pass, q 0.1", straight_rows(3000), Some(0.1)),
        ("landing.csv, adaptive q", landing_rows(), None),
        ("straight pass, adaptive q", straight_rows(3000), None),
    ];
    for (name, rows, q) in &cases {
        let whole = tracker_sigmas(rows, *q, usize::MAX);
        let excess = |lag: usize| -> f64 {
            let lagged = tracker_sigmas(rows, *q, lag);
            let mut worst: f64 = 0.0;
            for (a, b) in lagged.iter().zip(&whole) {
                assert_eq!(a.is_some(), b.is_some());
                if let (Some(a), Some(b)) = (a, b) {
                    for i in 0..6 {
                        worst = worst.max(a[i] / b[i] - 1.0);
                    }
                }
            }
            worst
        };
        let table: Vec<String> = [5, 10, 20, 50, 100, 150, 200, 300, 500]
            .iter()
            .map(|&lag| format!("{lag}: {:.2e}", excess(lag)))
            .collect();
        println!(
            "{name}: worst σ excess over the whole-interval smoother by lag: {}",
            table.join(", ")
        );
        let e = excess(DEFAULT_LAG);
        assert!(
            e <= 0.01,
            "{name}: the default lag's σ exceed the whole smoother's by {e}"
        );
    }
}
