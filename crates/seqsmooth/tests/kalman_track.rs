//! `track::RadarTracker` against the same methods composed by hand from their parts
//! (`SlidingFit`, `KalmanFilter`, `kalman::smooth`), bit for bit, on a noisy pass with
//! irregular steps and missing components; the smoother's last row against the filter's (the
//! RTS property); refused rows leaving the tracker as it was; refused settings.

use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use seqsmooth::estimate::gauss_newton::{Correction, Epoch, Measurement};
use seqsmooth::estimate::sliding::{SlidingFit, Start};
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::kalman::{smooth, Discount, FixedLagSmoother, KalmanFilter};
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::measurement::NoiseCovariance;
use seqsmooth::model::radar::Radar;
use seqsmooth::track::{
    window_flag, RadarTracker, TrackError, TrackFlag, TrackMethod, Tracked, START_WINDOW,
};

/// `n` rows of a constant-velocity target seen from `site`, steps `U(0.5, 1.5)` s from a
/// Unix-epoch start, σ 10 m and 1 mrad, 5% of components missing.
fn pass(n: usize, site: [f64; 3], seed: u64) -> Vec<Measurement> {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let (sr, sa) = (10.0, 1e-3);
    let (nr, na) = (Normal::new(0.0, sr).unwrap(), Normal::new(0.0, sa).unwrap());
    let mut t = 1.7e9;
    (0..n)
        .map(|_| {
            t += rng.gen_range(0.5..1.5);
            let s = t - 1.7e9;
            let (x, y, z) = (
                20_000.0 + 150.0 * s - site[0],
                -8_000.0 + 60.0 * s - site[1],
                3_000.0 - 4.0 * s - site[2],
            );
            let r = (x * x + y * y + z * z).sqrt();
            let clean = [r, y.atan2(x), (z / r).asin()];
            let noisy = [
                clean[0] + nr.sample(&mut rng),
                clean[1] + na.sample(&mut rng),
                clean[2] + na.sample(&mut rng),
            ];
            Measurement {
                time: t,
                values: noisy
                    .iter()
                    .map(|&v| (!rng.gen_bool(0.05)).then_some(v))
                    .collect(),
                noise: NoiseCovariance::Variances(vec![sr * sr, sa * sa, sa * sa]),
            }
        })
        .collect()
}

/// One row's output: `None` undetermined or held, else the state, covariance, NIS and flag.
type Row = Option<(DVector<f64>, DMatrix<f64>, Option<f64>, TrackFlag)>;

/// Every row of `rows` through a tracker, then its `finish()`: the rows' own estimates, and
/// the smoother's (given with its lag or at the end), each at its row.
fn tracked(radar: Radar, method: TrackMethod, rows: &[Measurement]) -> (Vec<Row>, Vec<Row>) {
    let mut t = RadarTracker::new(radar, method).unwrap();
    let mut held = vec![None; rows.len()];
    let out = rows
        .iter()
        .enumerate()
        .map(|(k, m)| match t.push(m).unwrap() {
            Tracked::Estimate(e) => Some((e.state.clone(), e.covariance.clone(), e.nis, e.flag)),
            Tracked::Smoothed {
                row,
                estimate: s,
                flag,
            } => {
                let TrackMethod::Smooth { lag, .. } = method else {
                    panic!("{method:?} smoothed")
                };
                assert_eq!(row, k - lag);
                assert!(held[row].is_none());
                held[row] = Some((s.state.clone(), s.covariance.clone(), s.nis, flag));
                None
            }
            Tracked::Undetermined | Tracked::Held => None,
        })
        .collect();
    for (row, s, flag) in t.finish().unwrap() {
        assert!(held[row].is_none());
        held[row] = Some((s.state, s.covariance, s.nis, flag));
    }
    (out, held)
}

/// The sliding fit over `w` rows at the radar's nominal.
fn fit(radar: Radar, w: usize) -> SlidingFit<PolynomialDynamics, Radar> {
    SlidingFit::new(
        PolynomialDynamics::new(1, 3),
        radar,
        w,
        Epoch::End,
        Start::Radar { radar, degree: 2 },
    )
    .unwrap()
    .with_misfit_scale()
}

