//! The papers' experiments (docs/reyneke.md, docs/morrison.md): each page holds the blocks its
//! programs print, each under a marker `<!-- regenerated: EXAMPLE --runs N --seed S -->`; this
//! test runs each program's report at that `--runs` and `--seed` and compares it with the
//! block, so the pages' numbers are the programs' and not typed. The programs are the
//! examples themselves, compiled in here.

// Each example is compiled here as it is, with its own `mod papers` of the shared options.
#![allow(clippy::duplicate_mod)]

#[allow(dead_code)]
#[path = "../examples/morrison_figures.rs"]
mod morrison_figures;
#[allow(dead_code)]
#[path = "../examples/reyneke_equal.rs"]
mod reyneke_equal;
#[allow(dead_code)]
#[path = "../examples/reyneke_fig1.rs"]
mod reyneke_fig1;
#[allow(dead_code)]
#[path = "../examples/reyneke_gof.rs"]
mod reyneke_gof;

use std::path::Path;

/// Each marked block of `page`: `(example, runs, seed, block text)`.
fn blocks(page: &str) -> Vec<(String, usize, u64, String)> {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../..")
            .join(page),
    )
    .unwrap_or_else(|e| panic!("{page}: {e}"));
    let mut out = Vec::new();
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        let Some(rest) = line.trim().strip_prefix("<!-- regenerated:") else {
            continue;
        };
        let words: Vec<&str> = rest.trim_end_matches("-->").split_whitespace().collect();
        let (name, mut runs, mut seed) = (words[0].to_string(), None, None);
        for pair in words[1..].chunks(2) {
            match pair {
                ["--runs", v] => runs = Some(v.parse().expect("runs")),
                ["--seed", v] => seed = Some(v.parse().expect("seed")),
                other => panic!("{page}: unknown option {other:?} in the marker of {name}"),
            }
        }
        assert_eq!(
            lines.next().map(str::trim),
            Some("```text"),
            "{page}: {name}'s block"
        );
        let block: Vec<&str> = lines.by_ref().take_while(|l| l.trim() != "```").collect();
        out.push((
            name,
            runs.expect("--runs in the marker"),
            seed.expect("--seed in the marker"),
            block.join("\n") + "\n",
        ));
    }
    out
}

fn regenerated(page: &str, expected: &[&str]) {
    let found = blocks(page);
    for name in expected {
        assert!(
            found.iter().any(|b| b.0 == *name),
            "{page} has no block of {name}"
        );
    }
    for (name, runs, seed, block) in found {
        let printed = match name.as_str() {
            "reyneke_fig1" => reyneke_fig1::report(runs, seed),
            "reyneke_equal" => reyneke_equal::report(runs, seed),
            "reyneke_gof" => reyneke_gof::report(runs, seed),
            "morrison_figures" => morrison_figures::report(runs, seed),
            other => panic!("{page}: no program {other}"),
        };
        assert_eq!(
            printed, block,
            "{page}: the block of {name} --runs {runs} --seed {seed} is not what the program prints"
        );
    }
}

#[test]
fn reyneke_page_is_regenerated() {
    regenerated(
        "docs/reyneke.md",
        &["reyneke_fig1", "reyneke_equal", "reyneke_gof"],
    );
}

#[test]
fn morrison_page_is_regenerated() {
    regenerated("docs/morrison.md", &["morrison_figures"]);
}

/// The claims the pages draw from the blocks, checked on the programs' own numbers at small
/// runs: the variable-step filters equal the original ones (Reyneke et al. §8.1), and the
/// interpolation start leaves the larger transient (Morrison §13.8).
#[test]
fn the_pages_claims_hold_at_small_runs() {
    let equal = reyneke_equal::report(5, 7);
    for line in equal.lines().skip(2) {
        let sum_sq: f64 = line.split('|').nth(1).unwrap().trim().parse().unwrap();
        assert!(sum_sq < 1e-10, "{line}");
    }
    let fig = morrison_figures::report(40, 3);
    // at n = 40, the interpolation start's RMS error is several times the expanding start's
    for line in fig.lines().filter(|l| l.trim_start().starts_with("40 |")) {
        let cells: Vec<f64> = line
            .split('|')
            .skip(1)
            .flat_map(|c| c.split_whitespace().map(|v| v.parse::<f64>().unwrap()))
            .collect();
        assert!(cells[0] > 3.0 * cells[2], "{line}");
    }
}
