//! The arguments of `seqsmooth filter`.

use super::{
    parse_degree, parse_lead, parse_sigma, parse_tau, parse_theta, parse_window, Columns,
    EngineArg, Kind, Theta, CHUNK_ROWS,
};
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct FilterArgs {
    /// Input CSV with a header row, or a Parquet file if the name ends in .parquet (any case):
    /// numbers of any integer, float or decimal type, the time also a timestamp or date (as
    /// seconds since the Unix epoch), the id text or integers; omitted or '-' reads CSV from
    /// standard input. Columns other than the time, value and id columns are ignored
    #[arg(value_name = "INPUT")]
    pub input: Option<PathBuf>,
    /// Filter kind
    #[arg(long, value_enum)]
    pub kind: Kind,
    /// Polynomial degree M (0 to 24; with --engine gain 0 to 10)
    #[arg(long, value_name = "M", value_parser = parse_degree, allow_hyphen_values = true)]
    pub degree: usize,
    /// Fading memory and auto: discount per tau, 0 < T < 1 (e.g. 0.9 or 9/10)
    #[arg(long, value_name = "T", value_parser = parse_theta, allow_hyphen_values = true)]
    pub theta: Option<Theta>,
    /// Fading memory and auto: the time interval theta applies to [default: the median time
    /// step of the first 101 rows, so theta is the discount per typical sample; 1 for a single
    /// row]
    #[arg(long, value_name = "TAU", value_parser = parse_tau, allow_hyphen_values = true)]
    pub tau: Option<f64>,
    /// Fixed memory: the number of samples in the window, W >= M+1 (Morrison's L+1, savgol's
    /// window_length)
    #[arg(long, value_name = "W", value_parser = parse_window, allow_hyphen_values = true)]
    pub window: Option<usize>,
    /// Engine of the expanding, fading and auto filters: 'exact' is least squares on any
    /// timestamps; 'gain' is Morrison's fixed-gain recursion, exact on evenly spaced times and
    /// approximate on irregular ones. The fixed-memory filter is always the exact fit of its
    /// window [default: exact]
    #[arg(long, value_enum)]
    pub engine: Option<EngineArg>,
    /// Lead H in time units: each row's estimate is valid at t+H (negative = retrodiction)
    #[arg(long, value_name = "H", default_value = "0", value_parser = parse_lead,
          allow_hyphen_values = true)]
    pub lead: f64,
    #[command(flatten)]
    pub columns: Columns,
    /// White-noise standard deviation S of the values: adds the columns s0..sM, the 1-sigma
    /// errors of d0..dM from the filter's covariance. With --kind auto (which always writes
    /// s0..sM) the noise is taken to be S instead of estimated
    #[arg(long, value_name = "S", value_parser = parse_sigma, allow_hyphen_values = true)]
    pub sigma: Option<f64>,
    /// The automatic filter's final outlier decision on each sample waits for N accepted
    /// samples after it (0 to 31; 0: the gate's decision at the time, final once a later sample
    /// is taken) [default: degree + 4]
    #[arg(long, value_name = "N")]
    pub review_window: Option<usize>,
    /// Output file: CSV, or Parquet if the name ends in .parquet (any case; the CSV output's
    /// columns, numbers as Float64 with null for an empty cell, the time in seconds, the id
    /// column text or integers as in the input) [default: CSV on standard output]
    #[arg(short = 'o', long, value_name = "OUTPUT")]
    pub output: Option<PathBuf>,
    /// Name of a column naming the series: the rows of each id (any text) are a series of
    /// their own, filtered on its own with the same settings, and the column is written first
    #[arg(long, value_name = "NAME")]
    pub id_col: Option<String>,
    /// Never show the progress display (shown on standard error only when it is a terminal
    /// and the input is larger than one chunk of rows)
    #[arg(long)]
    pub no_progress: bool,
    /// Resume from FILE and save to it: the filters' state (each series' filter, the options,
    /// the automatic filter's rows still waiting for their outlier decision) is read from FILE
    /// if it exists and written to it at the end (atomically: a new file renamed over the old),
    /// so that a stream cut into files, each run with the same --state FILE, gives the rows of
    /// the unbroken run. A state made with other options is refused, naming the option; a
    /// damaged one is refused; a run that fails leaves FILE as it was. Each saved filter keeps
    /// what it was saved with: an automatic filter saved before 2026-12-07 keeps its memories
    /// θ², θ⁴, θ⁸, while a series first seen after the resume gets today's θ⁴
    #[arg(long, value_name = "FILE")]
    pub state: Option<PathBuf>,
    /// With --state: this input ends the stream, so the automatic filter decides its rows still
    /// waiting for their outlier decision and writes them (without it they wait in FILE for the
    /// next input, as in an unbroken run)
    #[arg(long = "final", requires = "state")]
    pub end: bool,
    /// Rows read, filtered and written at a time (testing aid)
    #[arg(long, value_name = "N", hide = true, default_value_t = CHUNK_ROWS,
          value_parser = clap::value_parser!(u32).range(1..))]
    pub chunk_rows: u32,
}
