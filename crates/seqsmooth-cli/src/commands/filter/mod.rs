//! `seqsmooth filter`: streams a CSV time series — or many, told apart by an id column —
//! through polynomial filters. A `.parquet` input or output is a Parquet file
//! ([`crate::io::parquet`]): its rows are read as records into the same chunks, and the output rows
//! written as a table, so everything in between is the CSV path's.
//!
//! The command reads, filters and writes chunks of rows ([`CHUNK_ROWS`]): a reader thread
//! reads and validates ([`crate::io::rows`]) the next chunk while the current one is run through the
//! filters of its series, the series in parallel (the library's
//! [`seqsmooth::polynomial::bank::StreamBank`]), then formatted in parallel pieces
//! and written in input order. Memory is a few chunks plus one filter per series, whatever the
//! length of the input. The first [`LOOKAHEAD`] data rows (the first `W` for a fixed-memory
//! window longer than that) decide the default `τ` (median time step) and the too-few-samples
//! check before any output is written. The automatic filter's rows wait until their outlier
//! decision is final, a few samples of their series later (`held`).

mod held;
mod state;

use crate::args::{check_window, name, only, EngineArg, FilterArgs, Kind, CHUNK_ROWS};
use crate::commands::shared::{filter_kind, LOOKAHEAD};
use crate::error::CliError;
use crate::io::parquet::{is_parquet, ParquetRows, ParquetTable};
use crate::io::progress::{self, Progress};
use crate::io::rows::{Chunk, RowReader};
use crate::io::{check_distinct, input_size, named, open_input, CsvIn, Need, Output};
use crate::io::{IdType, Records};
use rayon::prelude::*;
use seqsmooth::persist::stream::{StreamOptions, StreamState};
use seqsmooth::polynomial::rows::{decisions, RowLayout};
use seqsmooth::polynomial::spec::{AnyFilter, FilterSpec};
use seqsmooth::polynomial::stream::{self, StreamBank};
use seqsmooth::polynomial::tau;
use std::sync::mpsc;

/// Rows of the first chunk, unless the first rows held back or scanned need more: the chunks
/// then double in size up to `--chunk-rows`, so that filtering starts early.
const FIRST_CHUNK_ROWS: usize = 1 << 12;

/// Rows formatted per piece (on one thread).
const PIECE: usize = 4096;

/// Checks the arguments that go together; returns θ (fading memory and auto) in `f64`.
fn check_args(a: &FilterArgs) -> Result<Option<f64>, CliError> {
    let kind = a.kind;
    let theta = match (kind, &a.theta) {
        (Kind::Fading | Kind::Auto, Some(theta)) => Some(theta.value_f64()?),
        (Kind::Fading | Kind::Auto, None) => {
            return Err(CliError::Usage(format!(
                "--kind {} needs --theta T, the discount per tau (0 < T < 1)",
                name(kind)
            )))
        }
        (Kind::Expanding | Kind::Fixed, Some(_)) => return Err(only("--theta", "fading and auto")),
        (Kind::Expanding | Kind::Fixed, None) => None,
    };
    if matches!(kind, Kind::Expanding | Kind::Fixed) && a.tau.is_some() {
        return Err(only("--tau", "fading and auto"));
    }
    if kind != Kind::Auto && a.review_window.is_some() {
        return Err(only("--review-window", "auto"));
    }
    match (kind, a.window) {
        (Kind::Fixed, w) => _ = check_window(w, a.degree)?,
        (_, Some(_)) => return Err(only("--window", "fixed")),
        (_, None) => {}
    }
    if let Some(id) = &a.id_col {
        if *id == a.columns.time_col || *id == a.columns.value_col {
            return Err(CliError::Usage(format!(
                "--id-col {id} is the time or the value column; name a column of its own"
            )));
        }
    }
    if kind == Kind::Fixed && a.engine == Some(EngineArg::Gain) {
        return Err(CliError::Usage(
            "--engine gain applies only to --kind expanding, fading and auto: the fixed-memory \
             filter is always the exact least-squares fit of its window"
                .into(),
        ));
    }
    Ok(theta)
}

/// The default `τ`: the library's rule ([`seqsmooth::polynomial::tau::default_tau`]) over the
/// first `head` rows of `chunk`, which are all of the input when the chunk is the last and
/// holds no more; its refusals name `--tau`.
fn default_tau(chunk: &Chunk, head: usize) -> Result<f64, CliError> {
    let complete = chunk.done && chunk.len() <= head;
    tau::default_tau(&chunk.t[..head], &chunk.series[..head], complete).map_err(CliError::from)
}

