//! Radar tracking with the library's Kalman filter and Rauch–Tung–Striebel smoother, drawn.
//!
//! ```sh
//! cargo run -p seqsmooth-cli --example radar_tracking --release [-- OUT.png]
//! ```
//!
//! The data: the approach and landing of `tests/data/landing.csv` (474 rows 2.72 s apart, a
//! turn and a descent; east, north, up and the range, bearing and elevation from the radar at
//! the origin), with noise of known σ added to the polar columns (range 10 m, angles 1 mrad;
//! seed 2026, as `tests/track.rs`). The tracker is what `seqsmooth track --method kalman --q 10
//! --azimuth bearing` runs: the constant-velocity model on three axes, started from the
//! Gauss–Newton fit of the first rows that determines the state (`estimate::sliding`, window
//! 60, the radar nominal of Morrison §8.5), then the extended Kalman filter (ch. 12) with
//! white-noise acceleration of spectral density q = 10 m²/s³ (ch. 15); the smoother runs back
//! over the filter's run (`kalman::smooth`).
//!
//! The PNG (default `target/radar_tracking.png`) shows:
//!
//! - the plan view: the true path (east, north), the measurements turned into positions, the
//!   filter's and the smoother's tracks;
//! - the error of each estimate against the truth on east, north and up, with the filter's
//!   ±3σ band (shaded) and the smoother's ±3σ (dashed lines): an honest filter keeps its error
//!   inside its band about 99.7% of the time;
//! - the normalised innovation squared of every update, χ² with 3 degrees of freedom when the
//!   model holds, against its two-sided 99% interval, and its mean over the last 20 updates
//!   against the 99% interval of such a mean.
//!
//! It prints the share of rows inside ±3σ per axis for both estimates and the NIS summary.
//! The image in `docs/images/radar_tracking.png` is this example's output.

use nalgebra::{DMatrix, DVector};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{register_font, FontStyle};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use seqsmooth::estimate::batch::NoiseCovariance;
use seqsmooth::estimate::gauss_newton::{Epoch, Measurement};
use seqsmooth::estimate::sliding::{SlidingFit, Start};
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::kalman::{smooth, KalmanFilter};
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::radar::{wrap, Radar};
use seqsmooth::stats::chi_squared_quantile;
use seqsmooth::stats::consistency::mean_interval;
use std::error::Error;
use std::f64::consts::FRAC_PI_2;
use std::path::PathBuf;

/// The noise added to the range (m) and the angles (rad).
const SIGMA_RANGE: f64 = 10.0;
const SIGMA_ANGLE: f64 = 1e-3;
/// The spectral density of the white-noise acceleration (m²/s³), as `track --help` advises
/// for an airliner.
const Q: f64 = 10.0;
/// The updates in each mean of the NIS.
const NIS_WINDOW: usize = 20;

/// The embedded font (as `seqsmooth plot` draws with) and its family name.
static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");
const FAMILY: &str = "DejaVu Sans, sans-serif";

/// Colours, as `seqsmooth plot`'s.
const DATA: RGBColor = RGBColor(120, 120, 120);
const FILTER: RGBColor = RGBColor(31, 90, 180);
const SMOOTH: RGBColor = RGBColor(230, 120, 0);
const TRUTH: RGBColor = BLACK;
const BAND: RGBColor = RGBColor(0, 140, 70);

/// One row: time, truth (east, north, up), the noisy measurement (range, azimuth from +x,
/// elevation).
struct Row {
    t: f64,
    truth: [f64; 3],
    measured: [f64; 3],
}

/// An estimate's state (x, y, z, vx, vy, vz) and covariance at one row.
struct Estimate {
    state: DVector<f64>,
    covariance: DMatrix<f64>,
}

