//! The command's files: opening inputs and outputs, the one CSV reader (records with their
//! 1-based file lines, header checks, column lookup, number cells) and the one CSV writer
//! (cells, numbers with round-trip precision) of every subcommand. Other formats come in as
//! [`Records`] and go out as a [`Table`] of [`Output`] (Parquet: [`parquet`]). Imports no
//! subcommand.

mod output;
pub mod parquet;
pub mod progress;
pub mod rows;

pub use output::{check_distinct, temp_beside, Destination, Output, Table};

use crate::error::CliError;
use std::fs::File;
use std::io::{self, Read};
use std::path::Path;

/// The shortest text that parses back to exactly `x` (the `ryu` crate's digits): plain decimal
/// for `0` and `1e-5 <= |x| < 1e16`, otherwise scientific (`1e-300`, `2.5e20`). This is Rust's
/// `{}` and `{:e}` text with two changes to `ryu`'s: a trailing `.0` is dropped (`ryu` writes
/// `1.0`, Rust `1`), and where `x` lies exactly halfway between two shortest candidates `ryu`
/// takes the even last digit and Rust the one away from zero, so that digit goes up by one
/// (`tie_digit`). Non-finite values print as `NaN`, `inf`, `-inf` (never in valid output).
#[inline]
pub fn write_f64(out: &mut Vec<u8>, x: f64) {
    // The flags' cells (the automatic filter's `outlier` and `misfit`, two a row): the same
    // text as below, without the general formatting.
    if x == 1.0 || (x == 0.0 && x.is_sign_positive()) {
        out.push(if x == 1.0 { b'1' } else { b'0' });
        return;
    }
    let mut buf = ryu::Buffer::new();
    let text = buf.format(x).as_bytes();
    let text = text.strip_suffix(b".0").unwrap_or(text);
    let start = out.len();
    out.extend_from_slice(text);
    if let Some(last) = tie_digit(x, text) {
        out[start + last] += 1;
    }
}

/// Where `x` lies exactly halfway between the decimal `text` (`ryu`'s, `[-]d.ddd[eX]`, even
/// last digit) and the next one up in magnitude in its last digit: the index of that digit.
/// Then `2|x| = (2D + 1)·10^p`, `D` the digits and `10^p` the last one's unit; with
/// `|x| = o·2^e` (`o` odd) that is `e = p - 1` and `o·5^-p = 2D + 1` for `p < 0`, `o =
/// (2D+1)·5^p` otherwise, so `x` needs an exact decimal of at most 18 digits: checked on its
/// bits first, the digits only then.
#[inline]
fn tie_digit(x: f64, text: &[u8]) -> Option<usize> {
    // Zero is no tie (and its mantissa has no lowest set bit to shift to).
    if x == 0.0 {
        return None;
    }
    let bits = x.abs().to_bits();
    let (m, q) = match bits >> 52 {
        0 => (bits, -1074),
        b => (bits & ((1 << 52) - 1) | (1 << 52), b as i32 - 1075),
    };
    let (odd, e) = (
        u128::from(m >> m.trailing_zeros()),
        q + m.trailing_zeros() as i32,
    );
    // A tie has p = e + 1; for p < 0, o·5^-p = 2D + 1 < 2·10^17.
    let scaled = |p: i32| {
        5u128
            .checked_pow(p.unsigned_abs())
            .and_then(|f| f.checked_mul(odd))
    };
    if e < -1 && (e < -27 || scaled(e + 1).is_none_or(|v| v >= 2 * 10u128.pow(17))) {
        return None;
    }
    let (mut d, mut decimals, mut point, mut end) = (0u128, 0i32, false, text.len());
    for (i, &c) in text.iter().enumerate() {
        match c {
            b'0'..=b'9' => {
                (d, decimals) = (10 * d + u128::from(c - b'0'), decimals + i32::from(point))
            }
            b'.' => point = true,
            b'e' => {
                end = i;
                break;
            }
            _ => {}
        }
    }
    let exp: i32 = std::str::from_utf8(&text[(end + 1).min(text.len())..])
        .ok()?
        .parse()
        .unwrap_or(0);
    let p = exp - decimals;
    let rhs = if p < 0 {
        Some(2 * d + 1)
    } else {
        5u128.checked_pow(p as u32)?.checked_mul(2 * d + 1)
    };
    let lhs = if p < 0 { scaled(p) } else { Some(odd) };
    (d % 2 == 0 && e == p - 1 && lhs.is_some() && lhs == rhs).then_some(end - 1)
}

