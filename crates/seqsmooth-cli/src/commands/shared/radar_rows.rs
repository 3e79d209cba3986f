//! The rows of `seqsmooth track`'s input, read and checked one at a time.
//!
//! Each row's time must be a finite number after the previous row's; its range, azimuth and
//! elevation cells are numbers in range or empty (a missing component): the range positive,
//! the azimuth within `[−2π, 2π]` and the elevation within `[−π/2, π/2]` (radians; a bearing
//! is turned into the angle from +x). Each present component's noise σ comes from the row's
//! σ column when the command names one and the cell is not empty, else from the flag; a σ
//! cell must hold a positive number whose square (the variance) is a normal double. Every
//! refusal names the file line and the column.
//!
//! The rows go into [`Batch`]es (numbers by row, time cells in one buffer): reading allocates
//! nothing per row once a batch's buffers have grown.

use crate::args::RadarArgs;
use crate::error::CliError;
use crate::io::{find_column, parse_cell, shown, CsvIn};
use seqsmooth::model::radar::{check_component, from_bearing, COMPONENTS};
use std::io::Read;

/// A measured column: its name (for messages), index and what it holds (a name of
/// [`COMPONENTS`] or "time").
struct Cell {
    name: String,
    index: usize,
    what: &'static str,
}

/// Where one σ comes from: a column of the input, the flag, or both (the column first).
pub(crate) struct SigmaSource {
    /// The flag's value (`--sigma-range`, `--sigma-angle`).
    pub(crate) flag: Option<f64>,
    /// The column's name, if the command names one (`--sigma-range-col`, `--sigma-angle-col`).
    pub(crate) column: Option<String>,
    /// The flag, for messages: `--sigma-range`.
    pub(crate) flag_name: &'static str,
}

/// A [`SigmaSource`] with its column found in the header.
struct Sigma {
    flag: Option<f64>,
    column: Option<(String, usize)>,
    flag_name: &'static str,
}

/// One checked row: its time, components (`None` for an empty cell, azimuths from +x), their
/// noise variances (1 where a component is missing: unused) and its 1-based file line.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Row {
    pub(crate) time: f64,
    pub(crate) values: [Option<f64>; 3],
    pub(crate) variances: [f64; 3],
    pub(crate) line: u64,
}

/// Consecutive rows of the input, with their time cells as written (trimmed) in one buffer.
#[derive(Debug, Default)]
pub(crate) struct Batch {
    pub(crate) rows: Vec<Row>,
    /// The time cells, end to end; row `i`'s ends at `ends[i]`.
    pub(crate) text: Vec<u8>,
    pub(crate) ends: Vec<usize>,
    /// Why the input ends after these rows, when it is an error: the next row's.
    pub(crate) error: Option<CliError>,
    /// Whether the input ends after these rows (at its end or at `error`).
    pub(crate) last: bool,
    /// Data rows read up to the end of this batch.
    pub(crate) count: usize,
}

impl Batch {
    /// The time cell of row `i`, as written.
    pub(crate) fn time_text(&self, i: usize) -> &[u8] {
        let start = if i == 0 { 0 } else { self.ends[i - 1] };
        &self.text[start..self.ends[i]]
    }
}

/// The input, read row by row: [`Rows::next`] checks the next row and appends it to a
/// [`Batch`].
pub(crate) struct Rows<R: Read> {
    csv: CsvIn<R>,
    time: Cell,
    /// Range, azimuth, elevation: the observation's component order.
    cells: [Cell; 3],
    /// The range's σ and the angles' σ.
    sigmas: [Sigma; 2],
    bearing: bool,
    /// The previous row's time, line and time cell (for the message of a time that does not
    /// increase).
    previous: Option<(f64, u64)>,
    previous_text: Vec<u8>,
    /// Data rows read so far.
    pub(crate) count: usize,
}

/// The names of the columns `track` reads.
pub(crate) struct Names<'a> {
    pub(crate) time: &'a str,
    pub(crate) range: &'a str,
    pub(crate) azimuth: &'a str,
    pub(crate) elevation: &'a str,
}

