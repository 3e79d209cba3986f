//! `seqsmooth filter`: streams a CSV time series through a polynomial filter.
//!
//! Reading streams row by row. Only the first [`LOOKAHEAD`] data rows are buffered: they give
//! the default `τ` (median time step) and decide the too-few-samples check before any output is
//! written. Every row is validated (number, finite, strictly increasing time) with its 1-based
//! file line (the header is line 1) and column name.

use crate::error::CliError;
use crate::number::fmt_f64;
use seqsmooth::{Engine, ExpandingMemory, FadingMemory, PolynomialFilter, PolynomialState};
use std::collections::VecDeque;
use std::fs::File;
use std::io::{self, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

/// Data rows buffered before output starts: up to 100 time steps for the `τ` median.
pub const LOOKAHEAD: usize = 101;

/// Which filter the command runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Kind {
    /// Expanding memory: least squares over all samples so far.
    Expanding,
    /// Fading memory: samples discounted by θ per τ of age.
    Fading,
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
    /// θ (fading memory only), in `(0, 1)`.
    pub theta: Option<f64>,
    /// τ; `None` = the median step of the first rows.
    pub tau: Option<f64>,
    /// Engine.
    pub engine: EngineArg,
    /// Lead `H`: each row's estimate is valid at `t + H`.
    pub lead: f64,
    /// Name of the time column.
    pub time_col: String,
    /// Name of the value column.
    pub value_col: String,
    /// Noise σ for the `s0..sM` columns.
    pub sigma: Option<f64>,
}

/// One validated data row.
#[derive(Clone, Debug)]
pub struct Sample {
    /// 1-based file line (header = line 1).
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
    /// Bytes read but not yet attributed to a record; `pending[0]` is at offset `base`.
    pending: VecDeque<u8>,
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
            pending: VecDeque::new(),
            base: 0,
            breaks: 0,
            after_cr: false,
        }
    }

    /// The 1-based line of the record the parser reports at byte offset `byte`: the parser's
    /// offset may sit before blank lines or a line terminator it skipped, so those are skipped
    /// here too. Offsets must not decrease between calls.
    pub fn line_at(&mut self, byte: u64) -> u64 {
        let mut k = (byte.saturating_sub(self.base) as usize).min(self.pending.len());
        while k < self.pending.len() && matches!(self.pending[k], b'\r' | b'\n') {
            k += 1;
        }
        for b in self.pending.drain(..k) {
            match b {
                b'\r' => self.breaks += 1,
                b'\n' if !self.after_cr => self.breaks += 1,
                _ => {}
            }
            self.after_cr = b == b'\r';
        }
        self.base += k as u64;
        self.breaks + 1
    }
}

impl<R: Read> Read for LineTracker<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.pending.extend(&buf[..n]);
        Ok(n)
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
    pub fn new(input: R, time_col: &str, value_col: &str, degree: usize) -> Result<Self, CliError> {
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
        if headers.is_empty() || (headers.len() == 1 && headers[0].is_empty()) {
            return Err(CliError::Data(format!(
                "too few samples: the input is empty (no header, no data rows); degree {degree} \
                 needs at least {} data rows",
                degree + 1
            )));
        }
        let find = |name: &str| {
            headers.iter().position(|h| h == name).ok_or_else(|| {
                CliError::Data(format!(
                    "column '{name}' not found in the header; columns are: {}",
                    headers.iter().collect::<Vec<_>>().join(", ")
                ))
            })
        };
        this.time_idx = find(time_col)?;
        this.value_idx = find(value_col)?;
        Ok(this)
    }

    fn csv_error(&mut self, e: csv::Error) -> CliError {
        let line = e
            .position()
            .map(|p| self.reader.get_mut().line_at(p.byte()));
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

fn parse_cell(text: &str, line: u64, column: &str, what: &str) -> Result<f64, CliError> {
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
    let mut steps: Vec<f64> = samples.windows(2).map(|w| w[1].t - w[0].t).collect();
    if steps.is_empty() {
        return 1.0;
    }
    steps.sort_by(f64::total_cmp);
    let k = steps.len();
    if k % 2 == 1 {
        steps[k / 2]
    } else {
        0.5 * steps[k / 2 - 1] + 0.5 * steps[k / 2]
    }
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
    };
    Ok(filter)
}

/// Writes the filter's output CSV: header `t,y,d0..dM[,s0..sM]`, one row per sample.
pub struct OutputWriter<W: Write> {
    writer: csv::Writer<W>,
    name: String,
    degree: usize,
    sigma: bool,
}

