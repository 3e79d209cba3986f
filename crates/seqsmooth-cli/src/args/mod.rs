//! The command line: the subcommands' arguments (clap), their help texts, the parsers of the
//! numeric arguments and the checks that tie arguments together. Imports no subcommand.
//!
//! Here: [`Cli`] and [`Command`] (with each subcommand's help text), the arguments that several
//! subcommands share ([`Columns`], [`MemoryArgs`], [`Kind`], …) and the shared parsers; each
//! subcommand's own arguments and parsers in a file of its own (`args/<subcommand>.rs`, and
//! `args/radar.rs`, the radar options of `track` and `fit`), re-exported here.
//!
//! The argument parsers return `Err(message)`; clap prints it as
//! `error: invalid value 'V' for '--name <X>': message` and exits with code 2.

use crate::error::{flag, CliError};
use clap::{Args, Parser, Subcommand};
use seqsmooth::estimate::gauss_newton::check_max_iterations;
use seqsmooth::estimate::sliding::check_window_length;
use seqsmooth::polynomial::{check_degree, check_derivative, check_lead, check_tau, MAX_DEGREE};
use seqsmooth::scalar::{parse_rational, Rational, MAX_DECIMAL_EXPONENT};
use seqsmooth::Engine;

mod demo;
mod filter;
mod fit;
mod gains;
mod paml;
mod plot;
mod radar;
mod smooth;
mod track;
mod vrf;

pub use demo::DemoArgs;
pub use filter::FilterArgs;
pub use fit::{parse_epoch, FitArgs, FitModel};
pub use gains::GainsArgs;
pub use paml::{parse_paml_degree, parse_segment, PamlArgs};
pub use plot::PlotArgs;
pub use radar::{azimuth_parser, parse_site, RadarArgs};
pub use smooth::SmoothArgs;
pub use track::{parse_number, parse_psd, refuse_beta, TrackArgs, TrackMethod};
pub use vrf::{parse_lead_steps, FormArg, LeadSteps, VrfArgs, VrfKind};

/// Rows per chunk of `seqsmooth filter`'s streaming pipeline (read, filter, write).
pub const CHUNK_ROWS: u32 = 1 << 16;

/// The exit-status paragraph of the help texts; `$few` names the too-short-input case.
macro_rules! exit_status {
    ($few:literal) => {
        concat!(
            "Exit status: 0 on success; 1 when the input data or a file is unusable (bad numbers, \
             NaN or infinite values, unsorted or duplicate times, missing columns, malformed CSV, ",
            $few,
            ", unreadable or unwritable files); 2 for command-line errors (unknown or missing \
             arguments, values out of range). Every message goes to stderr and starts with \
             'error: '; data errors name the 1-based file line (the header is line 1), the column \
             and the value.\n\nNumbers are written with round-trip precision: the shortest text \
             that parses back to the same double (plain decimals for 1e-5 <= |x| < 1e16, \
             otherwise scientific notation such as 1e-300)."
        )
    };
}

/// Text shown after every `--help`: exit codes and number formats.
const AFTER_HELP: &str = concat!(
    exit_status!("too few samples"),
    " Exact (--exact) values are rationals in lowest terms, 'p/q', or 'p' when the value is an integer."
);

