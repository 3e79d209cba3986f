//! The plot of a filter's run, as PNG or SVG: one engine for `seqsmooth demo` and `seqsmooth
//! plot`.
//!
//! A [`Track`] holds one row per sample — time, measured value, the estimated derivatives with
//! their 1σ where determined — and what the automatic filter adds (rejected samples, the misfit
//! flag, the noise σ in use, the switch to fading memory, restarts of the memory), plus the
//! truth when it is known. [`write()`] draws, under a title and a legend row:
//!
//! - one panel per requested derivative `k`: the estimate `d_k` (line), its ±3σ band (shaded),
//!   the truth (thin black line) and, for `k = 0`, the samples (grey dots; rejected ones as red
//!   crosses);
//! - above them, one error panel per requested `k` where the truth is known: `d_k − truth_k`
//!   about zero (the truth) with its ±3σ band and, for `k = 0`, the samples' `y − truth` and
//!   ±3σ of the noise;
//! - the residual panel `y − d0`, relative to the estimate: the residuals, the estimate's ±3σ
//!   band about zero, ±3σ of the noise (dashed) where known, and `truth − d0` where known;
//!   with a lead, each estimate is compared with the sample at its own time `t + lead`;
//! - in every panel, the outages (hatched grey), the spans where the misfit flag is up
//!   (shaded pink under a solid strip along the top), the switches to fading memory (green dashed lines) and the restarts
//!   (purple lines).
//!
//! **Outages.** A step between consecutive samples longer than [`OUTAGE_STEPS`] times the
//! typical step (the median step) is an outage ([`is_outage`], [`outages`]): it is hatched, and
//! no line, band or envelope is drawn across it — every curve breaks there, as it does where
//! its value is missing.
//!
//! **Dense series.** A series with more points than the plot has pixel columns is drawn
//! decimated per pixel column ([`crate::plot::decimate`]); its samples, too many for dots, as the
//! band between each column's lowest and highest sample (an envelope, not a zig-zag line that
//! would fill it solid), and its rejected samples as small crosses, at most the lowest and
//! highest of each column, their number in the legend. `seqsmooth plot` reads its rows into a
//! [`Track`] through [`crate::plot::decimate::Reducer`], keeping per half pixel the rows that hold
//! the extremes of every quantity drawn ([`drawn`]) plus a systematic sample of rows for the
//! axis ranges' quantiles ([`Track::sampled`]). Axes whose values share many leading digits
//! or are very large or small are drawn in tick units with an offset and a power of ten, said
//! in the axis label ([`crate::plot::ticks`]).
//!
//! **Beyond the axis.** Axis ranges ignore the start-up transients of the estimates (the
//! 1st-99th percentile of the estimates widened by the truth). A value beyond the range is
//! drawn at the axis edge and marked: a clipped sample as a triangle pointing off the axis,
//! each run of a clipped line (estimate, truth, error) by such a triangle at its farthest
//! point, and the panel notes how far the line goes ("beyond the axis: …"). The PNG's text is
//! drawn with the embedded DejaVu Sans (no system fonts are read); the SVG names the family
//! `DejaVu Sans, sans-serif`.

mod panel;
mod track;

use crate::error::CliError;
use crate::plot::decimate::{envelope, min_max};
use crate::plot::ticks::Scale;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{register_font, FontStyle};
use std::path::Path;
use std::sync::OnceLock;

/// DejaVu Sans (Bitstream Vera licence, see `assets/LICENSE-DejaVu.txt`).
static FONT: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");
/// The family name the embedded font is registered under: the PNG is drawn with it; the SVG
/// names it, with the viewer's `sans-serif` where DejaVu Sans is not installed.
const FAMILY: &str = "DejaVu Sans, sans-serif";

/// The image formats, chosen by a file's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Portable Network Graphics (`.png`).
    Png,
    /// Scalable Vector Graphics (`.svg`).
    Svg,
}

impl Format {
    /// The format of `path` by its extension (case-insensitive), or `None`.
    pub fn from_path(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "png" => Some(Format::Png),
            "svg" => Some(Format::Svg),
            _ => None,
        }
    }

    /// The format of `path`, or the usage error that it has none.
    pub fn of(path: &Path) -> Result<Format, CliError> {
        Format::from_path(path).ok_or_else(|| {
            CliError::Usage(format!(
                "cannot tell the image format of '{}': the file name must end in .png or .svg",
                path.display()
            ))
        })
    }
}

