//! `seqsmooth::persist`: every filter cut at a random sample, saved, restored and continued,
//! equals the unbroken filter continued bit for bit (every output's Debug form, which prints
//! each double's shortest round-trip digits, and the whole saved state afterwards, byte for
//! byte); the envelope refuses a truncated input, a changed byte, another type's state, a newer
//! version, and a body whose numbers break the type's invariants.

use nalgebra::{DMatrix, DVector};
use proptest::prelude::*;
use seqsmooth::discount::Discount;
use seqsmooth::error::{Error, ErrorKind};
use seqsmooth::kalman::bayes::BayesFilter;
use seqsmooth::kalman::discrete::{LinearFixedLag, LinearKalmanFilter, StepMatrices};
use seqsmooth::kalman::filter::KalmanFilter;
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::kalman::UnscentedKalmanFilter;
use seqsmooth::model::continuous::ContinuousModel;
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
use seqsmooth::model::observation::LinearObservation;
use seqsmooth::model::radar::Radar;
use seqsmooth::paml::{OnlineSmoother, SmootherGains};
use seqsmooth::persist::{from_bytes, to_bytes, Persist};
use seqsmooth::polynomial::automatic::{AutomaticFilter, MAX_MEMORY_LEVELS};
use seqsmooth::polynomial::bank::FadingBank;
use seqsmooth::polynomial::spec::{AnyFilter, FilterKind, FilterSpec};
use seqsmooth::track::{RadarTracker, TrackMethod};
use seqsmooth::{Engine, FadingMemory, PolynomialFilter};
use std::sync::Arc;

/// Irregular times and values from `seed` (a small LCG: the test's data are its own).
fn data(seed: u64, n: usize) -> Vec<(f64, f64)> {
    let mut s = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    let mut next = move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut t = 0.0;
    (0..n)
        .map(|_| {
            t += 0.3 + 1.4 * next();
            (t, (0.3 * t).sin() + 0.1 * (next() - 0.5))
        })
        .collect()
}

/// Runs `step` over `rows[..cut]`, saves and restores the filter, runs both over the rest:
/// their outputs and their final states are the same bits.
fn cut_and_continue<T: Persist>(
    mut f: T,
    rows: &[(f64, f64)],
    cut: usize,
    step: impl Fn(&mut T, usize, (f64, f64)) -> String,
) {
    for (k, &r) in rows[..cut].iter().enumerate() {
        step(&mut f, k, r);
    }
    let bytes = to_bytes(&f).unwrap();
    let mut g: T = from_bytes(&bytes).unwrap();
    for (k, &r) in rows.iter().enumerate().skip(cut) {
        assert_eq!(step(&mut f, k, r), step(&mut g, k, r), "row {k}");
    }
    assert_eq!(to_bytes(&f).unwrap(), to_bytes(&g).unwrap());
}

fn measurement(t: f64, y: f64, missing: bool) -> Measurement {
    Measurement {
        time: t,
        values: vec![(!missing).then_some(y)],
        noise: NoiseCovariance::Variances(vec![0.01]),
    }
}

fn position() -> LinearObservation {
    LinearObservation::new(DMatrix::from_row_slice(1, 2, &[1.0, 0.0])).unwrap()
}

/// A Kalman filter of two states observing the first, at its prior `(0, I)` at time 0.
fn at_rest<D: seqsmooth::model::dynamics::Dynamics>(d: D) -> KalmanFilter<D, LinearObservation> {
    KalmanFilter::new(
        d,
        position(),
        DVector::zeros(2),
        DMatrix::identity(2, 2),
        0.0,
    )
    .unwrap()
}

