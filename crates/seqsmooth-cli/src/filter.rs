//! `seqsmooth filter`: streams a CSV time series — or many, told apart by an id column —
//! through polynomial filters.
//!
//! The command reads, filters and writes chunks of rows ([`CHUNK_ROWS`]): a reader thread
//! splits ([`crate::records`]), parses ([`crate::decimal`]) and validates ([`crate::rows`]) the
//! next chunk while the current one is run through the filters of its series, the series in
//! parallel ([`crate::series`]), and, at the same time, the chunk before it is formatted in
//! parallel pieces ([`crate::layout`]) and written in input order. Memory is a few chunks plus
//! one filter per series, whatever the length of the input. The first [`LOOKAHEAD`] data rows (the
//! first `W` for a fixed-memory window longer than that) decide the default `τ` (median time
//! step) and the too-few-samples check before any output is written. Every row is validated
//! (number, finite, strictly increasing time within its series) with its 1-based file line
//! (the header is line 1) and column name.
//!
//! [`SampleReader`] and [`OutputWriter`] are the simpler row-at-a-time reader and writer of the
//! other commands.

use crate::error::CliError;
use crate::layout::Layout;
use crate::number::fmt_f64;
use crate::progress::{self, Progress};
use crate::rows::{Chunk, Row, RowReader};
use crate::series::{run_chunk, Results};
use rayon::prelude::*;
use seqsmooth::polynomial::automatic::{AutoConfig, AutomaticFilter};
use seqsmooth::{
    Engine, ExpandingMemory, FadingMemory, FixedEngine, FixedMemory, PolynomialFilter,
    PolynomialState,
};
use std::collections::{HashMap, VecDeque};
use std::fs::File;
use std::io::{self, BufWriter, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::mpsc;

/// Data rows buffered before output starts: up to 100 time steps for the `τ` median.
pub const LOOKAHEAD: usize = 101;

/// Rows per chunk of `seqsmooth filter`'s streaming pipeline (read, filter, write).
pub const CHUNK_ROWS: u32 = 1 << 16;

/// Rows of the first chunk, unless the first rows held back or scanned need more: the chunks
/// then double in size up to [`CHUNK_ROWS`], so that filtering starts early.
pub const FIRST_CHUNK_ROWS: usize = 1 << 12;

/// With `--id-col`, the default `τ` is the median of the first 100 steps within series among
/// this many first rows.
pub const TAU_SCAN_ROWS: usize = 1 << 16;

/// Which filter the command runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Kind {
    /// Expanding memory: least squares over all samples so far.
    Expanding,
    /// Fading memory: samples discounted by θ per τ of age.
    Fading,
    /// Fixed memory: least squares over the last W samples (--window W).
    Fixed,
    /// Automatic: fading memory that starts itself, settles its degree, estimates the noise,
    /// rejects outliers and flags misfit (--theta T).
    Auto,
}

impl Kind {
    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Expanding => "expanding",
            Kind::Fading => "fading",
            Kind::Fixed => "fixed",
            Kind::Auto => "auto",
        }
    }
}

/// The engine the filter runs on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum EngineArg {
    /// Recursive least squares, exact on any timestamps.
    Exact,
    /// Morrison's fixed-gain recursion: exact on evenly spaced times, approximate otherwise.
    Gain,
}

impl From<EngineArg> for Engine {
    fn from(e: EngineArg) -> Self {
        match e {
            EngineArg::Exact => Engine::Exact,
            EngineArg::Gain => Engine::Gain,
        }
    }
}

/// What the filter command does, after argument checking.
#[derive(Clone, Debug)]
pub struct FilterConfig {
    /// Input file; `None` = standard input.
    pub input: Option<PathBuf>,
    /// Output file; `None` = standard output.
    pub output: Option<PathBuf>,
    /// Filter kind.
    pub kind: Kind,
    /// Degree `m`.
    pub degree: usize,
    /// θ (fading memory and automatic only), in `(0, 1)`.
    pub theta: Option<f64>,
    /// τ; `None` = the median step of the first rows.
    pub tau: Option<f64>,
    /// The window `W` in samples (fixed memory only), at least `degree + 1`.
    pub window: Option<usize>,
    /// Engine.
    pub engine: EngineArg,
    /// Lead `H`: each row's estimate is valid at `t + H`.
    pub lead: f64,
    /// Name of the time column.
    pub time_col: String,
    /// Name of the value column.
    pub value_col: String,
    /// Noise σ for the `s0..sM` columns (the automatic filter's given noise).
    pub sigma: Option<f64>,
    /// The column naming the series (`--id-col`); `None` = one series.
    pub id_col: Option<String>,
    /// Never show a progress display (`--no-progress`).
    pub no_progress: bool,
    /// Rows per chunk of the streaming pipeline.
    pub chunk_rows: usize,
}

/// The data rows a command needs, and why (for the too-few-samples messages).
#[derive(Clone, Debug)]
pub struct Need {
    /// The number of data rows needed.
    pub rows: usize,
    /// What needs them, e.g. `degree 2` or `window 11`.
    pub why: String,
}

impl Need {
    /// A degree-`m` estimate needs `m + 1` rows.
    pub fn degree(m: usize) -> Self {
        Self {
            rows: m + 1,
            why: format!("degree {m}"),
        }
    }

    /// A window of `w` samples needs `w` rows.
    pub fn window(w: usize) -> Self {
        Self {
            rows: w,
            why: format!("window {w}"),
        }
    }

    /// The too-few-samples error when only `got` data rows were read.
    pub fn check(&self, got: usize) -> Result<(), CliError> {
        if got < self.rows {
            return Err(CliError::Data(format!(
                "too few samples: the input has {got} data row{}, {} needs at least {}",
                if got == 1 { "" } else { "s" },
                self.why,
                self.rows
            )));
        }
        Ok(())
    }
}

