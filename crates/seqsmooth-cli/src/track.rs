//! `seqsmooth track`: a radar's range, azimuth and elevation to a constant-velocity Cartesian
//! track, by the library's sliding Gauss–Newton fit (`estimate::sliding`), Kalman filter
//! (`kalman::KalmanFilter`, with driving noise or fading memory) or Kalman smoother
//! (`kalman::smooth`). The Kalman methods start from the first Gauss–Newton fit that
//! determines the state. Rows are read as `fit` reads them (its column checks and messages).

use crate::args::{AzimuthConvention, FitModel, TrackArgs, TrackMethod};
use crate::error::CliError;
use crate::fit::{measured, window_error, Column};
use crate::io::{check_distinct, find_column, open_input, parse_cell, shown, write_f64, CsvIn};
use crate::io::{Need, Output};
use nalgebra::DVector;
use seqsmooth::estimate::batch::NoiseCovariance;
use seqsmooth::estimate::gauss_newton::{Correction, Epoch, Measurement};
use seqsmooth::estimate::sliding::{SlidingFit, Start};
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::kalman::{smooth, Discount, KalmanFilter};
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::radar::{wrap, Radar};
use seqsmooth::Error;
use std::collections::VecDeque;
use std::f64::consts::FRAC_PI_2;

/// The window of the Kalman methods' start (the first fit that determines the state).
const START_WINDOW: usize = 60;

/// One output row's numbers: the state and its σ, and the NIS; `None` for empty cells.
type Cells = Option<([f64; 6], [f64; 6], Option<f64>)>;

/// Runs `seqsmooth track`.
pub fn run(a: &TrackArgs) -> Result<(), CliError> {
    let usage = |s: &str| Err(CliError::Usage(s.into()));
    match a.method {
        TrackMethod::Fading if a.beta.is_none() && a.theta.is_none() => {
            return usage(
                "--method fading needs --beta B (per unit of time) or --theta T (per update)",
            )
        }
        TrackMethod::Fading | TrackMethod::Window if a.q.is_some() => {
            return usage("--q applies only to --method kalman and smooth")
        }
        TrackMethod::Window | TrackMethod::Kalman | TrackMethod::Smooth
            if a.beta.is_some() || a.theta.is_some() =>
        {
            return usage("--beta and --theta apply only to --method fading")
        }
        _ => {}
    }
    check_distinct(a.input.as_deref(), a.output.as_deref())?;
    let mut csv = CsvIn::new(open_input(a.input.as_deref())?)?;
    let need = Need::rows(2, "a radar track");
    need.check_header(&csv.header)?;
    let time = find_column(&csv.header, &a.time_col, "")?;
    let column = |name: &str, what: &'static str| -> Result<Column, CliError> {
        Ok(Column {
            name: name.to_string(),
            index: find_column(&csv.header, name, "")?,
            what,
        })
    };
    let columns = [
        column(&a.range_col, "range")?,
        column(&a.azimuth_col, "azimuth")?,
        column(&a.elevation_col, "elevation")?,
    ];
    let noise = NoiseCovariance::Variances(vec![
        a.sigma_range * a.sigma_range,
        a.sigma_angle * a.sigma_angle,
        a.sigma_angle * a.sigma_angle,
    ]);
    let radar = Radar::new(a.site, 6).map_err(|e| CliError::Usage(e.to_string()))?;
    let mut tracker = Tracker::new(a, radar)?;

    // Read every row (checked as fit checks them), then track.
    let (mut rows, mut lines, mut texts) = (Vec::new(), Vec::new(), Vec::new());
    let mut previous: Option<(f64, u64, Vec<u8>)> = None;
    while csv.next_record()? {
        let line = csv.line;
        let t_cell = csv.field(time).to_vec();
        let t = parse_cell(&t_cell, line, &a.time_col, "time")?;
        if let Some((prev, prev_line, prev_text)) = &previous {
            if t <= *prev {
                return Err(CliError::Data(format!(
                    "line {line}: time {} is not after the previous time {} (line \
                     {prev_line}): times must be strictly increasing",
                    shown(&t_cell),
                    shown(prev_text)
                )));
            }
        }
        let mut values = measured(&csv, line, &columns, FitModel::Radar)?;
        if a.azimuth == AzimuthConvention::Bearing {
            values[1] = values[1].map(|b| wrap(FRAC_PI_2 - b));
        }
        previous = Some((t, line, t_cell.clone()));
        rows.push(Measurement {
            time: t,
            values,
            noise: noise.clone(),
        });
        lines.push(line);
        texts.push(t_cell);
    }
    need.check(rows.len())?;
    let cells = tracker.run(&rows, &lines)?;
    if cells.iter().all(Option::is_none) {
        return Err(CliError::Data(format!(
            "the input's {} rows never determine the state: a radar track needs two rows with \
             range, azimuth and elevation",
            rows.len()
        )));
    }
    let mut text = b"t,x,y,z,vx,vy,vz,sx,sy,sz,svx,svy,svz,nis\n".to_vec();
    for (t_cell, c) in texts.iter().zip(&cells) {
        text.extend_from_slice(t_cell);
        match c {
            Some((x, s, nis)) => {
                for v in x.iter().chain(s) {
                    text.push(b',');
                    write_f64(&mut text, *v);
                }
                text.push(b',');
                if let Some(nis) = nis {
                    write_f64(&mut text, *nis);
                }
            }
            None => text.extend_from_slice(&[b','; 13]),
        }
        text.push(b'\n');
    }
    let mut out = Output::create(a.output.as_deref())?;
    out.write(&text)?;
    out.finish()
}

