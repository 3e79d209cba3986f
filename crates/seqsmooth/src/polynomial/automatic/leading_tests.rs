//! One factor per memory (`memory.rs`'s `update_pair`): a degree-`m` filter taken from its
//! degree `m + 1` companion's leading block against the same filter updated with the samples
//! itself, on long irregular runs at degrees 0-8: estimates, their covariance (σ) and the
//! residual sum of squares agree to rounding.

use crate::polynomial::expanding::ExpandingMemory;
use crate::polynomial::fading::FadingMemory;
use crate::polynomial::filter::PolynomialFilter;
use crate::polynomial::options::{DiscountMode, Engine};
use crate::recursive::InformationFilter;

/// Agreement in units of the estimate's own σ (entry by entry of the covariance, in units of
/// `σ_i σ_j`). The two differ by the rounding of one row (the `m + 2`-th sample, which the
/// two factors fold in by Gentleman's sequential and reciprocal forms) carried on by the
/// recursion, amplified like any rounding error by the fit's variance inflation
/// (`InformationFilter::variance_inflation`, up to ~10⁶ at degree 8 on these runs): measured
/// (2026-12-07) at most 3e-9 σ at degree 8 and 2e-10 below it (1e-11 below degree 6); a
/// leading block taken wrongly is off by O(σ) or more.
const TOL: f64 = 1e-7;

/// A run of `n` samples: steps `1 ± 40%`, a cubic with a change of acceleration half way and
/// unit Gaussian noise (a small generator of its own: the test's input is fixed).
fn run(n: usize, seed: u64) -> Vec<(f64, f64)> {
    let mut state = seed;
    let mut uniform = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    let mut t = 1000.0;
    (0..n)
        .map(|k| {
            t += 1.0 + 0.4 * (2.0 * uniform() - 1.0);
            let (u1, u2) = (uniform(), uniform());
            let noise = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
            let turn = if k > n / 2 {
                0.3 * (t - 1000.0 - n as f64 / 2.0).powi(2)
            } else {
                0.0
            };
            (
                t,
                5.0 + 2.0 * t - 1e-4 * t * t + 1e-8 * t.powi(3) + turn + noise,
            )
        })
        .collect()
}

/// The largest difference of `a` from `b` (estimates and covariances) in units of `b`'s σ.
fn worst(a: &dyn PolynomialFilter, b: &dyn PolynomialFilter, t: f64) -> f64 {
    let (Some(a), Some(b)) = (a.estimate_at(t), b.estimate_at(t)) else {
        assert_eq!(a.is_determined(), b.is_determined(), "determined at {t}");
        return 0.0;
    };
    let (ca, cb) = (a.covariance.unwrap(), b.covariance.unwrap());
    let p = b.derivatives.len();
    let sd: Vec<f64> = (0..p).map(|i| cb[(i, i)].sqrt()).collect();
    let mut w: f64 = 0.0;
    for i in 0..p {
        w = w.max((a.derivatives[i] - b.derivatives[i]).abs() / sd[i]);
        for j in 0..p {
            w = w.max((ca[(i, j)] - cb[(i, j)]).abs() / (sd[i] * sd[j]));
        }
    }
    w
}

#[test]
fn a_fading_filter_from_its_companions_leading_block_is_the_filter_to_rounding() {
    for (m, mode) in
        (0..=8).flat_map(|m| [DiscountMode::PerTime, DiscountMode::PerUpdate].map(move |d| (m, d)))
    {
        let make = |deg: usize| {
            FadingMemory::new(deg, 0.95, 1.0, Engine::Exact)
                .unwrap()
                .with_discount_mode(mode)
                .unwrap()
                .with_noise_sigma(1.0)
                .unwrap()
        };
        let (mut own, mut view, mut upper) = (make(m), make(m), make(m + 1));
        let mut w: f64 = 0.0;
        for (k, &(t, y)) in run(4000, 7 + m as u64).iter().enumerate() {
            own.update(t, y).unwrap();
            upper.update(t, y).unwrap();
            assert!(view.follow_leading(&upper), "degree {m}");
            if k % 7 == 0 || k < 40 {
                w = w
                    .max(worst(&view, &own, t))
                    .max(worst(&view, &own, t + 0.5));
            }
        }
        assert!(w <= TOL, "degree {m} {mode:?}: {w:e} σ");
        assert_eq!(view.samples(), own.samples());
    }
}