/// [`write_f64`] as a `String`.
pub fn fmt_f64(x: f64) -> String {
    let mut out = Vec::with_capacity(24);
    write_f64(&mut out, x);
    // Only ASCII digits, signs, '.', 'e', "NaN" and "inf" are written.
    String::from_utf8(out).unwrap_or_default()
}

/// `cell` as a CSV output field: quoted (with quotes doubled) when it holds a comma, a quote
/// or a line break.
pub fn csv_field(cell: &[u8]) -> Vec<u8> {
    let special = |b: &u8| matches!(b, b',' | b'"' | b'\r' | b'\n');
    if !cell.iter().any(special) {
        return cell.to_vec();
    }
    let parts: Vec<&[u8]> = cell.split(|&b| b == b'"').collect();
    [&b"\""[..], &parts.join(&b"\"\""[..]), b"\""].concat()
}

/// Parses the number in the (trimmed) cell of `line` in `column`, holding the `what`: a typed
/// error for an empty cell, a non-number or a non-finite value. The `fast-float2` crate
/// parses (correctly rounded, so the same double as `str::parse`); anything it does not take
/// as a finite number goes through `str::parse` for the same result and messages. A time
/// (`what` is `"time"`) may also be an ISO-8601 text (`2024-03-01T12:00:00Z`, fractional
/// seconds, an offset, a date alone; UTC without an offset), read as seconds since the Unix
/// epoch by the library's rule ([`seqsmooth::numeric::epoch::parse_iso8601`]), as Parquet
/// timestamps are: only after the number parser has failed, so numbers cost what they did.
#[inline]
pub fn parse_cell(cell: &[u8], line: u64, column: &str, what: &str) -> Result<f64, CliError> {
    match fast_float2::parse::<f64, _>(cell) {
        Ok(v) if v.is_finite() => Ok(v),
        _ => parse_cell_text(cell, line, column, what),
    }
}

#[cold]
#[inline(never)]
fn parse_cell_text(cell: &[u8], line: u64, column: &str, what: &str) -> Result<f64, CliError> {
    let at = format!("line {line}, column '{column}'");
    if cell.is_empty() {
        return Err(CliError::Data(format!(
            "{at}: the cell is empty, expected a number"
        )));
    }
    let text = shown(cell);
    if what == "time" && seqsmooth::numeric::epoch::looks_like_date(cell) {
        let iso = std::str::from_utf8(cell).map_err(|_| {
            CliError::Data(format!(
                "{at}: '{text}' is not a number or an ISO-8601 time"
            ))
        })?;
        return seqsmooth::numeric::epoch::parse_iso8601(iso).map_err(|e| {
            let reason = match &e {
                seqsmooth::Error::InvalidParameter { reason, .. } => Some(reason.clone()),
                _ => None,
            };
            CliError::from(e).reworded(|m| match reason {
                Some(reason) => format!("{at}: '{text}' is not an ISO-8601 time: {reason}"),
                None => format!("{at}: '{text}': {m}"),
            })
        });
    }
    let v: f64 = std::str::from_utf8(cell)
        .ok()
        .and_then(|s| s.parse().ok())
        .ok_or_else(|| CliError::Data(format!("{at}: '{text}' is not a number")))?;
    if !v.is_finite() {
        return Err(CliError::Data(format!("{at}: {what} {text} is not finite")));
    }
    Ok(v)
}

/// The longest cell text a message quotes whole, in characters.
const SHOWN_CHARS: usize = 64;