fn polynomial(kind: FilterKind, degree: usize, engine: Engine) -> AnyFilter {
    FilterSpec {
        theta: (kind != FilterKind::Expanding && kind != FilterKind::Fixed).then_some(0.9),
        tau: (kind != FilterKind::Expanding && kind != FilterKind::Fixed).then_some(1.0),
        window: (kind == FilterKind::Fixed).then_some(degree + 5),
        engine,
        sigma: Some(0.1),
        ..FilterSpec::new(kind, degree)
    }
    .build()
    .unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn polynomial_filters_resume_bit_for_bit(
        seed in 0u64..1_000_000, n in 10usize..120, cut in 1usize..120, degree in 0usize..4,
        kind in 0usize..4, gain in any::<bool>(),
    ) {
        let kind = [FilterKind::Expanding, FilterKind::Fading, FilterKind::Fixed,
            FilterKind::Automatic][kind];
        let engine = if gain && kind != FilterKind::Fixed { Engine::Gain } else { Engine::Exact };
        let degree = if kind == FilterKind::Automatic { degree.max(1) } else { degree };
        let rows = data(seed, n);
        cut_and_continue(polynomial(kind, degree, engine), &rows, cut.min(n - 1), |f, _, (t, y)| {
            let _ = f.update(t, y);
            format!("{:?}", f.try_estimate())
        });
    }

    #[test]
    fn kalman_filters_resume_bit_for_bit(
        seed in 0u64..1_000_000, n in 5usize..80, cut in 1usize..80, fading in any::<bool>(),
    ) {
        let rows = data(seed, n);
        let cut = cut.min(n - 1);
        let missing = |k: usize| (seed as usize + k * 7).is_multiple_of(5);
        let x0 = DVector::zeros(2);
        let p0 = DMatrix::identity(2, 2) * 100.0;
        let mut kf = KalmanFilter::new(PolynomialDynamics::new(1, 1), position(), x0.clone(), p0.clone(), 0.0)
            .unwrap()
            .with_process_noise(WhiteNoiseDerivative::new(1, 1, 0.05).unwrap())
            .unwrap();
        if fading {
            kf = kf.with_fading(Discount::PerTime { theta: 0.9, tau: 1.0 }).unwrap();
        }
        cut_and_continue(kf, &rows, cut, |f, k, (t, y)| {
            format!("{:?} {:?} {:?}", f.update(&measurement(t, y, missing(k))), f.state(), f.covariance())
        });
        let mut bayes = BayesFilter::new(PolynomialDynamics::new(1, 1), position(), 0.0).unwrap();
        if fading {
            bayes = bayes.with_fading(Discount::PerUpdate { theta: 0.9 }).unwrap();
        }
        cut_and_continue(bayes, &rows, cut, |f, k, (t, y)| {
            format!("{:?} {:?} {:?}", f.update(&measurement(t, y, missing(k))), f.estimate(), f.covariance())
        });
        let continuous = ContinuousModel::nearly_constant_velocity(&[0.05]).unwrap();
        let ckf = KalmanFilter::new(continuous.clone(), position(), x0.clone(), p0.clone(), 0.0)
            .unwrap()
            .with_process_noise(continuous)
            .unwrap();
        cut_and_continue(ckf, &rows, cut, |f, k, (t, y)| {
            format!("{:?} {:?} {:?}", f.update(&measurement(t, y, missing(k))), f.state(), f.covariance())
        });
        let ukf = UnscentedKalmanFilter::new(PolynomialDynamics::new(1, 1), position(), x0, p0, 0.0)
            .unwrap()
            .with_process_noise(WhiteNoiseDerivative::new(1, 1, 0.05).unwrap())
            .unwrap();
        cut_and_continue(ukf, &rows, cut, |f, k, (t, y)| {
            format!("{:?} {:?} {:?}", f.update(&measurement(t, y, missing(k))), f.state(), f.covariance())
        });
        let dt = 0.5 + rows[0].0;
        let linear = LinearKalmanFilter::new(
            DVector::zeros(2),
            DMatrix::identity(2, 2) * 10.0,
            DMatrix::from_row_slice(2, 2, &[1.0, dt, 0.0, 1.0]),
            DMatrix::from_row_slice(1, 2, &[1.0, 0.0]),
            DMatrix::identity(2, 2) * 0.01,
            DMatrix::identity(1, 1) * 0.25,
        )
        .unwrap();
        let z = |k: usize, y: f64| if missing(k) { f64::NAN } else { y };
        cut_and_continue(linear.clone(), &rows, cut, |f, k, (_, y)| {
            let none = StepMatrices::default();
            format!("{:?} {:?} {:?}", f.predict(&none), f.update(&[z(k, y)], &none), f.covariance())
        });
        cut_and_continue(LinearFixedLag::new(&linear, 1 + (seed as usize) % 4), &rows, cut, |f, k, (_, y)| {
            format!("{:?}", f.push(&[z(k, y)], &StepMatrices::default()))
        });
    }

    #[test]
    fn banks_tracker_and_online_smoother_resume_bit_for_bit(
        seed in 0u64..1_000_000, n in 12usize..60, cut in 1usize..60, method in 0usize..4,
    ) {
        let rows = data(seed, n);
        let cut = cut.min(n - 1);
        cut_and_continue(FadingBank::new(1, 0.8, 1.0, 3).unwrap(), &rows, cut, |f, _, (t, y)| {
            format!("{:?} {:?}", f.update(&[y, t, y * t]), f.estimate(2))
        });
        let method = [
            TrackMethod::Kalman { q: Some(0.5) },
            TrackMethod::Kalman { q: None },
            TrackMethod::Window { window: 8 },
            TrackMethod::Fading(Some(Discount::PerTime { theta: 0.8, tau: 1.0 })),
        ][method];
        let tracker = RadarTracker::new(Radar::new([0.0; 3], 6).unwrap(), method).unwrap();
        cut_and_continue(tracker, &rows, cut, |f, k, (t, y)| {
            let s = t + 100.0 * y;
            let (x, v, z) = (20_000.0 + 150.0 * s, -8_000.0 + 60.0 * s, 3_000.0 + y);
            let r = (x * x + v * v + z * z).sqrt();
            let m = Measurement {
                time: t,
                values: vec![Some(r), (k % 7 != 3).then_some(v.atan2(x)), Some((z / r).asin())],
                noise: NoiseCovariance::Variances(vec![100.0, 1e-6, 1e-6]),
            };
            format!("{:?}", f.push(&m))
        });
        let times: Vec<f64> = rows.iter().map(|r| r.0).collect();
        let gains = SmootherGains::new(&times, &vec![0.1; n], 2).unwrap();
        cut_and_continue(OnlineSmoother::new(Arc::new(gains)), &rows, cut, |f, _, (_, y)| {
            format!("{:?} {:?}", f.push(y), f.polynomial_samples())
        });
    }
}

