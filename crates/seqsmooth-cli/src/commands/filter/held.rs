//! The automatic filter's rows, held back until their `outlier` flag is final.
//!
//! The filter decides each sample finally once enough samples after it are in (its review,
//! [`seqsmooth::polynomial::automatic::AutoOutput::decided`]: by interpolation between the
//! samples before and after, which may reject a sample the gate passed or take one it rejected),
//! and at the end of the input from the samples there are
//! ([`seqsmooth::polynomial::AutomaticFilter::finish`]). Decisions come in each series' sample
//! order. A row is written with its `outlier` cell set to the decision, in input order, so every
//! row from the first undecided one on waits, across chunks if need be.

use crate::error::CliError;
use crate::io::Output;
use seqsmooth::persist::stream::PendingRow;
use seqsmooth::polynomial::rows::Undecided;
use std::collections::VecDeque;

/// One formatted row and where its `outlier` cell is.
struct Row {
    /// The row's series.
    series: usize,
    bytes: Vec<u8>,
    /// Byte offset of the `outlier` cell while its decision is to come.
    open: Option<usize>,
    /// Waiting for the decision.
    waiting: bool,
}

impl Row {
    /// The verdict (`true`: rejected) in the row's `outlier` cell.
    fn decide(&mut self, rejected: bool) {
        if let Some(at) = self.open.take() {
            self.bytes[at] = if rejected { b'1' } else { b'0' };
        }
        self.waiting = false;
    }
}

/// Formatted rows not written yet, and per series those among them still undecided.
#[derive(Default)]
pub struct Held {
    rows: VecDeque<Row>,
    /// Index of `rows[0]` among all rows pushed.
    first: usize,
    /// Per series, the indices (among all rows pushed) of its undecided rows: the library's
    /// rule of which row a decision is on.
    open: Undecided,
}

impl Held {
    /// Takes the formatted `row` of `series`, undecided (its `outlier` cell `trailing` cells
    /// before the row's end), then the `decided` verdicts its update made on the series'
    /// oldest undecided rows (this one included).
    pub fn push(&mut self, series: usize, bytes: Vec<u8>, trailing: usize, decided: &[bool]) {
        let open = outlier_offset(&bytes, trailing);
        let index = self.first + self.rows.len();
        self.rows.push_back(Row {
            series,
            bytes,
            open,
            waiting: true,
        });
        let (rows, first) = (&mut self.rows, self.first);
        (self.open).push(series, index, decided, |i, r| rows[i - first].decide(r));
    }

    /// The verdicts (`true`: rejected) on the oldest undecided rows of `series`, in order.
    pub fn decide(&mut self, series: usize, verdicts: &[bool]) {
        let (rows, first) = (&mut self.rows, self.first);
        (self.open).decide(series, verdicts, |i, r| rows[i - first].decide(r));
    }

    /// The rows held, to save with the filters (`--state`).
    pub fn save(&self) -> Vec<PendingRow> {
        let row = |r: &Row| PendingRow {
            series: r.series,
            bytes: r.bytes.clone(),
            cell: r.open,
            waiting: r.waiting,
        };
        self.rows.iter().map(row).collect()
    }

    /// The rows a saved state held, in order, held again.
    pub fn restore(rows: Vec<PendingRow>) -> Self {
        let mut held = Self::default();
        for r in rows {
            let index = held.rows.len();
            if r.waiting {
                held.open.push(r.series, index, &[], |_, _| {});
            }
            held.rows.push_back(Row {
                series: r.series,
                bytes: r.bytes,
                open: r.cell,
                waiting: r.waiting,
            });
        }
        held
    }

    /// Writes the rows up to the first undecided one.
    pub fn flush_final(&mut self, sink: &mut Output) -> Result<(), CliError> {
        while self.rows.front().is_some_and(|r| !r.waiting) {
            let row = self.rows.pop_front().expect("front checked");
            self.first += 1;
            sink.write(&row.bytes)?;
        }
        Ok(())
    }

    /// Writes every row, an undecided one with the gate's verdict (the run stopped early).
    pub fn flush_all(&mut self, sink: &mut Output) -> Result<(), CliError> {
        for row in self.rows.drain(..) {
            sink.write(&row.bytes)?;
        }
        self.first = 0;
        self.open.clear();
        Ok(())
    }
}

/// The byte offset of the cell `trailing` cells before the end of the formatted row `bytes`
/// (`…,cell,c1,…,c_trailing\n`), when that cell is `0` or `1`. The cells after it are numbers
/// or empty, so the commas are theirs.
fn outlier_offset(bytes: &[u8], trailing: usize) -> Option<usize> {
    let commas: Vec<usize> = bytes
        .iter()
        .enumerate()
        .rev()
        .filter(|(_, &b)| b == b',')
        .map(|(i, _)| i)
        .take(trailing + 1)
        .collect();
    let at = commas.get(trailing)? + 1;
    let flag = matches!(bytes.get(at), Some(b'0' | b'1'));
    (flag && bytes.get(at + 1) == Some(&b',')).then_some(at)
}

#[cfg(test)]
mod tests {
    use super::outlier_offset;

    #[test]
    fn finds_the_cell_counting_from_the_end() {
        let row = b"\"a,b\",1,2,3,0.5,1,0,\n";
        assert_eq!(outlier_offset(row, 2), Some(16));
        assert_eq!(outlier_offset(b"1,2,0.5,0,0,\n", 2), Some(8));
        assert_eq!(outlier_offset(b"1,2,0.5,,0,\n", 2), None);
        assert_eq!(outlier_offset(b"1\n", 2), None);
    }
}
