//! The Kalman bank (`kalman::bank`) against one library `KalmanFilter` (and its `Smoother`,
//! `FixedLagSmoother`) per series: 1,000 series with their own irregular times and 10 %
//! missing components, the filter and both smoothers equal to 1e-12 relative; any split of the
//! series into batches the same numbers bit for bit (proptest); the streaming form equal to the
//! batch; bad input refused, naming the series and its row.

use nalgebra::{DMatrix, DVector};
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use seqsmooth::kalman::bank::{BankRows, KalmanBank, Panel};
use seqsmooth::kalman::fixed_lag::FixedLagSmoother;
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::kalman::{smoother, KalmanFilter};
use seqsmooth::model::continuous::ContinuousModel;
use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
use seqsmooth::model::observation::LinearObservation;
use seqsmooth::Error;

/// Series of their own lengths (20..60 rows), irregular times (gaps 0.1..2, a repeated time
/// now and then), `p` components observed with noise, each missing with probability 10 %.
struct Data {
    offsets: Vec<usize>,
    times: Vec<f64>,
    values: Vec<f64>,
}

impl Data {
    fn panel(&self) -> Panel<'_> {
        Panel {
            offsets: &self.offsets,
            times: &self.times,
            values: &self.values,
        }
    }
}

fn data(series: usize, p: usize, seed: u64) -> Data {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let (mut offsets, mut times, mut values) = (vec![0], Vec::new(), Vec::new());
    for _ in 0..series {
        let rows = rng.gen_range(20..60);
        let mut t: f64 = rng.gen_range(-5.0..5.0);
        let velocity: Vec<f64> = (0..p).map(|_| rng.gen_range(-3.0..3.0)).collect();
        for _ in 0..rows {
            if rng.gen_bool(0.95) {
                t += rng.gen_range(0.1..2.0);
            }
            times.push(t);
            for v in &velocity {
                let e: f64 = StandardNormal.sample(&mut rng);
                let missing = rng.gen_bool(0.1);
                values.push(if missing { f64::NAN } else { v * t + e });
            }
        }
        offsets.push(times.len());
    }
    Data {
        offsets,
        times,
        values,
    }
}

/// Series at a constant step (0.5) with now and then a longer one, a missing component in 2 %
/// of the rows and a repeated time in 1 %, of unequal lengths: most steps are the lanes'
/// straight path (every lane's row complete at its remembered step), the rest their general
/// step, in runs of both.
fn data_steady(series: usize, p: usize, seed: u64) -> Data {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let (mut offsets, mut times, mut values) = (vec![0], Vec::new(), Vec::new());
    for _ in 0..series {
        let rows = rng.gen_range(20..90);
        let mut t: f64 = rng.gen_range(-5.0..5.0);
        let velocity: Vec<f64> = (0..p).map(|_| rng.gen_range(-3.0..3.0)).collect();
        for _ in 0..rows {
            if !rng.gen_bool(0.01) {
                t += if rng.gen_bool(0.05) { 1.5 } else { 0.5 };
            }
            times.push(t);
            let missing = rng.gen_bool(0.02).then(|| rng.gen_range(0..p));
            for (c, v) in velocity.iter().enumerate() {
                let e: f64 = StandardNormal.sample(&mut rng);
                values.push(if missing == Some(c) {
                    f64::NAN
                } else {
                    v * t + e
                });
            }
        }
        offsets.push(times.len());
    }
    Data {
        offsets,
        times,
        values,
    }
}

/// The rows of series `s` as the library's measurements.
fn measurements(d: &Data, s: usize, p: usize, r: &DMatrix<f64>) -> Vec<Measurement> {
    (d.offsets[s]..d.offsets[s + 1])
        .map(|row| Measurement {
            time: d.times[row],
            values: d.values[row * p..(row + 1) * p]
                .iter()
                .map(|v| (!v.is_nan()).then_some(*v))
                .collect(),
            noise: NoiseCovariance::Full(r.clone()),
        })
        .collect()
}

