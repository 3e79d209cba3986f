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
use seqsmooth::kalman::bank::{BankRows, KalmanBank, Panel};
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
        let out = py
            .detach(|| run_grouped(&self.bank, codes, t, z, pass))
            .py()?;
        let nis: Vec<f64> = out.nis.iter().map(|v| v.unwrap_or(f64::NAN)).collect();
        let state = matrix(py, out.state, count, n)?;
        let sigma = matrix(py, out.sigma, count, n)?;
        let nis = PyArray1::from_vec(py, nis).into_any();
        Ok((state, sigma, nis).into_pyobject(py)?.into_any())
    }
}

/// The rows by series, `pass` over the panel, the results by input row; an error's row the
/// input's ([`Error::InBatch`]). Rows already grouped (each label's rows one run, as a frame
/// sorted by its id) are the panel as they are, nothing copied; otherwise the rows are
/// grouped by a stable counting sort (each series' rows kept in input order) and the results
/// put back in input order.
fn run_grouped(
    bank: &KalmanBank<PolynomialDynamics>,
    labels: &[i64],
    t: &[f64],
    z: &[f64],
    pass: Pass,
) -> Result<BankRows, Error> {
    let (n, p, count) = (bank.states(), bank.components(), t.len());
    let run = |panel: &Panel<'_>| match pass {
        Pass::Filter => bank.filter(panel),
        Pass::Rts => bank.smooth(panel),
        Pass::Lag(lag) => bank.smooth_fixed_lag(panel, lag),
    };
    // An error of series `channel`'s row `index` named by its input row.
    let input_row = |e: Error, row: &dyn Fn(usize, usize) -> usize| match e {
        Error::InChannel {
            channel, source, ..
        } => match *source {
            Error::InBatch { index, source } => Error::InBatch {
                index: row(channel, index),
                source,
            },
            other => other,
        },
        other => other,
    };
    // The runs of equal labels; grouped when no label starts two runs.
    let mut starts: Vec<usize> = Vec::with_capacity(1024);
    for i in 0..count {
        if i == 0 || labels[i] != labels[i - 1] {
            starts.push(i);
        }
    }
    let mut firsts: Vec<i64> = starts.iter().map(|&i| labels[i]).collect();
    firsts.sort_unstable();
    if firsts.windows(2).all(|w| w[0] != w[1]) {
        starts.push(count);
        let panel = Panel {
            offsets: &starts,
            times: t,
            values: z,
        };
        return run(&panel).map_err(|e| input_row(e, &|s, k| starts[s] + k));
    }
    let mut group = std::collections::HashMap::with_capacity(firsts.len());
    let mut series = Vec::with_capacity(count);
    for &label in labels {
        let next = group.len();
        series.push(*group.entry(label).or_insert(next));
    }
    let groups = group.len();
    let mut offsets = vec![0usize; groups + 1];
    for &s in &series {
        offsets[s + 1] += 1;
    }
    for s in 0..groups {
        offsets[s + 1] += offsets[s];
    }
    let mut next = offsets.clone();
    let mut order = vec![0usize; count];
    for (i, &s) in series.iter().enumerate() {
        order[next[s]] = i;
        next[s] += 1;
    }
    let times: Vec<f64> = order.iter().map(|&i| t[i]).collect();
    let mut values = Vec::with_capacity(count * p);
    for &i in &order {
        values.extend_from_slice(&z[i * p..(i + 1) * p]);
    }
    let panel = Panel {
        offsets: &offsets,
        times: &times,
        values: &values,
    };
    let grouped = run(&panel).map_err(|e| input_row(e, &|s, k| order[offsets[s] + k]))?;
    let mut out = BankRows {
        states: n,
        state: vec![0.0; count * n],
        sigma: vec![0.0; count * n],
        nis: vec![None; count],
    };
    for (k, &i) in order.iter().enumerate() {
        out.state[i * n..(i + 1) * n].copy_from_slice(&grouped.state[k * n..(k + 1) * n]);
        out.sigma[i * n..(i + 1) * n].copy_from_slice(&grouped.sigma[k * n..(k + 1) * n]);
        out.nis[i] = grouped.nis[k];
    }
    Ok(out)
}