/// Runs `seqsmooth filter`.
///
/// An error in one of the first `hold` rows stops the command before any output; a later one
/// after the rows before it, of every series, have been written.
pub fn run(a: &FilterArgs) -> Result<(), CliError> {
    let theta = check_args(a)?;
    check_distinct(a.input.as_deref(), a.output.as_deref())?;
    let need = match (a.kind, a.window) {
        (Kind::Fixed, Some(w)) => Need::window(w.max(a.degree + 1)),
        _ => Need::degree(a.degree),
    };
    let started = std::time::Instant::now();
    let size = input_size(a.input.as_deref());
    // A `.parquet` input is read as Parquet, anything else as CSV, through the same checks.
    let records: Box<dyn Records + Send> = match named(a.input.as_deref()) {
        Some(path) if is_parquet(Some(path)) => Box::new(ParquetRows::open(path)?),
        _ => Box::new(CsvIn::new(open_input(a.input.as_deref())?)?),
    };
    let mut reader = RowReader::from_records(
        records,
        &a.columns.time_col,
        &a.columns.value_col,
        a.id_col.as_deref(),
        &need,
    )?;
    let id_type = a.id_col.as_ref().map(|_| reader.id_type());
    // A saved state (--state): its series keep their indices, its filters their samples.
    let saved = a.state.as_deref().map(state::read).transpose()?.flatten();
    let mut raw_ids = saved.as_ref().map_or_else(Vec::new, |s| s.ids.clone());
    let mut ids = reader.resume_ids(&raw_ids);
    // A fixed-memory window longer than LOOKAHEAD is read in full before the first output row:
    // its rows have no estimate, and an input shorter than the window is an error.
    let hold = LOOKAHEAD.max(need.rows);
    let chunk_rows = a.chunk_rows as usize;
    // With --id-col, the default τ comes from the steps within series among the first
    // TAU_SCAN_ROWS rows: they are all in the first chunk, whatever the chunk size.
    let tau_needed = a.tau.is_none() && matches!(a.kind, Kind::Fading | Kind::Auto);
    let scan = if tau_needed && a.id_col.is_some() {
        tau::TAU_SCAN_ROWS
    } else {
        0
    };
    let first_rows = chunk_rows.min(FIRST_CHUNK_ROWS).max(hold).max(scan);
    let mut chunk = Chunk::default();
    reader.read_chunk(&mut chunk, first_rows);
    let early = chunk.len() < hold;
    if let Some(e) = chunk.error.take_if(|_| early) {
        return Err(e);
    }
    if saved.is_none() {
        need.check(chunk.len())?;
    }
    // A resumed stream keeps the τ its first run decided.
    let tau = match a.tau.or(saved.as_ref().and_then(|s| s.options.tau)) {
        Some(tau) => tau,
        None if tau_needed => default_tau(&chunk, chunk.len().min(hold.max(scan)))?,
        None => 1.0,
    };
    let spec = FilterSpec {
        theta,
        tau: Some(tau),
        window: a.window,
        engine: a.engine.unwrap_or(EngineArg::Exact).into(),
        sigma: a.sigma,
        review_window: a.review_window,
        ..FilterSpec::new(filter_kind(a.kind), a.degree)
    };
    let prototype = spec.build().map_err(CliError::from)?;
    let options = StreamOptions::of(&spec, a.lead, a.id_col.is_some());
    if let (Some(s), Some(path)) = (&saved, &a.state) {
        let refuse = |e| CliError::from(e).reworded(|m| state::in_file(path, &m));
        s.check_options(&options).map_err(refuse)?;
    }
    // The automatic filter always writes s0..sM (from the given or the estimated noise).
    let sigma = spec.writes_sigma();
    let lead = a.lead;
    let layout = RowLayout {
        sigma,
        lead,
        trailing: true,
    };
    let extra = prototype.trailing_columns();
    // The automatic filter's rows carry cells more, not written: the final outlier decisions
    // each row's update made (see `held`).
    let auto = a.kind == Kind::Auto;
    let shown = ((a.degree + 1) << usize::from(sigma)) + extra.len();
    let stride = prototype.stride(layout);
    let (mut held, bank) = match saved {
        Some(s) => (
            held::Held::restore(s.pending),
            StreamBank::resume(prototype, s.filters),
        ),
        None => (held::Held::default(), StreamBank::growing(prototype)),
    };
    let mut bank = bank.map_err(CliError::from)?;
    // With --state and without --final the stream goes on in the next input: the automatic
    // filter's undecided rows wait in the state, as they would wait for the next rows.
    let goes_on = a.state.is_some() && !a.end;
    let (mut values, mut out) = (Vec::new(), None);
    let mut progress = Progress::hidden();
    // The rest of the input is read on a thread of its own, a chunk ahead.
    let mut pipeline = (!chunk.done && chunk.error.is_none()).then(|| {
        let sizes = (1..).map(move |k| first_rows.saturating_mul(1 << k.min(16)));
        Pipeline::start(reader, sizes.map(move |rows| rows.min(chunk_rows)))
    });
    // A lead is recorded in a trailing column, so that the output says where its estimates are.
    let lead_cell = [lead];
    let lead_cells = &lead_cell[..usize::from(lead != 0.0)];
    let mut columns = extra.to_vec();
    columns.extend(lead_cells.iter().map(|_| "lead"));
    for first in std::iter::once(true).chain(std::iter::repeat(false)) {
        ids.append(&mut chunk.new_ids);
        raw_ids.append(&mut chunk.new_raw_ids);
        values.resize(chunk.len() * stride, 0.0);
        // The library's rows, each refused row (no estimate once determined, a number beyond
        // the double range) the error of its row: right or refused.
        let run =
            |f: &mut AnyFilter, t: &[f64], y: &[f64], o: &mut [f64]| f.run_rows(t, y, o, layout);
        let rows = stream::Chunk {
            channels: &chunk.series,
            times: &chunk.t,
            values: &chunk.y,
            estimates: &mut values,
            stride,
        };
        let failed = bank.update_par(rows, run).err();
        let mut failed = failed.map(|e| row_error(e, &chunk, &need, a.kind));
        let limit = failed.as_ref().map_or(chunk.len(), |(i, _)| *i);
        if let Some((_, e)) = failed.take_if(|_| first && limit < hold) {
            return Err(e);
        }
        let sink = match &mut out {
            Some(sink) => sink,
            None => {
                let mut sink = create_output(a.output.as_deref(), id_type)?;
                let mut header = Vec::new();
                chunk.header(&mut header, a.id_col.as_deref(), a.degree, sigma, &columns);
                sink.write(&header)?;
                out.insert(sink)
            }
        };
        let id = |i: usize| a.id_col.as_ref().map(|_| ids[chunk.series[i]].as_slice());
        if auto {
            // The outlier flag is written once final: `outlier` is the third cell from the
            // end, before `misfit` and `bias` (and `lead`).
            for i in 0..limit {
                let row = &values[i * stride..(i + 1) * stride];
                let write = |buf: &mut Vec<u8>| {
                    chunk.row_with(buf, i, id(i), &row[..shown], lead_cells);
                };
                let decided = decisions(&row[shown..]);
                held.push(chunk.series[i], write, 2 + lead_cells.len(), &decided);
            }
            if failed.is_none() && chunk.error.is_none() && chunk.done && !goes_on {
                // The input is complete: every series decides its samples still waiting.
                for series in 0..bank.channels() {
                    if let Some(f) = bank.channel_mut(series).and_then(AnyFilter::automatic_mut) {
                        held.decide(series, &f.finish());
                    }
                }
            }
            held.flush_final(sink)?;
        } else {
            let pieces: Vec<Vec<u8>> = (0..limit.div_ceil(PIECE))
                .into_par_iter()
                .map(|k| {
                    let mut buf = Vec::with_capacity(PIECE.min(limit) * (stride + 2) * 20);
                    for i in k * PIECE..((k + 1) * PIECE).min(limit) {
                        let values = &values[i * stride..(i + 1) * stride];
                        chunk.row_with(&mut buf, i, id(i), values, lead_cells);
                    }
                    buf
                })
                .collect();
            for piece in &pieces {
                sink.write(piece)?;
            }
        }
        if failed.is_some() || chunk.error.is_some() || chunk.done {
            let ok = failed.is_none() && chunk.error.is_none();
            if !(ok && goes_on) {
                // Stopped early: the rows still undecided keep the gate's verdict.
                held.flush_all(sink)?;
            }
            return match (failed, chunk.error.take()) {
                // Dropped unfinished: standard output keeps the rows before the error, a
                // file is not written, nor the state.
                (Some((_, e)), _) | (None, Some(e)) => Err(e),
                (None, None) => {
                    out.take().map_or(Ok(()), Output::finish)?;
                    let Some(path) = &a.state else { return Ok(()) };
                    let saved = StreamState {
                        options,
                        ids: if a.id_col.is_some() {
                            raw_ids
                        } else {
                            Vec::new()
                        },
                        filters: bank.into_channels(),
                        pending: held.save(),
                    };
                    state::write(path, &saved)
                }
            };
        }
        if first && progress::wanted(a.no_progress) {
            progress = Progress::new(size, started);
        }
        progress.update(chunk.bytes_read, chunk.rows_read);
        let next = pipeline.as_mut();
        let next =
            next.ok_or_else(|| CliError::Data("internal error: the input reader is gone".into()))?;
        chunk = match next.swap(chunk) {
            Ok(next) => next,
            Err(e) => {
                if let Some(sink) = &mut out {
                    held.flush_all(sink)?;
                }
                return Err(e);
            }
        };
    }
    Ok(())
}

