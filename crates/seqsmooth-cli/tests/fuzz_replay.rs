//! Replays the fuzz corpora on stable: every file of `fuzz/corpus/<target>/` goes through the
//! same body (`fuzz/bodies/`) as the cargo-fuzz target `<target>` runs, which panics when an
//! invariant fails (a panic, a NaN or infinite output, an error without a message); an input
//! that takes longer than 10 s fails too. `fuzz/regressions/<target>/` holds the inputs the
//! campaigns found failing, replayed by the ignored test `regressions` until they pass.

#[path = "../../../fuzz/bodies/mod.rs"]
mod bodies;

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The longest one input may take (libFuzzer's `-timeout=10` in the campaigns).
const TIME_OUT: Duration = Duration::from_secs(10);

fn fuzz_dir(kind: &str, target: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fuzz")
        .join(kind)
        .join(target)
}

/// The files of `dir`, sorted (none if it does not exist).
fn inputs(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|d| d.map(|e| e.expect("a directory entry").path()).collect())
        .unwrap_or_default();
    files.retain(|p| p.is_file() && !p.ends_with("README.md"));
    files.sort();
    files
}

/// Runs every input of `kind/<target>/` through its body; returns the number run, and
/// panics naming the first input that fails.
fn replay(kind: &str, target: &str, body: fn(&[u8])) -> usize {
    let files = inputs(&fuzz_dir(kind, target));
    for file in &files {
        let data = std::fs::read(file).expect("a corpus file");
        let start = Instant::now();
        if let Err(e) = std::panic::catch_unwind(|| body(&data)) {
            let why = e
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            panic!("{} fails: {why}", file.display());
        }
        let took = start.elapsed();
        assert!(took < TIME_OUT, "{} took {took:?}", file.display());
    }
    files.len()
}

fn body(target: &str) -> fn(&[u8]) {
    bodies::TARGETS
        .iter()
        .find(|(name, _)| *name == target)
        .map(|&(_, body)| body)
        .expect("a target")
}

macro_rules! corpus {
    ($($test:ident => $target:literal),+ $(,)?) => {
        $(
            #[test]
            fn $test() {
                let n = replay("corpus", $target, body($target));
                assert!(n > 0, "the corpus of {} is empty", $target);
            }
        )+
    };
}

corpus! {
    corpus_csv => "csv",
    corpus_number => "number",
    corpus_filters => "filters",
    corpus_cli => "cli",
}

/// The failing inputs the campaigns found (see `fuzz/regressions/README.md`): ignored until
/// the library and CLI are fixed; run with `cargo test --release -p seqsmooth-cli --test
/// fuzz_replay -- --ignored`.
#[test]
#[ignore = "the inputs the fuzz campaigns found failing; enable once fixed"]
fn regressions() {
    let mut failed = Vec::new();
    for (target, body) in bodies::TARGETS {
        for file in inputs(&fuzz_dir("regressions", target)) {
            let data = std::fs::read(&file).expect("a regression file");
            let start = Instant::now();
            let ok = std::panic::catch_unwind(|| body(&data)).is_ok();
            if !ok || start.elapsed() >= TIME_OUT {
                failed.push(file.display().to_string());
            }
        }
    }
    assert!(failed.is_empty(), "failing: {failed:#?}");
}