/// A cell's text as a message quotes it: invalid UTF-8 as `\u{fffd}`, control and other
/// invisible characters escaped (`\0`, `\t`, `\u{200b}`, …), and a text longer than
/// 64 characters cut to its first 40, followed by `…` and the cell's length in bytes.
///
/// ```
/// use seqsmooth_cli::io::shown;
/// assert_eq!(shown(b"1.5"), "1.5");
/// assert_eq!(shown(b"1\x002"), "1\\02");
/// assert_eq!(shown(&[b'9'; 100]), format!("{}… (100 bytes)", "9".repeat(40)));
/// ```
pub fn shown(cell: &[u8]) -> String {
    let text = String::from_utf8_lossy(cell);
    let escaped = |c: char| -> String {
        let invisible = c.is_control()
            || matches!(c, '\u{200b}'..='\u{200f}' | '\u{2028}'..='\u{202e}' | '\u{2060}'..='\u{2064}' | '\u{feff}');
        if invisible {
            c.escape_debug().collect()
        } else {
            c.to_string()
        }
    };
    if text.chars().count() <= SHOWN_CHARS {
        text.chars().map(escaped).collect()
    } else {
        let head: String = text.chars().take(40).map(escaped).collect();
        format!("{head}… ({} bytes)", cell.len())
    }
}

/// `bytes` without leading and trailing whitespace (Unicode whitespace for UTF-8 text, as
/// `str::trim`; ASCII whitespace otherwise).
pub fn trim(bytes: &[u8]) -> &[u8] {
    let ascii = bytes.trim_ascii();
    match (ascii.first(), ascii.last()) {
        // Non-ASCII whitespace starts with a byte >= 0x80 and ends with one.
        (Some(&a), Some(&b)) if a >= 0x80 || b >= 0x80 => match std::str::from_utf8(ascii) {
            Ok(s) => s.trim().as_bytes(),
            Err(_) => ascii,
        },
        _ => ascii,
    }
}

/// The data rows a command needs, and why (for the too-few-samples messages).
#[derive(Clone, Debug)]
pub struct Need {
    /// The number of data rows needed.
    pub rows: usize,
    /// What needs them, e.g. `degree 2` or `window 11`.
    pub why: String,
}

impl Need {
    /// A degree-`m` estimate needs `m + 1` rows.
    pub fn degree(m: usize) -> Self {
        Self {
            rows: m + 1,
            why: format!("degree {m}"),
        }
    }

    /// `rows` rows for `why` (e.g. `the radar model`).
    pub fn rows(rows: usize, why: &str) -> Self {
        Self {
            rows,
            why: why.to_string(),
        }
    }

    /// A window of `w` samples needs `w` rows.
    pub fn window(w: usize) -> Self {
        Self {
            rows: w,
            why: format!("window {w}"),
        }
    }

    /// The too-few-samples error when only `got` data rows were read.
    pub fn check(&self, got: usize) -> Result<(), CliError> {
        if got < self.rows {
            return Err(CliError::Data(format!(
                "too few samples: the input has {got} data row{}, {} needs at least {}",
                plural(got),
                self.why,
                self.rows
            )));
        }
        Ok(())
    }

    /// An input without a header (empty) cannot hold the samples needed.
    pub fn check_header(&self, headers: &[String]) -> Result<(), CliError> {
        if headers.iter().all(String::is_empty) {
            return Err(CliError::Data(format!(
                "too few samples: the input is empty (no header, no data rows); {} needs at \
                 least {} data row{}",
                self.why,
                self.rows,
                plural(self.rows)
            )));
        }
        Ok(())
    }
}

/// `"s"` unless `n` is 1.
pub fn plural(n: usize) -> &'static str {
    if n == 1 {
        ""
    } else {
        "s"
    }
}