fn main() -> Result<(), Box<dyn Error>> {
    let out = std::env::args_os().nth(1).map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target/radar_tracking.png"),
        PathBuf::from,
    );
    let rows = landing()?;

    // The start: the fit of the first rows that determines the state.
    let radar = Radar::new([0.0; 3], 6)?;
    let dynamics = PolynomialDynamics::new(1, 3);
    let mut start = SlidingFit::new(
        dynamics,
        radar,
        60,
        Epoch::End,
        Start::Radar { radar, degree: 2 },
    )?;
    let measurements: Vec<Measurement> = rows
        .iter()
        .map(|r| Measurement {
            time: r.t,
            values: r.measured.iter().map(|&v| Some(v)).collect(),
            noise: NoiseCovariance::Variances(vec![
                SIGMA_RANGE * SIGMA_RANGE,
                SIGMA_ANGLE * SIGMA_ANGLE,
                SIGMA_ANGLE * SIGMA_ANGLE,
            ]),
        })
        .collect();
    let mut first = None;
    for (k, m) in measurements.iter().enumerate() {
        if let Some(fit) = start.push(m.clone())? {
            first = Some((k, fit));
            break;
        }
    }
    let (k0, fit) = first.ok_or("the rows never determine the state")?;
    let filter = KalmanFilter::new(dynamics, radar, fit.state, fit.covariance, fit.epoch)?
        .with_process_noise(WhiteNoiseDerivative::new(1, 3, Q)?)?;

    // The filter and the smoother over the rows after the start (the smoother's forward pass
    // is the filter: its filtered states and NIS are the filter's).
    let rest = &measurements[k0 + 1..];
    let smoothed = smooth(filter, rest)?;
    let filtered: Vec<Estimate> = smoothed
        .iter()
        .map(|s| Estimate {
            state: s.filtered_state.clone(),
            covariance: s.filtered_covariance.clone(),
        })
        .collect();
    let nis: Vec<Option<f64>> = smoothed.iter().map(|s| s.nis).collect();
    let smoothed: Vec<Estimate> = smoothed
        .into_iter()
        .map(|s| Estimate {
            state: s.state,
            covariance: s.covariance,
        })
        .collect();
    let rows = &rows[k0 + 1..];

    // The numbers the plot shows.
    for (name, estimates) in [("filter", &filtered), ("smoother", &smoothed)] {
        let inside: Vec<String> = ["east", "north", "up"]
            .iter()
            .enumerate()
            .map(|(axis, label)| {
                let n = rows
                    .iter()
                    .zip(estimates.iter())
                    .filter(|(r, e)| {
                        (e.state[axis] - r.truth[axis]).abs()
                            <= 3.0 * e.covariance[(axis, axis)].sqrt()
                    })
                    .count();
                format!("{label} {:.1}%", 100.0 * n as f64 / rows.len() as f64)
            })
            .collect();
        println!("{name}: within ±3σ on {}", inside.join(", "));
    }
    let values: Vec<f64> = nis.iter().flatten().copied().collect();
    let (lo, hi) = (
        chi_squared_quantile(3.0, 0.005)?,
        chi_squared_quantile(3.0, 0.995)?,
    );
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    let (mean_lo, mean_hi) = mean_interval(3, values.len(), 0.99)?;
    let outside = values.iter().filter(|&&v| v < lo || v > hi).count();
    println!(
        "NIS: mean {mean:.3} over {} updates (99% interval of the mean [{mean_lo:.3}, \
         {mean_hi:.3}]); {outside} outside [{lo:.4}, {hi:.3}] ({:.1}%, 1% expected)",
        values.len(),
        100.0 * outside as f64 / values.len() as f64
    );

    register_font(FAMILY, FontStyle::Normal, FONT).map_err(|_| "cannot load the font")?;
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let root = BitMapBackend::new(&out, (1600, 1500)).into_drawing_area();
    draw(&root, rows, &filtered, &smoothed, &nis)?;
    root.present()?;
    println!("wrote {}", out.display());
    Ok(())
}

