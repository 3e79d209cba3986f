//! The library's typed errors. Every variant names the offending value.

use thiserror::Error;

pub mod param;
pub use param::Param;

/// What went wrong, with the value that caused it.
///
/// ```
/// use seqsmooth::{Engine, Error, FadingMemory};
/// let e = FadingMemory::new(1, 1.5, 1.0, Engine::Exact).unwrap_err();
/// assert_eq!(e, Error::ThetaOutOfRange { theta: 1.5 });
/// assert_eq!(e.to_string(), "theta 1.5 is out of range: it must lie strictly between 0 and 1");
/// ```
#[derive(Clone, Debug, Error, PartialEq)]
pub enum Error {
    /// A sample value or timestamp is NaN or infinite.
    #[error("{what} {value} is not finite")]
    NonFinite {
        /// `"time"` or `"value"`.
        what: &'static str,
        /// The offending number.
        value: f64,
    },
    /// A timestamp is not after the previous one.
    #[error(
        "time {time} is not after the previous time {previous}: times must be strictly increasing"
    )]
    TimeNotIncreasing {
        /// The new timestamp.
        time: f64,
        /// The previous timestamp.
        previous: f64,
    },
    /// The discount factor is outside `(0, 1)`.
    #[error("{}", self.named("theta"))]
    ThetaOutOfRange {
        /// The rejected θ.
        theta: f64,
    },
    /// The nominal sampling interval is not a positive finite number.
    #[error("{}", self.named("tau"))]
    TauOutOfRange {
        /// The rejected τ.
        tau: f64,
    },
    /// The degree is larger than the library supports.
    #[error("{}", self.named("degree"))]
    DegreeOutOfRange {
        /// The rejected degree.
        degree: usize,
        /// The largest degree accepted.
        max: usize,
    },
    /// The degree is beyond what the gain engine supports (the exact engine supports it).
    #[error("{}", self.named("degree"))]
    GainDegreeOutOfRange {
        /// The rejected degree.
        degree: usize,
        /// The largest degree the gain engine accepts.
        max: usize,
    },
    /// A value is beyond the gain engine's range (the exact engine accepts it).
    #[error(
        "value {value:e} is beyond the gain engine's range: |y| must stay below {max:e} (its \
         double-word arithmetic needs the headroom); use the exact engine, or rescale the values"
    )]
    GainValueOutOfRange {
        /// The rejected value.
        value: f64,
        /// The largest magnitude the gain engine accepts.
        max: f64,
    },
    /// Not enough samples to determine the estimate.
    #[error("too few samples: {got} given, at least {needed} needed")]
    TooFewSamples {
        /// Samples required.
        needed: usize,
        /// Samples available.
        got: usize,
    },
    /// Fewer samples than a parameter asks for (a window longer than the series).
    #[error("{}", self.named(param.name()))]
    TooFewSamplesFor {
        /// The parameter that asks for them (a window).
        param: Param,
        /// Samples required (the parameter's value).
        needed: usize,
        /// Samples available.
        got: usize,
    },
    /// The data give no default for a parameter the caller left out (the default `τ`, the
    /// median time step, of rows with no step): the caller must give it.
    #[error("{}", self.named(param.name()))]
    NoDefault {
        /// The parameter left out.
        param: Param,
        /// Why the data give no default.
        why: String,
    },
    /// A sample of a batch ([`PolynomialFilter::update_many`](crate::PolynomialFilter::update_many))
    /// was rejected; the samples before it were processed, it and the rest were not.
    #[error("sample {index} of the batch: {source}")]
    InBatch {
        /// Position of the rejected sample in the batch.
        index: usize,
        /// Why it was rejected.
        source: Box<Error>,
    },
    /// A channel of a bank ([`StreamBank`](crate::polynomial::bank::StreamBank)) rejected its
    /// input; the other channels were processed.
    #[error("channel {channel}: {source}{}", also_failed_note(also_failed))]
    InChannel {
        /// The (first) failing channel.
        channel: usize,
        /// Why it was rejected.
        source: Box<Error>,
        /// Other channels of the same call that failed too (each stopped at its bad sample).
        also_failed: Vec<usize>,
    },
    /// No estimate: the samples so far do not determine the fit (too few of them, or weights
    /// that leave it singular).
    #[error("no estimate after {samples} samples: {why}")]
    NotDetermined {
        /// The samples processed.
        samples: u64,
        /// Why the fit is not determined, and what to change.
        why: String,
    },
    /// The estimate exists, but one of its numbers is beyond the double range (about 1.8e308)
    /// in the caller's units of time and value.
    #[error(
        "the estimate's {what} is beyond the double range (about 1.8e308) in these units: \
         express the times in a larger unit, rescale the values, or estimate nearer the samples"
    )]
    EstimateOutOfRange {
        /// The number: `d2` (the second derivative), `variance of d1`, `covariance of d0, d2`.
        what: String,
    },
    /// The observations do not determine the state: the (whitened) observation matrix `T` has
    /// rank below the state dimension (Morrison §8.9, Ex. 6.4).
    #[error(
        "the observations determine only {rank} of the {states} state components (smallest \
         singular value of the whitened T {smallest_singular_value:e}, largest \
         {largest_singular_value:e}): observe at more distinct times or add observations of \
         other kinds"
    )]
    Unobservable {
        /// The numerical rank of `T`.
        rank: usize,
        /// The state dimension (columns of `T`).
        states: usize,
        /// The smallest singular value.
        smallest_singular_value: f64,
        /// The largest singular value.
        largest_singular_value: f64,
    },
    /// Gauss–Newton differential correction (Morrison §8.7) did not settle: the correction was
    /// still above the tolerance after the allowed iterations.
    #[error(
        "differential correction did not converge in {iterations} iterations: the last \
         correction was {correction:e} of its own sigma (tolerance {tolerance:e}), chi-squared \
         {chi_squared:e}; start nearer the truth, shorten the window, or allow more iterations"
    )]
    NotConverged {
        /// Iterations done.
        iterations: usize,
        /// The last correction, `sqrt(dXᵀ S⁻¹ dX)`.
        correction: f64,
        /// The tolerance it had to meet.
        tolerance: f64,
        /// The residual chi-squared at the last estimate.
        chi_squared: f64,
    },
    /// Gauss–Newton differential correction diverged: no fraction of the correction (halved
    /// `halvings` times) lowered the weighted residual sum of squares (Morrison §8.6, step IX).
    #[error(
        "differential correction diverged at iteration {iteration}: chi-squared {chi_squared:e} \
         did not fall along the correction even when halved {halvings} times; the nominal \
         trajectory is too far from the data"
    )]
    Diverged {
        /// The iteration at which no step was accepted.
        iteration: usize,
        /// The chi-squared at the last accepted estimate.
        chi_squared: f64,
        /// Halvings tried.
        halvings: usize,
    },
    /// A Levenberg–Marquardt fit stopped short of a minimum: the evaluations allowed ran out,
    /// or no step lowered the residual sum of squares.
    #[error(
        "the Levenberg-Marquardt fit stopped after {evaluations} evaluations without converging \
         ({reason}); chi-squared {chi_squared:e} at its last estimate: start nearer the \
         solution, or check that the data determine the model's parameters"
    )]
    FitNotConverged {
        /// Model evaluations made.
        evaluations: usize,
        /// Why it stopped.
        reason: String,
        /// The residual chi-squared at the last estimate.
        chi_squared: f64,
    },
    /// A singular value decomposition did not converge within its iteration limit (entries
    /// of very different scales: rescale the data).
    #[error(
        "the singular value decomposition of a {rows}x{cols} matrix did not converge in \
         {iterations} iterations (its entries span too many orders of magnitude: rescale the \
         data)"
    )]
    SvdNotConverged {
        /// Rows of the matrix.
        rows: usize,
        /// Its columns.
        cols: usize,
        /// The iterations allowed.
        iterations: usize,
    },
    /// A symmetric eigendecomposition did not converge within its iteration limit.
    #[error(
        "the eigendecomposition of a symmetric {size}x{size} matrix did not converge in \
         {iterations} iterations"
    )]
    EigenNotConverged {
        /// Rows (and columns) of the matrix.
        size: usize,
        /// The iterations allowed.
        iterations: usize,
    },
    /// A saved state ([`crate::persist::from_bytes`]) that cannot be restored: truncated, a
    /// byte changed, another type's, a newer format, or a body whose numbers break the type's
    /// invariants.
    #[error("damaged saved state: {reason}")]
    DamagedState {
        /// What is wrong, in words.
        reason: String,
    },
    /// Some other parameter is out of range.
    #[error("{}", self.named(name.name()))]
    InvalidParameter {
        /// The parameter (its kind says whether it is a setting or the data).
        name: Param,
        /// Its value, as text.
        value: String,
        /// Why it is rejected.
        reason: String,
    },
}