/// The index of the column `name` in the header, or an error listing the columns (`why`
/// after "the header"); a name the header holds more than once is ambiguous, an error too.
pub fn find_column(headers: &[String], name: &str, why: &str) -> Result<usize, CliError> {
    let mut at = headers
        .iter()
        .enumerate()
        .filter(|(_, h)| *h == name)
        .map(|(i, _)| i);
    let found = at.next();
    if let (Some(first), Some(second)) = (found, at.next()) {
        return Err(CliError::Data(format!(
            "column '{}' appears more than once in the header (columns {} and {}): which one \
             is meant is ambiguous; rename one",
            shown(name.as_bytes()),
            first + 1,
            second + 1
        )));
    }
    found.ok_or_else(|| {
        if looks_like_data(headers) {
            return headerless(headers, &format!("a column '{}'", shown(name.as_bytes())));
        }
        CliError::Data(format!(
            "column '{}' not found in the header{why}; columns are: {}",
            shown(name.as_bytes()),
            headers
                .iter()
                .map(|h| shown(h.as_bytes()))
                .collect::<Vec<_>>()
                .join(", ")
        ))
    })
}

/// Whether a header's cells all read as numbers or ISO-8601 dates: the first row of a CSV
/// without a header line.
///
/// ```
/// use seqsmooth_cli::io::looks_like_data;
/// let cells = |c: &[&str]| c.iter().map(|s| s.to_string()).collect::<Vec<_>>();
/// assert!(looks_like_data(&cells(&["0", "-173184.4958"])));
/// assert!(looks_like_data(&cells(&["2024-03-01T12:00:00Z", "1.5"])));
/// assert!(!looks_like_data(&cells(&["t", "y"])) && !looks_like_data(&cells(&["0", "y"])));
/// ```
pub fn looks_like_data(headers: &[String]) -> bool {
    !headers.is_empty()
        && headers.iter().all(|h| {
            let b = h.as_bytes();
            fast_float2::parse::<f64, _>(b).is_ok() || seqsmooth::numeric::epoch::looks_like_date(b)
        })
}

/// The error for an input whose first row (`headers`) looks like data, not a header: what the
/// command needs (`needs`, e.g. `the header line 't,y'`) and how to give it.
pub fn headerless(headers: &[String], needs: &str) -> CliError {
    let first = headers
        .iter()
        .map(|h| shown(h.as_bytes()))
        .collect::<Vec<_>>()
        .join(",");
    CliError::Data(format!(
        "the first row ('{first}') looks like data, not a header: the input needs a header line \
         naming its columns first, and this command needs {needs}: add it as the first line of \
         the file"
    ))
}

/// The numbers of `\r` and `\n` bytes in `bytes`, counted in `u8` lanes over chunks of at most
/// 255 bytes, which the compiler vectorises (a `filter().count()` runs byte by byte).
fn count_breaks(bytes: &[u8]) -> (u64, u64) {
    bytes.chunks(255).fold((0, 0), |(r, n), c| {
        let (cr, lf) = c.iter().fold((0u8, 0u8), |(r, n), &b| {
            (r + u8::from(b == b'\r'), n + u8::from(b == b'\n'))
        });
        (r + u64::from(cr), n + u64::from(lf))
    })
}

/// Counts the lines of the bytes the CSV parser consumes.
///
/// The `csv` crate's own line numbers are wrong after blank lines and with CRLF line ends, so
/// the reader passes every byte through here and the line of a record is computed from its byte
/// offset. Only the bytes read ahead of the current record are kept (the parser's buffer).
struct LineTracker<R: Read> {
    inner: R,
    /// Bytes read; `pending[start..]` are not yet attributed to a record, and `pending[start]`
    /// is at offset `base`. The attributed prefix is dropped at the next read.
    pending: Vec<u8>,
    start: usize,
    base: u64,
    /// Line terminators (`\n`, `\r\n` or a lone `\r`) before `base`.
    breaks: u64,
    /// Whether the byte before `base` is `\r` (so a `\n` at `base` ends no new line).
    after_cr: bool,
}

