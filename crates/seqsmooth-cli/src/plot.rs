//! `seqsmooth plot`: draws the output of `seqsmooth filter` (any kind) as PNG or SVG.
//!
//! The output's columns say what there is to draw: `t,y,d0..dM` always, `s0..sM` (the ±3σ
//! bands) with `--sigma` or `--kind auto`, `noise,outlier,misfit` for `--kind auto` (the ±3σ
//! noise lines, rejected samples, misfit spans), `window` for `--kind fixed` (not drawn), `lead`
//! with `--lead H` (the estimates are drawn at `t + H`, and each is compared in the residual
//! panel with the sample at that time where there is one). Empty
//! cells (no estimate yet, a degree not reached yet) leave gaps. The filter's input file may be
//! given too, for a truth column. The drawing is [`crate::chart`]'s, the same as the demo's.

use crate::args::PlotArgs;
use crate::chart::{self, Layout, Track};
use crate::error::CliError;
use crate::io::{
    find_column, fmt_f64, input_name, named, not_utf8, open_input, parse_cell, plural, shown, CsvIn,
};
use std::path::Path;

/// The cells of a column, or why they are unusable.
type Column<T> = Result<Vec<T>, CliError>;

/// A CSV file read in full: the header and the data rows with their 1-based file lines.
struct Table {
    /// The file's name in messages: `'path'` or `standard input`.
    name: String,
    header: Vec<String>,
    rows: Vec<(u64, Vec<String>)>,
}

impl Table {
    fn read(path: Option<&Path>) -> Result<Table, CliError> {
        let name = input_name(path);
        let at = |e: CliError| CliError::Data(format!("{name}: {e}"));
        let mut csv = CsvIn::new(open_input(path)?).map_err(at)?;
        let header = std::mem::take(&mut csv.header);
        let mut rows = Vec::new();
        while csv.next_record().map_err(at)? {
            let line = csv.line;
            let cells: Result<Vec<String>, _> = (0..header.len())
                .map(|i| std::str::from_utf8(csv.field(i)).map(str::to_string))
                .collect();
            rows.push((line, cells.map_err(|_| at(not_utf8(line)))?));
        }
        if header.iter().all(String::is_empty) {
            return Err(CliError::Data(format!(
                "{name}: the file is empty (no header, no data rows)"
            )));
        }
        if rows.is_empty() {
            return Err(CliError::Data(format!("{name}: no data rows to plot")));
        }
        Ok(Table { name, header, rows })
    }

    fn column(&self, col: &str) -> Option<usize> {
        self.header.iter().position(|h| h == col)
    }

    fn required(&self, col: &str, why: &str) -> Result<usize, CliError> {
        find_column(&self.header, col, why).map_err(|e| self.error(e))
    }

    fn error(&self, e: CliError) -> CliError {
        CliError::Data(format!("{}: {e}", self.name))
    }

    /// The numbers of column `idx`; empty cells are `None` when `empty` allows them.
    fn numbers(&self, idx: usize, what: &str, empty: bool) -> Column<Option<f64>> {
        let col = &self.header[idx];
        self.rows
            .iter()
            .map(|(line, r)| {
                let text = &r[idx];
                if empty && text.is_empty() {
                    return Ok(None);
                }
                parse_cell(text.as_bytes(), *line, col, what)
                    .map(Some)
                    .map_err(|e| self.error(e))
            })
            .collect()
    }

    /// The numbers of column `idx`, every cell filled.
    fn filled(&self, idx: usize, what: &str) -> Column<f64> {
        let v = self.numbers(idx, what, false)?;
        Ok(v.into_iter().flatten().collect())
    }

    /// The times of column `idx`: every cell filled, strictly increasing.
    fn times(&self, idx: usize) -> Column<f64> {
        let t = self.filled(idx, "time")?;
        match (1..t.len()).find(|&i| t[i] <= t[i - 1]) {
            None => Ok(t),
            Some(i) => Err(self.error(CliError::Data(format!(
                "line {}, column '{}': time {} is not after the previous time {} (line {}): \
                 a plot needs one series in time order",
                self.rows[i].0,
                shown(self.header[idx].as_bytes()),
                shown(self.rows[i].1[idx].as_bytes()),
                shown(self.rows[i - 1].1[idx].as_bytes()),
                self.rows[i - 1].0
            )))),
        }
    }

    /// `read` of the column `col`, empty when there is none.
    fn optional<T>(&self, col: &str, read: fn(&Self, usize) -> Column<T>) -> Column<T> {
        self.column(col).map_or(Ok(Vec::new()), |i| read(self, i))
    }