/// What kind of failure an [`Error`](enum@Error) is: the front ends choose by it, the Python
/// exception class (`seqsmooth.errors`, named [`ErrorKind::name`] + `Error`) and the command's
/// exit code (2 for [`ErrorKind::Parameter`], as for a bad argument; 1 for the others).
///
/// ```
/// use seqsmooth::error::{Error, ErrorKind};
/// assert_eq!(Error::ThetaOutOfRange { theta: 2.0 }.kind(), ErrorKind::Parameter);
/// assert_eq!(Error::NonFinite { what: "value", value: f64::NAN }.kind(), ErrorKind::InvalidInput);
/// assert_eq!(ErrorKind::TooFewSamples.name(), "TooFewSamples");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ErrorKind {
    /// The data handed in: a sample, a timestamp, a row's component or σ, the arrays' lengths.
    InvalidInput,
    /// A setting out of its range: degree, θ, τ, a window, an engine, a σ, a model's shape.
    Parameter,
    /// Too few samples for what was asked.
    TooFewSamples,
    /// No estimate yet: the samples so far do not determine it.
    NotDetermined,
    /// A numerical failure on valid input: a number beyond the double range, a fit that did
    /// not converge, an unobservable state.
    Numerical,
    /// A saved state that cannot be restored (damaged, another type's, a newer format).
    DamagedState,
}