impl<R: Read> LineTracker<R> {
    /// The 1-based line of the record the parser reports at byte offset `byte`: the parser's
    /// offset may sit before blank lines or a line terminator it skipped, so those are skipped
    /// here too. Offsets must not decrease between calls.
    fn line_at(&mut self, byte: u64) -> u64 {
        let rest = &self.pending[self.start..];
        let mut k = (byte.saturating_sub(self.base) as usize).min(rest.len());
        while k < rest.len() && matches!(rest[k], b'\r' | b'\n') {
            k += 1;
        }
        let span = &rest[..k];
        // A `\n` right after a `\r` ends the same line; any other `\r` or `\n` ends one.
        let (returns, newlines) = count_breaks(span);
        if returns == 0 {
            self.breaks += newlines - u64::from(self.after_cr && span.first() == Some(&b'\n'));
            self.after_cr &= k == 0;
        } else {
            for &b in span {
                self.breaks += u64::from(b == b'\r' || (b == b'\n' && !self.after_cr));
                self.after_cr = b == b'\r';
            }
        }
        self.start += k;
        self.base += k as u64;
        self.breaks + 1
    }
}

impl<R: Read> Read for LineTracker<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        // The parser asks for more only once it has used up what it had: what is left
        // unattributed is at most one buffer.
        self.pending.drain(..self.start);
        self.start = 0;
        let n = self.inner.read(buf)?;
        self.pending.extend_from_slice(&buf[..n]);
        Ok(n)
    }
}

/// Reads the records of a CSV input with a header row (the `csv` crate's parser), each with
/// its 1-based file line (the header is line 1 unless blank lines precede it).
pub struct CsvIn<R: Read> {
    reader: csv::Reader<LineTracker<R>>,
    record: csv::ByteRecord,
    /// The header's cells, trimmed; empty for an empty input.
    pub header: Vec<String>,
    /// The line of the current record.
    pub line: u64,
}

impl<R: Read> CsvIn<R> {
    /// Reads the header of `input`.
    pub fn new(input: R) -> Result<Self, CliError> {
        let tracker = LineTracker {
            inner: input,
            pending: Vec::new(),
            start: 0,
            base: 0,
            breaks: 0,
            after_cr: false,
        };
        let reader = csv::ReaderBuilder::new()
            .flexible(false)
            .from_reader(tracker);
        let mut this = Self {
            reader,
            record: csv::ByteRecord::new(),
            header: Vec::new(),
            line: 1,
        };
        let header = this.reader.byte_headers().cloned();
        let header = header.map_err(|e| this.error(e))?;
        let byte = header.position().map_or(0, |p| p.byte());
        this.line = this.reader.get_mut().line_at(byte);
        for cell in &header {
            let text = std::str::from_utf8(cell).map_err(|_| not_utf8(this.line))?;
            this.header.push(text.trim().to_string());
        }
        Ok(this)
    }

    /// Reads the next record; `false` at the end of the input.
    pub fn next_record(&mut self) -> Result<bool, CliError> {
        match self.reader.read_byte_record(&mut self.record) {
            Ok(true) => {
                let byte = self.record.position().map_or(0, |p| p.byte());
                self.line = self.reader.get_mut().line_at(byte);
                Ok(true)
            }
            Ok(false) => Ok(false),
            Err(e) => Err(self.error(e)),
        }
    }

    /// Field `i` of the current record, trimmed.
    #[inline]
    pub fn field(&self, i: usize) -> &[u8] {
        trim(&self.record[i])
    }

    pub fn bytes_read(&self) -> u64 {
        self.reader.position().byte()
    }

    /// The error of the CSV parser `e`, with the line of its position.
    fn error(&mut self, e: csv::Error) -> CliError {
        let line = e
            .position()
            .map(|p| self.reader.get_mut().line_at(p.byte()));
        let at = line.map_or_else(String::new, |l| format!("line {l}: "));
        match e.kind() {
            csv::ErrorKind::UnequalLengths {
                expected_len, len, ..
            } => CliError::Data(format!(
                "{at}malformed CSV: the row has {len} field{} but the header has {expected_len}",
                plural(*len as usize)
            )),
            csv::ErrorKind::Io(io) => CliError::Data(format!("cannot read the input: {io}")),
            _ => CliError::Data(format!("{at}malformed CSV: {e}")),
        }
    }
}