/// `|a − b| ≤ 10⁻¹² max|b|` over the row's entries (each quantity's own scale).
fn close(a: &[f64], b: &[f64], what: &str) {
    let scale = b.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        assert!(
            (x - y).abs() <= 1e-12 * scale,
            "{what}[{i}]: bank {x}, library {y}"
        );
    }
}

/// The same NIS to 10⁻¹² relative, present in the same rows.
fn same_nis(bank: Option<f64>, library: Option<f64>) {
    assert_eq!(bank.is_some(), library.is_some());
    if let (Some(a), Some(b)) = (bank, library) {
        close(&[a], &[b], "NIS");
    }
}

fn sigma(s: &DMatrix<f64>) -> Vec<f64> {
    s.diagonal().iter().map(|v| v.max(0.0).sqrt()).collect()
}

/// One model: the bank and the library's filter of series `s` (the prior at its first time).
struct Model<D: Dynamics> {
    bank: KalmanBank<D>,
    library: Box<dyn Fn(f64) -> KalmanFilter<D, LinearObservation>>,
    r: DMatrix<f64>,
}

fn polynomial() -> Model<PolynomialDynamics> {
    // Constant velocity on two axes, both positions observed with a full R.
    let (n, p) = (4, 2);
    let h = DMatrix::from_fn(p, n, |i, j| f64::from(i == j));
    let r = DMatrix::from_row_slice(2, 2, &[1.5, 0.3, 0.3, 0.8]);
    let x0 = DVector::from_vec(vec![0.5, -0.5, 0.0, 0.0]);
    let s0 = DMatrix::from_diagonal(&DVector::from_vec(vec![100.0, 100.0, 25.0, 25.0]));
    let noise = WhiteNoiseDerivative::new(1, 2, 0.05).unwrap();
    let dynamics = PolynomialDynamics::new(1, 2);
    let obs = LinearObservation::new(h).unwrap();
    let bank = KalmanBank::new(dynamics, obs.clone(), r.clone(), x0.clone(), s0.clone())
        .unwrap()
        .with_process_noise(noise)
        .unwrap();
    let library = Box::new(move |t| {
        KalmanFilter::new(dynamics, obs.clone(), x0.clone(), s0.clone(), t)
            .unwrap()
            .with_process_noise(noise)
            .unwrap()
    });
    Model { bank, library, r }
}

fn singer() -> Model<ContinuousModel> {
    // The Singer model on one axis (n = 3), discretised for each step's own length; position
    // observed.
    let model = ContinuousModel::singer(1, 0.3, 4.0).unwrap();
    let obs = LinearObservation::value_of(3);
    let r = DMatrix::from_element(1, 1, 0.7);
    let x0 = DVector::zeros(3);
    let s0 = DMatrix::from_diagonal(&DVector::from_vec(vec![50.0, 10.0, 4.0]));
    let bank = KalmanBank::new(
        model.clone(),
        obs.clone(),
        r.clone(),
        x0.clone(),
        s0.clone(),
    )
    .unwrap()
    .with_process_noise(model.clone())
    .unwrap();
    let library = Box::new(move |t| {
        KalmanFilter::new(model.clone(), obs.clone(), x0.clone(), s0.clone(), t)
            .unwrap()
            .with_process_noise(model.clone())
            .unwrap()
    });
    Model { bank, library, r }
}

