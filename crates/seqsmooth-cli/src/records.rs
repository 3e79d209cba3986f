//! The CSV records of `seqsmooth filter`'s input, each with its 1-based file line.
//!
//! The records are split by the `csv` crate's rules, with the options the command used it with
//! (the tests compare the two): `,` between fields; a field that starts with `"` is quoted, a
//! doubled `"` inside it is one `"`, and whatever follows its closing quote up to the next `,`
//! or line end is part of the field; `\n`, `\r\n` or a lone `\r` ends a record; blank lines are
//! skipped; a UTF-8 byte-order mark at the start of the input is dropped; an unterminated quote
//! runs to the end of the input.
//!
//! Records without a `"` (nearly all of them) are split where they lie in the read buffer, with
//! no copy; a record with one is unquoted into a side buffer. Lines are counted as the bytes
//! are consumed (`\r\n` counts once; line ends inside quoted fields count too), so the line of
//! every record is known at no extra cost.

use std::io::{self, Read};

/// The initial size of the read buffer; it doubles while a record does not fit.
const BUFFER: usize = 1 << 18;

/// The bytes that end an unquoted field (`,`, `\r`, `\n`) or may start a quoted one (`"`).
const SPECIAL: [bool; 256] = {
    let mut t = [false; 256];
    t[b',' as usize] = true;
    t[b'"' as usize] = true;
    t[b'\r' as usize] = true;
    t[b'\n' as usize] = true;
    t
};

/// The first of `,`, `"`, `\r` and `\n` in `bytes` from `from` on. Eight bytes at a time: all
/// four are below `-` (0x2D), and so are few bytes of numbers and names (a space, `+`), which
/// are passed over one by one.
fn find_special(bytes: &[u8], mut from: usize) -> Option<usize> {
    const ONES: u64 = 0x0101_0101_0101_0101;
    while let Some(chunk) = bytes.get(from..).and_then(<[u8]>::first_chunk::<8>) {
        let v = u64::from_le_bytes(*chunk);
        // The lowest flagged byte is exactly the first byte below 0x2D (a borrow only reaches
        // the bytes above it).
        let below = v.wrapping_sub(ONES * 0x2D) & !v & (ONES * 0x80);
        if below == 0 {
            from += 8;
            continue;
        }
        let at = from + (below.trailing_zeros() / 8) as usize;
        if SPECIAL[bytes[at] as usize] {
            return Some(at);
        }
        from = at + 1;
    }
    let tail = bytes.get(from..)?;
    tail.iter()
        .position(|&b| SPECIAL[b as usize])
        .map(|k| from + k)
}

/// How splitting a record at the start of the unconsumed bytes went.
enum Split {
    /// The record ends at this offset of the buffer (its terminator, or the end of the input).
    Done(usize),
    /// The record has a quote: it needs the unquoting splitter.
    Quoted,
    /// The record runs past the bytes read so far: read more and split it again.
    More,
}

/// The state of the unquoting splitter (the `csv` crate's states, less those its options
/// never reach).
#[derive(Clone, Copy, PartialEq, Eq)]
enum State {
    /// At the start of a field.
    StartField,
    /// In an unquoted field (or after a quoted part).
    InField,
    /// Inside quotes.
    InQuotes,
    /// Right after a `"` inside quotes: a second `"` is a literal one, anything else ends the
    /// quotes.
    AfterQuote,
}

/// Reads the CSV records of an input one at a time.
pub struct Records<R: Read> {
    inner: R,
    /// The read buffer: `buf[pos..filled]` is read and not yet consumed.
    buf: Vec<u8>,
    pos: usize,
    filled: usize,
    /// Whether the input has ended.
    eof: bool,
    /// Whether a leading byte-order mark has been looked for.
    bom_checked: bool,
    /// Bytes read from the input so far.
    bytes_read: u64,
    /// Line ends (`\n`, `\r\n` or a lone `\r`) consumed so far.
    breaks: u64,
    /// Whether the last byte consumed is `\r` (so a `\n` next ends no new line).
    after_cr: bool,
    /// The current record's fields: ranges of `buf`, or of `unquoted` when `quoted`.
    fields: Vec<(usize, usize)>,
    unquoted: Vec<u8>,
    quoted: bool,
}

impl<R: Read> Records<R> {
    /// Reads the records of `inner`.
    pub fn new(inner: R) -> Self {
        Self {
            inner,
            buf: vec![0; BUFFER],
            pos: 0,
            filled: 0,
            eof: false,
            bom_checked: false,
            bytes_read: 0,
            breaks: 0,
            after_cr: false,
            fields: Vec::new(),
            unquoted: Vec::new(),
            quoted: false,
        }
    }

    /// The number of bytes read from the input so far.
    pub fn bytes_read(&self) -> u64 {
        self.bytes_read
    }

    /// The number of fields of the current record.
    pub fn len(&self) -> usize {
        self.fields.len()
    }