/// The chosen method's settings.
struct Tracker {
    method: TrackMethod,
    radar: Radar,
    dynamics: PolynomialDynamics,
    window: usize,
    q: f64,
    discount: Option<Discount>,
}

impl Tracker {
    fn new(a: &TrackArgs, radar: Radar) -> Result<Self, CliError> {
        let discount = match (a.beta, a.theta) {
            (Some(b), _) => Some(Discount::PerTime(b)),
            (_, Some(t)) => Some(Discount::PerUpdate(t)),
            _ => None,
        };
        Ok(Self {
            method: a.method,
            radar,
            dynamics: PolynomialDynamics::new(1, 3),
            window: a.window,
            q: a.q.unwrap_or(0.0),
            discount,
        })
    }

    fn sliding(&self, window: usize) -> Result<SlidingFit<PolynomialDynamics, Radar>, CliError> {
        SlidingFit::new(
            self.dynamics,
            self.radar,
            window,
            Epoch::End,
            Start::Radar {
                radar: self.radar,
                degree: 2,
            },
        )
        .map_err(|e| CliError::Usage(e.to_string()))
    }

    /// The cells of every row.
    fn run(&mut self, rows: &[Measurement], lines: &[u64]) -> Result<Vec<Cells>, CliError> {
        match self.method {
            TrackMethod::Window => self.window_method(rows, lines),
            _ => self.kalman_methods(rows, lines),
        }
    }

    fn window_method(&self, rows: &[Measurement], lines: &[u64]) -> Result<Vec<Cells>, CliError> {
        let mut fit = self.sliding(self.window)?;
        let mut window_lines = VecDeque::with_capacity(self.window);
        let mut previous: Option<Correction> = None;
        let mut out = Vec::with_capacity(rows.len());
        for (m, &line) in rows.iter().zip(lines) {
            if window_lines.len() == self.window {
                window_lines.pop_front();
            }
            window_lines.push_back(line);
            // The row's innovation against the previous window's estimate.
            let nis = match &previous {
                Some(p) => self.filter_from(p)?.update(m).ok().flatten().map(|i| i.nis),
                None => None,
            };
            let c = fit
                .push(m.clone())
                .map_err(|e| window_error(e, &window_lines, self.window, FitModel::Radar))?;
            out.push(c.as_ref().map(|c| cells(&c.state, &c.covariance, nis)));
            previous = c;
        }
        Ok(out)
    }

    /// A Kalman filter from a fit, with the method's driving noise or fading.
    fn filter_from(
        &self,
        c: &Correction,
    ) -> Result<KalmanFilter<PolynomialDynamics, Radar>, CliError> {
        let library = |e: Error| CliError::Data(format!("cannot start the filter: {e}"));
        let f = KalmanFilter::new(
            self.dynamics,
            self.radar,
            c.state.clone(),
            c.covariance.clone(),
            c.epoch,
        )
        .map_err(library)?;
        match (self.method, self.discount) {
            (TrackMethod::Fading, Some(d)) => f.with_fading(d).map_err(library),
            (TrackMethod::Window, _) => Ok(f),
            _ => f
                .with_process_noise(WhiteNoiseDerivative::new(1, 3, self.q).map_err(library)?)
                .map_err(library),
        }
    }

    fn kalman_methods(&self, rows: &[Measurement], lines: &[u64]) -> Result<Vec<Cells>, CliError> {
        let mut out: Vec<Cells> = Vec::with_capacity(rows.len());
        // The start: the first fit of the rows so far that determines the state.
        let mut start = self.sliding(START_WINDOW)?;
        let mut window_lines = VecDeque::new();
        let mut begun = None;
        for (k, (m, &line)) in rows.iter().zip(lines).enumerate() {
            window_lines.push_back(line);
            let c = start
                .push(m.clone())
                .map_err(|e| window_error(e, &window_lines, START_WINDOW, FitModel::Radar))?;
            match c {
                Some(c) => {
                    out.push(Some(cells(&c.state, &c.covariance, None)));
                    begun = Some((k, c));
                    break;
                }
                None => out.push(None),
            }
        }
        let Some((k0, c)) = begun else {
            return Ok(out);
        };
        let filter = self.filter_from(&c)?;
        let rest = &rows[k0 + 1..];
        let at = |i: usize| lines[k0 + 1 + i];
        if self.method == TrackMethod::Smooth {
            let smoothed = smooth(filter, rest).map_err(|e| match e {
                Error::InBatch { index, source } => {
                    CliError::Data(format!("line {}: {source}", at(index)))
                }
                e => CliError::Data(format!("the smoother failed: {e}")),
            })?;
            out.extend(
                smoothed
                    .iter()
                    .map(|s| Some(cells(&s.state, &s.covariance, s.nis))),
            );
            return Ok(out);
        }
        let mut filter = filter;
        for (i, m) in rest.iter().enumerate() {
            let innovation = filter.update(m).map_err(|e| {
                CliError::Data(format!("line {}: the filter's update failed: {e}", at(i)))
            })?;
            out.push(Some(cells(
                filter.state(),
                filter.covariance(),
                innovation.map(|i| i.nis),
            )));
        }
        Ok(out)
    }
}

/// A row's cells from a state and covariance.
fn cells(
    x: &DVector<f64>,
    s: &nalgebra::DMatrix<f64>,
    nis: Option<f64>,
) -> ([f64; 6], [f64; 6], Option<f64>) {
    let mut state = [0.0; 6];
    let mut sigma = [0.0; 6];
    for k in 0..6 {
        state[k] = x[k];
        sigma[k] = s[(k, k)].max(0.0).sqrt();
    }
    (state, sigma, nis)
}