/// A Kalman filter from a fit.
fn filter(radar: Radar, c: &Correction) -> KalmanFilter<PolynomialDynamics, Radar> {
    KalmanFilter::new(
        PolynomialDynamics::new(1, 3),
        radar,
        c.state.clone(),
        c.covariance.clone(),
        c.epoch,
    )
    .unwrap()
}

/// The first row whose start fit determines the state, and that fit.
fn start(radar: Radar, rows: &[Measurement]) -> (usize, Correction) {
    let mut f = fit(radar, START_WINDOW);
    for (k, m) in rows.iter().enumerate() {
        if let Some(c) = f.push(m.clone()).unwrap() {
            return (k, c);
        }
    }
    panic!("the pass never determines the state");
}

#[test]
fn kalman_and_fading_equal_the_filter_from_the_first_fit() {
    let radar = Radar::new([100.0, -50.0, 10.0], 6).unwrap();
    let rows = pass(400, [100.0, -50.0, 10.0], 1);
    let (k0, c) = start(radar, &rows);
    for method in [
        TrackMethod::Kalman { q: Some(0.5) },
        TrackMethod::Fading(Some(Discount::PerTime(0.9))),
        TrackMethod::Fading(Some(Discount::PerUpdate(0.8))),
    ] {
        let (out, held) = tracked(radar, method, &rows);
        assert!(held.iter().all(Option::is_none));
        assert!(out[..k0].iter().all(Option::is_none), "{method:?}");
        let first = out[k0].as_ref().unwrap();
        assert_eq!(
            (&first.0, &first.1, first.2, first.3),
            (&c.state, &c.covariance, None, TrackFlag::None)
        );
        let mut f = filter(radar, &c);
        f = match method {
            TrackMethod::Kalman { q: Some(q) } => f
                .with_process_noise(WhiteNoiseDerivative::new(1, 3, q).unwrap())
                .unwrap(),
            TrackMethod::Fading(Some(d)) => f.with_fading(d).unwrap(),
            _ => unreachable!(),
        };
        // The gate (χ²₃ at 0.999, 16.266) leaves out a lone row beyond it: the reference
        // takes the prediction there.
        let gate = seqsmooth::stats::chi_squared_quantile(3.0, 0.999).unwrap();
        let mut outliers = 0;
        for (k, m) in rows.iter().enumerate().skip(k0 + 1) {
            let (x, s, n, flag) = out[k].as_ref().unwrap();
            let nis = if *flag == TrackFlag::Outlier {
                outliers += 1;
                assert!(n.unwrap() > gate, "{method:?} row {k}");
                let (stats, used) = f.update_gated(m, |_| false).unwrap().unwrap();
                assert!(!used);
                Some(stats.nis)
            } else {
                f.update_stats(m).unwrap().map(|i| i.nis)
            };
            assert_eq!(
                (x, s, *n),
                (f.state(), f.covariance(), nis),
                "{method:?} row {k}"
            );
        }
        assert!(outliers <= 2, "{method:?}: {outliers} rows left out");
    }
}

#[test]
fn smooth_is_the_smoother_over_the_rows_after_the_start() {
    let radar = Radar::new([0.0; 3], 6).unwrap();
    let rows = pass(300, [0.0; 3], 2);
    let (k0, c) = start(radar, &rows);
    let q = 0.2;
    let f = filter(radar, &c)
        .with_process_noise(WhiteNoiseDerivative::new(1, 3, q).unwrap())
        .unwrap();
    // An unbounded lag: the whole-interval smoother's; a lag of 25 rows: the fixed-lag
    // smoother's, each row given 25 rows later.
    for lag in [usize::MAX, 300, 25, 0] {
        let method = TrackMethod::Smooth { q: Some(q), lag };
        let (out, held) = tracked(radar, method, &rows);
        assert!(out
            .iter()
            .enumerate()
            .all(|(k, r)| r.is_some() == (k == k0)));
        assert!(held
            .iter()
            .enumerate()
            .all(|(k, r)| r.is_some() == (k > k0)));
        let s = if lag >= rows.len() {
            smooth(f.clone(), &rows[k0 + 1..]).unwrap()
        } else {
            let mut s = FixedLagSmoother::new(f.clone(), lag);
            let mut v: Vec<_> = rows[k0 + 1..]
                .iter()
                .filter_map(|m| s.push(m).unwrap())
                .collect();
            v.extend(s.finish().unwrap());
            v
        };
        for (k, s) in s.iter().enumerate() {
            let (x, p, n, flag) = held[k0 + 1 + k].as_ref().unwrap();
            assert_ne!(*flag, TrackFlag::Outlier, "no row of this pass is left out");
            assert_eq!((x, p, *n), (&s.state, &s.covariance, s.nis), "lag {lag}");
        }
    }
    let (_, held) = tracked(
        radar,
        TrackMethod::Smooth {
            q: Some(q),
            lag: 300,
        },
        &rows,
    );
    // At the last row the smoothed estimate is the filtered one (RTS).
    let (kalman, _) = tracked(radar, TrackMethod::Kalman { q: Some(q) }, &rows);
    let (x, p, ..) = held.last().unwrap().as_ref().unwrap();
    let (xf, pf, ..) = kalman.last().unwrap().as_ref().unwrap();
    assert!((x - xf).amax() <= 1e-9 * xf.amax() && (p - pf).amax() <= 1e-9 * pf.amax());
}