fn damaged(e: Error) -> String {
    assert_eq!(e.kind(), ErrorKind::DamagedState, "{e}");
    e.to_string()
}

fn a_filter() -> AnyFilter {
    let mut f = polynomial(FilterKind::Fading, 2, Engine::Exact);
    for (t, y) in data(3, 40) {
        f.update(t, y).unwrap();
    }
    f
}

#[test]
fn every_truncation_and_every_changed_byte_is_refused() {
    let bytes = to_bytes(&a_filter()).unwrap();
    for n in 0..bytes.len() {
        damaged(from_bytes::<AnyFilter>(&bytes[..n]).unwrap_err());
    }
    for i in 0..bytes.len() {
        for bit in 0..8 {
            let mut b = bytes.clone();
            b[i] ^= 1 << bit;
            damaged(from_bytes::<AnyFilter>(&b).unwrap_err());
        }
    }
    let mut longer = bytes.clone();
    longer.push(0);
    assert!(damaged(from_bytes::<AnyFilter>(&longer).unwrap_err()).contains("trailing"));
}

#[test]
fn another_type_and_a_newer_version_are_refused_by_name() {
    let bytes = to_bytes(&a_filter()).unwrap();
    let why = damaged(from_bytes::<FadingBank>(&bytes).unwrap_err());
    assert!(
        why.contains("the state of a AnyFilter, not of a FadingBank"),
        "{why}"
    );
    let mut newer = bytes.clone();
    newer[8] = 3;
    let why = damaged(from_bytes::<AnyFilter>(&newer).unwrap_err());
    assert!(why.contains("format version 3"), "{why}");
    let why = damaged(from_bytes::<AnyFilter>(b"not a saved state at all").unwrap_err());
    assert!(why.contains("tag"), "{why}");
}

