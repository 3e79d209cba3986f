//! The filters of the series of `seqsmooth filter`: one state per series, kept across chunks;
//! a chunk's rows grouped by series and the groups run in parallel.
//!
//! Each chunk is grouped by a counting sort (stable: each series' rows stay in input order).
//! The results are laid out in grouped order, so every group writes its own contiguous slice
//! and the groups run on rayon's threads without sharing anything; the writer reads them back
//! in input order through the row → slot map.

use crate::error::CliError;
use crate::filter::{Cells, Extra, Runner};
use crate::rows::{Chunk, Row};
use rayon::prelude::*;
use seqsmooth::PolynomialFilter;

/// The per-chunk results: `values` and `cells` in slot order.
#[derive(Debug, Default)]
pub struct Results {
    /// `stride` values per slot.
    pub values: Vec<f64>,
    /// One per slot.
    pub cells: Vec<Cells>,
    /// The slot of each row (in input order); empty when slots are rows (one series).
    pub slot: Vec<u32>,
    /// Rows in slot order.
    order: Vec<u32>,
    /// Per series in the chunk (in order of first appearance): series index, first slot.
    groups: Vec<(u32, usize)>,
    /// Per series index: its position in `groups` while grouping, else `u32::MAX`.
    mark: Vec<u32>,
    /// The batch buffers of a single series.
    batch: Batch,
}

impl Results {
    /// The slot of row `i`.
    #[inline]
    pub fn slot_of(&self, i: usize) -> usize {
        if self.slot.is_empty() {
            i
        } else {
            self.slot[i] as usize
        }
    }

    /// Groups the rows by series into `order`, `slot` and `groups`.
    fn group(&mut self, rows: &[Row], series: usize) {
        self.groups.clear();
        self.order.clear();
        self.slot.clear();
        if series <= 1 {
            self.groups.push((0, 0));
            return;
        }
        if self.mark.len() < series {
            self.mark.resize(series, u32::MAX);
        }
        // Count the rows of each series (`groups[g].1` as a count first).
        for r in rows {
            let g = &mut self.mark[r.series as usize];
            if *g == u32::MAX {
                *g = self.groups.len() as u32;
                self.groups.push((r.series, 0));
            }
            self.groups[*g as usize].1 += 1;
        }
        // Counts to first slots, then place each row after the previous ones of its series.
        let mut next = 0;
        for g in &mut self.groups {
            let count = g.1;
            g.1 = next;
            next += count;
        }
        let mut cursor: Vec<usize> = self.groups.iter().map(|g| g.1).collect();
        self.order.resize(rows.len(), 0);
        self.slot.resize(rows.len(), 0);
        for (i, r) in rows.iter().enumerate() {
            let c = &mut cursor[self.mark[r.series as usize] as usize];
            self.order[*c] = i as u32;
            self.slot[i] = *c as u32;
            *c += 1;
        }
        for &(s, _) in &self.groups {
            self.mark[s as usize] = u32::MAX;
        }
    }
}

/// What a row's results are: the estimate at `t + lead`, with 1σ columns or not.
#[derive(Clone, Copy, Debug)]
struct Step {
    lead: f64,
    sigma: bool,
}

/// Runs the rows `rows` (indices into `chunk.rows`, all of one series) through `runner`,
/// storing each row's results in `values` (`stride` per row) and `cells`. Stops at the first
/// error: its row index and message.
fn run_group(
    runner: &mut Runner,
    chunk: &Chunk,
    rows: impl Iterator<Item = usize>,
    Step { lead, sigma }: Step,
    values: &mut [f64],
    cells: &mut [Cells],
    batch: &mut Batch,
) -> Option<(usize, CliError)> {
    let stride = values.len().checked_div(cells.len()).unwrap_or(1).max(1);
    if !sigma && lead == 0.0 {
        if let Some(f) = runner.batch_filter() {
            if f.degree() + 1 == stride {
                return run_group_batch(f, chunk, rows, values, cells, batch);
            }
        }
    }
    for ((i, v), c) in rows.zip(values.chunks_exact_mut(stride)).zip(cells) {
        let row = &chunk.rows[i];
        match runner.step_into(row.t, row.y, lead, sigma, v) {
            Ok(out) => *c = out,
            Err(e) => return Some((i, CliError::Data(format!("line {}: {e}", row.line)))),
        }
    }
    None
}

/// The buffers of [`run_group_batch`], kept from chunk to chunk.
#[derive(Debug, Default)]
pub struct Batch {
    /// The group's rows (indices into the chunk).
    rows: Vec<usize>,
    /// Their times and values.
    ts: Vec<f64>,
    ys: Vec<f64>,
}

