//! The numbers the Python package's `FadingBank` and `ExpandingBank` must give to the last bit:
//! this library's run of the banks over fixed inputs (five channels, 60 time steps, taken in
//! chunks of 1, 2, 7 and 50 rows), every channel's unscaled estimate after each chunk, stored
//! in `crates/seqsmooth-py/tests/fixtures/bank_rust.txt` with the inputs (shortest round-trip
//! form). This test fails when the library's numbers change; rewrite the file with
//! `SEQSMOOTH_WRITE_FIXTURES=1 cargo test --test bank_python_fixture`.
//! `crates/seqsmooth-py/tests/test_bank.py` reads it.

use seqsmooth::polynomial::bank::{ExpandingBank, FadingBank};
mod common;

use common::python_fixture::{check, line};
use std::fmt::Write;

const CHANNELS: usize = 5;
const STEPS: usize = 60;
const CHUNKS: [usize; 4] = [1, 2, 7, 50];
const TAU: f64 = 0.25;

/// Row-major `STEPS × CHANNELS` values from integers: a line per channel with a bounded wiggle.
fn inputs() -> Vec<f64> {
    let mut y = Vec::with_capacity(STEPS * CHANNELS);
    for k in 0..STEPS as u32 {
        for c in 0..CHANNELS as u32 {
            let wiggle = f64::from((k * 37 + c * 11) % 13) - 6.0;
            let line = f64::from(c) * 3.0 - 4.0 + f64::from(k) * (f64::from(c) - 2.0) / 4.0;
            y.push(line + wiggle / 8.0);
        }
    }
    y
}

/// One bank's run: after each chunk, `tag,<steps so far>` and each channel's `m+1` unscaled
/// derivatives (channel by channel), or `tag,<steps>,-` while the bank is not determined.
fn run(
    out: &mut String,
    tag: &str,
    degree: usize,
    mut rows: impl FnMut(&[f64]) -> Vec<Option<Vec<f64>>>,
) {
    let y = inputs();
    let mut done = 0;
    for chunk in CHUNKS {
        let estimates = rows(&y[done * CHANNELS..(done + chunk) * CHANNELS]);
        done += chunk;
        if estimates.iter().any(Option::is_none) {
            writeln!(out, "{tag},{degree},{done},-").unwrap();
        } else {
            let values = estimates.into_iter().flatten().flatten();
            line(out, &format!("{tag},{degree},{done}"), values);
        }
    }
}

/// Every channel's estimate, as the binding reads it: derivative by derivative over all
/// channels (`derivative_into`), then channel by channel.
macro_rules! estimates {
    ($bank:expr, $degree:expr) => {{
        let bank = &$bank;
        if bank.samples() <= $degree as u64 {
            vec![None; CHANNELS]
        } else {
            let mut columns = vec![vec![0.0; CHANNELS]; $degree + 1];
            for (d, column) in columns.iter_mut().enumerate() {
                bank.derivative_into(d, column).unwrap();
            }
            (0..CHANNELS)
                .map(|c| Some(columns.iter().map(|col| col[c]).collect()))
                .collect()
        }
    }};
}

fn fixture() -> String {
    let mut out = String::new();
    line(&mut out, "input", inputs());
    for degree in [0, 1, 2, 3, 5] {
        let mut bank = FadingBank::new(degree, 0.875, TAU, CHANNELS).unwrap();
        run(&mut out, "fading", degree, |rows| {
            bank.update_rows(rows).unwrap();
            estimates!(bank, degree)
        });
    }
    for degree in [0, 1, 2, 4, 8] {
        let mut bank = ExpandingBank::new(degree, TAU, CHANNELS).unwrap();
        run(&mut out, "expanding", degree, |rows| {
            bank.update_rows(rows).unwrap();
            estimates!(bank, degree)
        });
    }
    out
}

#[test]
fn the_python_fixture_is_this_librarys_run() {
    let text = fixture();
    check("bank_rust.txt", &text);
    // a bank of degree m has no estimate before m+1 steps (chunks end at 1, 3, 10, 60 steps)
    let undetermined = |m: usize| {
        CHUNKS
            .iter()
            .scan(0, |s, c| {
                *s += c;
                Some(*s)
            })
            .filter(|&s| s <= m)
            .count()
    };
    let want: usize = [0, 1, 2, 3, 5, 0, 1, 2, 4, 8]
        .into_iter()
        .map(undetermined)
        .sum();
    assert_eq!(want, 12);
    assert_eq!(text.lines().filter(|l| l.ends_with(",-")).count(), want);
}