/// The landing rows with their noise added (seed fixed), azimuths turned from bearings into
/// angles from +x (east) towards +y (north).
fn landing() -> Result<Vec<Row>, Box<dyn Error>> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/landing.csv");
    let text = std::fs::read_to_string(&path)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let mut rng = rand::rngs::StdRng::seed_from_u64(2026);
    let (range_noise, angle_noise) = (
        Normal::new(0.0, SIGMA_RANGE)?,
        Normal::new(0.0, SIGMA_ANGLE)?,
    );
    let mut rows = Vec::new();
    for line in text.lines().skip(1) {
        // time,east,north,up,azimuth,elevation,range
        let c = line
            .split(',')
            .map(str::parse)
            .collect::<Result<Vec<f64>, _>>()?;
        let range = c[6] + range_noise.sample(&mut rng);
        let bearing = c[4] + angle_noise.sample(&mut rng);
        let elevation = c[5] + angle_noise.sample(&mut rng);
        rows.push(Row {
            t: c[0],
            truth: [c[1], c[2], c[3]],
            measured: [range, wrap(FRAC_PI_2 - bearing), elevation],
        });
    }
    Ok(rows)
}

fn font(size: f64) -> TextStyle<'static> {
    TextStyle::from((FAMILY, size).into_font()).color(&BLACK)
}

/// The figure: title and legend, the plan view and the NIS side by side, then the three
/// error panels.
fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    rows: &[Row],
    filtered: &[Estimate],
    smoothed: &[Estimate],
    nis: &[Option<f64>],
) -> Result<(), Box<dyn Error>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let top = Pos::new(HPos::Center, VPos::Top);
    let width = root.dim_in_pixel().0 as i32;
    root.draw_text(
        "Radar tracking of an approach and landing: Kalman filter and RTS smoother",
        &font(24.0).pos(top),
        (width / 2, 12),
    )?;
    root.draw_text(
        &format!(
            "landing.csv, {} rows after the start; noise σ {SIGMA_RANGE} m in range, \
             {} mrad in bearing and elevation (seed 2026); constant velocity, \
             white-noise acceleration q = {Q} m²/s³",
            rows.len(),
            SIGMA_ANGLE * 1e3
        ),
        &font(15.0).color(&RGBColor(70, 70, 70)).pos(top),
        (width / 2, 44),
    )?;
    let (_, body) = root.split_vertically(72);
    let (upper, lower) = body.split_vertically(560);
    let (plan, nis_area) = upper.split_horizontally(720);
    plan_view(&plan, rows, filtered, smoothed)?;
    nis_panel(&nis_area, rows, nis)?;
    let panels = lower.split_evenly((3, 1));
    for (axis, area) in panels.iter().enumerate() {
        error_panel(area, rows, filtered, smoothed, axis, axis == 2)?;
    }
    Ok(())
}

/// The plan view (km): truth, measured positions, the filter's and the smoother's tracks.
fn plan_view<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    rows: &[Row],
    filtered: &[Estimate],
    smoothed: &[Estimate],
) -> Result<(), Box<dyn Error>>
where
    DB::ErrorType: 'static,
{
    let km = |v: f64| v / 1e3;
    let measured: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| {
            let [range, azimuth, elevation] = r.measured;
            let ground = range * elevation.cos();
            (km(ground * azimuth.cos()), km(ground * azimuth.sin()))
        })
        .collect();
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in &measured {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    // Equal scales on both axes: the drawing area is about 1.2 times as wide as high.
    let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
    let half = ((x1 - x0) / 2.0 / 1.2).max((y1 - y0) / 2.0) * 1.08;
    let mut chart = ChartBuilder::on(area)
        .caption("Plan view", font(18.0))
        .margin(10)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(cx - 1.2 * half..cx + 1.2 * half, cy - half..cy + half)?;
    chart
        .configure_mesh()
        .x_desc("east (km)")
        .y_desc("north (km)")
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .label_style(font(14.0))
        .axis_desc_style(font(16.0))
        .light_line_style(RGBColor(242, 242, 242))
        .bold_line_style(RGBColor(215, 215, 215))
        .draw()?;
    chart
        .draw_series(
            measured
                .iter()
                .map(|&p| Circle::new(p, 2, DATA.mix(0.7).filled())),
        )?
        .label("measured (range, bearing, elevation as positions)")
        .legend(|(x, y)| Circle::new((x + 10, y), 3, DATA.filled()));
    chart
        .draw_series(LineSeries::new(
            rows.iter().map(|r| (km(r.truth[0]), km(r.truth[1]))),
            TRUTH.stroke_width(3),
        ))?
        .label("truth")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], TRUTH.stroke_width(3)));
    for (estimates, colour, label) in [
        (filtered, FILTER, "Kalman filter"),
        (smoothed, SMOOTH, "RTS smoother"),
    ] {
        chart
            .draw_series(LineSeries::new(
                estimates.iter().map(|e| (km(e.state[0]), km(e.state[1]))),
                colour.stroke_width(1),
            ))?
            .label(label)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], colour.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .label_font(font(14.0))
        .background_style(WHITE.mix(0.9))
        .border_style(RGBColor(200, 200, 200))
        .draw()?;
    Ok(())
}

