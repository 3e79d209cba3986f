//! The stored runs the Python package must match to the last bit
//! (`crates/seqsmooth-py/tests/fixtures/*_rust.txt`): a line of numbers in shortest
//! round-trip form, and the check that a stored file is this library's run (rewritten with
//! `SEQSMOOTH_WRITE_FIXTURES=1`).

use std::fmt::Write;
use std::path::PathBuf;

/// `tag,v1,v2,…` (shortest round-trip digits) and a newline.
pub fn line(out: &mut String, tag: &str, values: impl IntoIterator<Item = f64>) {
    out.push_str(tag);
    for v in values {
        write!(out, ",{v:?}").unwrap();
    }
    out.push('\n');
}

/// Writes `text` to the fixture `name` when `SEQSMOOTH_WRITE_FIXTURES` is set, then fails
/// unless the stored fixture is `text`.
pub fn check(name: &str, text: &str) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../seqsmooth-py/tests/fixtures")
        .join(name);
    if std::env::var_os("SEQSMOOTH_WRITE_FIXTURES").is_some() {
        std::fs::write(&path, text).unwrap();
    }
    let stored = std::fs::read_to_string(&path).unwrap();
    assert!(
        stored == text,
        "{} is not this library's run",
        path.display()
    );
}
