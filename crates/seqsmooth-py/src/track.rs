//! The radar tracker (`track::RadarTracker`) as a Python class, `RadarTracker`: a
//! radar's range, azimuth and elevation to a constant-velocity Cartesian track by the sliding
//! Gauss–Newton fit, the extended Kalman filter (driving noise or fading memory) or its
//! smoother; the rows checked by the library's `radar_row`, as `seqsmooth track` checks them.

use crate::arrays::{matrix, series, times, Series};
use crate::errors::{raise, to_py, IntoPy, Kind};
use crate::kalman::discount_from;
use crate::persist;
use nalgebra::{DMatrix, DVector};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use seqsmooth::estimate::gauss_newton::{check_max_iterations, GaussNewton, Measurement};
use seqsmooth::kalman::smoother::Smoothed;
use seqsmooth::model::radar::{AzimuthConvention, Radar};
use seqsmooth::track::{
    radar_row, MotionModel, RadarTracker, TrackError, TrackFlag, TrackMethod, Tracked, DEFAULT_LAG,
    DEFAULT_WINDOW, REPORTED,
};
use seqsmooth::{Error, Param};

/// A tracker's error as its exception; `offset` is the batch's first row in the tracker's
/// count, so that an index names the caller's position in the batch.
fn track_error(e: TrackError, offset: usize) -> PyErr {
    let in_batch = |row: usize, source: Error| {
        to_py(
            Error::InBatch {
                index: row - offset,
                source: Box::new(source),
            },
            0,
        )
    };
    match e {
        TrackError::Window { rows, source } => match source {
            Error::InBatch { index, source } if rows.start + index >= offset => {
                in_batch(rows.start + index, *source)
            }
            source => {
                let message = format!(
                    "rows {}-{} (the window): {source}",
                    rows.start,
                    rows.end.saturating_sub(1)
                );
                let kind = Kind::of(&source);
                let last = rows.end.saturating_sub(1);
                raise(kind, message, last.checked_sub(offset))
            }
        },
        TrackError::Update { row, source } if row >= offset => in_batch(row, source),
        TrackError::Smooth(Error::InBatch { index, source }) => to_py(
            Error::InBatch {
                index: index.saturating_sub(offset),
                source,
            },
            0,
        ),
        e => {
            // The class by the cause's kind, the message the tracker's.
            let message = e.to_string();
            let (TrackError::Window { source, .. }
            | TrackError::Start(source)
            | TrackError::Update { source, .. }
            | TrackError::Smooth(source)) = e;
            raise(Kind::of(&source), message, None)
        }
    }
}

/// One output row: state, covariance (row-major), NIS and flag; NaN (`""`) where none.
fn write_row(
    estimate: &Tracked<'_>,
    states: &mut [f64],
    covariances: &mut [f64],
    nis: &mut f64,
    flag: &mut &'static str,
) {
    if let Tracked::Estimate(e) = estimate {
        reported(e.state, e.covariance, states, covariances);
        *nis = e.nis.unwrap_or(f64::NAN);
        *flag = e.flag.name();
    }
}

/// The reported part of a model's state (position and velocity, [`REPORTED`]) and its
/// covariance block (row-major: symmetric, so column-major is row-major).
fn reported(x: &DVector<f64>, s: &DMatrix<f64>, states: &mut [f64], covariances: &mut [f64]) {
    states.copy_from_slice(&x.as_slice()[..REPORTED]);
    for (k, c) in covariances.chunks_mut(REPORTED).enumerate() {
        c.copy_from_slice(&s.column(k).as_slice()[..REPORTED]);
    }
}

/// The rows' flags (`TrackFlag::name`: `""`, `"outlier"`, `"misfit"`) as a numpy array of str.
pub(crate) fn flag_array<'py>(py: Python<'py>, flags: &[&str]) -> PyResult<Bound<'py, PyAny>> {
    let kwargs = pyo3::types::PyDict::new(py);
    kwargs.set_item("dtype", "<U7")?;
    py.import("numpy")?
        .getattr("array")?
        .call((pyo3::types::PyList::new(py, flags)?,), Some(&kwargs))
}

