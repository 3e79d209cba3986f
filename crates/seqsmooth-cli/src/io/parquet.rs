//! Parquet files in and out (`seqsmooth filter data.parquet -o out.parquet`), on the `arrow`
//! and `parquet` crates.
//!
//! In: [`ParquetRows`] reads a file's record batches, only the columns asked for, as
//! [`Records`], so that the rows go through the same checks and chunks as CSV rows. Numbers of
//! any Arrow numeric type become `f64`; a timestamp or date, seconds since the Unix epoch. Each
//! number also has the text the CSV output echoes: its shortest round-trip digits.
//!
//! Out: [`ParquetTable`] takes the rows the CSV output would hold and writes them as a table
//! with the same columns: the id column with the input's type, every other column `Float64`,
//! null where the CSV cell is empty. The shortest round-trip digits parse back to the very
//! same double, so the numbers are the CSV output's bit for bit. Rows are written in batches of
//! [`BATCH_ROWS`] into row groups of at most [`ROW_GROUP_ROWS`].

use crate::error::CliError;
use crate::io::{fmt_f64, shown, write_f64, IdType, Places, Records, Table};
use arrow::array::{
    Array, ArrayRef, AsArray, Float64Array, Float64Builder, Int64Builder, StringArray,
    StringBuilder, UInt64Builder,
};
use arrow::compute::cast;
use arrow::datatypes::{DataType, Field, Float64Type, Int64Type, Schema, SchemaRef, TimeUnit};
use arrow::record_batch::RecordBatch;
use parquet::arrow::arrow_reader::{ParquetRecordBatchReader, ParquetRecordBatchReaderBuilder};
use parquet::arrow::{ArrowWriter, ProjectionMask};
use parquet::basic::Compression;
use parquet::file::properties::WriterProperties;
use parquet::schema::types::ColumnPath;
use std::cell::Cell;
use std::fs::File;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;
use std::sync::{Arc, Once};

/// Rows read from the file per record batch.
const READ_BATCH_ROWS: usize = 16_384;

/// Rows written per record batch.
pub const BATCH_ROWS: usize = 65_536;

/// The most rows in a row group of an output file.
pub const ROW_GROUP_ROWS: usize = 262_144;

pub use crate::io::is_parquet;

thread_local! {
    /// Whether this thread is in [`guarded`]: its panics are reported as errors, not printed.
    static GUARDED: Cell<bool> = const { Cell::new(false) };
}

/// Installs, once, the panic hook that stays quiet on a thread in [`guarded`] and runs the
/// previous hook on any other.
fn quiet_hook() {
    static HOOK: Once = Once::new();
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !GUARDED.with(Cell::get) {
                previous(info);
            }
        }));
    });
}

/// Runs `f`, a call into the `parquet` crate on data from the file, turning a panic (a corrupt
/// file the crate does not check) into an error of `name`.
fn guarded<T>(name: &str, what: &str, f: impl FnOnce() -> T) -> Result<T, CliError> {
    quiet_hook();
    GUARDED.with(|g| g.set(true));
    let result = catch_unwind(AssertUnwindSafe(f));
    GUARDED.with(|g| g.set(false));
    result.map_err(|_| {
        CliError::Data(format!(
            "cannot read the Parquet file {name}: it is corrupt ({what} failed)"
        ))
    })
}

/// How a column's numbers become `f64`.
#[derive(Clone, Copy, Debug)]
enum Numbers {
    /// An Arrow numeric type: cast to `Float64` (integers as `as f64` rounds them).
    Cast,
    /// Integer ticks of a timestamp or a `Date64`, so many per second: seconds since the epoch.
    Ticks(i64),
    /// `Date32` days: seconds since the epoch.
    Days,
}

/// How the numbers of a column of type `t` are read, if they are numbers.
fn numbers_of(t: &DataType) -> Option<Numbers> {
    use DataType::*;
    let per_second = |unit: &TimeUnit| match unit {
        TimeUnit::Second => 1,
        TimeUnit::Millisecond => 1_000,
        TimeUnit::Microsecond => 1_000_000,
        TimeUnit::Nanosecond => 1_000_000_000,
    };
    match t {
        Int8 | Int16 | Int32 | Int64 | UInt8 | UInt16 | UInt32 | UInt64 | Float16 | Float32
        | Float64 | Decimal128(..) | Decimal256(..) => Some(Numbers::Cast),
        Timestamp(unit, _) => Some(Numbers::Ticks(per_second(unit))),
        Date32 => Some(Numbers::Days),
        Date64 => Some(Numbers::Ticks(1_000)),
        _ => None,
    }
}