/// What to draw and how to label it.
#[derive(Clone, Debug)]
pub struct Layout {
    /// Title at the top.
    pub title: String,
    /// A second line under the title (e.g. the filter's parameters); empty for none.
    pub subtitle: String,
    /// Label of the time axis, with its unit.
    pub time_label: String,
    /// The error panels `d_k − truth_k`, on top: the derivative order and the axis label.
    pub errors: Vec<(usize, String)>,
    /// The derivative panels, top to bottom: the derivative order and the axis label.
    pub panels: Vec<(usize, String)>,
    /// Label of the residual panel; `None` for no residual panel.
    pub residual_label: Option<String>,
    /// Image width and height in pixels.
    pub size: (u32, u32),
}

impl Layout {
    /// The default image height for `panels` derivative panels and an optional residual panel.
    pub fn default_height(panels: usize, residual: bool) -> u32 {
        let h = 120 + 330 * panels as u32 + if residual { 250 } else { 0 };
        h.max(400)
    }
}

/// Colours of the plot's elements.
const DATA: RGBColor = RGBColor(120, 120, 120);
const REJECTED: RGBColor = RGBColor(215, 25, 28);
const ESTIMATE: RGBColor = RGBColor(31, 90, 180);
const TRUTH: RGBColor = RGBColor(0, 0, 0);
const NOISE: RGBColor = RGBColor(230, 120, 0);
const SWITCH: RGBColor = RGBColor(0, 140, 70);
const RESTART: RGBColor = RGBColor(140, 40, 170);
const MISFIT: RGBColor = RGBColor(225, 60, 150);
const TRUTH_ERROR: RGBColor = RGBColor(0, 130, 140);
const OUTAGE: RGBColor = RGBColor(110, 110, 110);
/// Opacities of the misfit and outage shading and of a dense series' envelope.
const MISFIT_ALPHA: f64 = 0.16;
const OUTAGE_ALPHA: f64 = 0.12;
const ENVELOPE_ALPHA: f64 = 0.35;
/// Marks of values beyond the axis at most one per this many pixels along each edge.
const MARK_SPACING: i64 = 12;
/// Height in pixels of the solid strip along the top of a misfit span.
const MISFIT_STRIP: i32 = 4;

fn register() -> Result<(), CliError> {
    static DONE: OnceLock<bool> = OnceLock::new();
    let ok = *DONE.get_or_init(|| register_font(FAMILY, FontStyle::Normal, FONT).is_ok());
    let failed = || CliError::Data("the embedded font could not be loaded".into());
    ok.then_some(()).ok_or_else(failed)
}

/// Draws `track` as laid out by `layout` into `path`, as PNG or SVG by its extension.
pub fn write(track: &Track, layout: &Layout, path: &Path) -> Result<(), CliError> {
    register()?;
    let format = Format::of(path)?;
    let name = path.display();
    let fail = |e: Err| CliError::Data(format!("cannot write the plot to '{name}': {e}"));
    // Drawn into a temporary file beside `path` (with the extension that picks the encoder),
    // renamed onto it when complete: a failed plot leaves an existing file as it was. A device
    // or a named pipe is drawn into in place.
    let target = match crate::io::Destination::of(path) {
        crate::io::Destination::InPlace(device) => {
            render_into(&device, track, layout, format).map_err(fail)?;
            return Ok(());
        }
        crate::io::Destination::Replace(target) => target,
    };
    let suffix = match format {
        Format::Png => ".png",
        Format::Svg => ".svg",
    };
    let temp = crate::io::temp_beside(&target, suffix).map_err(|e| fail(e.into()))?;
    let temp = temp.into_temp_path();
    render_into(&temp, track, layout, format).map_err(fail)?;
    temp.persist(&target).map_err(|e| fail(e.error.into()))
}

/// Draws `track` into the file `path` as `format`.
fn render_into(path: &Path, track: &Track, layout: &Layout, format: Format) -> Result<(), Err> {
    macro_rules! render {
        ($backend:ident) => {{
            let root = $backend::new(path, layout.size).into_drawing_area();
            draw(&root, track, layout, format == Format::Png)?;
            root.present().map_err(|e| -> Err { e.into() })?;
        }};
    }
    match format {
        Format::Png => render!(BitMapBackend),
        Format::Svg => render!(SVGBackend),
    }
    Ok(())
}

fn font(size: f64) -> TextStyle<'static> {
    TextStyle::from((FAMILY, size).into_font()).color(&BLACK)
}

/// `[lo, hi]` widened by `pad` of its span on each side (a unit span about a single value).
fn padded((lo, hi): (f64, f64), pad: f64) -> (f64, f64) {
    let span = hi - lo;
    if span > 0.0 {
        (lo - pad * span, hi + pad * span)
    } else {
        let w = if lo == 0.0 { 1.0 } else { 0.05 * lo.abs() };
        (lo - w, hi + w)
    }
}