/// The bank's filter, RTS and fixed-lag rows against the library's, series by series.
fn equals_library<D: Dynamics + Clone + Sync>(model: &Model<D>, d: &Data, lag: usize) {
    let p = model.r.nrows();
    let filtered = model.bank.filter(&d.panel()).unwrap();
    let smoothed = model.bank.smooth(&d.panel()).unwrap();
    let lagged = model.bank.smooth_fixed_lag(&d.panel(), lag).unwrap();
    for s in 0..d.offsets.len() - 1 {
        let ms = measurements(d, s, p, &model.r);
        let first = d.offsets[s];
        let mut f = (model.library)(ms[0].time);
        for (k, m) in ms.iter().enumerate() {
            let nis = f.update(m).unwrap().map(|i| i.nis);
            let (x, sd, bank_nis) = filtered.row(first + k);
            close(x, f.state().as_slice(), "filtered state");
            close(sd, &f.std_devs(), "filtered σ");
            same_nis(bank_nis, nis);
        }
        let rts = smoother::smooth((model.library)(ms[0].time), &ms).unwrap();
        let mut fl = FixedLagSmoother::new((model.library)(ms[0].time), lag);
        let mut given = Vec::new();
        for m in &ms {
            given.extend(fl.push(m).unwrap());
        }
        given.extend(fl.finish().unwrap());
        for (k, (a, b)) in rts.iter().zip(&given).enumerate() {
            let (x, sd, nis) = smoothed.row(first + k);
            close(x, a.state.as_slice(), "RTS state");
            close(sd, &sigma(&a.covariance), "RTS σ");
            same_nis(nis, a.nis);
            let (x, sd, nis) = lagged.row(first + k);
            close(x, b.state.as_slice(), "fixed-lag state");
            close(sd, &sigma(&b.covariance), "fixed-lag σ");
            same_nis(nis, b.nis);
        }
    }
}

#[test]
fn bank_equals_one_library_filter_per_series_polynomial() {
    let d = data(1000, 2, 7);
    let missing = d.values.iter().filter(|v| v.is_nan()).count() as f64 / d.values.len() as f64;
    assert!((0.08..0.12).contains(&missing), "{missing}");
    equals_library(&polynomial(), &d, 5);
}

/// The polynomial model of `degree` on `axes` axes, the positions observed with a full `R`
/// (correlated components), white-noise driving.
fn polynomial_of(degree: usize, axes: usize) -> Model<PolynomialDynamics> {
    let n = (degree + 1) * axes;
    let h = DMatrix::from_fn(axes, n, |i, j| f64::from(i == j));
    let r = DMatrix::from_fn(
        axes,
        axes,
        |i, j| if i == j { 1.0 + 0.3 * i as f64 } else { 0.2 },
    );
    let x0 = DVector::zeros(n);
    let s0 = DMatrix::from_diagonal(&DVector::from_fn(n, |i, _| 100.0 / (1 + i / axes) as f64));
    let noise = WhiteNoiseDerivative::new(degree, axes, 0.05).unwrap();
    let dynamics = PolynomialDynamics::new(degree, axes);
    let obs = LinearObservation::new(h).unwrap();
    let bank = KalmanBank::new(dynamics, obs.clone(), r.clone(), x0.clone(), s0.clone())
        .unwrap()
        .with_process_noise(noise)
        .unwrap();
    let library = Box::new(move |t| {
        KalmanFilter::new(dynamics, obs.clone(), x0.clone(), s0.clone(), t)
            .unwrap()
            .with_process_noise(noise)
            .unwrap()
    });
    Model { bank, library, r }
}

/// Both sides of the bank's size dispatch: the fixed-size path at its largest (9 states, 3
/// components, so 1, 2 or 3 present) and the general path beyond it (10 states and 5
/// components; 4 components), each equal to the library's filter per series.
#[test]
fn bank_equals_the_library_on_both_sides_of_the_fixed_sizes() {
    for (degree, axes, seed) in [(2, 3, 21), (1, 5, 22), (0, 4, 23), (0, 1, 24)] {
        eprintln!("degree {degree}, {axes} axes");
        let d = data(60, axes, seed);
        equals_library(&polynomial_of(degree, axes), &d, 4);
    }
}

#[test]
fn bank_equals_one_library_filter_per_series_continuous() {
    equals_library(&singer(), &data(300, 1, 8), 3);
}

