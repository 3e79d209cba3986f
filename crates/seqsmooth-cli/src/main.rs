//! The `seqsmooth` command: polynomial smoothing and prediction filters (Morrison 1969;
//! Reyneke et al. 2012) on CSV time series, their gains and variance-reduction matrices, and a
//! demo on built-in data. A thin layer over the `seqsmooth` library: argument parsing, file
//! formats and messages.

mod demo;
mod error;
mod filter;
mod number;
mod tables;

use clap::{Args, Parser, Subcommand};
use error::CliError;
use filter::{EngineArg, FilterConfig, Kind};
use number::{parse_degree, parse_index, parse_lead, parse_sigma, parse_tau, parse_theta, Theta};
use std::path::PathBuf;
use std::process::ExitCode;
use tables::{FormArg, Format, Memory};

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
    /// Smooth, differentiate and predict a CSV time series with an expanding- or fading-memory
    /// polynomial filter
    #[command(after_help = FILTER_AFTER_HELP)]
    Filter(FilterArgs),
    /// Print Morrison's scaled current-estimate gains h_0..h_m (header k,gain)
    #[command(after_help = AFTER_HELP)]
    Gains(GainsArgs),
    /// Print the scaled variance-reduction matrix (header i,j,value, row-major)
    #[command(after_help = AFTER_HELP)]
    Vrf(VrfArgs),
    /// Run the filters on built-in noisy data and print a short summary
    #[command(after_help = AFTER_HELP)]
    Demo(DemoArgs),
}

/// Help text after `seqsmooth filter --help`.
const FILTER_AFTER_HELP: &str = "\
Output: CSV with header t,y,d0..dM (and s0..sM with --sigma), one row per input row in input \
order. The t and y cells echo the input cells; dk is the k-th time derivative, in the input's \
time units, of the estimate valid at t+H from the rows up to and including this one. Rows before \
the estimate is determined (the first M rows) have empty d and s cells.

Reading streams: only the first 101 data rows are held back (for the default tau and the \
too-few-samples check). An error in a later row stops the command after the rows before it have \
been written.

Exit status: 0 on success; 1 when the input data or a file is unusable (bad numbers, NaN or \
infinite values, unsorted or duplicate times, missing columns, malformed CSV, too few samples, \
unreadable or unwritable files); 2 for command-line errors (unknown or missing arguments, values \
out of range). Every message goes to stderr and starts with 'error: '; data errors name the \
1-based file line (the header is line 1), the column and the value.

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
    /// Fading memory: discount per tau, 0 < T < 1 (e.g. 0.9 or 9/10)
    #[arg(long, value_name = "T", value_parser = parse_theta, allow_hyphen_values = true)]
    theta: Option<Theta>,
    /// Fading memory: the time interval theta applies to [default: the median time step of the
    /// first 101 rows, so theta is the discount per typical sample; 1 for a single row]
    #[arg(long, value_name = "TAU", value_parser = parse_tau, allow_hyphen_values = true)]
    tau: Option<f64>,
    /// Engine: 'exact' is least squares on any timestamps; 'gain' is Morrison's fixed-gain
    /// recursion, exact on evenly spaced times and approximate on irregular ones
    #[arg(long, value_enum, default_value_t = EngineArg::Exact)]
    engine: EngineArg,
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
    /// errors of d0..dM from the filter's covariance
    #[arg(long, value_name = "S", value_parser = parse_sigma, allow_hyphen_values = true)]
    sigma: Option<f64>,
    /// Output file [default: standard output]
    #[arg(short = 'o', long, value_name = "OUTPUT")]
    output: Option<PathBuf>,
}

