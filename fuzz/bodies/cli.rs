//! The CLI's argument-to-output path, in process: an argument vector decoded from the input
//! goes through clap (`Cli::try_parse_from`) and the subcommand's `run`, as `main` dispatches
//! it, on the rest of the input as the CSV file, with `-o` to a file in a fresh temporary
//! directory (`filter`, `smooth`, `fit` and `track`, the subcommands that read data).
//!
//! Checks: a refused command line has a message; a failed run is a typed error (`Usage` or
//! `Data`) with a message and leaves no output file (nor a temporary one) behind; a
//! successful run writes a header and one row per data row (the first cells echo the input),
//! every computed cell (`d*`, `s*`, `window`, `noise`, `outlier`, `misfit`) empty or a
//! finite number, and no `d` cell empty once the rows of its series determine the estimate
//! (expanding and fading memory: from the degree's `M+1`-th row; fixed memory: where the window
//! cell is `W`; `smooth`: every row; `fit`: the state cells all empty or all numbers).

use super::check;
use super::input::Input;
use clap::Parser;
use seqsmooth_cli::args::{Cli, Command, Kind};
use seqsmooth_cli::commands::{filter, fit, smooth, track};
use seqsmooth_cli::error::CliError;
use std::collections::HashMap;
use std::path::Path;

/// The options of `filter` and `smooth`, with values the input picks among.
const OPTIONS: [(&str, &[&str]); 12] = [
    ("--kind", &["expanding", "fading", "fixed", "auto", "gain"]),
    (
        "--degree",
        &["0", "1", "2", "3", "5", "8", "12", "24", "25", "-1"],
    ),
    ("--theta", &["0.9", "0.5", "9/10", "0.999999", "1", "0"]),
    ("--tau", &["1", "0.01", "1e-300", "1e300", "0"]),
    ("--window", &["1", "2", "3", "5", "11", "101"]),
    ("--engine", &["exact", "gain"]),
    ("--lead", &["0", "1", "-1", "1e308", "-2.5", "1e-300"]),
    ("--time-col", &["t", "y", "id", "x"]),
    ("--value-col", &["y", "t", "id", "x"]),
    ("--sigma", &["1", "0.1", "1e300", "1e-300", "0"]),
    ("--id-col", &["id", "t", "y", "x"]),
    ("--chunk-rows", &["1", "2", "3", "100"]),
];

/// The options of `fit`.
const FIT_OPTIONS: [(&str, &[&str]); 14] = [
    ("--model", &["radar", "polynomial", "kalman"]),
    ("--degree", &["0", "1", "2", "3", "8", "24", "-1"]),
    ("--window", &["1", "2", "3", "5", "60", "0"]),
    ("--epoch", &["end", "centre", "0", "1e300", "nan"]),
    ("--site", &["0,0,0", "1,2,3", "1e300,0,0", "0,0", "nan,0,0"]),
    ("--sigma-range", &["10", "1e-300", "0"]),
    ("--sigma-angle", &["1e-3", "1", "1e300"]),
    ("--sigma", &["1", "0.1", "1e-300"]),
    ("--time-col", &["t", "y", "range", "x"]),
    ("--value-col", &["y", "t", "x"]),
    ("--range-col", &["range", "y", "t"]),
    ("--azimuth-col", &["azimuth", "y", "x"]),
    ("--elevation-col", &["elevation", "y", "x"]),
    ("--max-iterations", &["1", "2", "20", "0"]),
];

/// The options of `track`.
const TRACK_OPTIONS: [(&str, &[&str]); 12] = [
    (
        "--method",
        &["window", "kalman", "fading", "smooth", "bayes"],
    ),
    ("--sigma-range", &["10", "1e-300", "0"]),
    ("--sigma-angle", &["1e-3", "1", "1e300"]),
    ("--q", &["0", "1", "10", "1e300", "-1"]),
    ("--beta", &["0.7", "1", "1e-300", "0"]),
    ("--theta", &["0.9", "0.5"]),
    ("--window", &["1", "2", "6", "60", "0"]),
    ("--azimuth", &["from-x", "bearing"]),
    ("--site", &["0,0,0", "1,2,3", "1e300,0,0"]),
    ("--time-col", &["t", "range", "x"]),
    ("--range-col", &["range", "t", "y"]),
    ("--elevation-col", &["elevation", "azimuth"]),
];

/// The argument vector: subcommand, input and output files, then options as `--name=value`
/// (so that no value can become a file name).
fn arguments(input: &mut Input, csv: &Path, out: &Path) -> Vec<String> {
    let pick = input.byte();
    let (sub, options): (&str, &[(&str, &[&str])]) = if pick.is_multiple_of(4) {
        ("smooth", &OPTIONS)
    } else if pick % 8 == 1 {
        ("fit", &FIT_OPTIONS)
    } else if pick % 8 == 3 {
        ("track", &TRACK_OPTIONS)
    } else {
        ("filter", &OPTIONS)
    };
    let mut args: Vec<String> = vec![
        "seqsmooth".into(),
        sub.into(),
        csv.display().to_string(),
        format!("--output={}", out.display()),
    ];
    let n = input.below(9);
    let mut used = vec![false; options.len()];
    for _ in 0..n {
        let k = input.below(options.len() + 1);
        if k == options.len() {
            if sub != "fit" && sub != "track" {
                args.push("--no-progress".into());
            }
            continue;
        }
        if std::mem::replace(&mut used[k], true) {
            continue;
        }
        let (name, values) = options[k];
        let value = match input.byte() % 8 {
            0 => input.text(12),
            1 => seqsmooth_cli::io::fmt_f64(input.any_number()),
            _ => values[input.below(values.len())].to_string(),
        };
        args.push(format!("{name}={value}"));
    }
    args
}

