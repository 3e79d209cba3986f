//! A radar track: range, azimuth and elevation ([`Radar`]) to a Cartesian state
//! `(x, y, z, ẋ, ẏ, ż, …)` of one of the built-in motion models ([`model`]: constant velocity by
//! default, constant acceleration, Singer, the coordinated turn), by one of four methods:
//!
//! | method | each row's estimate | source |
//! |---|---|---|
//! | [`TrackMethod::Window`] | the Gauss–Newton fit of the last `W` rows (warm started), its innovation against the previous row's fit | §8.5-8.7 ([`SlidingFit`]) |
//! | [`TrackMethod::Kalman`] | the extended Kalman filter, white noise of density `q` driving the acceleration | ch. 12, (15.2.23) |
//! | [`TrackMethod::Fading`] | the extended Kalman filter with fading memory (`θ` per span `τ` of time or `θ` per update, [`Discount`]), its true covariance | ch. 14 |
//! | [`TrackMethod::Smooth`] | the Rauch–Tung–Striebel smoother over the Kalman filter's run with a lag of `L` rows: each row's estimate from the `L` rows after it, given `L` rows later | [`crate::kalman::fixed_lag`] |
//!
//! The Kalman methods start from the first Gauss–Newton fit of the rows so far (at most
//! [`START_WINDOW`]) that determines the state, started at the radar nominal of §8.5; that
//! row's estimate is the fit's. The rows before give no estimate. This is the one tracker of
//! the `seqsmooth track` command and of the Python binding.
//!
//! Every estimate comes with a [`TrackFlag`]: the Kalman methods test each update's NIS and
//! the NIS of the last few against χ² (Morrison §14.8, [`adaptive`]): a lone update
//! beyond the gate is an outlier, left out (the row's estimate is the prediction); a window
//! beyond its χ² is a misfit (a manoeuvre the model does not follow), flagged. Without a given
//! driving noise (`q: None`) or discount (`Fading(None)`) the memory is adaptive: each misfit
//! shortens it (a larger `q`, a smaller `θ`), quiet updates lengthen it again; the driving
//! noise starts at `q₀ = σ_r² / T³` (the range's noise variance over the cube of the start's
//! mean step: a tracking index of 1), the discount at `θ₀ = 0.9` per update. The window
//! method gates each row likewise, on its NIS against the previous window's estimate (a lone
//! row beyond the gate takes its place in the window unmeasured), tests each window's
//! residual χ² against its degrees of freedom (§8.6) and carries
//! the misfit in its covariance, scaled by `max(1, χ²/ν)` ([`misfit_scale`](crate::estimate::sliding::misfit_scale)); a window beyond
//! `χ²_ν` at `1 − MISFIT_ALPHA` is flagged.

pub mod adaptive;
mod memory;
pub mod model;

use crate::discount::Discount;
use crate::error::{Error, Param};
use crate::estimate::gauss_newton::{
    check_max_iterations, Correction, Epoch, GaussNewton, Measurement,
};
use crate::estimate::sliding::{SlidingFit, Start};
use crate::kalman::filter::KalmanFilter;
use crate::kalman::fixed_lag::FixedLagSmoother;
use crate::kalman::noise::check_psd;
use crate::kalman::smoother::Smoothed;
use crate::model::dynamics::PolynomialDynamics;
use crate::model::radar::{check_component, from_bearing, Radar};
pub use adaptive::TrackFlag;
use adaptive::{Monitor, MISFIT_ALPHA};
use memory::{base_noise, Filter, Memory, MemoryKind};
use model::TrackDynamics;
pub use model::{
    MotionModel, DEFAULT_MANOEUVRE_ALPHA, DEFAULT_TURN_RATE_NOISE, TURN_RATE_PRIOR_SIGMA,
};
use nalgebra::{DMatrix, DVector};
use std::collections::VecDeque;
use std::ops::Range;

/// The state components every row reports, whatever the model: position and velocity
/// `(x, y, z, ẋ, ẏ, ż)`, the first six of every model's state ([`model`]), with their
/// covariance block.
pub const REPORTED: usize = 6;

