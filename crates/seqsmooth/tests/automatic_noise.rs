//! The automatic filter's noise estimate (differences, innovations) and its outlier gate
//! (Reyneke et al. (2012) §7): false alarms, rejected samples and runs of rejections.
//!
//! The scenarios are those of `common::automatic` (a manoeuvring target, jittered times, dropped
//! samples, outliers; 100 runs of 2200 samples, fixed seeds).

mod common;

use common::automatic::*;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use seqsmooth::estimate::PolynomialFit;
use seqsmooth::polynomial::automatic::{
    AutomaticFilter, NoiseSource, OutlierRule, REYNEKE_DEFAULT_K,
};
use seqsmooth::polynomial::expanding::vrf::expanding_vrf;
use seqsmooth::polynomial::fading::switch::memory_length_constant;
use seqsmooth::polynomial::fading::vrf::fading_vrf;
use seqsmooth::polynomial::form::EstimateForm;

#[test]
fn estimated_noise_from_differences_and_innovations() {
    for source in [
        NoiseSource::Differences { window: None },
        NoiseSource::Innovations { window: None },
    ] {
        let c = main_defaults().with_noise_source(source).unwrap();
        let (s, _) = score(&c, GENTLE);
        let mut ratios = Vec::new();
        for seed in 0..RUNS {
            let mut f = c.clone();
            for d in track(seed, GENTLE) {
                f.update(d.t, d.y).unwrap();
            }
            ratios.push(f.noise_sigma().unwrap() / SIGMA);
        }
        let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
        let worst = ratios.iter().fold(0.0f64, |a, r| a.max((r - 1.0).abs()));
        // ~2150 samples a run: SE(σ̂)/σ ≈ ½√(2·2.31/2150) = 2.3% per run (third differences;
        // less for innovations), 0.23% for the mean of 100 runs (4.5 SE: 1.05%).
        assert!((mean - 1.0).abs() < 0.0105, "{source:?}: mean σ̂/σ {mean}");
        assert!(worst < 0.105);
        assert!(s.coverage() >= 0.985);
        assert!(s.detection() >= 0.93);
        assert!(s.false_alarm_rate() <= 0.01);
    }
}

#[test]
fn reyneke_gate_false_alarms() {
    // As printed (k = 1, σ_v(1 + √(2/N))): 10% to 25% of good samples rejected (Reyneke et al. §7).
    let printed = OutlierRule::Reyneke { k: 1.0 };
    for (n, want) in [(5.0, 0.10), (10.0, 0.15), (30.0, 0.21), (100.0, 0.25)] {
        let p = printed.false_alarm_rate(0.0, n).unwrap();
        assert!((p - want).abs() < 0.006, "N {n}: {p}");
    }
    // The default k = 3 where the gate is active (prediction VRF ≤ 1): worst case over every
    // sample count of the expanding start and every θ of the fading memory, degrees 0-4.
    let rule = OutlierRule::reyneke();
    assert_eq!(
        rule,
        OutlierRule::Reyneke {
            k: REYNEKE_DEFAULT_K
        }
    );
    for m in 0..=5usize {
        let mut worst: f64 = 0.0;
        for n in (m as u64 + 1)..3000 {
            let v = expanding_vrf::<f64>(m, n, EstimateForm::Predictor).unwrap()[(0, 0)];
            if v <= 1.0 {
                worst = worst.max(rule.false_alarm_rate(v, (n + 1) as f64).unwrap());
            }
        }
        for i in 1..1000 {
            let theta = i as f64 / 1000.0;
            let v = fading_vrf(m, theta, EstimateForm::Predictor).unwrap()[(0, 0)];
            if v <= 1.0 {
                let n = memory_length_constant(0, m) / (1.0 - theta);
                worst = worst.max(rule.false_alarm_rate(v, n).unwrap());
            }
        }
        if m <= 4 {
            assert!(worst <= 0.01);
        } else {
            assert!(worst > 0.01); // the documented limit
        }
    }
    // And on the scenario.
    let c = main_filter().with_outlier_rule(rule).unwrap();
    let (s, _) = score(&c, GENTLE);
    assert!(s.false_alarm_rate() <= 0.01);
    assert!(s.detection() >= 0.9);
}

