//! The `seqsmooth` command: polynomial smoothing and prediction filters (Morrison 1969;
//! Reyneke et al. 2012) on CSV time series — expanding, fading and fixed memory, the automatic
//! filter, and whole-series (Savitzky–Golay) smoothing — their gains and variance-reduction
//! matrices, and a demo on built-in data. A thin layer over the `seqsmooth` library: argument
//! parsing, file formats and messages.

mod chart;
mod decimal;
mod demo;
mod error;
mod filter;
mod layout;
mod number;
mod plot;
mod progress;
mod records;
mod rows;
mod series;
mod shortest;
mod smooth;
mod tables;

use clap::{Args, Parser, Subcommand};
use error::CliError;
use filter::{EngineArg, FilterConfig, Kind};
use number::{
    parse_degree, parse_index, parse_lead, parse_lead_steps, parse_sigma, parse_tau, parse_theta,
    parse_window, LeadSteps, Theta,
};
use smooth::SmoothConfig;
use std::path::PathBuf;
use std::process::ExitCode;
use tables::{FormArg, Format, Memory, TableKind, VrfKind};

/// Text shown after every `--help`: exit codes and number formats.
const AFTER_HELP: &str = "\
Exit status: 0 on success; 1 when the input data or a file is unusable (bad numbers, NaN or \
infinite values, unsorted or duplicate times, missing columns, malformed CSV, too few samples, \
unreadable or unwritable files); 2 for command-line errors (unknown or missing arguments, values \
out of range). Every message goes to stderr and starts with 'error: '; data errors name the \
1-based file line (the header is line 1), the column and the value.

Numbers are written with round-trip precision: the shortest text that parses back to the same \
double (plain decimals for 1e-5 <= |x| < 1e16, otherwise scientific notation such as 1e-300). \
Exact (--exact) values are rationals in lowest terms, 'p/q', or 'p' when the value is an integer.";

/// Top-level command line.
#[derive(Debug, Parser)]
#[command(
    name = "seqsmooth",
    version,
    about = "Polynomial smoothing and prediction filters (Morrison 1969; Reyneke et al. 2012)",
    after_help = AFTER_HELP
)]
struct Cli {
    /// The subcommand.
    #[command(subcommand)]
    command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
enum Command {
    /// Smooth, differentiate and predict a CSV time series, row by row, with an expanding-,
    /// fading- or fixed-memory or the automatic polynomial filter
    #[command(after_help = FILTER_AFTER_HELP)]
    Filter(FilterArgs),
    /// Smooth and differentiate a whole CSV time series with centred fixed-memory windows
    /// (Savitzky-Golay, non-causal; reads the whole input first)
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
}

/// Help text after `seqsmooth plot --help`.
const PLOT_AFTER_HELP: &str = "\
Reads the CSV written by 'seqsmooth filter' and draws, under a title and a legend: a panel per \
--derivative K with the estimate dK, its +-3 sigma band from sK (when the output has s \
columns) and, for K = 0, the samples (rejected ones as red crosses, from the auto filter's \
outlier column); then a residual panel y - d0 with the estimate's +-3 sigma band about zero \
and the auto filter's +-3 noise sigma (dashed). The spans where the auto filter's misfit flag \
is up are shaded in every panel. Empty cells leave gaps. Axis ranges leave out the start-up \
transients of the estimates; residuals beyond the range are drawn as triangles at its edge.

With --input (the file given to 'seqsmooth filter') the truth column --truth-col is drawn \
too; the input's times and values must match the output's rows.

Exit status: 0 on success; 1 when the input data or a file is unusable (missing file or \
columns, malformed CSV, non-numeric cells, unwritable image); 2 for command-line errors \
(unknown or missing arguments, values out of range, an output name not ending in .png or \
.svg). Every message goes to stderr and starts with 'error: '; data errors name the file, the \
1-based line (the header is line 1) and the column.";

/// Help text after `seqsmooth filter --help`.
const FILTER_AFTER_HELP: &str = "\
Output: CSV, one row per input row in input order, with the header
  --kind expanding, fading:  t,y,d0..dM            (and s0..sM with --sigma)
  --kind fixed:              t,y,d0..dM,window     (t,y,d0..dM,s0..sM,window with --sigma)
  --kind auto:               t,y,d0..dM,s0..sM,noise,outlier,misfit
The t and y cells echo the input cells; dk is the k-th time derivative, in the input's time \
units, of the estimate valid at t+H from the rows up to and including this one, and sk its \
1-sigma error. Rows before the estimate is determined have empty d and s cells: the first M rows \
(expanding, fading), the first W-1 rows (fixed); auto estimates from the first row on.

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
(M+1)-th differences of the accepted samples (empty until it has 5 terms); s0..sM come from it \
(empty while there is none). outlier is 1 when the row's sample was rejected by the 3-sigma \
innovation gate (it did not update the filter; the row's estimate is the prediction across it), \
else 0. misfit is 1 while the chi-squared test of the last 10 innovations (false-alarm rate 1%) \
says the model no longer fits, else 0; a strong misfit restarts the memory.

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
written; the message names the line, the column and, for a time, the series.

