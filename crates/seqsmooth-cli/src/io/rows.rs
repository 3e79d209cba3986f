//! The rows of a time series, one series or many (`--id-col`), read and validated in
//! chunks, and echoed to the output. The rows come from any [`Records`]: a CSV text, or a
//! Parquet file's rows (`crate::io::parquet`), through the same checks.
//!
//! Every row is validated as it is read — the time and value cells are numbers, finite, and
//! the time is strictly after the previous time of the same series — with its 1-based file
//! line (data row of a Parquet file) and column. A chunk holds its rows' numbers column by column and the text of their
//! time and value cells (echoed to the output) in one buffer, so reading allocates nothing per
//! row once the buffers have grown. Per series only the id, the newest time (with its line,
//! and its text from chunk to chunk, for the message of a time that goes backwards) are kept.

use crate::error::CliError;
use crate::io::{csv_field, find_column, shown, write_f64, CsvIn, IdType, Need, Places, Records};
use std::collections::HashMap;
use std::io::Read;

/// Consecutive data rows of the input, column by column.
#[derive(Debug, Default)]
pub struct Chunk {
    /// Times.
    pub t: Vec<f64>,
    /// Values.
    pub y: Vec<f64>,
    /// A third number per row, when the reader has one ([`RowReader::with_extra`]).
    pub extra: Vec<f64>,
    /// The series of each row: 0 for a single series, else its id's index in order of
    /// appearance.
    pub series: Vec<usize>,
    /// 1-based file lines (header = line 1), or data rows of a Parquet file: see `places`.
    pub lines: Vec<u64>,
    /// What `lines` count, for messages.
    pub places: Places,
    /// Per row: offset in `text` of the time cell's text, its length, the value cell's length.
    cells: Vec<(usize, usize, usize)>,
    /// The time and value cells of the rows, as written (trimmed).
    text: Vec<u8>,
    /// The ids of the series first seen in this chunk, in order of their index, as CSV output
    /// cells (quoted where needed).
    pub new_ids: Vec<Vec<u8>>,
    /// The same ids as read (for a saved state, `--state`).
    pub new_raw_ids: Vec<Vec<u8>>,
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
    /// The number of rows.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether the chunk has no rows.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Where row `i` is, as a message starts with it (`line 5`, `row 4 of the Parquet file
    /// 'x'`).
    pub fn at(&self, i: usize) -> String {
        self.places.at(self.lines[i])
    }

    /// The time cell of row `i`, as written.
    fn t_text(&self, i: usize) -> &[u8] {
        let (at, t, _) = self.cells[i];
        &self.text[at..at + t]
    }

    /// Appends `[id,]t,y` of row `i`: the id cell (with `--id-col`), and the time and value
    /// cells as read.
    pub fn echo(&self, out: &mut Vec<u8>, i: usize, id: Option<&[u8]>) {
        if let Some(id) = id {
            out.extend_from_slice(id);
            out.push(b',');
        }
        let (at, t, y) = self.cells[i];
        out.extend_from_slice(&self.text[at..at + t]);
        out.push(b',');
        out.extend_from_slice(&self.text[at + t..at + t + y]);
    }

    /// Appends the output row of row `i`: [`echo`](Self::echo), then `values` (NaN an empty
    /// cell) and the line end.
    #[inline]
    pub fn row(&self, out: &mut Vec<u8>, i: usize, id: Option<&[u8]>, values: &[f64]) {
        self.row_with(out, i, id, values, &[]);
    }

    /// [`row`](Self::row) with the cells `tail` after `values` (the `lead` of `seqsmooth
    /// filter --lead`).
    #[inline]
    pub fn row_with(
        &self,
        out: &mut Vec<u8>,
        i: usize,
        id: Option<&[u8]>,
        values: &[f64],
        tail: &[f64],
    ) {
        self.echo(out, i, id);
        for &v in values.iter().chain(tail) {
            out.push(b',');
            if !v.is_nan() {
                write_f64(out, v);
            }
        }
        out.push(b'\n');
    }

    /// Appends the header `[id,]t,y,d0..dM[,s0..sM][,extra…]`.
    pub fn header(
        &self,
        out: &mut Vec<u8>,
        id: Option<&str>,
        m: usize,
        sigma: bool,
        extra: &[&str],
    ) {
        let mut cells: Vec<Vec<u8>> = id.map(|id| csv_field(id.as_bytes())).into_iter().collect();
        cells.extend([b"t".to_vec(), b"y".to_vec()]);
        cells.extend((0..=m).map(|k| format!("d{k}").into_bytes()));
        if sigma {
            cells.extend((0..=m).map(|k| format!("s{k}").into_bytes()));
        }
        cells.extend(extra.iter().map(|c| c.as_bytes().to_vec()));
        out.extend_from_slice(&cells.join(&b","[..]));
        out.push(b'\n');
    }

