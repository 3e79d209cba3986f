//! `PolynomialFilter::try_estimate_at`: an estimate finite in every number, or the reason there
//! is none, for every kind and engine; `update_many_into` rows hold no infinite number.
//! Oracles: the exact values (a line has second derivative 0; 2·Δ²y/Δt² for three samples) and
//! the double range itself.

use seqsmooth::PolynomialFilter;
use seqsmooth::{Engine, Error, ExpandingMemory, FadingMemory, FixedEngine, FixedMemory};

fn kinds(m: usize) -> Vec<Box<dyn PolynomialFilter>> {
    let mut v: Vec<Box<dyn PolynomialFilter>> = Vec::new();
    for e in [Engine::Exact, Engine::Gain] {
        v.push(Box::new(ExpandingMemory::new(m, e).unwrap()));
        v.push(Box::new(FadingMemory::new(m, 0.9, 1e-200, e).unwrap()));
    }
    for e in [
        FixedEngine::Direct,
        FixedEngine::Sliding,
        FixedEngine::Irregular,
    ] {
        v.push(Box::new(FixedMemory::new(m, m + 1, e).unwrap()));
    }
    v
}

/// Steps of 1e-200 at degree 2: on a line `d1 = 1e200` is right and given (`d2 = 0`, or
/// refused where rounding makes it beyond the range); on a parabola with
/// `Δ²y = 2` the second derivative is 2e400, beyond a double, and every kind and engine says
/// so by name, in `try_estimate_at`, and with `NaN` in that cell only of the rows (expanding and
/// fading memory) or the whole row (fixed memory), never `inf`.
#[test]
fn derivatives_beyond_the_double_range_are_named() {
    let t = [0.0, 1e-200, 2e-200, 3e-200];
    for mut f in kinds(2) {
        // A line: exact, d1 = 1e200 per unit time, d2 = 0.
        for (&t, y) in t[..3].iter().zip([1.0, 2.0, 3.0]) {
            f.update(t, y).unwrap();
        }
        // The second derivative is 0 ± rounding: a rounding of 1e-16 in the scaled fit is
        // 1e384 per unit time², so the engines whose basis is not the step itself refuse it.
        match f.try_estimate() {
            Ok(s) => {
                assert!(
                    (s.derivatives[1] / 1e200 - 1.0).abs() < 1e-9,
                    "{f:?}: {s:?}"
                );
                assert!(s.derivatives[2].abs() < 1e190, "{f:?}: {s:?}");
            }
            Err(Error::EstimateOutOfRange { what }) => assert_eq!(what, "d2", "{f:?}"),
            Err(e) => panic!("{f:?}: {e}"),
        }
        // Bends: y = 3, 5 after 3: Δ²y = 1 over 1e-200 steps, d2 ≈ 1e400.
        f.update(t[3], 5.0).unwrap();
        match f.try_estimate() {
            Err(Error::EstimateOutOfRange { what }) => assert_eq!(what, "d2", "{f:?}"),
            other => panic!("{f:?}: {other:?}"),
        }
        assert!(f.estimate().is_none());
    }
    for mut f in kinds(2) {
        let mut rows = [0.0; 12];
        f.update_many_into(&t, &[1.0, 2.0, 3.0, 5.0], &mut rows)
            .unwrap();
        assert!(rows.iter().all(|v| !v.is_infinite()), "{f:?}: {rows:?}");
        // d2 is marked; d0 and d1 stand (expanding, fading) or go with their row (fixed).
        assert!(rows[11].is_nan(), "{f:?}: {rows:?}");
        let whole_row = rows[9..].iter().all(|v| v.is_nan());
        assert!(
            whole_row || ((rows[9] - 5.0).abs() < 1.0 && rows[10].is_finite()),
            "{f:?}: {rows:?}"
        );
    }
}

/// A fading-memory τ of 1e-300 on unit steps: the discount θ^(1/τ) underflows to 0 and each
/// sample forgets the ones before, so after `m+1` samples the exact engine's fit is singular
/// and says why, naming τ; before, it names the sample count.
#[test]
fn a_discount_that_underflows_is_named() {
    let mut f = FadingMemory::new(2, 0.9, 1e-300, Engine::Exact).unwrap();
    f.update(0.0, 1.0).unwrap();
    assert!(matches!(
        f.try_estimate(),
        Err(Error::TooFewSamples { needed: 3, got: 1 })
    ));
    for (t, y) in [(1.0, 2.0), (2.0, 5.0), (3.0, 10.0)] {
        f.update(t, y).unwrap();
    }
    match f.try_estimate() {
        Err(Error::NotDetermined { samples: 4, why }) => assert!(why.contains("τ"), "{why}"),
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        f.try_estimate_at(f64::NAN),
        Err(Error::NonFinite { .. })
    ));
}

/// Whatever the reason, `estimate_at` is `None` exactly when `try_estimate_at` is an error, and
/// a state it returns passes [`PolynomialState::checked`].
#[test]
fn estimate_at_agrees_with_try_estimate_at() {
    for mut f in kinds(3) {
        for k in 0..6 {
            let t = k as f64 * 1e-100;
            f.update(t, (k * k) as f64).unwrap();
            for at in [t, t + 1e-100, t + 1e200] {
                match (f.estimate_at(at), f.try_estimate_at(at)) {
                    (Some(a), Ok(b)) => {
                        assert_eq!(a, b);
                        assert_eq!(a.clone().checked().ok(), Some(a));
                    }
                    (None, Err(_)) => {}
                    other => panic!("{f:?} at {at}: {other:?}"),
                }
            }
        }
    }
}
