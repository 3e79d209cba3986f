//! `seqsmooth paml`: a series cut into segments of `--segment` time units from its first
//! sample, each replaced by its `N+1` polynomial samples (Villien & Ostertag 2009; the
//! library's `paml::PolynomialSamples`): the segment's weighted least-squares polynomial of
//! degree `N` at the Gauss nodes of its own samples, uncorrelated, with their variances.
//!
//! Rows are read a chunk at a time and each segment is written once the first row after it
//! arrives, so memory holds one segment. A segment with fewer than `N+1` samples is named on
//! standard error and left out.

use crate::args::PamlArgs;
use crate::error::CliError;
use crate::io::rows::{Chunk, RowReader};
use crate::io::{check_distinct, open_input, write_f64, Need, Output};
use seqsmooth::paml::PolynomialSamples;

/// Rows read at a time.
const CHUNK_ROWS: usize = 1 << 16;

/// The rows of the segment being gathered.
#[derive(Default)]
struct Segment {
    index: u64,
    t: Vec<f64>,
    y: Vec<f64>,
    sigma: Vec<f64>,
    /// The first row's place, for messages.
    first_line: u64,
}

/// Runs `seqsmooth paml`.
pub fn run(a: &PamlArgs) -> Result<(), CliError> {
    check_distinct(a.input.as_deref(), a.output.as_deref())?;
    let need = Need::degree(a.order);
    let input = open_input(a.input.as_deref())?;
    let mut reader = RowReader::new(
        input,
        &a.columns.time_col,
        &a.columns.value_col,
        None,
        &need,
    )?;
    if let Some(name) = &a.sigma_col {
        reader = reader.with_extra(name, "noise sigma")?;
    }
    let sigma = a.sigma.unwrap_or(1.0);
    let mut out = Output::create(a.output.as_deref())?;
    out.write(b"segment,t,value,variance\n")?;
    let mut chunk = Chunk::default();
    let mut segment = Segment::default();
    let mut start: Option<f64> = None;
    let mut rows = 0usize;
    let mut text = Vec::new();
    loop {
        reader.read_chunk(&mut chunk, CHUNK_ROWS);
        for i in 0..chunk.len() {
            let t = chunk.t[i];
            let s = if a.sigma_col.is_some() {
                let s = chunk.extra[i];
                if !seqsmooth::estimate::batch::is_usable_sigma(s) {
                    return Err(CliError::Data(format!(
                        "{}: noise sigma {s} in column '{}' is out of range: it must be above 0 \
                         with a normal square (about 1.5e-154 to 1.3e154)",
                        chunk.at(i),
                        a.sigma_col.as_deref().unwrap_or_default()
                    )));
                }
                s
            } else {
                sigma
            };
            let t0 = *start.get_or_insert(t);
            // Segment k holds t0 + k·S ≤ t < t0 + (k+1)·S.
            let k = ((t - t0) / a.segment).floor() as u64;
            if k != segment.index || segment.t.is_empty() {
                if !segment.t.is_empty() {
                    finish(&mut segment, a, t0, &mut text)?;
                    out.write(&text)?;
                    text.clear();
                }
                segment.index = k;
                segment.first_line = chunk.lines[i];
            }
            segment.t.push(t);
            segment.y.push(chunk.y[i]);
            segment.sigma.push(s);
            rows += 1;
        }
        if let Some(e) = chunk.error.take() {
            return Err(e);
        }
        if chunk.done {
            break;
        }
    }
    need.check(rows)?;
    if let Some(t0) = start {
        finish(&mut segment, a, t0, &mut text)?;
        out.write(&text)?;
    }
    out.finish()
}

/// Writes the polynomial samples of `segment` into `text` (or names it on standard error when
/// it has too few samples) and empties it.
fn finish(
    segment: &mut Segment,
    a: &PamlArgs,
    t0: f64,
    text: &mut Vec<u8>,
) -> Result<(), CliError> {
    let n = a.order;
    let (from, to) = (
        t0 + segment.index as f64 * a.segment,
        t0 + (segment.index + 1) as f64 * a.segment,
    );
    if segment.t.len() <= n {
        eprintln!(
            "seqsmooth paml: segment {} [{from}, {to}) has {} sample{}, order {n} needs {}: left out",
            segment.index,
            segment.t.len(),
            if segment.t.len() == 1 { "" } else { "s" },
            n + 1
        );
    } else {
        let ps = PolynomialSamples::from_segment(&segment.t, &segment.y, &segment.sigma, n)
            .map_err(|e| {
                CliError::Data(format!(
                    "segment {} [{from}, {to}) from line {}: {e}",
                    segment.index, segment.first_line
                ))
            })?;
        let id = segment.index.to_string();
        for ((t, v), var) in ps.times().iter().zip(&ps.values).zip(&ps.variances) {
            text.extend_from_slice(id.as_bytes());
            for x in [t, v, var] {
                text.push(b',');
                write_f64(text, *x);
            }
            text.push(b'\n');
        }
    }
    segment.t.clear();
    segment.y.clear();
    segment.sigma.clear();
    Ok(())
}
