//! The CLI's CSV layer (`seqsmooth_cli::io`): the reader (`CsvIn`: records, 1-based lines,
//! trimmed cells), number cells with line and column in their errors, column lookup, the
//! writer's quoting (`csv_field` reads back as the same cell) and message quoting (`shown`).
//!
//! Input: one byte choosing a column name to look up, then the CSV text.

use super::check;
use super::number::round_trip;
use seqsmooth_cli::io::{csv_field, find_column, parse_cell, shown, trim, CsvIn};

/// The cell `cell` written by `csv_field` reads back as one record holding just `cell`.
fn quoting(cell: &[u8]) {
    let mut line = csv_field(cell);
    line.push(b'\n');
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .from_reader(&line[..]);
    let mut record = csv::ByteRecord::new();
    match reader.read_byte_record(&mut record) {
        // An empty cell is an empty line, which the reader skips.
        Ok(false) => assert!(cell.is_empty(), "{line:?} reads as nothing"),
        Ok(true) => {
            assert_eq!(record.len(), 1, "{line:?} reads as {record:?}");
            assert_eq!(&record[0], cell, "{line:?} reads as {record:?}");
        }
        Err(e) => panic!("{line:?} does not read back: {e}"),
    }
}

/// A message's quotation of `cell`: no control characters; a cell of more than 64 characters
/// cut, with its length in bytes.
fn quotation(cell: &[u8]) {
    let text = shown(cell);
    assert!(
        !text.chars().any(char::is_control),
        "shown({cell:?}) = {text:?}"
    );
    if String::from_utf8_lossy(cell).chars().count() > 64 {
        let tail = format!("… ({} bytes)", cell.len());
        assert!(text.ends_with(&tail), "shown({cell:?}) = {text:?}");
    }
}

pub fn run(data: &[u8]) {
    let (pick, text) = data.split_at(data.len().min(1));
    let breaks = text.iter().filter(|&&b| b == b'\n' || b == b'\r').count() as u64;
    let mut csv = match CsvIn::new(text) {
        Ok(csv) => csv,
        Err(e) => return check::error_message(&e),
    };
    let header = csv.header.clone();
    for h in &header {
        assert_eq!(
            h.as_bytes(),
            trim(h.as_bytes()),
            "an untrimmed header cell {h:?}"
        );
        quotation(h.as_bytes());
    }
    // Look up a column the header has, or one it has not.
    let name = match pick.first() {
        Some(&k) if !header.is_empty() && k < 128 => header[usize::from(k) % header.len()].clone(),
        _ => "t".to_string(),
    };
    match find_column(&header, &name, "") {
        Ok(i) => assert_eq!(header[i], name),
        Err(e) => {
            check::error_message(&e);
            assert!(header.iter().filter(|h| **h == name).count() != 1);
        }
    }
    let mut last = csv.line;
    assert!(last >= 1 && last <= breaks + 1, "header line {last}");
    loop {
        match csv.next_record() {
            Ok(false) => break,
            Ok(true) => {
                let line = csv.line;
                assert!(line > last, "record line {line} after line {last}");
                assert!(
                    line <= breaks + 1,
                    "line {line} in a text of {breaks} line breaks"
                );
                last = line;
                for (i, column) in header.iter().enumerate() {
                    let cell = csv.field(i);
                    assert_eq!(cell, trim(cell));
                    quoting(cell);
                    quotation(cell);
                    match parse_cell(cell, line, column, "value") {
                        Ok(v) => round_trip(v),
                        Err(e) => {
                            check::error_message(&e);
                            let at = format!("line {line}, column '");
                            assert!(e.to_string().starts_with(&at), "{e}");
                        }
                    }
                }
            }
            Err(e) => {
                check::error_message(&e);
                break;
            }
        }
    }
}
