//! `seqsmooth plot`: draws the output of `seqsmooth filter` (any kind) as PNG or SVG.
//!
//! The output's columns say what there is to draw: `t,y,d0..dM` always, `s0..sM` (the ±3σ
//! bands) with `--sigma` or `--kind auto`, `noise,outlier,misfit` for `--kind auto` (the ±3σ
//! noise lines, rejected samples, misfit spans), `window` for `--kind fixed` (not drawn), `lead`
//! with `--lead H` (the estimates are drawn at `t + H`, and each is compared in the residual
//! panel with the sample at that time where there is one). Empty
//! cells (no estimate yet, a degree not reached yet) leave gaps. The filter's input file may be
//! given too, for a truth column. The drawing is [`crate::plot::chart`]'s, the same as the demo's.
//!
//! The rows are read one at a time and decimated as they come ([`crate::plot::decimate::Reducer`]:
//! per half pixel column, the rows holding the extremes of every quantity drawn; time bins
//! that merge pairwise as the time range grows, since standard input cannot be read twice),
//! with a systematic sample of rows for the axis ranges, the outages' candidate steps, the
//! share of each bin's time under the misfit flag and the counts: memory is bounded by the image's width, not the input's
//! length. With a lead, the rows within the lead wait for the sample at their time
//! ([`crate::plot::chart::LeadMatcher`]).

use crate::args::PlotArgs;
use crate::error::CliError;
use crate::io::{
    find_column, fmt_f64, input_name, named, open_input, parse_cell, plural, shown, CsvIn,
};
use crate::plot::chart::{self, Counts, Layout, LeadMatcher, Row, Sample, Track};
use crate::plot::decimate::{Reducer, Stride};
use std::io::Read;
use std::path::Path;

/// Rows kept in the systematic sample the axis ranges' quantiles are taken over, and steps in
/// the one the typical step (for the outages) is the median of.
const SAMPLE_ROWS: usize = 20_000;
const SAMPLE_STEPS: usize = 20_000;
/// Time bins per pixel column of the plot, and at most this many in all (about 17 KB each
/// at 10⁷ rows of an automatic filter's output: 90 MB at the default width, 166 MB at most;
/// wider than 2,048 columns a bin spans more than half a pixel).
const BINS_PER_COLUMN: usize = 4;
const MAX_BINS: usize = 8192;

/// A CSV file read a row at a time.
struct Source {
    /// The file's name in messages: `'path'` or `standard input`.
    name: String,
    csv: CsvIn<Box<dyn Read + Send>>,
    header: Vec<String>,
    rows: usize,
}

