//! End-to-end tests of `seqsmooth demo`.

mod common;
use common::*;

/// The demo runs on built-in data, exits 0 and prints a summary of all four filters; `-o`
/// writes one filter's CSV.
#[test]
fn demo_runs() {
    // (the plot itself is tested in tests/plot.rs; keep the crate directory clean)
    let out = ok(&["demo", "--no-plot"], "");
    assert!(!out.is_empty());
    for word in ["expanding", "fading", "exact", "gain"] {
        assert!(out.contains(word), "{out}");
    }
    let path = tmp("demo.csv");
    let path = path.to_str().unwrap();
    let again = ok(&["demo", "--no-plot", "-o", path], "");
    assert_eq!(again, out, "deterministic");
    let csv = std::fs::read_to_string(path).unwrap();
    let (header, rows) = table(&csv);
    assert_eq!(header, ["t", "y", "d0", "d1", "d2", "s0", "s1", "s2"]);
    assert_eq!(rows.len(), 400);
}
