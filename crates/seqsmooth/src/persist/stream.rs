//! The saved state of a stream of series filtered with one [`FilterSpec`]: the options it was
//! made with, each series' id and filter, and the rows a front end formatted but could not write
//! yet (the automatic filter's rows waiting for their outlier decision). A stream cut into
//! pieces, each run from the state the previous one saved, gives the rows of the unbroken run
//! (`seqsmooth filter --state FILE`).
//!
//! ```
//! use seqsmooth::persist::stream::{StreamOptions, StreamState};
//! use seqsmooth::persist::{from_bytes, to_bytes};
//! use seqsmooth::polynomial::spec::{FilterKind, FilterSpec};
//! use seqsmooth::PolynomialFilter;
//! let spec = FilterSpec { theta: Some(0.9), tau: Some(1.0), ..FilterSpec::new(FilterKind::Fading, 1) };
//! let mut f = spec.build()?;
//! f.update_many(&[0.0, 1.0, 2.0], &[1.0, 2.0, 3.0])?;
//! let options = StreamOptions::of(&spec, 0.0, false);
//! let state = StreamState { options: options.clone(), ids: vec![], filters: vec![f], pending: vec![] };
//! let back: StreamState = from_bytes(&to_bytes(&state)?)?;
//! back.check_options(&options)?; // the same options: resumed
//! let other = StreamOptions { theta: Some(0.8), ..options };
//! assert!(back.check_options(&other).unwrap_err().to_string().contains("theta"));
//! # Ok::<(), seqsmooth::Error>(())
//! ```

use super::Persist;
use crate::error::{Error, Param};
use crate::polynomial::spec::{AnyFilter, FilterKind, FilterSpec};
use crate::polynomial::{Engine, PolynomialFilter};
use serde::{Deserialize, Serialize};

/// The options of a filtered stream that its rows depend on: a state is resumed only with the
/// same ones.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StreamOptions {
    /// The filter kind.
    pub kind: FilterKind,
    /// The polynomial degree.
    pub degree: usize,
    /// The discount `θ` (fading memory, automatic).
    pub theta: Option<f64>,
    /// The time `θ` applies to, resolved (given or the default of the first rows).
    pub tau: Option<f64>,
    /// The fixed memory's window.
    pub window: Option<usize>,
    /// The engine.
    pub engine: Engine,
    /// The noise σ.
    pub sigma: Option<f64>,
    /// The automatic filter's review window.
    pub review_window: Option<usize>,
    /// The lead `H` of every row's estimate.
    pub lead: f64,
    /// Whether the rows are told apart by an id (many series) or are one series.
    pub series: bool,
}

impl StreamOptions {
    /// The options of `spec` (its `τ` resolved) with `lead`, over many series or one.
    pub fn of(spec: &FilterSpec, lead: f64, series: bool) -> Self {
        Self {
            kind: spec.kind,
            degree: spec.degree,
            theta: spec.theta,
            tau: spec.tau,
            window: spec.window,
            engine: spec.engine,
            sigma: spec.sigma,
            review_window: spec.review_window,
            lead,
            series,
        }
    }
}

/// A row formatted by a front end and not written yet: its series, its bytes, the byte offset
/// of its outlier cell while undecided, and whether it waits for that decision.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PendingRow {
    /// The row's series (index into [`StreamState::filters`]).
    pub series: usize,
    /// The formatted row.
    pub bytes: Vec<u8>,
    /// The byte offset of its outlier cell while the decision is to come.
    pub cell: Option<usize>,
    /// Waiting for the decision.
    pub waiting: bool,
}

/// The saved state of a filtered stream (see the module doc); saved and read by
/// [`to_bytes`](super::to_bytes) / [`from_bytes`](super::from_bytes).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StreamState {
    /// The options the stream was filtered with.
    pub options: StreamOptions,
    /// Each series' id (with [`StreamOptions::series`]), in order of first appearance.
    pub ids: Vec<Vec<u8>>,
    /// Each series' filter, in the same order (one, or none yet, for a single series).
    pub filters: Vec<AnyFilter>,
    /// Rows formatted and not written yet, in output order.
    pub pending: Vec<PendingRow>,
}

