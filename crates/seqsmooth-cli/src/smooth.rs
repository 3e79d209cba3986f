//! `seqsmooth smooth`: whole-series (non-causal) smoothing and differentiation with centred
//! fixed-memory windows, the counterpart of `scipy.signal.savgol_filter(mode="interp")`.
//!
//! Unlike `seqsmooth filter` this reads the whole input before writing anything: a row's
//! window reaches `⌊W/2⌋` rows ahead of it (and the last rows share the last full window).
//! The rows are validated as the filter validates them (line, column and value in messages).

use crate::error::CliError;
use crate::filter::{check_distinct, open_input, open_output, Need, OutputWriter, SampleReader};
use seqsmooth::polynomial::fixed::smooth;
use seqsmooth::PolynomialState;
use std::path::PathBuf;

/// What `seqsmooth smooth` does, after argument checking.
#[derive(Clone, Debug)]
pub struct SmoothConfig {
    /// Input file; `None` = standard input.
    pub input: Option<PathBuf>,
    /// Output file; `None` = standard output.
    pub output: Option<PathBuf>,
    /// Degree `m`.
    pub degree: usize,
    /// Window `W` in samples, at least `m + 1`.
    pub window: usize,
    /// Name of the time column.
    pub time_col: String,
    /// Name of the value column.
    pub value_col: String,
}

/// Runs `seqsmooth smooth`: header `t,y,d0..dM`, one row per input row in input order.
pub fn run(cfg: &SmoothConfig) -> Result<(), CliError> {
    check_distinct(cfg.input.as_deref(), cfg.output.as_deref())?;
    let need = Need::window(cfg.window.max(cfg.degree + 1));
    let input = open_input(cfg.input.as_deref())?;
    let mut reader = SampleReader::new(input, &cfg.time_col, &cfg.value_col, &need)?;
    let mut samples = Vec::new();
    while let Some(s) = reader.next_sample()? {
        samples.push(s);
    }
    need.check(samples.len())?;
    let times: Vec<f64> = samples.iter().map(|s| s.t).collect();
    let values: Vec<f64> = samples.iter().map(|s| s.y).collect();
    // The arguments and the rows are checked already (degree, window, finite and increasing
    // values, enough of them): an error left here is about the data as a whole.
    let rows = smooth(&times, &values, cfg.degree, cfg.window)
        .map_err(|e| CliError::Data(format!("cannot smooth the input: {e}")))?;

    let (sink, name) = open_output(cfg.output.as_deref())?;
    let mut out = OutputWriter::new(sink, &name, cfg.degree, false)?;
    for (s, derivatives) in samples.iter().zip(rows) {
        let state = PolynomialState::new(s.t, derivatives);
        out.row(&s.t_text, &s.y_text, Some(&state))?;
    }
    out.finish()
}
