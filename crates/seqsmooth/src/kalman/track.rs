//! A radar track: range, azimuth and elevation ([`Radar`]) to a constant-velocity Cartesian
//! state `(x, y, z, ẋ, ẏ, ż)`, by one of four methods over the same models:
//!
//! | method | each row's estimate | source |
//! |---|---|---|
//! | [`TrackMethod::Window`] | the Gauss–Newton fit of the last `W` rows (warm started), its innovation against the previous row's fit | §8.5-8.7 ([`SlidingFit`]) |
//! | [`TrackMethod::Kalman`] | the extended Kalman filter, white noise of density `q` driving the acceleration | ch. 12, (15.2.23) |
//! | [`TrackMethod::Fading`] | the extended Kalman filter with fading memory (`β` per time or `θ` per update), its true covariance | ch. 14 |
//! | [`TrackMethod::Smooth`] | the Rauch–Tung–Striebel smoother over the Kalman filter's run with a lag of `L` rows: each row's estimate from the `L` rows after it, given `L` rows later | [`super::fixed_lag`] |
//!
//! The Kalman methods start from the first Gauss–Newton fit of the rows so far (at most
//! [`START_WINDOW`]) that determines the state, started at the radar nominal of §8.5; that
//! row's estimate is the fit's. The rows before give no estimate. This is the one tracker of
//! the `seqsmooth track` command and of the Python binding.

use super::filter::{Discount, KalmanFilter};
use super::fixed_lag::FixedLagSmoother;
use super::noise::WhiteNoiseDerivative;
use super::smoother::Smoothed;
use crate::error::Error;
use crate::estimate::gauss_newton::{Correction, Epoch, Measurement};
use crate::estimate::sliding::{SlidingFit, Start};
use crate::model::dynamics::PolynomialDynamics;
use crate::model::radar::Radar;
use nalgebra::{DMatrix, DVector};
use std::ops::Range;

/// The window of the Kalman methods' start: the first fit of at most this many last rows that
/// determines the state.
pub const START_WINDOW: usize = 60;

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
    /// driving each axis's acceleration; 0 for none.
    Kalman {
        /// `q ≥ 0`.
        q: f64,
    },
    /// The extended Kalman filter with fading memory.
    Fading(Discount),
    /// The fixed-lag smoother over the Kalman filter's run (driving noise `q`): each row's
    /// estimate from the `lag` rows after it, given when the `lag`-th comes
    /// ([`Tracked::Smoothed`]); the last `lag` rows' at [`RadarTracker::finish`], from every
    /// row. `lag` 0 is the filter; a lag at least the rows' number the whole-interval smoother.
    Smooth {
        /// `q ≥ 0`.
        q: f64,
        /// `L`, in rows ([`DEFAULT_LAG`] by default): the smoother holds `L + 1` rows.
        lag: usize,
    },
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
    /// `X = (x, y, z, ẋ, ẏ, ż)` at the row's time.
    pub state: &'a DVector<f64>,
    /// Its covariance.
    pub covariance: &'a DMatrix<f64>,
    /// The row's normalised innovation squared against the prediction from the row before
    /// (`None` at the start, or where it could not be formed).
    pub nis: Option<f64>,
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
        /// Its smoothed estimate (`nis` the forward filter's at that row).
        estimate: &'a Smoothed,
    },
}

/// The filter of the Kalman methods.
type Filter = KalmanFilter<PolynomialDynamics, Radar>;

/// What the method keeps between rows.
#[derive(Clone, Debug)]
enum Stage {
    /// The Kalman methods before the state is determined: the start's fit.
    Starting(Box<SlidingFit<PolynomialDynamics, Radar>>),
    /// kalman and fading: the filter, and the start's fit for the row that made it.
    Filtering(Box<Filter>, Option<Correction>),
    /// smooth: the fixed-lag smoother over the rows after the start, the start's fit, its
    /// row, and the row the last push gave.
    Smoothing(
        Box<FixedLagSmoother<PolynomialDynamics, Radar>>,
        Option<Correction>,
        usize,
        Option<(usize, Smoothed)>,
    ),
    /// smooth after [`RadarTracker::finish`]: no more rows.
    Finished,
    /// window: the fit over the last rows, and the previous row's estimate.
    Window(
        Box<SlidingFit<PolynomialDynamics, Radar>>,
        Option<Correction>,
    ),
}

/// A radar's rows to a track, row by row.
///
/// ```
/// use seqsmooth::estimate::batch::NoiseCovariance;
/// use seqsmooth::estimate::gauss_newton::Measurement;
/// use seqsmooth::kalman::track::{RadarTracker, TrackMethod, Tracked};
/// use seqsmooth::model::radar::Radar;
/// // A target at (1000, 2000, 500) moving at (10, -5, 0) per second, seen exactly.
/// let radar = Radar::new([0.0; 3], 6).unwrap();
/// let mut tracker = RadarTracker::new(radar, TrackMethod::Kalman { q: 0.0 }).unwrap();
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
///         last = Some(e.state[3]);
///     }
/// }
/// assert!((last.unwrap() - 10.0).abs() < 1e-6);
/// ```
#[derive(Clone, Debug)]
pub struct RadarTracker {
    method: TrackMethod,
    radar: Radar,
    dynamics: PolynomialDynamics,
    stage: Stage,
    /// The rows taken so far.
    rows: usize,
    /// The last row's time.
    last_time: f64,
}