#[derive(Debug, Parser)]
#[command(
    name = "seqsmooth",
    version,
    about = "Polynomial smoothing and prediction filters (Morrison 1969; Reyneke et al. 2012)",
    after_help = AFTER_HELP
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Smooth, differentiate and predict a CSV time series, row by row, with an expanding-,
    /// fading- or fixed-memory or the automatic polynomial filter
    #[command(after_help = FILTER_AFTER_HELP)]
    Filter(FilterArgs),
    /// Smooth and differentiate a CSV time series with centred fixed-memory windows
    /// (Savitzky-Golay, non-causal), with the 1-sigma of each value; streams
    #[command(after_help = SMOOTH_AFTER_HELP)]
    Smooth(SmoothArgs),
    /// Print Morrison's scaled current-estimate gains h_0..h_m (header k,gain)
    #[command(after_help = AFTER_HELP)]
    Gains(GainsArgs),
    /// Print the scaled variance-reduction matrix (header i,j,value, row-major)
    #[command(after_help = AFTER_HELP)]
    Vrf(VrfArgs),
    /// Run the automatic filter on a built-in manoeuvring-target track, print a short summary
    /// and write a plot (PNG and SVG)
    #[command(after_help = AFTER_HELP)]
    Demo(DemoArgs),
    /// Plot the output of 'seqsmooth filter' (any kind) as PNG or SVG
    #[command(after_help = PLOT_AFTER_HELP)]
    Plot(PlotArgs),
    /// Fit a state to each row's window of measurements by Gauss-Newton differential
    /// correction: a radar's range, azimuth and elevation, or a scalar polynomial series
    #[command(after_help = FIT_AFTER_HELP)]
    Fit(FitArgs),
    /// Track a target from a radar's range, azimuth and elevation: sliding Gauss-Newton window,
    /// Kalman filter, fading-memory Kalman filter, or Kalman smoother
    #[command(after_help = TRACK_AFTER_HELP)]
    Track(TrackArgs),
    /// Compress a series into polynomial samples (Villien & Ostertag 2009): per segment of
    /// SECONDS, its weighted least-squares polynomial of degree N at the N+1 Gauss nodes of
    /// its own samples, uncorrelated, with their variances
    #[command(after_help = PAML_AFTER_HELP)]
    Paml(PamlArgs),
}

const PAML_AFTER_HELP: &str = "\
Output: CSV with the header
  segment,t,value,variance
N+1 rows per segment: segment k covers [t0 + k*SECONDS, t0 + (k+1)*SECONDS), t0 the first \
sample's time; t a Gauss node of the segment's samples weighted by 1/sigma^2, value the \
segment's weighted least-squares polynomial there and variance its variance (in the units of \
sigma^2; the N+1 values are uncorrelated). A segment with fewer than N+1 samples is named on \
standard error by its time span and left out. Without --sigma or --sigma-col every sample's \
sigma is 1 (the variances are then per unit noise variance).";

const TRACK_AFTER_HELP: &str = concat!(
    "\
Output: CSV, one row per input row in input order, with the header
  t,x,y,z,vx,vy,vz,sx,sy,sz,svx,svy,svz,nis,flag
t echoes the input cell; x..vz is the position and velocity of --model's state at t (in the \
units of the range and of t; with --azimuth bearing x is east, y north, z up), s.. their \
1-sigma errors, and nis \
the normalised innovation squared of the row's update (chi-squared with as many degrees of \
freedom as components present when the model holds; Morrison 14.8). Rows before the state is \
determinable leave their cells empty.

flag says where the sigmas may not cover the error: empty when the tests pass; 'outlier' when \
the row's NIS is beyond the gate (the 99.9% point of chi-squared) after a row within it: the \
measurement is left out (the row's estimate is the prediction; window: the fit of the window \
without it); 'misfit' when the model does \
not follow the target (a manoeuvre): the NIS summed over the last 5 updates is beyond its 99% \
point (kalman, fading, smooth), or the window's residual chi-squared is beyond the 99% point \
for its degrees of freedom (window). Keep the unflagged rows for estimates whose 3-sigma \
covers the truth (ACCURACY.md, 'The tracker's coverage').