/// A computed cell: empty or a finite number.
fn computed(cell: &str, line: usize, column: &str) {
    if !cell.is_empty() {
        let v: f64 = cell
            .parse()
            .unwrap_or_else(|_| panic!("line {line}, column {column}: {cell:?} is not a number"));
        assert!(v.is_finite(), "line {line}, column {column}: {cell}");
    }
}

/// Checks the output of a successful run.
fn output(cli: &Command, text: &[u8], data_rows: usize) {
    let mut reader = csv::ReaderBuilder::new().from_reader(text);
    let header: Vec<String> = reader
        .headers()
        .expect("the output has a header")
        .iter()
        .map(str::to_string)
        .collect();
    let (first, kind, degree, window, id) = match cli {
        Command::Filter(a) => {
            let id = a.id_col.is_some();
            (2 + usize::from(id), Some(a.kind), a.degree, a.window, id)
        }
        Command::Smooth(a) => (2, None, a.degree, Some(a.window), false),
        Command::Fit(_) | Command::Track(_) => return fitted(&header, &mut reader, data_rows),
        _ => unreachable!("only filter, smooth, fit and track are run"),
    };
    let d: Vec<usize> = (0..=degree).map(|k| first + k).collect();
    for &k in &d {
        assert_eq!(header[k], format!("d{}", k - first), "header {header:?}");
    }
    let window_col = header.iter().position(|h| h == "window");
    let mut seen: HashMap<String, usize> = HashMap::new();
    let mut rows = 0;
    for (i, record) in reader.records().enumerate() {
        let record = record.expect("the output is CSV");
        let line = i + 2;
        rows += 1;
        for (c, cell) in record.iter().enumerate().skip(first) {
            computed(cell, line, &header[c]);
        }
        let series = if id {
            record[0].to_string()
        } else {
            String::new()
        };
        let count = seen.entry(series).or_insert(0);
        *count += 1;
        let determined = match kind {
            None => true,
            Some(Kind::Expanding | Kind::Fading) => *count > degree,
            Some(Kind::Fixed) => {
                let w = window.map(|w| w.max(degree + 1)).unwrap_or(usize::MAX);
                window_col.is_some_and(|c| record[c] == w.to_string())
            }
            Some(Kind::Auto) => false,
        };
        if determined {
            for &k in &d {
                assert!(
                    !record[k].is_empty(),
                    "line {line}: {} empty: {record:?}",
                    header[k]
                );
            }
        }
    }
    assert_eq!(rows, data_rows, "one output row per input row");
}

/// Checks the output of a successful `fit` or `track`: after the echoed cells (`t`, and `y`
/// for the polynomial model), every cell empty or a finite number (the `flag` column empty,
/// `outlier` or `misfit`), the state cells (up to
/// `iterations` or `nis`) all empty or all numbers, at least one row with a state, one row per
/// data row.
fn fitted(header: &[String], reader: &mut csv::Reader<&[u8]>, data_rows: usize) {
    let first = if header.get(1).is_some_and(|h| h == "y") {
        2
    } else {
        1
    };
    let states = header
        .iter()
        .position(|h| h == "iterations" || h == "nis")
        .expect("an iterations or nis column");
    let (mut rows, mut estimated) = (0, 0);
    for (i, record) in reader.records().enumerate() {
        let record = record.expect("the output is CSV");
        let line = i + 2;
        rows += 1;
        for (c, cell) in record.iter().enumerate().skip(first) {
            if header[c] == "flag" {
                assert!(
                    ["", "outlier", "misfit"].contains(&cell),
                    "line {line}: flag {cell:?}"
                );
            } else {
                computed(cell, line, &header[c]);
            }
        }
        let empty = (first..states).filter(|&c| record[c].is_empty()).count();
        assert!(
            empty == 0 || empty == states - first,
            "line {line}: some state cells empty: {record:?}"
        );
        estimated += usize::from(empty == 0);
    }
    assert!(estimated > 0, "a successful fit has an estimate");
    assert_eq!(rows, data_rows, "one output row per input row");
}

pub fn run(data: &[u8]) {
    let mut input = Input::new(data);
    let dir = tempfile::tempdir().expect("a temporary directory");
    let (csv, out) = (dir.path().join("in.csv"), dir.path().join("out.csv"));
    let args = arguments(&mut input, &csv, &out);
    let text = input.rest();
    if check::trace() {
        eprintln!("args {args:?}\ninput {:?}", String::from_utf8_lossy(text));
    }
    std::fs::write(&csv, text).expect("the input file");
    let cli = match Cli::try_parse_from(&args) {
        Ok(cli) => cli,
        Err(e) => return check::error_message(&e),
    };
    let result = match &cli.command {
        Command::Filter(a) => filter::run(a),
        Command::Smooth(a) => smooth::run(a),
        Command::Fit(a) => fit::run(a),
        Command::Track(a) => track::run(a),
        _ => unreachable!("only filter, smooth, fit and track are run"),
    };
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .expect("the temporary directory")
        .map(|e| e.expect("an entry").file_name())
        .filter(|n| n != "in.csv")
        .collect();
    match result {
        Err(e) => {
            check::error_message(&e);
            assert!(matches!(e, CliError::Usage(_) | CliError::Data(_)), "{e:?}");
            assert!(left.is_empty(), "{e} left {left:?} behind");
        }
        Ok(()) => {
            assert_eq!(left, ["out.csv"], "files after a run");
            let written = std::fs::read(&out).expect("the output file");
            // The data rows the run read: every record after the header.
            let rows = csv::ReaderBuilder::new()
                .from_reader(text)
                .byte_records()
                .count();
            output(&cli.command, &written, rows);
        }
    }
}
