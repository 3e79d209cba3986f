//! Span design (`seqsmooth::polynomial::fixed::{Design, tau_for_derivative_sigma}`; Morrison
//! (1969) §7.6, §7.13): the design example (7.6.1)-(7.6.5) and the bias/random-error balance of
//! Ex 7.26, each search checked on both sides of its answer against the exact covariance and
//! bias.

use seqsmooth::error::Param;
use seqsmooth::polynomial::fixed::{
    covariance_unscaled, dominant_bias, tau_for_derivative_sigma, Design, Lead,
};
use seqsmooth::Error;

#[test]
fn design_example_t7_16() {
    // (7.6.1)-(7.6.5): σ_ν = 10 ft, m = 1, one-step prediction, σ(x) = 3 ft -> L = 45 (exact
    // root 44.93); velocity variance 0.0123/τ²; σ(x') = 4 ft/s -> τ = 0.0278 s — the book
    // prints "τ = 0.029 seconds, i.e. about 36 observations per second" (misprint register
    // a misprint in (7.6.5): 0.029 -> 0.0278; 36/s is right).
    let lead = Lead::Steps(1.0);
    assert_eq!(
        Design {
            degree: 1,
            lead,
            tau: 1.0,
            sigma_nu: 10.0
        }
        .min_span_for_sigma(0, 3.0)
        .unwrap(),
        45
    );
    let sd = |l: u64| 10.0 * covariance_unscaled(1, l, 1.0, 1.0).unwrap()[(0, 0)].sqrt();
    assert!(sd(45) <= 3.0 && sd(44) > 3.0);
    let var_v = 100.0 * covariance_unscaled(1, 45, 1.0, 1.0).unwrap()[(1, 1)];
    assert!((var_v - 0.012334).abs() < 1e-6, "{var_v}");
    let tau = tau_for_derivative_sigma(1, 45, lead, 1, 10.0, 4.0).unwrap();
    assert!((tau - (var_v / 16.0).sqrt()).abs() < 1e-15);
    assert!((tau - 0.02777).abs() < 1e-5 && (1.0 / tau - 36.0).abs() < 0.1);
    assert!((tau - 0.029).abs() > 1e-3);
    // At that τ the velocity 1σ is 4 ft/s.
    let s = covariance_unscaled(1, 45, 1.0, tau).unwrap();
    assert!((10.0 * s[(1, 1)].sqrt() - 4.0).abs() < 1e-12);
    // The search is exact on both sides for other leads and derivatives.
    for (m, i, lead, tau, target) in [
        (2usize, 0usize, Lead::Centre, 1.0, 0.3),
        (2, 1, Lead::Steps(0.0), 0.1, 0.5),
        (3, 2, Lead::Centre, 0.5, 0.05),
        (0, 0, Lead::Steps(0.0), 1.0, 1.0),
    ] {
        let l = Design {
            degree: m,
            lead,
            tau,
            sigma_nu: 1.0,
        }
        .min_span_for_sigma(i, target)
        .unwrap();
        let sd = |l: u64| {
            let s = covariance_unscaled(m, l, lead.steps(l), tau).unwrap();
            s[(i, i)].sqrt()
        };
        assert!(sd(l) <= target, "m = {m}");
        assert!(
            l == m as u64 || sd(l - 1) > target,
            "m = {m}: L = {l} is not the smallest"
        );
    }
}

#[test]
fn balance_span_ex_7_26_t7_23() {
    // Ex 7.26: m = 1, σ_ν = 200 ft, R'' = 32 ft/s² (a2 = 16), τ = 1 s.
    // Design::balance_span at the end point (σ and bias both at h = 0): L = 7 (σ 129.1 ≥ bias 112.0;
    // L = 8: σ 122.9 < bias 149.3).
    let b = Design {
        degree: 1,
        lead: Lead::Steps(0.0),
        tau: 1.0,
        sigma_nu: 200.0,
    }
    .balance_span(16.0, 1.0)
    .unwrap();
    assert_eq!(b.span, 7);
    assert!((b.random_sigma - 129.1).abs() < 0.05 && (b.bias - 112.0).abs() < 1e-9);
    // The defining property, for other leads, degrees and ratios: the bias is within ratio·σ at
    // the returned L and not at L+1.
    for (m, lead, ratio) in [
        (1usize, Lead::Steps(1.0), 1.0),
        (1, Lead::Centre, 1.0),
        (2, Lead::Steps(0.0), 0.1),
        (3, Lead::Centre, 0.5),
    ] {
        let b = Design {
            degree: m,
            lead,
            tau: 1.0,
            sigma_nu: 1.0,
        }
        .balance_span(1e-4, ratio)
        .unwrap();
        let at = |l: u64| {
            let s = covariance_unscaled(m, l, lead.steps(l), 1.0).unwrap()[(0, 0)].sqrt();
            let bias = dominant_bias(m, l, lead.steps(l), 1.0, 1e-4).unwrap()[0].abs();
            (s, bias)
        };
        let (s0, b0) = at(b.span);
        let (s1, b1) = at(b.span + 1);
        assert!(
            b0 <= ratio * s0 && b1 > ratio * s1,
            "m = {m}, {lead:?}: L = {}",
            b.span
        );
        assert_eq!((b.random_sigma, b.bias), (s0, b0));
    }
    // At the centre the dominant bias vanishes for even m: nothing to balance.
    assert!(matches!(
        Design {
            degree: 2,
            lead: Lead::Centre,
            tau: 1.0,
            sigma_nu: 1.0
        }
        .balance_span(1.0, 1.0),
        Err(Error::InvalidParameter {
            name: Param::Lead,
            ..
        })
    ));
}