/// `range` widened to take in the finite `values`.
fn widen(range: &mut Option<(f64, f64)>, values: impl IntoIterator<Item = f64>) {
    for v in values.into_iter().filter(|v| v.is_finite()) {
        *range = Some(range.map_or((v, v), |(lo, hi)| (lo.min(v), hi.max(v))));
    }
}

pub use crate::plot::ticks::tick;
use panel::{panels, PanelData};
pub use track::*;

/// The legend entries that apply.
#[derive(Clone, Copy, PartialEq)]
enum Key {
    Data,
    DataLine,
    Rejected,
    Estimate,
    Band,
    Truth,
    TruthError,
    Noise,
    Switch,
    Restart,
    Misfit,
    Outage,
    Clipped,
}

impl Key {
    fn label(self, track: &Track) -> String {
        let text = match self {
            Key::Data => "samples",
            Key::DataLine => "samples, lowest to highest per pixel (too dense for dots)",
            Key::Rejected => {
                let n = match track.counts {
                    Some(c) => c.rejected,
                    None => track.rejected.iter().filter(|&&r| r).count(),
                };
                return format!("rejected (outlier): {n}");
            }
            Key::Estimate => "estimate",
            Key::Band => "estimate ±3σ",
            Key::Truth => "truth",
            Key::TruthError => "truth − estimate",
            Key::Noise => "noise ±3σ",
            Key::Switch => "switch to fading memory",
            Key::Restart => "misfit restart",
            Key::Misfit if !track.misfit_share.is_empty() => {
                "misfit flagged (the darker, the more of the time)"
            }
            Key::Misfit => "misfit flagged",
            Key::Outage => "no samples (outage)",
            Key::Clipped => "beyond the axis (at its edge)",
        };
        text.to_string()
    }
}

/// Samples drawn as dots up to one per this many pixel columns, else as their envelope.
const DOTS_PER_PIXEL: f64 = 0.5;
/// Rejected samples drawn as large crosses up to one per this many pixel columns, else small.
const CROSSES_PER_PIXEL: f64 = 0.05;

/// Whether the panel's samples are too many for dots across `columns` pixels.
fn dense(p: &PanelData, columns: u32) -> bool {
    p.points.iter().filter(|q| !q.2).count() as f64 > DOTS_PER_PIXEL * f64::from(columns)
}

fn legend_keys(panels: &[PanelData], track: &Track, columns: u32) -> Vec<Key> {
    let any = |f: &dyn Fn(&PanelData) -> bool| panels.iter().any(f);
    let clipped = |p: &PanelData| {
        let out = |v: f64| v < p.range.0 || v > p.range.1;
        (p.clip_points && p.points.iter().any(|q| out(q.1)))
            || p.line.iter().chain(&p.truth).flatten().any(|&v| out(v))
    };
    let samples = |p: &PanelData| p.points.iter().any(|q| !q.2);
    let truth =
        |key: Key| move |p: &PanelData| p.truth_key == key && p.truth.iter().any(Option::is_some);
    [
        (any(&|p| samples(p) && !dense(p, columns)), Key::Data),
        (any(&|p| samples(p) && dense(p, columns)), Key::DataLine),
        (any(&|p| p.points.iter().any(|q| q.2)), Key::Rejected),
        (any(&clipped), Key::Clipped),
        (any(&|p| p.line.iter().any(Option::is_some)), Key::Estimate),
        (any(&|p| p.band.iter().any(Option::is_some)), Key::Band),
        (any(&truth(Key::Truth)), Key::Truth),
        (any(&truth(Key::TruthError)), Key::TruthError),
        (any(&|p| p.noise.iter().any(Option::is_some)), Key::Noise),
        (!track.switches.is_empty(), Key::Switch),
        (!track.restarts.is_empty(), Key::Restart),
        (
            !track.misfit.is_empty() || !track.misfit_share.is_empty(),
            Key::Misfit,
        ),
        (!track.outages.is_empty(), Key::Outage),
    ]
    .into_iter()
    .filter_map(|(on, key)| on.then_some(key))
    .collect()
}

/// A drawing error of either backend.
type Err = Box<dyn std::error::Error>;

/// A triangle at `$at` (a coordinate of the area drawn on) pointing up (`$up`) or down, 9
/// pixels tall: the mark of a value beyond the top or bottom of the axis.
macro_rules! edge_mark {
    ($at:expr, $up:expr, $style:expr) => {{
        let h = if $up { -9 } else { 9 };
        EmptyElement::at($at) + Polygon::new(vec![(-6, 0), (6, 0), (0, h)], $style)
    }};
}

