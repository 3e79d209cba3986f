//! `seqsmooth track`: a radar's range, azimuth and elevation to a constant-velocity Cartesian
//! track, by the library's sliding Gauss–Newton fit (`estimate::sliding`), Kalman filter
//! (`kalman::KalmanFilter`, with driving noise or fading memory) or Kalman smoother
//! (`kalman::fixed_lag`). The Kalman methods start from the first Gauss–Newton fit that
//! determines the state.
//!
//! Rows are read and checked one at a time (`shared/radar_rows.rs`: line and column in every
//! message; each component's noise σ from the row's σ column or the flag). The window, kalman
//! and fading methods stream: each row is tracked and its output row written as it is read, in
//! memory independent of the input's length. Reading, tracking and writing run on three threads
//! with a few batches of rows between them (`track/stream.rs`), so that parsing and formatting
//! overlap the tracking; the output is the one of taking the rows one at a time, byte for byte.
//! The rows before the first estimate are held, so that an input that never determines the
//! state writes nothing; the output file is a temporary file renamed onto the named one only
//! when every row is done ([`Output`]), so a failure leaves no output file. The smoother
//! streams with its lag: it holds the last `--lag` rows (their time cells and lines here, their
//! filter's states in the library) and writes each row when the row `--lag` later is in, the
//! last ones at the end.

mod stream;

use crate::args::{FitModel, TrackArgs, TrackMethod};
use crate::commands::shared::radar_rows::{self as rows, Rows};
use crate::commands::shared::window::window_error;
use crate::error::CliError;
use crate::io::{check_distinct, open_input, write_f64, CsvIn, Need, Output};
use nalgebra::{DMatrix, DVector};
use seqsmooth::estimate::gauss_newton::GaussNewton;
use seqsmooth::estimate::gauss_newton::Measurement;
use seqsmooth::kalman::Discount;
use seqsmooth::model::radar::Radar;
use seqsmooth::numeric::sigma::std_dev;
use seqsmooth::track::{
    RadarTracker, TrackError, TrackFlag, TrackMethod as Method, Tracked, DEFAULT_LAG,
    DEFAULT_WINDOW, START_WINDOW,
};
use seqsmooth::Error;
use std::collections::VecDeque;
use stream::Block;

/// The output's header.
const HEADER: &[u8] = b"t,x,y,z,vx,vy,vz,sx,sy,sz,svx,svy,svz,nis,flag\n";

/// The smoother's memory bound above which the command says it before the first row.
const HELD_NOTE_BYTES: usize = 100_000_000;

/// Output bytes gathered before they are written.
const WRITE_BYTES: usize = 1 << 16;

/// One row's estimate: the state, its σ, the NIS and the flag.
type Estimate = ([f64; 6], [f64; 6], Option<f64>, TrackFlag);

/// One output row's numbers; `None` for empty cells.
type Cells = Option<Estimate>;

