//! `PolynomialFilter::update_many` against per-sample `update`: same estimates, same errors,
//! and the accuracy of the fading-memory gain engine's plain-`f64` steady kernel.

use seqsmooth::{
    Engine, Error, ExpandingMemory, FadingMemory, FixedEngine, FixedMemory, PolynomialFilter,
};

/// Deterministic data: a slow sine, a trend and a unit pseudo-random term.
fn sample(n: usize) -> f64 {
    let mut s = (n as u64).wrapping_mul(0xD1B5_4A32_D192_ED03) ^ 0x9E37_79B9_7F4A_7C15;
    s ^= s >> 29;
    s = s.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    s ^= s >> 32;
    let noise = (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
    let t = n as f64;
    100.0 * (0.003 * t).sin() + 0.01 * t + noise
}

/// `n` times `k·0.1` (steps equal up to rounding) or, `irregular`, steps `0.1·(1 ± 0.3)`.
fn grid(n: usize, irregular: bool) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let k = k as f64;
            if irregular {
                0.1 * k + 0.03 * (1.7 * k).sin()
            } else {
                0.1 * k
            }
        })
        .collect()
}

fn filters(m: usize, irregular: bool) -> Vec<(String, Box<dyn PolynomialFilter>)> {
    let mut v: Vec<(String, Box<dyn PolynomialFilter>)> = Vec::new();
    for engine in [Engine::Exact, Engine::Gain] {
        v.push((
            format!("expanding {engine:?}"),
            Box::new(ExpandingMemory::new(m, engine).unwrap()),
        ));
        v.push((
            format!("fading {engine:?}"),
            Box::new(FadingMemory::new(m, 0.9, 0.1, engine).unwrap()),
        ));
    }
    v.push((
        "fixed".into(),
        Box::new(
            FixedMemory::new(
                m,
                20 + 2 * m,
                if irregular {
                    FixedEngine::Irregular
                } else {
                    FixedEngine::Sliding
                },
            )
            .unwrap(),
        ),
    ));
    v
}

/// Largest difference per derivative between two states, relative to `scale`.
fn rel_diff(a: &[f64], b: &[f64], scale: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .zip(scale)
        .map(|((x, y), s)| (x - y).abs() / s.max(1e-300))
        .fold(0.0, f64::max)
}

#[test]
fn update_many_equals_update_on_even_and_irregular_times() {
    for m in [0, 1, 2, 3, 5, 8] {
        for irregular in [false, true] {
            let times = grid(3000, irregular);
            let ys: Vec<f64> = (0..times.len()).map(sample).collect();
            for ((name, mut one), (_, mut many)) in
                filters(m, irregular).into_iter().zip(filters(m, irregular))
            {
                let mut scale = vec![0.0f64; m + 1];
                let mut worst = 0.0f64;
                // Batches of varied lengths, compared at every batch end.
                let mut i = 0;
                let mut len = 1;
                while i < times.len() {
                    let j = (i + len).min(times.len());
                    many.update_many(&times[i..j], &ys[i..j]).unwrap();
                    for k in i..j {
                        one.update(times[k], ys[k]).unwrap();
                    }
                    assert_eq!(one.samples(), many.samples());
                    match (one.estimate(), many.estimate()) {
                        (Some(a), Some(b)) => {
                            for (s, x) in scale.iter_mut().zip(&a.derivatives) {
                                *s = s.max(x.abs());
                            }
                            worst = worst.max(rel_diff(&a.derivatives, &b.derivatives, &scale));
                        }
                        (None, None) => {}
                        (a, b) => panic!("{name}: determined {} vs {}", a.is_some(), b.is_some()),
                    }
                    i = j;
                    len = len % 300 + 37;
                }
                eprintln!("m = {m}, irregular = {irregular}, {name}: {worst:.2e}");
                // Exact and fixed engines run the same code: equal. The gain engine's plain
                // steady kernel differs from the compensated per-sample path by rounding.
                let bound = if name.contains("Gain") { 1e-11 } else { 0.0 };
                assert!(worst <= bound, "m = {m} {name}: {worst:e}");
            }
        }
    }
}

