//! The tables of `seqsmooth gains` and `seqsmooth vrf`: numbers as cells (exact rationals or
//! round-trip `f64`) and the rows written as CSV or an aligned table.

use crate::args::Format;
use crate::error::CliError;
use crate::io::{fmt_f64, Output};
use seqsmooth::scalar::Rational;

/// A number's cell: an exact rational `p/q` (or `p`), or an `f64` with round-trip precision.
pub trait Cell {
    fn cell(&self) -> String;
}

impl Cell for f64 {
    fn cell(&self) -> String {
        fmt_f64(*self)
    }
}

impl Cell for Rational {
    fn cell(&self) -> String {
        self.to_string()
    }
}

pub fn cells<'a, T: Cell + 'a>(values: impl IntoIterator<Item = &'a T>) -> Vec<String> {
    values.into_iter().map(Cell::cell).collect()
}

/// Writes `rows` (the first the header) to standard output as CSV or an aligned table.
pub fn write_table(rows: &[Vec<String>], format: Format) -> Result<(), CliError> {
    let mut out = Output::stdout();
    match format {
        Format::Csv => rows.iter().try_for_each(|r| out.row(r))?,
        Format::Table => out.aligned(rows, 0)?,
    }
    out.finish()
}
