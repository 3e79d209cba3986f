//! `seqsmooth track`: a radar's range, azimuth and elevation to a constant-velocity Cartesian
//! track, by the library's sliding Gauss–Newton fit (`estimate::sliding`), Kalman filter
//! (`kalman::KalmanFilter`, with driving noise or fading memory) or Kalman smoother
//! (`kalman::smooth`). The Kalman methods start from the first Gauss–Newton fit that
//! determines the state.
//!
//! Rows are read and checked one at a time (`track/rows.rs`: line and column in every
//! message; each component's noise σ from the row's σ column or the flag). The window, kalman
//! and fading methods stream: each row is tracked and its output row written as it is read, in
//! memory independent of the input's length. Reading, tracking and writing run on three threads
//! with a few batches of rows between them (`track/stream.rs`), so that parsing and formatting
//! overlap the tracking; the output is the one of taking the rows one at a time, byte for byte.
//! The rows before the first estimate are held, so that an input that never determines the
//! state writes nothing; the output file is a temporary file renamed onto the named one only
//! when every row is done ([`Output`]), so a failure leaves no output file. The smoother needs
//! every row before its first output: it keeps the rows after the start and smooths them at
//! the end.

mod rows;
mod stream;

use crate::args::{AzimuthConvention, FitModel, TrackArgs, TrackMethod};
use crate::error::CliError;
use crate::fit::window_error;
use crate::io::{check_distinct, open_input, write_f64, CsvIn, Need, Output};
use nalgebra::{DMatrix, DVector};
use rows::{Names, Rows, SigmaSource};
use seqsmooth::estimate::gauss_newton::{Correction, Epoch, Measurement};
use seqsmooth::estimate::sliding::{SlidingFit, Start};
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::kalman::{smooth, Discount, KalmanFilter};
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::radar::Radar;
use seqsmooth::Error;
use std::collections::VecDeque;
use stream::Block;

/// The window of the Kalman methods' start (the first fit that determines the state).
const START_WINDOW: usize = 60;

/// The output's header.
const HEADER: &[u8] = b"t,x,y,z,vx,vy,vz,sx,sy,sz,svx,svy,svz,nis\n";

/// Output bytes gathered before they are written.
const WRITE_BYTES: usize = 1 << 16;

/// One row's estimate: the state, its σ, and the NIS.
type Estimate = ([f64; 6], [f64; 6], Option<f64>);

/// One output row's numbers; `None` for empty cells.
type Cells = Option<Estimate>;

/// The filter of the Kalman methods.
type Filter = KalmanFilter<PolynomialDynamics, Radar>;

/// The sliding fit of the window method and of the Kalman methods' start.
type Fit = SlidingFit<PolynomialDynamics, Radar>;

/// Runs `seqsmooth track`.
pub fn run(a: &TrackArgs) -> Result<(), CliError> {
    let usage = |s: &str| Err(CliError::Usage(s.into()));
    match a.method {
        TrackMethod::Fading if a.beta.is_none() && a.theta.is_none() => {
            return usage(
                "--method fading needs --beta B (per unit of time) or --theta T (per update)",
            )
        }
        TrackMethod::Fading | TrackMethod::Window if a.q.is_some() => {
            return usage("--q applies only to --method kalman and smooth")
        }
        TrackMethod::Window | TrackMethod::Kalman | TrackMethod::Smooth
            if a.beta.is_some() || a.theta.is_some() =>
        {
            return usage("--beta and --theta apply only to --method fading")
        }
        _ => {}
    }
    if a.sigma_range.is_none() && a.sigma_range_col.is_none() {
        return usage(
            "track needs --sigma-range S (the range's noise sigma) or --sigma-range-col NAME \
             (a column of per-row sigmas; with both, the flag serves the rows whose cell is empty)",
        );
    }
    if a.sigma_angle.is_none() && a.sigma_angle_col.is_none() {
        return usage(
            "track needs --sigma-angle S (the azimuth's and elevation's noise sigma, in radians) \
             or --sigma-angle-col NAME (a column of per-row sigmas; with both, the flag serves \
             the rows whose cell is empty)",
        );
    }
    check_distinct(a.input.as_deref(), a.output.as_deref())?;
    let csv = CsvIn::new(open_input(a.input.as_deref())?)?;
    let need = Need::rows(2, "a radar track");
    need.check_header(&csv.header)?;
    let names = Names {
        time: &a.time_col,
        range: &a.range_col,
        azimuth: &a.azimuth_col,
        elevation: &a.elevation_col,
    };
    let sigmas = [
        SigmaSource {
            flag: a.sigma_range,
            column: a.sigma_range_col.clone(),
            flag_name: "--sigma-range",
        },
        SigmaSource {
            flag: a.sigma_angle,
            column: a.sigma_angle_col.clone(),
            flag_name: "--sigma-angle",
        },
    ];
    let bearing = a.azimuth == AzimuthConvention::Bearing;
    let rows = Rows::new(csv, &names, sigmas, bearing)?;
    let radar = Radar::new(a.site, 6).map_err(|e| CliError::Usage(e.to_string()))?;
    let mut tracker = Tracker::new(a, radar)?;
    stream::run(rows, &mut tracker, a.output.as_deref(), &need)
}