/// The adaptive smoother's forward filter is the adaptive kalman method's, gated and adapted
/// alike at every lag: each smoothed row carries that row's NIS and flag (an injected outlier
/// named `Outlier` however late it is released), lag 0 is the filter, and the last row of any
/// lag is the filter's (RTS).
#[test]
fn the_adaptive_smoother_carries_the_filters_flags_at_every_lag() {
    let radar = Radar::new([0.0; 3], 6).unwrap();
    let mut rows = pass(400, [0.0; 3], 5);
    let (k0, _) = start(radar, &rows);
    let bad = k0 + 100;
    rows[bad].values[0] = Some(rows[bad].values[0].unwrap_or(5e4) + 400.0); // 40σ
    let (kalman, _) = tracked(radar, TrackMethod::Kalman { q: None }, &rows);
    assert_eq!(kalman[bad].as_ref().unwrap().3, TrackFlag::Outlier);
    for lag in [0, 1, 25, 200, usize::MAX] {
        let (out, held) = tracked(radar, TrackMethod::Smooth { q: None, lag }, &rows);
        assert_eq!(out[k0], kalman[k0], "lag {lag}: the start's row");
        for k in k0 + 1..rows.len() {
            let (x, p, n, flag) = held[k].as_ref().unwrap();
            let (xk, pk, nk, fk) = kalman[k].as_ref().unwrap();
            assert_eq!((n, flag), (nk, fk), "lag {lag} row {k}");
            if lag == 0 || k == rows.len() - 1 {
                assert!((x - xk).amax() <= 1e-9 * xk.amax(), "lag {lag} row {k}");
                assert!((p - pk).amax() <= 1e-9 * pk.amax(), "lag {lag} row {k}");
            }
        }
    }
}

#[test]
fn window_is_the_sliding_fit_with_the_previous_fits_innovation() {
    let radar = Radar::new([0.0; 3], 6).unwrap();
    let rows = pass(200, [0.0; 3], 3);
    let w = 12;
    let (out, _) = tracked(radar, TrackMethod::Window { window: w }, &rows);
    let mut f = fit(radar, w);
    let mut previous: Option<Correction> = None;
    for (k, m) in rows.iter().enumerate() {
        let nis = previous.as_ref().and_then(|p| {
            let mut kf = filter(radar, p);
            kf.update_stats(m).unwrap().map(|i| i.nis)
        });
        // A row the gate leaves out takes its place in the window unmeasured.
        let mut taken = m.clone();
        if out[k].as_ref().is_some_and(|o| o.3 == TrackFlag::Outlier) {
            taken.values = vec![None; 3];
        }
        previous = f.push(taken).unwrap();
        match (&previous, &out[k]) {
            (None, None) => {}
            (Some(c), Some((x, s, n, flag))) => {
                assert_eq!((x, s, *n), (&c.state, &c.covariance, nis), "row {k}");
                if *flag != TrackFlag::Outlier {
                    assert_eq!(*flag, window_flag(c), "row {k}");
                }
            }
            (c, o) => panic!("row {k}: fit {:?}, tracker {:?}", c.is_some(), o.is_some()),
        }
    }
    assert!(
        out.iter()
            .filter(|r| r.as_ref().is_some_and(|r| r.2.is_some()))
            .count()
            > 150
    );
}