/// The window of the Kalman methods' start: the first fit of at most this many last rows that
/// determines the state.
pub const START_WINDOW: usize = 60;

/// The window method's rows per fit when none is given: the radar fit's
/// [`RADAR_WINDOW`](crate::estimate::sliding::RADAR_WINDOW).
pub const DEFAULT_WINDOW: usize = crate::estimate::sliding::RADAR_WINDOW;

/// The adaptive fading filter's discount per update at level 0 (a memory of about 19 updates).
pub const DEFAULT_THETA: f64 = 0.9;

/// The adaptive levels: the driving noise `q₀ 4^ℓ` for `ℓ` in `NOISE_LEVELS`, the discount
/// `1 − (1 − θ₀) 2^ℓ` for `ℓ` in `FADING_LEVELS`.
const NOISE_LEVELS: (i32, i32) = (-6, 14);
const FADING_LEVELS: (i32, i32) = (-4, 3);
/// The smoother's default lag, in rows ([`TrackMethod::Smooth`]).
pub const DEFAULT_LAG: usize = 200;

/// How rows become estimates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TrackMethod {
    /// The fit of the last `window` rows at each row.
    Window {
        /// `W`, the rows of each fit (2 or more).
        window: usize,
    },
    /// The extended Kalman filter with white noise of spectral density `q` (distance²/time³)
    /// driving each axis's acceleration; 0 for none, `None` for the adaptive driving noise.
    Kalman {
        /// `q ≥ 0`, or `None`: adaptive.
        q: Option<f64>,
    },
    /// The extended Kalman filter with fading memory; `None` for the adaptive discount.
    Fading(Option<Discount>),
    /// The fixed-lag smoother over the Kalman filter's run (driving noise `q`, `None` adaptive
    /// as for [`TrackMethod::Kalman`]: the forward filter gated and adapted as that one):
    /// each row's estimate from the `lag` rows after it, given when the `lag`-th comes
    /// ([`Tracked::Smoothed`]); the last `lag` rows' at [`RadarTracker::finish`], from every
    /// row. `lag` 0 is the filter; a lag at least the rows' number the whole-interval smoother.
    Smooth {
        /// `q ≥ 0`, or `None`: adaptive.
        q: Option<f64>,
        /// `L`, in rows ([`DEFAULT_LAG`] by default): the smoother holds `L + 1` rows.
        lag: usize,
    },
}

impl TrackMethod {
    /// The method named `kalman`, `fading`, `smooth` or `window` at its defaults: adaptive
    /// driving noise, adaptive discount, [`DEFAULT_WINDOW`] rows.
    ///
    /// ```
    /// use seqsmooth::track::{TrackMethod, DEFAULT_WINDOW};
    /// assert_eq!(TrackMethod::named("window"), Some(TrackMethod::Window { window: DEFAULT_WINDOW }));
    /// assert_eq!(TrackMethod::named("kalman"), Some(TrackMethod::Kalman { q: None }));
    /// assert_eq!(TrackMethod::named("other"), None);
    /// ```
    pub fn named(name: &str) -> Option<Self> {
        Some(match name {
            "kalman" => TrackMethod::Kalman { q: None },
            "fading" => TrackMethod::Fading(None),
            "smooth" => TrackMethod::Smooth {
                q: None,
                lag: DEFAULT_LAG,
            },
            "window" => TrackMethod::Window {
                window: DEFAULT_WINDOW,
            },
            _ => return None,
        })
    }
}