    fn clear(&mut self) {
        self.t.clear();
        self.y.clear();
        self.extra.clear();
        self.series.clear();
        self.lines.clear();
        self.cells.clear();
        self.text.clear();
        self.new_ids.clear();
        self.new_raw_ids.clear();
        self.error = None;
        self.done = false;
    }
}

/// The newest row of a series.
#[derive(Debug)]
struct Newest {
    t: f64,
    line: u64,
    /// The row in the chunk being read, whose text is there; `None` when it is in an earlier
    /// chunk, and its time cell in `text`.
    row: Option<usize>,
    text: Vec<u8>,
}

/// Reads and validates the data rows of a time series in chunks, from a CSV text
/// (`RowReader::new`) or any [`Records`] (`RowReader::from_records`).
pub struct RowReader<S: Records> {
    csv: S,
    time_idx: usize,
    value_idx: usize,
    id_idx: Option<usize>,
    time_col: String,
    value_col: String,
    /// A third numeric column, its index, name and what it holds (for messages).
    extra: Option<(usize, String, &'static str)>,
    /// Series index by id (with `--id-col`), and the ids as written, for messages.
    index: HashMap<Vec<u8>, usize>,
    ids: Vec<String>,
    /// The newest row of each series, by index.
    newest: Vec<Option<Newest>>,
    /// The series whose newest row is in the chunk being read.
    touched: Vec<usize>,
    rows_read: u64,
}

impl<R: Read> RowReader<CsvIn<R>> {
    /// Reads the header of the CSV text `input` and locates the time and value columns, and the
    /// id column if given.
    pub fn new(
        input: R,
        time_col: &str,
        value_col: &str,
        id_col: Option<&str>,
        need: &Need,
    ) -> Result<Self, CliError> {
        Self::from_records(CsvIn::new(input)?, time_col, value_col, id_col, need)
    }
}

impl<S: Records> RowReader<S> {
    /// Locates the time and value columns of `csv`, and the id column if given, and selects
    /// them.
    pub fn from_records(
        mut csv: S,
        time_col: &str,
        value_col: &str,
        id_col: Option<&str>,
        need: &Need,
    ) -> Result<Self, CliError> {
        need.check_header(csv.header())?;
        if crate::io::looks_like_data(csv.header()) {
            let mut names = format!("the header line '{time_col},{value_col}'");
            if let Some(id) = id_col {
                names = format!(
                    "a header line naming the columns '{id}', '{time_col}' and '{value_col}'"
                );
            }
            return Err(crate::io::headerless(csv.header(), &names));
        }
        let why = csv.header_why();
        let find = |name: &str| find_column(csv.header(), name, &why);
        let (time_idx, value_idx) = (find(time_col)?, find(value_col)?);
        let id_idx = id_col.map(find).transpose()?;
        csv.select(&[time_idx, value_idx], id_idx)?;
        Ok(Self {
            csv,
            time_idx,
            value_idx,
            id_idx,
            time_col: time_col.to_string(),
            value_col: value_col.to_string(),
            extra: None,
            index: HashMap::new(),
            ids: Vec::new(),
            newest: id_idx.map_or_else(|| vec![None], |_| Vec::new()),
            touched: Vec::new(),
            rows_read: 0,
        })
    }

    /// Also reads the numeric column `name` (holding the `what`, for messages) into
    /// [`Chunk::extra`], checked as the time and value are.
    pub fn with_extra(mut self, name: &str, what: &'static str) -> Result<Self, CliError> {
        let why = self.csv.header_why();
        let i = find_column(self.csv.header(), name, &why)?;
        self.csv
            .select(&[self.time_idx, self.value_idx, i], self.id_idx)?;
        self.extra = Some((i, name.to_string(), what));
        Ok(self)
    }

