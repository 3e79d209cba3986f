//! Reading a CSV time series in chunks of rows, one series or many (`--id-col`): the input
//! side of `seqsmooth filter`.
//!
//! Every row is validated as it is read — the time and value cells are numbers, finite, and
//! the time is strictly after the previous time of the same series — with its 1-based file
//! line (the header is line 1) and column. The records and their lines come from
//! [`crate::records`], the numbers from [`crate::decimal`] (or `str::parse` for other forms). A chunk holds its rows' numbers and the text of
//! their time and value cells (echoed to the output) in one buffer, so reading allocates
//! nothing per row once the buffers have grown. Per series only the id, the newest time (with
//! its line, and its text from chunk to chunk, for the message of a time that goes backwards)
//! and an index are kept.

use crate::decimal::parse_decimal;
use crate::error::CliError;
use crate::filter::Need;
use crate::records::Records;
use std::collections::HashMap;
use std::io::Read;

/// One validated data row of a [`Chunk`].
#[derive(Clone, Copy, Debug)]
pub struct Row {
    /// 1-based file line (header = line 1).
    pub line: u64,
    /// Time.
    pub t: f64,
    /// Value.
    pub y: f64,
    /// Offset in [`Chunk::text`] of the time cell's text, followed by the value cell's.
    pub text: usize,
    /// Length of the time cell's text.
    pub t_len: u32,
    /// Length of the value cell's text.
    pub y_len: u32,
    /// The series: 0 for a single series, else the index of its id in order of appearance.
    pub series: u32,
}

/// Consecutive data rows of the input.
#[derive(Debug, Default)]
pub struct Chunk {
    /// The rows, in input order.
    pub rows: Vec<Row>,
    /// The time and value cells of the rows, as written (trimmed).
    pub text: Vec<u8>,
    /// The ids of the series first seen in this chunk, in order of their index, as CSV output
    /// cells (quoted where needed).
    pub new_ids: Vec<Vec<u8>>,
    /// Why reading stopped before the chunk was full, other than the end of the input: the
    /// error of the row after the last one.
    pub error: Option<CliError>,
    /// Whether the input ended.
    pub done: bool,
    /// Bytes read from the input up to the end of this chunk (for the progress display).
    pub bytes_read: u64,
    /// Data rows read up to the end of this chunk.
    pub rows_read: u64,
}

impl Chunk {
    /// The time and value cells of `row`, as written.
    pub fn cells(&self, row: &Row) -> (&[u8], &[u8]) {
        let t_end = row.text + row.t_len as usize;
        (
            &self.text[row.text..t_end],
            &self.text[t_end..t_end + row.y_len as usize],
        )
    }

    fn clear(&mut self) {
        self.rows.clear();
        self.text.clear();
        self.new_ids.clear();
        self.error = None;
        self.done = false;
    }
}

/// The newest row of a series.
#[derive(Debug, Default)]
struct Newest {
    t: f64,
    line: u64,
    /// The row in the chunk being read, whose text is there; `None` when it is in an earlier
    /// chunk, and its time cell in `text`.
    row: Option<usize>,
    /// The time cell as written, when the row is in an earlier chunk.
    text: Vec<u8>,
}

/// Reads and validates the data rows of a CSV time series in chunks.
pub struct RowReader<R: Read> {
    records: Records<R>,
    /// The number of columns of the header.
    width: usize,
    time_idx: usize,
    value_idx: usize,
    id_idx: Option<usize>,
    time_col: String,
    value_col: String,
    /// Series index by id (with `--id-col`).
    index: HashMap<Vec<u8>, u32>,
    /// The ids as written, for messages, by series index (with `--id-col`).
    ids: Vec<String>,
    /// The newest row of each series, by index.
    newest: Vec<Option<Newest>>,
    /// The series whose newest row is in the chunk being read.
    touched: Vec<u32>,
    rows_read: u64,
}

