//! The arguments of `seqsmooth fit`.

use super::{parse_degree, parse_max_iterations, parse_sigma, parse_window, refused, RadarArgs};
use clap::Args;
use seqsmooth::estimate::gauss_newton::{Epoch, GaussNewton};
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct FitArgs {
    /// Input CSV with a header row; omitted or '-' reads standard input. Columns other than the
    /// ones named are ignored
    #[arg(value_name = "INPUT")]
    pub input: Option<PathBuf>,
    /// The dynamic and observation model
    #[arg(long, value_enum)]
    pub model: FitModel,
    /// Degree of the motion: polynomial, the polynomial's degree M (0 to 24, required); radar,
    /// 1 for constant velocity or 2 for constant acceleration [radar default: 1]
    #[arg(long, value_name = "M", value_parser = parse_degree, allow_hyphen_values = true)]
    pub degree: Option<usize>,
    /// The number of rows in each window, W >= 1 (all rows so far while fewer have come)
    /// [default: radar 8, polynomial 60]
    #[arg(long, value_name = "W", value_parser = parse_window, allow_hyphen_values = true)]
    pub window: Option<usize>,
    /// The time each row's state refers to: 'end' (the row's own time), 'centre' (the mean
    /// time of its window) or a time T
    #[arg(long, value_name = "EPOCH", default_value = "end", value_parser = parse_epoch,
          allow_hyphen_values = true)]
    pub epoch: Epoch,
    /// Polynomial: the values' noise standard deviation (required)
    #[arg(long, value_name = "S", value_parser = parse_sigma, allow_hyphen_values = true)]
    pub sigma: Option<f64>,
    /// Name of the time column
    #[arg(long, value_name = "NAME", default_value = "t")]
    pub time_col: String,
    /// Polynomial: name of the value column
    #[arg(long, value_name = "NAME", default_value = "y")]
    pub value_col: String,
    #[command(flatten)]
    pub radar: RadarArgs,
    /// Gauss-Newton iterations allowed per window
    #[arg(long, value_name = "N", default_value_t = GaussNewton::default().max_iterations,
          value_parser = parse_max_iterations, allow_hyphen_values = true)]
    pub max_iterations: usize,
    /// Output file [default: standard output]
    #[arg(short = 'o', long, value_name = "OUTPUT")]
    pub output: Option<PathBuf>,
}

/// The models of `seqsmooth fit`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum FitModel {
    /// A Cartesian target seen by a radar: range, azimuth, elevation.
    Radar,
    /// A scalar polynomial in time, observed directly.
    Polynomial,
}

/// Parses `--epoch`: a name of the library's ([`Epoch::from_name`]: `end`, `centre`, `center`),
/// or a time in its range ([`Epoch::check`]).
pub fn parse_epoch(s: &str) -> Result<Epoch, String> {
    let text = s.trim();
    let epoch = match Epoch::from_name(text) {
        Some(epoch) => epoch,
        None => Epoch::At(
            text.parse::<f64>()
                .map_err(|_| format!("epoch '{text}' is neither 'end', 'centre' nor a time"))?,
        ),
    };
    epoch.check().map_err(refused)?;
    Ok(epoch)
}