    /// The lead of the `lead` column (the same in every row), which `--lead` may repeat.
    fn lead(&self, idx: usize, given: f64) -> Result<f64, CliError> {
        let v = self.filled(idx, "lead")?;
        let first = v[0];
        let bad = |i: usize, why: &str| {
            let (line, r) = &self.rows[i];
            Err(CliError::Data(format!(
                "{}: line {line}, column 'lead': {} {why}",
                self.name,
                shown(r[idx].as_bytes())
            )))
        };
        if let Some(i) = v.iter().position(|&h| h != first) {
            return bad(
                i,
                "differs from the lead of the first row: one filter run has one lead",
            );
        }
        if !first.is_finite() {
            return bad(0, "is not a finite lead");
        }
        if given != 0.0 && given != first {
            return bad(0, &format!("is not the --lead {} given", fmt_f64(given)));
        }
        Ok(first)
    }

    /// Non-negative numbers (standard deviations), empty cells allowed.
    fn sigmas(&self, idx: usize) -> Column<Option<f64>> {
        let v = self.numbers(idx, "standard deviation", true)?;
        for ((line, r), s) in self.rows.iter().zip(&v) {
            if s.is_some_and(|s| s < 0.0) {
                return Err(CliError::Data(format!(
                    "{}: line {line}, column '{}': standard deviation {} is negative",
                    self.name, self.header[idx], &r[idx]
                )));
            }
        }
        Ok(v)
    }

    /// The 0/1 flags of column `idx`.
    fn flags(&self, idx: usize) -> Column<bool> {
        let col = &self.header[idx];
        self.rows
            .iter()
            .map(|(line, r)| match r[idx].as_str() {
                "0" => Ok(false),
                "1" => Ok(true),
                other => Err(CliError::Data(format!(
                    "{}: line {line}, column '{col}': '{other}' is not a flag, expected 0 or 1",
                    self.name
                ))),
            })
            .collect()
    }
}

/// `name (unit)`, or `name` without a unit.
fn with_unit(name: &str, unit: Option<&str>) -> String {
    match unit {
        Some(u) if !u.is_empty() => format!("{name} ({u})"),
        _ => name.to_string(),
    }
}

/// Superscript digits for derivative orders and unit powers.
fn superscript(k: usize) -> String {
    const S: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    k.to_string()
        .chars()
        .map(|c| S[c.to_digit(10).unwrap_or(0) as usize])
        .collect()
}

/// The axis label of derivative `k`: `y`, `dy/dt`, `d²y/dt²`, … with its unit.
pub fn derivative_label(k: usize, time_unit: Option<&str>, value_unit: Option<&str>) -> String {
    let power = if k == 1 {
        String::new()
    } else {
        superscript(k)
    };
    let name = match k {
        0 => "y".to_string(),
        _ => format!("d{power}y/dt{power}"),
    };
    let unit = match (k, value_unit, time_unit) {
        (0, v, _) => v.map(str::to_string),
        (_, v, Some(t)) => Some(format!("{}/{t}{power}", v.unwrap_or("1"))),
        _ => None,
    };
    with_unit(&name, unit.as_deref())
}