impl Source {
    fn open(path: Option<&Path>) -> Result<Source, CliError> {
        let name = input_name(path);
        let at = |e: CliError| CliError::Data(format!("{name}: {e}"));
        let mut csv = CsvIn::new(open_input(path)?).map_err(at)?;
        let header = std::mem::take(&mut csv.header);
        if header.iter().all(String::is_empty) {
            return Err(CliError::Data(format!(
                "{name}: the file is empty (no header, no data rows)"
            )));
        }
        Ok(Source {
            name,
            csv,
            header,
            rows: 0,
        })
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

    /// Reads the next row; `false` at the end.
    fn next(&mut self) -> Result<bool, CliError> {
        let more = self.csv.next_record().map_err(|e| self.error(e))?;
        self.rows += usize::from(more);
        Ok(more)
    }

    /// Counts the rows left.
    fn count_rest(&mut self) -> Result<usize, CliError> {
        while self.next()? {}
        Ok(self.rows)
    }

    fn line(&self) -> u64 {
        self.csv.line
    }

    fn cell(&self, idx: usize) -> &[u8] {
        self.csv.field(idx)
    }

    /// The number in column `idx` (`what` it is, for messages), or `None` for an empty cell
    /// where `empty` allows one.
    fn number(&self, idx: usize, what: &str, empty: bool) -> Result<Option<f64>, CliError> {
        let text = self.cell(idx);
        if empty && text.is_empty() {
            return Ok(None);
        }
        parse_cell(text, self.line(), &self.header[idx], what)
            .map(Some)
            .map_err(|e| self.error(e))
    }

    /// The number in column `idx`, the cell filled.
    fn filled(&self, idx: usize, what: &str) -> Result<f64, CliError> {
        Ok(self.number(idx, what, false)?.unwrap_or(0.0))
    }

    /// A non-negative number (a standard deviation) or an empty cell.
    fn sigma(&self, idx: usize) -> Result<Option<f64>, CliError> {
        let v = self.number(idx, "standard deviation", true)?;
        if v.is_some_and(|s| s < 0.0) {
            return Err(CliError::Data(format!(
                "{}: line {}, column '{}': standard deviation {} is negative",
                self.name,
                self.line(),
                self.header[idx],
                shown(self.cell(idx))
            )));
        }
        Ok(v)
    }

    /// A 0/1 flag.
    fn flag(&self, idx: usize) -> Result<bool, CliError> {
        match self.cell(idx) {
            b"0" => Ok(false),
            b"1" => Ok(true),
            other => Err(CliError::Data(format!(
                "{}: line {}, column '{}': '{}' is not a flag, expected 0 or 1",
                self.name,
                self.line(),
                self.header[idx],
                shown(other)
            ))),
        }
    }
}

/// The previous row's time, its cell and line: each time must come after it.
#[derive(Default)]
struct Order(Option<(f64, u64)>, Vec<u8>);

impl Order {
    fn check(&mut self, src: &Source, idx: usize, t: f64) -> Result<(), CliError> {
        if let Some((p, line)) = self.0 {
            let cell = &self.1;
            if t <= p {
                return Err(src.error(CliError::Data(format!(
                    "line {}, column '{}': time {} is not after the previous time {} (line \
                     {line}): a plot needs one series in time order",
                    src.line(),
                    shown(src.header[idx].as_bytes()),
                    shown(src.cell(idx)),
                    shown(cell)
                ))));
            }
        }
        self.0 = Some((t, src.line()));
        self.1.clear();
        self.1.extend_from_slice(src.cell(idx));
        Ok(())
    }
}

/// The columns of the filter output a plot reads.
struct Columns {
    t: usize,
    y: usize,
    /// `d0..d{top}` and `s0..s{top}`, where present.
    d: Vec<Option<usize>>,
    s: Vec<Option<usize>>,
    noise: Option<usize>,
    outlier: Option<usize>,
    misfit: Option<usize>,
    /// The highest derivative of the output: a row with it is past the start-up.
    highest: Option<usize>,
    lead: Option<usize>,
}

impl Columns {
    fn of(out: &Source, cfg: &PlotArgs) -> Result<Columns, CliError> {
        let why = " (the output of 'seqsmooth filter' has t,y,d0..dM)";
        let (t, y) = (out.required("t", why)?, out.required("y", why)?);
        let top = cfg.derivative.iter().copied().max().unwrap_or(0);
        let mut d = Vec::new();
        for k in 0..=top {
            let name = format!("d{k}");
            d.push(if cfg.derivative.contains(&k) {
                let why = format!(
                    " (derivative {k} was asked for: the filter's degree must be at least {k})"
                );
                Some(out.required(&name, &why)?)
            } else {
                out.column(&name)
            });
        }
        let s = (0..=top).map(|k| out.column(&format!("s{k}"))).collect();
        let highest = (0..)
            .take_while(|k| out.column(&format!("d{k}")).is_some())
            .last();
        let highest = match highest {
            Some(m) => Some(out.required(&format!("d{m}"), "")?),
            None => None,
        };
        Ok(Columns {
            t,
            y,
            d,
            s,
            noise: out.column("noise"),
            outlier: out.column("outlier"),
            misfit: out.column("misfit"),
            highest,
            lead: out.column("lead"),
        })
    }
}

/// The filter's input, read beside its output for the truth.
struct Input {
    src: Source,
    t: usize,
    y: usize,
    truth: Option<usize>,
}

impl Input {
    fn open(cfg: &PlotArgs) -> Result<Option<Input>, CliError> {
        let Some(path) = &cfg.input else {
            return Ok(None);
        };
        let src = Source::open(Some(path))?;
        let t = src.required(&cfg.time_col, " (give its name with --time-col)")?;
        let y = src.required(&cfg.value_col, " (give its name with --value-col)")?;
        let truth = match &cfg.truth_col {
            Some(tc) => Some(src.required(tc, " (the --truth-col)")?),
            None => None,
        };
        Ok(Some(Input { src, t, y, truth }))
    }

    /// The error that the input and the output have different numbers of rows.
    fn count_error(&mut self, out: &mut Source) -> Result<CliError, CliError> {
        let (a, b) = (self.src.count_rest()?, out.count_rest()?);
        Ok(CliError::Data(format!(
            "the input {} has {a} data row{} but the filter output {} has {b}: give the input \
             the output was made from",
            self.src.name,
            plural(a),
            out.name
        )))
    }