/// Why a row (or the end) failed.
#[derive(Debug, thiserror::Error)]
pub enum TrackError {
    /// The Gauss–Newton fit of the window of rows `rows` (the failing row last) failed; an
    /// [`Error::InBatch`] index in `source` counts within the window.
    #[error("rows {}-{} (the window): {source}", rows.start, rows.end.saturating_sub(1))]
    Window {
        /// The rows of the window, counted from the tracker's first (0).
        rows: Range<usize>,
        /// The fit's error.
        source: Error,
    },
    /// The Kalman filter could not start from the first fit.
    #[error("cannot start the filter: {0}")]
    Start(Error),
    /// The filter's update of row `row` failed.
    #[error("row {row}: the filter's update failed: {source}")]
    Update {
        /// The row, counted from the tracker's first (0).
        row: usize,
        /// The update's error.
        source: Error,
    },
    /// The smoother failed; an [`Error::InBatch`] index counts from the tracker's first row.
    #[error("the smoother failed: {0}")]
    Smooth(Error),
}

/// A row's estimate, borrowed from the tracker until its next row.
#[derive(Clone, Copy, Debug)]
pub struct TrackEstimate<'a> {
    /// The model's state at the row's time, `(x, y, z, ẋ, ẏ, ż)` first ([`REPORTED`]).
    pub state: &'a DVector<f64>,
    /// Its covariance.
    pub covariance: &'a DMatrix<f64>,
    /// The row's normalised innovation squared against the prediction from the row before
    /// (`None` at the start, or where it could not be formed).
    pub nis: Option<f64>,
    /// How the estimate stands: [`TrackFlag::None`], or why its σ may not cover its error.
    pub flag: TrackFlag,
}

/// What a row gave.
#[derive(Clone, Copy, Debug)]
pub enum Tracked<'a> {
    /// No estimate: the rows so far do not determine the state.
    Undetermined,
    /// The row's estimate.
    Estimate(TrackEstimate<'a>),
    /// Held by the smoother, which gives no row yet (its first `lag` rows; the rest come at
    /// [`RadarTracker::finish`]).
    Held,
    /// Held by the smoother, which gives the estimate of the earlier row `row` (`lag` rows
    /// back), from the rows up to this one.
    Smoothed {
        /// The row given, counted from the tracker's first (0).
        row: usize,
        /// Its smoothed estimate (`nis` the forward filter's at that row, also where the gate
        /// left the row out).
        estimate: &'a Smoothed,
        /// The forward pass's flag of that row.
        flag: TrackFlag,
    },
}

/// The memory of `method` and `model` for a filter started from the fit over `rows` (the
/// adaptive `q₀` from their steps and range noise, [`base_noise`]; Singer's variance where
/// given, else adaptive).
fn memory_of<'a, I: Iterator<Item = &'a Measurement>>(
    method: TrackMethod,
    model: MotionModel,
    rows: impl Fn() -> I,
) -> Result<Memory, Error> {
    let fixed = match (method, model) {
        (_, MotionModel::Singer { variance, .. }) => variance,
        (TrackMethod::Kalman { q } | TrackMethod::Smooth { q, .. }, _) => q,
        _ => None,
    };
    let (kind, adaptive, levels) = match method {
        TrackMethod::Kalman { .. } | TrackMethod::Smooth { .. } if fixed.is_some() => {
            (MemoryKind::Noise(fixed.unwrap_or(0.0)), false, (0, 0))
        }
        TrackMethod::Kalman { .. } | TrackMethod::Smooth { .. } => {
            let q0 = base_noise(rows(), model.noise_degree());
            let q0 = model.adaptive_base(q0, base_noise(rows(), 1));
            (MemoryKind::Noise(q0), true, NOISE_LEVELS)
        }
        TrackMethod::Fading(Some(d)) => (MemoryKind::Fading(d), false, (0, 0)),
        TrackMethod::Fading(None) => (
            MemoryKind::Fading(Discount::PerUpdate {
                theta: DEFAULT_THETA,
            }),
            true,
            FADING_LEVELS,
        ),
        TrackMethod::Window { .. } => (MemoryKind::Noise(0.0), false, (0, 0)),
    };
    Memory::new(model, kind, adaptive, levels)
}

/// The smooth method's forward pass: the fixed-lag smoother, the memory that gates and adapts
/// its filter (as the kalman method's), and the NIS and flag of each row the smoother holds,
/// oldest first (its ring's rows: at most `lag + 1`).
#[derive(Clone, Debug)]
struct Lagged {
    smoother: FixedLagSmoother<TrackDynamics, Radar>,
    memory: Memory,
    held: VecDeque<(Option<f64>, TrackFlag)>,
}