/// The output `path`: a Parquet file for a `.parquet` path (ids of `id_type` in the first
/// column, if any), else CSV text (a file, or standard output).
fn create_output(
    path: Option<&std::path::Path>,
    id_type: Option<IdType>,
) -> Result<Output, CliError> {
    match named(path) {
        Some(p) if is_parquet(Some(p)) => Output::table(p, |file, name| {
            Ok(Box::new(ParquetTable::new(file, name, id_type)))
        }),
        _ => Output::create(path),
    }
}

/// The row and message of the bank's error `e` on `chunk` (a series of `kind` needing `need`
/// rows for its fit).
fn row_error(e: seqsmooth::Error, chunk: &Chunk, need: &Need, kind: Kind) -> (usize, CliError) {
    let (index, source) = match e {
        seqsmooth::Error::InChannel { source, .. } => match *source {
            seqsmooth::Error::InBatch { index, source } => (index, *source),
            other => (0, other),
        },
        other => (0, other),
    };
    let at = chunk.at(index);
    let why = match &source {
        seqsmooth::Error::EstimateOutOfRange { what } => Some(too_large(what)),
        // A row the library refuses for want of an estimate once the fit is determined.
        seqsmooth::Error::NotDetermined { samples, why } => Some(format!(
            "no estimate for this row, sample {samples} of its series ({} needs {}): {why}{}",
            need.why,
            need.rows,
            match kind {
                Kind::Fading | Kind::Auto => "; use a larger --tau",
                Kind::Expanding | Kind::Fixed => "",
            }
        )),
        _ => None,
    };
    let e = CliError::from(source).reworded(|m| format!("{at}: {}", why.unwrap_or(m)));
    (index, e)
}