/// One validated data row.
#[derive(Clone, Debug)]
pub struct Sample {
    /// 1-based file line (header = line 1).
    #[allow(dead_code)] // No command needs it after validation; the tests check it.
    pub line: u64,
    /// Time.
    pub t: f64,
    /// Value.
    pub y: f64,
    /// The time cell as written (echoed to the output).
    pub t_text: String,
    /// The value cell as written (echoed to the output).
    pub y_text: String,
}

/// Counts the lines of the bytes the CSV parser consumes.
///
/// The `csv` crate's own line numbers are wrong after blank lines and with CRLF line ends, so
/// the reader passes every byte through here and the line of a record is computed from its byte
/// offset. Only the bytes read ahead of the current record are kept (the parser's buffer).
pub struct LineTracker<R: Read> {
    inner: R,
    /// Bytes read; `pending[start..]` are not yet attributed to a record, and `pending[start]`
    /// is at offset `base`. The attributed prefix is dropped at the next read.
    pending: Vec<u8>,
    start: usize,
    base: u64,
    /// Line terminators (`\n`, `\r\n` or a lone `\r`) before `base`.
    breaks: u64,
    /// Whether the byte before `base` is `\r` (so a `\n` at `base` ends no new line).
    after_cr: bool,
}

impl<R: Read> LineTracker<R> {
    /// Wraps `inner`.
    pub fn new(inner: R) -> Self {
        Self {
            inner,
            pending: Vec::new(),
            start: 0,
            base: 0,
            breaks: 0,
            after_cr: false,
        }
    }

    /// The 1-based line of the record the parser reports at byte offset `byte`: the parser's
    /// offset may sit before blank lines or a line terminator it skipped, so those are skipped
    /// here too. Offsets must not decrease between calls.
    pub fn line_at(&mut self, byte: u64) -> u64 {
        let rest = &self.pending[self.start..];
        let mut k = (byte.saturating_sub(self.base) as usize).min(rest.len());
        while k < rest.len() && matches!(rest[k], b'\r' | b'\n') {
            k += 1;
        }
        let span = &rest[..k];
        // A `\n` right after a `\r` ends the same line; any other `\r` or `\n` ends one.
        let newlines = span.iter().filter(|&&b| b == b'\n').count() as u64;
        if !span.contains(&b'\r') {
            let continued = self.after_cr && span.first() == Some(&b'\n');
            self.breaks += newlines - u64::from(continued);
            if k > 0 {
                self.after_cr = false;
            }
        } else {
            for &b in span {
                self.breaks += u64::from(b == b'\r' || (b == b'\n' && !self.after_cr));
                self.after_cr = b == b'\r';
            }
        }
        self.start += k;
        self.base += k as u64;
        self.breaks + 1
    }
}

impl<R: Read> Read for LineTracker<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        // The parser asks for more only once it has used up what it had: what is left
        // unattributed is at most one buffer.
        self.pending.drain(..self.start);
        self.start = 0;
        let n = self.inner.read(buf)?;
        self.pending.extend_from_slice(&buf[..n]);
        Ok(n)
    }
}

/// An input without a header (empty) cannot hold the samples `need` asks for.
pub fn check_header(headers: &[String], need: &Need) -> Result<(), CliError> {
    if headers.is_empty() || (headers.len() == 1 && headers[0].is_empty()) {
        return Err(CliError::Data(format!(
            "too few samples: the input is empty (no header, no data rows); {} needs at \
             least {} data row{}",
            need.why,
            need.rows,
            if need.rows == 1 { "" } else { "s" }
        )));
    }
    Ok(())
}

/// The index of the column `name` in the header, or an error listing the columns.
pub fn find_column(headers: &[String], name: &str) -> Result<usize, CliError> {
    headers.iter().position(|h| h == name).ok_or_else(|| {
        CliError::Data(format!(
            "column '{name}' not found in the header; columns are: {}",
            headers.join(", ")
        ))
    })
}

/// The error of the CSV parser `e`, with the line `tracker` finds for its position.
pub fn csv_read_error<R: Read>(tracker: &mut LineTracker<R>, e: csv::Error) -> CliError {
    let line = e.position().map(|p| tracker.line_at(p.byte()));
    let at = match line {
        Some(l) => format!("line {l}: "),
        None => String::new(),
    };
    match e.kind() {
        csv::ErrorKind::UnequalLengths {
            expected_len, len, ..
        } => CliError::Data(format!(
            "{at}malformed CSV: the row has {len} field{} but the header has {expected_len}",
            if *len == 1 { "" } else { "s" }
        )),
        csv::ErrorKind::Utf8 { .. } => {
            CliError::Data(format!("{at}malformed CSV: the row is not valid UTF-8"))
        }
        csv::ErrorKind::Io(io) => CliError::Data(format!("cannot read the input: {io}")),
        _ => CliError::Data(format!("{at}malformed CSV: {e}")),
    }
}

/// Reads and validates the rows of a CSV time series one at a time.
pub struct SampleReader<R: Read> {
    reader: csv::Reader<LineTracker<R>>,
    record: csv::StringRecord,
    time_idx: usize,
    value_idx: usize,
    time_col: String,
    value_col: String,
    previous: Option<(f64, String, u64)>,
}

impl<R: Read> SampleReader<R> {
    /// Reads the header and locates the two columns.
    pub fn new(input: R, time_col: &str, value_col: &str, need: &Need) -> Result<Self, CliError> {
        let reader = csv::ReaderBuilder::new()
            .has_headers(true)
            .flexible(false)
            .trim(csv::Trim::All)
            .from_reader(LineTracker::new(input));
        let mut this = Self {
            reader,
            record: csv::StringRecord::new(),
            time_idx: 0,
            value_idx: 0,
            time_col: time_col.to_string(),
            value_col: value_col.to_string(),
            previous: None,
        };
        let headers = match this.reader.headers() {
            Ok(h) => h.clone(),
            Err(e) => return Err(this.csv_error(e)),
        };
        let headers: Vec<String> = headers.iter().map(str::to_string).collect();
        check_header(&headers, need)?;
        let find = |name: &str| find_column(&headers, name);
        this.time_idx = find(time_col)?;
        this.value_idx = find(value_col)?;
        Ok(this)
    }