/// The bank over the series `cuts` apart (a batch each), its rows in order.
fn in_batches(
    bank: &KalmanBank<PolynomialDynamics>,
    d: &Data,
    cuts: &[usize],
    lag: usize,
) -> [BankRows; 3] {
    let p = bank.components();
    // Empty rows to start with: the first batch appended gives them their state dimension.
    let mut all: [BankRows; 3] = Default::default();
    let mut bounds = vec![0];
    bounds.extend(cuts.iter().copied());
    bounds.push(d.offsets.len() - 1);
    for w in bounds.windows(2) {
        let (a, b) = (d.offsets[w[0]], d.offsets[w[1]]);
        let offsets: Vec<usize> = d.offsets[w[0]..=w[1]].iter().map(|o| o - a).collect();
        let panel = Panel {
            offsets: &offsets,
            times: &d.times[a..b],
            values: &d.values[a * p..b * p],
        };
        let parts = [
            bank.filter(&panel).unwrap(),
            bank.smooth(&panel).unwrap(),
            bank.smooth_fixed_lag(&panel, lag).unwrap(),
        ];
        for (o, part) in all.iter_mut().zip(parts) {
            o.append(part);
        }
    }
    all
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn any_split_into_batches_gives_the_same_numbers(
        mut cuts in proptest::collection::vec(0usize..=200, 0..6),
        lag in 0usize..6,
    ) {
        cuts.sort_unstable();
        let d = data(200, 2, 11);
        let bank = polynomial().bank;
        let whole = in_batches(&bank, &d, &[], lag);
        let split = in_batches(&bank, &d, &cuts, lag);
        prop_assert_eq!(whole, split);
    }

    /// The lane path's own model (constant velocity, the position observed): batches of a
    /// few series each (fewer than a task's lanes, so series move between the lanes and the
    /// one-series path), the same numbers bit for bit.
    #[test]
    fn any_split_into_small_batches_gives_the_same_numbers_scalar(
        sizes in proptest::collection::vec(1usize..=9, 1..30),
    ) {
        let d = data(120, 1, 12);
        let bank = polynomial_of(1, 1).bank;
        let mut cuts = Vec::new();
        let mut at = 0;
        for size in sizes {
            at += size;
            if at < 120 {
                cuts.push(at);
            }
        }
        let whole = in_batches(&bank, &d, &[], 2);
        let split = in_batches(&bank, &d, &cuts, 2);
        prop_assert_eq!(whole, split);
    }
}

/// Every series in a bank of its own (the one-series path) against its rows in the whole
/// bank (in lanes with its neighbours), bit for bit, the filter and the RTS smoother: the
/// scalar observation (whole rows missing: the lanes' masks), two components (rows with one
/// missing: steps taken alone), the largest fixed size (9 states, 3 components).
#[test]
fn each_series_alone_gives_its_numbers_in_lanes() {
    alone_as_in_lanes(data, 31);
}

/// [`each_series_alone_gives_its_numbers_in_lanes`] on the data `make` gives (90 series), for
/// one, two and three components, with seeds from `seed`.
fn alone_as_in_lanes(make: fn(usize, usize, u64) -> Data, seed: u64) {
    for (model, p, seed) in [
        (polynomial_of(1, 1), 1, seed),
        (polynomial(), 2, seed + 1),
        (polynomial_of(2, 3), 3, seed + 2),
    ] {
        let d = make(90, p, seed);
        let bank = &model.bank;
        let whole = [
            bank.filter(&d.panel()).unwrap(),
            bank.smooth(&d.panel()).unwrap(),
        ];
        let cuts: Vec<usize> = (1..90).collect();
        let alone = in_batches(bank, &d, &cuts, 1);
        for (a, b) in whole.iter().zip(&alone) {
            assert_eq!(a, b, "p = {p}");
        }
    }
}