impl<W: Write> OutputWriter<W> {
    /// Writes the header to `sink`, named `name` in error messages.
    pub fn new(sink: W, name: &str, degree: usize, sigma: bool) -> Result<Self, CliError> {
        let mut writer = csv::WriterBuilder::new().from_writer(sink);
        let mut header = vec!["t".to_string(), "y".to_string()];
        header.extend((0..=degree).map(|k| format!("d{k}")));
        if sigma {
            header.extend((0..=degree).map(|k| format!("s{k}")));
        }
        writer
            .write_record(&header)
            .map_err(|e| CliError::write_csv(name, e))?;
        Ok(Self {
            writer,
            name: name.to_string(),
            degree,
            sigma,
        })
    }

    /// Writes one row: the echoed `t` and `y` cells and the estimate (empty cells without one).
    pub fn row(
        &mut self,
        t_text: &str,
        y_text: &str,
        estimate: Option<&PolynomialState>,
    ) -> Result<(), CliError> {
        let width = self.degree + 1;
        let mut cells: Vec<String> = Vec::with_capacity(2 + 2 * width);
        cells.push(t_text.to_string());
        cells.push(y_text.to_string());
        match estimate {
            Some(s) => cells.extend(s.derivatives.iter().map(|&d| fmt_f64(d))),
            None => cells.extend((0..width).map(|_| String::new())),
        }
        if self.sigma {
            match estimate.and_then(PolynomialState::std_devs) {
                Some(sd) => cells.extend(sd.iter().map(|&d| fmt_f64(d))),
                None => cells.extend((0..width).map(|_| String::new())),
            }
        }
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

fn open_input(path: Option<&Path>) -> Result<Box<dyn Read>, CliError> {
    match path {
        Some(p) if p.as_os_str() != "-" => {
            let file = File::open(p).map_err(|e| {
                CliError::Data(format!("cannot open input file '{}': {e}", p.display()))
            })?;
            // The CSV reader buffers; no BufReader needed.
            Ok(Box::new(file))
        }
        _ => Ok(Box::new(io::stdin().lock())),
    }
}

/// Runs `seqsmooth filter`.
pub fn run(cfg: &FilterConfig) -> Result<(), CliError> {
    if let (Some(i), Some(o)) = (&cfg.input, &cfg.output) {
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
    let input = open_input(cfg.input.as_deref())?;
    let mut reader = SampleReader::new(input, &cfg.time_col, &cfg.value_col, cfg.degree)?;

    let mut head = Vec::with_capacity(LOOKAHEAD);
    while head.len() < LOOKAHEAD {
        match reader.next_sample()? {
            Some(s) => head.push(s),
            None => break,
        }
    }
    let needed = cfg.degree + 1;
    if head.len() < needed {
        return Err(CliError::Data(format!(
            "too few samples: the input has {} data row{}, degree {} needs at least {needed}",
            head.len(),
            if head.len() == 1 { "" } else { "s" },
            cfg.degree
        )));
    }
    let tau = match (cfg.kind, cfg.tau) {
        (_, Some(tau)) => tau,
        (Kind::Fading, None) => {
            let tau = median_step(&head);
            if !(tau.is_finite() && tau > 0.0) {
                return Err(CliError::Data(format!(
                    "the median time step of the first rows, {}, is not a usable tau; give --tau",
                    fmt_f64(tau)
                )));
            }
            tau
        }
        (Kind::Expanding, None) => 1.0,
    };
    let mut filter = build_filter(cfg.kind, cfg.degree, cfg.theta, tau, cfg.engine, cfg.sigma)
        .map_err(|e| CliError::Usage(e.to_string()))?;

    let (sink, name) = open_output(cfg.output.as_deref())?;
    let mut out = OutputWriter::new(sink, &name, cfg.degree, cfg.sigma.is_some())?;
    let mut step = |s: &Sample| -> Result<(), CliError> {
        filter
            .update(s.t, s.y)
            .map_err(|e| CliError::Data(format!("line {}: {e}", s.line)))?;
        let estimate = filter.estimate_at(s.t + cfg.lead);
        out.row(&s.t_text, &s.y_text, estimate.as_ref())
    };
    for s in &head {
        step(s)?;
    }
    drop(head);
    while let Some(s) = reader.next_sample()? {
        step(&s)?;
    }
    out.finish()
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
        let mut r = SampleReader::new(text.as_bytes(), "t", "y", 1).unwrap();
        assert_eq!(r.next_sample().unwrap().unwrap().line, 2);
        assert_eq!(r.next_sample().unwrap().unwrap().line, 3);
        let e = r.next_sample().unwrap_err().to_string();
        assert_eq!(e, "line 5, column 'y': 'abc' is not a number");
    }

    fn lines(text: &str) -> Vec<u64> {
        let mut r = SampleReader::new(text.as_bytes(), "t", "y", 0).unwrap();
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
