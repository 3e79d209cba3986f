//! `seqsmooth fit`: Gauss–Newton differential correction of each row's window of
//! measurements (the library's `estimate::sliding::SlidingFit`), for a radar's range, azimuth
//! and elevation of a Cartesian target, or a scalar polynomial series.
//!
//! Streams: each row is read, checked (line and column in every message), fitted and written.
//! The rows before the first estimate are held, so that an input that never determines the
//! state writes nothing.

use crate::args::{EpochArg, FitArgs, FitModel};
use crate::error::CliError;
use crate::io::{check_distinct, find_column, open_input, parse_cell, shown, write_f64, CsvIn};
use crate::io::{Need, Output};
use seqsmooth::estimate::batch::NoiseCovariance;
use seqsmooth::estimate::gauss_newton::{Correction, Epoch, GaussNewton, Measurement};
use seqsmooth::estimate::sliding::{SlidingFit, POLYNOMIAL_WINDOW, RADAR_WINDOW};
use seqsmooth::kalman::track::window_flag;
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::observation::LinearObservation;
use seqsmooth::model::radar::Radar;
use seqsmooth::Error;
use std::collections::VecDeque;
use std::f64::consts::FRAC_PI_2;

/// The model's sliding fit.
enum Fitter {
    Radar(SlidingFit<PolynomialDynamics, Radar>),
    Polynomial(SlidingFit<PolynomialDynamics, LinearObservation>),
}

impl Fitter {
    fn push(&mut self, m: Measurement) -> Result<Option<Correction>, Error> {
        match self {
            Fitter::Radar(f) => f.push_finite(m),
            Fitter::Polynomial(f) => f.push_finite(m),
        }
    }
}

/// One measured column: its name, index and what it holds (for messages).
pub(crate) struct Column {
    pub(crate) name: String,
    pub(crate) index: usize,
    pub(crate) what: &'static str,
}

/// The settings the arguments resolve to.
struct Setup {
    fitter: Fitter,
    /// The measured columns, in the observation's component order.
    columns: Vec<Column>,
    /// The noise variance of each component.
    variances: Vec<f64>,
    /// The data rows the model needs at the least, and why.
    need: Need,
    /// The state's column names, in state order, and those of their 1-sigma errors.
    states: Vec<String>,
    sigmas: Vec<String>,
    /// Whether the value cell is echoed after the time (polynomial).
    echo_value: bool,
}