/// The envelope around `body` for type `name` with a valid checksum: what a crafted input
/// looks like.
fn envelope(name: &str, body: &[u8]) -> Vec<u8> {
    let mut out = b"SEQSMST\0".to_vec();
    out.extend_from_slice(&seqsmooth::persist::FORMAT_VERSION.to_le_bytes());
    out.push(name.len() as u8);
    out.extend_from_slice(name.as_bytes());
    out.extend_from_slice(&(body.len() as u64).to_le_bytes());
    let mut crc = crc32fast::Hasher::new();
    crc.update(&out);
    crc.update(body);
    out.extend_from_slice(&crc.finalize().to_le_bytes());
    out.extend_from_slice(body);
    out
}

/// A CBOR map's entries.
type Entries = Vec<(ciborium::Value, ciborium::Value)>;

#[test]
fn a_crafted_body_breaking_the_invariants_is_refused() {
    type Kf = KalmanFilter<PolynomialDynamics, LinearObservation>;
    let kf: Kf = at_rest(PolynomialDynamics::new(1, 1));
    let name = <Kf as Persist>::name();
    let good = to_bytes(&kf).unwrap();
    let body = &good[good.len() - (good.len() - (8 + 2 + 1 + name.len() + 8 + 4))..];
    assert_eq!(
        envelope(&name, body),
        good,
        "the test's envelope is the library's"
    );
    // Decode the body as CBOR, break one invariant, encode it again with a valid checksum.
    let value: ciborium::Value = ciborium::from_reader(body).unwrap();
    let edit = |f: &dyn Fn(&mut Entries)| {
        let mut v = value.clone();
        f(v.as_map_mut().unwrap());
        let mut b = Vec::new();
        ciborium::into_writer(&v, &mut b).unwrap();
        from_bytes::<Kf>(&envelope(&name, &b)).unwrap_err()
    };
    let field = |m: &mut Entries, key: &str| -> usize {
        m.iter()
            .position(|(k, _)| k.as_text() == Some(key))
            .unwrap()
    };
    // the covariance not positive semi-definite: its first entry −1
    let why = damaged(edit(&|m| {
        let i = field(m, "covariance");
        let data = m[i].1.as_array_mut().unwrap()[0].as_array_mut().unwrap();
        data[0] = ciborium::Value::Float(-1.0);
    }));
    assert!(why.contains("covariance"), "{why}");
    // the state of the wrong length
    let why = damaged(edit(&|m| {
        let i = field(m, "state");
        let data = m[i].1.as_array_mut().unwrap()[0].as_array_mut().unwrap();
        data.push(ciborium::Value::Float(0.0));
    }));
    assert!(why.contains("decode") || why.contains("state"), "{why}");
    // a NaN time
    let why = damaged(edit(&|m| {
        let i = field(m, "time");
        m[i].1 = ciborium::Value::Float(f64::NAN);
    }));
    assert!(why.contains("time"), "{why}");
}

#[test]
fn a_continuous_model_not_matching_its_matrices_is_refused() {
    type Kf = KalmanFilter<ContinuousModel, LinearObservation>;
    let kf: Kf = at_rest(ContinuousModel::nearly_constant_velocity(&[0.05]).unwrap());
    let name = <Kf as Persist>::name();
    assert_eq!(name, "KalmanFilter<ContinuousModel, LinearObservation>");
    let good = to_bytes(&kf).unwrap();
    let body = &good[8 + 2 + 1 + name.len() + 8 + 4..];
    let value: ciborium::Value = ciborium::from_reader(body).unwrap();
    let edit = |f: &dyn Fn(&mut ciborium::Value)| {
        let mut v = value.clone();
        let m = v.as_map_mut().unwrap();
        let i = m
            .iter()
            .position(|(k, _)| k.as_text() == Some("dynamics"))
            .unwrap();
        f(&mut m[i].1);
        let mut b = Vec::new();
        ciborium::into_writer(&v, &mut b).unwrap();
        from_bytes::<Kf>(&envelope(&name, &b)).unwrap_err()
    };
    let entry = |d: &mut ciborium::Value, key: &str| -> usize {
        d.as_map()
            .unwrap()
            .iter()
            .position(|(k, _)| k.as_text() == Some(key))
            .unwrap()
    };
    // ‖A‖₁ not A's (it scales each step's series)
    let why = damaged(edit(&|d| {
        let i = entry(d, "norm");
        d.as_map_mut().unwrap()[i].1 = ciborium::Value::Float(1e300);
    }));
    assert!(why.contains("continuous model"), "{why}");
    // Q_c not positive semi-definite: its first entry −1
    let why = damaged(edit(&|d| {
        let i = entry(d, "qc");
        let data = d.as_map_mut().unwrap()[i].1.as_array_mut().unwrap()[0]
            .as_array_mut()
            .unwrap();
        data[0] = ciborium::Value::Float(-1.0);
    }));
    assert!(why.contains("continuous model"), "{why}");
}