Progress: on standard error when it is a terminal and the input is longer than one chunk \
(bytes of the file read, or rows and rows/s from standard input); --no-progress turns it off.

Exit status: 0 on success; 1 when the input data or a file is unusable (bad numbers, NaN or \
infinite values, unsorted or duplicate times, missing columns, malformed CSV, too few samples, \
unreadable or unwritable files); 2 for command-line errors (unknown or missing arguments, values \
out of range). Every message goes to stderr and starts with 'error: '; data errors name the \
1-based file line (the header is line 1), the column and the value.

Numbers are written with round-trip precision: the shortest text that parses back to the same \
double (plain decimals for 1e-5 <= |x| < 1e16, otherwise scientific notation such as 1e-300).";

/// Help text after `seqsmooth smooth --help`.
const SMOOTH_AFTER_HELP: &str = "\
Output: CSV with header t,y,d0..dM, one row per input row in input order. The t and y cells \
echo the input cells; dk is the k-th time derivative, in the input's time units, of the \
least-squares polynomial of degree M through the W rows most nearly centred on this one \
(floor((W-1)/2) rows before it), evaluated at its own time; the first and last rows use the \
first and last full windows. Every row has an estimate.

Evenly spaced times (every step within a relative 1e-9 of the first, allowing for the rounding \
of the timestamps themselves): for odd W, dk is \
scipy.signal.savgol_filter(y, W, M, deriv=k, delta=dt, mode='interp') with dt the mean step; \
for even W each row sits half a step after the centre of its window. Irregular times: the same \
windows, each fitted by least squares at the actual times.

