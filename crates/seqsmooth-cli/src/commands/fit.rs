//! `seqsmooth fit`: Gauss–Newton differential correction of each row's window of
//! measurements (the library's `estimate::sliding::SlidingFit`), for a radar's range, azimuth
//! and elevation of a Cartesian target, or a scalar polynomial series.
//!
//! Streams: each row is read, checked (line and column in every message), fitted and written.
//! The rows before the first estimate are held, so that an input that never determines the
//! state writes nothing.

use crate::args::{FitArgs, FitModel};
use crate::commands::shared::radar_rows::{check_sigmas, Batch, Rows};
use crate::commands::shared::window::window_error;
use crate::error::CliError;
use crate::io::{check_distinct, find_column, open_input, parse_cell, shown, write_f64, CsvIn};
use crate::io::{Need, Output};
use seqsmooth::estimate::batch::NoiseCovariance;
use seqsmooth::estimate::gauss_newton::{Epoch, GaussNewton, Measurement};
use seqsmooth::estimate::sliding::{Fitter, SlidingFit, POLYNOMIAL_WINDOW, RADAR_WINDOW};
use seqsmooth::track::window_flag;
use seqsmooth::Error;
use std::collections::VecDeque;
use std::io::Read;

/// Where the rows come from: the radar reader that `track` uses (its columns, σ, azimuth
/// convention and the library's rule for a radar row), or the polynomial's value column.
enum Source<R: Read> {
    Radar(Box<Rows<R>>, Batch),
    Polynomial {
        csv: CsvIn<R>,
        time: usize,
        value: usize,
        variance: f64,
        /// The previous row's time, line and time cell (a time must increase).
        previous: Option<(f64, u64, Vec<u8>)>,
    },
}

/// One row read: its time cell as written, the value cell to echo (polynomial), the
/// measurement and its file line.
struct Taken {
    t_cell: Vec<u8>,
    echo: Option<Vec<u8>>,
    measurement: Measurement,
    line: u64,
}

impl<R: Read> Source<R> {
    /// The next row, checked; `None` at the end of the input.
    fn next(&mut self, a: &FitArgs) -> Result<Option<Taken>, CliError> {
        match self {
            Source::Radar(rows, batch) => {
                batch.rows.clear();
                batch.text.clear();
                batch.ends.clear();
                if !rows.next(batch)? {
                    return Ok(None);
                }
                let row = batch.rows[0];
                Ok(Some(Taken {
                    t_cell: batch.time_text(0).to_vec(),
                    echo: None,
                    measurement: Measurement {
                        time: row.time,
                        values: row.values.to_vec(),
                        noise: NoiseCovariance::Variances(row.variances.to_vec()),
                    },
                    line: row.line,
                }))
            }
            Source::Polynomial {
                csv,
                time,
                value,
                variance,
                previous,
            } => {
                if !csv.next_record()? {
                    return Ok(None);
                }
                let line = csv.line;
                let t_cell = csv.field(*time).to_vec();
                let t = parse_cell(&t_cell, line, &a.time_col, "time")?;
                if let Some((prev, prev_line, prev_text)) = previous.as_ref() {
                    if t <= *prev {
                        let why = if t == *prev {
                            "duplicate time; times must be strictly increasing"
                        } else {
                            "times must be strictly increasing"
                        };
                        return Err(CliError::Data(format!(
                            "line {line}: time {} is not after the previous time {} (line \
                             {prev_line}): {why}",
                            shown(&t_cell),
                            shown(prev_text)
                        )));
                    }
                }
                let cell = csv.field(*value).to_vec();
                let y = parse_cell(&cell, line, &a.value_col, "value")?;
                *previous = Some((t, line, t_cell.clone()));
                Ok(Some(Taken {
                    t_cell,
                    echo: Some(cell),
                    measurement: Measurement {
                        time: t,
                        values: vec![Some(y)],
                        noise: NoiseCovariance::Variances(vec![*variance]),
                    },
                    line,
                }))
            }
        }
    }
}