/// The id type of a column of type `t`, if it can hold ids: text, or integers (their decimal
/// text).
fn id_type_of(t: &DataType) -> Option<IdType> {
    use DataType::*;
    match t {
        Utf8 | LargeUtf8 | Utf8View => Some(IdType::Text),
        Dictionary(_, values) if matches!(**values, Utf8 | LargeUtf8 | Utf8View) => {
            Some(IdType::Text)
        }
        Int8 | Int16 | Int32 | Int64 => Some(IdType::Signed),
        UInt8 | UInt16 | UInt32 | UInt64 => Some(IdType::Unsigned),
        _ => None,
    }
}

/// `ticks` at `per_second` to the second as the nearest double to the exact decimal: the
/// library's one rule ([`seqsmooth::numeric::epoch::seconds_from_ticks`]).
fn seconds(ticks: i64, per_second: i64) -> f64 {
    seqsmooth::numeric::epoch::seconds_from_ticks(ticks, 1, per_second)
        .unwrap_or(ticks as f64 / per_second as f64)
}

/// One selected column of the current batch.
enum Column {
    /// A time or value column, as doubles (null where the file has none).
    Numbers(Float64Array),
    /// The id column, as text.
    Text(StringArray),
}

/// A column the reader asked for.
struct Selected {
    /// Its index in the file's columns.
    index: usize,
    /// How its numbers are read; `None` for the id column.
    numbers: Option<Numbers>,
}

/// The rows of a Parquet file as [`Records`]: only the selected columns are decoded, a record
/// batch at a time.
pub struct ParquetRows {
    /// `'path'`, for messages.
    name: Arc<str>,
    /// The names of the file's columns.
    header: Vec<String>,
    /// The Arrow types of the file's columns.
    types: Vec<DataType>,
    /// Until [`Records::select`]: the reader to build.
    builder: Option<ParquetRecordBatchReaderBuilder<File>>,
    /// After [`Records::select`]: the record batches of the selected columns.
    batches: Option<ParquetRecordBatchReader>,
    /// The slot of each file column in `selected`, if selected.
    slots: Vec<Option<usize>>,
    /// The selected columns, by slot.
    selected: Vec<Selected>,
    /// The selected columns of the current batch, by slot.
    columns: Vec<Column>,
    /// The text of the current row's numbers, by slot.
    texts: Vec<Vec<u8>>,
    /// The current row in the batch.
    at: usize,
    /// The rows of the batch.
    batch_rows: usize,
    /// 1-based data row of the current record (0 before the first).
    row: u64,
    /// The file's rows, for the progress estimate.
    total_rows: u64,
    /// The file's bytes, for the progress estimate.
    size: u64,
    /// The type of the id column (text when there is none).
    id_type: IdType,
}

impl ParquetRows {
    /// Opens the Parquet file `path` and reads its schema.
    pub fn open(path: &Path) -> Result<Self, CliError> {
        let name = format!("'{}'", path.display());
        let file = File::open(path)
            .map_err(|e| CliError::Data(format!("cannot open input file {name}: {e}")))?;
        let size = file.metadata().map_or(0, |m| m.len());
        let builder = guarded(&name, "reading its footer", || {
            ParquetRecordBatchReaderBuilder::try_new(file)
        })?
        .map_err(|e| CliError::Data(format!("cannot read the Parquet file {name}: {e}")))?;
        let schema = builder.schema().clone();
        let total_rows = u64::try_from(builder.metadata().file_metadata().num_rows()).unwrap_or(0);
        Ok(Self {
            name: name.into(),
            header: schema.fields().iter().map(|f| f.name().clone()).collect(),
            types: schema
                .fields()
                .iter()
                .map(|f| f.data_type().clone())
                .collect(),
            builder: Some(builder.with_batch_size(READ_BATCH_ROWS)),
            batches: None,
            slots: vec![None; schema.fields().len()],
            selected: Vec::new(),
            columns: Vec::new(),
            texts: Vec::new(),
            at: 0,
            batch_rows: 0,
            row: 0,
            total_rows,
            size,
            id_type: IdType::Text,
        })
    }

    /// Where the current row is, and the column named `column`, as a message starts with them.
    fn at_cell(&self, column: &str) -> String {
        format!("{}, column '{column}'", self.places().at(self.row))
    }

    /// An error reading the file's data.
    fn read_error(&self, e: impl std::fmt::Display) -> CliError {
        CliError::Data(format!(
            "cannot read the Parquet file {} after data row {}: {e}",
            self.name, self.row
        ))
    }