/// [`run_group`] for the expanding- and fading-memory filters without 1σ columns or lead: the
/// group's samples in one `update_many_into` call (the library's batch kernels) that writes
/// the estimates straight into the rows' values, then the rows' cells. Same results and errors
/// as row by row (the estimates up to rounding).
fn run_group_batch(
    f: &mut dyn PolynomialFilter,
    chunk: &Chunk,
    rows: impl Iterator<Item = usize>,
    values: &mut [f64],
    cells: &mut [Cells],
    batch: &mut Batch,
) -> Option<(usize, CliError)> {
    let Batch { rows: idx, ts, ys } = batch;
    idx.clear();
    idx.extend(rows);
    ts.clear();
    ts.extend(idx.iter().map(|&i| chunk.rows[i].t));
    ys.clear();
    ys.extend(idx.iter().map(|&i| chunk.rows[i].y));
    // Without 1σ columns a row's values are its d0..dM, the estimate's layout; a row without
    // an estimate keeps NaN.
    let w = f.degree() + 1;
    let values = &mut values[..idx.len() * w];
    values.fill(f64::NAN);
    let result = f.update_many_into(ts, ys, values);
    let (done, error) = match result {
        Ok(()) => (idx.len(), None),
        Err(seqsmooth::Error::InBatch { index, source }) => (index, Some((index, *source))),
        Err(e) => (0, Some((0, e))),
    };
    for (e, c) in values.chunks_exact(w).zip(cells.iter_mut()).take(done) {
        *c = if e[0].is_nan() {
            Cells::default()
        } else {
            Cells {
                derivatives: w,
                std_devs: 0,
                extra: Extra::None,
            }
        };
    }
    error.map(|(k, e)| {
        let i = idx[k];
        (
            i,
            CliError::Data(format!("line {}: {e}", chunk.rows[i].line)),
        )
    })
}

/// Runs the rows of `chunk` through the filters of their series (`runners`, by series index,
/// one for each series seen so far), the series in parallel. The results go to `results`,
/// `stride` values per row. Returns the first error in input order: the row index and the
/// message (the rows before it are all done; rows after it may or may not be).
pub fn run_chunk(
    chunk: &Chunk,
    runners: &mut [Option<Runner>],
    lead: f64,
    sigma: bool,
    stride: usize,
    results: &mut Results,
) -> Option<(usize, CliError)> {
    let step = Step { lead, sigma };
    let n = chunk.rows.len();
    results.values.resize(n * stride, 0.0);
    results.cells.resize(n, Cells::default());
    results.group(&chunk.rows, runners.len());
    if n == 0 {
        return None;
    }
    if results.slot.is_empty() {
        let Some(runner) = runners.first_mut().and_then(Option::as_mut) else {
            return Some((0, CliError::Data("internal error: no filter".into())));
        };
        return run_group(
            runner,
            chunk,
            0..n,
            step,
            &mut results.values,
            &mut results.cells,
            &mut results.batch,
        );
    }
    // Split the slot arrays into one disjoint piece per group, with the group's filter.
    let Results {
        values,
        cells,
        order,
        groups,
        ..
    } = results;
    let mut work = Vec::with_capacity(groups.len());
    let (mut values, mut cells, mut order) = (&mut values[..], &mut cells[..], &order[..]);
    for (g, &(series, first)) in groups.iter().enumerate() {
        let end = groups.get(g + 1).map_or(n, |next| next.1);
        let len = end - first;
        let (v, rest_v) = std::mem::take(&mut values).split_at_mut(len * stride);
        let (c, rest_c) = std::mem::take(&mut cells).split_at_mut(len);
        let (o, rest_o) = order.split_at(len);
        values = rest_v;
        cells = rest_c;
        order = rest_o;
        let runner = runners[series as usize].take();
        work.push((series, runner, o, v, c));
    }
    let first_error = work
        .par_iter_mut()
        .with_min_len(4)
        .filter_map(|(_, runner, o, v, c)| match runner.as_mut() {
            Some(runner) => run_group(
                runner,
                chunk,
                o.iter().map(|&i| i as usize),
                step,
                v,
                c,
                &mut Batch::default(),
            ),
            // Every series seen gets its filter before its rows are run.
            None => Some((
                o[0] as usize,
                CliError::Data("internal error: a series has no filter".into()),
            )),
        })
        .min_by_key(|(i, _)| *i);
    for (series, runner, ..) in work {
        runners[series as usize] = runner;
    }
    first_error
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(series: u32) -> Row {
        Row {
            line: 0,
            t: 0.0,
            y: 0.0,
            text: 0,
            t_len: 0,
            y_len: 0,
            series,
        }
    }

    #[test]
    fn grouping_is_a_stable_counting_sort() {
        let rows: Vec<Row> = [2, 0, 2, 2, 1, 0].into_iter().map(row).collect();
        let mut r = Results::default();
        r.group(&rows, 3);
        assert_eq!(r.groups, [(2, 0), (0, 3), (1, 5)]);
        assert_eq!(r.order, [0, 2, 3, 1, 5, 4]);
        for (i, &s) in r.slot.iter().enumerate() {
            assert_eq!(r.order[s as usize] as usize, i);
        }
        assert!(r.mark.iter().all(|&m| m == u32::MAX));
        r.group(&rows[..1], 1);
        assert!(r.slot.is_empty());
        assert_eq!(r.slot_of(0), 0);
    }
}
