//! The automatic filter's configuration: bad configuration and input are typed errors, and the
//! filter is Clone, Send, Sync and Debug.

mod common;

use seqsmooth::polynomial::automatic::{
    AutoConfig, AutoOutput, AutomaticFilter, MisfitResponse, NoiseSource, OutlierRule,
};
use seqsmooth::polynomial::switching::SwitchRule;
use seqsmooth::Error;

#[test]
fn bad_configuration_and_input_are_typed_errors() {
    let base = AutoConfig::new(2, 0.9, 1.0);
    type Change = Box<dyn Fn(&mut AutoConfig)>;
    let bad: Vec<(&str, Change)> = vec![
        ("degree", Box::new(|c| c.degree = 99)),
        ("θ = 1", Box::new(|c| c.theta = 1.0)),
        ("θ NaN", Box::new(|c| c.theta = f64::NAN)),
        ("τ = 0", Box::new(|c| c.tau = 0.0)),
        ("τ inf", Box::new(|c| c.tau = f64::INFINITY)),
        ("σ = 0", Box::new(|c| c.noise_sigma = Some(0.0))),
        ("σ NaN", Box::new(|c| c.noise_sigma = Some(f64::NAN))),
        (
            "noise window",
            Box::new(|c| c.noise_source = NoiseSource::Differences { window: Some(0) }),
        ),
        (
            "innovation window",
            Box::new(|c| c.noise_source = NoiseSource::Innovations { window: Some(0) }),
        ),
        (
            "gate k",
            Box::new(|c| c.outliers = OutlierRule::Innovation { k: -1.0 }),
        ),
        (
            "Reyneke k",
            Box::new(|c| c.outliers = OutlierRule::Reyneke { k: f64::NAN }),
        ),
        ("misfit window", Box::new(|c| c.misfit_window = 0)),
        ("misfit α", Box::new(|c| c.misfit_alpha = 0.0)),
        (
            "restart α",
            Box::new(|c| c.misfit_response = MisfitResponse::Restart { alpha: 1.0 }),
        ),
        ("start degree", Box::new(|c| c.start_degree = 3)),
        ("settle VRF", Box::new(|c| c.settle_vrf = 0.0)),
        ("gate VRF limit", Box::new(|c| c.gate_max_vrf = f64::NAN)),
        (
            "switch derivative",
            Box::new(|c| c.switch_rule = SwitchRule::Derivative(5)),
        ),
    ];
    for (what, change) in bad {
        let mut c = base.clone();
        change(&mut c);
        assert!(AutomaticFilter::new(c).is_err(), "{what} accepted");
    }
    let mut f = AutomaticFilter::new(base).unwrap();
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
