//! `gains` and `vrf`: the gains (Tables 9.1, 13.1) and the scaled variance-reduction matrices
//! (Tables 9.2, 13.2-13.3; fixed memory (7.5.22)-(7.5.26)) of the expanding-, fading- and
//! fixed-memory filters, as `seqsmooth gains` and `seqsmooth vrf` give them: in `f64` (numpy)
//! or exactly (`fractions.Fraction`).

use crate::arrays::matrix;
use crate::errors::{raise, IntoPy, Kind};
use nalgebra::DMatrix;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyList, PyString};
use seqsmooth::polynomial::expanding::gains::expanding_gains;
use seqsmooth::polynomial::expanding::vrf::expanding_vrf;
use seqsmooth::polynomial::fading::gains::fading_gains;
use seqsmooth::polynomial::fading::vrf::fading_vrf;
use seqsmooth::polynomial::fixed::{check_lead_steps, check_window, covariance};
use seqsmooth::polynomial::form::{EstimateForm, GainForm};
use seqsmooth::scalar::{parse_rational, ratio_to_f64, Rational};

/// A number given exactly: a `Fraction`, an `int`, a `str` (`"9/10"`, `"0.9"`) or a `float`,
/// the float read as the shortest decimal that prints it (`0.9` is `9/10`, as on the command
/// line).
fn exact(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Rational> {
    let text = if obj.is_instance_of::<PyString>() {
        obj.extract::<String>()?
    } else {
        obj.str()?.to_string()
    };
    parse_rational(&text).ok_or_else(|| {
        raise(
            Kind::Parameter,
            format!("{name} {text} is not a number (a Fraction, an int, a float or a str such as \"9/10\")"),
            None,
        )
    })
}

/// θ exactly, strictly between 0 and 1.
fn theta_of(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Rational> {
    let Some(obj) = obj else {
        return Err(raise(
            Kind::Parameter,
            "kind 'fading' needs theta, the discount per sample (0 < theta < 1)",
            None,
        ));
    };
    let theta = exact(obj, "theta")?;
    // The library's range of θ, exactly.
    seqsmooth::polynomial::check_theta_of(&theta).map_err(|_| {
        raise(
            Kind::Parameter,
            format!("theta {theta} is out of range: it must lie strictly between 0 and 1"),
            None,
        )
    })?;
    Ok(theta)
}

fn degree_of(degree: usize) -> PyResult<usize> {
    // The library's range of a polynomial degree.
    seqsmooth::polynomial::check_degree(degree).py()?;
    Ok(degree)
}

fn n_of(n: Option<u64>) -> PyResult<u64> {
    n.ok_or_else(|| {
        raise(
            Kind::Parameter,
            "kind 'expanding' needs n, the 0-based index of the newest sample",
            None,
        )
    })
}

/// Refuses an argument given to a kind it does not apply to.
fn only<T>(value: &Option<T>, name: &str, kinds: &str) -> PyResult<()> {
    match value {
        Some(_) => Err(raise(
            Kind::Parameter,
            format!("{name} applies only to kind {kinds}"),
            None,
        )),
        None => Ok(()),
    }
}

fn form_of(form: &str) -> PyResult<bool> {
    match form {
        "current" => Ok(false),
        "predictor" => Ok(true),
        other => Err(raise(
            Kind::Parameter,
            format!("form {other:?} is not one of 'current', 'predictor'"),
            None,
        )),
    }
}

/// A rational as a `fractions.Fraction`.
fn fraction<'py>(py: Python<'py>, r: &Rational) -> PyResult<Bound<'py, PyAny>> {
    py.import("fractions")?
        .getattr("Fraction")?
        .call1((r.to_string(),))
}

/// The gains of the ``degree``-``m`` filter (Morrison Tables 9.1, 13.1): for the
/// expanding-memory filter at sample index ``n`` (0-based), for the fading-memory filter with
/// discount ``theta`` per sample; in the current form ``Z*_{n,n} = Z*_{n,n−1} + H ε`` or the
/// predictor form (gain ``Φ(1) H``). Scaled (Morrison's ``Z``), as ``seqsmooth gains``.
///
/// Parameters
/// ----------
/// kind : {"expanding", "fading"}
/// degree : int
/// n : int, optional
///     Expanding memory: the newest sample's 0-based index.
/// theta : Fraction, int, float or str, optional
///     Fading memory: the discount per sample, ``0 < theta < 1`` (a float is read as its
///     shortest decimal: ``0.9`` is ``9/10``).
/// form : {"current", "predictor"}
/// exact : bool
///     ``True``: a list of ``fractions.Fraction``; else a numpy array.
#[pyfunction]
#[pyo3(signature = (kind, degree, n = None, theta = None, form = "current", exact = false))]
pub fn gains<'py>(
    py: Python<'py>,
    kind: &str,
    degree: usize,
    n: Option<u64>,
    theta: Option<&Bound<'py, PyAny>>,
    form: &str,
    exact: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let m = degree_of(degree)?;
    let form = if form_of(form)? {
        GainForm::Predictor
    } else {
        GainForm::Current
    };
    let values: Vec<Rational> = match kind {
        "expanding" => {
            only(&theta, "theta", "'fading'")?;
            let n = n_of(n)?;
            if !exact {
                let g = py.detach(|| expanding_gains::<f64>(m, n, form));
                return Ok(PyArray1::from_vec(py, g).into_any());
            }
            py.detach(|| expanding_gains::<Rational>(m, n, form))
        }
        "fading" => {
            only(&n, "n", "'expanding'")?;
            let theta = theta_of(theta)?;
            if !exact {
                let t = ratio_to_f64(&theta);
                let g = py.detach(|| fading_gains::<f64>(m, t, form));
                return Ok(PyArray1::from_vec(py, g).into_any());
            }
            py.detach(|| fading_gains::<Rational>(m, theta, form))
        }
        other => {
            return Err(raise(
                Kind::Parameter,
                format!("kind {other:?} is not one of 'expanding', 'fading'"),
                None,
            ))
        }
    };
    let list = PyList::empty(py);
    for v in &values {
        list.append(fraction(py, v)?)?;
    }
    Ok(list.into_any())
}