/// Why a number of an estimate cannot be written, in the command line's terms.
fn too_large(what: &str) -> String {
    format!(
        "the estimate's {what} is too large for a double (beyond 1.8e308); express the times in \
         a larger unit, rescale the values or use a shorter --lead"
    )
}

/// A thread that reads the input chunk by chunk ahead of the filtering and writing, passing
/// full chunks one way and emptied ones back.
struct Pipeline {
    full: mpsc::Receiver<Chunk>,
    empty: mpsc::Sender<Chunk>,
}

impl Pipeline {
    /// Starts reading chunks from `reader` on a new thread, of as many rows as `sizes` gives
    /// in turn. The thread ends after the last chunk, or when the pipeline is dropped.
    fn start<S: Records + Send + 'static>(
        mut reader: RowReader<S>,
        mut sizes: impl Iterator<Item = usize> + Send + 'static,
    ) -> Self {
        let (full_tx, full) = mpsc::sync_channel::<Chunk>(1);
        let (empty, empty_rx) = mpsc::channel::<Chunk>();
        // Detached: on an early error the command exits without waiting for a pending read.
        std::thread::spawn(move || loop {
            let mut chunk = empty_rx.try_recv().unwrap_or_default();
            reader.read_chunk(&mut chunk, sizes.next().unwrap_or(CHUNK_ROWS as usize));
            let last = chunk.done || chunk.error.is_some();
            if full_tx.send(chunk).is_err() || last {
                return;
            }
        });
        Self { full, empty }
    }

    /// Hands back a used chunk and takes the next one.
    fn swap(&mut self, used: Chunk) -> Result<Chunk, CliError> {
        // The reader may have finished: then the used chunk is simply dropped.
        let _ = self.empty.send(used);
        self.full
            .recv()
            .map_err(|_| CliError::Data("internal error: the input reader stopped".into()))
    }
}
