//! The arguments of `seqsmooth vrf`.

use super::{parse_window, refused, Format, MemoryArgs};
use clap::Args;
use seqsmooth::polynomial::fixed::check_lead_steps;
use seqsmooth::polynomial::form::EstimateForm;
use seqsmooth::scalar::Rational;
use seqsmooth::scalar::{parse_rational, MAX_DECIMAL_EXPONENT};

#[derive(Debug, Args)]
pub struct VrfArgs {
    /// Filter kind
    #[arg(long, value_enum)]
    pub kind: VrfKind,
    #[command(flatten)]
    pub memory: MemoryArgs,
    /// Fixed memory: the number of samples in the window, W >= M+1 (Morrison's L+1)
    #[arg(long, value_name = "W", value_parser = parse_window, allow_hyphen_values = true)]
    pub window: Option<usize>,
    /// Fixed memory: the lead H in samples after the newest one: 0 the current estimate
    /// (default), 1 the 1-step prediction, -(W-1)/2 the centre of the window; any number, e.g.
    /// -2.5 or -5/2 (exact with --exact)
    #[arg(long, value_name = "H", value_parser = parse_lead_steps, allow_hyphen_values = true)]
    pub lead: Option<LeadSteps>,
    /// Expanding and fading memory: which estimate, the current one (Z*_{n,n}) or the 1-step
    /// prediction (Z*_{n+1,n}) [default: current]
    #[arg(long, value_enum)]
    pub form: Option<FormArg>,
    /// Print exact rationals in lowest terms, p/q (an integer as p), instead of doubles.
    /// Without it θ (or H) is rounded to the nearest double before the computation
    #[arg(long)]
    pub exact: bool,
    /// Output format
    #[arg(long, value_enum, default_value_t = Format::Csv)]
    pub format: Format,
}

/// The filter kinds with a variance-reduction matrix.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum VrfKind {
    /// Expanding memory (--n N, --form).
    Expanding,
    /// Fading memory (--theta T, --form).
    Fading,
    /// Fixed memory over W samples (--window W, --lead H).
    Fixed,
}

/// Which estimate a variance-reduction matrix describes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum FormArg {
    /// The current estimate Z*_{n,n}.
    #[default]
    Current,
    /// The 1-step prediction Z*_{n+1,n}.
    Predictor,
}

impl From<FormArg> for EstimateForm {
    fn from(f: FormArg) -> Self {
        match f {
            FormArg::Current => EstimateForm::Current,
            FormArg::Predictor => EstimateForm::Predictor,
        }
    }
}

/// A lead in sampling intervals as given on the command line (`seqsmooth vrf --kind fixed`):
/// exact, and rounded to `f64`; zero by default.
#[derive(Clone, Debug, Default)]
pub struct LeadSteps {
    /// The lead exactly (`-2.5` is `-5/2`).
    pub exact: Rational,
    /// The lead rounded to the nearest `f64`.
    pub value: f64,
}

/// Parses `--lead` of `seqsmooth vrf`: `0`, `1`, `-2.5`, `-5/2` or `25e-1`, in samples, exactly;
/// finite in double precision.
pub fn parse_lead_steps(s: &str) -> Result<LeadSteps, String> {
    let text = s.trim();
    let not_a_number = || format!("lead '{text}' is not a number (write it as -2.5 or -5/2)");
    // An exponent this large would take unbounded time to expand exactly: the library's rule.
    if !seqsmooth::scalar::decimal_exponent_in_range(text) {
        return Err(format!(
            "lead {text} is out of range: write it with an exponent from \
             -{MAX_DECIMAL_EXPONENT} to {MAX_DECIMAL_EXPONENT}"
        ));
    }
    let exact = parse_rational(text).ok_or_else(not_a_number)?;
    let value = seqsmooth::scalar::ratio_to_f64(&exact);
    // The library's range of a lead in samples.
    check_lead_steps(value).map_err(refused)?;
    Ok(LeadSteps { exact, value })
}
