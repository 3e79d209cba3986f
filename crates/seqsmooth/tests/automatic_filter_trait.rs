//! The automatic filter through [`PolynomialFilter`]: the same estimates as through its own
//! methods, exactly (bit for bit); batches equal per-sample updates; a `Box<dyn
//! PolynomialFilter>` holding it; and the builders equal the configuration they record.
//!
//! Scenario: degree 2, θ = 0.95 per τ = 1, irregular steps (1 ± 40%), Gaussian noise σ = 0.5,
//! a 20σ outlier every 97 samples, an unmodelled cubic from t = 300 on and a 20σ step at
//! t = 200 (so the gate, the misfit test, the restart and the ladder all act: the adaptive
//! memory follows the cubic without a restart, the step restarts it), 600 samples.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use seqsmooth::error::Param;
use seqsmooth::polynomial::automatic::{
    AutoConfig, AutoOutput, AutomaticFilter, MisfitResponse, NoiseSource, OutlierRule, Phase,
};
use seqsmooth::polynomial::SwitchRule;
use seqsmooth::{DiscountMode, Engine, Error, ExpandingMemory, PolynomialFilter};

const N: usize = 600;

fn scenario(seed: u64) -> (Vec<f64>, Vec<f64>) {
    let mut rng = StdRng::seed_from_u64(seed);
    let noise = Normal::new(0.0, 0.5).unwrap();
    let mut t: f64 = 0.0;
    let mut times = Vec::with_capacity(N);
    let mut values = Vec::with_capacity(N);
    for n in 0..N {
        t += rng.gen_range(0.6..1.4);
        let trend = 3.0 - 0.2 * t + 0.004 * t * t;
        let manoeuvre = if t > 300.0 {
            1e-4 * (t - 300.0).powi(3)
        } else {
            0.0
        };
        let outlier = if n % 97 == 50 { 10.0 } else { 0.0 };
        let step = if t > 200.0 { 10.0 } else { 0.0 };
        times.push(t);
        values.push(trend + manoeuvre + step + outlier + noise.sample(&mut rng));
    }
    (times, values)
}

/// Filters built three ways: known σ, estimated σ from differences, estimated σ from
/// innovations with Reyneke's gate on the gain engine.
fn filters() -> Vec<AutomaticFilter> {
    let base = || AutomaticFilter::new(2, 0.95, 1.0).unwrap();
    vec![
        base().with_noise_sigma(0.5).unwrap(),
        base(),
        base()
            .with_noise_source(NoiseSource::Innovations { window: Some(100) })
            .unwrap()
            .with_outlier_rule(OutlierRule::reyneke())
            .unwrap()
            .with_engine(Engine::Gain)
            .unwrap(),
    ]
}