/// What the method keeps between rows.
#[derive(Clone, Debug)]
enum Stage {
    /// The Kalman methods before the state is determined: the start's fit.
    Starting(Box<SlidingFit<PolynomialDynamics, Radar>>),
    /// kalman and fading: the filter and its memory, and the start's fit for the row that
    /// made it.
    Filtering(Box<(Filter, Memory)>, Option<Correction>),
    /// smooth: the fixed-lag smoother over the rows after the start and its memory, the
    /// start's fit, its row, and the row the last push gave.
    Smoothing(
        Box<Lagged>,
        Option<Correction>,
        usize,
        Option<(usize, Smoothed, TrackFlag)>,
    ),
    /// smooth after [`RadarTracker::finish`]: no more rows.
    Finished,
    /// window: the fit over the last rows, the previous row's estimate, and the outlier gate
    /// on the row's innovation against it.
    Window(
        Box<SlidingFit<PolynomialDynamics, Radar>>,
        Option<Correction>,
        Box<Monitor>,
    ),
}

/// A radar's rows to a track, row by row.
///
/// ```
/// use seqsmooth::model::measurement::NoiseCovariance;
/// use seqsmooth::model::measurement::Measurement;
/// use seqsmooth::track::{RadarTracker, TrackFlag, TrackMethod, Tracked};
/// use seqsmooth::model::radar::Radar;
/// // A target at (1000, 2000, 500) moving at (10, -5, 0) per second, seen exactly.
/// let radar = Radar::new([0.0; 3], 6).unwrap();
/// let mut tracker = RadarTracker::new(radar, TrackMethod::Kalman { q: Some(0.0) }).unwrap();
/// let mut last = None;
/// for k in 0..10 {
///     let t = k as f64;
///     let (x, y, z) = (1000.0 + 10.0 * t, 2000.0 - 5.0 * t, 500.0);
///     let r = (x * x + y * y + z * z).sqrt();
///     let m = Measurement {
///         time: t,
///         values: vec![Some(r), Some(y.atan2(x)), Some((z / r).asin())],
///         noise: NoiseCovariance::Variances(vec![1.0, 1e-6, 1e-6]),
///     };
///     if let Tracked::Estimate(e) = tracker.push(&m).unwrap() {
///         last = Some((e.state[3], e.flag));
///     }
/// }
/// let (vx, flag) = last.unwrap();
/// assert!((vx - 10.0).abs() < 1e-6 && flag == TrackFlag::None);
/// ```
#[derive(Clone, Debug)]
pub struct RadarTracker {
    method: TrackMethod,
    model: MotionModel,
    /// The radar of the model's state (the filters').
    radar: Radar,
    dynamics: TrackDynamics,
    stage: Stage,
    /// The rows taken so far.
    rows: usize,
    /// The last row's time.
    last_time: f64,
}

impl RadarTracker {
    /// A tracker of `radar`'s rows (a six-state radar: [`Radar::new`] with 6) by `method`,
    /// its Gauss–Newton fits with [`GaussNewton::default`]'s limits.
    pub fn new(radar: Radar, method: TrackMethod) -> Result<Self, Error> {
        Self::with_solver(radar, method, GaussNewton::default())
    }

    /// [`Self::new`] with the Gauss–Newton limits of every fit (the window method's, the
    /// Kalman methods' start): `max_iterations` is `seqsmooth track --max-iterations`.
    ///
    /// ```
    /// use seqsmooth::estimate::gauss_newton::GaussNewton;
    /// use seqsmooth::track::{RadarTracker, TrackMethod};
    /// use seqsmooth::model::radar::Radar;
    /// let radar = Radar::new([0.0; 3], 6).unwrap();
    /// let limits = GaussNewton { max_iterations: 100, ..GaussNewton::default() };
    /// assert!(RadarTracker::with_solver(radar, TrackMethod::Window { window: 20 }, limits).is_ok());
    /// let none = GaussNewton { max_iterations: 0, ..GaussNewton::default() };
    /// assert!(RadarTracker::with_solver(radar, TrackMethod::Window { window: 20 }, none).is_err());
    /// ```
    pub fn with_solver(
        radar: Radar,
        method: TrackMethod,
        solver: GaussNewton,
    ) -> Result<Self, Error> {
        Self::with_model(radar, method, MotionModel::ConstantVelocity, solver)
    }

