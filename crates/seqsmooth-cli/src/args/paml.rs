//! The arguments of `seqsmooth paml`.

use super::{parse_f64, parse_sigma, parse_whole, Columns, POSITIVE};
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct PamlArgs {
    /// Input CSV with a header row; omitted or '-' reads standard input. Times strictly
    /// increasing; read segment by segment
    #[arg(value_name = "INPUT")]
    pub input: Option<PathBuf>,
    /// Polynomial degree N of each segment (0 to 30): N+1 polynomial samples per segment
    #[arg(long, value_name = "N", value_parser = parse_order, allow_hyphen_values = true)]
    pub order: usize,
    /// Segment length in the time column's units
    #[arg(long, value_name = "SECONDS", value_parser = parse_segment, allow_hyphen_values = true)]
    pub segment: f64,
    /// The values' noise standard deviation, the same for every sample
    #[arg(long, value_name = "S", value_parser = parse_sigma, allow_hyphen_values = true,
          conflicts_with = "sigma_col")]
    pub sigma: Option<f64>,
    /// The column holding each sample's noise standard deviation
    #[arg(long, value_name = "NAME")]
    pub sigma_col: Option<String>,
    #[command(flatten)]
    pub columns: Columns,
    /// Output file [default: standard output]
    #[arg(short = 'o', long, value_name = "OUTPUT")]
    pub output: Option<PathBuf>,
}

/// Parses `--order`: a whole number from 0 to 30.
pub fn parse_order(s: &str) -> Result<usize, String> {
    parse_whole("order", s, "", 0, 30).map(|v| v as usize)
}

/// Parses `--segment`: a positive finite number.
pub fn parse_segment(s: &str) -> Result<f64, String> {
    parse_f64("segment", s, POSITIVE)
}
