//! The arguments of `seqsmooth smooth`.

use super::{parse_degree, parse_sigma, parse_window, Columns};
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct SmoothArgs {
    /// Input CSV with a header row; omitted or '-' reads standard input. Columns other than the
    /// time and value columns are ignored. Times are numbers or ISO-8601 (2024-03-01T12:00:00Z,
    /// fractional seconds, an offset, a date alone; UTC without an offset), read as seconds
    /// since the Unix epoch
    #[arg(value_name = "INPUT")]
    pub input: Option<PathBuf>,
    /// Polynomial degree M (0 to 24)
    #[arg(long, value_name = "M", value_parser = parse_degree, allow_hyphen_values = true)]
    pub degree: usize,
    /// The number of samples in each window, M+1 <= W <= the number of rows (savgol's
    /// window_length, Morrison's L+1); odd W centres every window on its row
    #[arg(long, value_name = "W", value_parser = parse_window, allow_hyphen_values = true)]
    pub window: usize,
    #[command(flatten)]
    pub columns: Columns,
    /// White-noise standard deviation S of the values, for the 1-sigma columns s0..sM
    /// [default: estimated from each window's residuals]
    #[arg(long, value_name = "S", value_parser = parse_sigma, allow_hyphen_values = true)]
    pub sigma: Option<f64>,
    /// Output file [default: standard output]
    #[arg(short = 'o', long, value_name = "OUTPUT")]
    pub output: Option<PathBuf>,
}