    /// [`Self::with_solver`] with the motion `model` ([`model`]) of the Kalman methods: the
    /// window method fits constant velocity only, and refuses any other model; Singer's
    /// driving noise is its manoeuvre variance (a `q` is refused with it, and with the
    /// fading method, which has no driving noise, a variance or a turn rate noise). `radar` is the six-state radar
    /// of constant velocity; the filters' has the model's states.
    ///
    /// ```
    /// use seqsmooth::estimate::gauss_newton::GaussNewton;
    /// use seqsmooth::track::{MotionModel, RadarTracker, TrackMethod};
    /// use seqsmooth::model::radar::Radar;
    /// let radar = Radar::new([0.0; 3], 6).unwrap();
    /// let turn = MotionModel::named("coordinated-turn").unwrap();
    /// let kalman = TrackMethod::Kalman { q: None };
    /// assert!(RadarTracker::with_model(radar, kalman, turn, GaussNewton::default()).is_ok());
    /// let window = TrackMethod::Window { window: 8 };
    /// assert!(RadarTracker::with_model(radar, window, turn, GaussNewton::default()).is_err());
    /// ```
    pub fn with_model(
        radar: Radar,
        method: TrackMethod,
        model: MotionModel,
        solver: GaussNewton,
    ) -> Result<Self, Error> {
        model.check()?;
        model.check_method(method)?;
        let dynamics = model.dynamics()?;
        check_max_iterations(solver.max_iterations)?;
        let fit_radar = match model.start_degree() {
            1 => radar,
            degree => Radar::new(radar.site(), 3 * (degree + 1))?,
        };
        let start = |solver| sliding(fit_radar, model.start_degree(), START_WINDOW, solver);
        let stage = match method {
            TrackMethod::Window { window } => {
                if window < 2 {
                    return Err(Error::InvalidParameter {
                        name: Param::Window,
                        value: window.to_string(),
                        reason: "a radar track's fit needs at least 2 rows (6 states, 3 \
                                 components a row)"
                            .into(),
                    });
                }
                Stage::Window(
                    Box::new(sliding(radar, 1, window, solver)?),
                    None,
                    Box::new(Monitor::new(3, false, 0, 0)?),
                )
            }
            TrackMethod::Kalman { q } | TrackMethod::Smooth { q, .. } => {
                if let Some(q) = q {
                    check_psd(q)?;
                }
                Stage::Starting(Box::new(start(solver)?))
            }
            TrackMethod::Fading(d) => {
                if let Some(d) = d {
                    d.checked()?;
                }
                Stage::Starting(Box::new(start(solver)?))
            }
        };
        let radar = Radar::new(radar.site(), model.dimension())?;
        Ok(Self {
            method,
            model,
            radar,
            dynamics,
            stage,
            rows: 0,
            last_time: f64::NEG_INFINITY,
        })
    }

    /// The method.
    pub fn method(&self) -> TrackMethod {
        self.method
    }

    /// The motion model.
    pub fn model(&self) -> MotionModel {
        self.model
    }

