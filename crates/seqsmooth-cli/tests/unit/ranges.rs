//! No range check in the front ends: the command's argument parsers (`src/args`) and the
//! Python binding (`crates/seqsmooth-py/src`) parse text and objects into numbers and leave
//! every range to the library's checks. The sources (comments and string literals blanked) are
//! scanned for the shapes a range check takes: a clap `.range(…)`, a range's `.contains(&…)`, a
//! comparison with a number or a constant, an `is_finite()` test. The few left are listed with
//! why each is not a parameter's range; any other fails. (A comparison of two variables, such
//! as a window against the degree, is not told from ordinary code: those were moved by hand.)

use std::path::{Path, PathBuf};

/// The shapes found that are not a parameter's range: (file, code on the line, why).
const ALLOWED: &[(&str, &str, &str)] = &[
    (
        "seqsmooth-py/src/automatic.rs",
        "if bytes.iter().any(|&d| d > 1) {",
        "a restored pickle's own extra (the final decisions made but not yet reported, kept \
         beside the library's bytes): data read back, refused as damaged, no parameter",
    ),
    (
        "seqsmooth-py/src/stream.rs",
        "if self.spec.kind.uses_tau() && self.spec.tau.is_none() && !last && n < TAU_SCAN_ROWS {",
        "how the caller cuts the rows into chunks (the library's default-τ rows, \
         TAU_SCAN_ROWS, must come in the first one): a size of the caller's chunk, no parameter",
    ),
    (
        "seqsmooth-py/src/kalman.rs",
        "(r, 1) if r == n && n > 1 => DMatrix::from_diagonal(",
        "a shape branch: a column of n variances read as a diagonal covariance, not a range",
    ),
    (
        "seqsmooth-py/src/track.rs",
        "let sigmas_ok = sigmas.iter().flatten().all(|s| s.is_finite() && *s > 0.0);",
        "a restored pickle's extras (the tracker's noise the binding keeps beside the library's \
         bytes): data read back, refused as damaged, no parameter",
    ),
    (
        "seqsmooth-py/src/callables.rs",
        "if let Some(i) = flat.iter().position(|v| !v.is_finite()) {",
        "a Python callable's result (data): refused naming the callable and the entry, which \
         the library's own refusal of a non-finite estimate could not name",
    ),
    (
        "seqsmooth-py/src/callables.rs",
        "if self.iterations > 1 {",
        "chooses the iterated update for more than one iteration: a branch, not a range",
    ),
    (
        "seqsmooth-cli/src/args/filter.rs",
        "clap::value_parser!(u32).range(1..)",
        "--chunk-rows: the command's own reading in chunks (a hidden testing aid), no library \
         parameter",
    ),
    (
        "seqsmooth-cli/src/args/plot.rs",
        "clap::value_parser!(u32).range(300..=10000)",
        "--width and --height: the image the command draws, no library parameter",
    ),
    (
        "seqsmooth-cli/src/args/mod.rs",
        "whole.as_ref().is_ok_and(|v| *v < 0)",
        "parsing: a negative whole number, which no count can hold, is told apart from text",
    ),
    (
        "seqsmooth-py/src/polynomial.rs",
        "Some(t) if !t.is_finite() => Err(raise(",
        "the time an estimate is asked at (data, not a setting): refused before the library \
         extrapolates to it",
    ),
    (
        "seqsmooth-py/src/fit.rs",
        "if !time.is_finite() {",
        "a row's time (data), refused by the library's NonFinite error with the row's index",
    ),
    (
        "seqsmooth-py/src/fit.rs",
        "} else if !y.is_finite() {",
        "a row's value (data), refused by the library's NonFinite error with the row's index",
    ),
];

/// `src` with its comments and the contents of its string and char literals blanked (the
/// line structure kept), so that a message's "0 < theta < 1" is not taken for code.
fn code_of(src: &str) -> String {
    let mut out = String::with_capacity(src.len());
    let mut chars = src.chars().peekable();
    let mut in_string = false;
    while let Some(c) = chars.next() {
        if in_string {
            match c {
                '\\' => {
                    chars.next();
                    out.push_str("  ");
                }
                '"' => {
                    in_string = false;
                    out.push('"');
                }
                '\n' => out.push('\n'),
                _ => out.push(' '),
            }
            continue;
        }
        match c {
            '/' if chars.peek() == Some(&'/') => {
                for c in chars.by_ref() {
                    if c == '\n' {
                        out.push('\n');
                        break;
                    }
                }
            }
            '"' => {
                in_string = true;
                out.push('"');
            }
            _ => out.push(c),
        }
    }
    out
}