    /// The truth at the output's current row (the input's next row, which must be the row the
    /// output's was made from).
    fn row(
        &mut self,
        out: &mut Source,
        cols: &Columns,
        cfg: &PlotArgs,
        (t, y): (f64, f64),
    ) -> Result<Option<f64>, CliError> {
        if !self.src.next()? {
            return Err(self.count_error(out)?);
        }
        let it = self.src.filled(self.t, "time")?;
        let iy = self.src.filled(self.y, "value")?;
        if it != t || iy != y {
            let (col, a, b) = if it != t {
                (&cfg.time_col, self.src.cell(self.t), out.cell(cols.t))
            } else {
                (&cfg.value_col, self.src.cell(self.y), out.cell(cols.y))
            };
            return Err(CliError::Data(format!(
                "{}: line {}, column '{col}': {} differs from {} on line {} of the filter \
                 output {}: give the input the output was made from",
                self.src.name,
                self.src.line(),
                shown(a),
                shown(b),
                out.line(),
                out.name
            )));
        }
        match self.truth {
            Some(i) => Ok(Some(self.src.filled(i, "truth")?)),
            None => Ok(None),
        }
    }
}

/// The lead of the `lead` column (the same in every row), which `--lead` may repeat.
fn check_lead(
    out: &Source,
    idx: usize,
    first: &mut Option<f64>,
    given: f64,
) -> Result<(), CliError> {
    let h = out.filled(idx, "lead")?;
    let bad = |why: &str| {
        Err(CliError::Data(format!(
            "{}: line {}, column 'lead': {} {why}",
            out.name,
            out.line(),
            shown(out.cell(idx))
        )))
    };
    match *first {
        Some(f) if h != f => {
            bad("differs from the lead of the first row: one filter run has one lead")
        }
        Some(_) => Ok(()),
        None => {
            if !h.is_finite() {
                return bad("is not a finite lead");
            }
            if given != 0.0 && given != h {
                return bad(&format!("is not the --lead {} given", fmt_f64(given)));
            }
            *first = Some(h);
            Ok(())
        }
    }
}

/// What reading the rows gathers besides the decimated track.
#[derive(Default)]
struct Tally {
    /// Rows whose estimate has a sample at its time, and rows with an estimate.
    compared: usize,
    with_d0: usize,
}

/// The rows as they come out of the lead matcher: decimated, sampled and counted.
struct Gather {
    reducer: Reducer<Row>,
    sample: Stride<Row>,
    values: Vec<f64>,
    idx: u64,
    tally: Tally,
}

impl Gather {
    fn take(&mut self, mut row: Row, at: Option<Sample>) {
        row.at = at;
        let d0 = row.d.first().copied().flatten().is_some();
        self.tally.with_d0 += usize::from(d0);
        self.tally.compared += usize::from(d0 && row.at.is_some());
        chart::drawn(&row, &mut self.values);
        if self.sample.wants(self.idx) {
            self.sample.push(self.idx, row.clone());
        }
        self.reducer.push(self.idx, row.t, row, &self.values);
        self.idx += 1;
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

/// Reads the filter output (and input) named in `cfg` into a decimated track, the counts of
/// compared rows, and the title.
fn read_track(cfg: &PlotArgs) -> Result<(Track, Tally, String), CliError> {
    let mut out = Source::open(cfg.source.as_deref())?;
    let cols = Columns::of(&out, cfg)?;
    let mut input = Input::open(cfg)?;
    let columns = chart::columns_for_width(cfg.width) as usize;
    let bins = (BINS_PER_COLUMN * columns).min(MAX_BINS);
    let mut gather = Gather {
        reducer: Reducer::new(bins),
        sample: Stride::new(SAMPLE_ROWS),
        values: Vec::new(),
        idx: 0,
        tally: Tally::default(),
    };
    let mut steps = Stride::new(SAMPLE_STEPS);
    // The time under the misfit flag, per bin of the reducer's kind.
    let mut misfit = Reducer::<()>::new(bins);
    let mut order = Order::default();
    let (mut lead, mut matcher) = (None, None);
    let (mut rejected, mut previous, mut was_flagged) = (0, None, false);
    while out.next()? {
        let t = out.filled(cols.t, "time")?;
        order.check(&out, cols.t, t)?;
        let y = out.filled(cols.y, "value")?;
        let cell = |idx: Option<usize>, read: &dyn Fn(usize) -> Result<Option<f64>, CliError>| {
            idx.map_or(Ok(None), read)
        };
        let mut row = Row {
            t,
            y,
            ..Row::default()
        };
        for k in 0..cols.d.len() {
            row.d
                .push(cell(cols.d[k], &|i| out.number(i, "derivative", true))?);
            row.s.push(cell(cols.s[k], &|i| out.sigma(i))?);
        }
        row.noise = cell(cols.noise, &|i| out.sigma(i))?;
        row.rejected = match cols.outlier {
            Some(i) => out.flag(i)?,
            None => false,
        };
        let flagged = match cols.misfit {
            Some(i) => out.flag(i)?,
            None => false,
        };
        row.settled = match cols.highest {
            Some(i) => out.number(i, "derivative", true)?.is_some(),
            None => false,
        };
        if let Some(i) = cols.lead {
            check_lead(&out, i, &mut lead, cfg.lead)?;
        }
        if let Some(input) = &mut input {
            row.truth.extend(input.row(&mut out, &cols, cfg, (t, y))?);
        }
        // Per row: the step before it, the misfit flag's time (to the next row, as
        // `chart::flag_spans` has it), the rejection.
        if let Some(p) = previous.replace(t) {
            steps.push(out.rows as u64 - 2, t - p);
            if was_flagged {
                misfit.weigh(t - p);
            }
        }
        misfit.push(out.rows as u64, t, (), &[]);
        was_flagged = flagged;
        rejected += usize::from(row.rejected);
        let m = matcher.get_or_insert_with(|| LeadMatcher::new(lead.unwrap_or(cfg.lead)));
        let sample = row.sample();
        m.push(t, row, sample);
        while let Some((row, at)) = m.pop() {
            gather.take(row, at);
        }
    }
    if out.rows == 0 {
        return Err(CliError::Data(format!(
            "{}: no data rows to plot",
            out.name
        )));
    }
    if let Some(input) = &mut input {
        if input.src.next()? {
            return Err(input.count_error(&mut out)?);
        }
    }
    if let Some(m) = &mut matcher {
        m.finish();
        while let Some((row, at)) = m.pop() {
            gather.take(row, at);
        }
    }
    let rows = out.rows;
    let Gather {
        reducer,
        sample,
        tally,
        ..
    } = gather;
    let reduced = reducer.finish();
    let typical = chart::typical_step(steps.into_items().into_iter().map(|s| s.1));
    let outages = reduced
        .steps
        .iter()
        .copied()
        .filter(|&(a, b)| typical.is_some_and(|m| chart::is_outage(b - a, m)))
        .collect();
    let mut track = Track {
        misfit_share: misfit
            .finish()
            .weights
            .into_iter()
            .map(|(a, b, w)| (a, b, w / (b - a)))
            .collect(),
        outages,
        lead: lead.unwrap_or(cfg.lead),
        counts: Some(Counts { rows, rejected }),
        ..Track::default()
    };
    // The kept rows and the sampled ones, merged in order.
    let mut kept = reduced.rows.into_iter().peekable();
    let mut sampled = sample.into_items().into_iter().peekable();
    loop {
        let next_kept = kept.peek().map(|r| r.0);
        let next_sampled = sampled.peek().map(|r| r.0);
        match (next_kept, next_sampled) {
            (None, None) => break,
            (Some(a), Some(b)) if a == b => {
                kept.next();
                track.push(sampled.next().map(|r| r.1).unwrap_or_default(), Some(true));
            }
            (Some(a), b) if b.is_none_or(|b| a < b) => {
                track.push(kept.next().map(|r| r.1).unwrap_or_default(), Some(false));
            }
            _ => track.push(sampled.next().map(|r| r.1).unwrap_or_default(), Some(true)),
        }
    }
    let kind = if cols.misfit.is_some() || cols.outlier.is_some() {
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
    Ok((track, tally, title))
}

pub fn run(cfg: &PlotArgs) -> Result<(), CliError> {
    for p in &cfg.output {
        chart::Format::of(p)?;
    }
    let (track, tally, default_title) = read_track(cfg)?;
    let (tu, vu) = (cfg.time_unit.as_deref(), cfg.value_unit.as_deref());
    // With a lead, each estimate is compared with the sample at its own time t + H.
    let compared = tally.compared;
    let residuals = !cfg.no_residuals && compared > 0;
    let panels: Vec<(usize, String)> = cfg
        .derivative
        .iter()
        .map(|&k| (k, derivative_label(k, tu, vu)))
        .collect();
    let unit = tu.map(|u| format!(" {u}")).unwrap_or_default();
    let h = fmt_f64(track.lead);
    let with_d0 = tally.with_d0;
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
