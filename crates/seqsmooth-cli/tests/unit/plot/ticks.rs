//! Unit tests of `plot::ticks`: short, distinct tick labels at any magnitude, epoch dates.

use seqsmooth_cli::plot::ticks::{tick, unix_date, Scale};

/// The labels of the ticks of `lo..hi` as the chart draws them: in tick units, at the
/// multiples of a 1-2-5 step in it of about a tenth of the span, with the decimals of that.
fn labels(lo: f64, hi: f64, origin: Option<f64>) -> (Scale, Vec<String>) {
    let scale = Scale::for_range(lo, hi, origin);
    let (a, b) = (scale.to_axis(lo), scale.to_axis(hi));
    let rough = (b - a) / 10.0;
    let p = 10f64.powf(rough.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * p)
        .find(|&s| s >= rough)
        .unwrap();
    let first = (a / step).ceil() as i64;
    let last = (b / step).floor() as i64;
    let ticks = (first..=last)
        .map(|k| tick(k as f64 * step, rough))
        .collect();
    (scale, ticks)
}

fn assert_short_and_distinct(what: &str, labels: &[String]) {
    assert!(labels.len() >= 4, "{what}: {labels:?}");
    for (i, l) in labels.iter().enumerate() {
        assert!(
            l.chars().count() <= 10,
            "{what}: label '{l}' is longer than 10 characters"
        );
        assert!(
            !labels[..i].contains(l),
            "{what}: label '{l}' repeats: {labels:?}"
        );
    }
}

/// Epoch nanoseconds (1.7e18 + 0..1e9) and a small rate (1e-9 scale), and more magnitudes:
/// every label short and distinct, and the axis note says how to read them back.
#[test]
fn labels_are_short_and_distinct_at_any_magnitude() {
    let (s, l) = labels(1.7e18, 1.7e18 + 1e9, None);
    assert_short_and_distinct("1.7e18 + 1e9", &l);
    assert_eq!(s.note("value"), "value = tick × 1e9 + 1.7e18");
    let (s, l) = labels(0.0, 3e-9, None);
    assert_short_and_distinct("0..3e-9", &l);
    assert_eq!(s.note("value"), "value = tick × 1e-9");
    assert!(l.iter().all(|l| !l.starts_with("0.0000")), "{l:?}");
    let (s, l) = labels(-2.1e-9, 1.3e-9, None);
    assert_short_and_distinct("-2.1e-9..1.3e-9", &l);
    assert_eq!(s.exponent, -9);
    // Epoch nanoseconds on a time axis: measured from the first time t₀, with its date.
    let t0 = 1_700_000_000_123_456_768.0;
    let (s, l) = labels(t0 - 6e8, t0 + 6e10, Some(t0));
    assert_short_and_distinct("epoch ns", &l);
    assert_eq!(
        s.note("t"),
        "t = t₀ + tick × 1e9, t₀ = 1.7000000001234568e18 (as Unix ns: 2023-11-14 22:13:20 UTC)"
    );
    for (lo, hi) in [
        (1.7e9, 1.7e9 + 60.0),
        (-1e300, 1e300),
        (1e-300, 2e-300),
        (-5e7, 5e7),
    ] {
        let (_, l) = labels(lo, hi, None);
        assert_short_and_distinct(&format!("{lo}..{hi}"), &l);
    }
}

/// Ordinary ranges are drawn as they are: no offset, no power of ten.
#[test]
fn ordinary_ranges_are_plain() {
    for (lo, hi) in [
        (0.0, 1.0),
        (-173184.5, -10000.0),
        (-150.0, 130.0),
        (0.01, 0.05),
        (0.0, 425.0),
    ] {
        assert_eq!(
            Scale::for_range(lo, hi, Some(lo)),
            Scale::PLAIN,
            "{lo}..{hi}"
        );
        assert_eq!(Scale::PLAIN.note("t"), "");
    }
}

#[test]
fn unix_dates_in_every_unit() {
    let date = "2023-11-14 22:13:20 UTC";
    assert_eq!(unix_date(1.7e9), Some(("s", date.to_string())));
    assert_eq!(unix_date(1.7e12), Some(("ms", date.to_string())));
    assert_eq!(unix_date(1.7e15), Some(("µs", date.to_string())));
    assert_eq!(unix_date(1.7e18), Some(("ns", date.to_string())));
    assert_eq!(
        unix_date(951_782_400.0).unwrap().1,
        "2000-02-29 00:00:00 UTC"
    );
    assert_eq!(unix_date(100.0), None);
    assert_eq!(unix_date(1e25), None);
}