    fn csv_error(&mut self, e: csv::Error) -> CliError {
        csv_read_error(self.reader.get_mut(), e)
    }

    /// The next data row, validated; `None` at the end of the input.
    pub fn next_sample(&mut self) -> Result<Option<Sample>, CliError> {
        match self.reader.read_record(&mut self.record) {
            Ok(true) => {}
            Ok(false) => return Ok(None),
            Err(e) => return Err(self.csv_error(e)),
        }
        let byte = self.record.position().map_or(0, |p| p.byte());
        let line = self.reader.get_mut().line_at(byte);
        let t_text = self.record[self.time_idx].to_string();
        let y_text = self.record[self.value_idx].to_string();
        let t = parse_cell(&t_text, line, &self.time_col, "time")?;
        let y = parse_cell(&y_text, line, &self.value_col, "value")?;
        if let Some((prev, prev_text, prev_line)) = &self.previous {
            if t <= *prev {
                let why = if t == *prev {
                    "duplicate time; times must be strictly increasing"
                } else {
                    "times must be strictly increasing"
                };
                return Err(CliError::Data(format!(
                    "line {line}: time {t_text} is not after the previous time {prev_text} \
                     (line {prev_line}): {why}"
                )));
            }
        }
        self.previous = Some((t, t_text.clone(), line));
        Ok(Some(Sample {
            line,
            t,
            y,
            t_text,
            y_text,
        }))
    }
}

/// Parses the number in the cell `text` (line `line`, column `column`, holding the `what`): a
/// typed error for an empty cell, a non-number or a non-finite value.
pub fn parse_cell(text: &str, line: u64, column: &str, what: &str) -> Result<f64, CliError> {
    if text.is_empty() {
        return Err(CliError::Data(format!(
            "line {line}, column '{column}': the cell is empty, expected a number"
        )));
    }
    let v: f64 = text.parse().map_err(|_| {
        CliError::Data(format!(
            "line {line}, column '{column}': '{text}' is not a number"
        ))
    })?;
    if !v.is_finite() {
        return Err(CliError::Data(format!(
            "line {line}, column '{column}': {what} {text} is not finite"
        )));
    }
    Ok(v)
}

/// The median time step of `samples` (the mean of the middle two for an even count), or 1 for
/// fewer than two samples.
pub fn median_step(samples: &[Sample]) -> f64 {
    median(samples.windows(2).map(|w| w[1].t - w[0].t).collect()).unwrap_or(1.0)
}

/// The median of `values` (the mean of the middle two for an even count); `None` for none.
pub fn median(mut values: Vec<f64>) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    let k = values.len();
    Some(if k % 2 == 1 {
        values[k / 2]
    } else {
        0.5 * values[k / 2 - 1] + 0.5 * values[k / 2]
    })
}

/// The median of the first `LOOKAHEAD - 1` time steps within the series of `rows` (each
/// row's time minus the previous time of its series), in input order; `None` when no series
/// has two rows. For one series, the steps of its first `LOOKAHEAD` rows.
pub fn median_series_step(rows: &[Row]) -> Option<f64> {
    let mut last: HashMap<u32, f64> = HashMap::new();
    let mut steps = Vec::with_capacity(LOOKAHEAD - 1);
    for r in rows {
        if let Some(prev) = last.insert(r.series, r.t) {
            steps.push(r.t - prev);
            if steps.len() == LOOKAHEAD - 1 {
                break;
            }
        }
    }
    median(steps)
}

/// Builds the configured filter (τ already resolved for fading memory).
pub fn build_filter(
    kind: Kind,
    degree: usize,
    theta: Option<f64>,
    tau: f64,
    engine: EngineArg,
    sigma: Option<f64>,
) -> Result<Box<dyn PolynomialFilter>, seqsmooth::Error> {
    let filter: Box<dyn PolynomialFilter> = match kind {
        Kind::Expanding => {
            let f = ExpandingMemory::new(degree, engine.into())?;
            Box::new(match sigma {
                Some(s) => f.with_noise_sigma(s)?,
                None => f,
            })
        }
        Kind::Fading => {
            let theta = theta.ok_or_else(|| seqsmooth::Error::InvalidParameter {
                name: "theta",
                value: "(none)".into(),
                reason: "a fading-memory filter needs theta".into(),
            })?;
            let f = FadingMemory::new(degree, theta, tau, engine.into())?;
            Box::new(match sigma {
                Some(s) => f.with_noise_sigma(s)?,
                None => f,
            })
        }
        Kind::Fixed | Kind::Auto => {
            return Err(seqsmooth::Error::InvalidParameter {
                name: "kind",
                value: kind.name().into(),
                reason: "fixed-memory and automatic filters are built by build_runner".into(),
            })
        }
    };
    Ok(filter)
}

/// The fixed-memory filter of the command: least squares over the last `W` samples on any
/// timestamps.
///
/// The library's even-spacing engines reject a step that differs from the first; this runs
/// [`FixedEngine::Sliding`] (`O(m²)` per sample) while the times are evenly spaced, keeping the
/// newest `W` samples, and at the first uneven step replays them into a
/// [`FixedEngine::Irregular`] filter (a QR refit of the window per sample) that carries on: the
/// same least-squares fit either way, up to rounding.
#[derive(Clone, Debug)]
pub struct FixedRunner {
    filter: FixedMemory,
    degree: usize,
    window: usize,
    sigma: Option<f64>,
    /// The newest `window` samples while the sliding engine runs.
    recent: VecDeque<(f64, f64)>,
}

impl FixedRunner {
    /// A degree-`degree` filter over `window` samples, with noise `sigma` for the covariance.
    pub fn new(degree: usize, window: usize, sigma: Option<f64>) -> Result<Self, seqsmooth::Error> {
        Ok(Self {
            filter: Self::make(degree, window, sigma, FixedEngine::Sliding)?,
            degree,
            window,
            sigma,
            recent: VecDeque::new(),
        })
    }

