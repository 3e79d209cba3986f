//! Rows tagged with their series' label, in any order, as a [`Panel`](super::Panel)'s series:
//! the one rule of how a frame's rows become a bank's series (the Python `kalman_frame`'s).
//!
//! Rows already grouped (each label's rows one run, as a frame sorted by its id) are the panel
//! as they are, the series in the order of their runs, nothing copied. Otherwise the rows are
//! grouped by a stable counting sort: the series in the order of their labels' first rows, each
//! series' rows in input order; [`Grouping::gather`] puts a column in that order and
//! [`Grouping::scatter`] puts per-row results back in input order.

use rayon::prelude::*;
use std::collections::HashMap;

/// Rows per task of the parallel search for runs of equal labels.
const ROWS_PER_TASK: usize = 1 << 16;

/// How rows tagged by series label form a panel's series: the series' `offsets` over the
/// grouped rows and, when the input was not grouped, the input row of every grouped row.
///
/// ```
/// use seqsmooth::kalman::bank::Grouping;
/// // Already grouped (labels need not be sorted): the rows as they are.
/// let g = Grouping::from_labels(&[7, 7, 3, 3, 3]);
/// assert_eq!((g.offsets(), g.order()), (&[0, 2, 5][..], None));
/// // Interleaved: series by first appearance (7, then 3), each one's rows in input order.
/// let g = Grouping::from_labels(&[7, 3, 7, 3]);
/// assert_eq!((g.offsets(), g.order()), (&[0, 2, 4][..], Some(&[0, 2, 1, 3][..])));
/// assert_eq!(g.gather(&[10.0, 11.0, 12.0, 13.0], 1).as_ref(), &[10.0, 12.0, 11.0, 13.0]);
/// assert_eq!(g.scatter(&[10.0, 12.0, 11.0, 13.0], 1), vec![10.0, 11.0, 12.0, 13.0]);
/// assert_eq!(g.input_row(1, 1), 3); // series 1 (label 3), its second row
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Grouping {
    offsets: Vec<usize>,
    order: Option<Vec<usize>>,
}

impl Grouping {
    /// The grouping of rows labelled `labels` (one a row).
    pub fn from_labels(labels: &[i64]) -> Self {
        let count = labels.len();
        // Where each run of equal labels starts, found in parallel (in order).
        let starts: Vec<usize> = labels
            .par_chunks(ROWS_PER_TASK)
            .enumerate()
            .flat_map_iter(|(c, chunk)| {
                let first = c * ROWS_PER_TASK;
                let before = first.checked_sub(1).map(|i| labels[i]);
                chunk
                    .iter()
                    .enumerate()
                    .filter(move |&(k, &l)| {
                        let previous = if k == 0 { before } else { Some(chunk[k - 1]) };
                        previous != Some(l)
                    })
                    .map(move |(k, _)| first + k)
            })
            .collect();
        let mut firsts: Vec<i64> = starts.iter().map(|&i| labels[i]).collect();
        firsts.sort_unstable();
        if firsts.windows(2).all(|w| w[0] != w[1]) {
            let mut offsets = starts;
            offsets.push(count);
            return Self {
                offsets,
                order: None,
            };
        }
        // Series numbered by first appearance, then a stable counting sort by series.
        let mut number = HashMap::with_capacity(firsts.len());
        let series: Vec<usize> = labels
            .iter()
            .map(|&label| {
                let next = number.len();
                *number.entry(label).or_insert(next)
            })
            .collect();
        let mut offsets = vec![0usize; number.len() + 1];
        for &s in &series {
            offsets[s + 1] += 1;
        }
        for s in 0..number.len() {
            offsets[s + 1] += offsets[s];
        }
        let mut next = offsets.clone();
        let mut order = vec![0usize; count];
        for (i, &s) in series.iter().enumerate() {
            order[next[s]] = i;
            next[s] += 1;
        }
        Self {
            offsets,
            order: Some(order),
        }
    }

    /// The series' offsets over the grouped rows: series `s` is rows `offsets[s]..offsets[s + 1]`.
    pub fn offsets(&self) -> &[usize] {
        &self.offsets
    }

    /// The input row of every grouped row, or `None` when the input was grouped (grouped row
    /// `k` is input row `k`).
    pub fn order(&self) -> Option<&[usize]> {
        self.order.as_deref()
    }

    /// The input row of series `series`' row `k`.
    pub fn input_row(&self, series: usize, k: usize) -> usize {
        let row = self.offsets[series] + k;
        self.order.as_ref().map_or(row, |order| order[row])
    }