/// Formats an option's value for a message.
fn shown(v: &Option<f64>) -> String {
    v.map_or("none".into(), |v| format!("{v}"))
}

impl StreamState {
    /// Refuses `given` options that are not the state's, naming the first that differs
    /// ([`Error::InvalidParameter`]: its parameter, the value given and the state's); the kind,
    /// engine and id column are [`Param::Configuration`].
    pub fn check_options(&self, given: &StreamOptions) -> Result<(), Error> {
        let s = &self.options;
        let differs = |name: Param, value: String, saved: String| {
            Err(Error::InvalidParameter {
                name,
                value,
                reason: format!(
                    "the saved state was made with {saved}; resume with the options it was made \
                     with, or start a new state"
                ),
            })
        };
        if s.kind != given.kind {
            let (a, b) = (given.kind.name(), s.kind.name());
            return differs(
                Param::Configuration,
                format!("kind {a}"),
                format!("kind {b}"),
            );
        }
        if s.engine != given.engine {
            let (a, b) = (format!("{:?}", given.engine), format!("{:?}", s.engine));
            return differs(
                Param::Configuration,
                format!("engine {a}"),
                format!("engine {b}"),
            );
        }
        if s.series != given.series {
            let what = |many: bool| if many { "an id column" } else { "no id column" };
            return differs(
                Param::Configuration,
                what(given.series).into(),
                what(s.series).into(),
            );
        }
        let pairs = [
            (
                Param::Degree,
                Some(given.degree as f64),
                Some(s.degree as f64),
            ),
            (Param::Theta, given.theta, s.theta),
            (Param::Tau, given.tau, s.tau),
            (
                Param::Window,
                given.window.map(|w| w as f64),
                s.window.map(|w| w as f64),
            ),
            (Param::Sigma, given.sigma, s.sigma),
            (
                Param::ReviewWindow,
                given.review_window.map(|w| w as f64),
                s.review_window.map(|w| w as f64),
            ),
            (Param::Lead, Some(given.lead), Some(s.lead)),
        ];
        for (name, a, b) in pairs {
            if a.map(f64::to_bits) != b.map(f64::to_bits) {
                return differs(name, shown(&a), format!("{} {}", name.name(), shown(&b)));
            }
        }
        Ok(())
    }

    /// The invariants of a decoded state: every filter's own, of the state's kind and degree,
    /// one per id (at most one without ids), and pending rows of known series with their cell
    /// inside them.
    pub(crate) fn check_saved(&mut self) -> Result<(), String> {
        let o = &self.options;
        for f in &mut self.filters {
            Persist::check(f)?;
            if f.kind() != o.kind || f.degree() != o.degree {
                return Err("filter of another kind or degree than the options".into());
            }
        }
        let series_ok = if o.series {
            self.ids.len() == self.filters.len()
        } else {
            self.ids.is_empty() && self.filters.len() <= 1
        };
        if !series_ok {
            return Err(format!(
                "{} ids for {} filters",
                self.ids.len(),
                self.filters.len()
            ));
        }
        let finite = [o.theta, o.tau, o.sigma, Some(o.lead)];
        if finite.iter().flatten().any(|v| !v.is_finite()) {
            return Err("options hold a number that is not finite".into());
        }
        for r in &self.pending {
            let cell_ok = r.cell.is_none_or(|c| c < r.bytes.len());
            if r.series >= self.filters.len() || !cell_ok {
                return Err("pending row of an unknown series or cell".into());
            }
        }
        Ok(())
    }
}

impl Persist for StreamState {
    fn name() -> String {
        "StreamState".into()
    }

    fn check(&mut self) -> Result<(), String> {
        self.check_saved()
    }
}