/// The settings the arguments resolve to.
struct Setup {
    fitter: Fitter,
    /// The data rows the model needs at the least, and why.
    need: Need,
    /// The state's column names, in state order, and those of their 1-sigma errors.
    states: Vec<String>,
    sigmas: Vec<String>,
    /// The polynomial's noise variance (`--sigma` squared; radar rows carry their own).
    variance: f64,
}

/// Runs `seqsmooth fit`.
pub fn run(a: &FitArgs) -> Result<(), CliError> {
    if a.model == FitModel::Radar {
        check_sigmas(&a.radar, "fit --model radar")?;
    }
    check_distinct(a.input.as_deref(), a.output.as_deref())?;
    let input = open_input(a.input.as_deref())?;
    let csv = CsvIn::new(input)?;
    let mut setup = setup(a, &csv.header)?;
    let echo_value = a.model == FitModel::Polynomial;
    let mut source = match a.model {
        FitModel::Radar => Source::Radar(
            Box::new(Rows::of(csv, &a.time_col, &a.radar)?),
            Batch::default(),
        ),
        FitModel::Polynomial => Source::Polynomial {
            time: find_column(&csv.header, &a.time_col, "")?,
            value: find_column(&csv.header, &a.value_col, "")?,
            variance: setup.variance,
            previous: None,
            csv,
        },
    };
    let epoch_column = !matches!(a.epoch, Epoch::End);

    let mut text = Vec::new();
    let mut cells: Vec<String> = vec!["t".into()];
    if echo_value {
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
    let mut rows = 0usize;
    let n = setup.states.len();
    while let Some(Taken {
        t_cell,
        echo,
        measurement,
        line,
    }) = source.next(a)?
    {
        rows += 1;
        if lines.len() == window(a) {
            lines.pop_front();
        }
        lines.push_back(line);
        let fit = setup.fitter.push_finite(measurement).map_err(|e| match e {
            e @ Error::NonFinite {
                what: "fitted state",
                value,
            } => CliError::from(e).reworded(|_| {
                format!(
                    "line {line}: the fitted state holds {value}, beyond the double range; \
                     express the times in a larger unit or rescale the values"
                )
            }),
            e => window_error(e, &lines, window(a), a.model),
        })?;

        text.extend_from_slice(&t_cell);
        if let Some(cell) = echo {
            text.push(b',');
            text.extend_from_slice(&cell);
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
    let epoch = a.epoch;
    let library = CliError::from;
    let solver = GaussNewton::with_max_iterations(a.max_iterations).map_err(library)?;
    match a.model {
        FitModel::Radar => {
            if a.sigma.is_some() {
                return Err(usage(
                    "--sigma applies only to --model polynomial; a radar takes --sigma-range \
                     and --sigma-angle"
                        .into(),
                ));
            }
            // Its range (1 or 2) is the library's: `SlidingFit::radar` refuses the others.
            let degree = a.degree.unwrap_or(1);
            let need = Need::rows(2, "the radar model");
            need.check_header(header)?;
            let states = 3 * (degree + 1);
            let fit = SlidingFit::radar(a.radar.site, degree, window(a), epoch, solver)
                .map_err(library)?;
            let names = ["x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az"];
            Ok(Setup {
                fitter: Fitter::Radar(fit),
                need,
                states: names[..states].iter().map(|s| s.to_string()).collect(),
                sigmas: names[..states].iter().map(|s| format!("s{s}")).collect(),
                variance: 1.0,
            })
        }
        FitModel::Polynomial => {
            let r = &a.radar;
            if r.sigma_range.is_some()
                || r.sigma_angle.is_some()
                || r.sigma_range_col.is_some()
                || r.sigma_angle_col.is_some()
            {
                return Err(usage(
                    "--sigma-range, --sigma-angle and their -col columns apply only to --model \
                     radar"
                        .into(),
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
            // The window's range for the degree is the library's.
            let fit = SlidingFit::polynomial(degree, window(a), epoch, solver).map_err(library)?;
            let need = Need::degree(degree);
            need.check_header(header)?;
            Ok(Setup {
                fitter: Fitter::Polynomial(fit),
                need,
                states: (0..=degree).map(|k| format!("d{k}")).collect(),
                sigmas: (0..=degree).map(|k| format!("s{k}")).collect(),
                variance: sigma * sigma,
            })
        }
    }
}