/// The NIS of every update and its mean over the last [`NIS_WINDOW`], with their 99% intervals.
fn nis_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    rows: &[Row],
    nis: &[Option<f64>],
) -> Result<(), Box<dyn Error>>
where
    DB::ErrorType: 'static,
{
    let (lo, hi) = (
        chi_squared_quantile(3.0, 0.005)?,
        chi_squared_quantile(3.0, 0.995)?,
    );
    let (mean_lo, mean_hi) = mean_interval(3, NIS_WINDOW, 0.99)?;
    let points: Vec<(f64, f64)> = rows
        .iter()
        .zip(nis)
        .filter_map(|(r, n)| n.map(|n| (r.t, n)))
        .collect();
    let means: Vec<(f64, f64)> = points
        .windows(NIS_WINDOW)
        .map(|w| {
            let last = w[NIS_WINDOW - 1].0;
            (last, w.iter().map(|p| p.1).sum::<f64>() / NIS_WINDOW as f64)
        })
        .collect();
    let (t0, t1) = (rows[0].t, rows[rows.len() - 1].t);
    let top = points.iter().map(|p| p.1).fold(hi, f64::max) * 1.05;
    let mut chart = ChartBuilder::on(area)
        .caption(
            "Normalised innovation squared (3 components, χ²₃ under the model)",
            font(18.0),
        )
        .margin(10)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(t0..t1, 0.0..top)?;
    chart
        .configure_mesh()
        .x_desc("time (s)")
        .y_desc("NIS")
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .label_style(font(14.0))
        .axis_desc_style(font(16.0))
        .light_line_style(RGBColor(242, 242, 242))
        .bold_line_style(RGBColor(215, 215, 215))
        .draw()?;
    let edge = |v: f64| vec![(t0, v), (t1, v)];
    chart
        .draw_series(DashedLineSeries::new(edge(hi), 8, 6, BAND.stroke_width(2)))?
        .label(format!(
            "99% interval of one NIS [{lo:.3}, {hi:.2}] (upper edge; lower near 0)"
        ))
        .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BAND.stroke_width(2)));
    chart.draw_series(DashedLineSeries::new(edge(lo), 8, 6, BAND.stroke_width(2)))?;
    chart
        .draw_series(
            points
                .iter()
                .map(|&p| Circle::new(p, 2, FILTER.mix(0.6).filled())),
        )?
        .label("NIS of each update")
        .legend(|(x, y)| Circle::new((x + 10, y), 3, FILTER.filled()));
    chart.draw_series([Rectangle::new(
        [(t0, mean_lo), (t1, mean_hi)],
        SMOOTH.mix(0.18).filled(),
    )])?;
    chart
        .draw_series(LineSeries::new(means, SMOOTH.stroke_width(2)))?
        .label(format!(
            "mean of the last {NIS_WINDOW}, its 99% interval [{mean_lo:.2}, {mean_hi:.2}] shaded"
        ))
        .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], SMOOTH.stroke_width(2)));
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font(font(14.0))
        .background_style(WHITE.mix(0.9))
        .border_style(RGBColor(200, 200, 200))
        .draw()?;
    Ok(())
}

