//! Unit tests of `plot::chart`: gaps, tick labels and image formats.

use seqsmooth_cli::plot::chart::*;
use std::path::Path;

#[test]
fn runs_split_on_gaps() {
    let v = [true, true, false, true, false, false, true];
    assert_eq!(runs(v.len(), |i| v[i]), vec![0..2, 3..4, 6..7]);
    assert!(runs(0, |_| true).is_empty());
}

#[test]
fn tick_labels_have_the_step_decimals() {
    assert_eq!(tick(15000.0, 2500.0), "15000");
    assert_eq!(tick(0.25, 0.05), "0.25");
    assert_eq!(tick(-0.0001, 0.5), "0.0");
    assert_eq!(tick(3.0, 0.5), "3.0");
}

#[test]
fn formats_by_extension() {
    assert_eq!(Format::from_path(Path::new("a/b.PNG")), Some(Format::Png));
    assert_eq!(Format::from_path(Path::new("b.svg")), Some(Format::Svg));
    assert_eq!(Format::from_path(Path::new("b.pdf")), None);
    assert_eq!(Format::from_path(Path::new("b")), None);
}

/// With a lead, each row's estimate is compared with the sample at `t + lead`: found within a
/// thousandth of the median step (the rounding of `t + lead`), never a neighbour.
#[test]
fn samples_at_lead_match_the_estimate_time() {
    let t: Vec<f64> = (0..50).map(|i| 1.7e9 + 0.01 * i as f64).collect();
    let at = samples_at_lead(&t, 0.03);
    for (i, a) in at.iter().enumerate() {
        assert_eq!(*a, (i + 3 < t.len()).then_some(i + 3), "row {i}");
    }
    assert!(samples_at_lead(&t, 0.015).iter().all(Option::is_none));
    assert_eq!(samples_at_lead(&t, -0.01)[0], None);
    assert_eq!(samples_at_lead(&t, -0.01)[1], Some(0));
    assert_eq!(
        samples_at_lead(&t, 0.0),
        (0..50).map(Some).collect::<Vec<_>>()
    );
}

/// The outage rule: a step longer than OUTAGE_STEPS typical (median) steps; jittered steps,
/// dropouts of a few samples and the steps next to them are not outages.
#[test]
fn outages_are_steps_far_beyond_the_median() {
    assert_eq!(OUTAGE_STEPS, 10.0);
    let mut t = vec![0.0];
    for i in 1..1000 {
        let step = 1.0 + 0.3 * ((i * 7919 % 13) as f64 / 6.0 - 1.0);
        // dropouts of up to 3 samples, an outage of 12 at row 500
        let gap = match i {
            100 | 300 => 4.0,
            500 => 12.0 + step,
            _ => step,
        };
        t.push(t[i - 1] + gap);
    }
    assert_eq!(outages(&t), vec![(t[499], t[500])]);
    assert!(is_outage(10.01, 1.0) && !is_outage(10.0, 1.0));
    assert!(outages(&[1.0]).is_empty() && outages(&[]).is_empty());
}

/// Misfit spans: each run from its first row's time to the next row's; joined when closer
/// than the merge distance; a run open at the end closes at the last row.
#[test]
fn flag_spans_run_to_the_next_row_and_merge() {
    let t: Vec<f64> = (0..10).map(f64::from).collect();
    let f = [
        false, true, false, false, true, true, false, true, false, true,
    ];
    assert_eq!(
        flag_spans(&t, &f),
        vec![(1.0, 2.0), (4.0, 6.0), (7.0, 8.0), (9.0, 9.0)]
    );
    let mut s = Spans::default();
    for (&t, &f) in t.iter().zip(&f) {
        s.push(t, f, 1.5);
    }
    assert_eq!(s.finish(1.5), vec![(1.0, 2.0), (4.0, 9.0)]);
}

/// The streaming lead matcher against a direct search over the whole series: for random
/// irregular series and leads of either sign, each row's sample is the nearest one within a
/// thousandth of the median of the first 1024 steps of t + lead, or none.
#[test]
fn lead_matcher_finds_the_sample_at_each_estimate_time() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand::rngs::StdRng::seed_from_u64(30);
    for case in 0..40 {
        let n = rng.gen_range(2..3000);
        let mut t = vec![rng.gen_range(-1e3..1e3)];
        for _ in 1..n {
            let step = if rng.gen_bool(0.5) { 0.25 } else { 0.5 };
            t.push(t[t.len() - 1] + step);
        }
        let lead = [0.0, 0.5, -0.75, 2.0, 0.3][case % 5];
        let head: Vec<f64> = t.windows(2).take(LEAD_HEAD).map(|w| w[1] - w[0]).collect();
        let mut sorted = head.clone();
        sorted.sort_by(f64::total_cmp);
        let median = sorted[((sorted.len() - 1) as f64 * 0.5).round() as usize];
        let tol = 1e-3 * median;
        let want: Vec<Option<usize>> = t
            .iter()
            .map(|&ti| {
                let at = ti + lead;
                (0..n)
                    .filter(|&j| (t[j] - at).abs() <= tol)
                    .min_by(|&a, &b| (t[a] - at).abs().total_cmp(&(t[b] - at).abs()))
            })
            .collect();
        assert_eq!(samples_at_lead(&t, lead), want, "case {case}, lead {lead}");
        if lead == 0.5 {
            assert!(want.iter().any(Option::is_some) && want.iter().any(Option::is_none));
        }
    }
}

/// A row's drawn values: the sample, then per derivative the estimate, its band's edges, 3σ,
/// truth and error, then the residual, truth − estimate, 3σ noise and the sample's error.
#[test]
fn drawn_values_of_a_row() {
    let row = Row {
        t: 2.0,
        y: 10.0,
        d: vec![Some(9.0), None],
        s: vec![Some(1.0), Some(0.5)],
        truth: vec![9.5],
        noise: Some(2.0),
        rejected: true,
        settled: true,
        at: Some(Sample {
            t: 2.0,
            y: 10.0,
            rejected: true,
            truth: vec![Some(9.5)],
        }),
    };
    let mut v = Vec::new();
    drawn(&row, &mut v);
    let nan = f64::NAN;
    let want = [
        nan, 10.0, // sample (rejected)
        9.0, 12.0, 6.0, 3.0, 9.5, -0.5, // d0
        nan, nan, nan, 1.5, nan, nan, // d1 (no estimate)
        nan, 1.0, 0.5, 6.0, // residual (rejected), truth − d0, 3σ noise
        nan, 0.5, // y − truth (rejected)
    ];
    assert_eq!(v.len(), want.len());
    for (k, (a, b)) in v.iter().zip(want).enumerate() {
        assert!(
            a == &b || (a.is_nan() && b.is_nan()),
            "value {k}: {a} != {b}"
        );
    }
}