/// Arguments of `seqsmooth gains`.
#[derive(Debug, Args)]
struct GainsArgs {
    /// Filter kind
    #[arg(long, value_enum)]
    kind: Kind,
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
    kind: Kind,
    /// Polynomial degree M (0 to 24)
    #[arg(long, value_name = "M", value_parser = parse_degree, allow_hyphen_values = true)]
    degree: usize,
    /// Expanding memory: 0-based index of the newest sample, N >= M
    #[arg(long, value_name = "N", value_parser = parse_index, allow_hyphen_values = true)]
    n: Option<u64>,
    /// Fading memory: discount per sample, 0 < T < 1 (e.g. 0.9 or 9/10; exact with --exact)
    #[arg(long, value_name = "T", value_parser = parse_theta, allow_hyphen_values = true)]
    theta: Option<Theta>,
    /// Which estimate: the current one (Z*_{n,n}) or the 1-step prediction (Z*_{n+1,n})
    #[arg(long, value_enum, default_value_t = FormArg::Current)]
    form: FormArg,
    /// Print exact rationals in lowest terms, p/q (an integer as p), instead of doubles.
    /// Without it θ is rounded to the nearest double before the computation
    #[arg(long)]
    exact: bool,
    /// Output format
    #[arg(long, value_enum, default_value_t = Format::Csv)]
    format: Format,
}

/// Arguments of `seqsmooth demo`.
#[derive(Debug, Args)]
struct DemoArgs {
    /// Also write the fading-memory (exact engine) filter's CSV output (t,y,d0..d2,s0..s2) here
    #[arg(short = 'o', long, value_name = "FILE")]
    output: Option<PathBuf>,
}

/// Resolves `--n`/`--theta` for the memory kind of a gains or vrf table.
fn memory(kind: Kind, n: Option<u64>, theta: Option<Theta>) -> Result<Memory, CliError> {
    match (kind, n, theta) {
        (Kind::Expanding, Some(n), None) => Ok(Memory::Expanding { n }),
        (Kind::Expanding, None, _) => Err(CliError::Usage(
            "--kind expanding needs --n N, the 0-based index of the newest sample".into(),
        )),
        (Kind::Expanding, Some(_), Some(_)) => Err(CliError::Usage(
            "--theta applies only to --kind fading".into(),
        )),
        (Kind::Fading, None, Some(theta)) => Ok(Memory::Fading { theta }),
        (Kind::Fading, _, None) => Err(CliError::Usage(
            "--kind fading needs --theta T, the discount per sample (0 < T < 1)".into(),
        )),
        (Kind::Fading, Some(_), Some(_)) => Err(CliError::Usage(
            "--n applies only to --kind expanding".into(),
        )),
    }
}

fn run_filter(a: FilterArgs) -> Result<(), CliError> {
    let theta = match (a.kind, a.theta) {
        (Kind::Fading, Some(theta)) => Some(theta.value_f64().map_err(CliError::Usage)?),
        (Kind::Fading, None) => {
            return Err(CliError::Usage(
                "--kind fading needs --theta T, the discount per tau (0 < T < 1)".into(),
            ))
        }
        (Kind::Expanding, Some(_)) => {
            return Err(CliError::Usage(
                "--theta applies only to --kind fading".into(),
            ))
        }
        (Kind::Expanding, None) => None,
    };
    if a.kind == Kind::Expanding && a.tau.is_some() {
        return Err(CliError::Usage(
            "--tau applies only to --kind fading".into(),
        ));
    }
    filter::run(&FilterConfig {
        input: a.input,
        output: a.output,
        kind: a.kind,
        degree: a.degree,
        theta,
        tau: a.tau,
        engine: a.engine,
        lead: a.lead,
        time_col: a.time_col,
        value_col: a.value_col,
        sigma: a.sigma,
    })
}

fn run_vrf(a: VrfArgs) -> Result<(), CliError> {
    let mem = memory(a.kind, a.n, a.theta)?;
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
    tables::vrf(a.degree, &mem, a.form, a.exact, a.format)
}

fn run(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Filter(a) => run_filter(a),
        Command::Gains(a) => {
            let mem = memory(a.kind, a.n, a.theta)?;
            tables::gains(a.degree, &mem, a.exact, a.format)
        }
        Command::Vrf(a) => run_vrf(a),
        Command::Demo(a) => demo::run(a.output.as_deref()),
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