    /// Reads up to `max_rows` rows into `chunk` (replacing its contents). Reading stops early
    /// at the end of the input (`chunk.done`) or at a bad row (`chunk.error`; the rows before
    /// it are in the chunk).
    pub fn read_chunk(&mut self, chunk: &mut Chunk, max_rows: usize) {
        chunk.clear();
        while chunk.len() < max_rows {
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
        // The time cells of the series' newest rows, for the messages of the next chunks:
        // copied once per series and chunk, not per row.
        for s in self.touched.drain(..) {
            if let Some(newest) = &mut self.newest[s] {
                if let Some(i) = newest.row.take() {
                    newest.text.clear();
                    newest.text.extend_from_slice(chunk.t_text(i));
                }
            }
        }
        chunk.bytes_read = self.csv.bytes_read();
        chunk.places = self.csv.places();
        chunk.rows_read = self.rows_read;
    }

    /// The series `ids` (as read) known already, in order of their index, as a resumed run
    /// knows them from its saved state; returns them as CSV output cells.
    pub fn resume_ids(&mut self, ids: &[Vec<u8>]) -> Vec<Vec<u8>> {
        for id in ids {
            self.index.insert(id.clone(), self.ids.len());
            self.ids.push(String::from_utf8_lossy(id).into_owned());
            self.newest.push(None);
        }
        ids.iter().map(|id| csv_field(id)).collect()
    }

    /// How the id column's values are typed (text for CSV).
    pub fn id_type(&self) -> IdType {
        self.csv.id_type()
    }

    /// The series of the current record: its index, a new one for a new id. An id that is not
    /// UTF-8 text is refused (it is written back in every row).
    fn series(&mut self, chunk: &mut Chunk, line: u64) -> Result<usize, CliError> {
        let Some(i) = self.id_idx else { return Ok(0) };
        let id = self.csv.field(i);
        if let Some(&s) = self.index.get(id) {
            return Ok(s);
        }
        if std::str::from_utf8(id).is_err() {
            return Err(CliError::Data(format!(
                "{}, column {}: the id {} is not valid UTF-8 text",
                self.csv.places().at(line),
                i + 1,
                shown(id)
            )));
        }
        let s = self.ids.len();
        self.index.insert(id.to_vec(), s);
        self.ids.push(String::from_utf8_lossy(id).into_owned());
        self.newest.push(None);
        chunk.new_ids.push(csv_field(id));
        chunk.new_raw_ids.push(id.to_vec());
        Ok(s)
    }

    /// Reads one row into `chunk`; `false` at the end of the input.
    fn next_row(&mut self, chunk: &mut Chunk) -> Result<bool, CliError> {
        if !self.csv.next_record()? {
            return Ok(false);
        }
        let line = self.csv.place();
        let t = self.csv.number(self.time_idx, &self.time_col, "time")?;
        let y = self.csv.number(self.value_idx, &self.value_col, "value")?;
        let extra = match &self.extra {
            Some((i, name, what)) => Some(self.csv.number(*i, name, what)?),
            None => None,
        };
        let series = self.series(chunk, line)?;
        let (t_cell, y_cell) = (
            self.csv.field(self.time_idx),
            self.csv.field(self.value_idx),
        );
        let row = chunk.len();
        match &mut self.newest[series] {
            Some(prev) if t <= prev.t => {
                let why = if t == prev.t {
                    "duplicate time; times must be strictly increasing"
                } else {
                    "times must be strictly increasing"
                };
                let of = match self.id_idx {
                    None => String::new(),
                    Some(_) => format!(" of series '{}'", shown(self.ids[series].as_bytes())),
                };
                let prev_text = prev.row.map_or(&prev.text[..], |i| chunk.t_text(i));
                let places = self.csv.places();
                return Err(CliError::Data(format!(
                    "{}: time {} is not after the previous time {} ({}){of}: {why}",
                    places.at(line),
                    shown(t_cell),
                    shown(prev_text),
                    places.short(prev.line)
                )));
            }
            Some(prev) => {
                (prev.t, prev.line) = (t, line);
                if prev.row.replace(row).is_none() {
                    self.touched.push(series);
                }
            }
            none => {
                *none = Some(Newest {
                    t,
                    line,
                    row: Some(row),
                    text: Vec::new(),
                });
                self.touched.push(series);
            }
        }
        // An ISO-8601 time is echoed as the seconds it was read as (as a Parquet timestamp is).
        let at = chunk.text.len();
        if seqsmooth::numeric::epoch::looks_like_date(t_cell) {
            write_f64(&mut chunk.text, t);
        } else {
            chunk.text.extend_from_slice(t_cell);
        }
        chunk.cells.push((at, chunk.text.len() - at, y_cell.len()));
        chunk.text.extend_from_slice(y_cell);
        chunk.t.push(t);
        chunk.y.push(y);
        chunk.extra.extend(extra);
        chunk.series.push(series);
        chunk.lines.push(line);
        self.rows_read += 1;
        Ok(true)
    }
}
