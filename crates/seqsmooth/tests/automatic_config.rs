//! The automatic filter's configuration: bad configuration and input are typed errors, and the
//! filter is Clone, Send, Sync and Debug.

mod common;

use seqsmooth::polynomial::automatic::{
    AutoOutput, AutomaticFilter, MisfitResponse, NoiseSource, OutlierRule,
};
use seqsmooth::polynomial::fading::switch::SwitchRule;
use seqsmooth::Error;

#[test]
fn bad_configuration_and_input_are_typed_errors() {
    let base = || AutomaticFilter::new(2, 0.9, 1.0);
    type Change = fn(AutomaticFilter) -> Result<AutomaticFilter, Error>;
    let bad: Vec<(&str, Change)> = vec![
        ("degree", |_| AutomaticFilter::new(99, 0.9, 1.0)),
        ("θ = 1", |_| AutomaticFilter::new(2, 1.0, 1.0)),
        ("θ NaN", |_| AutomaticFilter::new(2, f64::NAN, 1.0)),
        ("τ = 0", |_| AutomaticFilter::new(2, 0.9, 0.0)),
        ("τ inf", |_| AutomaticFilter::new(2, 0.9, f64::INFINITY)),
        ("σ = 0", |f| f.with_noise_sigma(0.0)),
        ("σ NaN", |f| f.with_noise_sigma(f64::NAN)),
        ("σ² underflows", |f| f.with_noise_sigma(1e-300)),
        ("σ² overflows", |f| f.with_noise_sigma(1e300)),
        ("noise window", |f| {
            f.with_noise_source(NoiseSource::Differences { window: Some(0) })
        }),
        ("innovation window", |f| {
            f.with_noise_source(NoiseSource::Innovations { window: Some(0) })
        }),
        ("gate k", |f| {
            f.with_outlier_rule(OutlierRule::Innovation { k: -1.0 })
        }),
        ("Reyneke k", |f| {
            f.with_outlier_rule(OutlierRule::Reyneke { k: f64::NAN })
        }),
        ("misfit window", |f| f.with_misfit_window(0)),
        ("misfit α", |f| f.with_misfit_alpha(0.0)),
        ("restart α", |f| {
            f.with_misfit_response(MisfitResponse::Restart { alpha: 1.0 })
        }),
        ("start degree", |f| f.with_start_degree(3)),
        ("settle VRF", |f| f.with_settling(0.0, 3)),
        ("gate VRF limit", |f| f.with_gate_max_vrf(f64::NAN)),
        ("switch derivative", |f| {
            f.with_switch_rule(SwitchRule::Derivative(5))
        }),
    ];
    for (what, change) in bad {
        assert!(change(base().unwrap()).is_err(), "{what} accepted");
    }
    let mut f = base().unwrap();
    for k in 0..20 {
        f.update(k as f64, k as f64).unwrap();
    }
    let before = f.clone();
    assert!(matches!(
        f.update(19.0, 1.0),
        Err(Error::TimeNotIncreasing { .. })
    ));
    assert!(matches!(
        f.update(f64::NAN, 1.0),
        Err(Error::NonFinite { .. })
    ));
    assert!(matches!(
        f.update(20.0, f64::INFINITY),
        Err(Error::NonFinite { .. })
    ));
    assert_eq!(f.samples(), before.samples());
    assert_eq!(f.estimate(), before.estimate());
    assert_eq!(f.last_time(), Some(19.0));
}

#[test]
fn the_filter_is_clone_send_and_debug() {
    fn check<T: Clone + Send + Sync + std::fmt::Debug>() {}
    check::<AutomaticFilter>();
    check::<AutoOutput>();
}
