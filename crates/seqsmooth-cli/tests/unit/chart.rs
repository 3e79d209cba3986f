//! Unit tests of `chart`: gaps, tick labels and image formats.

use seqsmooth_cli::chart::*;
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
