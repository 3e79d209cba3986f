//! Number parsing and formatting of the CLI (`seqsmooth_cli::io`): every finite `f64` written
//! by `write_f64` reads back to the same bits (through the CLI's `parse_cell` and through
//! `str::parse`), and the text is Rust's own shortest text (`{}` for `0` and
//! `1e-5 <= |x| < 1e16`, `{:e}` otherwise); any cell text parses to a finite number equal to
//! `str::parse`'s, or is refused with its line and column.
//!
//! Input: 8 bytes of `f64` bits, then a cell's text.

use super::check;
use seqsmooth_cli::io::{fmt_f64, parse_cell, write_f64};

/// Checks the text of the finite `x`: Rust's text, and the same bits read back.
pub fn round_trip(x: f64) {
    let text = fmt_f64(x);
    let mut appended = b"1,".to_vec();
    write_f64(&mut appended, x);
    assert_eq!(
        &appended[2..],
        text.as_bytes(),
        "write_f64 and fmt_f64 differ"
    );
    if !x.is_finite() {
        return;
    }
    let a = x.abs();
    let rust = if a == 0.0 || (1e-5..1e16).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    };
    assert_eq!(text, rust, "the text of {:#x} is not Rust's", x.to_bits());
    let back = parse_cell(text.as_bytes(), 2, "y", "value")
        .unwrap_or_else(|e| panic!("{text} (bits {:#x}) does not read back: {e}", x.to_bits()));
    assert_eq!(back.to_bits(), x.to_bits(), "{text} reads back as {back:e}");
    let std: f64 = text.parse().expect("str::parse");
    assert_eq!(
        std.to_bits(),
        x.to_bits(),
        "{text} is {std:e} to str::parse"
    );
}

pub fn run(data: &[u8]) {
    let (bits, cell) = data.split_at(data.len().min(8));
    let mut b = [0u8; 8];
    b[..bits.len()].copy_from_slice(bits);
    round_trip(f64::from_le_bytes(b));
    match parse_cell(cell, 7, "y", "value") {
        Ok(v) => {
            assert!(v.is_finite(), "parse_cell gave {v}");
            // The same double as the standard library's parser.
            let std = std::str::from_utf8(cell)
                .ok()
                .and_then(|s| s.parse::<f64>().ok());
            assert_eq!(
                std.map(f64::to_bits),
                Some(v.to_bits()),
                "parse_cell({:?}) = {v:e}, str::parse gives {std:?}",
                String::from_utf8_lossy(cell)
            );
            round_trip(v);
        }
        Err(e) => {
            check::error_message(&e);
            let text = e.to_string();
            assert!(
                text.starts_with("line 7, column 'y': "),
                "a cell's error without its line and column: {text}"
            );
        }
    }
}