/// A radar track (Morrison §8.5-8.7, chs. 12, 14, 15): range, azimuth and elevation seen from
/// ``site`` to the state ``(x, y, z, vx, vy, vz)`` of a constant-velocity target, in the
/// range's units and the times' units.
///
/// Parameters
/// ----------
/// method : {"kalman", "fading", "smooth", "window"}
///     ``"window"``: the Gauss–Newton fit of each row's last ``window`` rows;
///     ``"kalman"``: the extended Kalman filter with white-noise acceleration ``q``;
///     ``"fading"``: the fading-memory extended Kalman filter (``theta`` with ``tau``, or
///     ``theta_per_update``);
///     ``"smooth"``: the fixed-lag Rauch–Tung–Striebel smoother over the Kalman filter: each
///     row's estimate from the ``lag`` rows after it, given ``lag`` rows later (``smoothed()``),
///     the last ones at ``finish()``. The Kalman methods start from the first fit of the rows
///     so far (at most 60) that determines the state.
/// sigma_range, sigma_angle : float, optional
///     The range's and the angles' noise σ (radians), for the rows that give none.
/// site : (float, float, float)
///     The radar's position.
/// q : float, optional
///     kalman, smooth: the acceleration's spectral density on each axis; by default
///     adaptive: from ``σ_range² / T³`` (``T`` the start's mean step), raised by the
///     innovation test's misfits and lowered when the innovations are quiet (Morrison §14.8).
/// theta, tau : float, optional
///     fading: the discount ``theta`` in (0, 1) per span ``tau`` of time, both or neither (as
///     ``FadingMemory``'s and ``seqsmooth track --theta T --tau TAU``).
/// theta_per_update : float, optional
///     fading: the discount in (0, 1) per update (what ``theta`` alone meant before; ``beta``
///     per unit of time is now ``theta``, ``tau=1.0``). Without a discount, an adaptive
///     discount per update from 0.9, shortened by misfits likewise.
/// window : int
///     window: the rows of each fit (default 8).
/// lag : int
///     smooth: the lag in rows (default 200); the smoother holds ``lag + 1`` rows; 0 is the
///     filter, a lag beyond the rows the whole-interval smoother.
/// max_iterations : int
///     The Gauss–Newton iterations allowed per fit (the window method's, the Kalman methods'
///     start), 1 to 1000 (default 20).
///
/// Every row's estimate has a flag (``update_many``'s fourth array, ``smoothed()``'s and
/// ``finish()``'s fifth): ``""``; ``"outlier"``, the row's measurement failed the innovation
/// gate and was left out (the estimate is the prediction); ``"misfit"``, the model does not
/// follow the target here (the innovation test, or the window's χ²), so the σ may not cover
/// the error. The smoother's rows carry the flag its forward filter gave them.
/// model : {"constant-velocity", "constant-acceleration", "singer", "coordinated-turn"}
///     The motion model of the Kalman methods (``seqsmooth track --model``); the window method
///     fits constant velocity only. ``q`` is the white acceleration's density (the jerk's for
///     constant acceleration; not Singer's, whose driving noise is ``manoeuvre_variance``).
///     Every model reports position and velocity: the states' first six components.
/// manoeuvre_alpha, manoeuvre_variance : float, optional
///     singer: the manoeuvre rate ``α > 0`` (default 0.1 per time unit) and variance
///     ``σ_m²`` (default adaptive).
/// turn_rate_noise : float, optional
///     coordinated-turn: the turn rate's random-walk density (default 1e-4 rad² per time³).
/// azimuth : {"from-x", "bearing"}
///     ``"from-x"``: from +x towards +y; ``"bearing"``: clockwise from +y (x east, y north).
#[pyclass(name = "RadarTracker", module = "seqsmooth")]
pub struct PyRadarTracker {
    inner: RadarTracker,
    sigmas: [Option<f64>; 2],
    bearing: bool,
    /// The smoother's rows given and not yet returned.
    given: Given,
}

/// Smoothed rows as the arrays `smoothed()` returns: row numbers, states, covariances
/// (row-major: symmetric), NIS and flags.
#[derive(Default)]
struct Given {
    rows: Vec<i64>,
    states: Vec<f64>,
    covariances: Vec<f64>,
    nis: Vec<f64>,
    flags: Vec<&'static str>,
}

impl Given {
    fn push(&mut self, row: usize, s: &Smoothed, flag: TrackFlag) {
        self.rows.push(row as i64);
        let (mut x, mut c) = ([0.0; REPORTED], [0.0; REPORTED * REPORTED]);
        reported(&s.state, &s.covariance, &mut x, &mut c);
        self.states.extend_from_slice(&x);
        self.covariances.extend_from_slice(&c);
        self.nis.push(s.nis.unwrap_or(f64::NAN));
        self.flags.push(flag.name());
    }