#[test]
fn an_expanding_filter_from_its_companions_leading_block_is_the_filter_to_rounding() {
    for m in 0..=8 {
        let make = |deg: usize| {
            ExpandingMemory::new(deg, Engine::Exact)
                .unwrap()
                .with_noise_sigma(1.0)
                .unwrap()
        };
        let (mut own, mut view, mut upper) = (make(m), make(m), make(m + 1));
        let mut w: f64 = 0.0;
        for (k, &(t, y)) in run(3000, 11 + m as u64).iter().enumerate() {
            own.update(t, y).unwrap();
            upper.update(t, y).unwrap();
            assert!(view.follow_leading(&upper), "degree {m}");
            if k % 7 == 0 || k < 40 {
                w = w.max(worst(&view, &own, t));
            }
        }
        assert!(w <= TOL, "degree {m}: {w:e} σ");
    }
}

#[test]
fn the_leading_block_takes_only_a_smaller_exact_filter_of_the_same_settings() {
    let fading = |deg: usize, theta: f64, engine: Engine| {
        FadingMemory::new(deg, theta, 1.0, engine)
            .unwrap()
            .with_noise_sigma(1.0)
            .unwrap()
    };
    let mut upper = fading(3, 0.9, Engine::Exact);
    for (t, y) in run(50, 3) {
        upper.update(t, y).unwrap();
    }
    assert!(!fading(3, 0.9, Engine::Exact).follow_leading(&upper)); // not smaller
    assert!(!fading(1, 0.9, Engine::Exact).follow_leading(&upper)); // two degrees down
    assert!(!fading(2, 0.8, Engine::Exact).follow_leading(&upper)); // another discount
    assert!(!fading(2, 0.9, Engine::Gain).follow_leading(&upper)); // the gain engine
    let plain = FadingMemory::new(2, 0.9, 1.0, Engine::Exact).unwrap();
    assert!(!plain.clone().follow_leading(&upper)); // no covariance where the companion has one
    let mut lower = fading(2, 0.9, Engine::Exact);
    assert!(lower.follow_leading(&upper));
    assert_eq!(lower.samples(), 50);
}

#[test]
fn the_leading_blocks_residual_is_the_smaller_fits_own() {
    // Morrison (10.2.42)-(10.2.44): the residual of the fit of the first q columns is the
    // larger fit's plus the squares of the dropped entries of Qᵀz.
    for p in 1..=9 {
        let mut own = InformationFilter::new(p).with_true_covariance();
        let mut upper = InformationFilter::new(p + 1).with_true_covariance();
        let mut t_prev = 1000.0;
        for (t, y) in run(3000, 5 + p as u64) {
            // A memory of about 2000 samples, in a basis spanning the run (as the engine keeps it).
            let g = (0.0005 * (t - t_prev)).exp();
            t_prev = t;
            let u = (t - 2500.0) / 1500.0;
            for f in [&mut own, &mut upper] {
                f.fade(g);
                f.observe_powers(u, y, 1.0);
            }
        }
        let mut lead = InformationFilter::new(p).with_true_covariance();
        assert!(upper.leading_into(&mut lead));
        let (a, b) = (lead.factor().residual_sq(), own.factor().residual_sq());
        assert!((a - b).abs() <= 1e-9 * b, "p {p}: {a} against {b}");
        let (ca, cb) = (lead.covariance().unwrap(), own.covariance().unwrap());
        let (xa, xb) = (lead.solve().unwrap(), own.solve().unwrap());
        for i in 0..p {
            let s = cb[(i, i)].sqrt();
            assert!((xa[i] - xb[i]).abs() <= TOL * s, "p {p} x{i}");
            assert!((ca[(i, i)] - cb[(i, i)]).abs() <= TOL * s * s, "p {p} c{i}");
        }
        assert!(!own.leading_into(&mut InformationFilter::new(p)));
        assert!(!upper.leading_into(&mut InformationFilter::new(p)), "no Q");
    }
}
