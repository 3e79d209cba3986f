//! `filter_series`, the engine of `seqsmooth.filter_frame`: many series in one set of columns,
//! each row tagged with its series (`codes`, 0-based), run through the library's
//! `StreamBank` (one filter per series, grouped by a counting sort, the series on the rayon
//! pool) with the library's rows (`AnyFilter::run_rows`), the same as `seqsmooth filter
//! --id-col`.

use crate::arrays::{matrix, series, times};
use crate::errors::{raise, IntoPy, Kind};
use crate::polynomial::{engine as engine_named, fixed_engine};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use seqsmooth::polynomial::rows::RowLayout;
use seqsmooth::polynomial::spec::{AnyFilter, FilterKind, FilterSpec};
use seqsmooth::polynomial::stream::{Chunk, StreamBank};

/// Filters the rows ``(t[i], y[i])`` of series ``codes[i]`` (0-based integers), each series
/// on its own filter of the given settings, and returns the columns ``d0..dM`` and with
/// ``sigma`` their 1σ ``s0..sM``, one value per input row, as the rows of one array
/// ``(columns, rows)`` (NaN while the series is not determined); without ``tau`` a fading
/// memory's is the median time step within series (the library's ``default_tau``); for ``fixed`` also the ``window`` cell of each row (the rows in its window),
/// as a pair. Errors are those of the earliest bad row, with its index.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (codes, t, y, kind, degree, theta = None, tau = None, window = None, engine = None, sigma = None))]
pub fn filter_series<'py>(
    py: Python<'py>,
    codes: &Bound<'py, PyAny>,
    t: &Bound<'py, PyAny>,
    y: &Bound<'py, PyAny>,
    kind: &str,
    degree: usize,
    theta: Option<f64>,
    tau: Option<f64>,
    window: Option<usize>,
    engine: Option<&str>,
    sigma: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let (ts, ys) = (times(t, "t")?, series(y, "y")?);
    let (t, y) = (ts.as_slice(), ys.as_slice());
    let n = t.len();
    let codes = codes.cast::<PyArray1<i64>>().map_err(|_| {
        raise(
            Kind::InvalidType,
            "codes must be a one-dimensional int64 numpy array",
            None,
        )
    })?;
    let codes = codes.readonly();
    let codes = codes.as_slice()?;
    if y.len() != n || codes.len() != n {
        return Err(raise(
            Kind::InvalidInput,
            format!(
                "{} codes, {n} times and {} values: one of each per row",
                codes.len(),
                y.len()
            ),
            None,
        ));
    }
    let mut channels = Vec::with_capacity(n);
    for (i, &c) in codes.iter().enumerate() {
        match usize::try_from(c) {
            Ok(c) if c < n => channels.push(c),
            _ => {
                return Err(raise(
                    Kind::InvalidInput,
                    format!(
                        "code {c} of row {i} is not a series number from 0 to {}",
                        n - 1
                    ),
                    Some(i),
                ))
            }
        }
    }
    let kind = match kind {
        "expanding" => FilterKind::Expanding,
        "fading" => FilterKind::Fading,
        "fixed" => FilterKind::Fixed,
        other => {
            return Err(raise(
                Kind::Parameter,
                format!("kind {other:?} is not one of 'expanding', 'fading', 'fixed'"),
                None,
            ))
        }
    };
    let spec = FilterSpec {
        theta,
        tau,
        window,
        sigma,
        ..FilterSpec::new(kind, degree)
    };
    let spec = match kind {
        FilterKind::Fixed => FilterSpec {
            fixed_engine: fixed_engine(engine.unwrap_or("adaptive"))?,
            ..spec
        },
        // Without tau, the library's default: the median time step within series, as
        // `seqsmooth filter` takes it without --tau.
        _ => FilterSpec {
            engine: engine_named(engine.unwrap_or("exact"))?,
            ..spec
        }
        .with_default_tau(t, &channels, true)
        .py()?,
    };
    let prototype = spec.build().py()?;
    // The fixed-memory filter's rows carry its `window` cell (the rows in each row's window).
    let layout = RowLayout {
        sigma: sigma.is_some(),
        lead: 0.0,
        trailing: kind == FilterKind::Fixed,
    };
    let stride = prototype.stride(layout);
    let mut out = vec![0.0; n * stride];
    let chunk = Chunk {
        channels: &channels,
        times: t,
        values: y,
        estimates: &mut out,
        stride,
    };
    py.detach(|| {
        let mut bank = StreamBank::growing(prototype)?;
        bank.update_par_columns(
            chunk,
            |f: &mut AnyFilter, t: &[f64], y: &[f64], o: &mut [f64]| f.run_rows(t, y, o, layout),
        )
    })
    .py()?;
    // Column by column already (each derivative's column contiguous, for the frame's columns).
    let cells = out.split_off(((degree + 1) << usize::from(layout.sigma)) * n);
    let values = matrix(py, out, stride - usize::from(layout.trailing), n)?;
    if !layout.trailing {
        return Ok(values);
    }
    let cells = PyArray1::from_vec(py, cells).into_any();
    Ok((values, cells).into_pyobject(py)?.into_any())
}