/// Runs `seqsmooth fit`.
pub fn run(a: &FitArgs) -> Result<(), CliError> {
    check_distinct(a.input.as_deref(), a.output.as_deref())?;
    let input = open_input(a.input.as_deref())?;
    let mut csv = CsvIn::new(input)?;
    let mut setup = setup(a, &csv.header)?;
    let time = find_column(&csv.header, &a.time_col, "")?;
    let epoch_column = !matches!(a.epoch, EpochArg::End);

    let mut text = Vec::new();
    let mut cells: Vec<String> = vec!["t".into()];
    if setup.echo_value {
        cells.push("y".into());
    }
    cells.extend(setup.states.iter().cloned());
    cells.extend(setup.sigmas.iter().cloned());
    cells.extend(["iterations".into(), "chi2".into()]);
    if epoch_column {
        cells.push("epoch".into());
    }
    let flag_column = a.model == FitModel::Radar;
    if flag_column {
        cells.push("flag".into());
    }
    text.extend_from_slice(cells.join(",").as_bytes());
    text.push(b'\n');

    let mut out: Option<Output> = None;
    let mut lines: VecDeque<u64> = VecDeque::with_capacity(window(a).min(1 << 12));
    let mut previous: Option<(f64, u64, Vec<u8>)> = None;
    let mut rows = 0usize;
    let n = setup.states.len();
    while csv.next_record()? {
        let line = csv.line;
        let t_cell = csv.field(time).to_vec();
        let t = parse_cell(&t_cell, line, &a.time_col, "time")?;
        if let Some((prev, prev_line, prev_text)) = &previous {
            if t <= *prev {
                let why = if t == *prev {
                    "duplicate time; times must be strictly increasing"
                } else {
                    "times must be strictly increasing"
                };
                return Err(CliError::Data(format!(
                    "line {line}: time {} is not after the previous time {} (line {prev_line}): \
                     {why}",
                    shown(&t_cell),
                    shown(prev_text)
                )));
            }
        }
        let values = measured(&csv, line, &setup.columns, a.model)?;
        previous = Some((t, line, t_cell.clone()));
        rows += 1;
        if lines.len() == window(a) {
            lines.pop_front();
        }
        lines.push_back(line);
        let m = Measurement {
            time: t,
            values,
            noise: NoiseCovariance::Variances(setup.variances.clone()),
        };
        let fit = setup.fitter.push(m).map_err(|e| match e {
            Error::NonFinite {
                what: "fitted state",
                value,
            } => CliError::Data(format!(
                "line {line}: the fitted state holds {value}, beyond the double range; \
                 express the times in a larger unit or rescale the values"
            )),
            e => window_error(e, &lines, window(a), a.model),
        })?;

        text.extend_from_slice(&t_cell);
        if setup.echo_value {
            text.push(b',');
            text.extend_from_slice(csv.field(setup.columns[0].index));
        }
        match &fit {
            Some(c) => {
                // Finite: `push_finite` refuses any other estimate.
                let sigmas: Vec<f64> = (0..n).map(|k| c.covariance[(k, k)].sqrt()).collect();
                for &v in c.state.iter().chain(&sigmas) {
                    text.push(b',');
                    write_f64(&mut text, v);
                }
                text.push(b',');
                text.extend_from_slice(c.iterations.len().to_string().as_bytes());
                text.push(b',');
                write_f64(&mut text, c.chi_squared);
                if epoch_column {
                    text.push(b',');
                    write_f64(&mut text, c.epoch);
                }
                if flag_column {
                    text.push(b',');
                    text.extend_from_slice(window_flag(c).name().as_bytes());
                }
            }
            None => {
                let empty = 2 * n + 2 + usize::from(epoch_column) + usize::from(flag_column);
                text.extend(std::iter::repeat_n(b',', empty));
            }
        }
        text.push(b'\n');
        if fit.is_some() && out.is_none() {
            out = Some(Output::create(a.output.as_deref())?);
        }
        if let Some(out) = &mut out {
            if text.len() >= 1 << 16 {
                out.write(&text)?;
                text.clear();
            }
        }
    }
    setup.need.check(rows)?;
    let Some(mut out) = out else {
        return Err(CliError::Data(format!(
            "the input's {rows} rows never determine the state: no window of up to {} rows \
             holds enough measured components at enough distinct times ({} needs at least {})",
            window(a),
            setup.need.why,
            setup.need.rows
        )));
    };
    out.write(&text)?;
    out.finish()
}

/// The rows of each window: `--window`, else the model's default.
fn window(a: &FitArgs) -> usize {
    a.window.unwrap_or(match a.model {
        FitModel::Radar => RADAR_WINDOW,
        FitModel::Polynomial => POLYNOMIAL_WINDOW,
    })
}