/// Hatching of the pixel rectangle `(x0, y0)-(x1, y1)`: 45° lines `gap` pixels apart.
fn hatch((x0, y0): (i32, i32), (x1, y1): (i32, i32), gap: i32) -> Vec<[(i32, i32); 2]> {
    let (w, h) = (x1 - x0, y1 - y0);
    let mut out = Vec::new();
    // Lines x - x0 + (y - y0) = c, from the bottom-left to the top-right.
    let mut c = gap / 2;
    while c < w + h {
        let a = (x0 + (c - h).max(0), y0 + c.min(h));
        let b = (x0 + c.min(w), y0 + (c - w).max(0));
        out.push([a, b]);
        c += gap;
    }
    out
}

/// Draws the legend symbol of `key` centred at `(x, y)`.
fn symbol<DB: DrawingBackend<ErrorType: 'static>>(
    area: &DrawingArea<DB, Shift>,
    key: Key,
    (x, y): (i32, i32),
) -> Result<(), Err> {
    let seg = |a: (i32, i32), b: (i32, i32), c: RGBColor, w: u32| {
        area.draw(&PathElement::new(vec![a, b], c.stroke_width(w)))
    };
    let corners = [(x - 14, y - 7), (x + 14, y + 7)];
    let rect = |c: RGBAColor| area.draw(&Rectangle::new(corners, c.filled()));
    match key {
        Key::Data => area.draw(&Circle::new((x, y), 3, DATA.filled())),
        Key::DataLine => rect(DATA.mix(ENVELOPE_ALPHA)),
        Key::Rejected => area.draw(&Cross::new((x, y), 5, REJECTED.stroke_width(2))),
        Key::Clipped => area
            .draw(&edge_mark!((x - 7, y + 4), true, DATA.filled()))
            .and_then(|_| area.draw(&edge_mark!((x + 7, y - 4), false, DATA.filled()))),
        Key::Estimate => seg((x - 14, y), (x + 14, y), ESTIMATE, 2),
        Key::Band => rect(ESTIMATE.mix(0.22)),
        Key::Truth => seg((x - 14, y), (x + 14, y), TRUTH, 1),
        Key::TruthError => seg((x - 14, y), (x + 14, y), TRUTH_ERROR, 2),
        Key::Noise => seg((x - 14, y), (x - 4, y), NOISE, 2)
            .and_then(|_| seg((x + 4, y), (x + 14, y), NOISE, 2)),
        Key::Switch => seg((x, y - 8), (x, y - 2), SWITCH, 2)
            .and_then(|_| seg((x, y + 2), (x, y + 8), SWITCH, 2)),
        Key::Restart => seg((x, y - 8), (x, y + 8), RESTART, 2),
        Key::Misfit => rect(MISFIT.mix(MISFIT_ALPHA)).and_then(|_| {
            let strip = [(x - 14, y - 7), (x + 14, y - 7 + MISFIT_STRIP)];
            area.draw(&Rectangle::new(strip, MISFIT.filled()))
        }),
        Key::Outage => rect(OUTAGE.mix(OUTAGE_ALPHA)).and_then(|_| {
            hatch(corners[0], corners[1], 6)
                .into_iter()
                .try_for_each(|[a, b]| seg(a, b, OUTAGE, 1))
        }),
    }?;
    Ok(())
}

/// Lays the legend out in rows across `width`; returns the rows of (key, x of its symbol).
fn legend_rows<DB: DrawingBackend<ErrorType: 'static>>(
    area: &DrawingArea<DB, Shift>,
    keys: &[Key],
    track: &Track,
    width: i32,
) -> Result<Vec<Vec<(Key, i32)>>, Err> {
    let style = font(15.0);
    // Each row's items (key, x from the row's start) and width.
    let mut rows: Vec<(Vec<(Key, i32)>, i32)> = vec![(Vec::new(), 0)];
    for &k in keys {
        let item = 32 + area.estimate_text_size(&k.label(track), &style)?.0 as i32 + 18;
        if rows
            .last()
            .is_some_and(|(row, w)| w + item > width - 40 && !row.is_empty())
        {
            rows.push((Vec::new(), 0));
        }
        if let Some((row, w)) = rows.last_mut() {
            row.push((k, *w));
            *w += item;
        }
    }
    // centre each row
    for (row, w) in &mut rows {
        row.iter_mut().for_each(|item| item.1 += (width - *w) / 2);
    }
    Ok(rows.into_iter().map(|(row, _)| row).collect())
}

/// The plot width in pixels (the image less the axis label area and margins).
fn plot_columns(layout: &Layout) -> u32 {
    columns_for_width(layout.size.0)
}

/// The plot's width in pixel columns in an image `width` pixels wide (less the axis label
/// area and margins).
pub fn columns_for_width(width: u32) -> u32 {
    width.saturating_sub(130).max(1)
}