impl ErrorKind {
    /// Every kind, in the order of their declaration.
    pub const ALL: [ErrorKind; 6] = [
        ErrorKind::InvalidInput,
        ErrorKind::Parameter,
        ErrorKind::TooFewSamples,
        ErrorKind::NotDetermined,
        ErrorKind::Numerical,
        ErrorKind::DamagedState,
    ];

    /// The kind's name, the same in every front end (`InvalidInput`, `Parameter`,
    /// `TooFewSamples`, `NotDetermined`, `Numerical`, `DamagedState`).
    pub fn name(self) -> &'static str {
        match self {
            ErrorKind::InvalidInput => "InvalidInput",
            ErrorKind::Parameter => "Parameter",
            ErrorKind::TooFewSamples => "TooFewSamples",
            ErrorKind::NotDetermined => "NotDetermined",
            ErrorKind::Numerical => "Numerical",
            ErrorKind::DamagedState => "DamagedState",
        }
    }
}

impl Error {
    /// The error's [`ErrorKind`] (inside a batch or a channel, its cause's).
    pub fn kind(&self) -> ErrorKind {
        match self {
            // A sample's value beyond the gain engine's range is the data's (the command has
            // always reported it so, exit code 1), though the exact engine would take it.
            Error::NonFinite { .. }
            | Error::TimeNotIncreasing { .. }
            | Error::GainValueOutOfRange { .. } => ErrorKind::InvalidInput,
            Error::InvalidParameter { name, .. } => name.kind(),
            Error::NoDefault { .. } => ErrorKind::InvalidInput,
            Error::ThetaOutOfRange { .. }
            | Error::TauOutOfRange { .. }
            | Error::DegreeOutOfRange { .. }
            | Error::GainDegreeOutOfRange { .. } => ErrorKind::Parameter,
            Error::TooFewSamples { .. } | Error::TooFewSamplesFor { .. } => {
                ErrorKind::TooFewSamples
            }
            Error::NotDetermined { .. } => ErrorKind::NotDetermined,
            Error::InBatch { source, .. } | Error::InChannel { source, .. } => source.kind(),
            Error::EstimateOutOfRange { .. }
            | Error::Unobservable { .. }
            | Error::NotConverged { .. }
            | Error::Diverged { .. }
            | Error::FitNotConverged { .. }
            | Error::SvdNotConverged { .. }
            | Error::EigenNotConverged { .. } => ErrorKind::Numerical,
            Error::DamagedState { .. } => ErrorKind::DamagedState,
        }
    }
}

impl Error {
    /// The parameter the error names (inside a batch or a channel, its cause's): the one a
    /// front end names in its own words ([`Error::message_in`]).
    ///
    /// ```
    /// use seqsmooth::error::{Error, Param};
    /// assert_eq!(Error::ThetaOutOfRange { theta: 2.0 }.param(), Some(Param::Theta));
    /// assert_eq!(Error::TooFewSamples { needed: 3, got: 1 }.param(), None);
    /// ```
    pub fn param(&self) -> Option<Param> {
        match self {
            Error::ThetaOutOfRange { .. } => Some(Param::Theta),
            Error::TauOutOfRange { .. } => Some(Param::Tau),
            Error::DegreeOutOfRange { .. } | Error::GainDegreeOutOfRange { .. } => {
                Some(Param::Degree)
            }
            Error::InvalidParameter { name: param, .. }
            | Error::TooFewSamplesFor { param, .. }
            | Error::NoDefault { param, .. } => Some(*param),
            Error::InBatch { source, .. } | Error::InChannel { source, .. } => source.param(),
            _ => None,
        }
    }