/// Reads the filter output (and input) named in `cfg` into a track.
fn read_track(cfg: &PlotArgs) -> Result<(Track, String), CliError> {
    let out = Table::read(cfg.source.as_deref())?;
    let n = out.rows.len();
    let why = " (the output of 'seqsmooth filter' has t,y,d0..dM)";
    let (t_idx, y_idx) = (out.required("t", why)?, out.required("y", why)?);
    let t = out.times(t_idx)?;
    let y = out.filled(y_idx, "value")?;
    let top = cfg.derivative.iter().copied().max().unwrap_or(0);
    let mut d = vec![vec![None; n]; top + 1];
    let mut s = vec![Vec::new(); top + 1];
    for k in 0..=top {
        let name = format!("d{k}");
        let idx = if cfg.derivative.contains(&k) {
            Some(out.required(
                &name,
                &format!(
                    " (derivative {k} was asked for: the filter's degree must be at least {k})"
                ),
            )?)
        } else {
            out.column(&name)
        };
        if let Some(idx) = idx {
            d[k] = out.numbers(idx, "derivative", true)?;
        }
        s[k] = out.optional(&format!("s{k}"), Table::sigmas)?;
    }
    let noise = out.optional("noise", Table::sigmas)?;
    let rejected = out.optional("outlier", Table::flags)?;
    let misfit = out.optional("misfit", Table::flags)?;
    // Past the start-up: the rows with the highest derivative of the output.
    let highest = (0..)
        .take_while(|k| out.column(&format!("d{k}")).is_some())
        .last();
    let settled = match highest {
        Some(m) => out.numbers(out.required(&format!("d{m}"), "")?, "derivative", true)?,
        None => Vec::new(),
    };
    let settled = settled.iter().map(Option::is_some).collect();
    let lead = match out.column("lead") {
        Some(idx) => out.lead(idx, cfg.lead)?,
        None => cfg.lead,
    };
    let mut truth = Vec::new();
    if let Some(path) = &cfg.input {
        let input = Table::read(Some(path))?;
        let ti = input.required(&cfg.time_col, " (give its name with --time-col)")?;
        let yi = input.required(&cfg.value_col, " (give its name with --value-col)")?;
        let it = input.times(ti)?;
        let iy = input.filled(yi, "value")?;
        if input.rows.len() != n {
            return Err(CliError::Data(format!(
                "the input {} has {} data row{} but the filter output {} has {n}: give the \
                 input the output was made from",
                input.name,
                input.rows.len(),
                plural(input.rows.len()),
                out.name
            )));
        }
        if let Some(i) = (0..n).find(|&i| it[i] != t[i] || iy[i] != y[i]) {
            let (col, a, b) = if it[i] != t[i] {
                (&cfg.time_col, &input.rows[i].1[ti], &out.rows[i].1[t_idx])
            } else {
                (&cfg.value_col, &input.rows[i].1[yi], &out.rows[i].1[y_idx])
            };
            return Err(CliError::Data(format!(
                "{}: line {}, column '{col}': {a} differs from {b} on line {} of the filter \
                 output {}: give the input the output was made from",
                input.name, input.rows[i].0, out.rows[i].0, out.name
            )));
        }
        if let Some(tc) = &cfg.truth_col {
            let idx = input.required(tc, " (the --truth-col)")?;
            truth.push(input.filled(idx, "truth")?);
        }
    }
    let kind = if !misfit.is_empty() || !rejected.is_empty() {
        "automatic filter"
    } else if out.column("window").is_some() {
        "fixed-memory filter"
    } else {
        "filter"
    };
    let file = match named(cfg.source.as_deref()) {
        Some(p) => p.file_name().map_or_else(
            || p.display().to_string(),
            |f| f.to_string_lossy().into_owned(),
        ),
        None => "standard input".to_string(),
    };
    let title = format!("seqsmooth {kind} output: {file}");
    Ok((
        Track {
            t,
            y,
            d,
            s,
            truth,
            noise,
            rejected,
            misfit,
            lead,
            settled,
            ..Track::default()
        },
        title,
    ))
}

pub fn run(cfg: &PlotArgs) -> Result<(), CliError> {
    for p in &cfg.output {
        chart::Format::of(p)?;
    }
    let (track, default_title) = read_track(cfg)?;
    let (tu, vu) = (cfg.time_unit.as_deref(), cfg.value_unit.as_deref());
    // With a lead, each estimate is compared with the sample at its own time t + H.
    let at = chart::samples_at_lead(&track.t, track.lead);
    let compared = (0..track.t.len())
        .filter(|&i| at[i].is_some() && track.d[0][i].is_some())
        .count();
    let residuals = !cfg.no_residuals && compared > 0;
    let panels: Vec<(usize, String)> = cfg
        .derivative
        .iter()
        .map(|&k| (k, derivative_label(k, tu, vu)))
        .collect();
    let unit = tu.map(|u| format!(" {u}")).unwrap_or_default();
    let h = fmt_f64(track.lead);
    let with_d0 = track.d[0].iter().filter(|d| d.is_some()).count();
    let lead = match compared {
        _ if cfg.no_residuals => format!("estimates drawn at t + {h}{unit}, their time"),
        0 => format!(
            "estimates drawn at t + {h}{unit}, their time; no residuals: no sample is at \
             the time of an estimate"
        ),
        _ => format!(
            "estimates drawn at t + {h}{unit}, their time; residuals against the sample at t + \
             {h}{unit} ({compared} of {with_d0} estimates have one)"
        ),
    };
    let default_height = Layout::default_height(cfg.derivative.len(), residuals);
    let layout = Layout {
        title: cfg.title.clone().unwrap_or(default_title),
        subtitle: if track.lead != 0.0 {
            lead
        } else {
            String::new()
        },
        time_label: with_unit("time t", tu),
        residual_label: residuals.then(|| with_unit("residual y − d0", vu)),
        size: (cfg.width, cfg.height.unwrap_or(default_height)),
        errors: Vec::new(),
        panels,
    };
    for p in &cfg.output {
        chart::write(&track, &layout, p)?;
    }
    Ok(())
}