    /// `(rows, states, covariances, nis, flags)`, `(n,)`, `(n, 6)`, `(n, 6, 6)`, `(n,)`,
    /// `(n,)`.
    fn arrays<'py>(self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let count = self.rows.len();
        let rows = PyArray1::from_vec(py, self.rows).into_any();
        let states = matrix(py, self.states, count, 6)?;
        let covariances = PyArray1::from_vec(py, self.covariances)
            .reshape([count, 6, 6])?
            .into_any();
        let nis = PyArray1::from_vec(py, self.nis).into_any();
        let flags = flag_array(py, &self.flags)?;
        PyTuple::new(py, [rows, states, covariances, nis, flags])
    }
}

impl PyRadarTracker {
    /// The rows of a batch as measurements; the first refused one's error (its index the
    /// position in the batch) after the rows before it.
    #[allow(clippy::too_many_arguments)]
    fn rows(
        &self,
        t: &Series<'_>,
        values: [&Series<'_>; 3],
        sigmas: [Option<&Series<'_>>; 2],
    ) -> (Vec<Measurement>, Option<PyErr>) {
        let n = t.as_slice().len();
        let mut rows = Vec::with_capacity(n);
        for i in 0..n {
            let v = values.map(|s| {
                let x = s.as_slice()[i];
                (!x.is_nan()).then_some(x)
            });
            let sigma = |k: usize| {
                sigmas[k]
                    .map(|s| s.as_slice()[i])
                    .filter(|s| !s.is_nan())
                    .or(self.sigmas[k])
            };
            match radar_row(t.as_slice()[i], v, sigma(0), sigma(1), self.bearing) {
                Ok(m) => rows.push(m),
                Err(e) => {
                    let e = Error::InBatch {
                        index: i,
                        source: Box::new(e),
                    };
                    return (rows, Some(to_py(e, 0)));
                }
            }
        }
        (rows, None)
    }
}

/// An optional per-row σ array of `n` values.
fn sigma_series<'py>(
    obj: Option<&Bound<'py, PyAny>>,
    name: &str,
    n: usize,
) -> PyResult<Option<Series<'py>>> {
    let Some(obj) = obj else { return Ok(None) };
    let s = series(obj, name)?;
    if s.as_slice().len() != n {
        return Err(raise(
            Kind::InvalidInput,
            format!(
                "{name} has {} values for {n} times: one per row (NaN takes the tracker's)",
                s.as_slice().len()
            ),
            None,
        ));
    }
    Ok(Some(s))
}

