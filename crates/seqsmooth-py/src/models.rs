//! The library's built-in nonlinear motion models as Python objects whose methods are the
//! callables `ExtendedKalmanFilter` and `UnscentedKalmanFilter` take (`f`, `F_jacobian`, `Q`):
//! `CoordinatedTurn` over `seqsmooth::model::coordinated_turn`.

use crate::arrays::{matrix, series};
use crate::errors::{raise, IntoPy, Kind};
use nalgebra::{DMatrix, DVector};
use numpy::PyArray1;
use pyo3::prelude::*;
use seqsmooth::kalman::noise::ProcessNoise;
use seqsmooth::model::coordinated_turn::CoordinatedTurn;
use seqsmooth::model::dynamics::Dynamics;

/// The coordinated turn (Bar-Shalom, Li and Kirubarajan §11.7; the library's
/// ``model::coordinated_turn``): a target turning at rate ``ω`` in the horizontal plane, its
/// vertical velocity constant, the state ``(x, y, z, vx, vy, vz)`` for a known ``turn_rate``
/// or ``(x, y, z, vx, vy, vz, ω)`` with ``ω`` estimated, propagated in closed form.
///
/// Parameters
/// ----------
/// q : float
///     The white acceleration's spectral density on each axis (≥ 0).
/// turn_rate : float, optional
///     A known turn rate (rad per time unit, anticlockwise from +x to +y); by default the
///     rate is the seventh state.
/// turn_rate_noise : float
///     The estimated rate's random-walk density ``q_ω`` (rad² per time³, ≥ 0; default 0).
///
/// Its methods are the callables of ``ExtendedKalmanFilter(f=m.f, F_jacobian=m.F_jacobian,
/// Q=m.Q, …)`` and ``UnscentedKalmanFilter(f=m.f, Q=m.Q, …)``: ``f(x, t0, t1)``, the state at
/// ``t1``; ``F_jacobian(x, t0, t1)``, the analytic ``Φ = ∂f/∂x`` (series for a small turn,
/// exact at ``ω = 0``); ``Q(t0, t1)``, the driving noise over the step in closed form.
#[pyclass(name = "CoordinatedTurn", module = "seqsmooth", frozen)]
pub struct PyCoordinatedTurn {
    inner: CoordinatedTurn,
}

impl PyCoordinatedTurn {
    /// `x` as the model's state (its length checked by the library's propagation).
    fn state(x: &Bound<'_, PyAny>) -> PyResult<DVector<f64>> {
        Ok(DVector::from_column_slice(series(x, "x")?.as_slice()))
    }
}

/// A square matrix as a row-major numpy array.
fn square<'py>(py: Python<'py>, m: &DMatrix<f64>) -> PyResult<Bound<'py, PyAny>> {
    let n = m.nrows();
    matrix(py, m.transpose().as_slice().to_vec(), n, n)
}

#[pymethods]
impl PyCoordinatedTurn {
    #[new]
    #[pyo3(signature = (q, *, turn_rate = None, turn_rate_noise = 0.0))]
    fn new(q: f64, turn_rate: Option<f64>, turn_rate_noise: f64) -> PyResult<Self> {
        let inner = match turn_rate {
            Some(_) if turn_rate_noise != 0.0 => {
                return Err(raise(
                    Kind::Parameter,
                    "turn_rate_noise applies only to an estimated turn rate (no turn_rate)",
                    None,
                ))
            }
            Some(w) => CoordinatedTurn::known(w, q),
            None => CoordinatedTurn::estimated(q, turn_rate_noise),
        }
        .py()?;
        Ok(Self { inner })
    }

    /// The state dimension: 6 (known rate) or 7.
    #[getter]
    fn dim(&self) -> usize {
        Dynamics::dimension(&self.inner)
    }

    /// The known turn rate, or ``None`` where it is the seventh state.
    #[getter]
    fn turn_rate(&self) -> Option<f64> {
        self.inner.turn_rate()
    }

    /// The state at ``t1`` from ``x`` at ``t0`` (either way in time).
    fn f<'py>(
        &self,
        py: Python<'py>,
        x: &Bound<'py, PyAny>,
        t0: f64,
        t1: f64,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let x = Self::state(x)?;
        let out = self.inner.propagate_state(&x, t0, t1).py()?;
        Ok(PyArray1::from_vec(py, out.as_slice().to_vec()))
    }

    /// ``Φ(t1, t0) = ∂f/∂x`` at ``x``, ``dim × dim``.
    #[allow(non_snake_case)]
    fn F_jacobian<'py>(
        &self,
        py: Python<'py>,
        x: &Bound<'py, PyAny>,
        t0: f64,
        t1: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let x = Self::state(x)?;
        let p = self.inner.propagate(&x, t0, t1).py()?;
        square(py, &p.transition)
    }

    /// The driving noise's covariance over the step ``|t1 − t0|``, ``dim × dim``.
    #[allow(non_snake_case)]
    fn Q<'py>(&self, py: Python<'py>, t0: f64, t1: f64) -> PyResult<Bound<'py, PyAny>> {
        let q = self.inner.covariance(t0, t1).py()?;
        square(py, &q)
    }

    fn __repr__(&self) -> String {
        match self.inner.turn_rate() {
            Some(w) => format!(
                "CoordinatedTurn(q={}, turn_rate={w})",
                self.inner.acceleration_density()
            ),
            None => format!(
                "CoordinatedTurn(q={}, turn_rate_noise={})",
                self.inner.acceleration_density(),
                self.inner.turn_rate_density()
            ),
        }
    }
}