/// A Kalman filter and an unscented filter saved over the stand-ins of their models
/// (`with_models` to `DynamicsLeftOut`/`ObservationLeftOut`, a front end's own driving noise
/// taken out) and restored over their models again continue bit for bit; a stand-in cannot be
/// run, and a model of another shape is refused.
#[test]
fn filters_saved_with_their_models_left_out_resume_bit_for_bit() {
    use seqsmooth::model::observation::Angles;
    use seqsmooth::persist::{DynamicsLeftOut, ObservationLeftOut};
    let rows = data(11, 40);
    let missing = |k: usize| k % 6 == 2;
    let run = |f: &mut KalmanFilter<PolynomialDynamics, LinearObservation>, from: usize| {
        let mut out = Vec::new();
        for (k, &(t, y)) in rows.iter().enumerate().skip(from) {
            out.push(format!(
                "{:?} {:?}",
                f.update(&measurement(t, y, missing(k))),
                f.covariance()
            ));
        }
        out
    };
    let stand_ins = || {
        (
            DynamicsLeftOut::new(2),
            ObservationLeftOut::new(2, Angles::new(1, &[]).unwrap()),
        )
    };
    for cut in [1, 17, 39] {
        let mut f = at_rest(PolynomialDynamics::new(1, 1))
            .with_process_noise(WhiteNoiseDerivative::new(1, 1, 0.05).unwrap())
            .unwrap();
        for (k, &(t, y)) in rows.iter().enumerate().take(cut) {
            f.update(&measurement(t, y, missing(k))).unwrap();
        }
        let mut bare = f.clone();
        let noise = bare.take_process_noise();
        assert!(noise.is_some());
        let (d, o) = stand_ins();
        let bare = bare.with_models(d, o).unwrap();
        let mut back: KalmanFilter<DynamicsLeftOut, ObservationLeftOut> =
            from_bytes(&to_bytes(&bare).unwrap()).unwrap();
        assert!(back.predict(1e9).is_err(), "a stand-in runs");
        assert!(back
            .clone()
            .with_models(PolynomialDynamics::new(2, 1), position())
            .is_err());
        let mut g = back
            .with_models(PolynomialDynamics::new(1, 1), position())
            .unwrap();
        g.set_process_noise(WhiteNoiseDerivative::new(1, 1, 0.05).unwrap())
            .unwrap();
        assert_eq!(run(&mut f, cut), run(&mut g, cut));
    }
    let mut u = UnscentedKalmanFilter::new(
        PolynomialDynamics::new(1, 1),
        position(),
        DVector::zeros(2),
        DMatrix::identity(2, 2) * 100.0,
        0.0,
    )
    .unwrap();
    for (k, &(t, y)) in rows.iter().enumerate().take(20) {
        u.update(&measurement(t, y, missing(k))).unwrap();
    }
    let (d, o) = stand_ins();
    let bare = u.clone().with_models(d, o).unwrap();
    let back: UnscentedKalmanFilter<DynamicsLeftOut, ObservationLeftOut> =
        from_bytes(&to_bytes(&bare).unwrap()).unwrap();
    let mut v = back
        .with_models(PolynomialDynamics::new(1, 1), position())
        .unwrap();
    for (k, &(t, y)) in rows.iter().enumerate().skip(20) {
        let m = measurement(t, y, missing(k));
        assert_eq!(format!("{:?}", u.update(&m)), format!("{:?}", v.update(&m)));
        assert_eq!(u.covariance(), v.covariance());
    }
}

