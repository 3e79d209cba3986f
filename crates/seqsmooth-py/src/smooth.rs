//! `smooth`: scipy's `savgol_filter` names and meaning, on any timestamps, through the
//! library's centred fixed-memory fit ([`seqsmooth::polynomial::fixed::smooth_into`]).

use crate::arrays::{series, times};
use crate::errors::{raise, scipy, IntoPy, Kind};
use numpy::PyArray1;
use pyo3::prelude::*;
use seqsmooth::polynomial::fixed::{even_times, smooth_into, smooth_with_sigma_into};

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
///     The sample times, strictly increasing, one per value: numbers, or dates (numpy
///     ``datetime64``, pandas, Polars, Arrow) read as seconds since the Unix epoch (as
///     :func:`seconds`; naive dates are UTC).
/// sigma : float, optional
///     The noise standard deviation of ``y``, for ``return_sigma``; without it σ is estimated
///     from each window's residuals, ``s² = Σ r²/(window_length - polyorder - 1)`` (which
///     needs ``window_length > polyorder + 1``; with Gaussian noise ``3σ`` then covers the
///     truth with the Student-t probability of that many degrees of freedom, 99.2 % at 18).
/// return_sigma : bool
///     Also return the 1σ of each value, from its window fit's covariance (Morrison ch. 7:
///     σ² times the variance-reduction factor of the sample's place in its window).
///
/// Returns
/// -------
/// numpy.ndarray or (numpy.ndarray, numpy.ndarray)
///     The ``deriv``-th derivative at each sample, in units of ``y`` per unit of ``t``
///     (or of ``delta``) to the power ``deriv``; with ``return_sigma`` also its 1σ.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (y, window_length, polyorder, deriv = 0, delta = 1.0, t = None, sigma = None, return_sigma = false))]
pub fn smooth<'py>(
    py: Python<'py>,
    y: &Bound<'py, PyAny>,
    window_length: usize,
    polyorder: usize,
    deriv: usize,
    delta: f64,
    t: Option<&Bound<'py, PyAny>>,
    sigma: Option<f64>,
    return_sigma: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let ys = series(y, "y")?;
    let y = ys.as_slice();
    let n = y.len();
    let given = t.map(|t| times(t, "t")).transpose()?;
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
            times = even_times(n, delta).py_in(&scipy)?;
            &times
        }
    };
    if n == 0 {
        return Err(raise(Kind::InvalidInput, "y is empty", None));
    }
    let w = polyorder + 1;
    let mut out = vec![0.0; n * w];
    let column = |rows: &[f64]| -> Vec<f64> {
        if deriv <= polyorder {
            rows.iter().skip(deriv).step_by(w).copied().collect()
        } else {
            vec![0.0; n]
        }
    };
    if !return_sigma {
        py.detach(|| smooth_into(t, y, polyorder, window_length, &mut out))
            .py_in(&scipy)?;
        return Ok(PyArray1::from_vec(py, column(&out)).into_any());
    }
    let mut sd = vec![0.0; n * w];
    py.detach(|| smooth_with_sigma_into(t, y, polyorder, window_length, sigma, &mut out, &mut sd))
        .py_in(&scipy)?;
    let (d, s) = (
        PyArray1::from_vec(py, column(&out)),
        PyArray1::from_vec(py, column(&sd)),
    );
    Ok((d, s).into_pyobject(py)?.into_any())
}
