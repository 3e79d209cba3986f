//! The sliding Gauss–Newton fit (`estimate::sliding::SlidingFit`) as a Python class,
//! `SlidingFit`: each row's window of the last `W` rows fitted by differential correction
//! (Morrison §8.5-8.7), for a radar's range, azimuth and elevation of a Cartesian target or for
//! a scalar polynomial series, as `seqsmooth fit` does. The models are the library's
//! `SlidingFit::radar` and `SlidingFit::polynomial`, the radar rows checked by the library's
//! `radar_row`, and an estimate beyond the double range refused by `push_finite`, so that each
//! row is the command's to the last bit.

use crate::arrays::{matrix, series, times, Series};
use crate::errors::{raise, to_py, Kind};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString, PyTuple};
use seqsmooth::estimate::batch::NoiseCovariance;
use seqsmooth::estimate::gauss_newton::{check_max_iterations, Epoch, GaussNewton, Measurement};
use seqsmooth::estimate::sliding::{
    check_window_length, Fitter, RowNoise, SlidingFit, POLYNOMIAL_WINDOW, RADAR_WINDOW,
};
use seqsmooth::model::dynamics::Dynamics;
use seqsmooth::model::radar::AzimuthConvention;
use seqsmooth::polynomial::check_degree;
use seqsmooth::track::radar_row;
use seqsmooth::track::window_flag;
use seqsmooth::{Error, Param};

/// A σ as `seqsmooth fit` accepts it: above 0, its square (the variance) a normal double.
pub(crate) fn check_sigma(name: &str, s: f64) -> PyResult<f64> {
    if seqsmooth::estimate::batch::is_usable_sigma(s) {
        Ok(s)
    } else {
        Err(raise(
            Kind::Parameter,
            format!("{name} {s} must be above 0 with a normal double square (the noise variance)"),
            None,
        ))
    }
}

/// A whole number `param` given to Python, for the library's `check` of a count: a negative
/// `v` is refused as the library refuses 0 (named as given), or as no count where it takes 0.
pub(crate) fn count(
    param: Param,
    v: i64,
    check: impl Fn(usize) -> Result<(), Error>,
) -> PyResult<usize> {
    let refused = |e: Error| to_py(e, 0);
    let Ok(n) = usize::try_from(v) else {
        let reason = match check(0) {
            Err(Error::InvalidParameter { reason, .. }) => reason,
            _ => "must not be negative".into(),
        };
        return Err(refused(Error::InvalidParameter {
            name: param,
            value: v.to_string(),
            reason,
        }));
    };
    check(n).map_err(refused)?;
    Ok(n)
}

/// `epoch` as given: ``"end"``, ``"centre"`` (``"center"``) or a finite time.
pub(crate) fn epoch_of(epoch: &Bound<'_, PyAny>) -> PyResult<Epoch> {
    let bad = |shown: String| {
        raise(
            Kind::Parameter,
            format!("epoch {shown} is neither 'end', 'centre' nor a time"),
            None,
        )
    };
    if let Ok(s) = epoch.cast::<PyString>() {
        let text: String = s.extract()?;
        return Epoch::from_name(&text).ok_or_else(|| bad(format!("{text:?}")));
    }
    // A time, in the library's range.
    let t = epoch
        .extract::<f64>()
        .map_err(|_| bad(epoch.repr().map_or_else(|_| "?".into(), |r| r.to_string())))?;
    Epoch::At(t).check().map_err(|e| to_py(e, 0))?;
    Ok(Epoch::At(t))
}

