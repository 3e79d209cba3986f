//! `seqsmooth gains` and `seqsmooth vrf`: Morrison's scaled gain vectors and
//! variance-reduction matrices (expanding, fading and fixed memory), in `f64` or exact
//! rationals.

use crate::error::CliError;
use crate::number::{fmt_f64, fmt_rational, LeadSteps, Theta};
use seqsmooth::polynomial::fixed::covariance;
use seqsmooth::polynomial::gains::{expanding_gains, fading_gains, GainForm};
use seqsmooth::polynomial::vrf::{expanding_vrf, fading_vrf, EstimateForm};
use seqsmooth::scalar::{ratio_to_f64, Rational};
use std::io::{self, BufWriter, Write};

/// Output format of the tables.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Format {
    /// Comma-separated values with a header row.
    #[default]
    Csv,
    /// Aligned text for reading.
    Table,
}

/// The filter kinds of `seqsmooth gains` (and the recursive ones of `seqsmooth vrf`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TableKind {
    /// Expanding memory (--n N).
    Expanding,
    /// Fading memory (--theta T).
    Fading,
}

/// The filter kinds with a variance-reduction matrix.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum VrfKind {
    /// Expanding memory (--n N, --form).
    Expanding,
    /// Fading memory (--theta T, --form).
    Fading,
    /// Fixed memory over W samples (--window W, --lead H).
    Fixed,
}

/// Which estimate a variance-reduction matrix describes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum FormArg {
    /// The current estimate Z*_{n,n}.
    #[default]
    Current,
    /// The 1-step prediction Z*_{n+1,n}.
    Predictor,
}

impl From<FormArg> for EstimateForm {
    fn from(f: FormArg) -> Self {
        match f {
            FormArg::Current => EstimateForm::Current,
            FormArg::Predictor => EstimateForm::Predictor,
        }
    }
}

/// The filter memory a table is for, after argument checking.
#[derive(Clone, Debug)]
pub enum Memory {
    /// Expanding memory at the 0-based index `n` of the newest sample.
    Expanding {
        /// Sample index.
        n: u64,
    },
    /// Fading memory with discount θ.
    Fading {
        /// θ (exact and `f64`).
        theta: Theta,
    },
}

/// Cells of a table: exact rationals or round-trip `f64` text.
fn cells_f64(v: impl IntoIterator<Item = f64>) -> Vec<String> {
    v.into_iter().map(fmt_f64).collect()
}

fn cells_exact<'a>(v: impl IntoIterator<Item = &'a Rational>) -> Vec<String> {
    v.into_iter().map(fmt_rational).collect()
}

fn theta_f64(theta: &Theta) -> Result<f64, CliError> {
    theta.value_f64().map_err(CliError::Usage)
}

/// Runs `seqsmooth gains`: header `k,gain`, one row per derivative order `k = 0..m`.
pub fn gains(degree: usize, memory: &Memory, exact: bool, format: Format) -> Result<(), CliError> {
    let values = match (memory, exact) {
        (Memory::Expanding { n }, true) => {
            cells_exact(&expanding_gains::<Rational>(degree, *n, GainForm::Current))
        }
        (Memory::Expanding { n }, false) => {
            cells_f64(expanding_gains::<f64>(degree, *n, GainForm::Current))
        }
        (Memory::Fading { theta }, true) => cells_exact(&fading_gains::<Rational>(
            degree,
            theta.exact.clone(),
            GainForm::Current,
        )),
        (Memory::Fading { theta }, false) => cells_f64(fading_gains::<f64>(
            degree,
            theta_f64(theta)?,
            GainForm::Current,
        )),
    };
    let rows: Vec<Vec<String>> = values
        .into_iter()
        .enumerate()
        .map(|(k, g)| vec![k.to_string(), g])
        .collect();
    match format {
        Format::Csv => write_csv(&["k", "gain"], &rows),
        Format::Table => {
            let mut all = vec![vec!["k".to_string(), "gain".to_string()]];
            all.extend(rows);
            write_aligned(&all)
        }
    }
}

