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