/// Same bits, NaN included.
fn same(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

#[test]
fn trait_gives_the_same_estimates_as_the_own_methods() {
    let (times, values) = scenario(1);
    for own in filters() {
        let mut own = own;
        let mut via: Box<dyn PolynomialFilter> = Box::new(own.clone());
        let (mut outliers, mut restarts, mut settling) = (0, 0, 0);
        for (&t, &y) in times.iter().zip(&values) {
            let out: AutoOutput = own.update(t, y).unwrap();
            PolynomialFilter::update(via.as_mut(), t, y).unwrap();
            assert_eq!(own.last_output(), Some(&out));
            assert_eq!(via.estimate(), own.estimate());
            assert_eq!(via.estimate_at(t + 0.5), own.estimate_at(t + 0.5));
            assert_eq!(via.estimate_at(t - 2.0), own.estimate_at(t - 2.0));
            assert_eq!(via.samples(), own.samples());
            assert_eq!(via.last_time(), own.last_time());
            assert_eq!(via.last_time(), Some(t));
            assert_eq!(via.degree(), 2);
            assert_eq!(via.is_determined(), own.estimate().is_some());
            outliers += out.outlier as usize;
            restarts += out.restart as usize;
            settling += (out.phase == Phase::Settling) as usize;
        }
        // the scenario exercises the gate, the restart and the ladder
        assert!(outliers >= 3, "{outliers} outliers");
        assert!(restarts >= 1, "{restarts} restarts");
        assert!(settling >= 1, "{settling} settling samples");
    }
}

#[test]
fn batches_equal_per_sample_updates() {
    let (times, values) = scenario(2);
    for reference in filters() {
        let mut one = reference.clone();
        let outputs: Vec<AutoOutput> = times
            .iter()
            .zip(&values)
            .map(|(&t, &y)| one.update(t, y).unwrap())
            .collect();

        // update_many, in uneven batches
        let mut many = reference.clone();
        let mut start = 0;
        for len in [1, 7, 100, 250, 242] {
            many.update_many(&times[start..start + len], &values[start..start + len])
                .unwrap();
            start += len;
            assert_eq!(many.last_output(), Some(&outputs[start - 1]));
        }
        assert_eq!(start, N);
        assert_eq!(many.estimate(), one.estimate());
        assert_eq!(many.samples(), one.samples());
        assert_eq!(many.rejected(), one.rejected());
        assert_eq!(many.restarts(), one.restarts());

        // update_many_into: each row is the sample's own output, NaN above its degree
        let mut into = reference.clone();
        let mut rows = vec![0.0; N * 3];
        into.update_many_into(&times, &values, &mut rows).unwrap();
        for (i, out) in outputs.iter().enumerate() {
            let mut want = vec![f64::NAN; 3];
            if let Some(d) = out.derivatives() {
                want[..d.len()].copy_from_slice(d);
            }
            assert!(same(&rows[3 * i..3 * i + 3], &want), "row {i}");
        }
        assert_eq!(into.last_output(), outputs.last());
        assert_eq!(into.estimate(), one.estimate());
    }
}

#[test]
fn a_bad_sample_in_a_batch_stops_there() {
    let (times, values) = scenario(3);
    let mut f = filters().remove(0);
    let mut t = times[..20].to_vec();
    t[12] = t[11]; // not after the previous time
    let err = f.update_many(&t, &values[..20]).unwrap_err();
    assert!(matches!(err, Error::InBatch { index: 12, .. }));
    assert_eq!(f.last_time(), Some(t[11]));
    assert_eq!(f.last_output().unwrap().time, t[11]);
    let mut rows = vec![0.0; 5];
    assert!(f
        .update_many_into(&t[12..14], &values[12..14], &mut rows)
        .is_err()); // 2·3 needed
    assert!(f.update_many(&t[12..14], &values[12..13]).is_err()); // lengths differ
    assert_eq!(f.last_time(), Some(t[11]));
}

#[test]
fn boxed_beside_the_other_filters() {
    let mut filters: Vec<Box<dyn PolynomialFilter>> = vec![
        Box::new(ExpandingMemory::new(1, Engine::Exact).unwrap()),
        Box::new(
            AutomaticFilter::new(1, 0.9, 1.0)
                .unwrap()
                .with_noise_sigma(0.1)
                .unwrap(),
        ),
    ];
    for f in filters.iter_mut() {
        let t: Vec<f64> = (0..80).map(f64::from).collect();
        let y: Vec<f64> = t.iter().map(|t| 1.0 + 0.25 * t).collect();
        f.update_many(&t, &y).unwrap();
        let s = f.estimate().unwrap();
        assert!((s.derivatives[0] - 20.75).abs() < 1e-9, "{f:?}");
        assert!((s.derivatives[1] - 0.25).abs() < 1e-9);
        assert_eq!(f.samples(), 80);
        assert!(f.is_determined());
    }
}

/// Every builder of the scenario's test, applied to degree 2, θ = 0.97 per τ = 0.5.
fn fully_built() -> AutomaticFilter {
    AutomaticFilter::new(2, 0.97, 0.5)
        .unwrap()
        .with_engine(Engine::Gain)
        .unwrap()
        .with_discount_mode(DiscountMode::PerUpdate)
        .unwrap()
        .with_switch_rule(SwitchRule::ColumnMean)
        .unwrap()
        .with_noise_source(NoiseSource::Differences { window: Some(50) })
        .unwrap()
        .with_outlier_rule(OutlierRule::Innovation { k: 3.5 })
        .unwrap()
        .with_gate_max_vrf(0.5)
        .unwrap()
        .with_max_consecutive_rejections(4)
        .unwrap()
        .with_misfit_window(12)
        .unwrap()
        .with_misfit_alpha(0.02)
        .unwrap()
        .with_misfit_response(MisfitResponse::Restart { alpha: 1e-3 })
        .unwrap()
        .with_start_degree(1)
        .unwrap()
        .with_settling(0.4, 2)
        .unwrap()
        .with_noise_screen(3.5)
        .unwrap()
        .with_memory_levels(2)
        .unwrap()
        .with_same_side_rejections(2)
        .unwrap()
        .with_review_window(4)
        .unwrap()
}

/// The record [`fully_built`] must hold, field by field.
fn fully_built_record() -> AutoConfig {
    AutoConfig {
        degree: 2,
        theta: 0.97,
        tau: 0.5,
        engine: Engine::Gain,
        discount: DiscountMode::PerUpdate,
        switch_rule: SwitchRule::ColumnMean,
        noise_sigma: None,
        noise_source: NoiseSource::Differences { window: Some(50) },
        noise_screen: 3.5,
        outliers: OutlierRule::Innovation { k: 3.5 },
        gate_max_vrf: 0.5,
        max_consecutive_rejections: 4,
        same_side_rejections: 2,
        review_window: 4,
        misfit_window: 12,
        misfit_alpha: 0.02,
        misfit_response: MisfitResponse::Restart { alpha: 1e-3 },
        memory_levels: 2,
        start_degree: 1,
        settle_vrf: 0.4,
        settle_stable: 2,
    }
}

#[test]
fn builders_equal_the_configuration_they_record() {
    let mut built = fully_built();
    assert_eq!(built.config(), &fully_built_record());
    let (times, values) = scenario(4);
    for (&t, &y) in times.iter().zip(&values) {
        built.update(t, y).unwrap();
    }
    // settings are fixed once the filter has a sample
    assert!(matches!(
        built.with_noise_sigma(1.0),
        Err(Error::InvalidParameter {
            name: Param::Configuration,
            ..
        })
    ));
}

#[test]
fn builders_reject_what_the_configuration_rejects() {
    let f = || AutomaticFilter::new(2, 0.9, 1.0).unwrap();
    assert!(matches!(
        AutomaticFilter::new(99, 0.9, 1.0),
        Err(Error::DegreeOutOfRange { .. })
    ));
    assert!(matches!(
        AutomaticFilter::new(2, 1.0, 1.0),
        Err(Error::ThetaOutOfRange { .. })
    ));
    assert!(matches!(
        AutomaticFilter::new(2, 0.9, 0.0),
        Err(Error::TauOutOfRange { .. })
    ));
    assert!(f().with_noise_sigma(f64::NAN).is_err());
    assert!(f()
        .with_noise_source(NoiseSource::Innovations { window: Some(0) })
        .is_err());
    assert!(f()
        .with_outlier_rule(OutlierRule::Reyneke { k: f64::NAN })
        .is_err());
    assert!(f().with_gate_max_vrf(0.0).is_err());
    assert!(f().with_misfit_window(0).is_err());
    assert!(f().with_misfit_alpha(1.0).is_err());
    assert!(f()
        .with_misfit_response(MisfitResponse::Restart { alpha: 0.0 })
        .is_err());
    assert!(f().with_start_degree(3).is_err());
    assert!(f().with_settling(f64::INFINITY, 3).is_err());
    assert!(f().with_switch_rule(SwitchRule::Derivative(3)).is_err());
    assert!(f().with_review_window(2).is_err());
    assert!(f().with_review_window(32).is_err());
}
