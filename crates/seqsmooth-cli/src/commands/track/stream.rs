//! `seqsmooth track` as three stages in flight: a reader thread reads and checks the rows in
//! batches ([`Rows`]), the calling thread tracks them ([`Tracker`]), a writer thread formats
//! and writes their output rows ([`Writer`]). Bounded channels keep a few batches between the
//! stages, so memory does not grow with the input.
//!
//! Errors keep the input's order: a batch carries the rows before a reading error and then the
//! error, so a tracking error on an earlier row is the one reported, as when the rows are taken
//! one at a time. On any error the tracker stops, sends the writer the rows tracked so far and
//! closes its channel: the writer then hands standard output every row before the error and
//! drops a file output's temporary file unrenamed. A writing error (a file that cannot be
//! created or written) stops the writer, whose closed channel stops the tracker; the writer's
//! error is reported.

use super::{Cells, Step, Tracker, Writer};
use crate::commands::shared::radar_rows::{Batch, Rows};
use crate::error::CliError;
use crate::io::Need;
use seqsmooth::estimate::batch::NoiseCovariance;
use seqsmooth::estimate::gauss_newton::Measurement;
use std::io::Read;
use std::path::Path;
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};

/// Rows per batch.
const BATCH_ROWS: usize = 4096;

/// Batches queued between two stages.
const QUEUED: usize = 4;

/// What the tracker sends the writer.
pub(super) enum Block {
    /// Rows' time cells (`ends` as in [`Batch`]) and their cells; `None` for a row the
    /// smoother holds, written by a later block (of the rows it gave). `cells` may be shorter
    /// than `ends` (the rows tracked before an error).
    Rows {
        text: Vec<u8>,
        ends: Vec<usize>,
        cells: Vec<Option<Cells>>,
    },
    /// The input is done, after this many data rows.
    Finish(usize),
}

/// Why the tracker stopped early.
enum Stop {
    /// An error of the input or the tracking.
    Error(CliError),
    /// The writer stopped (its error is the one to report).
    Writer,
}

impl From<CliError> for Stop {
    fn from(e: CliError) -> Self {
        Stop::Error(e)
    }
}

/// Reads, tracks and writes every row of `rows` with `tracker` into `path` (standard output
/// for `None` or `-`).
pub(super) fn run<R: Read + Send>(
    rows: Rows<R>,
    tracker: &mut Tracker,
    path: Option<&Path>,
    need: &Need,
) -> Result<(), CliError> {
    std::thread::scope(|s| {
        let (batches, batches_in) = sync_channel(QUEUED);
        let (blocks, blocks_in) = sync_channel(QUEUED);
        s.spawn(move || read(rows, batches));
        let writer = s.spawn(move || write(path, blocks_in));
        let tracked = track(tracker, batches_in, &blocks, need);
        drop(blocks);
        let written = writer
            .join()
            .unwrap_or_else(|p| std::panic::resume_unwind(p));
        match tracked {
            Ok(()) | Err(Stop::Writer) => written,
            Err(Stop::Error(e)) => Err(e),
        }
    })
}

/// The reader stage: batches of checked rows, the last with the input's end or its error.
/// Stops when the tracker does (the channel closed).
fn read<R: Read>(mut rows: Rows<R>, batches: SyncSender<Batch>) {
    loop {
        let mut batch = Batch {
            rows: Vec::with_capacity(BATCH_ROWS),
            ..Batch::default()
        };
        while batch.rows.len() < BATCH_ROWS {
            match rows.next(&mut batch) {
                Ok(true) => {}
                Ok(false) => {
                    batch.last = true;
                    break;
                }
                Err(e) => {
                    batch.error = Some(e);
                    batch.last = true;
                    break;
                }
            }
        }
        batch.count = rows.count;
        let last = batch.last;
        if batches.send(batch).is_err() || last {
            return;
        }
    }
}

/// The tracking stage: every row of every batch through `tracker`, the cells to the writer.
fn track(
    tracker: &mut Tracker,
    batches: Receiver<Batch>,
    blocks: &SyncSender<Block>,
    need: &Need,
) -> Result<(), Stop> {
    let mut m = Measurement {
        time: 0.0,
        values: vec![None; 3],
        noise: NoiseCovariance::Variances(vec![1.0; 3]),
    };
    let send = |block: Block| blocks.send(block).map_err(|_| Stop::Writer);
    for mut batch in batches {
        let mut cells = Vec::with_capacity(batch.rows.len());
        let mut failed = batch.error.take();
        for (i, r) in batch.rows.iter().enumerate() {
            m.time = r.time;
            m.values.copy_from_slice(&r.values);
            if let NoiseCovariance::Variances(v) = &mut m.noise {
                v.copy_from_slice(&r.variances);
            }
            match tracker.push(&m, r.line, batch.time_text(i)) {
                Ok(Step::Row(c)) => cells.push(Some(c)),
                Ok(Step::Held) => cells.push(None),
                Err(e) => {
                    failed = Some(e);
                    break;
                }
            }
        }
        send(Block::Rows {
            text: batch.text,
            ends: batch.ends,
            cells,
        })?;
        // The smoother's rows given during the batch come after every row of it not held.
        if let Some(given) = tracker.given() {
            send(given)?;
        }
        if let Some(e) = failed {
            return Err(Stop::Error(e));
        }
        if batch.last {
            need.check(batch.count)?;
            if let Some(held) = tracker.finish()? {
                send(held)?;
            }
            return send(Block::Finish(batch.count));
        }
    }
    // The reader sends a batch marked last before it stops, unless it panicked (and the scope
    // re-raises that panic).
    Err(Stop::Error(CliError::Data(
        "the input's reader stopped early".into(),
    )))
}

/// The writer stage: formats and writes the blocks' rows until [`Block::Finish`]; a channel
/// closed before it (the tracker stopped on an error) abandons the output.
fn write(path: Option<&Path>, blocks: Receiver<Block>) -> Result<(), CliError> {
    let mut out = Writer::new(path);
    for block in blocks {
        match block {
            Block::Rows { text, ends, cells } => {
                let mut start = 0;
                for (cells, &end) in cells.iter().zip(&ends) {
                    if let Some(c) = cells {
                        out.row(&text[start..end], c)?;
                    }
                    start = end;
                }
            }
            Block::Finish(rows) => return out.finish(rows),
        }
    }
    out.abandon();
    Ok(())
}