    /// Reads the next non-empty batch into `columns`; `false` at the end of the file.
    fn next_batch(&mut self) -> Result<bool, CliError> {
        loop {
            let Some(batches) = self.batches.as_mut() else {
                return Ok(false);
            };
            let next = guarded(&self.name, "decoding its data", || batches.next())?;
            let batch = match next {
                None => return Ok(false),
                Some(Err(e)) => return Err(self.read_error(e)),
                Some(Ok(batch)) => batch,
            };
            if batch.num_rows() == 0 {
                continue;
            }
            // The batch holds the selected columns in file order.
            let mut order: Vec<usize> = self.selected.iter().map(|s| s.index).collect();
            order.sort_unstable();
            order.dedup();
            let mut columns = Vec::with_capacity(self.selected.len());
            for s in &self.selected {
                let position = order.binary_search(&s.index).unwrap_or(0);
                let Some(array) = batch.columns().get(position) else {
                    return Err(self.read_error("a column is missing from the data"));
                };
                let column = match s.numbers {
                    Some(how) => {
                        Column::Numbers(to_f64(array, how).map_err(|e| self.read_error(e))?)
                    }
                    None => {
                        let text = cast(array, &DataType::Utf8).map_err(|e| self.read_error(e))?;
                        let text = text.as_string_opt::<i32>().cloned();
                        Column::Text(text.ok_or_else(|| self.read_error("an id is not text"))?)
                    }
                };
                columns.push(column);
            }
            self.columns = columns;
            self.batch_rows = batch.num_rows();
            self.at = 0;
            return Ok(true);
        }
    }
}

/// The numbers of `array` as doubles, read as `how` says.
fn to_f64(array: &ArrayRef, how: Numbers) -> Result<Float64Array, arrow::error::ArrowError> {
    let wrong = || arrow::error::ArrowError::CastError("unexpected column type".into());
    match how {
        Numbers::Cast => {
            let doubles = cast(array, &DataType::Float64)?;
            doubles
                .as_primitive_opt::<Float64Type>()
                .cloned()
                .ok_or_else(wrong)
        }
        Numbers::Ticks(per_second) => {
            let ticks = cast(array, &DataType::Int64)?;
            let ticks = ticks.as_primitive_opt::<Int64Type>().ok_or_else(wrong)?;
            Ok(ticks.unary::<_, Float64Type>(|v| seconds(v, per_second)))
        }
        Numbers::Days => {
            let days = cast(array, &DataType::Int64)?;
            let days = days.as_primitive_opt::<Int64Type>().ok_or_else(wrong)?;
            Ok(days.unary::<_, Float64Type>(|d| seconds(d * 86_400, 1)))
        }
    }
}

impl Records for ParquetRows {
    fn header(&self) -> &[String] {
        &self.header
    }

    fn header_why(&self) -> String {
        format!(" of the Parquet file {}", self.name)
    }

    fn select(&mut self, numbers: &[usize], text: Option<usize>) -> Result<(), CliError> {
        let type_error = |i: usize, what: &str| {
            CliError::Data(format!(
                "column '{}' of the Parquet file {} has the type {}, {what}",
                shown(self.header[i].as_bytes()),
                self.name,
                self.types[i]
            ))
        };
        let mut selected = Vec::new();
        for &i in numbers {
            let how = numbers_of(&self.types[i]).ok_or_else(|| {
                type_error(
                    i,
                    "not a number: the time and value columns must be integers, floats or \
                     decimals (the time also a timestamp or a date)",
                )
            })?;
            selected.push(Selected {
                index: i,
                numbers: Some(how),
            });
        }
        if let Some(i) = text {
            self.id_type = id_type_of(&self.types[i]).ok_or_else(|| {
                type_error(
                    i,
                    "not usable as an id: the id column must be text (or a dictionary of \
                     text) or integers",
                )
            })?;
            selected.push(Selected {
                index: i,
                numbers: None,
            });
        }
        for (slot, s) in selected.iter().enumerate() {
            self.slots[s.index].get_or_insert(slot);
        }
        let builder = self.builder.take().ok_or_else(|| {
            CliError::Data("internal error: the Parquet columns are selected twice".into())
        })?;
        let mask =
            ProjectionMask::roots(builder.parquet_schema(), selected.iter().map(|s| s.index));
        let reader = guarded(&self.name, "reading its row groups", || {
            builder.with_projection(mask).build()
        })?
        .map_err(|e| CliError::Data(format!("cannot read the Parquet file {}: {e}", self.name)))?;
        self.texts = vec![Vec::new(); selected.len()];
        self.selected = selected;
        self.batches = Some(reader);
        Ok(())
    }

