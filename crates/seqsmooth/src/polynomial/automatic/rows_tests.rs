//! The row runner's path (`AutomaticFilter::update_row`): what it reports of each estimate
//! (derivatives, 1σ, `b₀`) against `update`'s full output on the same samples, bit for bit,
//! and the output made whole afterwards (`complete_output`) equal to `update`'s.

use super::{AutomaticFilter, MisfitResponse};
use crate::numeric::sigma::std_dev;
use crate::polynomial::options::{DiscountMode, Engine};

/// A manoeuvring series: steps `1 ± 40%`, a piecewise constant acceleration changed every
/// 50-150 samples, unit-σ noise times `scale`, 3% outliers of 6-12σ (a generator of its own:
/// the input is fixed).
fn series(n: usize, seed: u64, scale: f64) -> Vec<(f64, f64)> {
    let mut state = seed;
    let mut uniform = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    let (mut t, mut x, mut v, mut a, mut next) = (50.0, 0.0, 20.0, 0.0, 100);
    (0..n)
        .map(|k| {
            let dt = 1.0 + 0.4 * (2.0 * uniform() - 1.0);
            t += dt;
            x += v * dt + 0.5 * a * dt * dt;
            v += a * dt;
            if k == next {
                a = 4.0 * uniform() - 2.0;
                next += 50 + (100.0 * uniform()) as usize;
            }
            let (u1, u2) = (uniform(), uniform());
            let mut e = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
            if uniform() < 0.03 {
                e += (6.0 + 6.0 * uniform()).copysign(uniform() - 0.5);
            }
            (t, x + scale * e)
        })
        .collect()
}

/// The filters of the test: degrees 0-3, σ given or estimated, the gain engine, per update,
/// two shorter memories, the flag-only misfit response.
fn filters() -> Vec<AutomaticFilter> {
    let new = |m: usize, theta: f64| AutomaticFilter::new(m, theta, 1.0).unwrap();
    vec![
        new(0, 0.9),
        new(1, 0.9).with_noise_sigma(3.0).unwrap(),
        new(2, 0.95),
        new(2, 0.95).with_memory_levels(2).unwrap(),
        new(2, 0.9).with_engine(Engine::Gain).unwrap(),
        new(2, 0.9)
            .with_discount_mode(DiscountMode::PerUpdate)
            .unwrap(),
        new(2, 0.95)
            .with_misfit_response(MisfitResponse::Flag)
            .unwrap(),
        new(3, 0.9),
    ]
}

#[test]
fn rows_report_the_full_outputs_numbers_bit_for_bit() {
    for (k, proto) in filters().into_iter().enumerate() {
        let (mut full, mut rows) = (proto.clone(), proto);
        let (mut reported, mut n) = (0, 0);
        for (t, y) in series(3000, 11 + k as u64, 3.0) {
            let out = full.update(t, y).unwrap();
            rows.update_row(t, y).unwrap();
            n += 1;
            if let Some(r) = rows.reported() {
                reported += 1;
                let s = out
                    .estimate
                    .as_ref()
                    .expect("an estimate where one is reported");
                let c = s.covariance.as_ref().expect("with its covariance");
                let bits = |v: &[f64]| v.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
                let sd: Vec<f64> = (0..c.nrows()).map(|i| std_dev(c[(i, i)])).collect();
                assert_eq!(
                    bits(r.derivatives()),
                    bits(&s.derivatives),
                    "filter {k} at {t}"
                );
                assert_eq!(bits(r.std_devs()), bits(&sd), "filter {k} at {t}");
                let b0 = out.bias.as_ref().map_or(f64::NAN, |b| b[0]);
                assert_eq!(r.bias0().to_bits(), b0.to_bits(), "filter {k} at {t}");
                let o = rows.last_output().unwrap();
                assert!(o.estimate.is_none() && o.withheld.is_none());
            } else {
                assert_eq!(rows.last_output(), Some(&out), "filter {k} at {t}");
            }
            // Made whole, the output is `update`'s; a second call changes nothing.
            let mut whole = rows.clone();
            whole.complete_output();
            assert_eq!(whole.last_output(), Some(&out), "filter {k} at {t}");
            whole.complete_output();
            assert_eq!(whole.last_output(), Some(&out), "filter {k} at {t}");
        }
        // The path answers on the exact engine (all but the start-up's samples; the gain
        // engine's memory 0 takes the full path), and the two filters end the same.
        if k != 4 {
            assert!(reported > n * 9 / 10, "filter {k}: {reported} of {n}");
        }
        rows.complete_output();
        assert_eq!(rows.finish(), full.finish());
        assert_eq!(rows.last_output(), full.last_output());
    }
}