/// The output: rows gathered in a buffer, written in blocks once the state is determined (the
/// rows before are held, and never written if it never is).
struct Writer<'a> {
    path: Option<&'a std::path::Path>,
    out: Option<Output>,
    text: Vec<u8>,
}

impl<'a> Writer<'a> {
    fn new(path: Option<&'a std::path::Path>) -> Self {
        Self {
            path,
            out: None,
            text: HEADER.to_vec(),
        }
    }

    /// Appends the row of time cell `t` and `cells`; creates the output at the first
    /// determined row.
    #[inline]
    fn row(&mut self, t: &[u8], cells: &Cells) -> Result<(), CliError> {
        let text = &mut self.text;
        text.extend_from_slice(t);
        match cells {
            Some((x, s, nis)) => {
                for v in x.iter().chain(s) {
                    text.push(b',');
                    write_f64(text, *v);
                }
                text.push(b',');
                if let Some(nis) = nis {
                    write_f64(text, *nis);
                }
            }
            None => text.extend_from_slice(&[b','; 13]),
        }
        text.push(b'\n');
        if cells.is_some() && self.out.is_none() {
            self.out = Some(Output::create(self.path)?);
        }
        if let Some(out) = &mut self.out {
            if self.text.len() >= WRITE_BYTES {
                out.write(&self.text)?;
                self.text.clear();
            }
        }
        Ok(())
    }

    /// After an error: the rows gathered go to standard output (or a device), which shows
    /// every row before the error; a file's temporary file is removed unrenamed.
    fn abandon(mut self) {
        if let Some(out) = &mut self.out {
            // The error being reported matters more than one writing it.
            let _ = out.write(&self.text);
        }
    }

    /// Writes what is left and completes the output; refuses an input whose `rows` never
    /// determined the state.
    fn finish(self, rows: usize) -> Result<(), CliError> {
        let Some(mut out) = self.out else {
            return Err(CliError::Data(format!(
                "the input's {rows} rows never determine the state: a radar track needs two \
                 rows with range, azimuth and elevation"
            )));
        };
        out.write(&self.text)?;
        out.finish()
    }
}

/// What a row gives: its output row now, or later ([`Tracker::finish`], the smoother).
enum Step {
    Row(Cells),
    Held,
}

/// What the method keeps between rows.
enum Stage {
    /// The Kalman methods before the state is determined: the start's fit over the rows so
    /// far, and their lines.
    Starting(Box<Fit>, VecDeque<u64>),
    /// kalman and fading: the filter.
    Filtering(Box<Filter>),
    /// smooth: the filter at the start, and the rows after it.
    Smoothing(Box<Filter>, Held),
    /// window: the fit over the last rows, their lines, and the previous row's estimate.
    Window(Box<Fit>, VecDeque<u64>, Option<Correction>),
}

/// The rows the smoother holds: their measurements, lines and time cells (one buffer).
#[derive(Default)]
struct Held {
    measurements: Vec<Measurement>,
    lines: Vec<u64>,
    text: Vec<u8>,
    ends: Vec<usize>,
}

/// The chosen method's settings and state.
struct Tracker {
    method: TrackMethod,
    radar: Radar,
    dynamics: PolynomialDynamics,
    window: usize,
    q: f64,
    discount: Option<Discount>,
    stage: Stage,
}

impl Tracker {
    fn new(a: &TrackArgs, radar: Radar) -> Result<Self, CliError> {
        let discount = match (a.beta, a.theta) {
            (Some(b), _) => Some(Discount::PerTime(b)),
            (_, Some(t)) => Some(Discount::PerUpdate(t)),
            _ => None,
        };
        let dynamics = PolynomialDynamics::new(1, 3);
        let stage = match a.method {
            TrackMethod::Window => Stage::Window(
                Box::new(sliding(dynamics, radar, a.window)?),
                VecDeque::with_capacity(a.window.min(1 << 16)),
                None,
            ),
            _ => Stage::Starting(
                Box::new(sliding(dynamics, radar, START_WINDOW)?),
                VecDeque::with_capacity(START_WINDOW),
            ),
        };
        Ok(Self {
            method: a.method,
            radar,
            dynamics,
            window: a.window,
            q: a.q.unwrap_or(0.0),
            discount,
            stage,
        })
    }

