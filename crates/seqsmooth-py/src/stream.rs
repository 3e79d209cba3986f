//! `FilterStream`: `filter_series` kept open, for rows that come in chunks (the batches of a
//! Polars streaming query, `seqsmooth.polars.filter_batches`): one library `StreamBank` of
//! `AnyFilter`s, one filter per series, carried from chunk to chunk, as `seqsmooth filter
//! --id-col` carries it from one chunk of its input to the next. Each chunk's rows come back
//! with `filter_series`' columns; the automatic filter's rows wait, in input order, until their
//! `outlier` flag is final (the library's `Undecided` rule), so that the rows are those of
//! `filter_series` on the whole input, bit for bit, in memory bounded by the series (their
//! filters and their rows still undecided), not by the rows.

use crate::arrays::{matrix, series, times};
use crate::errors::{raise, IntoPy, Kind};
use crate::frame::{rows_of, spec as spec_of};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use seqsmooth::polynomial::rows::{decisions, RowLayout, Undecided, DECISION_CELLS};
use seqsmooth::polynomial::spec::{AnyFilter, FilterKind, FilterSpec};
use seqsmooth::polynomial::stream::{Chunk, StreamBank};
use seqsmooth::polynomial::tau::TAU_SCAN_ROWS;
use std::collections::VecDeque;

/// The rows of many series as they come, chunk by chunk, through one filter per series of the
/// given settings (those of ``filter_series``); the rows of each chunk in order, numbered from
/// 0 at the first chunk's first row. Without ``tau`` the ``τ`` of ``fading`` and ``auto`` is
/// the default of the first chunk's rows (the library's ``default_tau``, the median time step
/// within series among the first ``TAU_SCAN_ROWS`` rows): the first chunk must then hold at
/// least ``TAU_SCAN_ROWS`` rows, or be the last one.
#[pyclass(name = "FilterStream", module = "seqsmooth._seqsmooth")]
pub struct PyFilterStream {
    /// The settings, `τ` perhaps not resolved yet.
    spec: FilterSpec,
    /// The filters, from the first chunk on (its `τ` then known).
    bank: Option<StreamBank<AnyFilter>>,
    layout: RowLayout,
    /// Cells a row of the bank's output has (the shown ones, then the automatic filter's
    /// decisions).
    stride: usize,
    names: Vec<String>,
    /// Rows taken so far (the first row of the next chunk).
    rows: usize,
    /// The automatic filter's rows not given back yet.
    held: Held,
    /// The last chunk was taken.
    ended: bool,
}

/// The automatic filter's rows not given back yet: from the oldest row whose `outlier` flag
/// is not final on (rows after it wait too, to come back in input order).
#[derive(Default)]
struct Held {
    /// The shown cells of each row, row after row.
    cells: VecDeque<f64>,
    /// Whether each row still waits for its decision.
    waiting: VecDeque<bool>,
    /// The number of `waiting[0]`'s row among all rows.
    first: usize,
    /// Per series, its undecided rows (numbered among all rows): the library's rule.
    open: Undecided,
}

impl Held {
    /// The row's `outlier` cell set to the verdict (where the row has a flag: a row whose
    /// estimate the filter withheld keeps its empty cell), as `filter_series` sets it.
    fn decide(
        cells: &mut VecDeque<f64>,
        waiting: &mut VecDeque<bool>,
        at: (usize, usize, usize),
        rejected: bool,
    ) {
        let (row, shown, flag) = at;
        let cell = &mut cells[row * shown + flag];
        if !cell.is_nan() {
            *cell = f64::from(u8::from(rejected));
        }
        waiting[row] = false;
    }
}