Reading: the whole input is read and checked before the first output row is written (a row's \
window reaches rows after it); use 'seqsmooth filter --kind fixed' for a causal, streaming fit.

Exit status: 0 on success; 1 when the input data or a file is unusable (bad numbers, NaN or \
infinite values, unsorted or duplicate times, missing columns, malformed CSV, fewer rows than \
the window, unreadable or unwritable files); 2 for command-line errors (unknown or missing \
arguments, values out of range). Every message goes to stderr and starts with 'error: '; data \
errors name the 1-based file line (the header is line 1), the column and the value.

Numbers are written with round-trip precision: the shortest text that parses back to the same \
double (plain decimals for 1e-5 <= |x| < 1e16, otherwise scientific notation such as 1e-300).";

/// Arguments of `seqsmooth filter`.
#[derive(Debug, Args)]
struct FilterArgs {
    /// Input CSV with a header row; omitted or '-' reads standard input. Columns other than the
    /// time and value columns are ignored
    #[arg(value_name = "INPUT")]
    input: Option<PathBuf>,
    /// Filter kind
    #[arg(long, value_enum)]
    kind: Kind,
    /// Polynomial degree M (0 to 24)
    #[arg(long, value_name = "M", value_parser = parse_degree, allow_hyphen_values = true)]
    degree: usize,
    /// Fading memory and auto: discount per tau, 0 < T < 1 (e.g. 0.9 or 9/10)
    #[arg(long, value_name = "T", value_parser = parse_theta, allow_hyphen_values = true)]
    theta: Option<Theta>,
    /// Fading memory and auto: the time interval theta applies to [default: the median time
    /// step of the first 101 rows, so theta is the discount per typical sample; 1 for a single
    /// row]
    #[arg(long, value_name = "TAU", value_parser = parse_tau, allow_hyphen_values = true)]
    tau: Option<f64>,
    /// Fixed memory: the number of samples in the window, W >= M+1 (Morrison's L+1, savgol's
    /// window_length)
    #[arg(long, value_name = "W", value_parser = parse_window, allow_hyphen_values = true)]
    window: Option<usize>,
    /// Engine of the expanding, fading and auto filters: 'exact' is least squares on any
    /// timestamps; 'gain' is Morrison's fixed-gain recursion, exact on evenly spaced times and
    /// approximate on irregular ones. The fixed-memory filter is always the exact fit of its
    /// window [default: exact]
    #[arg(long, value_enum)]
    engine: Option<EngineArg>,
    /// Lead H in time units: each row's estimate is valid at t+H (negative = retrodiction)
    #[arg(long, value_name = "H", default_value = "0", value_parser = parse_lead,
          allow_hyphen_values = true)]
    lead: f64,
    /// Name of the time column
    #[arg(long, value_name = "NAME", default_value = "t")]
    time_col: String,
    /// Name of the value column
    #[arg(long, value_name = "NAME", default_value = "y")]
    value_col: String,
    /// White-noise standard deviation S of the values: adds the columns s0..sM, the 1-sigma
    /// errors of d0..dM from the filter's covariance. With --kind auto (which always writes
    /// s0..sM) the noise is taken to be S instead of estimated
    #[arg(long, value_name = "S", value_parser = parse_sigma, allow_hyphen_values = true)]
    sigma: Option<f64>,
    /// Output file [default: standard output]
    #[arg(short = 'o', long, value_name = "OUTPUT")]
    output: Option<PathBuf>,
    /// Name of a column naming the series: the rows of each id (any text) are a series of
    /// their own, filtered on its own with the same settings, and the column is written first
    #[arg(long, value_name = "NAME")]
    id_col: Option<String>,
    /// Never show the progress display (shown on standard error only when it is a terminal
    /// and the input is larger than one chunk of rows)
    #[arg(long)]
    no_progress: bool,
    /// Rows read, filtered and written at a time (testing aid)
    #[arg(long, value_name = "N", hide = true, default_value_t = filter::CHUNK_ROWS,
          value_parser = clap::value_parser!(u32).range(1..))]
    chunk_rows: u32,
}

/// Arguments of `seqsmooth smooth`.
#[derive(Debug, Args)]
struct SmoothArgs {
    /// Input CSV with a header row; omitted or '-' reads standard input. Columns other than the
    /// time and value columns are ignored. Read in full before any output is written
    #[arg(value_name = "INPUT")]
    input: Option<PathBuf>,
    /// Polynomial degree M (0 to 24)
    #[arg(long, value_name = "M", value_parser = parse_degree, allow_hyphen_values = true)]
    degree: usize,
    /// The number of samples in each window, M+1 <= W <= the number of rows (savgol's
    /// window_length, Morrison's L+1); odd W centres every window on its row
    #[arg(long, value_name = "W", value_parser = parse_window, allow_hyphen_values = true)]
    window: usize,
    /// Name of the time column
    #[arg(long, value_name = "NAME", default_value = "t")]
    time_col: String,
    /// Name of the value column
    #[arg(long, value_name = "NAME", default_value = "y")]
    value_col: String,
    /// Output file [default: standard output]
    #[arg(short = 'o', long, value_name = "OUTPUT")]
    output: Option<PathBuf>,
}

/// Arguments of `seqsmooth gains`.
#[derive(Debug, Args)]
struct GainsArgs {
    /// Filter kind
    #[arg(long, value_enum)]
    kind: TableKind,
    /// Polynomial degree M (0 to 24)
    #[arg(long, value_name = "M", value_parser = parse_degree, allow_hyphen_values = true)]
    degree: usize,
    /// Expanding memory: 0-based index of the newest sample (n+1 samples seen)
    #[arg(long, value_name = "N", value_parser = parse_index, allow_hyphen_values = true)]
    n: Option<u64>,
    /// Fading memory: discount per sample, 0 < T < 1 (e.g. 0.9 or 9/10; exact with --exact)
    #[arg(long, value_name = "T", value_parser = parse_theta, allow_hyphen_values = true)]
    theta: Option<Theta>,
    /// Print exact rationals in lowest terms, p/q (an integer as p), instead of doubles.
    /// Without it θ is rounded to the nearest double before the computation
    #[arg(long)]
    exact: bool,
    /// Output format
    #[arg(long, value_enum, default_value_t = Format::Csv)]
    format: Format,
}