/// Runs `seqsmooth track`.
pub fn run(a: &TrackArgs) -> Result<(), CliError> {
    let usage = |s: &str| Err(CliError::Usage(s.into()));
    match a.method {
        TrackMethod::Fading | TrackMethod::Window if a.q.is_some() => {
            return usage("--q applies only to --method kalman and smooth")
        }
        TrackMethod::Window | TrackMethod::Kalman | TrackMethod::Smooth
            if a.theta.is_some() || a.theta_per_update.is_some() =>
        {
            return usage("--theta, --tau and --theta-per-update apply only to --method fading")
        }
        TrackMethod::Kalman | TrackMethod::Fading | TrackMethod::Smooth if a.window.is_some() => {
            return usage("--window applies only to --method window")
        }
        TrackMethod::Window | TrackMethod::Kalman | TrackMethod::Fading if a.lag.is_some() => {
            return usage("--lag applies only to --method smooth")
        }
        _ => {}
    }
    rows::check_sigmas(&a.radar, "track")?;
    check_distinct(a.input.as_deref(), a.output.as_deref())?;
    let csv = CsvIn::new(open_input(a.input.as_deref())?)?;
    let need = Need::rows(2, "a radar track");
    need.check_header(&csv.header)?;
    let rows = Rows::of(csv, &a.time_col, &a.radar)?;
    let radar = Radar::new(a.radar.site, 6).map_err(CliError::from)?;
    let mut tracker = Tracker::new(a, radar)?;
    let (held, bytes) = tracker.inner.held_bound();
    if bytes > HELD_NOTE_BYTES {
        eprintln!(
            "seqsmooth track: --lag {} holds up to {held} rows: up to {:.0} MB of memory \
             (a smaller --lag takes less)",
            held - 1,
            bytes as f64 / 1e6
        );
    }
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
            Some((x, s, nis, flag)) => {
                for v in x.iter().chain(s) {
                    text.push(b',');
                    write_f64(text, *v);
                }
                text.push(b',');
                if let Some(nis) = nis {
                    write_f64(text, *nis);
                }
                text.push(b',');
                text.extend_from_slice(flag.name().as_bytes());
            }
            None => text.extend_from_slice(&[b','; 14]),
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

/// What a row gives: its output row now, or later (the smoother's, [`Tracker::given`] and
/// [`Tracker::finish`]).
enum Step {
    Row(Cells),
    Held,
}

/// The rows the smoother holds (at most its lag): their lines and time cells' lengths, their
/// time cells (one ring of bytes), and the tracker's number of the first.
#[derive(Default)]
struct Held {
    first: usize,
    rows: VecDeque<(u64, usize)>,
    text: VecDeque<u8>,
}

impl Held {
    /// Holds row `row` of file line `line` and time cell `t`.
    fn hold(&mut self, row: usize, line: u64, t: &[u8]) {
        if self.rows.is_empty() {
            self.first = row;
        }
        self.rows.push_back((line, t.len()));
        self.text.extend(t);
    }

    /// Moves the first held row, row `row`, into `out` with `cells`.
    fn give(&mut self, row: usize, cells: Estimate, out: &mut Given) {
        assert_eq!(row, self.first, "the smoother gives its rows in order");
        let (_, len) = self.rows.pop_front().expect("the row given is held");
        out.text.extend(self.text.drain(..len));
        out.ends.push(out.text.len());
        out.cells.push(Some(Some(cells)));
        self.first += 1;
    }

    /// The file line of the tracker's row `row`: a held row's, else `current`'s.
    fn line(&self, row: usize, current: u64) -> u64 {
        row.checked_sub(self.first)
            .and_then(|k| self.rows.get(k))
            .map_or(current, |r| r.0)
    }
}

/// The rows the smoother gave since they were last sent, as the writer takes them.
#[derive(Default)]
struct Given {
    text: Vec<u8>,
    ends: Vec<usize>,
    cells: Vec<Option<Cells>>,
}

impl Given {
    /// The rows as a block for the writer, if there are any; empties `self`.
    fn take(&mut self) -> Option<Block> {
        if self.ends.is_empty() {
            return None;
        }
        let given = std::mem::take(self);
        Some(Block::Rows {
            text: given.text,
            ends: given.ends,
            cells: given.cells,
        })
    }
}

/// The library's tracker, with the file lines of the last rows (for its messages), the rows
/// the smoother holds and those it gave.
struct Tracker {
    inner: RadarTracker,
    /// The lines of the last `keep` rows, the latest last (enough for any window).
    lines: VecDeque<u64>,
    keep: usize,
    held: Held,
    given: Given,
}

impl Tracker {
    fn new(a: &TrackArgs, radar: Radar) -> Result<Self, CliError> {
        let method = match a.method {
            TrackMethod::Window => Method::Window {
                window: a.window.unwrap_or(DEFAULT_WINDOW),
            },
            TrackMethod::Kalman => Method::Kalman { q: a.q },
            TrackMethod::Smooth => Method::Smooth {
                q: a.q,
                lag: a.lag.unwrap_or(DEFAULT_LAG),
            },
            TrackMethod::Fading => Method::Fading(
                Discount::from_names(a.theta, a.tau, a.theta_per_update)
                    .map_err(|e| CliError::Usage(e.to_string()))?,
            ),
        };
        let solver = GaussNewton::with_max_iterations(a.max_iterations).map_err(CliError::from)?;
        let model = a
            .model
            .with_parameters(a.manoeuvre_alpha, a.manoeuvre_variance, a.turn_rate_noise)
            .map_err(CliError::from)?;
        let inner =
            RadarTracker::with_model(radar, method, model, solver).map_err(CliError::from)?;
        let keep = match method {
            Method::Window { window } => window,
            _ => START_WINDOW,
        };
        Ok(Self {
            inner,
            lines: VecDeque::with_capacity(keep.min(1 << 16)),
            keep,
            held: Held::default(),
            given: Given::default(),
        })
    }

    /// Tracks the row `m` of file line `line` and time cell `t`.
    fn push(&mut self, m: &Measurement, line: u64, t: &[u8]) -> Result<Step, CliError> {
        if self.lines.len() == self.keep {
            self.lines.pop_front();
        }
        self.lines.push_back(line);
        let row = self.inner.rows();
        match self.inner.push(m) {
            Ok(Tracked::Undetermined) => Ok(Step::Row(None)),
            Ok(Tracked::Estimate(e)) => {
                Ok(Step::Row(Some(cells(e.state, e.covariance, e.nis, e.flag))))
            }
            Ok(Tracked::Held) => {
                self.held.hold(row, line, t);
                Ok(Step::Held)
            }
            Ok(Tracked::Smoothed {
                row: given,
                estimate: s,
                flag,
            }) => {
                let c = cells(&s.state, &s.covariance, s.nis, flag);
                self.held.hold(row, line, t);
                self.held.give(given, c, &mut self.given);
                Ok(Step::Held)
            }
            Err(TrackError::Smooth(Error::InBatch { index, source })) => {
                let at = self.held.line(index, line);
                Err(CliError::from(*source).reworded(|m| format!("line {at}: {m}")))
            }
            Err(TrackError::Window { rows, source }) => {
                let lines: VecDeque<u64> = self
                    .lines
                    .iter()
                    .skip(self.lines.len().saturating_sub(rows.len()))
                    .copied()
                    .collect();
                Err(window_error(source, &lines, rows.len(), FitModel::Radar))
            }
            Err(TrackError::Update { source, .. }) => Err(CliError::from(source)
                .reworded(|m| format!("line {line}: the filter's update failed: {m}"))),
            Err(e) => Err(tracker_error(e)),
        }
    }

    /// The rows the smoother gave since the last call, for the writer.
    fn given(&mut self) -> Option<Block> {
        self.given.take()
    }

    /// The rows held to the end (the smoother's last), smoothed, after those given before.
    fn finish(&mut self) -> Result<Option<Block>, CliError> {
        let held = &mut self.held;
        let smoothed = self.inner.finish().map_err(|e| match e {
            TrackError::Smooth(Error::InBatch { index, source }) => {
                let at = held.line(index, 0);
                CliError::from(*source).reworded(|m| format!("line {at}: {m}"))
            }
            e => tracker_error(e),
        })?;
        for (row, s, flag) in smoothed {
            let c = cells(&s.state, &s.covariance, s.nis, flag);
            held.give(row, c, &mut self.given);
        }
        Ok(self.given.take())
    }
}

/// A row's cells from a state and covariance.
fn cells(x: &DVector<f64>, s: &DMatrix<f64>, nis: Option<f64>, flag: TrackFlag) -> Estimate {
    let mut state = [0.0; 6];
    let mut sigma = [0.0; 6];
    for k in 0..6 {
        state[k] = x[k];
        sigma[k] = std_dev(s[(k, k)]);
    }
    (state, sigma, nis, flag)
}

/// The tracker's error `e` as the command's: its exit code by its cause's kind (the one
/// `From<seqsmooth::Error>`), its message the tracker's.
fn tracker_error(e: TrackError) -> CliError {
    let message = e.to_string();
    let (TrackError::Window { source, .. }
    | TrackError::Start(source)
    | TrackError::Update { source, .. }
    | TrackError::Smooth(source)) = e;
    CliError::from(source).reworded(|_| message)
}