    /// The rows taken so far.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Tracks the next row (after the previous one in time: a row at or before it is refused
    /// as [`TrackError::Update`]). A refused row is not taken, and the tracker is as before it.
    pub fn push(&mut self, m: &Measurement) -> Result<Tracked<'_>, TrackError> {
        let row = self.rows;
        if m.time <= self.last_time {
            return Err(TrackError::Update {
                row,
                source: Error::InvalidParameter {
                    name: Param::Time,
                    value: m.time.to_string(),
                    reason: format!("must be after the previous row's time {}", self.last_time),
                },
            });
        }
        let window = |w: usize, source: Error| TrackError::Window {
            rows: (row + 1).saturating_sub(w)..row + 1,
            source,
        };
        // The row taken: `None` held, else `Some((nis, flag))`; the estimate is borrowed below.
        let taken = match &mut self.stage {
            Stage::Starting(fit) => {
                let Some(mut c) = fit.push(m.clone()).map_err(|e| window(START_WINDOW, e))? else {
                    self.rows += 1;
                    self.last_time = m.time;
                    return Ok(Tracked::Undetermined);
                };
                self.model.extend(&mut c);
                let memory = memory_of(self.method, self.model, || fit.measurements());
                let started = memory.and_then(|memory| {
                    let mut f = filter_from(self.dynamics.clone(), self.radar, &c)?;
                    memory.apply(&mut f)?;
                    Ok((f, memory))
                });
                let (filter, memory) = started.map_err(TrackError::Start)?;
                self.stage = if let TrackMethod::Smooth { lag, .. } = self.method {
                    let lagged = Lagged {
                        smoother: FixedLagSmoother::new(filter, lag),
                        memory,
                        held: VecDeque::new(),
                    };
                    Stage::Smoothing(Box::new(lagged), Some(c), row, None)
                } else {
                    Stage::Filtering(Box::new((filter, memory)), Some(c))
                };
                Some((None, TrackFlag::None))
            }
            Stage::Window(fit, previous, gate) => {
                let stats = match previous {
                    Some(p) => filter_from(self.dynamics.clone(), self.radar, p)
                        .map_err(TrackError::Start)?
                        .update_stats(m)
                        .ok()
                        .flatten(),
                    None => None,
                };
                // The gate: a lone row beyond it takes its place in the window unmeasured.
                let used = stats.is_none_or(|s| gate.accepts(s.nis, s.components));
                let mut taken = m.clone();
                if !used {
                    taken.values.iter_mut().for_each(|v| *v = None);
                }
                let w = fit.window();
                let fitted = fit.push(taken).map_err(|e| window(w, e))?;
                if let Some(s) = stats {
                    gate.record(s.nis, s.components, used);
                }
                *previous = fitted;
                let flag = match previous {
                    _ if !used => TrackFlag::Outlier,
                    Some(c) => window_flag(c),
                    None => TrackFlag::None,
                };
                Some((stats.map(|s| s.nis), flag))
            }
            Stage::Filtering(kalman, start) => {
                let (filter, memory) = &mut **kalman;
                let taken = memory
                    .step(filter, m)
                    .map_err(|source| TrackError::Update { row, source })?;
                *start = None;
                Some(taken)
            }
            Stage::Finished => {
                return Err(TrackError::Update {
                    row,
                    source: Error::InvalidParameter {
                        name: Param::Row,
                        value: row.to_string(),
                        reason: "comes after finish(): the smoother has given its estimates".into(),
                    },
                })
            }
            Stage::Smoothing(lagged, start, first, given) => {
                let first = *first + 1;
                let Lagged {
                    smoother,
                    memory,
                    held,
                } = &mut **lagged;
                let (out, nis, flag) = memory.step_smoother(smoother, m).map_err(|e| match e {
                    // The backward pass's (the updates' errors are not in a batch).
                    Error::InBatch { .. } => smoothing_error(e, first),
                    source => TrackError::Update { row, source },
                })?;
                held.push_back((nis, flag));
                *given = out.map(|mut s| {
                    let (nis, flag) = held.pop_front().expect("the row given is held");
                    s.nis = nis;
                    (row - smoother.held(), s, flag)
                });
                debug_assert_eq!(held.len(), smoother.held());
                *start = None;
                None
            }
        };
        self.rows += 1;
        self.last_time = m.time;
        let Some((nis, flag)) = taken else {
            return Ok(match &self.stage {
                Stage::Smoothing(.., Some((row, estimate, flag))) => Tracked::Smoothed {
                    row: *row,
                    estimate,
                    flag: *flag,
                },
                _ => Tracked::Held,
            });
        };
        let (state, covariance) = match &self.stage {
            Stage::Window(_, Some(c), _)
            | Stage::Filtering(_, Some(c))
            | Stage::Smoothing(_, Some(c), ..) => (&c.state, &c.covariance),
            Stage::Filtering(kalman, None) => (kalman.0.state(), kalman.0.covariance()),
            _ => return Ok(Tracked::Undetermined),
        };
        Ok(Tracked::Estimate(TrackEstimate {
            state,
            covariance,
            nis,
            flag,
        }))
    }

    /// The smoother's estimates of the rows it still holds (its last `lag` rows, each with
    /// its row and the forward pass's flag), smoothed by every row; nothing for the other
    /// methods. The smoother takes no more rows after it. A row the gate left out has its
    /// NIS here (the forward update's, which left it out).
    pub fn finish(&mut self) -> Result<Vec<(usize, Smoothed, TrackFlag)>, TrackError> {
        let stage = std::mem::replace(&mut self.stage, Stage::Finished);
        let Stage::Smoothing(lagged, _, start, _) = stage else {
            self.stage = stage;
            return Ok(Vec::new());
        };
        let Lagged { smoother, held, .. } = *lagged;
        let first = start + 1 + smoother.pushed() - smoother.held();
        let smoothed = smoother
            .finish()
            .map_err(|e| smoothing_error(e, start + 1))?;
        Ok(smoothed
            .into_iter()
            .zip(held)
            .enumerate()
            .map(|(k, (mut s, (nis, flag)))| {
                s.nis = nis;
                (first + k, s, flag)
            })
            .collect())
    }

    /// The rows the smoother holds at most (`lag + 1`; 0 for the other methods), and the
    /// bytes they take: a bound of the tracker's memory beyond a few kilobytes, known before
    /// the first row.
    pub fn held_bound(&self) -> (usize, usize) {
        match self.method {
            TrackMethod::Smooth { lag, .. } => {
                let rows = lag.saturating_add(1);
                let n = self.model.dimension();
                let each = FixedLagSmoother::<TrackDynamics, Radar>::bytes_per_measurement(n)
                    + std::mem::size_of::<(Option<f64>, TrackFlag)>();
                (rows, rows.saturating_mul(each))
            }
            _ => (0, 0),
        }
    }
}