/// The scaled variance-reduction matrix (the covariance of the scaled estimate per unit
/// noise variance) of the ``degree``-``m`` filter: expanding memory at sample index ``n``
/// (Table 9.2), fading memory with ``theta`` (Tables 13.2-13.3, (13.7.1)), in the current or
/// predictor ``form``; fixed memory over ``window`` samples at ``lead`` samples after the
/// newest (``W(h) W(h)ᵀ``, (7.5.22)-(7.5.26): 0 the current estimate, 1 the 1-step
/// prediction, ``-(window-1)/2`` the centre). As ``seqsmooth vrf``.
///
/// Returns a numpy array ``(m+1, m+1)``, or with ``exact=True`` a list of rows of
/// ``fractions.Fraction``.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (kind, degree, n = None, theta = None, window = None, lead = None, form = None, exact = false))]
pub fn vrf<'py>(
    py: Python<'py>,
    kind: &str,
    degree: usize,
    n: Option<u64>,
    theta: Option<&Bound<'py, PyAny>>,
    window: Option<usize>,
    lead: Option<&Bound<'py, PyAny>>,
    form: Option<&str>,
    exact: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let m = degree_of(degree)?;
    let estimate_form = |form: Option<&str>| -> PyResult<EstimateForm> {
        Ok(if form_of(form.unwrap_or("current"))? {
            EstimateForm::Predictor
        } else {
            EstimateForm::Current
        })
    };
    let rational: DMatrix<Rational>;
    match kind {
        "expanding" | "fading" => {
            only(&window, "window", "'fixed'")?;
            only(&lead, "lead", "'fixed' (expanding and fading take form)")?;
            let form = estimate_form(form)?;
            if kind == "expanding" {
                only(&theta, "theta", "'fading'")?;
                let n = n_of(n)?;
                // The range of n for the degree is the library's (`expanding_vrf` checks it).
                // Exact, then rounded (the f64 recursion overflows for large n at high degree).
                rational = py.detach(|| expanding_vrf::<Rational>(m, n, form)).py()?;
            } else {
                only(&n, "n", "'expanding'")?;
                let theta = theta_of(theta)?;
                if !exact {
                    let t = ratio_to_f64(&theta);
                    let s = py.detach(|| fading_vrf::<f64>(m, t, form)).py()?;
                    return matrix(py, s.transpose().as_slice().to_vec(), m + 1, m + 1);
                }
                rational = py.detach(|| fading_vrf::<Rational>(m, theta, form)).py()?;
            }
        }
        "fixed" => {
            only(&n, "n", "'expanding'")?;
            only(&theta, "theta", "'fading'")?;
            only(&form, "form", "'expanding' and 'fading' (fixed takes lead)")?;
            let window = match window {
                // The window's range for the degree is the library's.
                Some(w) => check_window(m, w).map(|()| w).py()?,
                None => {
                    return Err(raise(
                        Kind::Parameter,
                        "kind 'fixed' needs window, the number of samples in the window",
                        None,
                    ))
                }
            };
            let span = window as u64 - 1;
            let h = match lead {
                Some(l) => self::exact(l, "lead")?,
                None => Rational::from_integer(0.into()),
            };
            // The library's range of a lead in samples.
            check_lead_steps(ratio_to_f64(&h)).py()?;
            if !exact {
                let h = ratio_to_f64(&h);
                let s = py.detach(|| covariance::<f64>(m, span, h)).py()?;
                return matrix(py, s.transpose().as_slice().to_vec(), m + 1, m + 1);
            }
            rational = py.detach(|| covariance::<Rational>(m, span, h)).py()?;
        }
        other => {
            return Err(raise(
                Kind::Parameter,
                format!("kind {other:?} is not one of 'expanding', 'fading', 'fixed'"),
                None,
            ))
        }
    }
    if !exact {
        let values: Vec<f64> = rational.transpose().iter().map(ratio_to_f64).collect();
        return matrix(py, values, m + 1, m + 1);
    }
    let rows = PyList::empty(py);
    for i in 0..=m {
        let row = PyList::empty(py);
        for j in 0..=m {
            row.append(fraction(py, &rational[(i, j)])?)?;
        }
        rows.append(row)?;
    }
    Ok(rows.into_any())
}