--method window: the Gauss-Newton fit of each row's last W rows (--window, default 8; all rows \
so far while fewer), as 'seqsmooth fit --model radar'; nis is the row's innovation against the \
previous window's estimate. The model is straight-line motion across the window; the \
covariance is scaled by max(1, chi2/dof) so that it carries the window's misfit. A window that \
does not converge stops the command: allow more iterations (--max-iterations, default 20) or \
shorten the window.
--method kalman: the extended Kalman filter (Morrison 12.5) with white-noise acceleration of \
spectral density --q (m^2/s^3 for metres and seconds), started from the Gauss-Newton fit of \
the first rows that determine the state (that row's cells are the fit's, its nis empty). \
Without --q the driving noise is adaptive: it starts at sigma_range^2/T^3 (T the start's mean \
step) and is multiplied by 4 at each misfit whose NIS is still high (16 beyond the gate), and \
divided by 4 after 15 quiet updates whose mean NIS is below its expectation.
--method fading: the same start, then the fading-memory Kalman filter (Morrison 14.4) with \
--theta T per --tau TAU of time (a row dt older weighs T^(dt/TAU), as in 'seqsmooth filter') \
or --theta-per-update T; s.. are the true 1-sigma errors. Without either the discount is \
adaptive, per update from 0.9: each misfit doubles 1 - theta, quiet updates halve it again.
--method smooth: the fixed-lag Rauch-Tung-Striebel smoother over the kalman method's run (its \
--q or adaptive driving noise, its gate and flags): each row's estimate from the rows up to \
--lag N rows after it (default 200), written N rows later with the flag the forward filter \
gave it, the last N rows from every row at the end; nis is the forward filter's. It holds N+1 \
rows (at most 2.8 kB each: 0.6 MB at the default); a lag beyond the input's rows is the \
whole-interval smoother, and a lag whose rows would take over 100 MB is said on stderr before \
the first row. The other methods stream: each row's output is written as it is read, in \
memory independent of the input's length.

Angles in radians; --azimuth from-x (default): from +x towards +y; --azimuth bearing: \
clockwise from north with x = east, y = north. Elevation from the x-y plane. An empty range, \
azimuth or elevation cell is a missing component; a row with all three empty is a missing \
measurement (the filters predict across it). Azimuths must lie within [-2pi, 2pi], elevations \
within [-pi/2, pi/2], ranges above 0.

Noise: --sigma-range and --sigma-angle give every row's sigma; --sigma-range-col NAME and \
--sigma-angle-col NAME name columns of per-row sigmas (the angle column serves azimuth and \
elevation), each cell a positive number. A row's empty sigma cell takes the flag; without the \
flag it is refused where the row measures a component that sigma weighs.

",
    exit_status!("too few samples")
);