    fn make(
        degree: usize,
        window: usize,
        sigma: Option<f64>,
        engine: FixedEngine,
    ) -> Result<FixedMemory, seqsmooth::Error> {
        let f = FixedMemory::new(degree, window, engine)?;
        match sigma {
            Some(s) => f.with_noise_sigma(s),
            None => Ok(f),
        }
    }

    /// Processes one sample.
    pub fn update(&mut self, t: f64, y: f64) -> Result<(), seqsmooth::Error> {
        if self.filter.engine() != FixedEngine::Irregular {
            if self.filter.update(t, y).is_ok() {
                self.recent.push_back((t, y));
                if self.recent.len() > self.window {
                    self.recent.pop_front();
                }
                return Ok(());
            }
            // The first uneven step (the input is already checked to be finite and
            // increasing): the same fit on the irregular engine, from the newest samples.
            let mut f = Self::make(self.degree, self.window, self.sigma, FixedEngine::Irregular)?;
            for &(t, y) in &self.recent {
                f.update(t, y)?;
            }
            self.filter = f;
            self.recent = VecDeque::new();
        }
        self.filter.update(t, y)
    }

    /// The number of samples in the window so far: `W` once full.
    pub fn filled(&self) -> usize {
        (self.filter.samples() as usize).min(self.window)
    }

    /// The estimate at time `t`; `None` until the window is full.
    pub fn estimate_at(&self, t: f64) -> Option<PolynomialState> {
        self.filter.estimate_at(t)
    }
}

/// A running filter of any kind. Cloning a new one is how each series gets its filter.
#[derive(Clone)]
pub enum Runner {
    /// Expanding memory.
    Expanding(Box<ExpandingMemory>),
    /// Fading memory.
    Fading(Box<FadingMemory>),
    /// Fixed memory.
    Fixed(Box<FixedRunner>),
    /// The automatic filter.
    Auto(Box<AutomaticFilter>),
}

/// The trailing cells of one output row (after `d0..dM` and `s0..sM`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Extra {
    /// Expanding and fading memory: none.
    #[default]
    None,
    /// Fixed memory: the number of rows in the window.
    Window(usize),
    /// The automatic filter: the noise σ in use, the outlier and misfit flags.
    Auto {
        /// The noise σ in use, if any.
        noise: Option<f64>,
        /// The sample was rejected as an outlier.
        outlier: bool,
        /// The misfit test fired.
        misfit: bool,
    },
}

/// What one output row holds besides its values: how many derivatives and 1σ cells are
/// filled (the rest are empty) and the trailing cells.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Cells {
    /// The number of derivatives `d0, d1, …` with a value.
    pub derivatives: usize,
    /// The number of 1σ cells `s0, s1, …` with a value.
    pub std_devs: usize,
    /// The trailing cells.
    pub extra: Extra,
}

/// Copies an estimate into the row slots: derivatives into `values[..m+1]`, and with `sigma`
/// their 1σ into `values[m+1..]`. The estimate may be of a lower degree than the slots.
fn store(estimate: Option<&PolynomialState>, sigma: bool, values: &mut [f64]) -> Cells {
    let Some(s) = estimate else {
        return Cells::default();
    };
    let width = if sigma {
        values.len() / 2
    } else {
        values.len()
    };
    let nd = s.derivatives.len().min(width);
    values[..nd].copy_from_slice(&s.derivatives[..nd]);
    let ns = match (&s.covariance, sigma) {
        (Some(c), true) => {
            let ns = c.nrows().min(width);
            for (i, v) in values[width..width + ns].iter_mut().enumerate() {
                *v = c[(i, i)].max(0.0).sqrt();
            }
            ns
        }
        _ => 0,
    };
    Cells {
        derivatives: nd,
        std_devs: ns,
        extra: Extra::None,
    }
}

impl Runner {
    /// The expanding- or fading-memory filter, which takes batches
    /// ([`PolynomialFilter::update_many_into`]); `None` for the other kinds.
    pub fn batch_filter(&mut self) -> Option<&mut dyn PolynomialFilter> {
        match self {
            Runner::Expanding(f) => Some(f.as_mut()),
            Runner::Fading(f) => Some(f.as_mut()),
            Runner::Fixed(_) | Runner::Auto(_) => None,
        }
    }

    /// The columns after `d0..dM` and `s0..sM` this kind writes.
    pub fn extra_columns(&self) -> &'static [&'static str] {
        match self {
            Runner::Expanding(_) | Runner::Fading(_) => &[],
            Runner::Fixed(_) => &["window"],
            Runner::Auto(_) => &["noise", "outlier", "misfit"],
        }
    }

    /// Processes the sample `(t, y)` and stores the row's estimate at `t + lead` in `values`:
    /// `m+1` slots for the derivatives, and with `sigma` `m+1` more for their 1σ (taken from
    /// the covariance). Slots past the returned counts are left as they were.
    pub fn step_into(
        &mut self,
        t: f64,
        y: f64,
        lead: f64,
        sigma: bool,
        values: &mut [f64],
    ) -> Result<Cells, seqsmooth::Error> {
        match self {
            Runner::Expanding(f) => {
                f.update(t, y)?;
                Ok(store(f.estimate_at(t + lead).as_ref(), sigma, values))
            }
            Runner::Fading(f) => {
                f.update(t, y)?;
                Ok(store(f.estimate_at(t + lead).as_ref(), sigma, values))
            }
            Runner::Fixed(f) => {
                f.update(t, y)?;
                let mut cells = store(f.estimate_at(t + lead).as_ref(), sigma, values);
                cells.extra = Extra::Window(f.filled());
                Ok(cells)
            }
            Runner::Auto(f) => {
                let out = f.update(t, y)?;
                // The output's estimate is at t: the update's own, or across a rejected sample
                // the prediction; with a lead the active filter's, the same way.
                let mut cells = if lead == 0.0 {
                    store(out.estimate.as_ref(), sigma, values)
                } else {
                    store(f.estimate_at(t + lead).as_ref(), sigma, values)
                };
                cells.extra = Extra::Auto {
                    noise: out.noise_sigma,
                    outlier: out.outlier,
                    misfit: out.misfit,
                };
                Ok(cells)
            }
        }
    }
}