    /// The message with the parameter it names ([`Error::param`]) spelled by `spell` (a front
    /// end's word for it: the command's flag, a Python keyword), or by its
    /// [`Param::name`] where `spell` gives none.
    ///
    /// ```
    /// use seqsmooth::error::{Error, Param};
    /// let e = Error::InBatch { index: 2, source: Box::new(Error::ThetaOutOfRange { theta: 2.0 }) };
    /// let flag = |p: Param| (p == Param::Theta).then_some("--theta");
    /// assert_eq!(
    ///     e.message_in(&flag),
    ///     "sample 2 of the batch: --theta 2 is out of range: it must lie strictly between 0 and 1"
    /// );
    /// let short = Error::TooFewSamplesFor { param: Param::Window, needed: 31, got: 30 };
    /// let scipy = |p: Param| (p == Param::Window).then_some("window_length");
    /// assert_eq!(
    ///     short.message_in(&scipy),
    ///     "too few samples for window_length 31: 30 given, at least 31 needed"
    /// );
    /// ```
    pub fn message_in(&self, spell: &dyn Fn(Param) -> Option<&'static str>) -> String {
        let message = self.to_string();
        let Some(word) = self.param().and_then(spell) else {
            return message;
        };
        // The cause's message stands whole inside its batch's or channel's.
        let mut cause = self;
        while let Error::InBatch { source, .. } | Error::InChannel { source, .. } = cause {
            cause = source;
        }
        message.replacen(&cause.to_string(), &cause.named(word), 1)
    }

    /// The message of an error that names a parameter, the parameter called `name`.
    fn named(&self, name: &str) -> String {
        match self {
            Error::ThetaOutOfRange { theta } => {
                format!("{name} {theta} is out of range: it must lie strictly between 0 and 1")
            }
            Error::TauOutOfRange { tau } => {
                format!("{name} {tau} is out of range: it must be a positive finite number")
            }
            Error::DegreeOutOfRange { degree, max } => {
                format!("{name} {degree} is out of range: the largest supported degree is {max}")
            }
            Error::GainDegreeOutOfRange { degree, max } => format!(
                "{name} {degree} is too high for the gain engine: it is supported to degree \
                 {max} (above it its fixed-gain recursion is numerically unstable on irregular \
                 timestamps); use the exact engine"
            ),
            Error::InvalidParameter { value, reason, .. } => {
                format!("{name} {value} is invalid: {reason}")
            }
            Error::TooFewSamplesFor { needed, got, .. } => {
                format!(
                    "too few samples for {name} {needed}: {got} given, at least {needed} needed"
                )
            }
            Error::NoDefault { why, .. } => {
                format!("the data give no default {name}: {why}; give {name}")
            }
            other => other.to_string(),
        }
    }
}

fn also_failed_note(others: &[usize]) -> String {
    if others.is_empty() {
        String::new()
    } else {
        format!(" (channels {others:?} failed as well)")
    }
}

/// Validates one sample of a stream: finite time and value, and a time strictly after the
/// previous one (when there is one).
///
/// ```
/// use seqsmooth::error::{check_sample, Error};
/// assert!(check_sample(1.0, 2.0, Some(0.5)).is_ok());
/// assert_eq!(check_sample(1.0, 2.0, Some(1.0)), Err(Error::TimeNotIncreasing { time: 1.0, previous: 1.0 }));
/// assert!(matches!(check_sample(f64::NAN, 2.0, None), Err(Error::NonFinite { what: "time", .. })));
/// ```
pub fn check_sample(t: f64, y: f64, previous: Option<f64>) -> Result<(), Error> {
    if !t.is_finite() {
        return Err(Error::NonFinite {
            what: "time",
            value: t,
        });
    }
    if !y.is_finite() {
        return Err(Error::NonFinite {
            what: "value",
            value: y,
        });
    }
    match previous {
        Some(previous) if t <= previous => Err(Error::TimeNotIncreasing { time: t, previous }),
        _ => Ok(()),
    }
}

/// The first non-finite number of `xs` as an [`Error::NonFinite`] naming it `what` (`"time"` or
/// `"value"`).
/// A degree's range `degree ≤ max` ([`Error::DegreeOutOfRange`]): the shape of every cap on a
/// degree (the filters', PAML's, the Gauss rules').
pub(crate) fn check_degree_at_most(degree: usize, max: usize) -> Result<(), Error> {
    if degree > max {
        return Err(Error::DegreeOutOfRange { degree, max });
    }
    Ok(())
}

pub(crate) fn check_finite(what: &'static str, xs: &[f64]) -> Result<(), Error> {
    match xs.iter().find(|x| !x.is_finite()) {
        Some(&value) => Err(Error::NonFinite { what, value }),
        None => Ok(()),
    }
}

/// One time per value, or an [`Error::InvalidParameter`] called `name` giving `reason`.
pub(crate) fn check_lengths(
    name: Param,
    times: &[f64],
    values: &[f64],
    reason: &str,
) -> Result<(), Error> {
    if times.len() != values.len() {
        return Err(Error::InvalidParameter {
            name,
            value: format!("{} times, {} values", times.len(), values.len()),
            reason: reason.into(),
        });
    }
    Ok(())
}