/// Arguments of `seqsmooth vrf`.
#[derive(Debug, Args)]
struct VrfArgs {
    /// Filter kind
    #[arg(long, value_enum)]
    kind: VrfKind,
    /// Polynomial degree M (0 to 24)
    #[arg(long, value_name = "M", value_parser = parse_degree, allow_hyphen_values = true)]
    degree: usize,
    /// Expanding memory: 0-based index of the newest sample, N >= M
    #[arg(long, value_name = "N", value_parser = parse_index, allow_hyphen_values = true)]
    n: Option<u64>,
    /// Fading memory: discount per sample, 0 < T < 1 (e.g. 0.9 or 9/10; exact with --exact)
    #[arg(long, value_name = "T", value_parser = parse_theta, allow_hyphen_values = true)]
    theta: Option<Theta>,
    /// Fixed memory: the number of samples in the window, W >= M+1 (Morrison's L+1)
    #[arg(long, value_name = "W", value_parser = parse_window, allow_hyphen_values = true)]
    window: Option<usize>,
    /// Fixed memory: the lead H in samples after the newest one: 0 the current estimate
    /// (default), 1 the 1-step prediction, -(W-1)/2 the centre of the window; any number, e.g.
    /// -2.5 or -5/2 (exact with --exact)
    #[arg(long, value_name = "H", value_parser = parse_lead_steps, allow_hyphen_values = true)]
    lead: Option<LeadSteps>,
    /// Expanding and fading memory: which estimate, the current one (Z*_{n,n}) or the 1-step
    /// prediction (Z*_{n+1,n}) [default: current]
    #[arg(long, value_enum)]
    form: Option<FormArg>,
    /// Print exact rationals in lowest terms, p/q (an integer as p), instead of doubles.
    /// Without it θ (or H) is rounded to the nearest double before the computation
    #[arg(long)]
    exact: bool,
    /// Output format
    #[arg(long, value_enum, default_value_t = Format::Csv)]
    format: Format,
}

/// Arguments of `seqsmooth demo`.
#[derive(Debug, Args)]
struct DemoArgs {
    /// Also write the plain fading-memory (exact engine) filter's CSV output
    /// (t,y,d0..d2,s0..s2) here
    #[arg(short = 'o', long, value_name = "FILE")]
    output: Option<PathBuf>,
    /// Path prefix of the plot: writes PREFIX.png and PREFIX.svg
    #[arg(long, value_name = "PREFIX", default_value = demo::DEFAULT_PLOT)]
    plot: PathBuf,
    /// Write no plot
    #[arg(long, conflicts_with = "plot")]
    no_plot: bool,
}

/// Arguments of `seqsmooth plot`.
#[derive(Debug, Args)]
struct PlotArgs {
    /// The output of 'seqsmooth filter' (CSV with header t,y,d0..dM[,s0..sM][,...]); omitted
    /// or '-' reads standard input
    #[arg(value_name = "FILTER_OUTPUT")]
    source: Option<PathBuf>,
    /// Image file to write, PNG or SVG by its extension (.png, .svg); repeat for both
    #[arg(short = 'o', long, value_name = "IMAGE", required = true)]
    output: Vec<PathBuf>,
    /// Derivative to plot, one panel each, in the order given (0 the value, 1 the rate, ...);
    /// repeat for several
    #[arg(long, value_name = "K", default_value = "0", value_parser = parse_degree,
          allow_hyphen_values = true)]
    derivative: Vec<usize>,
    /// Leave out the residual panel
    #[arg(long)]
    no_residuals: bool,
    /// Title [default: the filter kind and the file name]
    #[arg(long, value_name = "TEXT")]
    title: Option<String>,
    /// Image width in pixels
    #[arg(long, value_name = "PX", default_value_t = 1200,
          value_parser = clap::value_parser!(u32).range(300..=10000))]
    width: u32,
    /// Image height in pixels [default: 330 per derivative panel, 250 for the residuals, 120
    /// for the title and legend]
    #[arg(long, value_name = "PX", value_parser = clap::value_parser!(u32).range(300..=10000))]
    height: Option<u32>,
    /// Unit of the times, for the axis labels (e.g. s)
    #[arg(long, value_name = "UNIT")]
    time_unit: Option<String>,
    /// Unit of the values, for the axis labels (e.g. m)
    #[arg(long, value_name = "UNIT")]
    value_unit: Option<String>,
    /// The --lead H the output was made with: the estimates are drawn at t+H (and the residual
    /// panel, which needs H = 0, is left out)
    #[arg(long, value_name = "H", default_value = "0", value_parser = parse_lead,
          allow_hyphen_values = true)]
    lead: f64,
    /// The filter's input file, to draw its truth column (--truth-col)
    #[arg(long, value_name = "FILE")]
    input: Option<PathBuf>,
    /// Name of the input's time column
    #[arg(long, value_name = "NAME", default_value = "t")]
    time_col: String,
    /// Name of the input's value column
    #[arg(long, value_name = "NAME", default_value = "y")]
    value_col: String,
    /// Column of the input holding the true values, drawn as a line (needs --input)
    #[arg(long, value_name = "NAME", requires = "input")]
    truth_col: Option<String>,
}