/// Where the rows of an input are, for messages: the lines of a CSV text, or the data rows of a
/// Parquet file (which has no lines).
#[derive(Clone, Debug, Default)]
pub enum Places {
    /// 1-based lines of a CSV text (the header is line 1 unless blank lines precede it).
    #[default]
    Lines,
    /// 1-based data rows of the Parquet file named here (`'path'`).
    ParquetRows(std::sync::Arc<str>),
}

impl Places {
    /// Place `n` as a message starts with it: `line 5`, or `row 4 of the Parquet file 'x'`.
    ///
    /// ```
    /// use seqsmooth_cli::io::Places;
    /// assert_eq!(Places::Lines.at(5), "line 5");
    /// let rows = Places::ParquetRows("'a.parquet'".into());
    /// assert_eq!(rows.at(4), "row 4 of the Parquet file 'a.parquet'");
    /// assert_eq!(rows.short(3), "row 3");
    /// ```
    pub fn at(&self, n: u64) -> String {
        match self {
            Places::Lines => format!("line {n}"),
            Places::ParquetRows(file) => format!("row {n} of the Parquet file {file}"),
        }
    }

    /// Place `n` named a second time in a message: `line 5` or `row 4`.
    pub fn short(&self, n: u64) -> String {
        match self {
            Places::Lines => format!("line {n}"),
            Places::ParquetRows(_) => format!("row {n}"),
        }
    }
}

/// A source of data records with named columns: the CSV reader ([`CsvIn`]) or a Parquet
/// file's rows. Records are read one at a time; the cells of the current one are read by
/// column index (in [`Records::header`]).
pub trait Records {
    /// The column names, in order.
    fn header(&self) -> &[String];

    /// What follows "the header" in a message about a column not found or ambiguous (`""`
    /// for CSV).
    fn header_why(&self) -> String {
        String::new()
    }

    /// Declares the columns the reader will ask for: `numbers` through [`Records::number`]
    /// and [`Records::field`], `text` (an id) through [`Records::field`]. A source that
    /// decodes only what is asked (Parquet) checks their types here. The default accepts any.
    fn select(&mut self, numbers: &[usize], text: Option<usize>) -> Result<(), CliError> {
        let _ = (numbers, text);
        Ok(())
    }

    /// Reads the next record; `false` at the end of the input.
    fn next_record(&mut self) -> Result<bool, CliError>;

    /// The 1-based place of the current record (see [`Records::places`]).
    fn place(&self) -> u64;

    /// What [`Records::place`] counts.
    fn places(&self) -> Places;

    /// The text of cell `i` of the current record (trimmed): as written for CSV, the
    /// shortest round-trip digits of a number ([`write_f64`]) for Parquet.
    fn field(&self, i: usize) -> &[u8];

    /// The number in cell `i` of the current record, in `column`, holding the `what` (`time`,
    /// `value`): a typed error for a missing (empty or null) cell, a non-number or a non-finite
    /// number.
    fn number(&self, i: usize, column: &str, what: &str) -> Result<f64, CliError>;

    /// How much of the input has been read, in bytes (estimated for Parquet), for the progress
    /// display.
    fn bytes_read(&self) -> u64;

    /// How the id column's values are typed, for an output that keeps types (Parquet).
    fn id_type(&self) -> IdType {
        IdType::Text
    }
}

impl<T: Records + ?Sized> Records for Box<T> {
    fn header(&self) -> &[String] {
        (**self).header()
    }
    fn header_why(&self) -> String {
        (**self).header_why()
    }
    fn select(&mut self, numbers: &[usize], text: Option<usize>) -> Result<(), CliError> {
        (**self).select(numbers, text)
    }
    fn next_record(&mut self) -> Result<bool, CliError> {
        (**self).next_record()
    }
    fn place(&self) -> u64 {
        (**self).place()
    }
    fn places(&self) -> Places {
        (**self).places()
    }
    fn field(&self, i: usize) -> &[u8] {
        (**self).field(i)
    }
    fn number(&self, i: usize, column: &str, what: &str) -> Result<f64, CliError> {
        (**self).number(i, column, what)
    }
    fn bytes_read(&self) -> u64 {
        (**self).bytes_read()
    }
    fn id_type(&self) -> IdType {
        (**self).id_type()
    }
}