    /// Tracks the row `m` of file line `line` and time cell `t`.
    fn push(&mut self, m: &Measurement, line: u64, t: &[u8]) -> Result<Step, CliError> {
        match &mut self.stage {
            Stage::Filtering(filter) => {
                let innovation = filter.update_stats(m).map_err(|e| {
                    CliError::Data(format!("line {line}: the filter's update failed: {e}"))
                })?;
                Ok(Step::Row(Some(cells(
                    filter.state(),
                    filter.covariance(),
                    innovation.map(|i| i.nis),
                ))))
            }
            Stage::Smoothing(_, held) => {
                held.measurements.push(m.clone());
                held.lines.push(line);
                held.text.extend_from_slice(t);
                held.ends.push(held.text.len());
                Ok(Step::Held)
            }
            Stage::Starting(fit, lines) => {
                if lines.len() == START_WINDOW {
                    lines.pop_front();
                }
                lines.push_back(line);
                let c = fit
                    .push(m.clone())
                    .map_err(|e| window_error(e, lines, START_WINDOW, FitModel::Radar))?;
                let Some(c) = c else {
                    return Ok(Step::Row(None));
                };
                let filter = Box::new(self.filter_from(&c)?);
                self.stage = if self.method == TrackMethod::Smooth {
                    Stage::Smoothing(filter, Held::default())
                } else {
                    Stage::Filtering(filter)
                };
                Ok(Step::Row(Some(cells(&c.state, &c.covariance, None))))
            }
            Stage::Window(..) => self.window_step(m, line),
        }
    }

    /// The window method's row: the fit of the last rows, and the row's innovation against
    /// the previous row's fit.
    fn window_step(&mut self, m: &Measurement, line: u64) -> Result<Step, CliError> {
        let nis = match &self.stage {
            Stage::Window(_, _, Some(p)) => self
                .filter_from(p)?
                .update_stats(m)
                .ok()
                .flatten()
                .map(|i| i.nis),
            _ => None,
        };
        let Stage::Window(fit, lines, previous) = &mut self.stage else {
            return Ok(Step::Held);
        };
        if lines.len() == self.window {
            lines.pop_front();
        }
        lines.push_back(line);
        let c = fit
            .push(m.clone())
            .map_err(|e| window_error(e, lines, self.window, FitModel::Radar))?;
        let row = c.as_ref().map(|c| cells(&c.state, &c.covariance, nis));
        *previous = c;
        Ok(Step::Row(row))
    }

    /// The rows held to the end (the smoother's), smoothed.
    fn finish(&mut self) -> Result<Option<Block>, CliError> {
        let Stage::Smoothing(filter, held) = &mut self.stage else {
            return Ok(None);
        };
        let held = std::mem::take(held);
        let at = |i: usize| held.lines[i];
        let smoothed = smooth((**filter).clone(), &held.measurements).map_err(|e| match e {
            Error::InBatch { index, source } => {
                CliError::Data(format!("line {}: {source}", at(index)))
            }
            e => CliError::Data(format!("the smoother failed: {e}")),
        })?;
        let cells = smoothed
            .iter()
            .map(|s| Some(Some(cells(&s.state, &s.covariance, s.nis))))
            .collect();
        Ok(Some(Block::Rows {
            text: held.text,
            ends: held.ends,
            cells,
        }))
    }

    /// A Kalman filter from a fit, with the method's driving noise or fading.
    fn filter_from(&self, c: &Correction) -> Result<Filter, CliError> {
        let library = |e: Error| CliError::Data(format!("cannot start the filter: {e}"));
        let f = KalmanFilter::new(
            self.dynamics,
            self.radar,
            c.state.clone(),
            c.covariance.clone(),
            c.epoch,
        )
        .map_err(library)?;
        match (self.method, self.discount) {
            (TrackMethod::Fading, Some(d)) => f.with_fading(d).map_err(library),
            (TrackMethod::Window, _) => Ok(f),
            _ => f
                .with_process_noise(WhiteNoiseDerivative::new(1, 3, self.q).map_err(library)?)
                .map_err(library),
        }
    }
}

/// The sliding fit over `window` rows, started as the radar's nominal (§8.5).
fn sliding(dynamics: PolynomialDynamics, radar: Radar, window: usize) -> Result<Fit, CliError> {
    SlidingFit::new(
        dynamics,
        radar,
        window,
        Epoch::End,
        Start::Radar { radar, degree: 2 },
    )
    .map_err(|e| CliError::Usage(e.to_string()))
}

/// A row's cells from a state and covariance.
fn cells(x: &DVector<f64>, s: &DMatrix<f64>, nis: Option<f64>) -> Estimate {
    let mut state = [0.0; 6];
    let mut sigma = [0.0; 6];
    for k in 0..6 {
        state[k] = x[k];
        sigma[k] = s[(k, k)].max(0.0).sqrt();
    }
    (state, sigma, nis)
}