    /// The number of rows grouped.
    pub fn rows(&self) -> usize {
        self.offsets.last().copied().unwrap_or(0)
    }

    /// `input` (`width` values a row, input order) in grouped order: borrowed when the input
    /// was grouped.
    ///
    /// # Panics
    ///
    /// If `input` is not `width` values for each of [`Self::rows`].
    pub fn gather<'a, T: Copy>(&self, input: &'a [T], width: usize) -> std::borrow::Cow<'a, [T]> {
        assert_eq!(
            input.len(),
            self.rows() * width,
            "gather: {width} values a row"
        );
        match &self.order {
            None => std::borrow::Cow::Borrowed(input),
            Some(order) => {
                let mut out = Vec::with_capacity(order.len() * width);
                for &i in order {
                    out.extend_from_slice(&input[i * width..(i + 1) * width]);
                }
                std::borrow::Cow::Owned(out)
            }
        }
    }

    /// `grouped` (`width` values a row, grouped order) in input order.
    ///
    /// # Panics
    ///
    /// If `grouped` is not `width` values for each of [`Self::rows`].
    pub fn scatter<T: Copy + Default>(&self, grouped: &[T], width: usize) -> Vec<T> {
        assert_eq!(
            grouped.len(),
            self.rows() * width,
            "scatter: {width} values a row"
        );
        match &self.order {
            None => grouped.to_vec(),
            Some(order) => {
                let mut out = vec![T::default(); grouped.len()];
                for (k, &i) in order.iter().enumerate() {
                    out[i * width..(i + 1) * width]
                        .copy_from_slice(&grouped[k * width..(k + 1) * width]);
                }
                out
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The grouping by its definition, row by row: series by first appearance, rows in input
    /// order within each.
    fn by_definition(labels: &[i64]) -> Vec<Vec<usize>> {
        let mut seen: Vec<(i64, Vec<usize>)> = Vec::new();
        for (i, &l) in labels.iter().enumerate() {
            match seen.iter_mut().find(|(k, _)| *k == l) {
                Some((_, rows)) => rows.push(i),
                None => seen.push((l, vec![i])),
            }
        }
        seen.into_iter().map(|(_, rows)| rows).collect()
    }

    fn series_rows(g: &Grouping) -> Vec<Vec<usize>> {
        (0..g.offsets.len() - 1)
            .map(|s| {
                (0..g.offsets[s + 1] - g.offsets[s])
                    .map(|k| g.input_row(s, k))
                    .collect()
            })
            .collect()
    }

    #[test]
    fn groups_as_defined_across_task_boundaries() {
        let n = 3 * ROWS_PER_TASK + 17;
        // Runs crossing the tasks' boundaries (grouped), then the same labels interleaved.
        let grouped: Vec<i64> = (0..n).map(|i| (i / 1000) as i64 * 7 - 50).collect();
        let g = Grouping::from_labels(&grouped);
        assert_eq!(g.order(), None);
        assert_eq!(series_rows(&g), by_definition(&grouped));
        // One run boundary exactly at a task boundary, the same label on both sides of another.
        let mut edge = vec![1i64; n];
        edge[ROWS_PER_TASK..2 * ROWS_PER_TASK].fill(2);
        edge[2 * ROWS_PER_TASK..].fill(3);
        assert_eq!(
            Grouping::from_labels(&edge).offsets(),
            &[0, ROWS_PER_TASK, 2 * ROWS_PER_TASK, n]
        );
        let interleaved: Vec<i64> = (0..n).map(|i| ((i * 7919) % 13) as i64).collect();
        let g = Grouping::from_labels(&interleaved);
        assert!(g.order().is_some());
        assert_eq!(series_rows(&g), by_definition(&interleaved));
        // A label that comes back after another's run is not grouped.
        let g = Grouping::from_labels(&[5, 5, 6, 5]);
        assert_eq!(series_rows(&g), vec![vec![0, 1, 3], vec![2]]);
    }

    #[test]
    fn gather_then_scatter_is_the_input() {
        let labels = [2i64, 9, 2, 4, 9, 2];
        let g = Grouping::from_labels(&labels);
        let input: Vec<f64> = (0..12).map(f64::from).collect();
        let grouped = g.gather(&input, 2);
        assert_eq!(&grouped[..4], &[0.0, 1.0, 4.0, 5.0]); // label 2's first rows
        assert_eq!(g.scatter(&grouped, 2), input);
        assert_eq!(Grouping::from_labels(&[]).offsets(), &[0]);
    }
}
