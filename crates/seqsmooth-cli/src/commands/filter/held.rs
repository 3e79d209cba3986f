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

/// One formatted row in [`Held::bytes`] and where its `outlier` cell is (offsets counted from
/// the first byte ever held, so that writing the front leaves them as they are).
struct Row {
    /// The row's series.
    series: usize,
    /// Offset one past the row's last byte (it starts where the row before it ends).
    end: usize,
    /// Offset of the `outlier` cell while its decision is to come.
    open: Option<usize>,
    /// Waiting for the decision.
    waiting: bool,
}

impl Row {
    /// The verdict (`true`: rejected) in the row's `outlier` cell of `bytes` (which start at
    /// offset `base`).
    fn decide(&mut self, bytes: &mut [u8], base: usize, rejected: bool) {
        if let Some(at) = self.open.take() {
            bytes[at - base] = if rejected { b'1' } else { b'0' };
        }
        self.waiting = false;
    }
}

/// Formatted rows not written yet, one after another in one buffer, and per series those
/// among them still undecided.
#[derive(Default)]
pub struct Held {
    /// The rows' bytes, from offset `base` on.
    bytes: Vec<u8>,
    base: usize,
    rows: VecDeque<Row>,
    /// Index of `rows[0]` among all rows pushed.
    first: usize,
    /// Per series, the indices (among all rows pushed) of its undecided rows: the library's
    /// rule of which row a decision is on.
    open: Undecided,
}

impl Held {
    /// Takes the row of `series` that `write` appends (formatted, undecided: its `outlier`
    /// cell `trailing` cells before the row's end), then the `decided` verdicts its update
    /// made on the series' oldest undecided rows (this one included).
    pub fn push(
        &mut self,
        series: usize,
        write: impl FnOnce(&mut Vec<u8>),
        trailing: usize,
        decided: &[bool],
    ) {
        let start = self.bytes.len();
        write(&mut self.bytes);
        let open = outlier_offset(&self.bytes[start..], trailing).map(|at| self.base + start + at);
        self.add(series, open, true);
        self.apply(series, decided, true);
    }

    /// Appends the row metadata of the bytes just added.
    fn add(&mut self, series: usize, open: Option<usize>, waiting: bool) {
        self.rows.push_back(Row {
            series,
            end: self.base + self.bytes.len(),
            open,
            waiting,
        });
    }

    /// The verdicts on the oldest undecided rows of `series` (with `pushed`, after the row just
    /// pushed has joined them).
    fn apply(&mut self, series: usize, verdicts: &[bool], pushed: bool) {
        let Self {
            bytes,
            base,
            rows,
            first,
            open,
        } = self;
        // The row just pushed, if any, is the last.
        let index = (*first + rows.len()).saturating_sub(1);
        let decide = |i: usize, r: bool| rows[i - *first].decide(bytes, *base, r);
        if pushed {
            open.push(series, index, verdicts, decide);
        } else {
            open.decide(series, verdicts, decide);
        }
    }

    /// The verdicts (`true`: rejected) on the oldest undecided rows of `series`, in order.
    pub fn decide(&mut self, series: usize, verdicts: &[bool]) {
        self.apply(series, verdicts, false);
    }

    /// The rows held, to save with the filters (`--state`).
    pub fn save(&self) -> Vec<PendingRow> {
        let mut start = self.base;
        let row = |r: &Row| {
            let bytes = self.bytes[start - self.base..r.end - self.base].to_vec();
            let cell = r.open.map(|at| at - start);
            start = r.end;
            PendingRow {
                series: r.series,
                bytes,
                cell,
                waiting: r.waiting,
            }
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
            let start = held.bytes.len();
            held.bytes.extend_from_slice(&r.bytes);
            held.add(r.series, r.cell.map(|at| start + at), r.waiting);
        }
        held
    }

    /// Writes the rows up to the first undecided one.
    pub fn flush_final(&mut self, sink: &mut Output) -> Result<(), CliError> {
        let done = self.rows.iter().take_while(|r| !r.waiting).count();
        let Some(last) = done.checked_sub(1).map(|k| &self.rows[k]) else {
            return Ok(());
        };
        let end = last.end - self.base;
        sink.write(&self.bytes[..end])?;
        self.bytes.drain(..end);
        self.base += end;
        self.rows.drain(..done);
        self.first += done;
        Ok(())
    }

    /// Writes every row, an undecided one with the gate's verdict (the run stopped early).
    pub fn flush_all(&mut self, sink: &mut Output) -> Result<(), CliError> {
        sink.write(&self.bytes)?;
        self.base += self.bytes.len();
        self.bytes.clear();
        self.rows.clear();
        self.first = 0;
        self.open.clear();
        Ok(())
    }
}

/// The byte offset of the cell `trailing` cells before the end of the formatted row `bytes`
/// (`…,cell,c1,…,c_trailing\n`), when that cell is `0` or `1`. The cells after it are numbers
/// or empty, so the commas are theirs.
fn outlier_offset(bytes: &[u8], trailing: usize) -> Option<usize> {
    let comma = bytes
        .iter()
        .enumerate()
        .rev()
        .filter(|(_, &b)| b == b',')
        .nth(trailing)?
        .0;
    let at = comma + 1;
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