fn draw<DB: DrawingBackend<ErrorType: 'static>>(
    root: &DrawingArea<DB, Shift>,
    track: &Track,
    layout: &Layout,
    split: bool,
) -> Result<(), Err> {
    root.fill(&WHITE)?;
    let (width, height) = (layout.size.0 as i32, layout.size.1 as i32);
    let panels = panels(track, layout);
    let keys = legend_keys(&panels, track, plot_columns(layout));

    // Title, subtitle, legend.
    let mut y = 12;
    let top = Pos::new(HPos::Center, VPos::Top);
    root.draw_text(&layout.title, &font(24.0).pos(top), (width / 2, y))?;
    y += 32;
    if !layout.subtitle.is_empty() {
        let sub = font(15.0).color(&RGBColor(70, 70, 70)).pos(top);
        root.draw_text(&layout.subtitle, &sub, (width / 2, y))?;
        y += 24;
    }
    y += 6;
    let label_style = font(15.0).pos(Pos::new(HPos::Left, VPos::Center));
    for row in legend_rows(root, &keys, track, width)? {
        let cy = y + 11;
        for (key, x) in row {
            symbol(root, key, (x + 14, cy))?;
            root.draw_text(&key.label(track), &label_style, (x + 32, cy))?;
        }
        y += 26;
    }
    y += 6;

    // Panels: derivative panels weigh 1, the residual and error panels 0.7 (1 when they are
    // the only ones); the bottom one carries the time axis label.
    let (_, mut rest) = root.split_vertically(y);
    let residual = |p: &PanelData| p.clip_points && p.truth_key == Key::TruthError;
    let weight = |p: &PanelData| if residual(p) { 0.7 } else { 1.0 };
    let total: f64 = panels.iter().map(weight).sum();
    // The height less the bottom panel's time axis.
    let usable = (height - y) as f64 - 30.0;
    let mut xr = None;
    widen(&mut xr, track.t.iter().flat_map(|&t| [t, t + track.lead]));
    let (x0, x1) = padded(xr.unwrap_or((0.0, 1.0)), 0.01);
    let x = Scale::for_range(x0, x1, track.t.first().copied());
    let last = panels.len().saturating_sub(1);
    for (idx, panel) in panels.iter().enumerate() {
        let area = if idx == last {
            rest.clone()
        } else {
            let h = (usable * weight(panel) / total).round() as i32;
            let (top, bottom) = rest.split_vertically(h);
            rest = bottom;
            top
        };
        let note = x.note("t");
        let x_desc = if note.is_empty() {
            layout.time_label.clone()
        } else {
            format!("{}; {note}", layout.time_label)
        };
        let axis = Axis {
            scale: x.clone(),
            range: (x0, x1),
            desc: (idx == last).then_some(x_desc),
        };
        draw_panel(&area, track, panel, &axis, split)?;
    }
    Ok(())
}

/// A polyline, with `split` as its segments, each drawn on its own: the bitmap backend fills a
/// wider-than-1 polyline as one polygon, which a dense zig-zag turns into holes and spikes; a
/// segment is a simple quadrilateral. (An SVG viewer strokes the polyline itself.)
fn segments(pts: Vec<(f64, f64)>, style: ShapeStyle, split: bool) -> Vec<PathElement<(f64, f64)>> {
    if !split || style.stroke_width <= 1 || pts.len() < 3 {
        return vec![PathElement::new(pts, style)];
    }
    pts.windows(2)
        .map(|w| PathElement::new(w.to_vec(), style))
        .collect()
}

/// The time axis: its scale, its range (in time units) and, on the bottom panel, its label.
struct Axis {
    scale: Scale,
    range: (f64, f64),
    desc: Option<String>,
}