/// A sliding Gauss–Newton fit cut anywhere, saved and restored, gives the unbroken fit's
/// corrections bit for bit.
#[test]
fn a_sliding_fit_resumes_bit_for_bit() {
    use seqsmooth::estimate::gauss_newton::{Epoch, GaussNewton};
    use seqsmooth::estimate::sliding::{Fitter, SlidingFit};
    let rows = data(5, 30);
    for (cut, epoch) in [(2, Epoch::End), (9, Epoch::Centre), (25, Epoch::End)] {
        let fit = SlidingFit::polynomial(2, 6, epoch, GaussNewton::default()).unwrap();
        cut_and_continue(Fitter::Polynomial(fit), &rows, cut, |f, k, (t, y)| {
            format!("{:?}", f.push_finite(measurement(t, y, k % 7 == 3)))
        });
    }
}

/// A saved `Information` whose numbers break its invariants (a valid checksum): a prior
/// without σ, moments without samples, and moments that are no Gram matrix's are refused.
#[test]
fn a_crafted_information_is_refused() {
    use seqsmooth::polynomial::merge::Information;
    let mut info = Information::new(2, 0.0, 10.0, None).unwrap();
    let t: Vec<f64> = (0..40).map(|k| 0.25 * f64::from(k)).collect();
    let y: Vec<f64> = t.iter().map(|t| 1.0 + t * (0.5 - 0.01 * t)).collect();
    info.reduce(&t, &y).unwrap();
    let name = <Information as Persist>::name();
    let good = to_bytes(&info).unwrap();
    let body = &good[8 + 2 + 1 + name.len() + 8 + 4..];
    assert_eq!(envelope(&name, body), good);
    let value: ciborium::Value = ciborium::from_reader(body).unwrap();
    let edit = |f: &dyn Fn(&mut Entries)| {
        let mut v = value.clone();
        f(v.as_map_mut().unwrap());
        let mut b = Vec::new();
        ciborium::into_writer(&v, &mut b).unwrap();
        from_bytes::<Information>(&envelope(&name, &b))
    };
    let field = |m: &mut Entries, key: &str| -> usize {
        m.iter()
            .position(|(k, _)| k.as_text() == Some(key))
            .unwrap()
    };
    // Unchanged, the body decodes (the edits below are what is refused).
    assert!(edit(&|_| {}).is_ok());
    let why = damaged(
        edit(&|m| {
            let i = field(m, "prior");
            m[i].1 = ciborium::Value::Bool(true);
        })
        .unwrap_err(),
    );
    assert!(why.contains("prior"), "{why}");
    let why = damaged(
        edit(&|m| {
            let i = field(m, "samples");
            m[i].1 = ciborium::Value::Integer(0.into());
        })
        .unwrap_err(),
    );
    assert!(why.contains("without samples"), "{why}");
    let why = damaged(
        edit(&|m| {
            let i = field(m, "moments");
            let first_off_diagonal = m[i].1.as_array_mut().unwrap()[1].as_array_mut().unwrap();
            first_off_diagonal[0] = ciborium::Value::Float(1e200);
        })
        .unwrap_err(),
    );
    assert!(why.contains("Gram"), "{why}");
}

/// The CBOR body of a saved `AutomaticFilter` and the filter back from an edited body (with a
/// valid checksum: what a crafted or an old saved state looks like).
fn automatic_body(f: &AutomaticFilter) -> ciborium::Value {
    let name = <AutomaticFilter as Persist>::name();
    let bytes = to_bytes(f).unwrap();
    let body = &bytes[8 + 2 + 1 + name.len() + 8 + 4..];
    assert_eq!(
        envelope(&name, body),
        bytes,
        "the test's envelope is the library's"
    );
    ciborium::from_reader(body).unwrap()
}

fn automatic_from(body: &ciborium::Value) -> Result<AutomaticFilter, Error> {
    let mut b = Vec::new();
    ciborium::into_writer(body, &mut b).unwrap();
    from_bytes::<AutomaticFilter>(&envelope(&<AutomaticFilter as Persist>::name(), &b))
}