    fn next_record(&mut self) -> Result<bool, CliError> {
        if self.at + 1 < self.batch_rows {
            self.at += 1;
        } else if !self.next_batch()? {
            return Ok(false);
        }
        self.row += 1;
        let at = self.at;
        for (slot, column) in self.columns.iter().enumerate() {
            match column {
                Column::Numbers(values) => {
                    let text = &mut self.texts[slot];
                    text.clear();
                    if values.is_valid(at) {
                        write_f64(text, values.value(at));
                    }
                }
                Column::Text(ids) if ids.is_null(at) => {
                    let name = shown(self.header[self.selected[slot].index].as_bytes());
                    return Err(CliError::Data(format!(
                        "{}: the id is null; every row needs an id",
                        self.at_cell(&name)
                    )));
                }
                Column::Text(_) => {}
            }
        }
        Ok(true)
    }

    fn place(&self) -> u64 {
        self.row
    }

    fn places(&self) -> Places {
        Places::ParquetRows(self.name.clone())
    }

    fn field(&self, i: usize) -> &[u8] {
        match self.slots.get(i).copied().flatten() {
            Some(slot) => match &self.columns[slot] {
                Column::Numbers(_) => &self.texts[slot],
                Column::Text(ids) => ids.value(self.at).as_bytes(),
            },
            None => b"",
        }
    }

    fn number(&self, i: usize, column: &str, what: &str) -> Result<f64, CliError> {
        let values = match self.slots.get(i).copied().flatten() {
            Some(slot) => match &self.columns[slot] {
                Column::Numbers(values) => values,
                Column::Text(_) => return Err(self.read_error("the id column is not a number")),
            },
            None => return Err(self.read_error("a column was not selected")),
        };
        let at = || self.at_cell(column);
        if values.is_null(self.at) {
            return Err(CliError::Data(format!(
                "{}: the cell is null, expected a number",
                at()
            )));
        }
        let v = values.value(self.at);
        if !v.is_finite() {
            return Err(CliError::Data(format!(
                "{}: {what} {} is not finite",
                at(),
                fmt_f64(v)
            )));
        }
        Ok(v)
    }

    fn bytes_read(&self) -> u64 {
        match self.total_rows {
            0 => 0,
            total => (self.size as f64 * (self.row as f64 / total as f64)) as u64,
        }
    }

    fn id_type(&self) -> IdType {
        self.id_type
    }
}

/// A column of the output being built.
enum Builder {
    /// A number column: `Float64`, null for an empty cell.
    Numbers(Float64Builder),
    /// Text ids.
    Text(StringBuilder),
    /// Signed integer ids.
    Signed(Int64Builder),
    /// Unsigned integer ids.
    Unsigned(UInt64Builder),
}

impl Builder {
    /// Appends the CSV output cell `cell` (unquoted); `false` if it does not parse as the
    /// column's type (which the command never writes).
    fn push(&mut self, cell: &[u8]) -> bool {
        fn number<T: std::str::FromStr>(cell: &[u8]) -> Option<T> {
            std::str::from_utf8(cell).ok()?.parse().ok()
        }
        match self {
            Builder::Numbers(b) if cell.is_empty() => b.append_null(),
            Builder::Numbers(b) => match fast_float2::parse::<f64, _>(cell) {
                Ok(v) => b.append_value(v),
                Err(_) => return false,
            },
            Builder::Text(b) => match std::str::from_utf8(cell) {
                Ok(text) => b.append_value(text),
                Err(_) => return false,
            },
            Builder::Signed(b) => match number(cell) {
                Some(v) => b.append_value(v),
                None => return false,
            },
            Builder::Unsigned(b) => match number(cell) {
                Some(v) => b.append_value(v),
                None => return false,
            },
        }
        true
    }

    /// The column built so far (the builder starts again empty).
    fn finish(&mut self) -> ArrayRef {
        match self {
            Builder::Numbers(b) => Arc::new(b.finish()),
            Builder::Text(b) => Arc::new(b.finish()),
            Builder::Signed(b) => Arc::new(b.finish()),
            Builder::Unsigned(b) => Arc::new(b.finish()),
        }
    }
}

/// The rows of the CSV output as a Parquet file: columns and names as the CSV header, the id
/// column (first, with `--id-col`) of the input's id type, every other column nullable
/// `Float64`.
pub struct ParquetTable {
    /// `'path'`, for messages.
    name: String,
    /// The type of the first column's ids, or `None` when the first column is a number.
    id: Option<IdType>,
    /// Until the header is read: the file.
    file: Option<File>,
    /// Once the header is read: the writer of the file.
    writer: Option<ArrowWriter<File>>,
    /// Once the header is read: the columns.
    schema: Option<SchemaRef>,
    /// The columns of the rows not written yet.
    builders: Vec<Builder>,
    /// Rows in the builders.
    rows: usize,
}