/// Builds the configured filter of any kind (τ already resolved for fading memory and the
/// automatic filter).
pub fn build_runner(cfg: &FilterConfig, tau: f64) -> Result<Runner, seqsmooth::Error> {
    match cfg.kind {
        Kind::Expanding => {
            let f = ExpandingMemory::new(cfg.degree, cfg.engine.into())?;
            Ok(Runner::Expanding(Box::new(match cfg.sigma {
                Some(s) => f.with_noise_sigma(s)?,
                None => f,
            })))
        }
        Kind::Fading => {
            let theta = cfg
                .theta
                .ok_or_else(|| seqsmooth::Error::InvalidParameter {
                    name: "theta",
                    value: "(none)".into(),
                    reason: "a fading-memory filter needs theta".into(),
                })?;
            let f = FadingMemory::new(cfg.degree, theta, tau, cfg.engine.into())?;
            Ok(Runner::Fading(Box::new(match cfg.sigma {
                Some(s) => f.with_noise_sigma(s)?,
                None => f,
            })))
        }
        Kind::Fixed => {
            let window = cfg
                .window
                .ok_or_else(|| seqsmooth::Error::InvalidParameter {
                    name: "window",
                    value: "(none)".into(),
                    reason: "a fixed-memory filter needs a window".into(),
                })?;
            Ok(Runner::Fixed(Box::new(FixedRunner::new(
                cfg.degree, window, cfg.sigma,
            )?)))
        }
        Kind::Auto => {
            let theta = cfg
                .theta
                .ok_or_else(|| seqsmooth::Error::InvalidParameter {
                    name: "theta",
                    value: "(none)".into(),
                    reason: "the automatic filter needs theta".into(),
                })?;
            let mut config = AutoConfig::new(cfg.degree, theta, tau);
            config.engine = cfg.engine.into();
            config.noise_sigma = cfg.sigma;
            Ok(Runner::Auto(Box::new(AutomaticFilter::new(config)?)))
        }
    }
}

/// Writes the filter's output CSV: header `t,y,d0..dM[,s0..sM][,extra…]`, one row per sample.
pub struct OutputWriter<W: Write> {
    writer: csv::Writer<W>,
    name: String,
    degree: usize,
    sigma: bool,
    extra: usize,
}

/// `width` cells: the values formatted, then empty cells (an estimate of a lower degree than
/// the columns, or none).
fn padded(values: Option<&[f64]>, width: usize) -> impl Iterator<Item = String> + '_ {
    let values = values.unwrap_or(&[]);
    (0..width).map(move |k| values.get(k).map_or_else(String::new, |&v| fmt_f64(v)))
}

impl<W: Write> OutputWriter<W> {
    /// Writes the header to `sink`, named `name` in error messages.
    pub fn new(sink: W, name: &str, degree: usize, sigma: bool) -> Result<Self, CliError> {
        Self::with_extra(sink, name, degree, sigma, &[])
    }

    /// Writes the header with the trailing columns `extra` to `sink`.
    pub fn with_extra(
        sink: W,
        name: &str,
        degree: usize,
        sigma: bool,
        extra: &[&str],
    ) -> Result<Self, CliError> {
        let mut writer = csv::WriterBuilder::new().from_writer(sink);
        let mut header = vec!["t".to_string(), "y".to_string()];
        header.extend((0..=degree).map(|k| format!("d{k}")));
        if sigma {
            header.extend((0..=degree).map(|k| format!("s{k}")));
        }
        header.extend(extra.iter().map(|c| c.to_string()));
        writer
            .write_record(&header)
            .map_err(|e| CliError::write_csv(name, e))?;
        Ok(Self {
            writer,
            name: name.to_string(),
            degree,
            sigma,
            extra: extra.len(),
        })
    }

    /// Writes one row: the echoed `t` and `y` cells and the estimate (empty cells without one).
    pub fn row(
        &mut self,
        t_text: &str,
        y_text: &str,
        estimate: Option<&PolynomialState>,
    ) -> Result<(), CliError> {
        self.row_with(t_text, y_text, estimate, &[])
    }

    /// Writes one row with the trailing cells `extra` (as many as the header's extra columns).
    /// Derivatives (and 1σ) beyond the estimate's degree are empty cells.
    pub fn row_with(
        &mut self,
        t_text: &str,
        y_text: &str,
        estimate: Option<&PolynomialState>,
        extra: &[String],
    ) -> Result<(), CliError> {
        debug_assert_eq!(extra.len(), self.extra);
        let width = self.degree + 1;
        let mut cells: Vec<String> = Vec::with_capacity(2 + 2 * width + extra.len());
        cells.push(t_text.to_string());
        cells.push(y_text.to_string());
        cells.extend(padded(estimate.map(|s| s.derivatives.as_slice()), width));
        if self.sigma {
            let sd = estimate.and_then(PolynomialState::std_devs);
            cells.extend(padded(sd.as_deref(), width));
        }
        cells.extend(extra.iter().cloned());
        self.writer
            .write_record(&cells)
            .map_err(|e| CliError::write_csv(&self.name, e))
    }

    /// Flushes everything to the sink.
    pub fn finish(mut self) -> Result<(), CliError> {
        let name = self.name.clone();
        self.writer.flush().map_err(|e| CliError::write(&name, e))?;
        let mut inner = self
            .writer
            .into_inner()
            .map_err(|e| CliError::write(&name, io::Error::other(e.to_string())))?;
        inner.flush().map_err(|e| CliError::write(&name, e))
    }
}

