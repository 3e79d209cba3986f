//! The Gauss–Newton fit of the user's own model over a window of measurements from Python,
//! `fit_model`: the library's `estimate::gauss_newton::GaussNewton::fit` (Morrison §8.5-8.7:
//! differential correction with step halving, the covariance `(Tᵀ R⁻¹ T)⁻¹` of the last
//! linearisation) over the callables of [`crate::callables`] (`f` or `dxdt`, `h`, their
//! optional Jacobians, angle residuals).

use crate::callables::{user_model, Transition};
use crate::errors::{raise, IntoPy, Kind};
use crate::fit::epoch_of;
use crate::kalman::{measurements, square};
use nalgebra::DVector;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use seqsmooth::estimate::gauss_newton::GaussNewton;

/// The Gauss–Newton fit (Morrison §8.5-8.7, iterative differential correction with step
/// halving) of the state of your own model at one epoch to all the measurements
/// ``(t[i], z[i])``: the weighted least-squares estimate minimising
/// ``Σ (z_i − h(x(t_i)))ᵀ R⁻¹ (z_i − h(x(t_i)))``, ``x(t)`` carried from the epoch by ``f`` or
/// by integrating ``dxdt`` (no driving noise).
///
/// Parameters
/// ----------
/// x0 : array_like, shape (n,)
///     The nominal state at the epoch the iteration starts from.
/// t, z : array_like
///     The measurements' times and values (``(N,)`` for one component or ``(N, p)``; NaN a
///     missing component).
/// R : array_like or float
///     The measurement noise (a variance for every component, ``p`` variances, or ``p × p``).
/// h : callable
///     ``h(x, t) -> z`` (``p`` values).
/// f, dxdt, F_jacobian, H_jacobian, dxdt_jacobian, angles
///     The model as for :class:`ExtendedKalmanFilter` (``f(x, t0, t1)`` or ``dxdt(x, t)``;
///     Jacobians by the library's central differences when not given).
/// epoch : str or float
///     Where the state refers to: ``"end"`` (the last time, default), ``"centre"`` (their
///     mean) or a time.
/// max_iterations : int
///     The linearisations allowed (1 to 1000, default 20); ``NotDeterminedError`` when the
///     correction is still above 1e-6 of its σ after them.
///
/// Returns
/// -------
/// dict
///     ``epoch``, ``state`` ``(n,)``, ``covariance`` ``(n, n)`` (``(Tᵀ R⁻¹ T)⁻¹`` at the last
///     linearisation), ``chi_squared`` (the weighted residual sum at the estimate),
///     ``degrees_of_freedom`` (components used less ``n``), ``iterations`` (the
///     linearisations taken) and ``condition_number`` (of the whitened ``T``).
#[pyfunction]
#[allow(non_snake_case, clippy::too_many_arguments)]
#[pyo3(signature = (x0, t, z, R, *, h, f = None, dxdt = None, F_jacobian = None, H_jacobian = None, dxdt_jacobian = None, angles = None, epoch = None, max_iterations = 20))]
pub fn fit_model<'py>(
    py: Python<'py>,
    x0: &Bound<'py, PyAny>,
    t: &Bound<'py, PyAny>,
    z: &Bound<'py, PyAny>,
    R: &Bound<'py, PyAny>,
    h: &Bound<'py, PyAny>,
    f: Option<&Bound<'py, PyAny>>,
    dxdt: Option<&Bound<'py, PyAny>>,
    F_jacobian: Option<&Bound<'py, PyAny>>,
    H_jacobian: Option<&Bound<'py, PyAny>>,
    dxdt_jacobian: Option<&Bound<'py, PyAny>>,
    angles: Option<Vec<usize>>,
    epoch: Option<&Bound<'py, PyAny>>,
    max_iterations: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let solver = GaussNewton::with_max_iterations(max_iterations).py()?;
    let epoch = match epoch.filter(|e| !e.is_none()) {
        Some(e) => epoch_of(e)?,
        None => seqsmooth::estimate::gauss_newton::Epoch::End,
    };
    let x = DVector::from_column_slice(crate::arrays::series(x0, "x0")?.as_slice());
    let times = crate::arrays::times(t, "t")?;
    if times.as_slice().is_empty() {
        return Err(raise(Kind::InvalidInput, "t and z are empty", None));
    }
    let t_epoch = epoch.time_for(times.as_slice());
    let transition = Transition {
        f,
        f_jacobian: F_jacobian,
        dxdt,
        dxdt_jacobian,
    };
    let model = user_model(&x, t_epoch, transition, h, H_jacobian, None, angles)?;
    let p = seqsmooth::model::observation::Observation::components(&model.observation);
    let rows = measurements(t, z, R, p)?;
    let result = solver.fit(&model.dynamics, &model.observation, &rows, epoch, &x, None);
    let fit = model.raised.py(result)?;
    let out = PyDict::new(py);
    out.set_item("epoch", fit.epoch)?;
    out.set_item("state", PyArray1::from_slice(py, fit.state.as_slice()))?;
    out.set_item("covariance", square(py, &fit.covariance)?)?;
    out.set_item("chi_squared", fit.chi_squared)?;
    out.set_item("degrees_of_freedom", fit.degrees_of_freedom)?;
    out.set_item("iterations", fit.iterations.len())?;
    out.set_item("condition_number", fit.condition_number)?;
    Ok(out)
}
