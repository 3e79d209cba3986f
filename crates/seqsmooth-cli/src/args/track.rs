//! The arguments of `seqsmooth track`.

use super::{parse_f64, parse_window, RadarArgs};
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct TrackArgs {
    /// Input CSV with a header row; omitted or '-' reads standard input
    #[arg(value_name = "INPUT")]
    pub input: Option<PathBuf>,
    /// The tracking method
    #[arg(long, value_enum, default_value_t = TrackMethod::Kalman)]
    pub method: TrackMethod,
    /// kalman, smooth: spectral density of the white-noise acceleration on each axis
    /// [default: adaptive, from the innovations]
    #[arg(long = "q", value_name = "ACCEL_PSD", value_parser = parse_psd, allow_hyphen_values = true)]
    pub q: Option<f64>,
    /// fading: the discount per unit of time, 0 < B <= 1 [default: an adaptive discount per
    /// update, from the innovations]
    #[arg(long, value_name = "B", value_parser = parse_discount, allow_hyphen_values = true,
          conflicts_with = "theta")]
    pub beta: Option<f64>,
    /// fading: the discount per update, 0 < T <= 1
    #[arg(long, value_name = "T", value_parser = parse_discount, allow_hyphen_values = true)]
    pub theta: Option<f64>,
    /// window: the number of rows in each window [default: 8]
    #[arg(long, value_name = "W", value_parser = parse_window, allow_hyphen_values = true)]
    pub window: Option<usize>,
    /// Gauss-Newton iterations allowed per fit (the window method's fits, the Kalman
    /// methods' start)
    #[arg(long, value_name = "N", default_value_t = 20,
          value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub max_iterations: u32,
    /// smooth: the lag in rows: each row's estimate from the N rows after it, written N rows
    /// later; the smoother holds N+1 rows (0 is the kalman filter) [default: 200]
    #[arg(long, value_name = "N")]
    pub lag: Option<usize>,
    /// Name of the time column
    #[arg(long, value_name = "NAME", default_value = "t")]
    pub time_col: String,
    #[command(flatten)]
    pub radar: RadarArgs,
    /// Output file [default: standard output]
    #[arg(short = 'o', long, value_name = "OUTPUT")]
    pub output: Option<PathBuf>,
}

/// The methods of `seqsmooth track`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TrackMethod {
    /// Gauss-Newton over each row's last W rows.
    Window,
    /// The extended Kalman filter with white-noise acceleration (--q).
    Kalman,
    /// The fading-memory Kalman filter (--beta or --theta).
    Fading,
    /// The Rauch-Tung-Striebel smoother over the Kalman filter.
    Smooth,
}

/// Parses `--q`: a non-negative finite number.
pub fn parse_psd(s: &str) -> Result<f64, String> {
    parse_f64(
        "q",
        s,
        (
            |v| v.is_finite() && v >= 0.0,
            "a non-negative finite number",
        ),
    )
}

/// Parses `--beta` and `--theta` of `track`: `0 < v <= 1`.
pub fn parse_discount(s: &str) -> Result<f64, String> {
    parse_f64(
        "discount",
        s,
        (|v| v > 0.0 && v <= 1.0, "a number with 0 < value <= 1"),
    )
}
