//! The automatic filter (`seqsmooth::polynomial::automatic`) on the gentle manoeuvre: ±3σ
//! coverage, outlier detection and false alarms after the start-up, with either engine and
//! discount mode.
//!
//! The scenarios are those of `common::automatic` (a manoeuvring target, jittered times, dropped
//! samples, outliers; 100 runs of 2200 samples, fixed seeds).

mod common;

use common::automatic::*;
use seqsmooth::{DiscountMode, Engine};

#[test]
fn gentle_manoeuvre_coverage_outliers_and_misfit() {
    let (s, _) = score(&main_filter(), GENTLE);
    assert!(s.scored > 180_000);
    assert!(s.coverage() >= 0.99);
    assert!(s.coverage_all() >= 0.99);
    assert!(s.detection() >= 0.95);
    assert!(s.false_alarm_rate() <= 0.01);
    assert!(s.misfit_rate() <= 0.02);
}

#[test]
fn gain_engine_and_per_update_discount_run_the_scenario() {
    let c = main_filter()
        .with_engine(Engine::Gain)
        .unwrap()
        .with_discount_mode(DiscountMode::PerUpdate)
        .unwrap();
    let (s, _) = score(&c, GENTLE);
    assert!(s.coverage() >= 0.97);
    assert!(s.false_alarm_rate() <= 0.01);
}