/// Opens the output sink: a buffered file or buffered standard output.
pub fn open_output(path: Option<&Path>) -> Result<(Box<dyn Write>, String), CliError> {
    match path {
        Some(p) if p.as_os_str() != "-" => {
            let name = format!("'{}'", p.display());
            let file = File::create(p)
                .map_err(|e| CliError::Data(format!("cannot create output file {name}: {e}")))?;
            Ok((Box::new(BufWriter::new(file)), name))
        }
        _ => Ok((
            Box::new(BufWriter::new(io::stdout().lock())),
            "standard output".to_string(),
        )),
    }
}

/// Opens the input: a file, or standard input for `None` or `-`.
pub fn open_input(path: Option<&Path>) -> Result<Box<dyn Read + Send>, CliError> {
    match path {
        Some(p) if p.as_os_str() != "-" => {
            let file = File::open(p).map_err(|e| {
                CliError::Data(format!("cannot open input file '{}': {e}", p.display()))
            })?;
            // The CSV reader buffers; no BufReader needed.
            Ok(Box::new(file))
        }
        // Unlocked, so that another thread may read it; the CSV reader reads large blocks.
        _ => Ok(Box::new(io::stdin())),
    }
}

/// Refuses an output file that is the input file.
pub fn check_distinct(input: Option<&Path>, output: Option<&Path>) -> Result<(), CliError> {
    if let (Some(i), Some(o)) = (input, output) {
        // Creating the output would truncate the input while it is still being read.
        if let (Ok(a), Ok(b)) = (i.canonicalize(), o.canonicalize()) {
            if a == b {
                return Err(CliError::Usage(format!(
                    "the output file '{}' is the input file; write to another file",
                    o.display()
                )));
            }
        }
    }
    Ok(())
}

/// Runs `seqsmooth filter`.
///
/// The input is read in chunks of [`FilterConfig::chunk_rows`] rows (the first chunk at least
/// the `hold` rows that decide τ and the too-few-samples check). Each chunk's rows are run
/// through their series' filters, the series in parallel, while the chunk before is formatted,
/// and written in input order; the memory is a few chunks plus one filter per series, whatever
/// the length of the input. An error
/// in one of the first `hold` rows stops the command before any output; a later one after the
/// rows before it, of every series, have been written.
pub fn run(cfg: &FilterConfig) -> Result<(), CliError> {
    check_distinct(cfg.input.as_deref(), cfg.output.as_deref())?;
    let need = match (cfg.kind, cfg.window) {
        (Kind::Fixed, Some(w)) => Need::window(w.max(cfg.degree + 1)),
        _ => Need::degree(cfg.degree),
    };
    let started = std::time::Instant::now();
    let size = input_size(cfg.input.as_deref());
    let input = open_input(cfg.input.as_deref())?;
    let mut reader = RowReader::new(
        input,
        &cfg.time_col,
        &cfg.value_col,
        cfg.id_col.as_deref(),
        &need,
    )?;

    // A fixed-memory window longer than LOOKAHEAD is read in full before the first output row:
    // its rows have no estimate, and an input shorter than the window is an error.
    let hold = LOOKAHEAD.max(need.rows);
    let chunk_rows = cfg.chunk_rows.max(1);
    let mut chunk = Chunk::default();
    // With --id-col, the default τ comes from the steps within series among the first
    // TAU_SCAN_ROWS rows: they are all in the first chunk, whatever the chunk size.
    let default_tau = cfg.tau.is_none() && matches!(cfg.kind, Kind::Fading | Kind::Auto);
    let scan = if default_tau && cfg.id_col.is_some() {
        TAU_SCAN_ROWS
    } else {
        0
    };
    let first_rows = chunk_rows.min(FIRST_CHUNK_ROWS).max(hold).max(scan);
    reader.read_chunk(&mut chunk, first_rows);
    if chunk.rows.len() < hold {
        if let Some(e) = chunk.error.take() {
            return Err(e);
        }
    }
    need.check(chunk.rows.len())?;
    let tau = match (cfg.kind, cfg.tau) {
        (_, Some(tau)) => tau,
        (Kind::Fading | Kind::Auto, None) => {
            let head = &chunk.rows[..chunk.rows.len().min(hold.max(scan))];
            let tau = match median_series_step(head) {
                Some(tau) => tau,
                // One row (per series) in all: τ does not matter.
                None if chunk.done && chunk.rows.len() <= head.len() => 1.0,
                None => {
                    return Err(CliError::Data(format!(
                        "no series has two rows among the first {} data rows, so there is no \
                         median time step for the default tau; give --tau",
                        head.len()
                    )))
                }
            };
            if !(tau.is_finite() && tau > 0.0) {
                return Err(CliError::Data(format!(
                    "the median time step of the first rows, {}, is not a usable tau; give --tau",
                    fmt_f64(tau)
                )));
            }
            tau
        }
        (Kind::Expanding | Kind::Fixed, None) => 1.0,
    };
    let prototype = build_runner(cfg, tau).map_err(|e| CliError::Usage(e.to_string()))?;
    // The automatic filter always writes s0..sM (from the given or the estimated noise).
    let layout = Layout {
        id: cfg.id_col.clone(),
        degree: cfg.degree,
        sigma: cfg.sigma.is_some() || cfg.kind == Kind::Auto,
        extra: prototype.extra_columns(),
    };
    let stride = layout.stride();
    let mut runners: Vec<Option<Runner>> = Vec::new();
    if cfg.id_col.is_none() {
        runners.push(Some(prototype.clone()));
    }
    let mut ids: Vec<Vec<u8>> = Vec::new();
    let mut results = Results::default();
    let mut spare = Results::default();
    // Formatted output: being filled (from the pending chunk), and waiting to be written.
    let (mut filling, mut formatted): (Vec<Vec<u8>>, Vec<Vec<u8>>) = Default::default();
    let mut ready = 0;
    let mut sink: Option<(Box<dyn Write>, String)> = None;
    let mut progress = Progress::hidden();
    let mut first = true;
    // The rest of the input is read on a thread of its own, a chunk ahead.
    let mut pipeline = (!chunk.done && chunk.error.is_none()).then(|| {
        let sizes = (1..).map(move |k| first_rows.saturating_mul(1 << k.min(16)));
        Pipeline::start(reader, sizes.map(move |rows| rows.min(chunk_rows)))
    });
    // The chunk before this one, filtered but not yet formatted.
    let mut pending: Option<(Chunk, Results)> = None;
    loop {
        for id in chunk.new_ids.drain(..) {
            runners.push(Some(prototype.clone()));
            ids.push(id);
        }
        let (ids, layout) = (&ids, &layout);
        // This chunk is filtered while the one before is formatted and the one before that
        // written.
        let (mut failed, mut pieces) = (None, 0);
        let written = rayon::in_place_scope(|scope| {
            scope.spawn(|_| {
                let (lead, sigma) = (cfg.lead, layout.sigma);
                failed = run_chunk(&chunk, &mut runners, lead, sigma, stride, &mut results);
            });
            if let Some((c, r)) = &pending {
                let table = Table::new(c, r, ids, layout);
                let (pieces, filling) = (&mut pieces, &mut filling);
                scope.spawn(move |_| *pieces = table.format_pieces(c.rows.len(), filling));
            }
            match &mut sink {
                Some((out, name)) => write_pieces(out, name, &formatted[..ready]),
                None => Ok(()),
            }
        });
        written?;
        std::mem::swap(&mut filling, &mut formatted);
        ready = pieces;
        let limit = failed.as_ref().map_or(chunk.rows.len(), |(i, _)| *i);
        if first && limit < hold {
            if let Some((_, e)) = failed {
                return Err(e);
            }
        }
        let (out, name) = match &mut sink {
            Some(s) => s,
            None => {
                let (mut out, name) = open_output(cfg.output.as_deref())?;
                out.write_all(&layout.header())
                    .map_err(|e| CliError::write(&name, e))?;
                sink.insert((out, name))
            }
        };
        let used = pending.take().map(|(c, r)| {
            spare = r;
            c
        });
        if failed.is_some() || chunk.error.is_some() || chunk.done {
            write_pieces(out, name, &formatted[..ready])?;
            let table = Table::new(&chunk, &results, ids, layout);
            let pieces = table.format_pieces(limit, &mut filling);
            write_pieces(out, name, &filling[..pieces])?;
            out.flush().map_err(|e| CliError::write(name, e))?;
            return match (failed, chunk.error.take()) {
                (Some((_, e)), _) | (None, Some(e)) => Err(e),
                (None, None) => Ok(()),
            };
        }
        if first && progress::wanted(cfg.no_progress) {
            progress = Progress::new(size, started);
        }
        progress.update(chunk.bytes_read, chunk.rows_read);
        first = false;
        let next = pipeline
            .as_mut()
            .ok_or_else(|| CliError::Data("internal error: the input reader is gone".into()))?;
        let filtered = std::mem::replace(&mut chunk, next.swap(used)?);
        pending = Some((
            filtered,
            std::mem::replace(&mut results, std::mem::take(&mut spare)),
        ));
    }
}