#[test]
fn a_refused_row_names_its_rows_and_changes_nothing() {
    let radar = Radar::new([0.0; 3], 6).unwrap();
    let rows = pass(80, [0.0; 3], 4);
    let (k0, _) = start(radar, &rows);
    for (method, at) in [
        (TrackMethod::Kalman { q: Some(1.0) }, 1),
        (TrackMethod::Kalman { q: Some(1.0) }, 40),
        (TrackMethod::Window { window: 10 }, 30),
        (
            TrackMethod::Smooth {
                q: Some(1.0),
                lag: 500,
            },
            50,
        ),
        (
            TrackMethod::Smooth {
                q: Some(1.0),
                lag: 3,
            },
            50,
        ),
    ] {
        let mut t = RadarTracker::new(radar, method).unwrap();
        let mut reference = RadarTracker::new(radar, method).unwrap();
        for m in &rows[..at] {
            t.push(m).unwrap();
            reference.push(m).unwrap();
        }
        let mut bad = rows[at].clone();
        bad.time = f64::NAN;
        let e = t.push(&bad).map(|_| ()).unwrap_err();
        match (&e, method) {
            (TrackError::Window { rows, .. }, TrackMethod::Window { window }) => {
                assert_eq!(*rows, at + 1 - window..at + 1)
            }
            (TrackError::Window { rows, .. }, _) if at <= k0 => assert_eq!(*rows, 0..at + 1),
            (
                TrackError::Update { row, .. },
                TrackMethod::Kalman { .. } | TrackMethod::Smooth { .. },
            ) if at > k0 => {
                assert_eq!(*row, at)
            }
            (e, m) => panic!("{m:?} at {at}: {e:?}"),
        }
        assert_eq!(t.rows(), at);
        let later = |t: &mut RadarTracker| -> Vec<Option<DVector<f64>>> {
            let mut v: Vec<_> = rows[at..]
                .iter()
                .map(|m| match t.push(m).unwrap() {
                    Tracked::Estimate(e) => Some(e.state.clone()),
                    Tracked::Smoothed { estimate, .. } => Some(estimate.state.clone()),
                    _ => None,
                })
                .collect();
            v.extend(
                t.finish()
                    .unwrap()
                    .into_iter()
                    .map(|(_, s, _)| Some(s.state)),
            );
            v
        };
        assert_eq!(later(&mut t), later(&mut reference), "{method:?} at {at}");
    }
    // Every method refuses a row at or before the previous one.
    for method in [
        TrackMethod::Kalman { q: Some(1.0) },
        TrackMethod::Fading(Some(Discount::PerUpdate(0.9))),
    ] {
        let mut t = RadarTracker::new(radar, method).unwrap();
        for m in &rows[..30] {
            t.push(m).unwrap();
        }
        let mut bad = rows[30].clone();
        bad.time = rows[29].time;
        assert!(matches!(
            t.push(&bad),
            Err(TrackError::Update { row: 30, .. })
        ));
    }
    // The smoother refuses a row out of order when it comes, and none after its finish.
    let method = TrackMethod::Smooth {
        q: Some(1.0),
        lag: 500,
    };
    let mut t = RadarTracker::new(radar, method).unwrap();
    for m in &rows[..60] {
        t.push(m).unwrap();
    }
    let mut bad = rows[60].clone();
    bad.time = rows[59].time - 1.0;
    assert!(matches!(
        t.push(&bad),
        Err(TrackError::Update { row: 60, .. })
    ));
    bad.time = rows[59].time;
    assert!(matches!(
        t.push(&bad),
        Err(TrackError::Update { row: 60, .. })
    ));
    assert_eq!(t.finish().unwrap().len(), 59 - k0);
    assert!(matches!(
        t.push(&rows[60]),
        Err(TrackError::Update { row: 60, .. })
    ));
}

#[test]
fn bad_settings_are_refused() {
    let radar = Radar::new([0.0; 3], 6).unwrap();
    for method in [
        TrackMethod::Kalman { q: Some(-1.0) },
        TrackMethod::Smooth {
            q: Some(f64::NAN),
            lag: 10,
        },
        TrackMethod::Kalman {
            q: Some(f64::INFINITY),
        },
        TrackMethod::Fading(Some(Discount::PerTime(0.0))),
        TrackMethod::Fading(Some(Discount::PerUpdate(1.5))),
        TrackMethod::Fading(Some(Discount::PerUpdate(f64::NAN))),
        TrackMethod::Window { window: 1 },
    ] {
        assert!(RadarTracker::new(radar, method).is_err(), "{method:?}");
    }
}