#[test]
fn update_many_reports_the_first_bad_sample_and_keeps_the_ones_before() {
    let bad_cases: Vec<(Vec<f64>, Vec<f64>, usize, &str)> = vec![
        (vec![1.0, 2.0, 2.0, 3.0], vec![0.0; 4], 2, "not after"),
        (vec![1.0, 2.0, 3.0, 1.5], vec![0.0; 4], 3, "not after"),
        (vec![1.0, f64::NAN, 3.0], vec![0.0; 3], 1, "time NaN"),
        (
            vec![1.0, 2.0, 3.0],
            vec![0.0, 1.0, f64::INFINITY],
            2,
            "value inf",
        ),
    ];
    for (times, values, index, what) in bad_cases {
        // Also across the 256-sample blocks of the fast check.
        for offset in [0usize, 300] {
            let mut t: Vec<f64> = (0..offset).map(|k| k as f64 * 1e-3 - 1.0).collect();
            let mut y = vec![0.5; offset];
            t.extend(&times);
            y.extend(&values);
            for (name, mut f) in filters(1, true) {
                let err = f.update_many(&t, &y).unwrap_err();
                match &err {
                    Error::InBatch { index: i, source } => {
                        assert_eq!(*i, offset + index, "{name} {what}: {err}");
                        let mut g = filters(1, true)
                            .into_iter()
                            .find(|(n, _)| *n == name)
                            .unwrap()
                            .1;
                        for k in 0..offset + index {
                            g.update(t[k], y[k]).unwrap();
                        }
                        // (compared as text: NaN ≠ NaN)
                        assert_eq!(
                            source.to_string(),
                            g.update(t[*i], y[*i]).unwrap_err().to_string()
                        );
                    }
                    other => panic!("{name} {what}: {other}"),
                }
                assert_eq!(f.samples(), (offset + index) as u64, "{name} {what}");
            }
        }
    }
    // Lengths must match; nothing is processed.
    let mut f = FadingMemory::new(1, 0.9, 1.0, Engine::Gain).unwrap();
    let err = f.update_many(&[1.0, 2.0], &[1.0]).unwrap_err();
    assert!(
        matches!(
            err,
            Error::InvalidParameter {
                name: "batch lengths",
                ..
            }
        ),
        "{err}"
    );
    assert_eq!(f.samples(), 0);
    // A batch that starts at or before the filter's last time.
    f.update(5.0, 1.0).unwrap();
    let err = f.update_many(&[5.0], &[1.0]).unwrap_err();
    assert!(matches!(err, Error::InBatch { index: 0, .. }), "{err}");
}

/// The plain-`f64` steady kernel against the compensated per-sample path over long runs, per
/// degree and θ: worst difference over the second half of the run (every 101st sample),
/// relative to the largest `|x^(k)|` there, worst over derivatives. Printed with
/// `--nocapture`; the table is in the `polynomial` module docs.
#[test]
fn plain_steady_kernel_accuracy_over_long_runs() {
    let n = 60_000;
    let times = grid(n, false);
    let ys: Vec<f64> = (0..n).map(sample).collect();
    // One long batch first (long enough for the block map to be built, degrees ≤ 5), then
    // batches of 101: a block map and 37 recursion steps each.
    let batches = || {
        std::iter::once(0..20_000).chain((20_000..n).step_by(101).map(move |i| i..(i + 101).min(n)))
    };
    for m in 0..=8 {
        let mut row = Vec::new();
        for theta in [0.5, 0.9, 0.99, 0.999] {
            let mut one = FadingMemory::new(m, theta, 0.1, Engine::Gain).unwrap();
            let mut many = FadingMemory::new(m, theta, 0.1, Engine::Gain).unwrap();
            let mut scale = vec![0.0f64; m + 1];
            let mut worst = vec![0.0f64; m + 1];
            for r in batches() {
                let (tc, yc) = (&times[r.clone()], &ys[r]);
                many.update_many(tc, yc).unwrap();
                for (t, y) in tc.iter().zip(yc) {
                    one.update(*t, *y).unwrap();
                }
                if one.samples() < n as u64 / 2 {
                    continue;
                }
                let a = one.estimate().unwrap().derivatives;
                let b = many.estimate().unwrap().derivatives;
                for k in 0..=m {
                    scale[k] = scale[k].max(a[k].abs());
                    worst[k] = worst[k].max((a[k] - b[k]).abs());
                }
            }
            let switched = many.switched_at().expect("switched within the run");
            assert!(
                switched < n as u64 / 2,
                "m = {m}, θ = {theta}: switch at {switched}"
            );
            let rel = worst
                .iter()
                .zip(&scale)
                .map(|(w, s)| w / s)
                .fold(0.0, f64::max);
            row.push(format!("{rel:.1e}"));
            assert!(rel < 1e-11, "m = {m}, θ = {theta}: {rel:e}");
        }
        eprintln!("| {m} | {} |", row.join(" | "));
    }
}