/// Writes formatted pieces of output to `out` (named `name`), in order.
fn write_pieces(out: &mut dyn Write, name: &str, pieces: &[Vec<u8>]) -> Result<(), CliError> {
    for piece in pieces {
        out.write_all(piece).map_err(|e| CliError::write(name, e))?;
    }
    Ok(())
}

/// A thread that reads the input chunk by chunk ahead of the filtering and writing, passing
/// full chunks one way and emptied ones back (at most four chunks exist: one read, one
/// ready, one filtered, one formatted).
struct Pipeline {
    full: mpsc::Receiver<Chunk>,
    empty: mpsc::Sender<Chunk>,
}

impl Pipeline {
    /// Starts reading chunks from `reader` on a new thread, of as many rows as `sizes` gives
    /// in turn. The thread ends after the last chunk, or when the pipeline is dropped (the
    /// command is ending).
    fn start<R: Read + Send + 'static>(
        mut reader: RowReader<R>,
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

    /// Hands back a used chunk, if any, and takes the next one.
    fn swap(&mut self, used: Option<Chunk>) -> Result<Chunk, CliError> {
        // The reader may have finished: then the used chunk is simply dropped.
        if let Some(used) = used {
            let _ = self.empty.send(used);
        }
        self.full
            .recv()
            .map_err(|_| CliError::Data("internal error: the input reader stopped".into()))
    }
}

/// The size of the input file, for the progress bar; `None` for standard input or anything
/// but a regular file.
fn input_size(path: Option<&Path>) -> Option<u64> {
    let p = path.filter(|p| p.as_os_str() != "-")?;
    let meta = std::fs::metadata(p).ok()?;
    meta.is_file().then_some(meta.len())
}

/// A chunk's rows with their results, ready to be written in input order.
struct Table<'a> {
    chunk: &'a Chunk,
    results: &'a Results,
    ids: &'a [Vec<u8>],
    layout: &'a Layout,
    stride: usize,
}

impl<'a> Table<'a> {
    /// Rows formatted per piece (on one thread).
    const PIECE: usize = 4096;

    /// The rows of `chunk` with their `results`, the series `ids` and the `layout`.
    fn new(chunk: &'a Chunk, results: &'a Results, ids: &'a [Vec<u8>], layout: &'a Layout) -> Self {
        Self {
            chunk,
            results,
            ids,
            layout,
            stride: layout.stride(),
        }
    }