fn draw_panel<DB: DrawingBackend<ErrorType: 'static>>(
    area: &DrawingArea<DB, Shift>,
    track: &Track,
    p: &PanelData,
    axis: &Axis,
    split: bool,
) -> Result<(), Err> {
    let bottom = axis.desc.is_some();
    let (y0, y1) = p.range;
    let ys = Scale::for_range(y0, y1, None);
    let (xs, (x0, x1)) = (&axis.scale, axis.range);
    let (ax, ay) = (|t: f64| xs.to_axis(t), |v: f64| ys.to_axis(v));
    let mut chart = ChartBuilder::on(area)
        .margin_left(10)
        .margin_right(25)
        .margin_top(8)
        .margin_bottom(if bottom { 8 } else { 4 })
        .x_label_area_size(if bottom { 55 } else { 28 })
        .y_label_area_size(95)
        .build_cartesian_2d(ax(x0)..ax(x1), ay(y0)..ay(y1))?;
    let (x_step, y_step) = ((ax(x1) - ax(x0)) / 10.0, (ay(y1) - ay(y0)) / 6.0);
    let x_fmt = move |v: &f64| tick(*v, x_step);
    let y_fmt = move |v: &f64| tick(*v, y_step);
    let note = ys.note("value");
    let y_desc = if note.is_empty() {
        p.label.clone()
    } else {
        format!("{}; {note}", p.label)
    };
    let mut mesh = chart.configure_mesh();
    mesh.x_labels(10)
        .y_labels(6)
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .label_style(font(14.0))
        .axis_desc_style(font(16.0))
        .max_light_lines(2)
        .light_line_style(RGBColor(242, 242, 242))
        .bold_line_style(RGBColor(215, 215, 215))
        .y_desc(y_desc);
    if let Some(desc) = &axis.desc {
        mesh.x_desc(desc.as_str());
    }
    mesh.draw()?;

    let n = track.t.len();
    let columns = chart.plotting_area().dim_in_pixel().0.max(1);
    let span = (ax(x0), ax(x1));
    let thin = |pts: Vec<(f64, f64)>| min_max(&pts, span, columns as usize);
    let clamp = |v: f64| ay(v.clamp(y0, y1));
    let (top, floor) = (ay(y1), ay(y0));
    let shade =
        |a: f64, b: f64, c: RGBAColor| Rectangle::new([(ax(a), top), (ax(b), floor)], c.filled());
    let spec = chart.as_coord_spec().clone();
    let pixel = |x: f64, y: f64| spec.translate(&(x, y));

    // Outages (hatched), then the misfit spans.
    let area = chart.plotting_area().strip_coord_spec();
    let base = chart.plotting_area().get_base_pixel();
    for &(a, b) in &track.outages {
        chart.draw_series([shade(a, b, OUTAGE.mix(OUTAGE_ALPHA))])?;
        let (p0, p1) = (pixel(ax(a), top), pixel(ax(b), floor));
        let local = |p: (i32, i32)| (p.0 - base.0, p.1 - base.1);
        for [u, v] in hatch(local(p0), local(p1), 8) {
            area.draw(&PathElement::new(
                vec![u, v],
                OUTAGE.mix(0.5).stroke_width(1),
            ))?;
        }
    }
    // A decimated track's misfit: per pixel column, the share of its time flagged (in
    // tenths), shaded the darker the more, with the strip where it is at least half.
    let shares = misfit_columns(&track.misfit_share, span, columns as usize, &ax);
    for (a, b, share) in shares {
        let tint = MISFIT.mix(MISFIT_ALPHA * (0.25 + 0.75 * share));
        chart.draw_series([Rectangle::new([(a, top), (b, floor)], tint.filled())])?;
        if share >= 0.5 {
            let (p0, p1) = (pixel(a, top), pixel(b, top));
            let local = |p: (i32, i32)| (p.0 - base.0, p.1 - base.1);
            let (u, v) = (local(p0), local(p1));
            let strip = [u, (v.0.max(u.0 + 1), v.1 + MISFIT_STRIP)];
            area.draw(&Rectangle::new(strip, MISFIT.filled()))?;
        }
    }
    for &(a, b) in &track.misfit {
        chart.draw_series([shade(a, b, MISFIT.mix(MISFIT_ALPHA))])?;
        let (p0, p1) = (pixel(ax(a), top), pixel(ax(b), top));
        let local = |p: (i32, i32)| (p.0 - base.0, p.1 - base.1);
        let (u, v) = (local(p0), local(p1));
        let strip = [u, (v.0.max(u.0 + 1), v.1 + MISFIT_STRIP)];
        area.draw(&Rectangle::new(strip, MISFIT.filled()))?;
    }

    // The runs of rows where `keep` holds, broken at the outages.
    let after = breaks(track);
    let runs_of = |keep: &dyn Fn(usize) -> bool| split_runs(runs(n, keep), &after);

    // ±3σ band: each edge decimated on its own.
    for r in runs_of(&|i| p.line[i].is_some() && p.band[i].is_some()) {
        let edge = |sign: f64| {
            let at = |i: usize| {
                let (l, b) = (p.line[i].unwrap_or(0.0), p.band[i].unwrap_or(0.0));
                (ax(track.t[i] + p.shift), clamp(l + sign * b))
            };
            thin(r.clone().map(at).collect())
        };
        let mut poly = edge(1.0);
        poly.extend(edge(-1.0).into_iter().rev());
        chart.draw_series([Polygon::new(poly, ESTIMATE.mix(0.22).filled())])?;
    }

    // The runs of a row-wise curve, `sign` times its values, at the times moved by `shift`,
    // decimated to the pixel columns.
    let curves = |v: &[Option<f64>], shift: f64, sign: f64| -> Vec<Vec<(f64, f64)>> {
        runs_of(&|i| v[i].is_some())
            .into_iter()
            .map(|r| {
                let at = |i: usize| (ax(track.t[i] + shift), clamp(sign * v[i].unwrap_or(0.0)));
                thin(r.map(at).collect())
            })
            .collect()
    };

    // ±3σ noise (dashed).
    for sign in [1.0, -1.0] {
        for pts in curves(&p.noise, 0.0, sign) {
            chart.draw_series(DashedLineSeries::new(pts, 7, 5, NOISE.stroke_width(2)))?;
        }
    }

    // Samples: dots, or too many for dots, the envelope of the accepted ones between the
    // outages; those beyond the axis as triangles at its edge, one per pixel column and edge.
    let inside = |v: f64| v >= y0 && v <= y1;
    let column = |x: f64| {
        let c = (ax(x) - span.0) / (span.1 - span.0) * f64::from(columns);
        c.floor() as i64
    };
    if dense(p, columns) {
        let accepted: Vec<(f64, f64)> = p
            .points
            .iter()
            .filter(|q| !q.2)
            .map(|q| (ax(q.0), clamp(q.1)))
            .collect();
        let gaps: Vec<(f64, f64)> = track.outages.iter().map(|o| (ax(o.0), ax(o.1))).collect();
        for poly in envelope(&accepted, span, columns as usize, &gaps) {
            chart.draw_series([Polygon::new(
                poly.clone(),
                DATA.mix(ENVELOPE_ALPHA).filled(),
            )])?;
            let mut outline = poly;
            outline.push(outline[0]);
            chart.draw_series([PathElement::new(outline, DATA.mix(0.6).stroke_width(1))])?;
        }
    } else {
        let dots = p.points.iter().filter(|q| !q.2 && inside(q.1));
        chart.draw_series(dots.map(|q| Circle::new((ax(q.0), ay(q.1)), 2, DATA.filled())))?;
    }
    // Samples beyond the axis: sparse, a mark each (one per MARK_SPACING pixels and edge);
    // dense, where the envelope runs into the edges of a range made of quantiles, the share
    // of them in a note (of the sampled rows: a decimated track keeps every extreme).
    let mut notes = Vec::new();
    if p.clip_points && dense(p, columns) {
        for (rejected, what) in [(false, "samples"), (true, "rejected samples")] {
            let sampled = || {
                let rows = p.point_rows.iter().zip(&p.points);
                rows.filter(|(k, q)| p.sampled[**k] && q.2 == rejected)
                    .map(|(_, q)| q)
            };
            let all = sampled().count();
            let out = sampled().filter(|q| !inside(q.1)).count();
            if out > 0 {
                let share = 100.0 * out as f64 / all.max(1) as f64;
                notes.push(format!("about {share:.1} % of the {what}"));
            }
        }
    } else if p.clip_points {
        // One mark per MARK_SPACING pixels and edge.
        let mut marked = std::collections::HashSet::new();
        let beyond = p.points.iter().filter(|q| !inside(q.1));
        let marks = beyond.filter(|q| marked.insert((column(q.0) / MARK_SPACING, q.1 > y1)));
        let marks: Vec<_> = marks
            .map(|q| edge_mark!((ax(q.0), clamp(q.1)), q.1 > y1, DATA.filled()))
            .collect();
        chart.draw_series(marks)?;
    }

    // Rejected samples: large crosses on top, or when many, small translucent ones, at most
    // the lowest and highest of each pixel column, under the estimate (which they would hide
    // where the value's range dwarfs the noise).
    let rejected: Vec<(f64, f64)> = p
        .points
        .iter()
        .filter(|q| q.2)
        .map(|q| (ax(q.0), clamp(q.1)))
        .collect();
    let many = rejected.len() as f64 > CROSSES_PER_PIXEL * f64::from(columns);
    if many {
        let kept = thin(rejected.clone());
        let style = REJECTED.mix(0.7).stroke_width(1);
        chart.draw_series(kept.into_iter().map(|q| Cross::new(q, 3, style)))?;
    }

    // Truth, then the estimate over it; each run beyond the axis marked at its farthest point.
    let truth_style = match p.truth_key {
        Key::TruthError => TRUTH_ERROR.stroke_width(2),
        _ => TRUTH.stroke_width(1),
    };
    for (v, shift, style, name, colour) in [
        (
            &p.truth,
            p.truth_shift,
            truth_style,
            p.truth_key.label(track),
            if p.truth_key == Key::TruthError {
                TRUTH_ERROR
            } else {
                TRUTH
            },
        ),
        (
            &p.line,
            p.shift,
            ESTIMATE.stroke_width(2),
            p.line_name.to_string(),
            ESTIMATE,
        ),
    ] {
        for pts in curves(v, shift, 1.0) {
            chart.draw_series(segments(pts, style, split))?;
        }
        let mut last_mark: Option<(i32, bool)> = None;
        let mut far: [Option<(f64, f64)>; 2] = [None, None];
        for r in runs_of(&|i| v[i].is_some_and(|v| !inside(v))) {
            let (i, value) = r
                .map(|i| (i, v[i].unwrap_or(0.0)))
                .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
                .unwrap_or((0, 0.0));
            let up = value > y1;
            let at = (ax(track.t[i] + shift), clamp(value));
            let x = pixel(at.0, at.1).0;
            if last_mark.is_none_or(|(px, pu)| pu != up || (x - px).abs() >= MARK_SPACING as i32) {
                chart.draw_series([edge_mark!(at, up, colour.filled())])?;
                last_mark = Some((x, up));
            }
            let slot = &mut far[usize::from(up)];
            if slot.is_none_or(|(_, f)| value.abs() > f.abs()) {
                *slot = Some((track.t[i] + shift, value));
            }
        }
        let reach: Vec<String> = far
            .iter()
            .flatten()
            .map(|&(t, v)| format!("{} at t = {}", significant(v), significant(t)))
            .collect();
        if !reach.is_empty() {
            notes.push(format!("{name} reaches {}", reach.join(" and ")));
        }
    }

    if !many {
        let style = REJECTED.stroke_width(2);
        chart.draw_series(rejected.into_iter().map(|q| Cross::new(q, 5, style)))?;
    }

    // Events: switches to fading memory (dashed), restarts.
    let edge = |t: f64| vec![(ax(t), top), (ax(t), floor)];
    for &t in &track.switches {
        chart.draw_series(DashedLineSeries::new(edge(t), 8, 6, SWITCH.stroke_width(2)))?;
    }
    for &t in &track.restarts {
        chart.draw_series(LineSeries::new(edge(t), RESTART.stroke_width(2)))?;
    }

    // What lies beyond the axis, in the panel's top left corner.
    if !notes.is_empty() {
        let text = format!("beyond the axis: {}", notes.join("; "));
        let style = font(13.0).color(&RGBColor(60, 60, 60));
        let (w, h) = area.estimate_text_size(&text, &style)?;
        let (w, h) = (w as i32, h as i32);
        area.draw(&Rectangle::new(
            [(4, 4), (12 + w, 10 + h)],
            WHITE.mix(0.85).filled(),
        ))?;
        area.draw_text(&text, &style, (8, 7))?;
    }
    Ok(())
}

