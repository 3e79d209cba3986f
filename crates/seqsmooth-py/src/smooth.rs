//! `smooth`: scipy's `savgol_filter` names and meaning, on any timestamps, through the
//! library's centred fixed-memory fit ([`seqsmooth::polynomial::fixed::smooth_into`]).

use crate::arrays::series;
use crate::errors::{raise, IntoPy, Kind};
use numpy::PyArray1;
use pyo3::prelude::*;
use seqsmooth::polynomial::fixed::smooth_into;

/// Smooths (and differentiates) a whole series: at each sample, the least-squares polynomial
/// of degree ``polyorder`` through the ``window_length`` samples most nearly centred on it,
/// its ``deriv``-th derivative at that sample's time (Morrison (7.4.16), the centred
/// fixed-memory filter).
///
/// With evenly spaced samples (``t`` omitted, spacing ``delta``) and an odd
/// ``window_length`` this is ``scipy.signal.savgol_filter(y, window_length, polyorder,
/// deriv, delta, mode="interp")``: the first and last half-windows take the fit of the first
/// and last full window. With ``t``, the same windows (by sample count) fitted at the actual
/// times by QR. For an even ``window_length`` each sample sits half a step after its window's
/// centre (savgol evaluates at the half-sample centre instead).
///
/// Parameters
/// ----------
/// y : array_like
///     The values, one-dimensional.
/// window_length : int
///     Samples in each window, ``polyorder + 1`` to ``len(y)``.
/// polyorder : int
///     The polynomial degree, 0 to 24.
/// deriv : int
///     The derivative to return (0: the smoothed values); above ``polyorder`` it is 0.
/// delta : float
///     The spacing of evenly spaced samples (ignored with ``t``).
/// t : array_like, optional
///     The sample times, strictly increasing, one per value.
///
/// Returns
/// -------
/// numpy.ndarray
///     The ``deriv``-th derivative at each sample, in units of ``y`` per unit of ``t``
///     (or of ``delta``) to the power ``deriv``.
#[pyfunction]
#[pyo3(signature = (y, window_length, polyorder, deriv = 0, delta = 1.0, t = None))]
pub fn smooth<'py>(
    py: Python<'py>,
    y: &Bound<'py, PyAny>,
    window_length: usize,
    polyorder: usize,
    deriv: usize,
    delta: f64,
    t: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let ys = series(y, "y")?;
    let y = ys.as_slice();
    let n = y.len();
    let given = t.map(|t| series(t, "t")).transpose()?;
    let times: Vec<f64>;
    let t = match &given {
        Some(ts) => {
            let t = ts.as_slice();
            if t.len() != n {
                return Err(raise(
                    Kind::InvalidInput,
                    format!("t has {} values and y {n}: one time per value", t.len()),
                    None,
                ));
            }
            t
        }
        None => {
            if !(delta.is_finite() && delta > 0.0) {
                return Err(raise(
                    Kind::Parameter,
                    format!("delta {delta} is invalid: it must be positive and finite"),
                    None,
                ));
            }
            times = (0..n).map(|i| i as f64 * delta).collect();
            &times
        }
    };
    if n == 0 {
        return Err(raise(Kind::InvalidInput, "y is empty", None));
    }
    let w = polyorder + 1;
    let mut out = vec![0.0; n * w];
    py.detach(|| smooth_into(t, y, polyorder, window_length, &mut out))
        .py()?;
    let column: Vec<f64> = if deriv <= polyorder {
        out.iter().skip(deriv).step_by(w).copied().collect()
    } else {
        vec![0.0; n]
    };
    Ok(PyArray1::from_vec(py, column))
}