    /// Field `i` of the current record (unquoted); panics past [`Records::len`].
    pub fn field(&self, i: usize) -> &[u8] {
        let (a, b) = self.fields[i];
        if self.quoted {
            &self.unquoted[a..b]
        } else {
            &self.buf[a..b]
        }
    }

    /// Reads the next record, which [`Records::field`] then gives: its 1-based line, or `None`
    /// at the end of the input.
    pub fn next_record(&mut self) -> io::Result<Option<u64>> {
        if !self.skip_line_ends()? {
            return Ok(None);
        }
        let line = self.breaks + 1;
        loop {
            let split = match self.split_plain() {
                Split::Quoted => self.split_quoted(),
                other => other,
            };
            match split {
                Split::Done(end) => {
                    self.pos = end;
                    self.after_cr = false;
                    return Ok(Some(line));
                }
                Split::More | Split::Quoted => self.refill()?,
            }
        }
    }

    /// Consumes the line ends before the next record, counting them; `false` at the end of
    /// the input.
    fn skip_line_ends(&mut self) -> io::Result<bool> {
        loop {
            while self.pos < self.filled {
                match self.buf[self.pos] {
                    b'\r' => {
                        self.breaks += 1;
                        self.after_cr = true;
                    }
                    b'\n' => {
                        self.breaks += u64::from(!self.after_cr);
                        self.after_cr = false;
                    }
                    _ => return Ok(true),
                }
                self.pos += 1;
            }
            if self.eof {
                return Ok(false);
            }
            self.refill()?;
        }
    }

    /// Splits a record without quotes where it lies in the buffer.
    fn split_plain(&mut self) -> Split {
        self.fields.clear();
        self.quoted = false;
        let bytes = &self.buf[..self.filled];
        let mut start = self.pos;
        loop {
            let Some(end) = find_special(bytes, start) else {
                if !self.eof {
                    return Split::More;
                }
                self.fields.push((start, self.filled));
                return Split::Done(self.filled);
            };
            match bytes[end] {
                b'"' => return Split::Quoted,
                b',' => {
                    self.fields.push((start, end));
                    start = end + 1;
                }
                _ => {
                    self.fields.push((start, end));
                    return Split::Done(end);
                }
            }
        }
    }

    /// Splits a record with quotes, unquoting its fields into the side buffer, and counts the
    /// line ends inside quotes.
    fn split_quoted(&mut self) -> Split {
        self.fields.clear();
        self.unquoted.clear();
        self.quoted = true;
        let mut state = State::StartField;
        let mut start = 0;
        let (mut breaks, mut after_cr) = (0u64, false);
        let mut i = self.pos;
        while i < self.filled {
            let b = self.buf[i];
            let ends_field = match state {
                State::InQuotes => {
                    if b == b'"' {
                        state = State::AfterQuote;
                    } else {
                        breaks += u64::from(b == b'\r' || (b == b'\n' && !after_cr));
                        self.unquoted.push(b);
                    }
                    false
                }
                State::StartField if b == b'"' => {
                    state = State::InQuotes;
                    false
                }
                State::AfterQuote if b == b'"' => {
                    state = State::InQuotes;
                    self.unquoted.push(b);
                    false
                }
                _ => matches!(b, b',' | b'\r' | b'\n'),
            };
            after_cr = b == b'\r';
            if ends_field {
                self.fields.push((start, self.unquoted.len()));
                start = self.unquoted.len();
                if b != b',' {
                    self.breaks += breaks;
                    return Split::Done(i);
                }
                state = State::StartField;
            } else if matches!(state, State::StartField | State::AfterQuote) && b != b'"' {
                state = State::InField;
                self.unquoted.push(b);
            } else if state == State::InField {
                self.unquoted.push(b);
            }
            i += 1;
        }
        if !self.eof {
            return Split::More;
        }
        self.fields.push((start, self.unquoted.len()));
        self.breaks += breaks;
        Split::Done(self.filled)
    }

