//! Unit tests of `commands::shared::runner`'s fixed-memory filter ([`FixedEngine::Adaptive`], what
//! `Runner::Fixed` runs): the switch from the sliding to the irregular engine.

use seqsmooth::{FixedEngine, FixedMemory, PolynomialFilter};

/// The fixed-memory filter of `Runner::Fixed` falls back from the sliding engine to the irregular one at the
/// first uneven step, and its estimates are the irregular engine's from the start (up to
/// rounding) on both sides of the switch.
#[test]
fn fixed_runner_switches_engine_at_first_uneven_step() {
    let mut runner = FixedMemory::new(2, 6, FixedEngine::Adaptive)
        .unwrap()
        .with_noise_sigma(0.5)
        .unwrap();
    let mut reference = FixedMemory::new(2, 6, FixedEngine::Irregular)
        .unwrap()
        .with_noise_sigma(0.5)
        .unwrap();
    let mut t = 0.0;
    for k in 0..40 {
        t += if k < 15 {
            0.25
        } else {
            0.25 + 0.1 * ((k % 3) as f64)
        };
        let y = (0.7 * t).sin() + 0.1 * ((k * 7 % 5) as f64);
        runner.update(t, y).unwrap();
        reference.update(t, y).unwrap();
        let engine = runner.engine();
        assert_eq!(engine == FixedEngine::Irregular, k >= 16, "k = {k}");
        assert_eq!((runner.samples() as usize).min(6), (k + 1).min(6));
        for lead in [0.0, 0.3, -0.6] {
            match (
                runner.estimate_at(t + lead),
                reference.estimate_at(t + lead),
            ) {
                (None, None) => assert!(k < 5),
                (Some(a), Some(b)) => {
                    for (x, y) in a.derivatives.iter().zip(&b.derivatives) {
                        assert!((x - y).abs() <= 1e-9 * (1.0 + y.abs()), "k = {k}: {x} {y}");
                    }
                    let (sa, sb) = (a.std_devs().unwrap(), b.std_devs().unwrap());
                    for (x, y) in sa.iter().zip(&sb) {
                        assert!((x - y).abs() <= 1e-9 * (1.0 + y.abs()), "k = {k}: {x} {y}");
                    }
                }
                _ => panic!("k = {k}: one estimate is missing"),
            }
        }
    }
}