    /// Appends the text of rows `rows` to `buf`.
    fn format(&self, rows: std::ops::Range<usize>, buf: &mut Vec<u8>) {
        for i in rows {
            let row = &self.chunk.rows[i];
            let (t, y) = self.chunk.cells(row);
            let slot = self.results.slot_of(i);
            let id = self
                .layout
                .id
                .as_ref()
                .and_then(|_| self.ids.get(row.series as usize))
                .map(Vec::as_slice);
            self.layout.row(
                buf,
                id,
                t,
                y,
                &self.results.values[slot * self.stride..(slot + 1) * self.stride],
                &self.results.cells[slot],
            );
        }
    }

    /// Formats the first `limit` rows into `bufs`, one piece of [`Table::PIECE`] rows per
    /// buffer, the pieces in parallel; returns the number of pieces.
    fn format_pieces(&self, limit: usize, bufs: &mut Vec<Vec<u8>>) -> usize {
        let pieces = limit.div_ceil(Self::PIECE);
        if bufs.len() < pieces {
            bufs.resize_with(pieces, Vec::new);
        }
        bufs[..pieces]
            .par_iter_mut()
            .enumerate()
            .for_each(|(k, buf)| {
                buf.clear();
                let start = k * Self::PIECE;
                self.format(start..(start + Self::PIECE).min(limit), buf);
            });
        pieces
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(t: f64) -> Sample {
        Sample {
            line: 0,
            t,
            y: 0.0,
            t_text: String::new(),
            y_text: String::new(),
        }
    }

    /// The fixed-memory runner falls back from the sliding engine to the irregular one at the
    /// first uneven step, and its estimates are the irregular engine's from the start (up to
    /// rounding) on both sides of the switch.
    #[test]
    fn fixed_runner_switches_engine_at_first_uneven_step() {
        let mut runner = FixedRunner::new(2, 6, Some(0.5)).unwrap();
        let mut reference = FixedMemory::new(2, 6, FixedEngine::Irregular)
            .unwrap()
            .with_noise_sigma(0.5)
            .unwrap();
        let mut t = 0.0;
        for k in 0..40 {
            t += if k < 15 {
                0.25
            } else {
                0.25 + 0.1 * ((k % 3) as f64)
            };
            let y = (0.7 * t).sin() + 0.1 * ((k * 7 % 5) as f64);
            runner.update(t, y).unwrap();
            reference.update(t, y).unwrap();
            let engine = runner.filter.engine();
            assert_eq!(engine == FixedEngine::Irregular, k >= 16, "k = {k}");
            assert_eq!(runner.filled(), (k + 1).min(6));
            for lead in [0.0, 0.3, -0.6] {
                match (
                    runner.estimate_at(t + lead),
                    reference.estimate_at(t + lead),
                ) {
                    (None, None) => assert!(k < 5),
                    (Some(a), Some(b)) => {
                        for (x, y) in a.derivatives.iter().zip(&b.derivatives) {
                            assert!((x - y).abs() <= 1e-9 * (1.0 + y.abs()), "k = {k}: {x} {y}");
                        }
                        let (sa, sb) = (a.std_devs().unwrap(), b.std_devs().unwrap());
                        for (x, y) in sa.iter().zip(&sb) {
                            assert!((x - y).abs() <= 1e-9 * (1.0 + y.abs()), "k = {k}: {x} {y}");
                        }
                    }
                    _ => panic!("k = {k}: one estimate is missing"),
                }
            }
        }
    }

    #[test]
    fn median_of_steps() {
        assert_eq!(median_step(&[sample(0.0)]), 1.0);
        assert_eq!(median_step(&[sample(0.0), sample(2.0)]), 2.0);
        let s: Vec<_> = [0.0, 1.0, 3.0, 3.5].into_iter().map(sample).collect();
        assert_eq!(median_step(&s), 1.0); // steps 1, 2, 0.5
        let s: Vec<_> = [0.0, 1.0, 3.0, 3.5, 7.5].into_iter().map(sample).collect();
        assert_eq!(median_step(&s), 1.5); // steps 0.5, 1, 2, 4
    }

    #[test]
    fn reader_lines_and_messages() {
        let text = "t,y\n0,1\n1,2\n\n2,abc\n";
        let mut r = SampleReader::new(text.as_bytes(), "t", "y", &Need::degree(1)).unwrap();
        assert_eq!(r.next_sample().unwrap().unwrap().line, 2);
        assert_eq!(r.next_sample().unwrap().unwrap().line, 3);
        let e = r.next_sample().unwrap_err().to_string();
        assert_eq!(e, "line 5, column 'y': 'abc' is not a number");
    }

    fn lines(text: &str) -> Vec<u64> {
        let mut r = SampleReader::new(text.as_bytes(), "t", "y", &Need::degree(0)).unwrap();
        let mut v = Vec::new();
        while let Some(s) = r.next_sample().unwrap() {
            v.push(s.line);
        }
        v
    }

    #[test]
    fn line_numbers_survive_blank_lines_crlf_and_quotes() {
        assert_eq!(lines("t,y\n\n\n0,1\n1,2\n"), [4, 5]);
        assert_eq!(lines("\nt,y\n0,1\n"), [3]);
        assert_eq!(lines("t,y\r\n0,1\r\n\r\n1,2\r\n"), [2, 4]);
        assert_eq!(lines("t,y\n0,1\r\n1,2\r2,3\n\r\n4,5"), [2, 3, 4, 6]);
        assert_eq!(lines("t,y,z\n0,1,\"a\nb\"\n1,2,x\n"), [2, 4]);
        assert_eq!(lines("t,y\n0,1\n\n\n\n1,2\n"), [2, 6]);
    }

    #[test]
    fn line_numbers_across_buffer_refills() {
        let mut text = String::from("t,y\r\n");
        for k in 0..5000 {
            text += &format!("{k},{k}\r\n");
            if k % 7 == 0 {
                text += "\r\n";
            }
        }
        let got = lines(&text);
        let mut line = 1;
        let want: Vec<u64> = (0..5000)
            .map(|k| {
                line += 1;
                let here = line;
                if k % 7 == 0 {
                    line += 1;
                }
                here
            })
            .collect();
        assert_eq!(got, want);
    }
}
