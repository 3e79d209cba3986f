//! The arguments of `seqsmooth track`.

use super::{parse_checked, parse_f64, parse_max_iterations, parse_window, refused, RadarArgs};
use clap::Args;
use seqsmooth::estimate::gauss_newton::GaussNewton;
use seqsmooth::kalman::noise::check_psd;
use seqsmooth::track::MotionModel;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct TrackArgs {
    /// Input CSV with a header row; omitted or '-' reads standard input
    #[arg(value_name = "INPUT")]
    pub input: Option<PathBuf>,
    /// The tracking method
    #[arg(long, value_enum, default_value_t = TrackMethod::Kalman)]
    pub method: TrackMethod,
    /// The motion model of the kalman, smooth and fading methods: constant-velocity,
    /// constant-acceleration, singer or coordinated-turn (the window method fits
    /// constant-velocity only)
    #[arg(long, value_name = "NAME", default_value = "constant-velocity", value_parser = parse_model)]
    pub model: MotionModel,
    /// --model singer: the manoeuvre rate alpha > 0, the reciprocal of the manoeuvre time
    /// constant, per time unit [default: 0.1]
    #[arg(long, value_name = "ALPHA", value_parser = parse_number, allow_hyphen_values = true)]
    pub manoeuvre_alpha: Option<f64>,
    /// --model singer: the manoeuvre variance (acceleration squared), the Singer model's
    /// driving noise [default: adaptive, from the innovations]
    #[arg(long, value_name = "VAR", value_parser = parse_number, allow_hyphen_values = true)]
    pub manoeuvre_variance: Option<f64>,
    /// --model coordinated-turn: the spectral density of the turn rate's random walk
    /// (rad^2 per time unit^3) [default: 1e-4]
    #[arg(long, value_name = "Q_OMEGA", value_parser = parse_number, allow_hyphen_values = true)]
    pub turn_rate_noise: Option<f64>,
    /// kalman, smooth: spectral density of the white-noise acceleration on each axis (of the
    /// jerk with --model constant-acceleration) [default: adaptive, from the innovations]
    #[arg(long = "q", value_name = "ACCEL_PSD", value_parser = parse_psd, allow_hyphen_values = true)]
    pub q: Option<f64>,
    /// fading: the discount per span --tau of time, 0 < T < 1 (with --tau) [default: an
    /// adaptive discount per update, from the innovations]
    #[arg(long, value_name = "T", value_parser = parse_number, allow_hyphen_values = true,
          requires = "tau", conflicts_with = "theta_per_update")]
    pub theta: Option<f64>,
    /// fading: the span of time --theta applies to, TAU > 0 in the times' units
    #[arg(long, value_name = "TAU", value_parser = parse_number, allow_hyphen_values = true,
          requires = "theta")]
    pub tau: Option<f64>,
    /// fading: the discount per update whatever the spacing, 0 < T < 1
    #[arg(long, value_name = "T", value_parser = parse_number, allow_hyphen_values = true)]
    pub theta_per_update: Option<f64>,
    /// Refused: '--beta B' (per unit of time) is now '--theta B --tau 1'
    #[arg(long, value_name = "B", hide = true, value_parser = refuse_beta)]
    pub beta: Option<f64>,
    /// window: the number of rows in each window [default: 8]
    #[arg(long, value_name = "W", value_parser = parse_window, allow_hyphen_values = true)]
    pub window: Option<usize>,
    /// Gauss-Newton iterations allowed per fit (the window method's fits, the Kalman
    /// methods' start)
    #[arg(long, value_name = "N", default_value_t = GaussNewton::default().max_iterations,
          value_parser = parse_max_iterations, allow_hyphen_values = true)]
    pub max_iterations: usize,
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
    /// The fading-memory Kalman filter (--theta with --tau, or --theta-per-update).
    Fading,
    /// The Rauch-Tung-Striebel smoother over the Kalman filter.
    Smooth,
}

/// Parses `--model`: a name of the library's ([`MotionModel::named`]).
pub fn parse_model(s: &str) -> Result<MotionModel, String> {
    MotionModel::named(s.trim()).map_err(refused)
}

/// Parses `--q`: a number in the library's range of a spectral density ([`check_psd`]).
pub fn parse_psd(s: &str) -> Result<f64, String> {
    parse_checked("q", s, check_psd)
}

/// Parses a number the library checks (`track`'s `--theta`, `--tau`, `--theta-per-update`).
pub fn parse_number(s: &str) -> Result<f64, String> {
    parse_f64("number", s)
}

/// `track --beta`, refused with its new spelling.
pub fn refuse_beta(s: &str) -> Result<f64, String> {
    Err(format!(
        "--beta is gone: a discount of {s} per unit of time is now '--theta {s} --tau 1' \
         (and '--theta T' alone meant per update: now '--theta-per-update T')"
    ))
}
