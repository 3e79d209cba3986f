//! `PolynomialFilter::update_many` against per-sample `update`: same estimates, same errors,
//! and the accuracy of the gain engines' plain-`f64` kernels.

mod common;

use common::batch::*;
use seqsmooth::error::Param;
use seqsmooth::{Engine, Error, ExpandingMemory, FadingMemory, PolynomialFilter};

#[test]
fn update_many_equals_update_on_even_and_irregular_times() {
    for m in [0, 1, 2, 3, 5, 8] {
        for irregular in [false, true] {
            for (name, worst) in update_many_difference(m, irregular) {
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
                name: Param::BatchLengths,
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
/// degree and θ (`common::batch::plain_steady_kernel_error`). The measured table:
/// `cargo run --release -p seqsmooth --example accuracy_batch`.
#[test]
fn plain_steady_kernel_accuracy_over_long_runs() {
    for m in 0..=8 {
        for theta in [0.5, 0.9, 0.99, 0.999] {
            let (rel, switched) = plain_steady_kernel_error(m, theta);
            assert!(
                switched < LONG_RUN as u64 / 2,
                "m = {m}, θ = {theta}: switch at {switched}"
            );
            assert!(rel < 1e-11, "m = {m}, θ = {theta}: {rel:e}");
        }
    }
}

/// The plain-`f64` expanding-memory kernel (degrees ≤ 4; measured once for all degrees to
/// choose that bound: 7.2e-12 at 5, 4.3e-11 at 7, 1.1e-9 at 8 on even times, 8.6e-9 at 8
/// jittered) against the compensated per-sample path
/// (`common::batch::plain_expanding_kernel_error`). The measured table:
/// `cargo run --release -p seqsmooth --example accuracy_batch`.
#[test]
fn plain_expanding_kernel_accuracy_over_long_runs() {
    for jitter in [false, true] {
        for m in 0..=8 {
            let rel = plain_expanding_kernel_error(m, jitter);
            // Degrees ≤ 4 run the plain kernel; above, update_many takes the compensated path.
            let bound = if m <= 4 { 1e-12 } else { 0.0 };
            assert!(rel <= bound, "m = {m}, jitter = {jitter}: {rel:e}");
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
                    name: Param::EstimatesLength,
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

/// Times from 1.7e9 in steps of 0.1 with a stretch of uneven steps (the steady kernels stop
/// and start again), and values on a curve with a bounded wiggle.
fn long_batch(n: usize) -> (Vec<f64>, Vec<f64>) {
    let t: Vec<f64> = (0..n)
        .map(|k| {
            let jitter = if (2_000..2_100).contains(&k) {
                0.03 * (k % 3) as f64
            } else {
                0.0
            };
            1.7e9 + k as f64 * 0.1 + jitter
        })
        .collect();
    let y = (0..n)
        .map(|k| (k as f64 * 1e-3).sin() * 5.0 + ((k * 37) % 11) as f64 / 20.0)
        .collect();
    (t, y)
}

/// `update_many_into` checks, runs and marks its batch in chunks (so that each chunk's
/// numbers stay in cache): the rows are the same to the bit however the batch is split, for
/// every kind and engine at degrees 2 and 8, across the chunks and the uneven stretch.
#[test]
fn update_many_into_is_the_same_in_any_split() {
    let n = 5_000;
    let (t, y) = long_batch(n);
    for m in [2, 8] {
        let w = m + 1;
        let whole: Vec<(String, Vec<f64>)> = filters(m, true)
            .into_iter()
            .map(|(name, mut f)| {
                let mut rows = vec![0.0; n * w];
                f.update_many_into(&t, &y, &mut rows).unwrap();
                (name, rows)
            })
            .collect();
        for split in [&[1usize, 1023, 1, 1024, 1025, 7][..], &[4999], &[2048, 1]] {
            for ((name, mut f), (_, want)) in filters(m, true).into_iter().zip(&whole) {
                let mut rows = vec![0.0; n * w];
                let mut start = 0;
                for &len in split.iter().chain([&n]) {
                    let end = (start + len).min(n);
                    f.update_many_into(
                        &t[start..end],
                        &y[start..end],
                        &mut rows[start * w..end * w],
                    )
                    .unwrap();
                    start = end;
                }
                let same = rows
                    .iter()
                    .zip(want)
                    .all(|(a, b)| a.to_bits() == b.to_bits());
                assert!(same, "m = {m} {name}, split {split:?}");
                assert!(rows[n * w - w..].iter().all(|v| v.is_finite()), "{name}");
            }
        }
    }
}

/// A bad sample in a later chunk of `update_many_into` is reported at its index; the samples
/// before it are taken and their rows written as in a clean run.
#[test]
fn update_many_into_reports_a_bad_sample_in_a_later_chunk() {
    let n = 5_000;
    let (t, mut y) = long_batch(n);
    let (clean_t, clean_y) = (t[..3_333].to_vec(), y[..3_333].to_vec());
    y[3_333] = f64::NAN;
    for ((name, mut f), (_, mut g)) in filters(2, true).into_iter().zip(filters(2, true)) {
        let mut rows = vec![0.0; n * 3];
        match f.update_many_into(&t, &y, &mut rows).unwrap_err() {
            Error::InBatch { index, .. } => assert_eq!(index, 3_333, "{name}"),
            other => panic!("{name}: {other}"),
        }
        assert_eq!(f.samples(), 3_333, "{name}");
        let mut want = vec![0.0; 3_333 * 3];
        g.update_many_into(&clean_t, &clean_y, &mut want).unwrap();
        let same = rows[..want.len()]
            .iter()
            .zip(&want)
            .all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(same, "{name}");
    }
}

/// Derivatives beyond the double range in the gain engine's steady kernel (τ = 1e-100 with
/// samples τ apart, y = 1e110·k²: x'' = 2e310 per unit time²) are NaN in the rows, the other
/// derivatives stand, and no row holds an infinity; the estimate names `d2`.
#[test]
fn the_steady_kernel_marks_derivatives_beyond_the_double_range() {
    let n = 3_000;
    let tau = 1e-100;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * tau).collect();
    let y: Vec<f64> = (0..n).map(|k| 1e110 * (k as f64).powi(2)).collect();
    for (m, theta) in [(2, 0.9), (3, 0.95)] {
        let mut f = FadingMemory::new(m, theta, tau, Engine::Gain).unwrap();
        let mut rows = vec![0.0; n * (m + 1)];
        f.update_many_into(&t, &y, &mut rows).unwrap();
        assert!(rows.iter().all(|v| !v.is_infinite()));
        let last = &rows[(n - 1) * (m + 1)..];
        assert!(last[2].is_nan(), "{last:?}");
        // d0 ≈ y, d1 ≈ 2e110·k/τ = 6e213 at k = 3000 (the fading fit of a parabola is exact)
        let k = (n - 1) as f64;
        assert!((last[0] / (1e110 * k * k) - 1.0).abs() < 1e-6, "{last:?}");
        assert!((last[1] / (2e110 * k / tau) - 1.0).abs() < 1e-6, "{last:?}");
        match f.try_estimate() {
            Err(Error::EstimateOutOfRange { what }) => assert_eq!(what, "d2"),
            other => panic!("{other:?}"),
        }
    }
}