/// The fitter, columns and noise of the arguments.
fn setup(a: &FitArgs, header: &[String]) -> Result<Setup, CliError> {
    let usage = |s: String| CliError::Usage(s);
    let epoch = match a.epoch {
        EpochArg::End => Epoch::End,
        EpochArg::Centre => Epoch::Centre,
        EpochArg::At(t) => Epoch::At(t),
    };
    let solver = GaussNewton {
        max_iterations: a.max_iterations as usize,
        ..GaussNewton::default()
    };
    let library = |e: Error| usage(e.to_string());
    let column = |name: &str, what: &'static str| -> Result<Column, CliError> {
        Ok(Column {
            name: name.to_string(),
            index: find_column(header, name, "")?,
            what,
        })
    };
    match a.model {
        FitModel::Radar => {
            if a.sigma.is_some() {
                return Err(usage(
                    "--sigma applies only to --model polynomial; a radar takes --sigma-range \
                     and --sigma-angle"
                        .into(),
                ));
            }
            let (Some(sr), Some(sa)) = (a.sigma_range, a.sigma_angle) else {
                return Err(usage(
                    "--model radar needs --sigma-range S (the range's noise sigma) and \
                     --sigma-angle S (the angles', in radians)"
                        .into(),
                ));
            };
            let degree = a.degree.unwrap_or(1);
            if !(1..=2).contains(&degree) {
                return Err(usage(format!(
                    "degree {degree} is out of range for --model radar: 1 (constant velocity) \
                     or 2 (constant acceleration)"
                )));
            }
            let need = Need::rows(2, "the radar model");
            need.check_header(header)?;
            let states = 3 * (degree + 1);
            let fit =
                SlidingFit::radar(a.site, degree, window(a), epoch, solver).map_err(library)?;
            let names = ["x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az"];
            Ok(Setup {
                fitter: Fitter::Radar(fit),
                columns: vec![
                    column(&a.range_col, "range")?,
                    column(&a.azimuth_col, "azimuth")?,
                    column(&a.elevation_col, "elevation")?,
                ],
                variances: vec![sr * sr, sa * sa, sa * sa],
                need,
                states: names[..states].iter().map(|s| s.to_string()).collect(),
                sigmas: names[..states].iter().map(|s| format!("s{s}")).collect(),
                echo_value: false,
            })
        }
        FitModel::Polynomial => {
            if a.sigma_range.is_some() || a.sigma_angle.is_some() {
                return Err(usage(
                    "--sigma-range and --sigma-angle apply only to --model radar".into(),
                ));
            }
            let Some(degree) = a.degree else {
                return Err(usage(
                    "--model polynomial needs --degree M, the polynomial's degree".into(),
                ));
            };
            let Some(sigma) = a.sigma else {
                return Err(usage(
                    "--model polynomial needs --sigma S, the values' noise standard deviation"
                        .into(),
                ));
            };
            if window(a) < degree + 1 {
                return Err(usage(format!(
                    "window {} is too small for degree {degree}: a degree-{degree} fit needs a \
                     window of at least {} rows",
                    window(a),
                    degree + 1
                )));
            }
            let need = Need::degree(degree);
            need.check_header(header)?;
            let fit = SlidingFit::polynomial(degree, window(a), epoch, solver).map_err(library)?;
            Ok(Setup {
                fitter: Fitter::Polynomial(fit),
                columns: vec![column(&a.value_col, "value")?],
                variances: vec![sigma * sigma],
                need,
                states: (0..=degree).map(|k| format!("d{k}")).collect(),
                sigmas: (0..=degree).map(|k| format!("s{k}")).collect(),
                echo_value: true,
            })
        }
    }
}

/// The measured components of the current row: an empty cell is a missing component (radar),
/// anything else a finite number in range.
pub(crate) fn measured<R: std::io::Read>(
    csv: &CsvIn<R>,
    line: u64,
    columns: &[Column],
    model: FitModel,
) -> Result<Vec<Option<f64>>, CliError> {
    let mut values = Vec::with_capacity(columns.len());
    for c in columns {
        let cell = csv.field(c.index);
        if cell.is_empty() && model == FitModel::Radar {
            values.push(None);
            continue;
        }
        let v = parse_cell(cell, line, &c.name, c.what)?;
        let bad = |why: &str| {
            CliError::Data(format!(
                "line {line}, column '{}': {} {} {why}",
                c.name,
                c.what,
                shown(cell)
            ))
        };
        match c.what {
            "range" if v <= 0.0 => return Err(bad("is not positive")),
            "elevation" if v.abs() > FRAC_PI_2 => {
                return Err(bad(
                    "is outside [-pi/2, pi/2]: elevations are in radians from the x-y plane",
                ))
            }
            _ => {}
        }
        values.push(Some(v));
    }
    Ok(values)
}

/// A window's error with the file lines of its rows (or of the one row it is about).
pub(crate) fn window_error(
    e: Error,
    lines: &VecDeque<u64>,
    window: usize,
    model: FitModel,
) -> CliError {
    let (first, last) = (
        lines.front().copied().unwrap_or(0),
        lines.back().copied().unwrap_or(0),
    );
    match e {
        Error::InBatch { index, source } => {
            let line = lines.get(index).copied().unwrap_or(last);
            CliError::Data(format!("line {line}: {source}"))
        }
        Error::Unobservable { .. } | Error::TooFewSamples { .. } => CliError::Data(format!(
            "lines {first}-{last}: the window of {} rows does not determine the state: {e}{}",
            lines.len().min(window),
            if model == FitModel::Radar {
                " (a radar window needs at least as many measured components as states, and \
                 its first fit two rows with range, azimuth and elevation)"
            } else {
                ""
            }
        )),
        e @ (Error::NotConverged { .. } | Error::Diverged { .. }) => CliError::Data(format!(
            "lines {first}-{last} (the window): {e} (with this command: --max-iterations N \
             allows more iterations, a shorter --window W fits fewer rows)"
        )),
        e => CliError::Data(format!("lines {first}-{last} (the window): {e}")),
    }
}