/// The smoother's error, an [`Error::InBatch`] index (counted from its first row, the tracker's
/// `first`) counted from the tracker's first row.
fn smoothing_error(e: Error, first: usize) -> TrackError {
    TrackError::Smooth(match e {
        Error::InBatch { index, source } => Error::InBatch {
            index: first + index,
            source,
        },
        e => e,
    })
}

/// A window fit's flag (the window method's, `seqsmooth fit --model radar`'s):
/// [`TrackFlag::Misfit`] where its residual χ² lies above the `1 − MISFIT_ALPHA` point of
/// `χ²_ν`, `ν` its degrees of freedom (§8.6; no test with `ν = 0`): the model does not follow
/// the window's rows. Its covariance carries the misfit too ([`misfit_scale`](crate::estimate::sliding::misfit_scale)).
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::estimate::gauss_newton::Correction;
/// use seqsmooth::track::{window_flag, TrackFlag};
/// let c = Correction { epoch: 0.0, state: DVector::zeros(6), covariance: DMatrix::identity(6, 6),
///     chi_squared: 40.0, degrees_of_freedom: 18, condition_number: 1.0, iterations: vec![] };
/// assert_eq!(window_flag(&c), TrackFlag::Misfit); // the 99% point of χ²(18) is 34.8
/// assert_eq!(window_flag(&Correction { chi_squared: 30.0, ..c }), TrackFlag::None);
/// ```
pub fn window_flag(c: &Correction) -> TrackFlag {
    let misfit = c.degrees_of_freedom > 0
        && crate::stats::chi_squared_quantile(c.degrees_of_freedom as f64, 1.0 - MISFIT_ALPHA)
            .is_ok_and(|limit| c.chi_squared > limit);
    if misfit {
        TrackFlag::Misfit
    } else {
        TrackFlag::None
    }
}

