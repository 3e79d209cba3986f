//! The arguments of `seqsmooth paml`.

use super::{parse_checked, parse_count, parse_sigma, Columns};
use clap::Args;
use seqsmooth::paml::{check_degree, check_segment_length, MAX_DEGREE};
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct PamlArgs {
    /// Input CSV with a header row; omitted or '-' reads standard input. Times strictly
    /// increasing; read segment by segment
    #[arg(value_name = "INPUT")]
    pub input: Option<PathBuf>,
    /// Polynomial degree N of each segment (0 to 30): N+1 polynomial samples per segment
    /// (--order, the paper's word, is an alias)
    #[arg(long, alias = "order", value_name = "N", value_parser = parse_paml_degree,
          allow_hyphen_values = true)]
    pub degree: usize,
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

/// Parses `paml --degree`: a whole number in the library's range of a segment's degree
/// ([`check_degree`]).
pub fn parse_paml_degree(s: &str) -> Result<usize, String> {
    let range = format!("from 0 to {MAX_DEGREE}");
    parse_count("degree", s, "", Some(range), check_degree)
}

/// Parses `--segment`: a number in the library's range of a segment's length
/// ([`check_segment_length`]).
pub fn parse_segment(s: &str) -> Result<f64, String> {
    parse_checked("segment", s, check_segment_length)
}