/// Estimate − truth on one axis (m): the filter's with its ±3σ band shaded, the smoother's
/// with its ±3σ dashed.
fn error_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    rows: &[Row],
    filtered: &[Estimate],
    smoothed: &[Estimate],
    axis: usize,
    bottom: bool,
) -> Result<(), Box<dyn Error>>
where
    DB::ErrorType: 'static,
{
    let name = ["east", "north", "up"][axis];
    let error = |e: &[Estimate]| -> Vec<(f64, f64, f64)> {
        rows.iter()
            .zip(e)
            .map(|(r, e)| {
                (
                    r.t,
                    e.state[axis] - r.truth[axis],
                    3.0 * e.covariance[(axis, axis)].sqrt(),
                )
            })
            .collect()
    };
    let (f, s) = (error(filtered), error(smoothed));
    // The range: the 95th percentile of the filter's 3σ, widened to the errors inside it, so
    // the start-up's large σ does not flatten the rest.
    let mut bands: Vec<f64> = f.iter().map(|p| p.2).collect();
    bands.sort_by(f64::total_cmp);
    let limit = bands[(bands.len() - 1) * 95 / 100] * 1.15;
    let clamp = |v: f64| v.clamp(-limit, limit);
    let (t0, t1) = (rows[0].t, rows[rows.len() - 1].t);
    let mut chart = ChartBuilder::on(area)
        .margin_left(10)
        .margin_right(20)
        .margin_top(6)
        .x_label_area_size(if bottom { 45 } else { 25 })
        .y_label_area_size(60)
        .build_cartesian_2d(t0..t1, -limit..limit)?;
    let mut mesh = chart.configure_mesh();
    mesh.y_desc(format!("{name} error (m)"))
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .label_style(font(14.0))
        .axis_desc_style(font(16.0))
        .light_line_style(RGBColor(242, 242, 242))
        .bold_line_style(RGBColor(215, 215, 215));
    if bottom {
        mesh.x_desc("time (s)");
    }
    mesh.draw()?;
    let mut band: Vec<(f64, f64)> = f.iter().map(|p| (p.0, clamp(p.2))).collect();
    band.extend(f.iter().rev().map(|p| (p.0, clamp(-p.2))));
    chart
        .draw_series([Polygon::new(band, FILTER.mix(0.18).filled())])?
        .label("filter ±3σ")
        .legend(|(x, y)| Rectangle::new([(x, y - 6), (x + 20, y + 6)], FILTER.mix(0.3).filled()));
    for sign in [1.0, -1.0] {
        let edge = s.iter().map(move |p| (p.0, clamp(sign * p.2)));
        let series =
            chart.draw_series(DashedLineSeries::new(edge, 6, 4, SMOOTH.stroke_width(1)))?;
        if sign > 0.0 {
            series
                .label("smoother ±3σ")
                .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], SMOOTH.stroke_width(1)));
        }
    }
    chart.draw_series(LineSeries::new(
        [(t0, 0.0), (t1, 0.0)],
        TRUTH.stroke_width(1),
    ))?;
    for (points, colour, label) in [(&f, FILTER, "filter error"), (&s, SMOOTH, "smoother error")] {
        chart
            .draw_series(LineSeries::new(
                points.iter().map(|p| (p.0, clamp(p.1))),
                colour.stroke_width(2),
            ))?
            .label(label)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], colour.stroke_width(2)));
    }
    if axis == 0 {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .label_font(font(13.0))
            .background_style(WHITE.mix(0.9))
            .border_style(RGBColor(200, 200, 200))
            .draw()?;
    }
    Ok(())
}