/// A Kalman filter (no driving noise, no fading) from a fit.
fn filter_from(dynamics: TrackDynamics, radar: Radar, c: &Correction) -> Result<Filter, Error> {
    KalmanFilter::new(
        dynamics,
        radar,
        c.state.clone(),
        c.covariance.clone(),
        c.epoch,
    )
}

/// The sliding fit of the polynomial model of `degree` on three axes over `window` rows
/// (`radar` of its states), started at the radar's nominal (§8.5), with `solver`'s limits and
/// the misfit carried in its covariance ([`misfit_scale`](crate::estimate::sliding::misfit_scale)).
fn sliding(
    radar: Radar,
    degree: usize,
    window: usize,
    solver: GaussNewton,
) -> Result<SlidingFit<PolynomialDynamics, Radar>, Error> {
    Ok(SlidingFit::new(
        PolynomialDynamics::new(degree, 3),
        radar,
        window,
        Epoch::End,
        Start::Radar { radar, degree: 2 },
    )?
    .with_solver(solver)
    .with_misfit_scale())
}

/// A radar row as a [`Measurement`], checked as `seqsmooth track` checks its rows: the time
/// finite; each of range, azimuth and elevation missing (`None`) or in range (the range above
/// 0, the azimuth within `[−2π, 2π]`, the elevation within `[−π/2, π/2]`, radians); the σ of
/// each present component (`sigma_range`, `sigma_angle` for both angles) above 0 with a normal
/// double square. With `bearing` the azimuth is a bearing (from +y, clockwise, x east and y
/// north) and is turned into the angle from +x.
///
/// ```
/// use seqsmooth::track::radar_row;
/// let m = radar_row(0.0, [Some(1000.0), Some(0.0), None], Some(5.0), Some(1e-3), true).unwrap();
/// assert!((m.values[1].unwrap() - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
/// assert!(radar_row(0.0, [Some(-1.0), None, None], Some(5.0), None, false).is_err());
/// ```
pub fn radar_row(
    time: f64,
    values: [Option<f64>; 3],
    sigma_range: Option<f64>,
    sigma_angle: Option<f64>,
    bearing: bool,
) -> Result<Measurement, Error> {
    if !time.is_finite() {
        return Err(Error::NonFinite {
            what: "time",
            value: time,
        });
    }
    for (k, v) in values.iter().enumerate() {
        if let Some(v) = *v {
            check_component(k, v).map_err(|why| Error::InvalidParameter {
                name: [Param::Range, Param::Azimuth, Param::Elevation][k],
                value: v.to_string(),
                reason: why.into(),
            })?;
        }
    }
    let needed = [
        (Param::SigmaRange, sigma_range, values[0].is_some()),
        (
            Param::SigmaAngle,
            sigma_angle,
            values[1].is_some() || values[2].is_some(),
        ),
    ];
    let mut variances = [1.0; 2];
    for (k, (name, sigma, needed)) in needed.into_iter().enumerate() {
        match sigma {
            Some(s) if crate::model::measurement::is_usable_sigma(s) => variances[k] = s * s,
            Some(s) => {
                return Err(Error::InvalidParameter {
                    name,
                    value: s.to_string(),
                    reason: "must be above 0 with a normal double square (the noise variance)"
                        .into(),
                })
            }
            None if needed => {
                return Err(Error::InvalidParameter {
                    name,
                    value: "none".into(),
                    reason: "is needed: the row has a component it weighs".into(),
                })
            }
            None => {}
        }
    }
    let mut values = values;
    if bearing {
        values[1] = values[1].map(from_bearing);
    }
    Ok(Measurement {
        time,
        values: values.to_vec(),
        noise: crate::model::measurement::NoiseCovariance::Variances(vec![
            variances[0],
            variances[1],
            variances[1],
        ]),
    })
}