/// Gauss–Newton differential correction over a sliding window (Morrison §8.5-8.7): after each
/// row, the minimum-variance fit of the last ``window`` rows (all rows so far while fewer have
/// come) at the epoch, as ``seqsmooth fit``.
///
/// Each window's fit minimises ``e(X) = Σ (Y_k − G(X, t_k))ᵀ R_k⁻¹ (Y_k − G(X, t_k))`` over
/// the state ``X`` at the epoch ``t_c`` by the iteration ``X ← X + (Tᵀ R⁻¹ T)⁻¹ Tᵀ R⁻¹ (Y −
/// G(X))``, ``T`` the observation's Jacobian through the transition (§8.6); its covariance is
/// ``S* = (Tᵀ R⁻¹ T)⁻¹`` at the last linearisation. It starts from the previous window's
/// estimate carried to the new epoch, the first window (and any whose carried start fails)
/// from the polynomial nominal of §8.5 (radar) or zero (polynomial: linear, so any start
/// gives the least-squares fit).
///
/// Parameters
/// ----------
/// model : {"radar", "polynomial"}
///     ``"radar"``: the Cartesian state ``(x, y, z, vx, vy, vz)`` (and ``(ax, ay, az)`` with
///     ``degree=2``) of a target seen from ``site`` as range, azimuth and elevation;
///     ``"polynomial"``: the derivatives ``(d0, …, dM)`` of a degree-M polynomial in t.
/// window : int
///     The rows of each fit, W ≥ 1 (default: radar 8, polynomial 60; polynomial: at least
///     ``degree + 1``).
/// epoch : {"end", "centre"} or float
///     The time each row's state refers to: the row's own time (the default; also None),
///     the mean time of its window, or this time.
/// degree : int, optional
///     radar: 1 (constant velocity, the default) or 2 (constant acceleration); polynomial:
///     the degree M, 0 to ``MAX_DEGREE`` (required).
/// site : (float, float, float), optional
///     radar: the radar's position, in the range's units (default the origin).
/// sigma_range, sigma_angle : float
///     radar (both required): the range's and the angles' noise σ (radians).
/// sigma : float
///     polynomial (required): the values' noise σ.
/// azimuth : {"from-x", "bearing"}
///     radar: ``"from-x"``, from +x towards +y; ``"bearing"``, clockwise from +y (x east,
///     y north), as ``seqsmooth track --azimuth bearing`` (``seqsmooth fit`` has no such
///     option: a bearing is turned into the angle from +x before the fit).
/// max_iterations : int
///     The Gauss–Newton iterations allowed per window, 1 to 1000 (default 20).
///
/// Raises
/// ------
/// ParameterError
///     A setting out of range, missing, or not for the model.
#[pyclass(name = "SlidingFit", module = "seqsmooth")]
pub struct PySlidingFit {
    inner: Fitter,
    /// radar: `(sigma_range, sigma_angle)`; polynomial: `(sigma, _)`.
    sigmas: [f64; 2],
    bearing: bool,
    /// The state's dimension.
    states: usize,
    rows: usize,
    /// For `__repr__`.
    model: &'static str,
    degree: usize,
    window: usize,
    epoch: Epoch,
}

impl PySlidingFit {
    /// The rows of a batch as measurements; the first refused one's error (its index the
    /// position in the batch) after the rows before it.
    fn rows(&self, t: &Series<'_>, values: &[Series<'_>]) -> (Vec<Measurement>, Option<PyErr>) {
        let t = t.as_slice();
        let mut rows = Vec::with_capacity(t.len());
        for (i, &time) in t.iter().enumerate() {
            let row = match self.inner {
                Fitter::Radar(_) => {
                    let v = [0, 1, 2].map(|k| {
                        let x = values[k].as_slice()[i];
                        (!x.is_nan()).then_some(x)
                    });
                    radar_row(
                        time,
                        v,
                        Some(self.sigmas[0]),
                        Some(self.sigmas[1]),
                        self.bearing,
                    )
                }
                Fitter::Polynomial(_) => {
                    let y = values[0].as_slice()[i];
                    if !time.is_finite() {
                        Err(Error::NonFinite {
                            what: "time",
                            value: time,
                        })
                    } else if !y.is_finite() {
                        Err(Error::NonFinite {
                            what: "value",
                            value: y,
                        })
                    } else {
                        Ok(Measurement {
                            time,
                            values: vec![Some(y)],
                            noise: NoiseCovariance::Variances(vec![
                                self.sigmas[0] * self.sigmas[0],
                            ]),
                        })
                    }
                }
            };
            match row {
                Ok(m) => rows.push(m),
                Err(e) => return (rows, Some(in_batch(e, i))),
            }
        }
        (rows, None)
    }
}

