//! `seqsmooth vrf`: the scaled variance-reduction matrices of the expanding-, fading- and
//! fixed-memory filters (fading memory: Morrison (13.7.1); fixed memory: Morrison
//! (7.5.22)-(7.5.26)), in `f64` or exact rationals.

use crate::args::{check_window, only, Format, Memory, TableKind, VrfArgs, VrfKind};
use crate::commands::shared::table::{cells, write_table};
use crate::error::CliError;
use seqsmooth::polynomial::expanding::vrf::{check_index, expanding_vrf};
use seqsmooth::polynomial::fading::vrf::fading_vrf;
use seqsmooth::polynomial::fixed::covariance;
use seqsmooth::polynomial::form::EstimateForm;
use seqsmooth::scalar::{ratio_to_f64, Rational};

/// The cells of the library's matrix result, row-major (nalgebra iterates column-major).
macro_rules! row_major {
    ($matrix:expr) => {
        cells($matrix.map_err(CliError::from)?.transpose().iter())
    };
}

/// Runs `seqsmooth vrf`: header `i,j,value`, the `(m+1)×(m+1)` matrix row-major.
pub fn run(a: &VrfArgs) -> Result<(), CliError> {
    let kind = match a.kind {
        VrfKind::Fixed => return fixed(a),
        VrfKind::Expanding => TableKind::Expanding,
        VrfKind::Fading => TableKind::Fading,
    };
    if a.window.is_some() {
        return Err(only("--window", "fixed"));
    }
    if a.lead.is_some() {
        return Err(CliError::Usage(
            "--lead applies only to --kind fixed; expanding and fading take --form".into(),
        ));
    }
    let m = a.memory.degree;
    let mem = a.memory.of(kind)?;
    if let Memory::Expanding(n) = mem {
        // The library's range of n for the degree, checked before any output.
        check_index(m, n)?;
    }
    let form = EstimateForm::from(a.form.unwrap_or_default());
    let values = match (mem, a.exact) {
        (Memory::Expanding(n), true) => row_major!(expanding_vrf::<Rational>(m, n, form)),
        // Exact, then rounded to nearest: the library's `expanding_vrf::<f64>` overflows in its
        // intermediates for large n at high degree (NaN, or silently wrong: m = 20, n = 10^15
        // gives 4.0e-13 for the (0,0) entry instead of 4.41e-13).
        (Memory::Expanding(n), false) => {
            let s = expanding_vrf::<Rational>(m, n, form);
            row_major!(s.map(|s| s.map(|v| ratio_to_f64(&v))))
        }
        (Memory::Fading(theta), true) => row_major!(fading_vrf::<Rational>(m, theta.exact, form)),
        (Memory::Fading(theta), false) => row_major!(fading_vrf(m, theta.value_f64()?, form)),
    };
    write_matrix(values, m + 1, a.format)
}

/// `seqsmooth vrf --kind fixed`: the scaled covariance per unit input variance `W(h) W(h)ᵀ` of
/// the fixed-memory estimate over `window = L+1` samples at the lead `h` in samples after the
/// newest (Morrison (7.5.22)-(7.5.26)); `τ = 1`, so this is also the VRF of the unscaled
/// derivatives in sample units. Without `--exact` the lead is rounded to the nearest double
/// and the matrix is computed in `f64` (the library evaluates it through the discrete Legendre
/// recursion).
fn fixed(a: &VrfArgs) -> Result<(), CliError> {
    if a.memory.n.is_some() {
        return Err(only("--n", "expanding"));
    }
    if a.memory.theta.is_some() {
        return Err(only("--theta", "fading"));
    }
    if a.form.is_some() {
        return Err(CliError::Usage(
            "--form applies only to --kind expanding and fading; for --kind fixed give --lead H \
             in samples (0 the current estimate, 1 the 1-step prediction, -(W-1)/2 the centre \
             of the window)"
                .into(),
        ));
    }
    let m = a.memory.degree;
    let span = check_window(a.window, m)? as u64 - 1;
    let lead = a.lead.clone().unwrap_or_default();
    let values = if a.exact {
        row_major!(covariance::<Rational>(m, span, lead.exact))
    } else {
        row_major!(covariance::<f64>(m, span, lead.value))
    };
    write_matrix(values, m + 1, a.format)
}

/// Writes the row-major `size × size` matrix `values` as `i,j,value` CSV or an aligned table.
fn write_matrix(values: Vec<String>, size: usize, format: Format) -> Result<(), CliError> {
    let rows: Vec<Vec<String>> = match format {
        Format::Csv => {
            let mut rows = vec![vec!["i".into(), "j".into(), "value".into()]];
            let cell =
                |(k, v): (usize, String)| vec![(k / size).to_string(), (k % size).to_string(), v];
            rows.extend(values.into_iter().enumerate().map(cell));
            rows
        }
        Format::Table => {
            let mut header = vec![String::new()];
            header.extend((0..size).map(|j| format!("j={j}")));
            let mut rows = vec![header];
            for (i, chunk) in values.chunks(size).enumerate() {
                rows.push([vec![format!("i={i}")], chunk.to_vec()].concat());
            }
            rows
        }
    };
    write_table(&rows, format)
}
