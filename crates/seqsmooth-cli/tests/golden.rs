//! The command's outputs, byte for byte, against golden files made by the binary before the
//! command's re-layout (`tests/fixtures/golden/make.sh`, which lists how): standard output,
//! standard error, the exit code, and the files a case writes (`*.out` names in its arguments).
//!
//! Nine cases are compared by value instead, because their engine changed on purpose: `smooth`
//! and `smooth-irregular` (whole-series smoothing now runs the fixed-memory filter's sliding
//! engine, `O(m²)` per sample at any window, instead of convolving; and it streams, with the 1σ
//! columns `s0..sM` after the golden `d0..dM`, which are left out of the comparison), `fixed`
//! (the window fit evaluates its derivatives in another order), and the cases with `--sigma`
//! of the expanding and fading filters, `exp-gain-sigma`, `fad-gain-sigma-lead`,
//! `fad-irregular`, `id-fad-sigma` and `awkward-fad` (the batch σ path: the gain engine's
//! covariance recursion runs in place and the exact engine's 1σ come from the information
//! factor row by row, without a matrix per sample: the 1σ move in the last digits), and `auto`
//! (the automatic filter's degree-`m` memories are taken from the leading block of their
//! degree `m + 1` companions' factors, the same least squares: its numbers move by at most
//! 1.7e-13 of their columns' largest, no flag or empty cell changes). Their text cells must be equal and every number
//! within [`CHANGED_ENGINE_TOLERANCE`] of its golden value, relative to the largest magnitude
//! of its column; the bound the library's tests put on `smooth` against the exact-weight
//! convolution is the same 1e-11.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Cases whose numbers may move by rounding (see the module docs).
const CHANGED_ENGINE: [&str; 9] = [
    "auto",
    "fixed",
    "smooth",
    "smooth-irregular",
    "exp-gain-sigma",
    "fad-gain-sigma-lead",
    "fad-irregular",
    "id-fad-sigma",
    "awkward-fad",
];
/// Relative to the largest magnitude in the cell's column.
const CHANGED_ENGINE_TOLERANCE: f64 = 1e-11;

/// `got` equals `want` cell by cell: text exactly, numbers within the tolerance.
fn assert_close_csv(name: &str, got: &[u8], want: &[u8]) {
    let rows = |b: &[u8]| -> Vec<Vec<String>> {
        String::from_utf8_lossy(b)
            .lines()
            .map(|l| l.split(',').map(str::to_string).collect())
            .collect()
    };
    let (mut got, want) = (rows(got), rows(want));
    // `smooth`'s 1σ columns s0..sM, which its golden files predate.
    if name.starts_with("smooth") && got.first().is_some_and(|h| h.iter().any(|c| c == "s0")) {
        let keep: Vec<bool> = got[0].iter().map(|c| !c.starts_with('s')).collect();
        for row in got.iter_mut() {
            let mut k = keep.iter();
            row.retain(|_| *k.next().unwrap_or(&true));
        }
    }
    assert_eq!(got.len(), want.len(), "{name}: row count");
    let width = want.iter().map(Vec::len).max().unwrap_or(0);
    let scale: Vec<f64> = (0..width)
        .map(|c| {
            want.iter()
                .filter_map(|r| r.get(c)?.parse::<f64>().ok())
                .fold(0.0, |a: f64, v| a.max(v.abs()))
        })
        .collect();
    let mut numbers = 0;
    for (i, (g, w)) in got.iter().zip(&want).enumerate() {
        assert_eq!(g.len(), w.len(), "{name}: row {i} width");
        for (c, (a, b)) in g.iter().zip(w).enumerate() {
            match (a.parse::<f64>(), b.parse::<f64>()) {
                (Ok(x), Ok(y)) => {
                    numbers += 1;
                    assert!(
                        (x - y).abs() <= CHANGED_ENGINE_TOLERANCE * scale[c],
                        "{name}: row {i}, column {c}: {a} against golden {b}"
                    );
                }
                _ => assert_eq!(a, b, "{name}: row {i}, column {c}"),
            }
        }
    }
    assert!(numbers > 20, "{name}: {numbers} numbers compared");
}

fn golden() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/golden")
}

#[test]
fn outputs_are_byte_identical_to_the_golden_files() {
    let dir = golden();
    let work = std::env::temp_dir().join(format!("seqsmooth-golden-{}", std::process::id()));
    std::fs::create_dir_all(&work).unwrap();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy();
        if path.extension().is_some_and(|e| e == "csv") && !name.starts_with("written-") {
            std::fs::copy(&path, work.join(path.file_name().unwrap())).unwrap();
        }
    }
    let cases = std::fs::read_to_string(dir.join("cases.txt")).unwrap();
    let mut checked = 0;
    for line in cases.lines().filter(|l| !l.is_empty()) {
        let (name, args) = line.split_once('|').unwrap();
        let args: Vec<&str> = args.split_whitespace().collect();
        // Cases read the outputs of earlier ones (plot): those are the golden files.
        let written: Vec<&str> = args
            .windows(2)
            .filter(|w| w[0] == "-o")
            .map(|w| w[1])
            .collect();
        for a in args
            .iter()
            .filter(|a| a.ends_with(".out") && !written.contains(a))
        {
            std::fs::copy(dir.join(a), work.join(a)).unwrap();
        }
        for w in &written {
            let _ = std::fs::remove_file(work.join(w));
        }
        let out = Command::new(env!("CARGO_BIN_EXE_seqsmooth"))
            .args(&args)
            .current_dir(&work)
            .output()
            .unwrap();
        let want = |ext: &str| std::fs::read(dir.join(format!("{name}.{ext}"))).unwrap();
        if CHANGED_ENGINE.contains(&name) {
            assert_close_csv(name, &out.stdout, &want("out"));
        } else {
            assert_eq!(out.stdout, want("out"), "{name}: standard output");
        }
        assert_eq!(out.stderr, want("err"), "{name}: standard error");
        let code = out.status.code().unwrap().to_string();
        assert_eq!(
            code.as_bytes(),
            want("code").trim_ascii(),
            "{name}: exit code"
        );
        // Files the case writes (-o NAME.out): compared too.
        for w in written {
            let got = std::fs::read(work.join(w)).unwrap_or_default();
            assert!(got == std::fs::read(dir.join(w)).unwrap(), "{name}: {w}");
        }
        checked += 1;
    }
    assert!(checked >= 30, "{checked} cases");
    let _ = std::fs::remove_dir_all(&work);
}