/// The pixel columns (of `columns` across the axis span `span`) that `shares` (spans of
/// time, each with the share of it flagged) cover: runs of columns of the same share in
/// tenths, as `(from, to, share)` in axis units, the share of each column the mean over it.
fn misfit_columns(
    shares: &[(f64, f64, f64)],
    span: (f64, f64),
    columns: usize,
    ax: &dyn Fn(f64) -> f64,
) -> Vec<(f64, f64, f64)> {
    let w = (span.1 - span.0) / columns.max(1) as f64;
    if shares.is_empty() || w.is_nan() || w <= 0.0 {
        return Vec::new();
    }
    let mut col = vec![0.0; columns];
    for &(a, b, s) in shares {
        let (xa, xb) = (ax(a), ax(b));
        let c0 = ((xa - span.0) / w).floor().max(0.0) as usize;
        let c1 = (((xb - span.0) / w).ceil().max(0.0) as usize).min(columns);
        for (c, v) in col.iter_mut().enumerate().take(c1).skip(c0) {
            let lo = span.0 + c as f64 * w;
            *v += s * (xb.min(lo + w) - xa.max(lo)).max(0.0) / w;
        }
    }
    // in tenths, any flagged time at least one: however little, it shows
    let tenths = |v: f64| {
        let t = (v.min(1.0) * 10.0).round() as u8;
        if v > 0.0 {
            t.max(1)
        } else {
            0
        }
    };
    let mut out = Vec::new();
    let mut c = 0;
    while c < columns {
        let level = tenths(col[c]);
        let end = (c..columns)
            .find(|&e| tenths(col[e]) != level)
            .unwrap_or(columns);
        if level > 0 {
            let x = |c: usize| span.0 + c as f64 * w;
            out.push((x(c), x(end), f64::from(level) / 10.0));
        }
        c = end;
    }
    out
}

/// `x` to four significant digits.
fn significant(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let a = x.abs();
    if (1e-3..1e6).contains(&a) {
        let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.3e}")
    }
}
