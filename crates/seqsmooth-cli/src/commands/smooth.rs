//! `seqsmooth smooth`: whole-series (non-causal) smoothing and differentiation with centred
//! fixed-memory windows, the counterpart of `scipy.signal.savgol_filter(mode="interp")`, with
//! the 1σ of every value.
//!
//! It streams, through the library's [`CentredSmoother`] (the engine of `smooth_into` too): a
//! row is written once the row `⌊W/2⌋` after it has been read, so only the chunks of rows not
//! yet written are held (memory bounded by the window and the chunk size, not the input). The
//! rows are validated as the filter validates them (line, column and value in messages).

use crate::args::{check_window, SmoothArgs};
use crate::error::CliError;
use crate::io::rows::{Chunk, RowReader};
use crate::io::{check_distinct, open_input, Need, Output};
use seqsmooth::polynomial::fixed::{CentredSmoother, SmoothSigma, SmoothedRow};
use seqsmooth::Error;
use std::collections::VecDeque;

/// Rows read at a time.
const CHUNK_ROWS: usize = 8192;

/// Bytes of output text collected before they are written.
const FLUSH_BYTES: usize = 1 << 20;

/// Why a run stopped: the library's error (to be placed on a line) or the command's own.
enum Stop {
    Library(Error),
    Command(CliError),
}

impl From<Error> for Stop {
    fn from(e: Error) -> Self {
        Stop::Library(e)
    }
}

/// The chunks of rows read and not yet all written, each with the index of its first row.
#[derive(Default)]
struct Pending {
    chunks: VecDeque<(usize, Chunk)>,
}

impl Pending {
    /// The chunk holding row `index` and the row's place in it.
    fn locate(&self, index: usize) -> (&Chunk, usize) {
        let (base, chunk) = self
            .chunks
            .iter()
            .find(|(base, c)| index < base + c.len())
            .expect("a row is written after it is read and before its chunk is dropped");
        (chunk, index - base)
    }
}

/// Appends the output row of `row` (its cells echoed from its chunk), or the error of a value
/// beyond the double range, on the row's line.
fn write_row(pending: &Pending, row: SmoothedRow<'_>, text: &mut Vec<u8>) -> Result<(), Stop> {
    let (chunk, i) = pending.locate(row.index);
    let sigmas = row.std_devs.unwrap_or(&[]);
    if let Some(k) = row
        .derivatives
        .iter()
        .chain(sigmas)
        .position(|v| !v.is_finite())
    {
        let p = row.derivatives.len();
        let what = if k < p {
            format!("d{k}")
        } else {
            format!("s{}", k - p)
        };
        return Err(Stop::Command(CliError::Data(format!(
            "line {}: the smoothed {what} is too large for a double (beyond 1.8e308); express \
             the times in a larger unit or rescale the values",
            chunk.lines[i]
        ))));
    }
    chunk.row_with(text, i, None, row.derivatives, sigmas);
    Ok(())
}

/// Runs `seqsmooth smooth`: header `t,y,d0..dM,s0..sM`, one row per input row in input order.
pub fn run(a: &SmoothArgs) -> Result<(), CliError> {
    check_window(Some(a.window), a.degree)?;
    check_distinct(a.input.as_deref(), a.output.as_deref())?;
    let sigma = a.sigma.map_or(SmoothSigma::Estimated, SmoothSigma::Given);
    let mut smoother = CentredSmoother::new(a.degree, a.window, sigma).map_err(|e| match e {
        Error::InvalidParameter { reason, .. } if a.sigma.is_none() => CliError::Usage(format!(
            "{reason} (--sigma S; without it sigma is estimated from the residuals)"
        )),
        e => CliError::Usage(e.to_string()),
    })?;
    let need = Need::window(a.window.max(a.degree + 1));
    let input = open_input(a.input.as_deref())?;
    let mut reader = RowReader::new(
        input,
        &a.columns.time_col,
        &a.columns.value_col,
        None,
        &need,
    )?;
    let mut out = Output::create(a.output.as_deref())?;
    let mut text = Vec::new();
    Chunk::default().header(&mut text, None, a.degree, true, &[]);
    let mut pending = Pending::default();
    let (mut read, mut written) = (0usize, 0usize);
    let mut spare = Chunk::default();
    loop {
        let mut chunk = std::mem::take(&mut spare);
        reader.read_chunk(&mut chunk, CHUNK_ROWS);
        let error = chunk.error.take();
        let done = chunk.done;
        let base = read;
        read += chunk.len();
        let rows = chunk.len();
        pending.chunks.push_back((base, chunk));
        for k in 0..rows {
            let (t, y) = {
                let newest = &pending.chunks.back().expect("just pushed").1;
                (newest.t[k], newest.y[k])
            };
            let pushed = smoother.push(t, y, |row| {
                written += 1;
                write_row(&pending, row, &mut text)
            });
            match pushed {
                Ok(()) => {}
                Err(Stop::Command(e)) => return Err(e),
                Err(Stop::Library(e)) => {
                    return Err(CliError::Data(format!(
                        "line {}: cannot smooth the window ending here: {e}",
                        pending.locate(base + k).0.lines[k]
                    )))
                }
            }
        }
        while let Some((b, c)) = pending.chunks.front() {
            if b + c.len() > written {
                break;
            }
            spare = pending.chunks.pop_front().expect("checked").1;
        }
        if text.len() >= FLUSH_BYTES {
            out.write(&text)?;
            text.clear();
        }
        if let Some(e) = error {
            return Err(e);
        }
        if done {
            break;
        }
    }
    need.check(read)?;
    let finished = smoother.finish(|row| write_row(&pending, row, &mut text));
    match finished {
        Ok(()) => {}
        Err(Stop::Command(e)) => return Err(e),
        Err(Stop::Library(e)) => {
            return Err(CliError::Data(format!("cannot smooth the input: {e}")))
        }
    }
    out.write(&text)?;
    out.finish()
}