    /// Moves the unconsumed bytes to the front of the buffer (doubling it when they fill it)
    /// and reads until it is full or the input ends. The first time, a byte-order mark is
    /// dropped (once 3 bytes are read).
    fn refill(&mut self) -> io::Result<()> {
        self.buf.copy_within(self.pos..self.filled, 0);
        self.filled -= self.pos;
        self.pos = 0;
        loop {
            if self.filled == self.buf.len() {
                self.buf.resize(2 * self.buf.len(), 0);
            }
            while self.filled < self.buf.len() && !self.eof {
                match self.inner.read(&mut self.buf[self.filled..]) {
                    Ok(0) => self.eof = true,
                    Ok(n) => {
                        self.filled += n;
                        self.bytes_read += n as u64;
                    }
                    Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                    Err(e) => return Err(e),
                }
            }
            if self.bom_checked {
                return Ok(());
            }
            if self.filled >= 3 || self.eof {
                self.bom_checked = true;
                if self.buf[..self.filled].starts_with(b"\xef\xbb\xbf") {
                    self.pos = 3;
                }
                return Ok(());
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::LineTracker;

    /// The records of `text` and their lines by this reader, with a read buffer of `size`
    /// bytes (reads of at most 3 bytes, to exercise refills and growth).
    fn ours(text: &[u8], size: usize) -> Vec<(u64, Vec<Vec<u8>>)> {
        struct Trickle<'a>(&'a [u8]);
        impl Read for Trickle<'_> {
            fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
                let n = buf.len().min(self.0.len()).min(3);
                buf[..n].copy_from_slice(&self.0[..n]);
                self.0 = &self.0[n..];
                Ok(n)
            }
        }
        let mut r = Records::new(Trickle(text));
        r.buf = vec![0; size];
        let mut out = Vec::new();
        while let Some(line) = r.next_record().unwrap() {
            out.push((line, (0..r.len()).map(|i| r.field(i).to_vec()).collect()));
        }
        assert_eq!(r.bytes_read(), text.len() as u64);
        out
    }

    /// The records of `text` by the `csv` crate with the command's former options, and their
    /// lines by the former line tracker.
    fn theirs(text: &[u8]) -> Vec<(u64, Vec<Vec<u8>>)> {
        let mut reader = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .from_reader(LineTracker::new(text));
        let mut record = csv::ByteRecord::new();
        let mut out = Vec::new();
        while reader.read_byte_record(&mut record).unwrap() {
            let byte = record.position().map_or(0, |p| p.byte());
            let line = reader.get_mut().line_at(byte);
            out.push((line, record.iter().map(<[u8]>::to_vec).collect()));
        }
        out
    }

    #[test]
    fn fields_lines_quotes_and_blank_lines() {
        let text = b"\xef\xbb\xbft,y\r\n\r\n0,1\n\"a,\"\"b\"\"\nc\",2\rx\"y,\"q\"z,\"\"\n\n,\n1,2";
        let got = ours(text, 4);
        let want: Vec<(u64, Vec<Vec<u8>>)> = vec![
            (1, vec![b"t".to_vec(), b"y".to_vec()]),
            (3, vec![b"0".to_vec(), b"1".to_vec()]),
            (4, vec![b"a,\"b\"\nc".to_vec(), b"2".to_vec()]),
            (6, vec![b"x\"y".to_vec(), b"qz".to_vec(), b"".to_vec()]),
            (8, vec![b"".to_vec(), b"".to_vec()]),
            (9, vec![b"1".to_vec(), b"2".to_vec()]),
        ];
        assert_eq!(got, want);
        assert_eq!(theirs(text), want);
        assert!(ours(b"", 4).is_empty());
        assert!(ours(b"\r\n\n\r", 4).is_empty());
        assert_eq!(ours(b"\"abc", 4), [(1, vec![b"abc".to_vec()])]);
    }

    #[test]
    fn agrees_with_the_csv_crate_on_random_inputs() {
        let alphabet: [&[u8]; 10] = [
            b"a",
            b"1",
            b".",
            b",",
            b",",
            b"\"",
            b"\r",
            b"\n",
            b" ",
            "é".as_bytes(),
        ];
        let mut state = 0x9E37_79B9_7F4A_7C15_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for case in 0..20_000 {
            let len = next() % 40;
            let mut text = Vec::new();
            if case % 10 == 0 {
                text.extend_from_slice(b"\xef\xbb\xbf");
            }
            for _ in 0..len {
                text.extend_from_slice(alphabet[(next() % 10) as usize]);
            }
            let mut want = theirs(&text);
            // After a byte-order mark the former tracker counted no blank line before the
            // first record (it took the record to start at the mark); this reader does.
            if text.starts_with(b"\xef\xbb\xbf") {
                let blank = text[3..].iter().take_while(|b| b"\r\n".contains(b));
                let mut after_cr = false;
                let breaks: u64 = blank
                    .map(|&b| {
                        let new_line = b == b'\r' || !after_cr;
                        after_cr = b == b'\r';
                        u64::from(new_line)
                    })
                    .sum();
                if let Some(first) = want.first_mut() {
                    first.0 += breaks;
                }
            }
            for size in [1, 5, 64, BUFFER] {
                assert_eq!(
                    ours(&text, size),
                    want,
                    "{:?}",
                    String::from_utf8_lossy(&text)
                );
            }
        }
    }

    #[test]
    fn finds_specials_past_spaces_and_signs() {
        let text = b"12345678 +-abcdefgh,ijk";
        assert_eq!(find_special(text, 0), Some(19));
        assert_eq!(find_special(text, 20), None);
        assert_eq!(find_special(b"a\"", 0), Some(1));
        assert_eq!(find_special(b"", 0), None);
    }
}