/// A header cell or an id as text for messages (invalid UTF-8 replaced).
fn lossy(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// `bytes` without leading and trailing whitespace (Unicode whitespace for UTF-8 text, like
/// the `csv` crate's trimming of text records; ASCII whitespace otherwise).
fn trim(bytes: &[u8]) -> &[u8] {
    let ascii = bytes.trim_ascii();
    // Non-ASCII whitespace starts with a byte >= 0x80 and ends with one.
    match (ascii.first(), ascii.last()) {
        (Some(&a), Some(&b)) if a >= 0x80 || b >= 0x80 => match std::str::from_utf8(ascii) {
            Ok(s) => s.trim().as_bytes(),
            Err(_) => ascii,
        },
        _ => ascii,
    }
}

/// `cell` as a CSV output field: quoted (with quotes doubled) when it holds a comma, a quote
/// or a line break.
pub fn csv_field(cell: &[u8]) -> Vec<u8> {
    if !cell
        .iter()
        .any(|b| matches!(b, b',' | b'"' | b'\r' | b'\n'))
    {
        return cell.to_vec();
    }
    let mut out = Vec::with_capacity(cell.len() + 2);
    out.push(b'"');
    for &b in cell {
        if b == b'"' {
            out.push(b'"');
        }
        out.push(b);
    }
    out.push(b'"');
    out
}

/// Parses a time or value cell (already trimmed) of `line` in `column`, holding the `what`: a
/// typed error for an empty cell, a non-number or a non-finite value. Plain decimals take
/// [`parse_decimal`]'s fast exact path; anything else `str::parse`, with the same result.
#[inline]
fn parse_cell(cell: &[u8], line: u64, column: &str, what: &str) -> Result<f64, CliError> {
    match parse_decimal(cell) {
        Some(v) => Ok(v),
        None => parse_cell_text(cell, line, column, what),
    }
}

/// [`parse_cell`] through `str::parse`, and its errors.
#[cold]
#[inline(never)]
fn parse_cell_text(cell: &[u8], line: u64, column: &str, what: &str) -> Result<f64, CliError> {
    if cell.is_empty() {
        return Err(CliError::Data(format!(
            "line {line}, column '{column}': the cell is empty, expected a number"
        )));
    }
    let not_a_number = || {
        CliError::Data(format!(
            "line {line}, column '{column}': '{}' is not a number",
            lossy(cell)
        ))
    };
    let text = std::str::from_utf8(cell).map_err(|_| not_a_number())?;
    let v: f64 = text.parse().map_err(|_| not_a_number())?;
    if !v.is_finite() {
        return Err(CliError::Data(format!(
            "line {line}, column '{column}': {what} {text} is not finite"
        )));
    }
    Ok(v)
}

/// The error of a record whose field count differs from the header's.
fn ragged(line: u64, len: usize, expected: usize) -> CliError {
    CliError::Data(format!(
        "line {line}: malformed CSV: the row has {len} field{} but the header has {expected}",
        if len == 1 { "" } else { "s" }
    ))
}

/// The error of a failed read of the input.
fn read_error(e: std::io::Error) -> CliError {
    CliError::Data(format!("cannot read the input: {e}"))
}

/// Reads the header: its cells trimmed, none for an empty input.
fn read_header<R: Read>(records: &mut Records<R>) -> Result<Vec<String>, CliError> {
    let Some(line) = records.next_record().map_err(read_error)? else {
        return Ok(Vec::new());
    };
    (0..records.len())
        .map(|i| match std::str::from_utf8(records.field(i)) {
            Ok(cell) => Ok(cell.trim().to_string()),
            Err(_) => Err(CliError::Data(format!(
                "line {line}: malformed CSV: the row is not valid UTF-8"
            ))),
        })
        .collect()
}

impl<R: Read> RowReader<R> {
    /// Reads the header and locates the time and value columns, and the id column if given.
    pub fn new(
        input: R,
        time_col: &str,
        value_col: &str,
        id_col: Option<&str>,
        need: &Need,
    ) -> Result<Self, CliError> {
        let mut records = Records::new(input);
        let headers = read_header(&mut records)?;
        let mut this = Self {
            records,
            width: headers.len(),
            time_idx: 0,
            value_idx: 0,
            id_idx: None,
            time_col: time_col.to_string(),
            value_col: value_col.to_string(),
            index: HashMap::new(),
            ids: Vec::new(),
            newest: Vec::new(),
            touched: Vec::new(),
            rows_read: 0,
        };
        crate::filter::check_header(&headers, need)?;
        let find = |name: &str| crate::filter::find_column(&headers, name);
        this.time_idx = find(time_col)?;
        this.value_idx = find(value_col)?;
        this.id_idx = id_col.map(find).transpose()?;
        if this.id_idx.is_none() {
            this.newest.push(None);
        }
        Ok(this)
    }

    /// The number of bytes read from the input so far.
    pub fn bytes_read(&self) -> u64 {
        self.records.bytes_read()
    }

    /// Reads up to `max_rows` rows into `chunk` (replacing its contents). Reading stops early
    /// at the end of the input (`chunk.done`) or at a bad row (`chunk.error`; the rows before
    /// it are in the chunk).
    pub fn read_chunk(&mut self, chunk: &mut Chunk, max_rows: usize) {
        chunk.clear();
        while chunk.rows.len() < max_rows {
            match self.next_row(chunk) {
                Ok(true) => {}
                Ok(false) => {
                    chunk.done = true;
                    break;
                }
                Err(e) => {
                    chunk.error = Some(e);
                    break;
                }
            }
        }
        self.keep_newest_text(chunk);
        chunk.bytes_read = self.bytes_read();
        chunk.rows_read = self.rows_read;
    }

    /// Copies the time cells of the series' newest rows out of `chunk` (read last), for the
    /// messages of the next chunks: once per series and chunk, not per row.
    fn keep_newest_text(&mut self, chunk: &Chunk) {
        for s in self.touched.drain(..) {
            if let Some(newest) = &mut self.newest[s as usize] {
                if let Some(i) = newest.row.take() {
                    let r = &chunk.rows[i];
                    newest.text.clear();
                    newest
                        .text
                        .extend_from_slice(&chunk.text[r.text..r.text + r.t_len as usize]);
                }
            }
        }
    }

    /// Reads one row into `chunk`; `false` at the end of the input.
    fn next_row(&mut self, chunk: &mut Chunk) -> Result<bool, CliError> {
        let line = match self.records.next_record() {
            Ok(Some(line)) => line,
            Ok(None) => return Ok(false),
            Err(e) => return Err(read_error(e)),
        };
        if self.records.len() != self.width {
            return Err(ragged(line, self.records.len(), self.width));
        }
        let t_cell = trim(self.records.field(self.time_idx));
        let y_cell = trim(self.records.field(self.value_idx));
        let t = parse_cell(t_cell, line, &self.time_col, "time")?;
        let y = parse_cell(y_cell, line, &self.value_col, "value")?;
        let series = match self.id_idx {
            None => 0,
            Some(i) => {
                let id = trim(self.records.field(i));
                match self.index.get(id) {
                    Some(&s) => s,
                    None => {
                        let s = u32::try_from(self.ids.len()).map_err(|_| {
                            CliError::Data(format!("line {line}: more than {} series", u32::MAX))
                        })?;
                        self.index.insert(id.to_vec(), s);
                        self.ids.push(lossy(id));
                        self.newest.push(None);
                        chunk.new_ids.push(csv_field(id));
                        s
                    }
                }
            }
        };
        let too_long = || CliError::Data(format!("line {line}: the cell is too long"));
        let t_len = u32::try_from(t_cell.len()).map_err(|_| too_long())?;
        let y_len = u32::try_from(y_cell.len()).map_err(|_| too_long())?;
        let row = chunk.rows.len();
        let newest = &mut self.newest[series as usize];
        if let Some(prev) = newest {
            if t <= prev.t {
                let why = if t == prev.t {
                    "duplicate time; times must be strictly increasing"
                } else {
                    "times must be strictly increasing"
                };
                let of = match self.id_idx {
                    None => String::new(),
                    Some(_) => format!(" of series '{}'", self.ids[series as usize]),
                };
                let prev_text = match prev.row {
                    Some(i) => {
                        let r = &chunk.rows[i];
                        &chunk.text[r.text..r.text + r.t_len as usize]
                    }
                    None => &prev.text,
                };
                return Err(CliError::Data(format!(
                    "line {line}: time {} is not after the previous time {} (line {}){of}: \
                     {why}",
                    lossy(t_cell),
                    lossy(prev_text),
                    prev.line
                )));
            }
            prev.t = t;
            prev.line = line;
            if prev.row.replace(row).is_none() {
                self.touched.push(series);
            }
        } else {
            *newest = Some(Newest {
                t,
                line,
                row: Some(row),
                text: Vec::new(),
            });
            self.touched.push(series);
        }
        let text = chunk.text.len();
        chunk.text.extend_from_slice(t_cell);
        chunk.text.extend_from_slice(y_cell);
        chunk.rows.push(Row {
            line,
            t,
            y,
            text,
            t_len,
            y_len,
            series,
        });
        self.rows_read += 1;
        Ok(true)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_all(text: &str, id: Option<&str>, max: usize) -> (Vec<Chunk>, Vec<Vec<u8>>) {
        let mut r = RowReader::new(text.as_bytes(), "t", "y", id, &Need::degree(0)).unwrap();
        let mut chunks = Vec::new();
        let mut ids = Vec::new();
        loop {
            let mut c = Chunk::default();
            r.read_chunk(&mut c, max);
            ids.extend(c.new_ids.iter().cloned());
            let stop = c.done || c.error.is_some();
            chunks.push(c);
            if stop {
                return (chunks, ids);
            }
        }
    }

    #[test]
    fn chunks_lines_cells_and_series() {
        let text = "id,t,y\na,0,1\n\"b,1\", 0.5 ,2\n\na,1,3e0\nc\"x,1,4\n";
        let (chunks, ids) = read_all(text, Some("id"), 2);
        // Two full chunks, then the end of the input in an empty one.
        assert_eq!(chunks.len(), 3);
        assert!(chunks[2].done && chunks[2].error.is_none() && chunks[2].rows.is_empty());
        assert_eq!(chunks[1].rows_read, 4);
        let rows: Vec<(u64, u32, String, String)> = chunks
            .iter()
            .flat_map(|c| {
                c.rows.iter().map(move |r| {
                    let (t, y) = c.cells(r);
                    (r.line, r.series, lossy(t), lossy(y))
                })
            })
            .collect();
        assert_eq!(
            rows,
            [
                (2, 0, "0".into(), "1".into()),
                (3, 1, "0.5".into(), "2".into()),
                (5, 0, "1".into(), "3e0".into()),
                (6, 2, "1".into(), "4".into()),
            ]
        );
        assert_eq!(
            ids,
            [b"a".to_vec(), b"\"b,1\"".to_vec(), b"\"c\"\"x\"".to_vec()]
        );
    }

    #[test]
    fn time_order_is_per_series() {
        let text = "id,t,y\na,5,1\nb,1,1\na,6,1\nb,2,1\nb,2,1\n";
        let (chunks, _) = read_all(text, Some("id"), 100);
        assert_eq!(chunks[0].rows.len(), 4);
        let e = chunks[0].error.as_ref().unwrap().to_string();
        assert_eq!(
            e,
            "line 6: time 2 is not after the previous time 2 (line 5) of series 'b': duplicate \
             time; times must be strictly increasing"
        );
    }

    #[test]
    fn bad_cells_stop_the_chunk_with_line_and_column() {
        let (chunks, _) = read_all("t,y\n0,1\n1,NaN\n2,3\n", None, 100);
        assert_eq!(chunks[0].rows.len(), 1);
        assert_eq!(
            chunks[0].error.as_ref().unwrap().to_string(),
            "line 3, column 'y': value NaN is not finite"
        );
    }

    #[test]
    fn quoting_of_output_fields() {
        assert_eq!(csv_field(b"abc"), b"abc");
        assert_eq!(csv_field(b""), b"");
        assert_eq!(csv_field(b"a b"), b"a b");
        assert_eq!(csv_field(b"a,b"), b"\"a,b\"");
        assert_eq!(csv_field(b"a\"b"), b"\"a\"\"b\"");
        assert_eq!(csv_field(b"a\nb"), b"\"a\nb\"");
    }
}