/// Whether `line` (code) has the shape of a range check.
fn looks_like_a_range_check(line: &str) -> bool {
    let bytes = line.as_bytes();
    // A comparison operator (not `=>`, `->`, `<<`, `>>`, generics' `<T>`) followed by a number,
    // a minus sign and a number, or a constant's name.
    let compared = (0..bytes.len()).any(|i| {
        let op = match bytes[i] {
            b'<' | b'>' => i,
            _ => return false,
        };
        let before = op.checked_sub(1).map(|k| bytes[k]);
        if matches!(before, Some(b'=' | b'-' | b'<' | b'>')) {
            return false;
        }
        let mut k = op + 1;
        if matches!(bytes.get(k), Some(b'=')) {
            k += 1;
        }
        if matches!(bytes.get(k), Some(b'<' | b'>')) {
            return false;
        }
        while matches!(bytes.get(k), Some(b' ')) {
            k += 1;
        }
        if matches!(bytes.get(k), Some(b'-')) {
            k += 1;
        }
        let rest = &line[k.min(line.len())..];
        let constant = rest
            .chars()
            .take_while(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || *c == '_')
            .count();
        rest.starts_with(|c: char| c.is_ascii_digit())
            || (constant >= 3 && rest.starts_with(|c: char| c.is_ascii_uppercase()))
    });
    let range_contains = line.contains("..") && line.contains(").contains(&");
    compared || range_contains || line.contains(".range(") || line.contains("is_finite()")
}

/// The `.rs` files under `dir`, recursively.
fn sources(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            files.extend(sources(&path));
        } else if path.extension().is_some_and(|e| e == "rs") {
            files.push(path);
        }
    }
    files.sort();
    files
}

/// Every line of the front ends' parsing code that has the shape of a range check and is not
/// in [`ALLOWED`], as `file:line: code`.
fn range_checks(crates: &Path) -> Vec<String> {
    let mut found = Vec::new();
    for dir in ["seqsmooth-cli/src/args", "seqsmooth-py/src"] {
        for file in sources(&crates.join(dir)) {
            let name = file.strip_prefix(crates).unwrap().to_string_lossy();
            let code = code_of(&std::fs::read_to_string(&file).unwrap());
            for (n, line) in code.lines().enumerate() {
                let line = line.trim();
                let allowed = ALLOWED
                    .iter()
                    .any(|(f, snippet, _)| name == *f && line.contains(snippet));
                if looks_like_a_range_check(line) && !allowed {
                    found.push(format!("{name}:{}: {line}", n + 1));
                }
            }
        }
    }
    found
}

#[test]
fn no_range_check_in_the_front_ends() {
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let crates = crates.canonicalize().unwrap();
    let found = range_checks(&crates);
    assert!(
        found.is_empty(),
        "range checks in the front ends (move them into the library, or say in ALLOWED why \
         one is not a parameter's range):\n{}",
        found.join("\n")
    );
    // Every allowance still names a line that exists.
    for (file, snippet, _) in ALLOWED {
        let code = code_of(&std::fs::read_to_string(crates.join(file)).unwrap());
        assert!(code.contains(snippet), "{file} no longer has {snippet:?}");
    }
}

/// The scanner finds the shapes the front ends used to have (each a range the library now
/// owns), and not the look-alikes of ordinary code, messages and comments.
#[test]
fn the_scanner_finds_range_checks() {
    for check in [
        "value_parser = clap::value_parser!(u32).range(1..=1000))]",
        "Ok(v) if (lo..=hi).contains(&v) => Ok(v),",
        "if !(1..=1000).contains(&max_iterations) {",
        "(|v| v.is_finite() && v > 0.0, \"a positive finite number\");",
        "|v| v.is_finite() && v >= 0.0,",
        "if window < 1 {",
        "if n == 0 || n > 60 {",
        "if n > MAX_GAUSS_DEGREE {",
    ] {
        assert!(looks_like_a_range_check(&code_of(check)), "{check}");
    }
    for ordinary in [
        "let x = y >> 12;",
        "fn f() -> Result<Vec<f64>, Error> {",
        "\"one\" => POLYNOMIAL_WINDOW as i64,",
        "format!(\"kind needs theta (0 < theta < 1)\")",
        "let v: Vec<usize> = Vec::new(); // not if n > 60",
        "let rows = vec![0.0; n * stride];",
    ] {
        assert!(!looks_like_a_range_check(&code_of(ordinary)), "{ordinary}");
    }
}