/// The plain-`f64` expanding-memory kernel (degrees ≤ 4; measured once for all degrees to
/// choose that bound: 7.2e-12 at 5, 4.3e-11 at 7, 1.1e-9 at 8 on even times, 8.6e-9 at 8
/// jittered) against the compensated per-sample path: 60 000
/// samples, even (`t = k·0.1`) and jittered (±30 %) times, worst difference over the run
/// from sample `10(m+1)` (every 101st sample), relative to the largest `|x^(k)|` there.
#[test]
fn plain_expanding_kernel_accuracy_over_long_runs() {
    let n = 60_000;
    for jitter in [false, true] {
        let times = grid(n, jitter);
        let ys: Vec<f64> = (0..n).map(sample).collect();
        let mut row = Vec::new();
        let mut rels = Vec::new();
        for m in 0..=8 {
            let mut one = ExpandingMemory::new(m, Engine::Gain).unwrap();
            let mut many = ExpandingMemory::new(m, Engine::Gain).unwrap();
            let mut scale = vec![0.0f64; m + 1];
            let mut worst = vec![0.0f64; m + 1];
            for (tc, yc) in times.chunks(101).zip(ys.chunks(101)) {
                many.update_many(tc, yc).unwrap();
                for (t, y) in tc.iter().zip(yc) {
                    one.update(*t, *y).unwrap();
                }
                if one.samples() < 10 * (m as u64 + 1) {
                    continue;
                }
                let a = one.estimate().unwrap().derivatives;
                let b = many.estimate().unwrap().derivatives;
                for k in 0..=m {
                    scale[k] = scale[k].max(a[k].abs());
                    worst[k] = worst[k].max((a[k] - b[k]).abs());
                }
            }
            let rel = worst
                .iter()
                .zip(&scale)
                .map(|(w, s)| w / s)
                .fold(0.0, f64::max);
            row.push(format!("{rel:.1e}"));
            rels.push(rel);
        }
        eprintln!(
            "| {} | {} |",
            if jitter { "±30 %" } else { "even" },
            row.join(" | ")
        );
        // Degrees ≤ 4 run the plain kernel; above, update_many takes the compensated path.
        for (m, rel) in rels.iter().enumerate() {
            let bound = if m <= 4 { 1e-12 } else { 0.0 };
            assert!(*rel <= bound, "m = {m}, jitter = {jitter}: {rel:e}");
        }
    }
}

/// `update_many_into` writes, for every sample, the estimate `update` + `estimate` gives.
#[test]
fn update_many_into_writes_every_samples_estimate() {
    for m in [0, 1, 2, 4, 6] {
        for irregular in [false, true] {
            let times = grid(2500, irregular);
            let ys: Vec<f64> = (0..times.len()).map(sample).collect();
            for ((name, mut one), (_, mut many)) in
                filters(m, irregular).into_iter().zip(filters(m, irregular))
            {
                let w = m + 1;
                let mut est = vec![0.0; times.len() * w];
                let mut i = 0;
                let mut len = 1;
                while i < times.len() {
                    let j = (i + len).min(times.len());
                    many.update_many_into(&times[i..j], &ys[i..j], &mut est[i * w..j * w])
                        .unwrap();
                    i = j;
                    len = len % 500 + 61;
                }
                let mut scale = vec![0.0f64; w];
                let mut worst = 0.0f64;
                for (k, row) in est.chunks(w).enumerate() {
                    one.update(times[k], ys[k]).unwrap();
                    match one.estimate() {
                        Some(s) => {
                            for (sc, x) in scale.iter_mut().zip(&s.derivatives) {
                                *sc = sc.max(x.abs());
                            }
                            worst = worst.max(rel_diff(&s.derivatives, row, &scale));
                        }
                        None => assert!(row.iter().all(|v| v.is_nan()), "{name}: row {k}"),
                    }
                }
                eprintln!("m = {m}, irregular = {irregular}, {name}: {worst:.2e}");
                let bound = if name.contains("Gain") { 1e-11 } else { 0.0 };
                assert!(worst <= bound, "m = {m} {name}: {worst:e}");
            }
        }
    }
}