/// Runs `seqsmooth vrf`: header `i,j,value`, the `(m+1)×(m+1)` matrix row-major.
pub fn vrf(
    degree: usize,
    memory: &Memory,
    form: FormArg,
    exact: bool,
    format: Format,
) -> Result<(), CliError> {
    let form = EstimateForm::from(form);
    let size = degree + 1;
    let lib = |e: seqsmooth::Error| CliError::Usage(e.to_string());
    let values: Vec<String> = match (memory, exact) {
        (Memory::Expanding { n }, true) => {
            let s = expanding_vrf::<Rational>(degree, *n, form).map_err(lib)?;
            cells_exact(s.transpose().iter())
        }
        (Memory::Expanding { n }, false) => {
            // Exact, then rounded to nearest: the library's `expanding_vrf::<f64>` overflows in
            // its intermediates for large n at high degree (NaN, or silently wrong: m = 20,
            // n = 10^15 gives 4.0e-13 for the (0,0) entry instead of 4.41e-13). The exact
            // evaluation takes under half a second even at m = 24, n = 10^6.
            let s = expanding_vrf::<Rational>(degree, *n, form).map_err(lib)?;
            cells_f64(s.transpose().iter().map(ratio_to_f64))
        }
        (Memory::Fading { theta }, true) => {
            let s = fading_vrf::<Rational>(degree, theta.exact.clone(), form).map_err(lib)?;
            cells_exact(s.transpose().iter())
        }
        (Memory::Fading { theta }, false) => {
            let s = fading_vrf::<f64>(degree, theta_f64(theta)?, form).map_err(lib)?;
            cells_f64(s.transpose().iter().copied())
        }
    };
    // nalgebra iterates column-major; the transpose makes `values` row-major.
    write_matrix(values, size, format)
}

/// Runs `seqsmooth vrf --kind fixed`: the scaled covariance per unit input variance
/// `W(h) W(h)ᵀ` of the fixed-memory estimate over `window = L+1` samples at the lead `h` in
/// samples after the newest (Morrison (7.5.22)-(7.5.26)); `τ = 1`, so this is also the VRF of
/// the unscaled derivatives in sample units. Without `exact` the lead is rounded to the nearest
/// double and the matrix is computed in `f64` (within ~1e-14 relative of the exact one at every
/// degree: the library evaluates it through the discrete Legendre recursion).
pub fn fixed_vrf(
    degree: usize,
    window: usize,
    lead: &LeadSteps,
    exact: bool,
    format: Format,
) -> Result<(), CliError> {
    let span = window as u64 - 1;
    let lib = |e: seqsmooth::Error| CliError::Usage(e.to_string());
    let values = if exact {
        let s = covariance::<Rational>(degree, span, lead.exact.clone()).map_err(lib)?;
        cells_exact(s.transpose().iter())
    } else {
        let s = covariance::<f64>(degree, span, lead.value).map_err(lib)?;
        cells_f64(s.transpose().iter().copied())
    };
    write_matrix(values, degree + 1, format)
}

/// Writes the row-major `size × size` matrix `values` as `i,j,value` CSV or an aligned table.
fn write_matrix(values: Vec<String>, size: usize, format: Format) -> Result<(), CliError> {
    match format {
        Format::Csv => {
            let rows: Vec<Vec<String>> = values
                .into_iter()
                .enumerate()
                .map(|(idx, v)| vec![(idx / size).to_string(), (idx % size).to_string(), v])
                .collect();
            write_csv(&["i", "j", "value"], &rows)
        }
        Format::Table => {
            let mut all = Vec::with_capacity(size + 1);
            let mut header = vec![String::new()];
            header.extend((0..size).map(|j| format!("j={j}")));
            all.push(header);
            for (i, chunk) in values.chunks(size).enumerate() {
                let mut row = vec![format!("i={i}")];
                row.extend(chunk.iter().cloned());
                all.push(row);
            }
            write_aligned(&all)
        }
    }
}

fn write_csv(header: &[&str], rows: &[Vec<String>]) -> Result<(), CliError> {
    let name = "standard output";
    let mut w = csv::Writer::from_writer(BufWriter::new(io::stdout().lock()));
    w.write_record(header)
        .map_err(|e| CliError::write_csv(name, e))?;
    for r in rows {
        w.write_record(r)
            .map_err(|e| CliError::write_csv(name, e))?;
    }
    w.flush().map_err(|e| CliError::write(name, e))
}

/// Writes rows of cells right-aligned in columns two spaces apart.
fn write_aligned(rows: &[Vec<String>]) -> Result<(), CliError> {
    let name = "standard output";
    let cols = rows.iter().map(Vec::len).max().unwrap_or(0);
    let widths: Vec<usize> = (0..cols)
        .map(|c| {
            rows.iter()
                .filter_map(|r| r.get(c))
                .map(|s| s.chars().count())
                .max()
                .unwrap_or(0)
        })
        .collect();
    let mut w = BufWriter::new(io::stdout().lock());
    for r in rows {
        let line: Vec<String> = r
            .iter()
            .zip(&widths)
            .map(|(s, &width)| format!("{s:>width$}"))
            .collect();
        writeln!(w, "{}", line.join("  ").trim_end()).map_err(|e| CliError::write(name, e))?;
    }
    w.flush().map_err(|e| CliError::write(name, e))
}
