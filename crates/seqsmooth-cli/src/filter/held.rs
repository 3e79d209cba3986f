//! The automatic filter's rows, held back until their `outlier` flag is final.
//!
//! A rejected sample is provisional: when the next samples of its series show a manoeuvre's
//! onset, not outliers, the filter applies the run after all
//! ([`seqsmooth::polynomial::automatic::AutoOutput::reinstated`]) and the rows of the run are
//! written with `outlier` 0. A rejection is final once a later sample of its series is taken,
//! or the input ends. Rows are written in input order, so every row from the first
//! provisional one on waits, across chunks if need be.

use crate::error::CliError;
use crate::io::Output;
use std::collections::VecDeque;

/// One formatted row and where its `outlier` cell is.
struct Row {
    bytes: Vec<u8>,
    /// Byte offset of the `outlier` cell's `1` while the rejection is provisional.
    open: Option<usize>,
}

/// Formatted rows not written yet, and per series the provisional rejections among them.
#[derive(Default)]
pub struct Held {
    rows: VecDeque<Row>,
    /// Index of `rows[0]` among all rows pushed.
    first: usize,
    /// Per series, the indices (among all rows pushed) of its provisional rejections, oldest
    /// first.
    open: Vec<Vec<usize>>,
}

impl Held {
    /// Takes the formatted `row` of `series`: its `outlier` cell, `trailing` cells before the
    /// row's end, says `1` when `outlier`; `reinstated` of the series' provisional rejections
    /// (the newest ones) were applied with this row after all.
    pub fn push(
        &mut self,
        series: usize,
        bytes: Vec<u8>,
        trailing: usize,
        outlier: bool,
        reinstated: usize,
    ) {
        if self.open.len() <= series {
            self.open.resize_with(series + 1, Vec::new);
        }
        let open = &mut self.open[series];
        // A rejected sample leaves the run open; a taken one closes it.
        let taken = !outlier || reinstated > 0;
        let from = open.len() - reinstated.min(open.len());
        let closed = if taken { open.len() } else { 0 };
        for (k, index) in open.drain(..closed).enumerate() {
            let row = &mut self.rows[index - self.first];
            if let (true, Some(at)) = (k >= from, row.open) {
                row.bytes[at] = b'0';
            }
            // Reinstated or not, a rejection before a taken sample is final.
            row.open = None;
        }
        let open_at = outlier.then(|| outlier_offset(&bytes, trailing)).flatten();
        if open_at.is_some() {
            open.push(self.first + self.rows.len());
        }
        self.rows.push_back(Row {
            bytes,
            open: open_at,
        });
    }

    /// Writes the rows up to the first provisional rejection.
    pub fn flush_final(&mut self, sink: &mut Output) -> Result<(), CliError> {
        while self.rows.front().is_some_and(|r| r.open.is_none()) {
            let row = self.rows.pop_front().expect("front checked");
            self.first += 1;
            sink.write(&row.bytes)?;
        }
        Ok(())
    }

    /// Writes every row: the input ended (or stopped), so no rejection can be revised.
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
/// (`…,cell,c1,…,c_trailing\n`), when that cell is `1`. The cells after it are numbers or
/// empty, so the commas are theirs.
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
    (bytes.get(at) == Some(&b'1') && bytes.get(at + 1) == Some(&b',')).then_some(at)
}

#[cfg(test)]
mod tests {
    use super::outlier_offset;

    #[test]
    fn finds_the_cell_counting_from_the_end() {
        let row = b"\"a,b\",1,2,3,0.5,1,0,\n";
        assert_eq!(outlier_offset(row, 2), Some(16));
        assert_eq!(outlier_offset(b"1,2,0.5,0,0,\n", 2), None);
        assert_eq!(outlier_offset(b"1\n", 2), None);
    }
}