impl<R: Read> Rows<R> {
    /// The reader of `csv`'s rows: finds the columns (a missing or ambiguous one is refused
    /// with the header's line).
    pub(crate) fn new(
        csv: CsvIn<R>,
        names: &Names,
        sigmas: [SigmaSource; 2],
        bearing: bool,
    ) -> Result<Self, CliError> {
        let line = csv.line;
        let at_header = |e: CliError| match e {
            CliError::Data(m) => CliError::Data(format!("line {line} (the header): {m}")),
            e => e,
        };
        let find = |name: &str| find_column(&csv.header, name, "").map_err(at_header);
        let cell = |name: &str, what: &'static str| -> Result<Cell, CliError> {
            Ok(Cell {
                name: name.to_string(),
                index: find(name)?,
                what,
            })
        };
        let [range_sigma, angle_sigma] = sigmas;
        let sigma = |s: SigmaSource| -> Result<Sigma, CliError> {
            let column = match s.column {
                Some(name) => Some((name.clone(), find(&name)?)),
                None => None,
            };
            Ok(Sigma {
                flag: s.flag,
                column,
                flag_name: s.flag_name,
            })
        };
        Ok(Self {
            time: cell(names.time, "time")?,
            cells: [
                cell(names.range, COMPONENTS[0])?,
                cell(names.azimuth, COMPONENTS[1])?,
                cell(names.elevation, COMPONENTS[2])?,
            ],
            sigmas: [sigma(range_sigma)?, sigma(angle_sigma)?],
            bearing,
            previous: None,
            previous_text: Vec::new(),
            count: 0,
            csv,
        })
    }

    /// Reads and checks the next row and appends it to `batch`; `false` at the end of the
    /// input.
    pub(crate) fn next(&mut self, batch: &mut Batch) -> Result<bool, CliError> {
        if !self.csv.next_record()? {
            return Ok(false);
        }
        let line = self.csv.line;
        let t_cell = self.csv.field(self.time.index);
        let t = parse_cell(t_cell, line, &self.time.name, "time")?;
        if let Some((previous, previous_line)) = self.previous {
            if t <= previous {
                let why = if t == previous {
                    "duplicate time; times must be strictly increasing"
                } else {
                    "times must be strictly increasing"
                };
                return Err(CliError::Data(format!(
                    "line {line}, column '{}': time {} is not after the previous time {} (line \
                     {previous_line}): {why}",
                    self.time.name,
                    shown(t_cell),
                    shown(&self.previous_text)
                )));
            }
        }
        let mut values = [None; 3];
        for (k, (value, c)) in values.iter_mut().zip(&self.cells).enumerate() {
            *value = component(self.csv.field(c.index), line, c, k)?;
        }
        let mut variances = [1.0; 3];
        let needed = [
            values[0].is_some(),
            values[1].is_some() || values[2].is_some(),
        ];
        for (k, s) in self.sigmas.iter().enumerate() {
            if let Some(sigma) = self.sigma(s, needed[k], line)? {
                let v = sigma * sigma;
                if k == 0 {
                    variances[0] = v;
                } else {
                    variances[1] = v;
                    variances[2] = v;
                }
            }
        }
        if self.bearing {
            values[1] = values[1].map(from_bearing);
        }
        let t_cell = self.csv.field(self.time.index);
        self.previous_text.clear();
        self.previous_text.extend_from_slice(t_cell);
        batch.text.extend_from_slice(t_cell);
        batch.ends.push(batch.text.len());
        batch.rows.push(Row {
            time: t,
            values,
            variances,
            line,
        });
        self.previous = Some((t, line));
        self.count += 1;
        Ok(true)
    }

    /// The row's σ from `s`: its cell, else the flag; `None` when neither gives one and none
    /// is `needed` (the components it weighs are missing), an error when one is.
    fn sigma(&self, s: &Sigma, needed: bool, line: u64) -> Result<Option<f64>, CliError> {
        if let Some((name, index)) = &s.column {
            let cell = self.csv.field(*index);
            if !cell.is_empty() {
                let v = parse_cell(cell, line, name, "sigma")?;
                if !seqsmooth::estimate::batch::is_usable_sigma(v) {
                    return Err(CliError::Data(format!(
                        "line {line}, column '{name}': sigma {} is {}",
                        shown(cell),
                        if v <= 0.0 {
                            "not positive: a noise standard deviation must be above 0"
                        } else {
                            "out of range: its square, the noise variance, must be a normal \
                             double (sigma from about 1.5e-154 to 1.3e154; rescale the values)"
                        }
                    )));
                }
                return Ok(Some(v));
            }
            if s.flag.is_none() && needed {
                return Err(CliError::Data(format!(
                    "line {line}, column '{name}': the cell is empty and no {} is given: the \
                     row's measurement needs its noise sigma (give the cell, or {} S for the \
                     rows without one)",
                    s.flag_name, s.flag_name
                )));
            }
        }
        Ok(s.flag)
    }
}

/// The `k`-th component's cell: `None` when empty, else a number the library's rule for a
/// radar row takes ([`check_component`]).
fn component(cell: &[u8], line: u64, c: &Cell, k: usize) -> Result<Option<f64>, CliError> {
    if cell.is_empty() {
        return Ok(None);
    }
    let v = parse_cell(cell, line, &c.name, c.what)?;
    check_component(k, v).map(Some).map_err(|why| {
        CliError::Data(format!(
            "line {line}, column '{}': {} {} {why}",
            c.name,
            c.what,
            shown(cell)
        ))
    })
}

/// Refuses a radar command that gives neither the flag nor a column for the range's σ, or for
/// the angles' (`command`: how the message names it, e.g. "track").
pub(crate) fn check_sigmas(a: &RadarArgs, command: &str) -> Result<(), CliError> {
    if a.sigma_range.is_none() && a.sigma_range_col.is_none() {
        return Err(CliError::Usage(format!(
            "{command} needs --sigma-range S (the range's noise sigma) or --sigma-range-col NAME \
             (a column of per-row sigmas; with both, the flag serves the rows whose cell is empty)"
        )));
    }
    if a.sigma_angle.is_none() && a.sigma_angle_col.is_none() {
        return Err(CliError::Usage(format!(
            "{command} needs --sigma-angle S (the azimuth's and elevation's noise sigma, in \
             radians) or --sigma-angle-col NAME (a column of per-row sigmas; with both, the flag \
             serves the rows whose cell is empty)"
        )));
    }
    Ok(())
}

impl<R: Read> Rows<R> {
    /// The reader of `csv`'s radar rows, with the columns, σ and azimuth convention of `a`
    /// and the time column `time`.
    pub(crate) fn of(csv: CsvIn<R>, time: &str, a: &RadarArgs) -> Result<Self, CliError> {
        let names = Names {
            time,
            range: &a.range_col,
            azimuth: &a.azimuth_col,
            elevation: &a.elevation_col,
        };
        let sigmas = [
            SigmaSource {
                flag: a.sigma_range,
                column: a.sigma_range_col.clone(),
                flag_name: "--sigma-range",
            },
            SigmaSource {
                flag: a.sigma_angle,
                column: a.sigma_angle_col.clone(),
                flag_name: "--sigma-angle",
            },
        ];
        Self::new(csv, &names, sigmas, a.azimuth.is_bearing())
    }
}