/// Resolves `--n`/`--theta` for the memory kind of a gains or vrf table.
fn memory(kind: TableKind, n: Option<u64>, theta: Option<Theta>) -> Result<Memory, CliError> {
    match (kind, n, theta) {
        (TableKind::Expanding, Some(n), None) => Ok(Memory::Expanding { n }),
        (TableKind::Expanding, None, _) => Err(CliError::Usage(
            "--kind expanding needs --n N, the 0-based index of the newest sample".into(),
        )),
        (TableKind::Expanding, Some(_), Some(_)) => Err(CliError::Usage(
            "--theta applies only to --kind fading".into(),
        )),
        (TableKind::Fading, None, Some(theta)) => Ok(Memory::Fading { theta }),
        (TableKind::Fading, _, None) => Err(CliError::Usage(
            "--kind fading needs --theta T, the discount per sample (0 < T < 1)".into(),
        )),
        (TableKind::Fading, Some(_), Some(_)) => Err(CliError::Usage(
            "--n applies only to --kind expanding".into(),
        )),
    }
}

/// The usage error of an argument given to a kind it does not apply to.
fn only(arg: &str, kinds: &str) -> CliError {
    CliError::Usage(format!("{arg} applies only to --kind {kinds}"))
}

/// Checks a window against the degree: a degree-M fit needs at least M+1 samples.
fn check_window(window: usize, degree: usize) -> Result<(), CliError> {
    if window < degree + 1 {
        return Err(CliError::Usage(format!(
            "window {window} is too small for degree {degree}: a degree-{degree} fit needs a \
             window of at least {} samples",
            degree + 1
        )));
    }
    Ok(())
}

fn run_filter(a: FilterArgs) -> Result<(), CliError> {
    let kind = a.kind;
    let theta = match (kind, a.theta) {
        (Kind::Fading | Kind::Auto, Some(theta)) => {
            Some(theta.value_f64().map_err(CliError::Usage)?)
        }
        (Kind::Fading | Kind::Auto, None) => {
            return Err(CliError::Usage(format!(
                "--kind {} needs --theta T, the discount per tau (0 < T < 1)",
                kind.name()
            )))
        }
        (Kind::Expanding | Kind::Fixed, Some(_)) => return Err(only("--theta", "fading and auto")),
        (Kind::Expanding | Kind::Fixed, None) => None,
    };
    if matches!(kind, Kind::Expanding | Kind::Fixed) && a.tau.is_some() {
        return Err(only("--tau", "fading and auto"));
    }
    match (kind, a.window) {
        (Kind::Fixed, Some(w)) => check_window(w, a.degree)?,
        (Kind::Fixed, None) => {
            return Err(CliError::Usage(format!(
                "--kind fixed needs --window W, the number of samples in the window (at least \
                 M+1 = {})",
                a.degree + 1
            )))
        }
        (_, Some(_)) => return Err(only("--window", "fixed")),
        (_, None) => {}
    }
    if let Some(id) = &a.id_col {
        if *id == a.time_col || *id == a.value_col {
            return Err(CliError::Usage(format!(
                "--id-col {id} is the time or the value column; name a column of its own"
            )));
        }
    }
    if kind == Kind::Fixed && a.engine == Some(EngineArg::Gain) {
        return Err(CliError::Usage(
            "--engine gain applies only to --kind expanding, fading and auto: the fixed-memory \
             filter is always the exact least-squares fit of its window"
                .into(),
        ));
    }
    filter::run(&FilterConfig {
        input: a.input,
        output: a.output,
        kind,
        degree: a.degree,
        theta,
        tau: a.tau,
        window: a.window,
        engine: a.engine.unwrap_or(EngineArg::Exact),
        lead: a.lead,
        time_col: a.time_col,
        value_col: a.value_col,
        sigma: a.sigma,
        id_col: a.id_col,
        no_progress: a.no_progress,
        chunk_rows: a.chunk_rows as usize,
    })
}