impl RadarTracker {
    /// A tracker of `radar`'s rows (a six-state radar: [`Radar::new`] with 6) by `method`.
    pub fn new(radar: Radar, method: TrackMethod) -> Result<Self, Error> {
        let dynamics = PolynomialDynamics::new(1, 3);
        let check = |name: &'static str, value: f64| {
            if value.is_finite() && value >= 0.0 {
                Ok(())
            } else {
                Err(Error::InvalidParameter {
                    name,
                    value: value.to_string(),
                    reason: "must be a finite number at least 0".into(),
                })
            }
        };
        let stage = match method {
            TrackMethod::Window { window } => {
                if window < 2 {
                    return Err(Error::InvalidParameter {
                        name: "window",
                        value: window.to_string(),
                        reason: "a radar track's fit needs at least 2 rows (6 states, 3 \
                                 components a row)"
                            .into(),
                    });
                }
                Stage::Window(Box::new(sliding(dynamics, radar, window)?), None)
            }
            TrackMethod::Kalman { q } | TrackMethod::Smooth { q, .. } => {
                check("q", q)?;
                Stage::Starting(Box::new(sliding(dynamics, radar, START_WINDOW)?))
            }
            TrackMethod::Fading(d) => {
                d.checked()?;
                Stage::Starting(Box::new(sliding(dynamics, radar, START_WINDOW)?))
            }
        };
        Ok(Self {
            method,
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
                    name: "time",
                    value: m.time.to_string(),
                    reason: format!("must be after the previous row's time {}", self.last_time),
                },
            });
        }
        let window = |w: usize, source: Error| TrackError::Window {
            rows: (row + 1).saturating_sub(w)..row + 1,
            source,
        };
        // The row taken: `None` held, else `Some(nis)`; the estimate is borrowed below.
        let nis = match &mut self.stage {
            Stage::Starting(fit) => {
                let Some(c) = fit.push(m.clone()).map_err(|e| window(START_WINDOW, e))? else {
                    self.rows += 1;
                    self.last_time = m.time;
                    return Ok(Tracked::Undetermined);
                };
                let filter = filter_from(self.dynamics, self.radar, self.method, &c);
                let filter = Box::new(filter.map_err(TrackError::Start)?);
                self.stage = if let TrackMethod::Smooth { lag, .. } = self.method {
                    let smoother = FixedLagSmoother::new(*filter, lag);
                    Stage::Smoothing(Box::new(smoother), Some(c), row, None)
                } else {
                    Stage::Filtering(filter, Some(c))
                };
                Some(None)
            }
            Stage::Window(fit, previous) => {
                let nis = match previous {
                    Some(p) => filter_from(self.dynamics, self.radar, self.method, p)
                        .map_err(TrackError::Start)?
                        .update_stats(m)
                        .ok()
                        .flatten()
                        .map(|i| i.nis),
                    None => None,
                };
                let w = fit.window();
                *previous = fit.push(m.clone()).map_err(|e| window(w, e))?;
                Some(nis)
            }
            Stage::Filtering(filter, start) => {
                let innovation = filter
                    .update_stats(m)
                    .map_err(|source| TrackError::Update { row, source })?;
                *start = None;
                Some(innovation.map(|i| i.nis))
            }
            Stage::Finished => {
                return Err(TrackError::Update {
                    row,
                    source: Error::InvalidParameter {
                        name: "row",
                        value: row.to_string(),
                        reason: "comes after finish(): the smoother has given its estimates".into(),
                    },
                })
            }
            Stage::Smoothing(smoother, start, first, given) => {
                let first = *first + 1;
                let out = smoother.push(m).map_err(|e| match e {
                    // The backward pass's (push's update errors are not in a batch).
                    Error::InBatch { .. } => smoothing_error(e, first),
                    source => TrackError::Update { row, source },
                })?;
                *given = out.map(|s| (row - smoother.held(), s));
                *start = None;
                None
            }
        };
        self.rows += 1;
        self.last_time = m.time;
        let Some(nis) = nis else {
            return Ok(match &self.stage {
                Stage::Smoothing(.., Some((row, estimate))) => Tracked::Smoothed {
                    row: *row,
                    estimate,
                },
                _ => Tracked::Held,
            });
        };
        let (state, covariance) = match &self.stage {
            Stage::Window(_, Some(c))
            | Stage::Filtering(_, Some(c))
            | Stage::Smoothing(_, Some(c), ..) => (&c.state, &c.covariance),
            Stage::Filtering(filter, None) => (filter.state(), filter.covariance()),
            _ => return Ok(Tracked::Undetermined),
        };
        Ok(Tracked::Estimate(TrackEstimate {
            state,
            covariance,
            nis,
        }))
    }

    /// The smoother's estimates of the rows it still holds (its last `lag` rows, each with
    /// its row), smoothed by every row; nothing for the other methods. The smoother takes no
    /// more rows after it.
    pub fn finish(&mut self) -> Result<Vec<(usize, Smoothed)>, TrackError> {
        let stage = std::mem::replace(&mut self.stage, Stage::Finished);
        let Stage::Smoothing(smoother, _, start, _) = stage else {
            self.stage = stage;
            return Ok(Vec::new());
        };
        let first = start + 1 + smoother.pushed() - smoother.held();
        let smoothed = smoother
            .finish()
            .map_err(|e| smoothing_error(e, start + 1))?;
        Ok(smoothed
            .into_iter()
            .enumerate()
            .map(|(k, s)| (first + k, s))
            .collect())
    }

    /// The rows the smoother holds at most (`lag + 1`; 0 for the other methods), and the
    /// bytes they take: a bound of the tracker's memory beyond a few kilobytes, known before
    /// the first row.
    pub fn held_bound(&self) -> (usize, usize) {
        match self.method {
            TrackMethod::Smooth { lag, .. } => {
                let rows = lag.saturating_add(1);
                let each = FixedLagSmoother::<PolynomialDynamics, Radar>::bytes_per_measurement(6);
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

/// A Kalman filter from a fit, with `method`'s driving noise or fading.
fn filter_from(
    dynamics: PolynomialDynamics,
    radar: Radar,
    method: TrackMethod,
    c: &Correction,
) -> Result<Filter, Error> {
    let f = KalmanFilter::new(
        dynamics,
        radar,
        c.state.clone(),
        c.covariance.clone(),
        c.epoch,
    )?;
    match method {
        TrackMethod::Fading(d) => f.with_fading(d),
        TrackMethod::Window { .. } => Ok(f),
        TrackMethod::Kalman { q } | TrackMethod::Smooth { q, .. } => {
            f.with_process_noise(WhiteNoiseDerivative::new(1, 3, q)?)
        }
    }
}

/// The sliding fit over `window` rows, started at the radar's nominal (§8.5).
fn sliding(
    dynamics: PolynomialDynamics,
    radar: Radar,
    window: usize,
) -> Result<SlidingFit<PolynomialDynamics, Radar>, Error> {
    SlidingFit::new(
        dynamics,
        radar,
        window,
        Epoch::End,
        Start::Radar { radar, degree: 2 },
    )
}

/// A radar row as a [`Measurement`], checked as `seqsmooth track` checks its rows: the time
/// finite; each of range, azimuth and elevation missing (`None`) or in range (the range above
/// 0, the azimuth within `[−2π, 2π]`, the elevation within `[−π/2, π/2]`, radians); the σ of
/// each present component (`sigma_range`, `sigma_angle` for both angles) above 0 with a normal
/// double square. With `bearing` the azimuth is a bearing (from +y, clockwise, x east and y
/// north) and is turned into the angle from +x.
///
/// ```
/// use seqsmooth::kalman::track::radar_row;
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
    use std::f64::consts::{FRAC_PI_2, TAU};
    if !time.is_finite() {
        return Err(Error::NonFinite {
            what: "time",
            value: time,
        });
    }
    let limits: [(&'static str, f64, &str); 3] = [
        ("range", f64::INFINITY, "must be a finite number above 0"),
        (
            "azimuth",
            TAU,
            "must lie in [-2pi, 2pi]: azimuths are in radians",
        ),
        (
            "elevation",
            FRAC_PI_2,
            "must lie in [-pi/2, pi/2]: elevations are in radians from the x-y plane",
        ),
    ];
    for (v, (name, limit, reason)) in values.iter().zip(limits) {
        if let Some(v) = *v {
            let bad = !v.is_finite() || v.abs() > limit || (name == "range" && v <= 0.0);
            if bad {
                return Err(Error::InvalidParameter {
                    name,
                    value: v.to_string(),
                    reason: reason.into(),
                });
            }
        }
    }
    let needed = [
        ("sigma_range", sigma_range, values[0].is_some()),
        (
            "sigma_angle",
            sigma_angle,
            values[1].is_some() || values[2].is_some(),
        ),
    ];
    let mut variances = [1.0; 2];
    for (k, (name, sigma, needed)) in needed.into_iter().enumerate() {
        match sigma {
            Some(s) if crate::estimate::batch::is_usable_sigma(s) => variances[k] = s * s,
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
        values[1] = values[1].map(|b| crate::model::radar::wrap(FRAC_PI_2 - b));
    }
    Ok(Measurement {
        time,
        values: values.to_vec(),
        noise: crate::estimate::batch::NoiseCovariance::Variances(vec![
            variances[0],
            variances[1],
            variances[1],
        ]),
    })
}