/// Rows of times ~1e154 and ranges ~1e143 (from the Python package's random bad calls): the
/// fit's SVD once looped forever; now every row is taken or refused, each quickly.
#[test]
fn extreme_scales_end_instead_of_looping() {
    use seqsmooth::kalman::Discount;
    use seqsmooth::model::measurement::Measurement;
    use seqsmooth::model::measurement::NoiseCovariance;
    use seqsmooth::model::radar::Radar;
    use seqsmooth::track::{RadarTracker, TrackMethod};
    const ROWS: [[f64; 4]; 21] = [
        [
            5.189989720259441e+153,
            4.343369678197512e+143,
            1.0,
            0.35815060192307024,
        ],
        [
            1.3004337721720608e+154,
            4.482171586874016e+143,
            3.0,
            0.3185789684307956,
        ],
        [
            2.0328771235231785e+154,
            9.19681854217737e+142,
            2.0,
            1.3782278975051496,
        ],
        [
            2.1111487976650718e+154,
            2.223210355810719e+143,
            6.0,
            0.3178608960246514,
        ],
        [
            3.198505549909155e+154,
            9.60050259794795e+143,
            2.0,
            0.9275605718175588,
        ],
        [
            3.2003960690930776e+154,
            4.566473787203499e+143,
            4.0,
            1.0790561955952045,
        ],
        [
            4.3916954058887045e+154,
            1.4930380120096661e+144,
            5.0,
            0.40787054068400685,
        ],
        [
            5.774891746193836e+154,
            7.092263945740531e+143,
            1.0,
            1.0840238966711118,
        ],
        [
            6.151250121628603e+154,
            8.905790274046526e+143,
            1.0,
            0.9644424469659629,
        ],
        [
            7.886553680523178e+154,
            2.1364666538294956e+143,
            3.0,
            1.3820522152992165,
        ],
        [
            8.986925675622439e+154,
            9.886560927833852e+143,
            3.0,
            0.048383814776340905,
        ],
        [
            9.862186290331828e+154,
            1.1935784705930634e+144,
            3.0,
            0.992949186206753,
        ],
        [
            1.0367359745801437e+155,
            5.429961324449483e+143,
            5.0,
            0.9379756105606916,
        ],
        [
            1.0870267131028484e+155,
            7.205164776380282e+142,
            6.0,
            0.3390616064214047,
        ],
        [
            1.2294234416777332e+155,
            3.9922639809911e+143,
            4.0,
            0.5379817228973374,
        ],
        [
            1.322736969043096e+155,
            4.397890882350564e+143,
            4.0,
            1.271790401932301,
        ],
        [
            1.368723367289903e+155,
            9.096713738000042e+143,
            0.0,
            1.3606348027158912,
        ],
        [
            1.3980266202499044e+155,
            5.699196766197036e+143,
            0.0,
            1.5141887220432602,
        ],
        [
            1.5433674482063594e+155,
            2.8067329229701373e+143,
            6.0,
            1.1654243849509878,
        ],
        [
            1.7231310073417664e+155,
            3.8102528520735687e+143,
            5.0,
            1.116065198832751,
        ],
        [
            1.758103307726431e+155,
            2.740796096314142e+143,
            1.0,
            0.16621265262958795,
        ],
    ];
    let radar = Radar::new([0.0; 3], 6).unwrap();
    let mut t =
        RadarTracker::new(radar, TrackMethod::Fading(Some(Discount::PerUpdate(0.9)))).unwrap();
    let mut refused = Vec::new();
    for (k, [time, r, az, el]) in ROWS.into_iter().enumerate() {
        let m = Measurement {
            time,
            values: vec![Some(r), Some(az), Some(el)],
            noise: NoiseCovariance::Variances(vec![100.0, 1e-6, 1e-6]),
        };
        if let Err(e) = t.push(&m) {
            refused.push((k, e.to_string()));
        }
    }
    // The window's QR factor holds a NaN here: `linalg::singular_values` refuses it before
    // the SVD (which looped on it, and stops after its iteration limit on finite matrices).
    assert!(
        refused
            .iter()
            .any(|(_, e)| e.contains("did not converge") || e.contains("NaN is not finite")),
        "{refused:?}"
    );
}