#[test]
fn innovation_noise_estimate_equals_the_residual_variance_before_the_switch() {
    // Without gating and before the switch, mean(ν²/(1+v)) over the expanding-memory filter's
    // innovations is the batch fit's e°/(N − m − 1) (Morrison (6.10.24)): the recursive
    // residuals sum to the residual sum of squares.
    let mut f = AutomaticFilter::new(2, 0.999, 1.0)
        .unwrap()
        .with_noise_source(NoiseSource::Innovations { window: None })
        .unwrap()
        .with_outlier_rule(OutlierRule::Off)
        .unwrap();
    let mut r = StdRng::seed_from_u64(4);
    let noise = Normal::new(0.0, 0.5).unwrap();
    let (mut ts, mut ys) = (Vec::new(), Vec::new());
    let mut t = 0.0;
    for _ in 0..300 {
        t += 0.5 + r.gen::<f64>();
        let y = 3.0 + 0.2 * t - 0.01 * t * t + noise.sample(&mut r);
        f.update(t, y).unwrap();
        ts.push(t);
        ys.push(y);
    }
    assert_eq!(f.switched_at(), None);
    let fit = PolynomialFit::new(&ts, &ys, None, 2).unwrap();
    let want = fit.residual_variance().unwrap();
    let got = f.noise_sigma().unwrap().powi(2);
    assert!((got - want).abs() < 1e-9 * want, "{got} vs {want}");
}

#[test]
fn rejected_sample_leaves_the_state_and_predicts_across() {
    let mut f = AutomaticFilter::new(1, 0.9, 1.0)
        .unwrap()
        .with_noise_sigma(0.1)
        .unwrap();
    let mut r = StdRng::seed_from_u64(3);
    let noise = Normal::new(0.0, 0.1).unwrap();
    for k in 0..100 {
        f.update(k as f64, 1.0 + 0.2 * k as f64 + noise.sample(&mut r))
            .unwrap();
    }
    let before = f.estimate().unwrap();
    let prediction = f.estimate_at(100.0).unwrap();
    let o = f.update(100.0, 1.0 + 20.0 + 10.0).unwrap(); // 100σ off
    assert!(o.outlier && !o.misfit && !o.manoeuvre);
    assert_eq!(o.estimate.as_ref().unwrap(), &prediction);
    assert_eq!(f.estimate().unwrap(), before);
    assert_eq!(f.samples(), 100);
    assert_eq!(f.rejected(), 1);
    let g = o.gate.unwrap();
    assert!((g - 3.0 * o.innovation_sigma.unwrap()).abs() < 1e-12);
    // the next good sample is accepted
    assert!(!f.update(101.0, 1.0 + 20.2).unwrap().outlier);
}

#[test]
fn a_run_of_rejections_is_a_manoeuvre() {
    // A persistent 30σ jump: two rejections, then the run is applied, the misfit flag goes up
    // and the memory restarts from the jump.
    let mut f = AutomaticFilter::new(1, 0.9, 1.0)
        .unwrap()
        .with_noise_sigma(0.1)
        .unwrap();
    for k in 0..100 {
        f.update(k as f64, 0.05 * ((k * 7 % 5) as f64 - 2.0))
            .unwrap();
    }
    let o1 = f.update(100.0, 3.0).unwrap();
    let o2 = f.update(101.0, 3.0).unwrap();
    let o3 = f.update(102.0, 3.0).unwrap();
    assert!(o1.outlier && o2.outlier);
    assert!(!o3.outlier && o3.manoeuvre && o3.misfit && o3.restart);
    assert_eq!(f.rejected(), 0);
    assert_eq!(f.restarts(), 1);
    assert_eq!(f.samples(), 103);
    // the restarted memory holds the three jumped samples (m + 2 = 3 at least): on the new level
    let s = f.estimate().unwrap();
    assert!((s.derivatives[0] - 3.0).abs() < 0.3, "{:?}", s.derivatives);
    for k in 103..140 {
        let o = f
            .update(k as f64, 3.0 + 0.05 * ((k * 7 % 5) as f64 - 2.0))
            .unwrap();
        assert!(!o.outlier);
    }
    assert!((f.estimate().unwrap().derivatives[0] - 3.0).abs() < 0.1);
}