/// Why the edited body is refused (it must be).
fn automatic_refused(body: &ciborium::Value) -> String {
    match automatic_from(body) {
        Ok(_) => panic!("a damaged AutomaticFilter was accepted"),
        Err(e) => damaged(e),
    }
}

/// The entry `key` of the CBOR map `v`.
fn entry<'a>(v: &'a mut ciborium::Value, key: &str) -> &'a mut ciborium::Value {
    let m = v.as_map_mut().unwrap();
    let i = m
        .iter()
        .position(|(k, _)| k.as_text() == Some(key))
        .unwrap_or_else(|| panic!("no {key}"));
    &mut m[i].1
}

/// The saved state's shorter memories (`fresh`: those a restart starts from).
fn shorter(body: &mut ciborium::Value, fresh: bool) -> &mut Vec<ciborium::Value> {
    let memories = entry(entry(body, "state"), "memories");
    let memories = if fresh {
        entry(memories, "fresh")
    } else {
        memories
    };
    entry(memories, "shorter").as_array_mut().unwrap()
}

/// A polynomial track with a little noise: every sample accepted, no restart.
fn gentle(n: usize) -> Vec<(f64, f64)> {
    data(5, n)
        .into_iter()
        .map(|(t, e)| {
            (
                t,
                1.0 + 0.5 * t + 0.02 * t * t + 0.1 * (e - (0.3 * t).sin()),
            )
        })
        .collect()
}

#[test]
fn an_automatic_state_with_more_shorter_memories_than_the_most_is_refused() {
    // A state saved when `memory_levels` went up to 16 (θ ≥ 0.9866 kept 9 to 16 of them):
    // `choose` has room for MAX_MEMORY_LEVELS + 1 positions and would index past them.
    let mut f = AutomaticFilter::new(2, 0.999, 1.0).unwrap();
    for (t, y) in gentle(60) {
        f.update(t, y).unwrap();
    }
    let good = automatic_body(&f);
    automatic_from(&good).unwrap();
    let n = MAX_MEMORY_LEVELS + 4;
    for fresh in [false, true] {
        let mut body = good.clone();
        let s = shorter(&mut body, fresh);
        let one = s[0].clone();
        s.resize(n, one);
        let why = automatic_refused(&body);
        assert!(why.contains(&format!("{n} shorter memories")), "{why}");
    }
    // … and with the setting it was saved with: refused as out of range.
    let mut body = good.clone();
    *entry(entry(entry(&mut body, "state"), "cfg"), "memory_levels") = (n as u64).into();
    let why = automatic_refused(&body);
    assert!(
        why.contains("memory levels") || why.contains("memory_levels"),
        "{why}"
    );
    // A companion of the wrong degree: the final degree's filter in its place.
    let mut body = good.clone();
    let s = shorter(&mut body, false);
    let fading = entry(&mut s[0], "fading").clone();
    *entry(&mut s[0], "upper") = fading;
    let why = automatic_refused(&body);
    assert!(why.contains("degree 2, 3 expected"), "{why}");
}

