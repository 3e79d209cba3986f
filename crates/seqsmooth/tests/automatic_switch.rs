//! The automatic filter's switch from expanding to fading memory happens at the index of the
//! switch rule (Morrison (1969) §13.8, Reyneke et al. (2012) Table 1).
//!
//! The scenarios are those of `common::automatic` (a manoeuvring target, jittered times, dropped
//! samples, outliers; 100 runs of 2200 samples, fixed seeds).

mod common;

use common::automatic::*;
use seqsmooth::polynomial::automatic::{AutomaticFilter, OutlierRule, Phase};
use seqsmooth::polynomial::fading::switch::SwitchRule;
use seqsmooth::DiscountMode;

#[test]
fn switch_happens_at_the_rule_index() {
    // The switch is evaluated for each arriving sample with n = accepted samples so far and the
    // per-sample discount θ^((t − t_0)/(n τ)); the first n at or past the rule's index is the
    // switch (SwitchRule docs; the same evaluation as the gain engine's).
    for rule in [
        SwitchRule::Position,
        SwitchRule::ExactCrossover,
        SwitchRule::ColumnMean,
    ] {
        for seed in 0..5 {
            let data = track(seed, GENTLE);
            // The gate's decisions (no review, which may revise them later): the accepted
            // samples counted here are those the filter took.
            let mut f = main_filter()
                .with_switch_rule(rule)
                .unwrap()
                .with_review_window(0)
                .unwrap();
            let c = f.config().clone();
            let (mut n, mut t0, mut expected, mut seen) = (0u64, None, None, None);
            for s in &data {
                if expected.is_none() && n > c.degree as u64 {
                    let theta_s = c.theta.powf((s.t - t0.unwrap()) / (n as f64 * c.tau));
                    if n >= rule.switch_index(c.degree, theta_s).unwrap() {
                        expected = Some(n);
                    }
                }
                let o = f.update(s.t, s.y).unwrap();
                if o.phase == Phase::Fading && seen.is_none() {
                    seen = f.switched_at();
                    // the first fading output is at the expected sample
                    assert_eq!(seen, expected, "{rule:?} seed {seed}");
                }
                if !o.outlier {
                    n += 1;
                    t0.get_or_insert(s.t);
                }
            }
            assert!(seen.is_some());
        }
    }
}

#[test]
fn switch_rules_on_even_samples_match_switch_index() {
    // On integer times with τ = 1 the per-sample discount is θ itself, so the switch is exactly
    // SwitchRule::switch_index(m, θ) (Morrison (13.8.8): m = 1, θ = 0.9 → 32; Ex. 13.21).
    let rules = [
        SwitchRule::Position,
        SwitchRule::ColumnMean,
        SwitchRule::Derivative(1),
        SwitchRule::ExactCrossover,
        SwitchRule::AtSample(50),
    ];
    for m in 1..=3 {
        for theta in [0.9, 0.95] {
            for rule in rules {
                for mode in [DiscountMode::PerTime, DiscountMode::PerUpdate] {
                    let mut f = AutomaticFilter::new(m, theta, 1.0)
                        .unwrap()
                        .with_noise_sigma(1.0)
                        .unwrap()
                        .with_outlier_rule(OutlierRule::Off)
                        .unwrap()
                        .with_switch_rule(rule)
                        .unwrap()
                        .with_discount_mode(mode)
                        .unwrap();
                    for k in 0..400 {
                        // PerUpdate ignores the spacing: jitter the times there
                        let t = match mode {
                            DiscountMode::PerTime => k as f64,
                            DiscountMode::PerUpdate => k as f64 + 0.3 * ((k * 7 % 5) as f64),
                        };
                        f.update(t, 0.1 * ((k * 13 % 7) as f64)).unwrap();
                    }
                    let want = rule.switch_index(m, theta).unwrap();
                    assert_eq!(
                        f.switched_at(),
                        Some(want),
                        "m {m} θ {theta} {rule:?} {mode:?}"
                    );
                }
            }
        }
    }
}