fn run_smooth(a: SmoothArgs) -> Result<(), CliError> {
    check_window(a.window, a.degree)?;
    smooth::run(&SmoothConfig {
        input: a.input,
        output: a.output,
        degree: a.degree,
        window: a.window,
        time_col: a.time_col,
        value_col: a.value_col,
    })
}

fn run_vrf(a: VrfArgs) -> Result<(), CliError> {
    let table_kind = match a.kind {
        VrfKind::Fixed => {
            if a.n.is_some() {
                return Err(only("--n", "expanding"));
            }
            if a.theta.is_some() {
                return Err(only("--theta", "fading"));
            }
            if a.form.is_some() {
                return Err(CliError::Usage(
                    "--form applies only to --kind expanding and fading; for --kind fixed give \
                     --lead H in samples (0 the current estimate, 1 the 1-step prediction, \
                     -(W-1)/2 the centre of the window)"
                        .into(),
                ));
            }
            let window = a.window.ok_or_else(|| {
                CliError::Usage(format!(
                    "--kind fixed needs --window W, the number of samples in the window (at \
                     least M+1 = {})",
                    a.degree + 1
                ))
            })?;
            check_window(window, a.degree)?;
            let lead = a.lead.unwrap_or_default();
            return tables::fixed_vrf(a.degree, window, &lead, a.exact, a.format);
        }
        VrfKind::Expanding => TableKind::Expanding,
        VrfKind::Fading => TableKind::Fading,
    };
    if a.window.is_some() {
        return Err(only("--window", "fixed"));
    }
    if a.lead.is_some() {
        return Err(CliError::Usage(
            "--lead applies only to --kind fixed; expanding and fading take --form".into(),
        ));
    }
    let mem = memory(table_kind, a.n, a.theta)?;
    if let Memory::Expanding { n } = mem {
        if n < a.degree as u64 {
            return Err(CliError::Usage(format!(
                "n {n} is too small for degree {}: the expanding-memory variance-reduction \
                 matrix needs n >= {} (at least {} samples)",
                a.degree,
                a.degree,
                a.degree + 1
            )));
        }
    }
    let form = a.form.unwrap_or_default();
    tables::vrf(a.degree, &mem, form, a.exact, a.format)
}

fn run(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Filter(a) => run_filter(a),
        Command::Smooth(a) => run_smooth(a),
        Command::Gains(a) => {
            let mem = memory(a.kind, a.n, a.theta)?;
            tables::gains(a.degree, &mem, a.exact, a.format)
        }
        Command::Vrf(a) => run_vrf(a),
        Command::Demo(a) => demo::run(&demo::DemoConfig {
            output: a.output,
            plot: (!a.no_plot).then_some(a.plot),
        }),
        Command::Plot(a) => plot::run(&plot::PlotConfig {
            source: a.source,
            outputs: a.output,
            derivatives: a.derivative,
            residuals: !a.no_residuals,
            title: a.title,
            width: a.width,
            height: a.height,
            time_unit: a.time_unit,
            value_unit: a.value_unit,
            lead: a.lead,
            input: a.input,
            time_col: a.time_col,
            value_col: a.value_col,
            truth_col: a.truth_col,
        }),
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(CliError::BrokenPipe) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            if matches!(e, CliError::Usage(_)) {
                eprintln!("\nFor more information, try '--help'.");
            }
            ExitCode::from(e.exit_code())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Cli;
    use clap::CommandFactory;

    #[test]
    fn clap_definition_is_consistent() {
        Cli::command().debug_assert();
    }
}