#[test]
fn an_automatic_state_saved_with_the_old_ladder_keeps_it() {
    // A filter saved before the ladder became θ^(4^j) holds θ², θ⁴, θ⁸: restored, it keeps
    // running them (each an exact fading memory on the accepted samples).
    let (m, theta, tau) = (2, 0.95, 1.0);
    let f = AutomaticFilter::new(m, theta, tau)
        .unwrap()
        .with_memory_levels(3)
        .unwrap();
    let unit = |degree: usize, th: f64| {
        FadingMemory::new(degree, th, tau, Engine::Exact)
            .unwrap()
            .with_noise_sigma(1.0)
            .unwrap()
    };
    let old: Vec<f64> = [2, 4, 8].iter().map(|&p| theta.powi(p)).collect();
    let mut body = automatic_body(&f);
    for fresh in [false, true] {
        let s = shorter(&mut body, fresh);
        assert_eq!(s.len(), 3);
        for (entry_j, &th) in s.iter_mut().zip(&old) {
            *entry(entry_j, "fading") = ciborium::Value::serialized(&unit(m, th)).unwrap();
            *entry(entry_j, "upper") = ciborium::Value::serialized(&unit(m + 1, th)).unwrap();
        }
    }
    let mut g = automatic_from(&body).unwrap();
    // The companions (degree m + 1) run on every sample; each memory's degree-m filter is
    // their leading block, taken when it is in use or compared (`polynomial/automatic/
    // memory.rs`; checked against the filter updated itself in `leading_tests.rs`).
    let mut oracle: Vec<_> = old.iter().map(|&th| unit(m + 1, th)).collect();
    for (t, y) in gentle(200) {
        g.update(t, y).unwrap();
        for o in &mut oracle {
            o.update(t, y).unwrap();
        }
    }
    assert_eq!(
        (g.rejected(), g.restarts()),
        (0, 0),
        "every sample accepted"
    );
    let mut after = automatic_body(&g);
    for fresh in [false, true] {
        let thetas: Vec<f64> = shorter(&mut after, fresh)
            .iter_mut()
            .map(|s| {
                let th = entry(entry(s, "fading"), "theta");
                th.as_float().unwrap()
            })
            .collect();
        assert_eq!(thetas, old, "the old ladder kept (fresh: {fresh})");
    }
    // The running ones are the exact fading memories of θ², θ⁴, θ⁸ on the same samples.
    let running = shorter(&mut after, false);
    for (s, o) in running.iter_mut().zip(&oracle) {
        let upper: FadingMemory = entry(s, "upper").deserialized().unwrap();
        assert!(o.estimate().is_some());
        assert_eq!(upper.estimate(), o.estimate());
    }
}

#[test]
fn an_automatic_state_of_version_1_reads_as_before() {
    // Version 1 had no `stale` flag (every shorter memory's filter was current): such a body,
    // the key taken out of a state saved mid-run, resumes exactly as the same body with the
    // flag written `false`.
    let mut f = AutomaticFilter::new(2, 0.95, 1.0).unwrap();
    let samples = gentle(300);
    for &(t, y) in &samples[..150] {
        f.update(t, y).unwrap();
    }
    let mut written = automatic_body(&f);
    let mut left_out = automatic_body(&f);
    let mut flags = 0;
    for fresh in [false, true] {
        for s in shorter(&mut written, fresh).iter_mut() {
            *entry(s, "stale") = ciborium::Value::Bool(false);
            flags += 1;
        }
        for s in shorter(&mut left_out, fresh).iter_mut() {
            let map = s.as_map_mut().unwrap();
            map.retain(|(k, _)| k.as_text() != Some("stale"));
            assert!(map.iter().all(|(k, _)| k.as_text() != Some("stale")));
        }
    }
    assert!(flags > 0, "the state has shorter memories");
    let mut a = automatic_from(&written).unwrap();
    let mut b = automatic_from(&left_out).unwrap();
    for &(t, y) in &samples[150..] {
        assert_eq!(
            format!("{:?}", a.update(t, y).unwrap()),
            format!("{:?}", b.update(t, y).unwrap())
        );
    }
    assert_eq!(to_bytes(&a).unwrap(), to_bytes(&b).unwrap());
}

#[test]
fn an_automatic_state_whose_shorter_pair_differs_is_refused() {
    // `Shorter::sync` takes a memory's filter from its companion's leading block; a crafted
    // pair of different discounts would leave the filter behind for good.
    let mut f = AutomaticFilter::new(2, 0.95, 1.0).unwrap();
    for (t, y) in gentle(20) {
        f.update(t, y).unwrap();
    }
    let mut body = automatic_body(&f);
    let s = &mut shorter(&mut body, false)[0];
    let other = FadingMemory::new(3, 0.5, 1.0, Engine::Exact)
        .unwrap()
        .with_noise_sigma(1.0)
        .unwrap();
    *entry(s, "upper") = ciborium::Value::serialized(&other).unwrap();
    let why = automatic_refused(&body);
    assert!(why.contains("differ in discount"), "{why}");
}
