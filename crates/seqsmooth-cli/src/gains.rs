//! `seqsmooth gains`: Morrison's scaled current-estimate gains `h_0..h_m` of the expanding-
//! and fading-memory filters (Reyneke et al. §6.4, §6.6), in `f64` or exact rationals.

use crate::args::{Format, GainsArgs, Memory};
use crate::error::CliError;
use crate::io::{fmt_f64, Output};
use seqsmooth::polynomial::expanding::gains::expanding_gains;
use seqsmooth::polynomial::fading::gains::fading_gains;
use seqsmooth::polynomial::form::GainForm;
use seqsmooth::scalar::Rational;

/// Runs `seqsmooth gains`: header `k,gain`, one row per derivative order `k = 0..m`.
pub fn run(a: &GainsArgs) -> Result<(), CliError> {
    let (m, form) = (a.memory.degree, GainForm::Current);
    let values: Vec<String> = match (a.memory.of(a.kind)?, a.exact) {
        (Memory::Expanding(n), true) => cells(&expanding_gains::<Rational>(m, n, form)),
        (Memory::Expanding(n), false) => cells(&expanding_gains::<f64>(m, n, form)),
        (Memory::Fading(theta), true) => cells(&fading_gains::<Rational>(m, theta.exact, form)),
        (Memory::Fading(theta), false) => cells(&fading_gains(m, theta.value_f64()?, form)),
    };
    let mut rows = vec![vec!["k".to_string(), "gain".to_string()]];
    let row = |(k, g): (usize, String)| vec![k.to_string(), g];
    rows.extend(values.into_iter().enumerate().map(row));
    write_table(&rows, a.format)
}

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