#[pymethods]
impl PyRadarTracker {
    /// ``pickle`` support (``copy.copy`` and ``copy.deepcopy`` too): the tracker's state in
    /// the library's saved form, with the σ given, the azimuth convention and the smoother's
    /// rows not yet taken, restored bit for bit. A copy is a deep copy of the state.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let me = slf.borrow();
        let g = &me.given;
        let state = (
            persist::save(py, &me.inner)?,
            me.sigmas,
            me.bearing,
            (&g.rows, &g.states, &g.covariances, &g.nis, &g.flags),
        )
            .into_pyobject(py)?;
        persist::reduce(slf.as_any(), state.into_any())
    }

    /// The tracker ``__reduce__`` saved (a ``DamagedStateError`` if ``state`` is damaged or
    /// another class's).
    #[staticmethod]
    fn _from_state(state: &Bound<'_, PyAny>) -> PyResult<Self> {
        type Rows = (Vec<i64>, Vec<f64>, Vec<f64>, Vec<f64>, Vec<String>);
        let items = persist::items(state, 4)?;
        let inner: RadarTracker = persist::load(&items.get_item(0)?)?;
        let bad = |_| persist::damaged("the tracker's settings or held rows are not readable");
        let sigmas: [Option<f64>; 2] = items.get_item(1)?.extract().map_err(bad)?;
        let bearing: bool = items.get_item(2)?.extract().map_err(bad)?;
        let (rows, states, covariances, nis, names): Rows =
            items.get_item(3)?.extract().map_err(bad)?;
        let count = rows.len();
        let flags = [TrackFlag::None, TrackFlag::Outlier, TrackFlag::Misfit].map(TrackFlag::name);
        let flags: Option<Vec<&'static str>> = names
            .iter()
            .map(|n| flags.iter().find(|f| *f == n).copied())
            .collect();
        let sigmas_ok = sigmas.iter().flatten().all(|s| s.is_finite() && *s > 0.0);
        match flags {
            Some(flags)
                if sigmas_ok
                    && states.len() == 6 * count
                    && covariances.len() == 36 * count
                    && nis.len() == count
                    && flags.len() == count =>
            {
                Ok(Self {
                    inner,
                    sigmas,
                    bearing,
                    given: Given {
                        rows,
                        states,
                        covariances,
                        nis,
                        flags,
                    },
                })
            }
            _ => Err(persist::damaged(
                "the tracker's settings or held rows do not fit",
            )),
        }
    }

    #[new]
    #[pyo3(signature = (method = "kalman", *, sigma_range = None, sigma_angle = None,
        site = (0.0, 0.0, 0.0), q = None, theta = None, tau = None, theta_per_update = None,
        beta = None, window = None,
        lag = None, azimuth = "from-x", max_iterations = 20, model = "constant-velocity",
        manoeuvre_alpha = None, manoeuvre_variance = None, turn_rate_noise = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        method: &str,
        sigma_range: Option<f64>,
        sigma_angle: Option<f64>,
        site: (f64, f64, f64),
        q: Option<f64>,
        theta: Option<f64>,
        tau: Option<f64>,
        theta_per_update: Option<f64>,
        beta: Option<f64>,
        window: Option<usize>,
        lag: Option<usize>,
        azimuth: &str,
        max_iterations: i64,
        model: &str,
        manoeuvre_alpha: Option<f64>,
        manoeuvre_variance: Option<f64>,
        turn_rate_noise: Option<f64>,
    ) -> PyResult<Self> {
        let model = MotionModel::named(model)
            .and_then(|m| m.with_parameters(manoeuvre_alpha, manoeuvre_variance, turn_rate_noise))
            .py()?;
        let usage = |m: &str| Err(raise(Kind::Parameter, m, None));
        let discount = discount_from(theta, tau, theta_per_update, beta)?;
        let fading = discount.is_some();
        let method = match method {
            "window" if q.is_some() || fading => return usage(
                "q and the discount (theta, tau, theta_per_update) do not apply to method='window'",
            ),
            "window" => TrackMethod::Window {
                window: window.unwrap_or(DEFAULT_WINDOW),
            },
            "kalman" | "smooth" if fading => {
                return usage(
                    "the discount (theta, tau, theta_per_update) applies only to method='fading'",
                )
            }
            "kalman" => TrackMethod::Kalman { q },
            "smooth" => TrackMethod::Smooth {
                q,
                lag: lag.unwrap_or(DEFAULT_LAG),
            },
            "fading" if q.is_some() => return usage("q applies only to 'kalman' and 'smooth'"),
            "fading" => TrackMethod::Fading(discount),
            other => {
                return usage(&format!(
                    "method {other:?} is not one of 'kalman', 'fading', 'smooth', 'window'"
                ))
            }
        };
        if window.is_some() && !matches!(method, TrackMethod::Window { .. }) {
            return usage("window applies only to method='window'");
        }
        if lag.is_some() && !matches!(method, TrackMethod::Smooth { .. }) {
            return usage("lag applies only to method='smooth'");
        }
        let bearing = AzimuthConvention::from_name(azimuth).py()?.is_bearing();
        for (name, sigma) in [("sigma_range", sigma_range), ("sigma_angle", sigma_angle)] {
            if let Some(s) = sigma {
                crate::fit::check_sigma(name, s)?;
            }
        }
        let max_iterations =
            crate::fit::count(Param::MaxIterations, max_iterations, check_max_iterations)?;
        let solver = GaussNewton::with_max_iterations(max_iterations).py()?;
        let radar = Radar::new([site.0, site.1, site.2], 6).py()?;
        Ok(Self {
            inner: RadarTracker::with_model(radar, method, model, solver).py()?,
            sigmas: [sigma_range, sigma_angle],
            bearing,
            given: Given::default(),
        })
    }

    /// The rows taken so far.
    #[getter]
    fn rows_taken(&self) -> usize {
        self.inner.rows()
    }

    /// Tracks the rows ``(t[i], range[i], azimuth[i], elevation[i])`` (NaN: a missing
    /// component), with per-row σ where given (NaN: the tracker's). Returns ``(states,
    /// covariances, nis, flags)``, ``(n, 6)``, ``(n, 6, 6)``, ``(n,)`` and ``(n,)`` of str:
    /// NaN rows (flag ``""``) where the rows so far do not determine the state, or the
    /// smoother holds the row (its estimate comes ``lag`` rows later from ``smoothed()``, or
    /// from ``finish``); a NIS is NaN where there is no innovation; a flag is ``""``,
    /// ``"outlier"`` or ``"misfit"`` (``seqsmooth track``'s ``flag``). On a refused row the
    /// rows before it are taken and the exception's ``index`` is its position.
    #[pyo3(signature = (t, range, azimuth, elevation, sigma_range = None, sigma_angle = None))]
    #[allow(clippy::too_many_arguments)]
    fn update_many<'py>(
        &mut self,
        py: Python<'py>,
        t: &Bound<'py, PyAny>,
        range: &Bound<'py, PyAny>,
        azimuth: &Bound<'py, PyAny>,
        elevation: &Bound<'py, PyAny>,
        sigma_range: Option<&Bound<'py, PyAny>>,
        sigma_angle: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let ts = times(t, "t")?;
        let n = ts.as_slice().len();
        let values = [
            series(range, "range")?,
            series(azimuth, "azimuth")?,
            series(elevation, "elevation")?,
        ];
        for (s, name) in values.iter().zip(["range", "azimuth", "elevation"]) {
            if s.as_slice().len() != n {
                return Err(raise(
                    Kind::InvalidInput,
                    format!("{name} has {} values for {n} times", s.as_slice().len()),
                    None,
                ));
            }
        }
        if n == 0 {
            return Err(raise(Kind::InvalidInput, "t is empty", None));
        }
        let sr = sigma_series(sigma_range, "sigma_range", n)?;
        let sa = sigma_series(sigma_angle, "sigma_angle", n)?;
        let (rows, refused) = self.rows(
            &ts,
            [&values[0], &values[1], &values[2]],
            [sr.as_ref(), sa.as_ref()],
        );
        let count = rows.len();
        let mut states = vec![f64::NAN; count * 6];
        let mut covariances = vec![f64::NAN; count * 36];
        let mut nis = vec![f64::NAN; count];
        let mut flags = vec![""; count];
        let offset = self.inner.rows();
        let tracker = &mut self.inner;
        let given = &mut self.given;
        let mut taken = 0;
        let failed = py.detach(|| {
            for (i, m) in rows.iter().enumerate() {
                let tracked = tracker.push(m)?;
                if let Tracked::Smoothed {
                    row,
                    estimate,
                    flag,
                } = tracked
                {
                    given.push(row, estimate, flag);
                }
                write_row(
                    &tracked,
                    &mut states[i * 6..(i + 1) * 6],
                    &mut covariances[i * 36..(i + 1) * 36],
                    &mut nis[i],
                    &mut flags[i],
                );
                taken = i + 1;
            }
            Ok::<(), TrackError>(())
        });
        if let Err(e) = failed {
            return Err(track_error(e, offset));
        }
        if let Some(e) = refused {
            return Err(e);
        }
        debug_assert_eq!(taken, count);
        let states = matrix(py, states, count, 6)?;
        let covariances = PyArray1::from_vec(py, covariances)
            .reshape([count, 6, 6])?
            .into_any();
        let nis = PyArray1::from_vec(py, nis).into_any();
        let flags = flag_array(py, &flags)?;
        PyTuple::new(py, [states, covariances, nis, flags])
    }

    /// The smoother's estimates given since the last call (each row's from the ``lag`` rows
    /// after it): ``(rows, states, covariances, nis, flags)``, ``(n,)``, ``(n, 6)``,
    /// ``(n, 6, 6)``, ``(n,)``, ``(n,)`` of str: ``update_many``'s arrays after the rows'
    /// numbers, counted from the tracker's first row (0); ``nis`` and ``flags`` the forward
    /// filter's (a row the gate left out: its NIS, ``"outlier"``); empty for the other
    /// methods. Call it after ``update_many`` to keep memory bounded by the lag; rows not
    /// taken wait for ``finish``.
    fn smoothed<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        std::mem::take(&mut self.given).arrays(py)
    }

    /// The smoother's estimates of the rows given and not yet taken by ``smoothed()``, then
    /// those of the rows it still holds (smoothed by every row): ``(rows, states, covariances,
    /// nis, flags)`` as ``smoothed()``; empty for the other methods. The smoother takes no
    /// more rows after it.
    fn finish<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let tracker = &mut self.inner;
        let smoothed = py
            .detach(|| tracker.finish())
            .map_err(|e| track_error(e, 0))?;
        let mut given = std::mem::take(&mut self.given);
        for (row, s, flag) in &smoothed {
            given.push(*row, s, *flag);
        }
        given.arrays(py)
    }

    fn __repr__(&self) -> String {
        format!(
            "RadarTracker(method={:?}, rows_taken={})",
            self.inner.method(),
            self.inner.rows()
        )
    }
}