#[pymethods]
impl PyFilterStream {
    #[new]
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (kind, degree, theta = None, tau = None, window = None, engine = None, sigma = None, review_window = None))]
    fn new(
        kind: &str,
        degree: usize,
        theta: Option<f64>,
        tau: Option<f64>,
        window: Option<usize>,
        engine: Option<&str>,
        sigma: Option<f64>,
        review_window: Option<usize>,
    ) -> PyResult<Self> {
        let spec = spec_of(
            kind,
            degree,
            theta,
            tau,
            window,
            engine,
            sigma,
            review_window,
        )?;
        // The settings checked now (τ, if to come, as 1 for the check), and the columns.
        let checked = FilterSpec {
            tau: spec.tau.or(spec.kind.uses_tau().then_some(1.0)),
            ..spec.clone()
        };
        let prototype = checked.build().py()?;
        let (layout, names) = rows_of(&spec, &prototype);
        Ok(Self {
            spec,
            bank: None,
            layout,
            stride: prototype.stride(layout),
            names,
            rows: 0,
            held: Held::default(),
            ended: false,
        })
    }

    /// The names of the columns ``update`` gives back, in order.
    #[getter]
    fn names(&self) -> Vec<String> {
        self.names.clone()
    }

    /// Rows taken so far.
    #[getter]
    fn rows(&self) -> usize {
        self.rows
    }

    /// Rows taken but not given back yet (the automatic filter's, waiting for their outlier
    /// decision; 0 for the other kinds).
    #[getter]
    fn waiting(&self) -> usize {
        self.held.waiting.len()
    }

    /// Takes a chunk of rows ``(t[i], y[i])`` of series ``codes[i]`` (int64, each series
    /// numbered from 0 in order of first appearance in the stream: a new series' number is
    /// the count of series before it), ``last`` when no chunk follows; gives back ``(values,
    /// rows)``: the columns of ``names`` (``(columns, rows)``) of the next ``rows`` rows of the
    /// stream — for every kind but ``auto`` the chunk's rows; for ``auto`` the rows whose
    /// outlier flag is now final, up to the first still waiting (with ``last``, all). The
    /// numbers are ``filter_series``' on all the rows at once. An error names its row among all
    /// rows (``.index``); the rows before it, of every series, are taken.
    #[pyo3(signature = (codes, t, y, last = false))]
    fn update<'py>(
        &mut self,
        py: Python<'py>,
        codes: &Bound<'py, PyAny>,
        t: &Bound<'py, PyAny>,
        y: &Bound<'py, PyAny>,
        last: bool,
    ) -> PyResult<(Bound<'py, PyAny>, usize)> {
        if self.ended {
            return Err(raise(
                Kind::InvalidInput,
                "the stream has ended: its last chunk was taken, or a row was refused",
                None,
            ));
        }
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
        // A series' number is at most the count of series before it.
        let mut known = self.bank.as_ref().map_or(0, StreamBank::channels);
        let mut channels = Vec::with_capacity(n);
        for (i, &c) in codes.iter().enumerate() {
            match usize::try_from(c) {
                Ok(c) if c <= known => {
                    known = known.max(c + 1);
                    channels.push(c);
                }
                _ => {
                    return Err(raise(
                        Kind::InvalidInput,
                        format!(
                            "code {c} of row {} is not a series number from 0 to {known} (the \
                             series so far, then a new one)",
                            self.rows + i
                        ),
                        Some(self.rows + i),
                    ))
                }
            }
        }
        if self.bank.is_none() {
            if self.spec.kind.uses_tau() && self.spec.tau.is_none() && !last && n < TAU_SCAN_ROWS {
                return Err(raise(
                    Kind::InvalidInput,
                    format!(
                        "the first chunk has {n} rows: without tau, it must hold the first \
                         {TAU_SCAN_ROWS} rows (the default tau is their median step) or all of \
                         them"
                    ),
                    None,
                ));
            }
            let spec = self
                .spec
                .clone()
                .with_default_tau(t, &channels, last)
                .py()?;
            self.bank = Some(StreamBank::growing(spec.build().py()?).py()?);
        }
        let Some(bank) = self.bank.as_mut() else {
            return Err(raise(Kind::InvalidInput, "the stream has no filters", None));
        };
        let (layout, shown, first) = (self.layout, self.names.len(), self.rows);
        let stride = self.stride;
        let run =
            |f: &mut AnyFilter, t: &[f64], y: &[f64], o: &mut [f64]| f.run_rows(t, y, o, layout);
        let auto = self.spec.kind == FilterKind::Automatic;
        if !auto {
            let mut out = vec![0.0; n * stride];
            py.detach(|| {
                let chunk = Chunk {
                    channels: &channels,
                    times: t,
                    values: y,
                    estimates: &mut out,
                    stride,
                };
                bank.update_par_columns(chunk, run)
            })
            .py_at(first)
            .inspect_err(|_| self.ended = true)?;
            self.rows += n;
            self.ended = last;
            out.truncate(shown * n);
            return Ok((matrix(py, out, shown, n)?, n));
        }
        // The automatic filter: by row, the decisions after the shown cells.
        let mut out = vec![0.0; n * stride];
        let flag = shown - 3; // `outlier`, before `misfit` and `bias`
        let held = &mut self.held;
        let done = py.detach(|| {
            let chunk = Chunk {
                channels: &channels,
                times: t,
                values: y,
                estimates: &mut out,
                stride,
            };
            let result = bank.update_par(chunk, run);
            // The rows before a bad one are taken, as filter_series takes them.
            let limit = match &result {
                Err(seqsmooth::Error::InChannel { source, .. }) => match source.as_ref() {
                    seqsmooth::Error::InBatch { index, .. } => *index,
                    _ => 0,
                },
                Err(_) => 0,
                Ok(()) => n,
            };
            let Held {
                cells,
                waiting,
                first: oldest,
                open,
            } = held;
            for (i, row) in out.chunks_exact(stride).take(limit).enumerate() {
                cells.extend(&row[..shown]);
                waiting.push_back(true);
                let verdicts = decisions(&row[shown..shown + DECISION_CELLS]);
                let base = *oldest;
                open.push(channels[i], first + i, &verdicts, |r, rejected| {
                    Held::decide(cells, waiting, (r - base, shown, flag), rejected)
                });
            }
            if result.is_ok() && last {
                // The whole input is in: every series decides its rows still waiting.
                for c in 0..bank.channels() {
                    if let Some(f) = bank.channel_mut(c).and_then(AnyFilter::automatic_mut) {
                        let base = *oldest;
                        open.decide(c, &f.finish(), |r, rejected| {
                            Held::decide(cells, waiting, (r - base, shown, flag), rejected)
                        });
                    }
                }
            }
            result.map(|()| limit)
        });
        let taken = done.py_at(first).inspect_err(|_| self.ended = true)?;
        self.rows += taken;
        self.ended = last;
        // The rows final from the oldest on (with the last chunk, all of them: a row still
        // undecided keeps the gate's verdict, as in filter_series).
        let held = &mut self.held;
        let ready = if last {
            held.waiting.len()
        } else {
            held.waiting.iter().take_while(|w| !**w).count()
        };
        let mut values = vec![0.0; shown * ready];
        for (i, row) in held
            .cells
            .drain(..ready * shown)
            .collect::<Vec<_>>()
            .chunks_exact(shown)
            .enumerate()
        {
            for (k, &v) in row.iter().enumerate() {
                values[k * ready + i] = v;
            }
        }
        held.waiting.drain(..ready);
        held.first += ready;
        if last {
            held.open.clear();
        }
        Ok((matrix(py, values, shown, ready)?, ready))
    }
}
