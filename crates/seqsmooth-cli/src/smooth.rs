//! `seqsmooth smooth`: whole-series (non-causal) smoothing and differentiation with centred
//! fixed-memory windows, the counterpart of `scipy.signal.savgol_filter(mode="interp")`.
//!
//! Unlike `seqsmooth filter` this reads the whole input before writing anything: a row's
//! window reaches `⌊W/2⌋` rows ahead of it (and the last rows share the last full window).
//! The rows are validated as the filter validates them (line, column and value in messages).

use crate::args::{check_window, SmoothArgs};
use crate::error::CliError;
use crate::filter::rows::{Chunk, RowReader};
use crate::io::{check_distinct, open_input, Need, Output};
use seqsmooth::polynomial::fixed::smooth_into;
use seqsmooth::Error;

/// Runs `seqsmooth smooth`: header `t,y,d0..dM`, one row per input row in input order.
pub fn run(a: &SmoothArgs) -> Result<(), CliError> {
    check_window(Some(a.window), a.degree)?;
    check_distinct(a.input.as_deref(), a.output.as_deref())?;
    let need = Need::window(a.window.max(a.degree + 1));
    let input = open_input(a.input.as_deref())?;
    let mut reader = RowReader::new(
        input,
        &a.columns.time_col,
        &a.columns.value_col,
        None,
        &need,
    )?;
    let mut rows = Chunk::default();
    reader.read_chunk(&mut rows, usize::MAX);
    if let Some(e) = rows.error.take() {
        return Err(e);
    }
    need.check(rows.len())?;
    // The arguments and the rows are checked already (degree, window, finite and increasing
    // values, enough of them): an error left here is a derivative beyond the double range at
    // a row, or about the data as a whole.
    let mut fits = vec![0.0; rows.len() * (a.degree + 1)];
    smooth_into(&rows.t, &rows.y, a.degree, a.window, &mut fits).map_err(|e| match e {
        Error::InBatch { index, source } => match *source {
            Error::EstimateOutOfRange { what } => CliError::Data(format!(
                "line {}: the smoothed {what} is too large for a double (beyond 1.8e308); \
                 express the times in a larger unit or rescale the values",
                rows.lines[index]
            )),
            other => CliError::Data(format!(
                "line {}: cannot smooth: {other}",
                rows.lines[index]
            )),
        },
        e => CliError::Data(format!("cannot smooth the input: {e}")),
    })?;
    let mut out = Output::create(a.output.as_deref())?;
    let mut text = Vec::new();
    rows.header(&mut text, None, a.degree, false, &[]);
    for (i, d) in fits.chunks_exact(a.degree + 1).enumerate() {
        rows.row(&mut text, i, None, d);
    }
    out.write(&text)?;
    out.finish()
}
