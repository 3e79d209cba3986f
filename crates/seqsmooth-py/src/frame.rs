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
use seqsmooth::polynomial::rows::{decisions, RowLayout, Undecided, DECISION_CELLS};
use seqsmooth::polynomial::spec::{AnyFilter, FilterKind, FilterSpec};
use seqsmooth::polynomial::stream::{Chunk, StreamBank};

/// Filters the rows ``(t[i], y[i])`` of series ``codes[i]`` (0-based integers), each series
/// on its own filter of the given settings (``kind`` ``"expanding"``, ``"fading"``,
/// ``"fixed"`` or ``"auto"``), and returns the columns of ``seqsmooth filter``'s rows, one
/// value per input row, as the rows of one array ``(columns, rows)``, and their names:
/// ``d0..dM``, with ``sigma`` (always for ``auto``) their 1σ ``s0..sM``, then the kind's cells
/// (``fixed``: ``window``; ``auto``: ``noise``, ``outlier`` — the final decision —,
/// ``misfit``, ``bias``); NaN where the command leaves a cell empty. Without ``tau`` the
/// ``τ`` of ``fading`` and ``auto`` is the median time step within series (the library's
/// ``default_tau``). Errors are those of the earliest bad row, with its index.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (codes, t, y, kind, degree, theta = None, tau = None, window = None, engine = None, sigma = None, review_window = None))]
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
    review_window: Option<usize>,
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
    let spec = spec(
        kind,
        degree,
        theta,
        tau,
        window,
        engine,
        sigma,
        review_window,
    )?;
    // Without tau, the library's default: the median time step within series, as
    // `seqsmooth filter` takes it without --tau.
    let spec = spec.with_default_tau(t, &channels, true).py()?;
    let prototype = spec.build().py()?;
    let (layout, names) = rows_of(&spec, &prototype);
    let extra = prototype.trailing_columns();
    let shown = names.len();
    let stride = prototype.stride(layout);
    let mut out = vec![0.0; n * stride];
    py.detach(|| {
        let mut bank = StreamBank::growing(prototype)?;
        let chunk = Chunk {
            channels: &channels,
            times: t,
            values: y,
            estimates: &mut out,
            stride,
        };
        bank.update_par_columns(
            chunk,
            |f: &mut AnyFilter, t: &[f64], y: &[f64], o: &mut [f64]| f.run_rows(t, y, o, layout),
        )?;
        if let Some(k) = extra.iter().position(|&c| c == "outlier") {
            let (cells, decided) = out.split_at_mut(shown * n);
            let flags = &mut cells[(shown - extra.len() + k) * n..][..n];
            final_outliers(&mut bank, &channels, decided, flags);
        }
        Ok::<_, seqsmooth::Error>(())
    })
    .py()?;
    // Column by column already (each column contiguous, for the frame's columns); the
    // automatic filter's decision cells dropped.
    out.truncate(shown * n);
    let values = matrix(py, out, shown, n)?;
    Ok((values, names).into_pyobject(py)?.into_any())
}

/// The filter of `kind` (``"expanding"``, ``"fading"``, ``"fixed"``, ``"auto"``) with
/// `filter_series`' settings, its `τ` as given (the default not resolved yet).
#[allow(clippy::too_many_arguments)]
pub(crate) fn spec(
    kind: &str,
    degree: usize,
    theta: Option<f64>,
    tau: Option<f64>,
    window: Option<usize>,
    engine: Option<&str>,
    sigma: Option<f64>,
    review_window: Option<usize>,
) -> PyResult<FilterSpec> {
    let kind = match kind {
        "expanding" => FilterKind::Expanding,
        "fading" => FilterKind::Fading,
        "fixed" => FilterKind::Fixed,
        "auto" => FilterKind::Automatic,
        other => {
            return Err(raise(
                Kind::Parameter,
                format!("kind {other:?} is not one of 'expanding', 'fading', 'fixed', 'auto'"),
                None,
            ))
        }
    };
    let spec = FilterSpec {
        theta,
        tau,
        window,
        sigma,
        review_window,
        ..FilterSpec::new(kind, degree)
    };
    Ok(match kind {
        FilterKind::Fixed => FilterSpec {
            fixed_engine: fixed_engine(engine.unwrap_or("adaptive"))?,
            ..spec
        },
        _ => FilterSpec {
            engine: engine_named(engine.unwrap_or("exact"))?,
            ..spec
        },
    })
}

/// The rows `prototype` (built from `spec`) writes for `filter_series`, and the names of the
/// columns shown: ``d0..dM``, with σ ``s0..sM``, then the kind's cells (fixed memory's
/// `window`, the automatic filter's `noise`, `outlier`, `misfit`, `bias`; the automatic filter
/// always has its 1σ). The automatic filter's decision cells follow, not shown.
pub(crate) fn rows_of(spec: &FilterSpec, prototype: &AnyFilter) -> (RowLayout, Vec<String>) {
    let extra = prototype.trailing_columns();
    let layout = RowLayout {
        sigma: spec.writes_sigma(),
        lead: 0.0,
        trailing: !extra.is_empty(),
    };
    let width = spec.degree + 1;
    let mut names: Vec<String> = (0..width).map(|k| format!("d{k}")).collect();
    if layout.sigma {
        names.extend((0..width).map(|k| format!("s{k}")));
    }
    names.extend(extra.iter().map(|c| c.to_string()));
    (layout, names)
}

/// Sets each row's `outlier` cell in `flags` (by row; empty where the filter withheld the
/// row) to the automatic filter's final decision, as `seqsmooth filter` writes it: the
/// decisions of each row's update (`decided`: the [`DECISION_CELLS`] columns, by row), then
/// those of each series' [`finish`](seqsmooth::polynomial::AutomaticFilter::finish), the whole
/// input being here, each on its series' oldest undecided row ([`Undecided`], the library's
/// rule).
fn final_outliers(
    bank: &mut StreamBank<AnyFilter>,
    channels: &[usize],
    decided: &[f64],
    flags: &mut [f64],
) {
    let n = channels.len();
    let mut set = |row: usize, rejected: bool| {
        if !flags[row].is_nan() {
            flags[row] = f64::from(u8::from(rejected));
        }
    };
    let mut open = Undecided::default();
    let mut cells = [0.0; DECISION_CELLS];
    for (i, &c) in channels.iter().enumerate() {
        for (k, cell) in cells.iter_mut().enumerate() {
            *cell = decided[k * n + i];
        }
        open.push(c, i, &decisions(&cells), &mut set);
    }
    for c in 0..bank.channels() {
        if let Some(f) = bank.channel_mut(c).and_then(AnyFilter::automatic_mut) {
            open.decide(c, &f.finish(), &mut set);
        }
    }
}