/// The lanes' straight path (constant steps, rows complete): each series alone (the
/// one-series path) gives its rows in the bank bit for bit, filter and smoother, and the bank
/// equals one library filter and smoother per series.
#[test]
fn the_lanes_straight_path_gives_each_series_its_numbers() {
    alone_as_in_lanes(data_steady, 41);
    equals_library(&polynomial_of(1, 1), &data_steady(200, 1, 44), 3);
}

/// The lane path's model on 1,000 series (irregular times, 10 % missing) against one library
/// filter and smoother per series.
#[test]
fn bank_equals_one_library_filter_per_series_scalar() {
    equals_library(&polynomial_of(1, 1), &data(1000, 1, 9), 3);
}

#[test]
fn the_stream_equals_the_batch_filter() {
    // Every series at its own times, fed a row of each at a time (a series without a row at
    // a step is given NaN for its time).
    let d = data(300, 2, 13);
    let bank = polynomial().bank;
    let batch = bank.filter(&d.panel()).unwrap();
    let series = d.offsets.len() - 1;
    let mut stream = bank.clone().stream(series);
    let longest = d.offsets.windows(2).map(|w| w[1] - w[0]).max().unwrap();
    let mut out = BankRows::default();
    for k in 0..longest {
        let mut times = vec![f64::NAN; series];
        let mut values = vec![0.0; series * 2];
        for s in 0..series {
            let row = d.offsets[s] + k;
            if row < d.offsets[s + 1] {
                times[s] = d.times[row];
                values[s * 2..s * 2 + 2].copy_from_slice(&d.values[row * 2..row * 2 + 2]);
            }
        }
        stream.update(&times, &values, &mut out).unwrap();
        for s in 0..series {
            let row = d.offsets[s] + k;
            if row < d.offsets[s + 1] {
                assert_eq!(out.row(s), batch.row(row), "series {s} row {k}");
            }
        }
    }
    assert_eq!(stream.bytes_per_series(), 8 * (4 + 16 + 1));
}

#[test]
fn bad_input_is_refused_naming_the_series_and_row() {
    let mut d = data(50, 2, 17);
    let bank = polynomial().bank;
    // An infinite value in series 30, its 4th row; a decreasing time in series 40.
    let row = d.offsets[30] + 3;
    d.values[row * 2] = f64::INFINITY;
    let back = d.offsets[40] + 6;
    d.times[back] = d.times[back - 1] - 1.0;
    for result in [
        bank.filter(&d.panel()),
        bank.smooth(&d.panel()),
        bank.smooth_fixed_lag(&d.panel(), 3),
    ] {
        match result {
            Err(Error::InChannel {
                channel: 30,
                source,
                ..
            }) => assert!(
                matches!(*source, Error::InBatch { index: 3, .. }),
                "{source}"
            ),
            other => panic!("{other:?}"),
        }
    }
    let bad_offsets = Panel {
        offsets: &[0, 5, 3],
        times: &d.times[..3],
        values: &d.values[..6],
    };
    assert!(bank.filter(&bad_offsets).is_err());
    let short = Panel {
        offsets: &[0, 3],
        times: &d.times[..3],
        values: &d.values[..5],
    };
    assert!(bank.filter(&short).is_err());
    // A nonlinear model is refused.
    struct Nonlinear;
    impl Dynamics for Nonlinear {
        fn dimension(&self) -> usize {
            2
        }
        fn propagate(
            &self,
            x: &DVector<f64>,
            a: f64,
            b: f64,
        ) -> Result<seqsmooth::model::dynamics::Propagation, Error> {
            PolynomialDynamics::new(1, 1).propagate(x, a, b)
        }
    }
    assert!(KalmanBank::new(
        Nonlinear,
        LinearObservation::value_of(2),
        DMatrix::identity(1, 1),
        DVector::zeros(2),
        DMatrix::identity(2, 2),
    )
    .is_err());
}
