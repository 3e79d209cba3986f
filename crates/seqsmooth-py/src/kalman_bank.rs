//! `KalmanBank`: the library's `kalman::bank::KalmanBank` over the polynomial model (degree,
//! axes, driving noise `q`, the observation `M`, `R`, the prior every series starts from at its
//! first time), many series in one set of arrays, each row tagged with its series (`series`,
//! int64 labels, any values, rows in any order: rows already grouped by label are taken as
//! they are; otherwise grouped by a stable counting sort, each series' rows kept in input
//! order), the results in input order. The engine of `seqsmooth.kalman_frame`.

use crate::arrays::{matrix, series, table};
use crate::errors::{raise, IntoPy, Kind};
use crate::kalman::{noise, observation_from, polynomial_prior};
use nalgebra::DMatrix;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use seqsmooth::kalman::bank::{Grouping, KalmanBank, Panel};
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::measurement::NoiseCovariance;
use seqsmooth::Error;

/// Many series through one Kalman filter's model: the polynomial model of ``degree`` on
/// ``axes`` axes with white-noise driving of spectral density ``q``, observed by
/// ``observation`` (default: the positions) with noise ``R``; every series starts from ``x0``,
/// ``P0`` at its own first time.
#[pyclass(name = "KalmanBank", module = "seqsmooth", frozen)]
pub struct PyKalmanBank {
    bank: KalmanBank<PolynomialDynamics>,
}

/// Which pass: the filter, the RTS smoother, or the fixed-lag smoother of a lag.
#[derive(Clone, Copy)]
enum Pass {
    Filter,
    Rts,
    Lag(usize),
}

#[pymethods]
impl PyKalmanBank {
    #[new]
    #[allow(non_snake_case)]
    #[pyo3(signature = (degree, x0, P0, R, axes = 1, q = 0.0, observation = None))]
    fn new(
        degree: usize,
        x0: &Bound<'_, PyAny>,
        P0: &Bound<'_, PyAny>,
        R: &Bound<'_, PyAny>,
        axes: usize,
        q: f64,
        observation: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let n = seqsmooth::polynomial::check_model(degree, axes).py()?;
        let (x, p0) = polynomial_prior(x0, P0, degree, axes, n)?;
        let observe = observation_from(observation, axes, n)?;
        let p = seqsmooth::model::observation::Observation::components(&observe);
        let r = match noise(R, p)? {
            NoiseCovariance::Full(r) => r,
            NoiseCovariance::Variances(v) => {
                DMatrix::from_diagonal(&nalgebra::DVector::from_vec(v))
            }
            NoiseCovariance::Identity => DMatrix::identity(p, p),
        };
        let mut bank =
            KalmanBank::new(PolynomialDynamics::new(degree, axes), observe, r, x, p0).py()?;
        if q != 0.0 {
            bank = bank
                .with_process_noise(WhiteNoiseDerivative::new(degree, axes, q).py()?)
                .py()?;
        }
        Ok(Self { bank })
    }

    /// The number of states ``n``.
    #[getter]
    fn states(&self) -> usize {
        self.bank.states()
    }

    /// The observed components ``p``.
    #[getter]
    fn components(&self) -> usize {
        self.bank.components()
    }

    /// The filter over every series: ``(state, sigma, nis)`` by input row.
    #[pyo3(signature = (series, t, z))]
    fn filter<'py>(
        &self,
        py: Python<'py>,
        series: &Bound<'py, PyAny>,
        t: &Bound<'py, PyAny>,
        z: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.run(py, series, t, z, Pass::Filter)
    }

    /// The RTS smoother over every series: ``(state, sigma, nis)`` by input row.
    #[pyo3(signature = (series, t, z))]
    fn smooth<'py>(
        &self,
        py: Python<'py>,
        series: &Bound<'py, PyAny>,
        t: &Bound<'py, PyAny>,
        z: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.run(py, series, t, z, Pass::Rts)
    }

    /// The fixed-lag smoother of ``lag`` rows over every series: ``(state, sigma, nis)``.
    #[pyo3(signature = (series, t, z, lag))]
    fn fixed_lag_smoother<'py>(
        &self,
        py: Python<'py>,
        series: &Bound<'py, PyAny>,
        t: &Bound<'py, PyAny>,
        z: &Bound<'py, PyAny>,
        lag: usize,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.run(py, series, t, z, Pass::Lag(lag))
    }
}