#[test]
fn update_many_into_checks_lengths_and_stops_at_a_bad_sample() {
    for (name, mut f) in filters(2, true) {
        let mut short = vec![0.0; 8];
        let err = f
            .update_many_into(&[1.0, 2.0, 3.0], &[1.0, 2.0, 3.0], &mut short)
            .unwrap_err();
        assert!(
            matches!(
                err,
                Error::InvalidParameter {
                    name: "estimates length",
                    ..
                }
            ),
            "{name}: {err}"
        );
        assert_eq!(f.samples(), 0, "{name}");
        let t: Vec<f64> = (0..40).map(|k| k as f64).chain([10.0, 50.0]).collect();
        let y: Vec<f64> = t.iter().map(|t| t * t).collect();
        let mut est = vec![-1.0; t.len() * 3];
        let err = f.update_many_into(&t, &y, &mut est).unwrap_err();
        assert!(
            matches!(err, Error::InBatch { index: 40, .. }),
            "{name}: {err}"
        );
        // rows 0..40 written (the last one exactly y = t², y' = 2t, y'' = 2), the rest untouched
        assert!(
            (est[39 * 3] - 1521.0).abs() < 1e-6,
            "{name}: {:?}",
            &est[117..120]
        );
        assert!(
            (est[39 * 3 + 2] - 2.0).abs() < 1e-6,
            "{name}: {:?}",
            &est[117..120]
        );
        assert!(est[40 * 3..].iter().all(|v| *v == -1.0), "{name}");
    }
}

/// Even runs interrupted by gaps (dropouts) and a changed step: `update_many` (whole blocks of
/// even steps as block maps or least-squares updates where it can, the recursion around the
/// breaks) against per-sample `update`,
/// fading memory (both discount modes) and expanding memory, degrees 0-8.
#[test]
fn update_many_across_gaps_and_step_changes() {
    let mut times = Vec::new();
    let mut t = 0.0;
    for k in 0..25_000 {
        // dropouts (a missing sample, then 7-sample gaps) and a step change from 0.1 to 0.25
        let step = if k < 3000 { 0.1 } else { 0.25 };
        t += if k == 700 || k == 1901 {
            2.0 * step
        } else if k == 2500 || k == 22_001 {
            8.0 * step
        } else {
            step
        };
        times.push(t);
    }
    let ys: Vec<f64> = (0..times.len()).map(sample).collect();
    for m in 0..=8 {
        for mode in [
            Some(seqsmooth::DiscountMode::PerTime),
            Some(seqsmooth::DiscountMode::PerUpdate),
            None,
        ] {
            let make = || -> Box<dyn PolynomialFilter> {
                match mode {
                    Some(mode) => Box::new(
                        FadingMemory::new(m, 0.95, 0.1, Engine::Gain)
                            .unwrap()
                            .with_discount_mode(mode)
                            .unwrap(),
                    ),
                    None => Box::new(ExpandingMemory::new(m, Engine::Gain).unwrap()),
                }
            };
            let (mut one, mut many) = (make(), make());
            // Degrees ≤ 5 (the block paths): a batch of 20 000 samples (long enough for the
            // block maps to be built), then batches of 997, over 25 000 samples. Degrees 6-8 (the
            // recursion alone, which drifts further from the compensated path over long runs
            // with gaps: 5.6e-11 at degree 8 over 25 000): batches of 997 over the first 5 000.
            // Compared at each batch end, relative to the largest |x^(k)| so far.
            let mut scale = vec![0.0f64; m + 1];
            let mut worst = 0.0f64;
            let (n, first) = if m <= 5 {
                (times.len(), 20_000)
            } else {
                (5_000, 997)
            };
            let batches = std::iter::once(0..first)
                .chain((first..n).step_by(997).map(|i| i..(i + 997).min(n)));
            for r in batches {
                let (tc, yc) = (&times[r.clone()], &ys[r]);
                many.update_many(tc, yc).unwrap();
                for (t, y) in tc.iter().zip(yc) {
                    one.update(*t, *y).unwrap();
                }
                let a = one.estimate().unwrap().derivatives;
                let b = many.estimate().unwrap().derivatives;
                for (s, x) in scale.iter_mut().zip(&a) {
                    *s = s.max(x.abs());
                }
                worst = worst.max(rel_diff(&a, &b, &scale));
            }
            assert!(worst <= 1e-11, "m = {m}, {mode:?}: {worst:e}");
        }
    }
}
