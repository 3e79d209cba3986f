//! End-to-end tests of `seqsmooth filter` on Parquet files: in, out, and both.
//!
//! The oracle is the command on the same data as CSV: the Parquet rows go through the same
//! reader checks, chunks and filters, so every output number must equal the CSV output's bit
//! for bit (the CSV's shortest round-trip digits parse back to the same double). Each case
//! runs CSV → CSV (the reference), Parquet → Parquet, Parquet → CSV and CSV → Parquet. The
//! errors name the file, the column and the data row, and a failed run leaves an existing
//! output file as it was.

mod common;
use common::{run, run_at};

use arrow::array::{
    Array, ArrayRef, AsArray, BooleanArray, Date32Array, DictionaryArray, Float32Array,
    Float64Array, Int64Array, LargeStringArray, ListArray, StringArray, TimestampMicrosecondArray,
    TimestampNanosecondArray,
};
use arrow::datatypes::{DataType, Field, Float64Type, Int32Type, Int64Type, Schema};
use arrow::record_batch::RecordBatch;
use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
use parquet::arrow::ArrowWriter;
use parquet::file::properties::WriterProperties;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// xorshift64*: deterministic test data.
struct Rng(u64);

impl Rng {
    fn uniform(&mut self) -> f64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        (x.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Test data: irregular Unix-epoch times in microseconds (about 1.7e9 s), values, and the
/// series of each row (ids `s00`… and one that needs CSV quoting).
struct Data {
    micros: Vec<i64>,
    y: Vec<f64>,
    ids: Vec<String>,
}

impl Data {
    /// `n` rows over `series` series (1: no ids needed), interleaved at random.
    fn new(n: usize, series: usize, seed: u64) -> Self {
        let mut rng = Rng(seed);
        let mut us = 1_700_000_000_000_000i64;
        let (mut micros, mut y, mut ids) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..n {
            us += 200_000 + (rng.uniform() * 1_600_000.0) as i64;
            micros.push(us);
            let x = i as f64 / 50.0;
            y.push(10.0 + 3.0 * x.sin() + 0.2 * x + (rng.uniform() - 0.5));
            let s = (rng.uniform() * series as f64) as usize;
            ids.push(if s == 7 {
                "a,\"b\"".to_string()
            } else {
                format!("s{s:02}")
            });
        }
        Data { micros, y, ids }
    }

    /// The times in seconds.
    fn t(&self) -> Vec<f64> {
        self.micros.iter().map(|&u| u as f64 / 1e6).collect()
    }
}

/// A CSV cell of an id, quoted where needed.
fn csv_id(id: &str) -> String {
    if id.contains([',', '"']) {
        format!("\"{}\"", id.replace('"', "\"\""))
    } else {
        id.to_string()
    }
}

/// The CSV text of columns `id` (if given), `t`, `y`: the cells of each row, `None` empty.
fn csv_text(ids: Option<&[String]>, t: &[f64], y: &[Option<String>]) -> String {
    let mut out = String::from(if ids.is_some() { "id,t,y\n" } else { "t,y\n" });
    for i in 0..t.len() {
        if let Some(ids) = ids {
            out += &csv_id(&ids[i]);
            out.push(',');
        }
        out += &format!("{},{}\n", t[i], y[i].as_deref().unwrap_or(""));
    }
    out
}

/// Writes `columns` as a Parquet file at `path`, in row groups of 1000 rows.
fn write_parquet(path: &Path, columns: Vec<(&str, ArrayRef)>) {
    let fields: Vec<Field> = columns
        .iter()
        .map(|(n, a)| Field::new(*n, a.data_type().clone(), true))
        .collect();
    let schema = Arc::new(Schema::new(fields));
    let batch = RecordBatch::try_new(schema.clone(), columns.into_iter().map(|c| c.1).collect())
        .expect("batch");
    let props = WriterProperties::builder()
        .set_max_row_group_row_count(Some(1000))
        .build();
    let file = std::fs::File::create(path).expect("create parquet");
    let mut w = ArrowWriter::try_new(file, schema, Some(props)).expect("writer");
    w.write(&batch).expect("write");
    w.close().expect("close");
}

/// A table read back: its column names and, per column, its cells (numbers as bits, null as
/// `None`; ids as text).
#[derive(Debug, PartialEq)]
struct Table {
    names: Vec<String>,
    columns: Vec<Vec<Option<String>>>,
}

/// A number cell as compared: its bits.
fn bits(v: f64) -> Option<String> {
    Some(format!("{:016x}", v.to_bits()))
}

/// Reads a Parquet output back; the column types are checked as the command writes them.
fn read_parquet(path: &Path, id: Option<&DataType>) -> Table {
    let file = std::fs::File::open(path).expect("open output");
    let reader = ParquetRecordBatchReaderBuilder::try_new(file)
        .expect("parquet output")
        .build()
        .expect("reader");
    let mut names = Vec::new();
    let mut columns: Vec<Vec<Option<String>>> = Vec::new();
    for batch in reader {
        let batch = batch.expect("batch");
        if names.is_empty() {
            names = batch
                .schema()
                .fields()
                .iter()
                .map(|f| f.name().clone())
                .collect();
            columns = vec![Vec::new(); names.len()];
        }
        for (k, array) in batch.columns().iter().enumerate() {
            let expected = match (k, id) {
                (0, Some(t)) => t.clone(),
                _ => DataType::Float64,
            };
            assert_eq!(array.data_type(), &expected, "column {}", names[k]);
            for i in 0..array.len() {
                let cell = if array.is_null(i) {
                    None
                } else {
                    match array.data_type() {
                        DataType::Float64 => bits(array.as_primitive::<Float64Type>().value(i)),
                        DataType::Int64 => {
                            Some(array.as_primitive::<Int64Type>().value(i).to_string())
                        }
                        _ => Some(array.as_string::<i32>().value(i).to_string()),
                    }
                };
                columns[k].push(cell);
            }
        }
    }
    Table { names, columns }
}

/// Asserts the tables are the same; the message names the first cell that differs.
fn same(got: &Table, want: &Table, what: &str) {
    assert_eq!(got.names, want.names, "{what}: column names");
    for (k, (g, w)) in got.columns.iter().zip(&want.columns).enumerate() {
        assert_eq!(g.len(), w.len(), "{what}: rows of column {}", want.names[k]);
        if let Some(i) = (0..g.len()).find(|&i| g[i] != w[i]) {
            panic!(
                "{what}: column {} row {}: {:?} instead of {:?}",
                want.names[k],
                i + 1,
                g[i],
                w[i]
            );
        }
    }
}

/// Reads a CSV output: the first column is the id when `id`, the others numbers.
fn read_csv(text: &str, id: bool) -> Table {
    let mut reader = csv::ReaderBuilder::new().from_reader(text.as_bytes());
    let names: Vec<String> = reader
        .headers()
        .expect("header")
        .iter()
        .map(String::from)
        .collect();
    let mut columns = vec![Vec::new(); names.len()];
    for record in reader.records() {
        let record = record.expect("record");
        for (k, cell) in record.iter().enumerate() {
            columns[k].push(match (k, cell) {
                (0, c) if id => Some(c.to_string()),
                (_, "") => None,
                (_, c) => bits(c.parse::<f64>().expect("number")),
            });
        }
    }
    Table { names, columns }
}

/// A scratch directory.
fn scratch() -> tempfile::TempDir {
    tempfile::tempdir().expect("temp dir")
}

/// `dir/name` as a string argument.
fn at(dir: &Path, name: &str) -> String {
    dir.join(name).to_str().expect("utf-8 path").to_string()
}

/// Runs `seqsmooth filter input args… [-o output]` and asserts success; the standard output.
fn filter_ok(input: &str, args: &[&str], output: Option<&str>) -> String {
    let mut all = vec!["filter", input];
    all.extend_from_slice(args);
    if let Some(o) = output {
        all.extend_from_slice(&["-o", o]);
    }
    let o = run(&all, "");
    assert_eq!(o.code, 0, "seqsmooth {all:?} failed: {}", o.stderr);
    assert_eq!(o.stderr, "", "seqsmooth {all:?} wrote to stderr");
    o.stdout
}

/// Runs `args` on the CSV `csv` and on the Parquet file `parquet` (the same data), all four
/// ways, and asserts the outputs are the same cell for cell (numbers bit for bit). `id`: the
/// Parquet output's id column type. Returns the reference table.
fn same_four_ways(
    dir: &Path,
    csv: &str,
    parquet: &str,
    args: &[&str],
    id: Option<DataType>,
) -> Table {
    let csv_in = at(dir, "in.csv");
    std::fs::write(&csv_in, csv).expect("write csv");
    let reference_text = filter_ok(&csv_in, args, None);
    let reference = read_csv(&reference_text, id.is_some());
    assert!(
        reference.columns[0].len() > 100,
        "too few rows: {reference_text:.300}"
    );
    // Parquet → Parquet.
    let out = at(dir, "out.parquet");
    assert_eq!(filter_ok(parquet, args, Some(&out)), "");
    same(
        &read_parquet(Path::new(&out), id.as_ref()),
        &reference,
        "parquet -> parquet",
    );
    // Parquet → CSV (standard output and a file).
    let text = filter_ok(parquet, args, None);
    same(&read_csv(&text, id.is_some()), &reference, "parquet -> csv");
    let out_csv = at(dir, "out.csv");
    filter_ok(parquet, args, Some(&out_csv));
    let file_text = std::fs::read_to_string(&out_csv).expect("csv output");
    same(
        &read_csv(&file_text, id.is_some()),
        &reference,
        "parquet -> csv file",
    );
    // CSV → Parquet (the extension in capitals).
    let out2 = at(dir, "out2.PARQUET");
    filter_ok(&csv_in, args, Some(&out2));
    let text_ids = id.as_ref().map(|_| DataType::Utf8);
    // The ids of a CSV input are text (integer ids of the Parquet input too: their decimal text).
    let back = read_parquet(Path::new(&out2), text_ids.as_ref());
    same(&back, &reference, "csv -> parquet");
    reference
}

/// The single-series data as CSV and as Parquet (Float64 times in seconds).
fn single(dir: &Path, n: usize, seed: u64) -> (Data, String, String) {
    let d = Data::new(n, 1, seed);
    let t = d.t();
    let y: Vec<Option<String>> = d.y.iter().map(|v| Some(format!("{v}"))).collect();
    let csv = csv_text(None, &t, &y);
    let path = at(dir, "in.parquet");
    write_parquet(
        Path::new(&path),
        vec![
            ("t", Arc::new(Float64Array::from(t.clone())) as ArrayRef),
            ("y", Arc::new(Float64Array::from(d.y.clone()))),
        ],
    );
    (d, csv, path)
}

/// The 25-series data as CSV and as Parquet (string ids).
fn many(dir: &Path, n: usize, seed: u64) -> (Data, String, String) {
    let d = Data::new(n, 25, seed);
    let t = d.t();
    let y: Vec<Option<String>> = d.y.iter().map(|v| Some(format!("{v}"))).collect();
    let csv = csv_text(Some(&d.ids), &t, &y);
    let path = at(dir, "in_ids.parquet");
    write_parquet(
        Path::new(&path),
        vec![
            ("id", Arc::new(StringArray::from(d.ids.clone())) as ArrayRef),
            ("t", Arc::new(Float64Array::from(t.clone()))),
            ("y", Arc::new(Float64Array::from(d.y.clone()))),
        ],
    );
    (d, csv, path)
}

#[test]
fn fading_with_sigma_is_the_csv_output_bit_for_bit() {
    let dir = scratch();
    let (_, csv, pq) = single(dir.path(), 3000, 1);
    let args = [
        "--kind",
        "fading",
        "--degree",
        "2",
        "--theta",
        "0.9",
        "--sigma",
        "0.3",
        "--chunk-rows",
        "700",
    ];
    let table = same_four_ways(dir.path(), &csv, &pq, &args, None);
    assert_eq!(table.names, ["t", "y", "d0", "d1", "d2", "s0", "s1", "s2"]);
}

#[test]
fn expanding_with_ids_is_the_csv_output_bit_for_bit() {
    let dir = scratch();
    let (_, csv, pq) = many(dir.path(), 4000, 2);
    let args = [
        "--kind",
        "expanding",
        "--degree",
        "1",
        "--id-col",
        "id",
        "--chunk-rows",
        "900",
    ];
    let table = same_four_ways(dir.path(), &csv, &pq, &args, Some(DataType::Utf8));
    assert_eq!(table.names, ["id", "t", "y", "d0", "d1"]);
    // The quoted id came back whole, in CSV and in Parquet alike.
    assert!(table.columns[0].contains(&Some("a,\"b\"".to_string())));
    let ids: std::collections::HashSet<_> = table.columns[0].iter().collect();
    assert_eq!(ids.len(), 25);
    // The ids as a dictionary of strings, and as large strings: the same output, ids as text.
    let d = Data::new(4000, 25, 2);
    let dictionary: DictionaryArray<Int32Type> = d.ids.iter().map(String::as_str).collect();
    let large = LargeStringArray::from(d.ids.clone());
    for (name, ids) in [
        ("dict.parquet", Arc::new(dictionary) as ArrayRef),
        ("large.parquet", Arc::new(large)),
    ] {
        let path = at(dir.path(), name);
        write_parquet(
            Path::new(&path),
            vec![
                ("id", ids),
                ("t", Arc::new(Float64Array::from(d.t()))),
                ("y", Arc::new(Float64Array::from(d.y.clone()))),
            ],
        );
        let out = at(dir.path(), "out_dict.parquet");
        filter_ok(&path, &args, Some(&out));
        same(
            &read_parquet(Path::new(&out), Some(&DataType::Utf8)),
            &table,
            name,
        );
    }
}

#[test]
fn fixed_with_and_without_ids_is_the_csv_output_bit_for_bit() {
    let dir = scratch();
    let (_, csv, pq) = many(dir.path(), 3000, 3);
    let args = [
        "--kind", "fixed", "--degree", "2", "--window", "12", "--id-col", "id",
    ];
    let table = same_four_ways(dir.path(), &csv, &pq, &args, Some(DataType::Utf8));
    assert_eq!(table.names, ["id", "t", "y", "d0", "d1", "d2", "window"]);
    // The first rows of each series have no estimate: null in Parquet, as empty in CSV.
    assert!(table.columns[3].iter().any(Option::is_none));
    let (_, csv, pq) = single(dir.path(), 2000, 4);
    let args = [
        "--kind", "fixed", "--degree", "1", "--window", "20", "--engine", "exact",
    ];
    same_four_ways(dir.path(), &csv, &pq, &args, None);
}

#[test]
fn auto_is_the_csv_output_bit_for_bit() {
    let dir = scratch();
    let (_, csv, pq) = single(dir.path(), 2500, 5);
    let args = [
        "--kind",
        "auto",
        "--degree",
        "2",
        "--theta",
        "0.95",
        "--chunk-rows",
        "600",
    ];
    let table = same_four_ways(dir.path(), &csv, &pq, &args, None);
    assert_eq!(
        table.names,
        ["t", "y", "d0", "d1", "d2", "s0", "s1", "s2", "noise", "outlier", "misfit", "bias"]
    );
    let (_, csv, pq) = many(dir.path(), 3000, 6);
    let args = [
        "--kind", "auto", "--degree", "1", "--theta", "0.9", "--id-col", "id",
    ];
    same_four_ways(dir.path(), &csv, &pq, &args, Some(DataType::Utf8));
}

#[test]
fn float32_and_int64_values_and_int64_ids() {
    let dir = scratch();
    let d = Data::new(3000, 25, 7);
    let t = d.t();
    // Float32 values: the CSV holds the doubles they widen to.
    let y32: Vec<f32> = d.y.iter().map(|&v| v as f32).collect();
    let cells: Vec<Option<String>> = y32.iter().map(|&v| Some(format!("{}", v as f64))).collect();
    let pq = at(dir.path(), "f32.parquet");
    write_parquet(
        Path::new(&pq),
        vec![
            ("t", Arc::new(Float64Array::from(t.clone())) as ArrayRef),
            ("y", Arc::new(Float32Array::from(y32))),
        ],
    );
    let args = [
        "--kind", "fading", "--degree", "1", "--theta", "0.8", "--sigma", "1",
    ];
    same_four_ways(dir.path(), &csv_text(None, &t, &cells), &pq, &args, None);
    // Int64 values (millis of the value) and Int64 ids, kept Int64 in the output.
    let yi: Vec<i64> = d.y.iter().map(|&v| (v * 1000.0).round() as i64).collect();
    let cells: Vec<Option<String>> = yi.iter().map(|v| Some(v.to_string())).collect();
    let num_ids: Vec<i64> = d
        .ids
        .iter()
        .map(|s| s.len() as i64 * 1000 + s.as_bytes()[1] as i64)
        .collect();
    let text_ids: Vec<String> = num_ids.iter().map(i64::to_string).collect();
    let pq = at(dir.path(), "i64.parquet");
    write_parquet(
        Path::new(&pq),
        vec![
            ("id", Arc::new(Int64Array::from(num_ids)) as ArrayRef),
            ("t", Arc::new(Float64Array::from(t.clone()))),
            ("y", Arc::new(Int64Array::from(yi))),
        ],
    );
    let args = ["--kind", "expanding", "--degree", "2", "--id-col", "id"];
    let csv = csv_text(Some(&text_ids), &t, &cells);
    let table = same_four_ways(dir.path(), &csv, &pq, &args, Some(DataType::Int64));
    assert!(table.columns[0]
        .iter()
        .all(|c| c.as_deref().is_some_and(|s| s.parse::<i64>().is_ok())));
}

#[test]
fn a_timestamp_time_column_is_seconds_since_the_epoch() {
    let dir = scratch();
    let d = Data::new(3000, 1, 8);
    let t = d.t();
    let y: Vec<Option<String>> = d.y.iter().map(|v| Some(format!("{v}"))).collect();
    let pq = at(dir.path(), "ts.parquet");
    let times = TimestampMicrosecondArray::from(d.micros.clone()).with_timezone("UTC");
    write_parquet(
        Path::new(&pq),
        vec![
            ("time", Arc::new(times) as ArrayRef),
            ("value", Arc::new(Float64Array::from(d.y.clone()))),
        ],
    );
    let csv = csv_text(None, &t, &y).replacen("t,y", "time,value", 1);
    let args = [
        "--kind",
        "fading",
        "--degree",
        "2",
        "--theta",
        "0.9",
        "--time-col",
        "time",
        "--value-col",
        "value",
    ];
    let table = same_four_ways(dir.path(), &csv, &pq, &args, None);
    // The times came back as seconds: the first is about 1.7e9.
    let first =
        f64::from_bits(u64::from_str_radix(table.columns[0][0].as_deref().unwrap(), 16).unwrap());
    assert!((1.7e9..1.8e9).contains(&first), "{first}");
}

#[test]
fn nanosecond_timestamps_and_dates_are_the_seconds_written_out() {
    let dir = scratch();
    let d = Data::new(2000, 1, 12);
    let y: Vec<Option<String>> = d.y.iter().map(|v| Some(format!("{v}"))).collect();
    // Nanoseconds beyond 2^53: the seconds are the decimal text's nearest double.
    let nanos: Vec<i64> = d
        .micros
        .iter()
        .enumerate()
        .map(|(i, &u)| u * 1000 + (i as i64 * 7919) % 1000)
        .collect();
    let text: Vec<String> = nanos
        .iter()
        .map(|&n| format!("{}.{:09}", n / 1_000_000_000, n % 1_000_000_000))
        .collect();
    let t: Vec<f64> = text.iter().map(|s| s.parse().unwrap()).collect();
    let pq = at(dir.path(), "ns.parquet");
    write_parquet(
        Path::new(&pq),
        vec![
            (
                "t",
                Arc::new(TimestampNanosecondArray::from(nanos)) as ArrayRef,
            ),
            ("y", Arc::new(Float64Array::from(d.y.clone()))),
        ],
    );
    let args = [
        "--kind", "fading", "--degree", "1", "--theta", "0.9", "--tau", "1",
    ];
    same_four_ways(dir.path(), &csv_text(None, &t, &y), &pq, &args, None);
    // Days since the epoch: 86 400 s each.
    let days: Vec<i32> = (0..2000).map(|i| 19_000 + i * 3 + i % 2).collect();
    let t: Vec<f64> = days.iter().map(|&d| f64::from(d) * 86_400.0).collect();
    let pq = at(dir.path(), "dates.parquet");
    write_parquet(
        Path::new(&pq),
        vec![
            ("t", Arc::new(Date32Array::from(days)) as ArrayRef),
            ("y", Arc::new(Float64Array::from(d.y.clone()))),
        ],
    );
    let args = ["--kind", "expanding", "--degree", "2"];
    same_four_ways(dir.path(), &csv_text(None, &t, &y), &pq, &args, None);
}

/// The single-series data with the value of data row `row` (1-based) missing: CSV (an empty
/// cell) and Parquet (a null).
fn with_missing_value(dir: &Path, row: usize) -> (String, String) {
    let d = Data::new(2000, 1, 9);
    let t = d.t();
    let mut y: Vec<Option<f64>> = d.y.iter().copied().map(Some).collect();
    y[row - 1] = None;
    let cells: Vec<Option<String>> = y.iter().map(|v| v.map(|v| format!("{v}"))).collect();
    let csv = at(dir, "missing.csv");
    std::fs::write(&csv, csv_text(None, &t, &cells)).expect("write csv");
    let pq = at(dir, "missing.parquet");
    write_parquet(
        Path::new(&pq),
        vec![
            ("t", Arc::new(Float64Array::from(t)) as ArrayRef),
            ("y", Arc::new(Float64Array::from(y))),
        ],
    );
    (csv, pq)
}

#[test]
fn a_null_value_is_treated_as_an_empty_csv_cell() {
    let dir = scratch();
    let args = [
        "--kind",
        "expanding",
        "--degree",
        "1",
        "--chunk-rows",
        "300",
    ];
    for row in [5, 1200] {
        let (csv, pq) = with_missing_value(dir.path(), row);
        let from_csv = run(&[&["filter", &csv][..], &args].concat(), "");
        let from_pq = run(&[&["filter", &pq][..], &args].concat(), "");
        // The same outcome: an error, the same rows written before it.
        assert_eq!(from_csv.code, 1, "{}", from_csv.stderr);
        assert_eq!(from_pq.code, 1, "{}", from_pq.stderr);
        assert_eq!(
            read_csv_or_empty(&from_pq.stdout),
            read_csv_or_empty(&from_csv.stdout)
        );
        assert_eq!(from_csv.stdout.is_empty(), row < 101, "row {row}");
        assert!(
            from_csv.stderr.contains("the cell is empty"),
            "{}",
            from_csv.stderr
        );
        let want =
            format!("error: row {row} of the Parquet file '{pq}', column 'y': the cell is null");
        assert!(from_pq.stderr.starts_with(&want), "{}", from_pq.stderr);
    }
}

/// A CSV output read back, or nothing for no output.
fn read_csv_or_empty(text: &str) -> Option<Table> {
    (!text.is_empty()).then(|| read_csv(text, false))
}

/// Runs `seqsmooth filter args…` and asserts a data error (exit code 1) whose message holds
/// every `parts`, and no panic.
fn fails(args: &[&str], parts: &[&str]) -> String {
    let o = run(args, "");
    assert_eq!(o.code, 1, "seqsmooth {args:?}: stderr {}", o.stderr);
    assert!(o.stderr.starts_with("error: "), "{}", o.stderr);
    for p in parts {
        assert!(o.stderr.contains(p), "stderr lacks {p:?}: {}", o.stderr);
    }
    assert!(!o.stderr.contains("panicked"), "{}", o.stderr);
    o.stderr
}

#[test]
fn a_missing_column_lists_the_columns_there_are() {
    let dir = scratch();
    let (_, _, pq) = single(dir.path(), 200, 10);
    fails(
        &[
            "filter",
            &pq,
            "--kind",
            "expanding",
            "--degree",
            "1",
            "--value-col",
            "price",
        ],
        &[
            "column 'price' not found",
            &format!("the Parquet file '{pq}'"),
            "columns are: t, y",
        ],
    );
}

#[test]
fn an_unsupported_column_type_is_named() {
    let dir = scratch();
    let t: Vec<f64> = (0..200).map(f64::from).collect();
    let pq = at(dir.path(), "types.parquet");
    let flags = BooleanArray::from((0..200).map(|i| i % 2 == 0).collect::<Vec<_>>());
    let lists = ListArray::from_iter_primitive::<Float64Type, _, _>(
        (0..200).map(|i| Some(vec![Some(f64::from(i))])),
    );
    write_parquet(
        Path::new(&pq),
        vec![
            ("t", Arc::new(Float64Array::from(t)) as ArrayRef),
            ("flag", Arc::new(flags)),
            ("list", Arc::new(lists)),
            ("y", Arc::new(Float64Array::from(vec![1.0; 200]))),
        ],
    );
    let base = [
        "filter",
        &pq,
        "--kind",
        "expanding",
        "--degree",
        "1",
        "--value-col",
    ];
    fails(
        &[&base[..], &["flag"]].concat(),
        &["column 'flag'", "has the type Boolean", "not a number"],
    );
    fails(
        &[&base[..], &["list"]].concat(),
        &["column 'list'", "has the type List", "not a number"],
    );
    fails(
        &[&base[..], &["t", "--time-col", "flag"]].concat(),
        &["column 'flag'", "Boolean"],
    );
    fails(
        &[&base[..], &["y", "--id-col", "flag"]].concat(),
        &[
            "column 'flag'",
            "has the type Boolean",
            "not usable as an id",
        ],
    );
}

#[test]
fn a_null_or_nan_time_is_refused_with_its_row() {
    let dir = scratch();
    for (bad, what) in [
        (None, "the cell is null"),
        (Some(f64::NAN), "time NaN is not finite"),
    ] {
        let mut t: Vec<Option<f64>> = (0..300).map(|i| Some(1.7e9 + f64::from(i))).collect();
        t[6] = bad;
        let y: Vec<f64> = (0..300).map(f64::from).collect();
        let pq = at(dir.path(), "badtime.parquet");
        write_parquet(
            Path::new(&pq),
            vec![
                ("t", Arc::new(Float64Array::from(t)) as ArrayRef),
                ("y", Arc::new(Float64Array::from(y))),
            ],
        );
        let out = at(dir.path(), "never.parquet");
        fails(
            &[
                "filter",
                &pq,
                "--kind",
                "expanding",
                "--degree",
                "1",
                "-o",
                &out,
            ],
            &[&format!(
                "row 7 of the Parquet file '{pq}', column 't': {what}"
            )],
        );
        assert!(!Path::new(&out).exists());
    }
}

#[test]
fn a_time_going_backwards_names_both_rows() {
    let dir = scratch();
    let mut t: Vec<f64> = (0..300).map(|i| 1.7e9 + f64::from(i)).collect();
    t[9] = t[3];
    let y: Vec<f64> = (0..300).map(f64::from).collect();
    let pq = at(dir.path(), "back.parquet");
    write_parquet(
        Path::new(&pq),
        vec![
            ("t", Arc::new(Float64Array::from(t)) as ArrayRef),
            ("y", Arc::new(Float64Array::from(y))),
        ],
    );
    fails(
        &["filter", &pq, "--kind", "expanding", "--degree", "1"],
        &[&format!("row 10 of the Parquet file '{pq}': time 1700000003 is not after the previous time 1700000008 (row 9)")],
    );
}

/// The files in `dir`.
fn listing(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("read dir")
        .map(|e| e.expect("entry").path())
        .collect();
    files.sort();
    files
}

#[test]
fn a_truncated_or_corrupt_file_is_a_clean_error() {
    let dir = scratch();
    let (_, _, pq) = single(dir.path(), 5000, 11);
    let bytes = std::fs::read(&pq).expect("read");
    let args = ["--kind", "expanding", "--degree", "1"];
    for cut in [bytes.len() / 2, bytes.len() - 3, 10, 0] {
        let path = at(dir.path(), "cut.parquet");
        std::fs::write(&path, &bytes[..cut]).expect("write");
        fails(
            &[&["filter", &path][..], &args].concat(),
            &["Parquet file", "cut.parquet"],
        );
    }
    // The footer intact, the data overwritten: the decoder's error, or the rows as read.
    for at_byte in [bytes.len() / 3, bytes.len() / 2] {
        let mut bad = bytes.clone();
        for b in &mut bad[at_byte..at_byte + 64] {
            *b ^= 0x5a;
        }
        let path = at(dir.path(), "garbled.parquet");
        std::fs::write(&path, &bad).expect("write");
        let o = run(&[&["filter", &path][..], &args].concat(), "");
        assert!(o.code == 0 || o.code == 1, "{}: {}", o.code, o.stderr);
        assert!(!o.stderr.contains("panicked"), "{}", o.stderr);
    }
}

#[test]
fn a_failed_run_leaves_the_output_file_as_it_was() {
    let dir = scratch();
    // The null value is after the first chunk: the output had been started.
    let (_, pq) = with_missing_value(dir.path(), 1500);
    let out = at(dir.path(), "out.parquet");
    std::fs::write(&out, "KEEP").expect("write");
    let before = listing(dir.path());
    fails(
        &[
            "filter",
            &pq,
            "--kind",
            "expanding",
            "--degree",
            "1",
            "--chunk-rows",
            "200",
            "-o",
            &out,
        ],
        &["row 1500 of the Parquet file"],
    );
    assert_eq!(std::fs::read_to_string(&out).expect("read"), "KEEP");
    assert_eq!(listing(dir.path()), before, "a temporary file was left");
    // Standard input stays CSV, even with a Parquet output.
    let csv = "t,y\n1,1\n2,2\n3,4\n";
    let o = run_at(
        Some(dir.path()),
        &[
            "filter",
            "-",
            "--kind",
            "expanding",
            "--degree",
            "1",
            "-o",
            "new.parquet",
        ],
        csv,
    );
    assert_eq!(o.code, 0, "{}", o.stderr);
    let table = read_parquet(&dir.path().join("new.parquet"), None);
    assert_eq!(table.names, ["t", "y", "d0", "d1"]);
    assert_eq!(table.columns[1], [bits(1.0), bits(2.0), bits(4.0)]);
    assert_eq!(table.columns[3][0], None);
}

/// The commands that read and write CSV only refuse a `.parquet` input or output by name,
/// with the usage exit code, and write no file.
#[test]
fn other_commands_refuse_parquet_by_name() {
    let out = common::tmp("refused.parquet");
    let _ = std::fs::remove_file(&out);
    let out = out.to_str().unwrap();
    let csv = "t,y\n0,1\n1,2\n2,4\n3,9\n4,16\n5,25\n";
    for args in [
        vec!["smooth", "--degree", "2", "--window", "5", "in.parquet"],
        vec![
            "fit",
            "--model",
            "polynomial",
            "--degree",
            "1",
            "--sigma",
            "1",
            "x.PARQUET",
        ],
        vec!["smooth", "--degree", "2", "--window", "5", "-o", out],
    ] {
        common::fails(
            &args,
            csv,
            2,
            &["is a Parquet file", "only `seqsmooth filter`"],
        );
    }
    assert!(!std::path::Path::new(out).exists());
}