impl ParquetTable {
    /// A table written to `file` (named `name` in messages); the first column holds ids of
    /// type `id`, if given.
    pub fn new(file: File, name: &str, id: Option<IdType>) -> Self {
        Self {
            name: name.to_string(),
            id,
            file: Some(file),
            writer: None,
            schema: None,
            builders: Vec::new(),
            rows: 0,
        }
    }

    /// An error writing the file.
    fn write_error(&self, e: impl std::fmt::Display) -> CliError {
        CliError::Data(format!("cannot write to {}: {e}", self.name))
    }

    /// Creates the writer for the columns named `header`.
    fn start(&mut self, header: &csv::ByteRecord) -> Result<(), CliError> {
        let mut fields = Vec::with_capacity(header.len());
        for (k, name) in header.iter().enumerate() {
            let name = String::from_utf8_lossy(name).into_owned();
            let (data_type, builder) = match (k, self.id) {
                (0, Some(IdType::Text)) => (DataType::Utf8, Builder::Text(StringBuilder::new())),
                (0, Some(IdType::Signed)) => {
                    (DataType::Int64, Builder::Signed(Int64Builder::new()))
                }
                (0, Some(IdType::Unsigned)) => {
                    (DataType::UInt64, Builder::Unsigned(UInt64Builder::new()))
                }
                _ => (DataType::Float64, Builder::Numbers(Float64Builder::new())),
            };
            // The id column never holds a null; the others are null where the cell is empty.
            fields.push(Field::new(name, data_type, k != 0 || self.id.is_none()));
            self.builders.push(builder);
        }
        // Dictionary encoding only for the ids: the estimates are almost all distinct, so a
        // dictionary would be built and dropped for every page.
        let mut props = WriterProperties::builder()
            .set_compression(Compression::SNAPPY)
            .set_max_row_group_row_count(Some(ROW_GROUP_ROWS))
            .set_dictionary_enabled(false);
        if let (Some(_), Some(id)) = (self.id, fields.first()) {
            let column = ColumnPath::new(vec![id.name().clone()]);
            props = props.set_column_dictionary_enabled(column, true);
        }
        let props = props.build();
        let schema = Arc::new(Schema::new(fields));
        let file = self
            .file
            .take()
            .ok_or_else(|| self.write_error("internal error: the file is gone"))?;
        let writer = ArrowWriter::try_new(file, schema.clone(), Some(props))
            .map_err(|e| self.write_error(e))?;
        self.writer = Some(writer);
        self.schema = Some(schema);
        Ok(())
    }

    /// Writes the rows in the builders as one record batch.
    fn flush(&mut self) -> Result<(), CliError> {
        if self.rows == 0 {
            return Ok(());
        }
        let (Some(schema), Some(writer)) = (&self.schema, &mut self.writer) else {
            return Ok(());
        };
        let columns = self.builders.iter_mut().map(Builder::finish).collect();
        let batch = RecordBatch::try_new(schema.clone(), columns);
        let written = batch
            .map_err(|e| e.to_string())
            .and_then(|b| writer.write(&b).map_err(|e| e.to_string()));
        self.rows = 0;
        written.map_err(|e| self.write_error(e))
    }
}

impl Table for ParquetTable {
    fn write_rows(&mut self, csv: &[u8]) -> Result<(), CliError> {
        let mut reader = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .from_reader(csv);
        let mut record = csv::ByteRecord::new();
        loop {
            match reader.read_byte_record(&mut record) {
                Ok(true) => {}
                Ok(false) => return Ok(()),
                Err(e) => return Err(self.write_error(format!("internal error: {e}"))),
            }
            if self.schema.is_none() {
                self.start(&record)?;
                continue;
            }
            if record.len() != self.builders.len() {
                return Err(self.write_error("internal error: a row has other columns"));
            }
            for (builder, cell) in self.builders.iter_mut().zip(record.iter()) {
                if !builder.push(cell) {
                    let cell = shown(cell);
                    return Err(self.write_error(format!("internal error: the cell '{cell}'")));
                }
            }
            self.rows += 1;
            if self.rows == BATCH_ROWS {
                self.flush()?;
            }
        }
    }

    fn close(mut self: Box<Self>) -> Result<(), CliError> {
        self.flush()?;
        match self.writer.take() {
            Some(writer) => writer.close().map(|_| ()).map_err(|e| self.write_error(e)),
            None => Err(self.write_error("internal error: no header was written")),
        }
    }
}