/// The type of an id column's values.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum IdType {
    /// Text (CSV, and Parquet strings and dictionaries of strings).
    #[default]
    Text,
    /// Signed integers (Parquet), written as their decimal text in CSV.
    Signed,
    /// Unsigned integers (Parquet), written as their decimal text in CSV.
    Unsigned,
}

impl<R: Read> Records for CsvIn<R> {
    fn header(&self) -> &[String] {
        &self.header
    }
    fn next_record(&mut self) -> Result<bool, CliError> {
        CsvIn::next_record(self)
    }
    fn place(&self) -> u64 {
        self.line
    }
    fn places(&self) -> Places {
        Places::Lines
    }
    #[inline]
    fn field(&self, i: usize) -> &[u8] {
        CsvIn::field(self, i)
    }
    #[inline]
    fn number(&self, i: usize, column: &str, what: &str) -> Result<f64, CliError> {
        parse_cell(CsvIn::field(self, i), self.line, column, what)
    }
    fn bytes_read(&self) -> u64 {
        CsvIn::bytes_read(self)
    }
}

/// The error of a row on `line` that is not UTF-8 text.
pub fn not_utf8(line: u64) -> CliError {
    CliError::Data(format!(
        "line {line}: malformed CSV: the row is not valid UTF-8"
    ))
}

/// The file `path` names, or `None` for standard input or output (`None` or `-`).
pub fn named(path: Option<&Path>) -> Option<&Path> {
    path.filter(|p| p.as_os_str() != "-")
}

/// Whether `path` names a Parquet file: its extension is `.parquet`, in any case. Standard
/// input and output (`None`, `-`) are CSV.
///
/// ```
/// use seqsmooth_cli::io::parquet::is_parquet;
/// use std::path::Path;
/// assert!(is_parquet(Some(Path::new("a/b.PARQUET"))));
/// assert!(!is_parquet(Some(Path::new("b.csv"))));
/// assert!(!is_parquet(None));
/// ```
pub fn is_parquet(path: Option<&Path>) -> bool {
    named(path)
        .and_then(Path::extension)
        .is_some_and(|e| e.eq_ignore_ascii_case("parquet"))
}

/// The refusal of a Parquet file by a command that reads and writes CSV only.
fn csv_only(p: &Path) -> CliError {
    CliError::Usage(format!(
        "'{}' is a Parquet file: only `seqsmooth filter` reads and writes Parquet; this \
         command takes CSV",
        p.display()
    ))
}

/// Opens the input: a file, or standard input for `None` or `-`. A `.parquet` file is
/// refused: the commands that call this read CSV (`filter` reads Parquet itself).
pub fn open_input(path: Option<&Path>) -> Result<Box<dyn Read + Send>, CliError> {
    match named(path) {
        Some(p) if is_parquet(Some(p)) => Err(csv_only(p)),
        Some(p) => {
            let file = File::open(p).map_err(|e| {
                CliError::Data(format!("cannot open input file '{}': {e}", p.display()))
            })?;
            // The CSV reader buffers; no BufReader needed.
            Ok(Box::new(file))
        }
        // Unlocked, so that another thread may read it; the CSV reader reads large blocks.
        None => Ok(Box::new(io::stdin())),
    }
}

/// The name of an input in messages: `'path'` or `standard input`.
pub fn input_name(path: Option<&Path>) -> String {
    named(path).map_or_else(|| "standard input".into(), |p| format!("'{}'", p.display()))
}

/// The size of the input file, for the progress bar; `None` for standard input or anything
/// but a regular file.
pub fn input_size(path: Option<&Path>) -> Option<u64> {
    let meta = std::fs::metadata(named(path)?).ok()?;
    meta.is_file().then_some(meta.len())
}