/// A refused row's error as its exception, `.index` its position `i` in the batch; an
/// estimate beyond the double range with the command's message and advice.
fn in_batch(e: Error, i: usize) -> PyErr {
    match e {
        e @ Error::NonFinite {
            what: "fitted state",
            value,
        } => raise(
            Kind::of(&e),
            format!(
                "sample {i} of the batch: the fitted state holds {value}, beyond the double \
                 range; express the times in a larger unit or rescale the values"
            ),
            Some(i),
        ),
        e => to_py(
            Error::InBatch {
                index: i,
                source: Box::new(e),
            },
            0,
        ),
    }
}

#[pymethods]
impl PySlidingFit {
    #[new]
    #[pyo3(signature = (model = "radar", *, window = None, epoch = None, degree = None,
        site = None, sigma_range = None, sigma_angle = None, sigma = None, azimuth = "from-x",
        max_iterations = 20),
        text_signature = "(model='radar', *, window=None, epoch='end', degree=None, site=None, \
            sigma_range=None, sigma_angle=None, sigma=None, azimuth='from-x', max_iterations=20)")]
    #[allow(clippy::too_many_arguments)]
    fn new(
        model: &str,
        window: Option<i64>,
        epoch: Option<&Bound<'_, PyAny>>,
        degree: Option<i64>,
        site: Option<(f64, f64, f64)>,
        sigma_range: Option<f64>,
        sigma_angle: Option<f64>,
        sigma: Option<f64>,
        azimuth: &str,
        max_iterations: i64,
    ) -> PyResult<Self> {
        let usage = |m: String| Err(raise(Kind::Parameter, m, None));
        let library = |e: Error| to_py(e, 0);
        let window = window.unwrap_or(match model {
            "polynomial" => POLYNOMIAL_WINDOW as i64,
            _ => RADAR_WINDOW as i64,
        });
        // The ranges are the library's.
        let window = count(Param::Window, window, check_window_length)?;
        let max_iterations = count(Param::MaxIterations, max_iterations, check_max_iterations)?;
        let solver = GaussNewton::with_max_iterations(max_iterations).map_err(library)?;
        let epoch = match epoch {
            Some(e) => epoch_of(e)?,
            None => Epoch::End,
        };
        let bearing = AzimuthConvention::from_name(azimuth)
            .map_err(library)?
            .is_bearing();
        let max = seqsmooth::polynomial::MAX_DEGREE;
        if let Some(d) = degree {
            // The library's range of a polynomial degree.
            let in_range = usize::try_from(d).is_ok_and(|d| check_degree(d).is_ok());
            if !in_range {
                return usage(format!(
                    "degree {d} is out of range: 0 to {max} (radar: 1 or 2)"
                ));
            }
        }
        let degree = degree.map(|d| d as usize);
        match model {
            "radar" => {
                if sigma.is_some() {
                    return usage(
                        "sigma applies only to model='polynomial'; a radar takes sigma_range \
                         and sigma_angle"
                            .into(),
                    );
                }
                let (Some(sr), Some(sa)) = (sigma_range, sigma_angle) else {
                    return usage(
                        "model='radar' needs sigma_range (the range's noise σ) and sigma_angle \
                         (the angles', in radians)"
                            .into(),
                    );
                };
                let sigmas = [
                    check_sigma("sigma_range", sr)?,
                    check_sigma("sigma_angle", sa)?,
                ];
                // Its range (1 or 2) is the library's: `SlidingFit::radar` refuses the others.
                let degree = degree.unwrap_or(1);
                let site = site.unwrap_or((0.0, 0.0, 0.0));
                let fit =
                    SlidingFit::radar([site.0, site.1, site.2], degree, window, epoch, solver)
                        .map_err(library)?;
                Ok(Self {
                    inner: Fitter::Radar(fit),
                    sigmas,
                    bearing,
                    states: 3 * (degree + 1),
                    rows: 0,
                    model: "radar",
                    degree,
                    window,
                    epoch,
                })
            }
            "polynomial" => {
                if sigma_range.is_some() || sigma_angle.is_some() {
                    return usage("sigma_range and sigma_angle apply only to model='radar'".into());
                }
                if site.is_some() || bearing {
                    return usage("site and azimuth apply only to model='radar'".into());
                }
                let Some(degree) = degree else {
                    return usage(
                        "model='polynomial' needs degree, the polynomial's degree".into(),
                    );
                };
                let Some(sigma) = sigma else {
                    return usage(
                        "model='polynomial' needs sigma, the values' noise standard deviation"
                            .into(),
                    );
                };
                let sigma = check_sigma("sigma", sigma)?;
                let fit = SlidingFit::polynomial(degree, window, epoch, solver).map_err(library)?;
                Ok(Self {
                    inner: Fitter::Polynomial(fit),
                    sigmas: [sigma, 0.0],
                    bearing,
                    states: degree + 1,
                    rows: 0,
                    model: "polynomial",
                    degree,
                    window,
                    epoch,
                })
            }
            other => usage(format!(
                "model {other:?} is not one of 'radar', 'polynomial'"
            )),
        }
    }

    /// The rows taken so far.
    #[getter]
    fn rows_taken(&self) -> usize {
        self.rows
    }

    /// Fits each row's window: ``update_many(t, y)`` (polynomial) or ``update_many(t, range,
    /// azimuth, elevation)`` (radar; NaN: a missing component, the row's others used; a row
    /// with all three missing still takes its place in the window).
    ///
    /// Returns
    /// -------
    /// states : ndarray, shape (n, dim)
    ///     Each row's state at its epoch: radar ``x, y, z, vx, vy, vz`` (``ax, ay, az``),
    ///     polynomial ``d0 … dM``; NaN rows while the window (not yet full) does not
    ///     determine the state.
    /// covariances : ndarray, shape (n, dim, dim)
    ///     ``S*``, the state's covariance (NaN rows likewise); ``sqrt`` of its diagonal is
    ///     the command's ``s`` columns.
    /// info : dict of ndarray, shape (n,)
    ///     The command's other columns: ``"iterations"`` (Gauss–Newton iterations taken),
    ///     ``"chi2"`` (the window's residual ``e(X*)``, with degrees of freedom the measured
    ///     components less the states) and ``"epoch"`` (the time the state refers to), all
    ///     float, NaN where the state is; radar also ``"flag"``, the command's ``flag``
    ///     column (str): ``"misfit"`` where the window's χ² fails its test (the covariance
    ///     carries the misfit, scaled by ``max(1, chi2/dof)``), else ``""``.
    ///
    /// Raises
    /// ------
    /// InvalidInputError
    ///     A refused row, ``.index`` its position in the batch: a time not finite or not
    ///     after the previous one, a value not finite, a range not above 0, an azimuth beyond
    ///     ±2π, an elevation beyond ±π/2; or a window whose numbers leave the double range
    ///     (the linearised system or the fitted state not finite: rescale the times or
    ///     values). The rows before it are taken; the fit is as before it.
    /// NumericalError, TooFewSamplesError
    ///     A full window that does not determine the state, an iteration that diverges or
    ///     does not converge (``.index`` the row; the fit as before it).
    #[pyo3(signature = (t, *values))]
    fn update_many<'py>(
        &mut self,
        py: Python<'py>,
        t: &Bound<'py, PyAny>,
        values: &Bound<'py, PyTuple>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let names: &[&str] = match self.inner {
            Fitter::Radar(_) => &["range", "azimuth", "elevation"],
            Fitter::Polynomial(_) => &["y"],
        };
        if values.len() != names.len() {
            return Err(raise(
                Kind::InvalidInput,
                format!(
                    "model='{}' takes update_many(t, {}): {} value arrays given",
                    self.model,
                    names.join(", "),
                    values.len()
                ),
                None,
            ));
        }
        let ts = times(t, "t")?;
        let n = ts.as_slice().len();
        let mut columns = Vec::with_capacity(names.len());
        for (v, name) in values.iter().zip(names) {
            let s = series(&v, name)?;
            if s.as_slice().len() != n {
                return Err(raise(
                    Kind::InvalidInput,
                    format!("{name} has {} values for {n} times", s.as_slice().len()),
                    None,
                ));
            }
            columns.push(s);
        }
        if n == 0 {
            return Err(raise(Kind::InvalidInput, "t is empty", None));
        }
        let (rows, refused) = self.rows(&ts, &columns);
        let count = rows.len();
        let d = self.states;
        let mut states = vec![f64::NAN; count * d];
        let mut covariances = vec![f64::NAN; count * d * d];
        let mut extra = [
            vec![f64::NAN; count],
            vec![f64::NAN; count],
            vec![f64::NAN; count],
        ];
        let mut flags = vec![""; count];
        let radar = matches!(self.inner, Fitter::Radar(_));
        let fitter = &mut self.inner;
        let mut taken = 0;
        let failed = py.detach(|| {
            for (i, m) in rows.into_iter().enumerate() {
                let fit = fitter.push_finite(m).map_err(|e| (i, e))?;
                taken = i + 1;
                if let Some(c) = fit {
                    states[i * d..(i + 1) * d].copy_from_slice(c.state.as_slice());
                    for r in 0..d {
                        for k in 0..d {
                            covariances[(i * d + r) * d + k] = c.covariance[(r, k)];
                        }
                    }
                    extra[0][i] = c.iterations.len() as f64;
                    extra[1][i] = c.chi_squared;
                    extra[2][i] = c.epoch;
                    flags[i] = window_flag(&c).name();
                }
            }
            Ok::<(), (usize, Error)>(())
        });
        self.rows += taken;
        if let Err((i, e)) = failed {
            return Err(in_batch(e, i));
        }
        if let Some(e) = refused {
            return Err(e);
        }
        let states = matrix(py, states, count, d)?;
        let covariances = PyArray1::from_vec(py, covariances)
            .reshape([count, d, d])?
            .into_any();
        let info = PyDict::new(py);
        for (name, v) in ["iterations", "chi2", "epoch"].into_iter().zip(extra) {
            info.set_item(name, PyArray1::from_vec(py, v))?;
        }
        if radar {
            info.set_item("flag", crate::track::flag_array(py, &flags)?)?;
        }
        PyTuple::new(py, [states, covariances, info.into_any()])
    }

    /// ``pickle`` support (``copy.copy`` and ``copy.deepcopy`` too): the fit (its window of
    /// rows, last estimate, settings) and the rows' noise in the library's saved form,
    /// restored bit for bit. A copy is a deep copy.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let me = slf.borrow();
        let rows = RowNoise {
            sigmas: me.sigmas,
            bearing: me.bearing,
            rows: me.rows as u64,
        };
        crate::persist::reduce_saved(slf.as_any(), &(me.inner.clone(), rows))
    }

    /// The fit ``__reduce__`` saved (a ``DamagedStateError`` if ``state`` is damaged or
    /// another class's).
    #[staticmethod]
    fn _from_state(state: &Bound<'_, PyAny>) -> PyResult<Self> {
        let (inner, rows): (Fitter, RowNoise) = crate::persist::load(state)?;
        let (model, degree, window, epoch, states) = match &inner {
            Fitter::Radar(f) => {
                let d = f.models().0;
                ("radar", d.degree(), f.window(), f.epoch(), d.dimension())
            }
            Fitter::Polynomial(f) => {
                let d = f.models().0;
                (
                    "polynomial",
                    d.degree(),
                    f.window(),
                    f.epoch(),
                    d.dimension(),
                )
            }
        };
        let taken = usize::try_from(rows.rows)
            .map_err(|_| crate::persist::damaged("the rows taken overflow"))?;
        Ok(Self {
            inner,
            sigmas: rows.sigmas,
            bearing: rows.bearing,
            states,
            rows: taken,
            model,
            degree,
            window,
            epoch,
        })
    }

    fn __repr__(&self) -> String {
        let epoch = match self.epoch {
            Epoch::End => "'end'".to_string(),
            Epoch::Centre => "'centre'".to_string(),
            Epoch::At(t) => format!("{t:?}"),
        };
        format!(
            "SlidingFit(model='{}', degree={}, window={}, epoch={epoch}, rows_taken={})",
            self.model, self.degree, self.window, self.rows
        )
    }
}
