//! Gauss rules for any positive measure, polynomial samples (Villien & Ostertag 2009) and
//! Luenberger's gains (1967): `gauss_rule`, `polynomial_samples`, `luenberger_gains`.

use crate::arrays::series;
use crate::errors::{raise, IntoPy, Kind};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyList;
use seqsmooth::basis::{GaussRule, Jacobi};
use seqsmooth::paml::PolynomialSamples;
use seqsmooth::polynomial::expanding::continuous::{hilbert_gains, luenberger_gains as gains};
use seqsmooth::scalar::Rational;

/// The largest number of nodes minus one [`gauss_rule`] takes.
const MAX_GAUSS_DEGREE: usize = 1_000;

fn array<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyAny> {
    PyArray1::from_vec(py, v).into_any()
}

/// The Gauss rule of ``n+1`` nodes for a positive measure, by Golub–Welsch on the recurrence
/// of its orthonormal polynomials: ``Σ_k λ_k f(t_k) = ∫ f dμ`` for every polynomial of degree
/// ``≤ 2n+1`` (Villien & Ostertag 2009, Lemma 3, eq. 26).
///
/// Parameters
/// ----------
/// n : int
///     The rule has ``n+1`` nodes.
/// t : array_like, optional
///     Sample times: the discrete measure ``Σ_j w_j δ(t − t_j)`` (at least ``n+1`` distinct).
/// weights : array_like, optional
///     ``w_j > 0`` with ``t`` (e.g. ``1/σ²``; default all 1).
/// kind : {"legendre", "chebyshev"}
///     Without ``t``: ``dt`` or ``dt/√((t − a)(b − t))`` on ``[a, b]``.
/// a, b : float
///     The interval for ``kind``.
///
/// Returns
/// -------
/// (nodes, weights) : two numpy arrays of ``n+1`` (nodes ascending; the weights are the
/// Christoffel numbers, summing to the measure's mass).
#[pyfunction]
#[pyo3(signature = (n, t = None, weights = None, kind = "legendre", a = -1.0, b = 1.0))]
pub fn gauss_rule<'py>(
    py: Python<'py>,
    n: usize,
    t: Option<&Bound<'py, PyAny>>,
    weights: Option<&Bound<'py, PyAny>>,
    kind: &str,
    a: f64,
    b: f64,
) -> PyResult<Bound<'py, PyAny>> {
    if n > MAX_GAUSS_DEGREE {
        return Err(raise(
            Kind::Parameter,
            format!("n {n} is out of range: at most {MAX_GAUSS_DEGREE}"),
            None,
        ));
    }
    let rule: GaussRule = match t {
        Some(t) => {
            let ts = series(t, "t")?;
            let ws = match weights {
                Some(w) => series(w, "weights")?.as_slice().to_vec(),
                None => vec![1.0; ts.as_slice().len()],
            };
            let ts = ts.as_slice().to_vec();
            py.detach(|| Jacobi::discrete(&ts, &ws, n).and_then(|j| j.gauss()))
                .py()?
        }
        None => {
            if weights.is_some() {
                return Err(raise(
                    Kind::Parameter,
                    "weights go with t (sample times)",
                    None,
                ));
            }
            let jacobi = match kind {
                "legendre" => Jacobi::legendre(n, a, b),
                "chebyshev" => Jacobi::chebyshev(n, a, b),
                other => {
                    return Err(raise(
                        Kind::Parameter,
                        format!("kind {other:?} is not one of 'legendre', 'chebyshev'"),
                        None,
                    ))
                }
            }
            .py()?;
            py.detach(|| jacobi.gauss()).py()?
        }
    };
    let nodes = rule.nodes();
    Ok((array(py, nodes), array(py, rule.weights))
        .into_pyobject(py)?
        .into_any())
}

/// The ``n+1`` polynomial samples of a segment (Villien & Ostertag 2009, §II): its weighted
/// least-squares polynomial of degree ``n`` (weights ``1/σ²``) at the Gauss nodes of the
/// samples' own measure, where the samples are uncorrelated with variances ``1/λ_k``
/// (eqs. 19-21, 37).
///
/// Parameters
/// ----------
/// t, y : array_like
///     The segment's times (any order, at least ``n+1`` distinct) and values.
/// sigma : float or array_like
///     The noise standard deviation, one for all or one per sample.
/// n : int
///     The polynomial's degree.
///
/// Returns
/// -------
/// (times, values, variances) : three numpy arrays of ``n+1``.
#[pyfunction]
pub fn polynomial_samples<'py>(
    py: Python<'py>,
    t: &Bound<'py, PyAny>,
    y: &Bound<'py, PyAny>,
    sigma: &Bound<'py, PyAny>,
    n: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let (ts, ys) = crate::arrays::pair(t, y)?;
    let (ts, ys) = (ts.as_slice().to_vec(), ys.as_slice().to_vec());
    let sigmas = match sigma.extract::<f64>() {
        Ok(s) => vec![s; ts.len()],
        Err(_) => series(sigma, "sigma")?.as_slice().to_vec(),
    };
    if n > MAX_GAUSS_DEGREE {
        return Err(raise(
            Kind::Parameter,
            format!("n {n} is out of range: at most {MAX_GAUSS_DEGREE}"),
            None,
        ));
    }
    let ps = py
        .detach(|| PolynomialSamples::from_segment(&ts, &ys, &sigmas, n))
        .py()?;
    let times = ps.times();
    Ok((
        array(py, times),
        array(py, ps.values),
        array(py, ps.variances),
    )
        .into_pyobject(py)?
        .into_any())
}

/// Luenberger's gains ``b = H⁻¹·1`` for ``n`` coefficients (a polynomial of degree
/// ``n − 1``; ``H`` the Hilbert matrix): his continuous-time law ``a_i' = (b_i/T^i) ε(T)``.
/// Integers: ``b_j = (−1)^(n+j) (n+j−1)!/(((j−1)!)² (n−j)!)`` (his explicit expression with
/// its factorial squared).
///
/// Returns a numpy array, or with ``exact=True`` a list of ``int`` (by exact inversion of
/// ``H``).
#[pyfunction]
#[pyo3(signature = (n, exact = false))]
pub fn luenberger_gains<'py>(
    py: Python<'py>,
    n: usize,
    exact: bool,
) -> PyResult<Bound<'py, PyAny>> {
    if n == 0 || n > 60 {
        return Err(raise(
            Kind::Parameter,
            format!("n {n} is out of range: 1 to 60 coefficients"),
            None,
        ));
    }
    if !exact {
        return Ok(array(py, gains::<f64>(n)));
    }
    let b: Vec<Rational> = py.detach(|| hilbert_gains(n));
    let list = PyList::empty(py);
    for v in &b {
        list.append(
            py.import("builtins")?
                .getattr("int")?
                .call1((v.to_integer().to_string(),))?,
        )?;
    }
    Ok(list.into_any())
}