const FIT_AFTER_HELP: &str = concat!(
    "\
Output: CSV, one row per input row in input order, with the header
  --model radar:       t,x,y,z,vx,vy,vz,sx,sy,sz,svx,svy,svz,iterations,chi2,flag
                       (--degree 2: t,x,y,z,vx,vy,vz,ax,ay,az,sx,...,svz,sax,say,saz,...)
  --model polynomial:  t,y,d0..dM,s0..sM,iterations,chi2
and, with --epoch other than end, a column epoch before flag: the time the state refers to. \
The radar's flag is 'misfit' where the window's chi2 lies beyond the 99% point of chi-squared \
with its degrees of freedom (the model does not follow the window's rows), else empty; its s \
columns carry the misfit, scaled by sqrt(max(1, chi2/dof)) (as 'seqsmooth track --method \
window'). The t \
(and y) cells echo the input cells. Each row's state is the Gauss-Newton differential \
correction (Morrison 8.6-8.7) of the last W rows up to and including it (all rows so far \
while fewer have come): the minimum-variance estimate of the state at the epoch, with its \
1-sigma errors (s columns), the iterations taken and the residual chi-squared of the window \
(with the sigmas given; its degrees of freedom are the measured components less the states). \
Rows before the window determines the state have empty cells.

radar: a Cartesian state, position and velocity (and acceleration with --degree 2) of a \
constant-velocity (constant-acceleration) target, in the units of the range and of t, from \
the range, azimuth and elevation seen from --site: azimuth from +x towards +y, elevation from \
the x-y plane, both in radians. An empty range, azimuth or elevation cell is a missing \
component: the row's other components are used. The first window's iteration starts from \
polynomial fits to the range and angles (Morrison 8.5), each later one from the previous \
state carried forward (from the polynomial fits again if that fails).

polynomial: the value's derivatives d0..dM of a degree-M polynomial in t, each row's state \
the least-squares fit of its window: the same numbers as 'seqsmooth filter --kind fixed \
--window W --sigma S' on the rows where both have an estimate (from row W on).

A window that still does not determine the state once it holds W rows (fewer distinct times \
than a polynomial needs; a radar window with too few angles), an iteration that diverges or \
does not converge, a bad cell or a time not after the previous one stops the command with the \
file lines of the window or the line and column of the cell. An output file (-o FILE) is \
written beside FILE and renamed onto it only when the command succeeds.

",
    exit_status!("too few samples")
);

const PLOT_AFTER_HELP: &str = "\
Reads the CSV written by 'seqsmooth filter' and draws, under a title and a legend: a panel per \
--derivative K with the estimate dK, its +-3 sigma band from sK (when the output has s \
columns) and, for K = 0, the samples (rejected ones as red crosses, from the auto filter's \
outlier column); then a residual panel y - d0 with the estimate's +-3 sigma band about zero \
and the auto filter's +-3 noise sigma (dashed). The spans where the auto filter's misfit flag \
is up are shaded in every panel. Empty cells leave gaps. Axis ranges leave out the start-up \
transients of the estimates (the residual axis, the rows before the highest derivative column \
has a value); residuals beyond the range are drawn as triangles at its edge.

With a lead column (filter --lead H) each estimate is drawn at its own time t+H and, in the \
residual panel, compared with the sample at that time (to a thousandth of the median of the \
first 1,024 steps); \
rows whose t+H is no sample time have no residual, and the subtitle says how many have one.

The rows are read one at a time and decimated as they come, in memory set by the image's \
width, not the input's length (standard input too: one pass). A series with more rows than \
the plot has pixel columns is drawn decimated per pixel column (the first, lowest, highest and \
last point of each column: every extreme kept); its samples, too many for dots, as the band \
from each column's lowest to its highest; many rejected samples as small crosses (at most \
the lowest and highest per column), their number in the legend; the misfit flag by the share \
of each column's time it is up. A step between samples longer than 10 times the median step \
is an outage: hatched, and no line or band is drawn across it. A value beyond an axis (a \
start-up transient, an outlier) is drawn at its edge and marked by a triangle, and the panel \
notes how far the lines go. An axis whose values share many leading digits, or are very \
large or small, is drawn in tick units and its label says how to read them back: 'value = \
tick x 1e9 + 1.7e18'; a time axis counts from its first time, 't = t0 + tick x 1e9, t0 = \
1.7e18 (as Unix ns: 2023-11-14 22:13:20 UTC)', with the date when t0 reads as Unix seconds, \
milliseconds, microseconds or nanoseconds.

With --input (the file given to 'seqsmooth filter') the truth column --truth-col is drawn \
too; the input's times and values must match the output's rows.

Exit status: 0 on success; 1 when the input data or a file is unusable (missing file or \
columns, malformed CSV, non-numeric cells, unwritable image); 2 for command-line errors \
(unknown or missing arguments, values out of range, an output name not ending in .png or \
.svg). Every message goes to stderr and starts with 'error: '; data errors name the file, the \
1-based line (the header is line 1) and the column.";

const FILTER_AFTER_HELP: &str = concat!(
    "\
Output: CSV, one row per input row in input order, with the header
  --kind expanding, fading:  t,y,d0..dM            (and s0..sM with --sigma)
  --kind fixed:              t,y,d0..dM,window     (t,y,d0..dM,s0..sM,window with --sigma)
  --kind auto:               t,y,d0..dM,s0..sM,noise,outlier,misfit,bias
and, with --lead H (H not 0), a last column lead holding H on every row. The t and y cells \
echo the input cells; dk is the k-th time derivative, in the input's time units, of the \
estimate valid at t+H from the rows up to and including this one, and sk its 1-sigma error. Rows before the estimate is determined have empty d and s cells: the first M rows \
(expanding, fading), the first W-1 rows (fixed); auto gives no estimate without its sigma: from the first row with --sigma, else from row M+6 (the noise cell empty before: not estimated yet).

fixed: the least-squares polynomial through the last W rows, on any timestamps (Morrison's \
sliding O(M^2) recursion while the times are evenly spaced, a refit of the window from the \
first uneven step on: the same fit). The window cell is the number of rows in the window: \
1, 2, ..., W-1 on the rows still filling it (whose d and s cells are empty), W on every row \
with an estimate. On evenly spaced rows, --lead -(W-1)*dt/2 (dt the time step) evaluates each \
row's window at its centre, where the estimate is most accurate.

auto: the automatic filter (Morrison 13.8, 14.8; Reyneke et al. 7): expanding memory at first, \
then fading memory with the discount T per TAU; it starts at degree 0 and steps up to M as the \
data determine each degree (the d and s cells above the degree reached so far are empty). noise \
is the noise sigma in use: S given with --sigma, otherwise the running estimate from the \
(M+1)-th differences of the accepted samples (empty until it has 5 terms); s0..sM come from it, \
and while it is empty so are d0..dM (no estimate is written without its sigma). outlier is 1 when the row's sample is rejected, else 0: the final \
decision, made once N more accepted samples of the series are in (--review-window N, default \
M+4; the end of the input decides the last rows), by the smaller-variance judge of two: the \
3-sigma gate on the 1-step prediction, or the sample's residual against a degree M+1 \
least-squares fit through the N accepted samples on each side of it (Morrison 7, 14.8). A \
rejected sample does not update the filter (the row's estimate was made before its decision: \
across a sample the gate rejected it is the prediction). Rows are written once decided, so \
output lags input by about N rows of each series. misfit is 1 while the chi-squared test of the last 10 innovations (false-alarm rate 1%) \
says the model no longer fits, else 0; a strong misfit restarts the memory. s0..sM are root \
mean squared errors: the noise's part plus the estimated bias of a start-up, a degree still \
settling or a manoeuvre (from the next degree's fit and the innovations' excess, Morrison 7.13, \
13.9, 14.8); bias is the position bias s0 includes, empty when s0..sM cover the noise only.

Several series (--id-col NAME): the rows with the same id (any text) form a series, filtered \
on its own with the same settings; the series may be interleaved in any way, on time grids of \
their own (times must increase within each series only). The output keeps the input's row \
order and starts with the id column: NAME,t,y,d0..dM,... A series shorter than the degree \
needs just has empty cells (the too-few-samples check is on the input as a whole). The default \
tau is the median of the first 100 time steps within series (among the first 65536 rows).

Reading streams in chunks of up to 65536 rows, the series of a chunk in parallel; memory stays \
bounded (a few chunks plus one filter per series) however long the input. The first 101 data \
rows (the first W for a longer fixed window) are held back: an error in one of them stops the \
command before any output. An error in a later row (a bad cell, a time not after the previous \
one of its series, ...) stops the command after every row before it, of every series, has been \
written to standard output; the message names the line, the column and, for a time, the \
series. An output file (-o FILE) is written beside FILE and renamed onto it only when the \
command succeeds: on any error an existing FILE is left as it was (a device such as /dev/null \
or a named pipe is written in place).

Progress: on standard error when it is a terminal and the input is longer than one chunk \
(bytes of the file read, or rows and rows/s from standard input); --no-progress turns it off.

",
    exit_status!("too few samples")
);

const SMOOTH_AFTER_HELP: &str = concat!(
    "\
Output: CSV with header t,y,d0..dM,s0..sM, one row per input row in input order. The t and y \
cells echo the input cells (an ISO-8601 time as its seconds since the Unix epoch); dk is the \
k-th time derivative, in the input's time units, of the least-squares polynomial of degree M \
through the W rows most nearly centred on this one (floor((W-1)/2) rows before it), evaluated \
at its own time; the first and last rows use the first and last full windows. sk is the 1-sigma \
error of dk from that window fit's covariance (Morrison ch. 7: sigma^2 times the \
variance-reduction factor of the row's place in its window), with sigma the --sigma given, \
else estimated from the window's own residuals, s^2 = sum r^2/(W-M-1) (which needs W > M+1; \
with Gaussian noise, 3*sk then covers the truth with the Student-t probability of W-M-1 degrees \
of freedom: 99.2 % at 18, at least 97 % from 6 on). Every row has an estimate and its sigma.

Evenly spaced windows (every step of the window within a relative 1e-9 of the first, allowing \
for the rounding of the timestamps themselves): for odd W, dk is \
scipy.signal.savgol_filter(y, W, M, deriv=k, delta=dt, mode='interp') with dt the window's mean \
step; for even W each row sits half a step after the centre of its window. Irregular windows: \
the same windows, each fitted by least squares at the actual times.

Reading: streams: a row is written once the row floor(W/2) after it has been read (memory \
bounded by the window, not the input). A bad row stops the command with its line; a file \
output is left untouched (standard output keeps the rows already written, a megabyte at a time).

",
    exit_status!("fewer rows than the window")
);

/// The time and value columns of an input (`seqsmooth filter`, `seqsmooth smooth`).
#[derive(Debug, Args)]
pub struct Columns {
    /// Name of the time column
    #[arg(long, value_name = "NAME", default_value = "t")]
    pub time_col: String,
    /// Name of the value column
    #[arg(long, value_name = "NAME", default_value = "y")]
    pub value_col: String,
}

/// The degree and memory of a gains or vrf table.
#[derive(Debug, Args)]
pub struct MemoryArgs {
    /// Polynomial degree M (0 to 24)
    #[arg(long, value_name = "M", value_parser = parse_degree, allow_hyphen_values = true)]
    pub degree: usize,
    /// Expanding memory: 0-based index of the newest sample (N+1 samples seen; vrf needs N >= M)
    #[arg(long, value_name = "N", value_parser = parse_index, allow_hyphen_values = true)]
    pub n: Option<u64>,
    /// Fading memory: discount per sample, 0 < T < 1 (e.g. 0.9 or 9/10; exact with --exact)
    #[arg(long, value_name = "T", value_parser = parse_theta, allow_hyphen_values = true)]
    pub theta: Option<Theta>,
}

/// Which filter `seqsmooth filter` runs.
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

/// The name of `value` on the command line (e.g. `fading` for [`Kind::Fading`]).
pub fn name(value: impl clap::ValueEnum) -> String {
    value
        .to_possible_value()
        .map_or_else(String::new, |v| v.get_name().to_string())
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

/// Output format of the tables.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Format {
    /// Comma-separated values with a header row.
    #[default]
    Csv,
    /// Aligned text for reading.
    Table,
}

/// The filter kinds of `seqsmooth gains` (and the recursive ones of `seqsmooth vrf`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TableKind {
    /// Expanding memory (--n N).
    Expanding,
    /// Fading memory (--theta T).
    Fading,
}

/// The filter memory a table is for, after argument checking: expanding memory at the 0-based
/// index `n` of the newest sample, or fading memory with discount θ.
#[derive(Clone, Debug)]
pub enum Memory {
    Expanding(u64),
    Fading(Theta),
}

impl MemoryArgs {
    /// Resolves `--n`/`--theta` for the memory kind of a gains or vrf table.
    pub fn of(&self, kind: TableKind) -> Result<Memory, CliError> {
        match (kind, self.n, self.theta.clone()) {
            (TableKind::Expanding, Some(n), None) => Ok(Memory::Expanding(n)),
            (TableKind::Expanding, None, _) => Err(CliError::Usage(
                "--kind expanding needs --n N, the 0-based index of the newest sample".into(),
            )),
            (TableKind::Expanding, Some(_), Some(_)) => Err(only("--theta", "fading")),
            (TableKind::Fading, None, Some(theta)) => Ok(Memory::Fading(theta)),
            (TableKind::Fading, _, None) => Err(CliError::Usage(
                "--kind fading needs --theta T, the discount per sample (0 < T < 1)".into(),
            )),
            (TableKind::Fading, Some(_), Some(_)) => Err(only("--n", "expanding")),
        }
    }
}

/// The usage error of an argument given to a kind it does not apply to.
pub fn only(arg: &str, kinds: &str) -> CliError {
    CliError::Usage(format!("{arg} applies only to --kind {kinds}"))
}

/// The `--window` of a fixed-memory fit, checked against the degree: given, and at least the
/// M+1 samples a degree-M fit needs.
pub fn check_window(window: Option<usize>, degree: usize) -> Result<usize, CliError> {
    let need = degree + 1;
    match window {
        None => Err(CliError::Usage(format!(
            "--kind fixed needs --window W, the number of samples in the window (at least M+1 \
             = {need})"
        ))),
        // The library's rule of a window, its reason in the message.
        Some(w) => seqsmooth::polynomial::fixed::check_window(degree, w)
            .map(|()| w)
            .map_err(|e| match e {
                seqsmooth::Error::InvalidParameter { reason, .. } if w < need => CliError::Usage(
                    format!("window {w} is too small for degree {degree}: {reason}"),
                ),
                seqsmooth::Error::InvalidParameter { reason, .. } => {
                    CliError::Usage(format!("window {w} is out of range: {reason}"))
                }
                other => CliError::from(other),
            }),
    }
}

/// A discount factor θ as given on the command line: exact, and rounded to `f64`.
#[derive(Clone, Debug)]
pub struct Theta {
    /// The text as given (used in messages).
    pub text: String,
    /// θ exactly (`0.9` is `9/10`).
    pub exact: Rational,
    /// θ rounded to the nearest `f64`.
    pub value: f64,
}

impl Theta {
    /// θ as an `f64` strictly inside `(0, 1)`, for the computations that run in `f64`.
    pub fn value_f64(&self) -> Result<f64, CliError> {
        if seqsmooth::polynomial::check_theta(self.value).is_ok() {
            Ok(self.value)
        } else {
            Err(CliError::Usage(format!(
                "theta {} is out of range: it rounds to {} in double precision, and the filters \
                 need 0 < theta < 1 after rounding (--exact tables accept it)",
                self.text, self.value
            )))
        }
    }
}

/// Parses `--theta`: `0.9`, `9/10` or `9e-1`, strictly between 0 and 1.
pub fn parse_theta(s: &str) -> Result<Theta, String> {
    let text = s.trim();
    // An exponent this large would take unbounded time to expand exactly (a fuzz campaign's
    // `--theta 5e6999999` took minutes): the library's rule.
    if !seqsmooth::scalar::decimal_exponent_in_range(text) {
        return Err(format!(
            "theta {text} is out of range: it must lie strictly between 0 and 1 (write it with \
             an exponent from -{MAX_DECIMAL_EXPONENT} to {MAX_DECIMAL_EXPONENT})"
        ));
    }
    let exact = parse_rational(text)
        .ok_or_else(|| format!("theta '{text}' is not a number (write it as 0.9 or 9/10)"))?;
    if seqsmooth::polynomial::check_theta_of(&exact).is_err() {
        return Err(format!(
            "theta {text} is out of range: it must lie strictly between 0 and 1"
        ));
    }
    let value = seqsmooth::scalar::ratio_to_f64(&exact);
    Ok(Theta {
        text: text.to_string(),
        exact,
        value,
    })
}

/// A library refusal of an argument, in the command's words (the flag it names, [`flag`]).
fn refused(e: seqsmooth::Error) -> String {
    e.message_in(&flag)
}

/// Parses a whole number `name` (of `unit`, e.g. " of samples") for the library, which checks
/// its range (`check`, refusing in the command's words). Text that is no `usize` is refused
/// here: a negative number by the library's rule of the smallest (where it refuses 0, named
/// as given), else with `range`, the library's range from its constants, where one is given.
fn parse_count(
    name: &str,
    s: &str,
    unit: &str,
    range: Option<String>,
    check: impl Fn(usize) -> Result<(), seqsmooth::Error>,
) -> Result<usize, String> {
    let text = s.trim();
    let Ok(n) = text.parse::<usize>() else {
        let whole = text.parse::<i128>();
        if whole.as_ref().is_ok_and(|v| *v < 0) {
            if let Err(seqsmooth::Error::InvalidParameter { name, reason, .. }) = check(0) {
                let value = text.to_string();
                return Err(refused(seqsmooth::Error::InvalidParameter {
                    name,
                    value,
                    reason,
                }));
            }
        }
        let (one, within) = range.map_or_else(Default::default, |r| {
            (format!("; it must be one {r}"), format!(" {r}"))
        });
        return Err(match whole {
            Ok(_) => {
                format!("{name} {text} is out of range: it must be a whole number{unit}{within}")
            }
            Err(_) => format!("{name} '{text}' is not a whole number{unit}{one}"),
        });
    };
    check(n).map_err(refused)?;
    Ok(n)
}

/// Parses `--degree`: a whole number, in the library's range ([`check_degree`]).
pub fn parse_degree(s: &str) -> Result<usize, String> {
    let range = format!("from 0 to {MAX_DEGREE}");
    parse_count("degree", s, "", Some(range), check_degree)
}

/// Parses `plot --derivative`: a whole number, in the library's range ([`check_derivative`]).
pub fn parse_derivative(s: &str) -> Result<usize, String> {
    let range = format!("from 0 to {MAX_DEGREE}");
    parse_count("derivative", s, "", Some(range), check_derivative)
}

/// Parses `--n`: the 0-based index of the newest sample, a whole number (any `u64`: the tables
/// are exact; the library checks it against the degree where it must).
pub fn parse_index(s: &str) -> Result<u64, String> {
    let text = s.trim();
    text.parse::<u64>()
        .map_err(|_| format!("n '{text}' is not a whole number (0, 1, 2, ...)"))
}

/// Parses the number `name`: any `f64`, NaN and infinities too (the library refuses them where
/// they are out of its range).
pub fn parse_f64(name: &str, s: &str) -> Result<f64, String> {
    let text = s.trim();
    text.parse::<f64>()
        .map_err(|_| format!("{name} '{text}' is not a number"))
}

/// Parses the number `name` and checks it by the library's rule `check` (refusing in the
/// command's words).
fn parse_checked(
    name: &str,
    s: &str,
    check: impl Fn(f64) -> Result<(), seqsmooth::Error>,
) -> Result<f64, String> {
    let v = parse_f64(name, s)?;
    check(v).map_err(refused)?;
    Ok(v)
}

/// Parses `--tau`: a number in the library's range ([`check_tau`]).
pub fn parse_tau(s: &str) -> Result<f64, String> {
    parse_checked("tau", s, check_tau)
}

/// Parses `--sigma`: a number in the range of a noise σ (the library's
/// [`is_usable_sigma`](seqsmooth::estimate::batch::is_usable_sigma)).
pub fn parse_sigma(s: &str) -> Result<f64, String> {
    let v = parse_f64("sigma", s)?;
    if seqsmooth::estimate::batch::is_usable_sigma(v) {
        Ok(v)
    } else {
        Err(format!(
            "sigma {} is out of range: it must be a positive number from about 1.5e-154 to \
             1.3e154 (its square, the noise variance, must be a normal double; rescale the \
             values otherwise)",
            s.trim()
        ))
    }
}

/// Parses `--lead`: a number in the library's range ([`check_lead`]; negative = retrodiction).
pub fn parse_lead(s: &str) -> Result<f64, String> {
    parse_checked("lead", s, check_lead)
}

/// Parses `--window`: the number of samples in the window (Morrison's `L+1`), a whole number
/// in the library's range of a window ([`check_window_length`]). Whether it suits the degree
/// is checked by the command, with the library's rule of each model.
pub fn parse_window(s: &str) -> Result<usize, String> {
    parse_count("window", s, " of samples", None, check_window_length)
}

/// Parses `--max-iterations`: a whole number in the library's range
/// ([`check_max_iterations`]).
pub fn parse_max_iterations(s: &str) -> Result<usize, String> {
    parse_count("max-iterations", s, "", None, check_max_iterations)
}
