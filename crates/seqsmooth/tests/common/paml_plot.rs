//! Log-scale line plots of σ by observation span, side by side (SVG), for the PAML examples.

#![allow(dead_code)]

use plotters::prelude::*;

/// One panel: its title, y label and named series (one value per x).
pub struct Panel {
    pub title: String,
    pub y_label: String,
    pub series: Vec<(String, Vec<f64>)>,
}

/// DejaVu Sans, the command's embedded font (Bitstream Vera licence, beside it in
/// `crates/seqsmooth-cli/assets/`): plotters reads no system fonts here.
static FONT: &[u8] = include_bytes!("../../../seqsmooth-cli/assets/DejaVuSans.ttf");

pub fn draw(
    path: &str,
    x_label: &str,
    x: &[f64],
    panels: &[Panel],
) -> Result<(), Box<dyn std::error::Error>> {
    plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
        .map_err(|_| "the embedded font could not be loaded")?;
    let root = SVGBackend::new(path, (480 * panels.len() as u32, 420)).into_drawing_area();
    root.fill(&WHITE)?;
    let areas = root.split_evenly((1, panels.len()));
    let colours = [BLACK, BLUE, RED, GREEN, MAGENTA];
    let (x_lo, x_hi) = (
        x.iter().copied().fold(f64::INFINITY, f64::min),
        x.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    );
    for (area, p) in areas.iter().zip(panels) {
        let values = p.series.iter().flat_map(|s| s.1.iter().copied());
        let good: Vec<f64> = values.filter(|v| v.is_finite() && *v > 0.0).collect();
        let lo = good.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = good.iter().copied().fold(0.0, f64::max);
        let mut chart = ChartBuilder::on(area)
            .caption(&p.title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(60)
            .build_cartesian_2d(x_lo..x_hi, (lo * 0.8..hi * 1.25).log_scale())?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc(&p.y_label)
            .draw()?;
        for ((name, v), colour) in p.series.iter().zip(colours) {
            chart
                .draw_series(LineSeries::new(
                    x.iter()
                        .zip(v)
                        .filter(|(_, v)| v.is_finite() && **v > 0.0)
                        .map(|(&a, &b)| (a, b)),
                    colour,
                ))?
                .label(name)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], colour));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerLeft)
            .background_style(WHITE)
            .border_style(BLACK)
            .draw()?;
    }
    root.present()?;
    Ok(())
}