impl PyKalmanBank {
    /// The rows grouped by series, `pass` run over them without the GIL, the results in input
    /// order: `(state rows × n, sigma rows × n, nis rows)`, NaN NIS where every component was
    /// missing. An error names the input row.
    fn run<'py>(
        &self,
        py: Python<'py>,
        codes: &Bound<'py, PyAny>,
        t: &Bound<'py, PyAny>,
        z: &Bound<'py, PyAny>,
        pass: Pass,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (n, p) = (self.bank.states(), self.bank.components());
        let ts = series(t, "t")?;
        let (zs, rows, cols) = table(z, "z")?;
        let (t, z) = (ts.as_slice(), zs.as_slice());
        let codes = codes.cast::<PyArray1<i64>>().map_err(|_| {
            raise(
                Kind::InvalidType,
                "series must be a one-dimensional int64 numpy array (each row's series label)",
                None,
            )
        })?;
        let codes = codes.readonly();
        let codes = codes.as_slice()?;
        let count = t.len();
        if rows != count || cols != p || codes.len() != count {
            return Err(raise(
                Kind::InvalidInput,
                format!(
                    "{} series codes, {count} times and z {rows}x{cols}: one code, one time \
                     and {p} values per row",
                    codes.len()
                ),
                None,
            ));
        }
        let (state, sigma, nis) = py
            .detach(|| run_grouped(&self.bank, codes, t, z, pass))
            .py()?;
        let state = matrix(py, state, count, n)?;
        let sigma = matrix(py, sigma, count, n)?;
        // The NIS column (NaN where every component was missing), handed to numpy as it is:
        // the bank's own buffer, or `run_grouped`'s copy in input order for interleaved rows.
        let nis = PyArray1::from_vec(py, nis).into_any();
        Ok((state, sigma, nis).into_pyobject(py)?.into_any())
    }
}

/// `(state, sigma, nis)` by row: `n`, `n` and one a row, the NIS NaN where none.
type Columns = (Vec<f64>, Vec<f64>, Vec<f64>);

/// The rows by series (the library's [`Grouping`]), `pass` over the panel, the results by
/// input row; an error's row the input's ([`Error::InBatch`]). Rows already grouped (each
/// label's rows one run, as a frame sorted by its id) are the panel as they are, nothing
/// copied; otherwise the rows are grouped by a stable counting sort (each series' rows kept in
/// input order) and the results put back in input order.
fn run_grouped(
    bank: &KalmanBank<PolynomialDynamics>,
    labels: &[i64],
    t: &[f64],
    z: &[f64],
    pass: Pass,
) -> Result<Columns, Error> {
    let (n, p) = (bank.states(), bank.components());
    let grouping = Grouping::from_labels(labels);
    let (times, values) = (grouping.gather(t, 1), grouping.gather(z, p));
    let panel = Panel {
        offsets: grouping.offsets(),
        times: &times,
        values: &values,
    };
    let grouped = match pass {
        Pass::Filter => bank.filter(&panel),
        Pass::Rts => bank.smooth(&panel),
        Pass::Lag(lag) => bank.smooth_fixed_lag(&panel, lag),
    }
    .map_err(|e| match e {
        // Series `channel`'s row `index` named by its input row.
        Error::InChannel {
            channel, source, ..
        } => match *source {
            Error::InBatch { index, source } => Error::InBatch {
                index: grouping.input_row(channel, index),
                source,
            },
            other => other,
        },
        other => other,
    })?;
    if grouping.order().is_none() {
        return Ok(grouped.into_columns());
    }
    let (state, sigma, nis) = grouped.into_columns();
    Ok((
        grouping.scatter(&state, n),
        grouping.scatter(&sigma, n),
        grouping.scatter(&nis, 1),
    ))
}
