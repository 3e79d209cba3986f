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
//! - the residual panel `y − d0`, relative to the estimate: the residuals, the estimate's ±3σ
//!   band about zero, ±3σ of the noise (dashed) where known, and `truth − d0` where known;
//! - in every panel, the spans where the misfit flag is up (shaded orange), the switches to
//!   fading memory (green dashed lines) and the restarts (purple lines).
//!
//! Axis ranges ignore the start-up transients of the estimates (the 1st-99th percentile of the
//! estimates widened by the truth); a residual or band beyond the range is clipped to its edge,
//! where a clipped residual is drawn as a triangle. Text is drawn with the embedded DejaVu Sans
//! (no system fonts are read).

use crate::error::CliError;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{register_font, FontStyle};
use std::path::Path;
use std::sync::OnceLock;

/// DejaVu Sans (Bitstream Vera licence, see `assets/LICENSE-DejaVu.txt`).
static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");
/// The family name the embedded font is registered under.
const FAMILY: &str = "sans-serif";

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

/// The rows of a filter run, column by column (every vector has one entry per row).
#[derive(Clone, Debug, Default)]
pub struct Track {
    /// Sample times.
    pub t: Vec<f64>,
    /// Measured values.
    pub y: Vec<f64>,
    /// `d[k][i]`: the `k`-th derivative estimated at row `i`, where determined.
    pub d: Vec<Vec<Option<f64>>>,
    /// `s[k][i]`: its 1σ, where known (`s[k]` may be missing or empty: no band).
    pub s: Vec<Vec<Option<f64>>>,
    /// `truth[k][i]`: the true `k`-th derivative (`truth[k]` empty or missing: unknown).
    pub truth: Vec<Vec<f64>>,
    /// The noise σ in use at each row (empty: unknown).
    pub noise: Vec<Option<f64>>,
    /// Whether each row's sample was rejected as an outlier (empty: no such column).
    pub rejected: Vec<bool>,
    /// Whether the misfit flag is up at each row (empty: no such column).
    pub misfit: Vec<bool>,
    /// Times at which the output switched from expanding to fading memory.
    pub switches: Vec<f64>,
    /// Times at which the memory was restarted on misfit.
    pub restarts: Vec<f64>,
    /// The estimates are valid at `t + lead` (the residual panel needs `lead = 0`).
    pub lead: f64,
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
const MISFIT: RGBColor = RGBColor(255, 170, 60);

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
    // renamed onto it when complete: a failed plot leaves an existing file as it was.
    let suffix = match format {
        Format::Png => ".png",
        Format::Svg => ".svg",
    };
    let temp = crate::io::temp_beside(path, suffix).map_err(|e| fail(e.into()))?;
    let temp = temp.into_temp_path();
    macro_rules! render {
        ($backend:ident) => {{
            let root = $backend::new(&temp, layout.size).into_drawing_area();
            draw(&root, track, layout).map_err(fail)?;
            root.present().map_err(|e| fail(e.into()))?;
        }};
    }
    match format {
        Format::Png => render!(BitMapBackend),
        Format::Svg => render!(SVGBackend),
    }
    temp.persist(path).map_err(|e| fail(e.error.into()))
}

fn font(size: f64) -> TextStyle<'static> {
    TextStyle::from((FAMILY, size).into_font()).color(&BLACK)
}

/// The value `p`-quantile of the finite `values` (nearest rank), if any.
fn quantile(values: impl IntoIterator<Item = f64>, p: f64) -> Option<f64> {
    let mut values: Vec<f64> = values.into_iter().collect();
    values.sort_by(f64::total_cmp);
    let k = (values.len().saturating_sub(1) as f64 * p).round() as usize;
    values.get(k).copied()
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

/// Maximal runs of consecutive indices where `keep` holds.
pub fn runs(n: usize, keep: impl Fn(usize) -> bool) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut start = None;
    for i in 0..=n {
        match (i < n && keep(i), start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                out.push(s..i);
                start = None;
            }
            _ => {}
        }
    }
    out
}

/// Tick label text with the decimals the axis step needs.
pub fn tick(v: f64, step: f64) -> String {
    let decimals = if step > 0.0 && step.is_finite() {
        (-(step.log10().floor()) as i32).clamp(0, 8) as usize
    } else {
        2
    };
    let s = format!("{v:.decimals$}");
    // "-0" and "-0.0" read as noise
    let unsigned = s.trim_start_matches('-');
    if unsigned.chars().all(|c| c == '0' || c == '.') {
        unsigned.to_string()
    } else {
        s
    }
}

/// One panel's y data, relative to the estimate for the residual panel.
struct PanelData {
    label: String,
    /// Points: (time, value, rejected).
    points: Vec<(f64, f64, bool)>,
    /// The centre line (the estimate, or zero) by row.
    line: Vec<Option<f64>>,
    /// The ±3σ half-width by row.
    band: Vec<Option<f64>>,
    /// The truth (or truth − estimate) by row.
    truth: Vec<Option<f64>>,
    /// ±3σ noise lines by row.
    noise: Vec<Option<f64>>,
    /// The x offset of the line, band and truth (the lead).
    shift: f64,
    range: (f64, f64),
    /// Clip points beyond the range to the edge (residual panel).
    clip_points: bool,
}

/// The panel of derivative `k`, or for `k = None` the residual panel, whose values are
/// relative to the estimate `d0` (the rows without one are left out).
fn panel(track: &Track, k: Option<usize>, label: &str) -> PanelData {
    let (n, j) = (track.t.len(), k.unwrap_or(0));
    let cell = |v: &[Vec<Option<f64>>], i: usize| v.get(j).and_then(|v| v.get(i)).copied()?;
    let base = |i: usize| k.map_or_else(|| cell(&track.d, i), |_| Some(0.0));
    let rejected = |i: usize| track.rejected.get(i) == Some(&true);
    let points = (0..n)
        .filter(|_| k.unwrap_or(0) == 0)
        .filter_map(|i| base(i).map(|b| (track.t[i], track.y[i] - b, rejected(i))))
        .collect();
    let rows = |f: &dyn Fn(usize, f64) -> Option<f64>| -> Vec<Option<f64>> {
        (0..n).map(|i| base(i).and_then(|b| f(i, b))).collect()
    };
    let truth = |i: usize| track.truth.get(j).and_then(|x| x.get(i)).copied();
    let noise = |i: usize| {
        track
            .noise
            .get(i)
            .copied()
            .flatten()
            .filter(|_| k.is_none())
    };
    let mut p = PanelData {
        label: label.to_string(),
        points,
        line: rows(&|i, b| cell(&track.d, i).map(|d| d - b)),
        band: rows(&|i, _| cell(&track.s, i).map(|s| 3.0 * s)),
        truth: rows(&|i, b| truth(i).map(|x| x - b)),
        noise: (0..n).map(|i| noise(i).map(|s| 3.0 * s)).collect(),
        shift: if k.is_some() { track.lead } else { 0.0 },
        range: (0.0, 1.0),
        clip_points: k.is_none(),
    };
    p.range = if p.clip_points {
        p.residual_range()
    } else {
        p.derivative_range()
    };
    p
}

impl PanelData {
    /// Every sample, the truth, and the central 98% of the estimates (start-up transients of
    /// the higher derivatives would squash the panel).
    fn derivative_range(&self) -> (f64, f64) {
        let (line, band) = (&self.line, &self.band);
        let mut range = None;
        widen(&mut range, self.points.iter().map(|p| p.1));
        widen(&mut range, self.truth.iter().flatten().copied());
        let est = || line.iter().flatten().copied().filter(|v| v.is_finite());
        if let (Some(lo), Some(hi)) = (quantile(est(), 0.01), quantile(est(), 0.99)) {
            widen(&mut range, [lo, hi]);
        }
        // The band where it is no wider than the spread of the panel (not at start-up).
        if let Some((lo, hi)) = range {
            let span = (hi - lo).max(f64::MIN_POSITIVE);
            if let Some(h) = quantile(band.iter().flatten().copied(), 0.9) {
                if h < 0.25 * span {
                    for (l, b) in line.iter().zip(band) {
                        if let (Some(l), Some(b)) = (l, b) {
                            if *b <= h {
                                widen(&mut range, [l - b, l + b]);
                            }
                        }
                    }
                }
            }
        }
        padded(range.unwrap_or((0.0, 1.0)), 0.05)
    }

    /// Symmetric: the 99th percentile of |residual| of the accepted samples, every rejected one
    /// up to twice that, the ±3σ noise and the settled band, the truth's error.
    fn residual_range(&self) -> (f64, f64) {
        let points = &self.points;
        let q = |v: &mut dyn Iterator<Item = f64>, p| quantile(v, p).unwrap_or(0.0);
        let mut r = q(&mut points.iter().filter(|p| !p.2).map(|p| p.1.abs()), 0.99)
            .max(q(&mut self.noise.iter().flatten().copied(), 0.9))
            .max(q(&mut self.band.iter().flatten().copied(), 0.9))
            .max(q(&mut self.truth.iter().flatten().map(|e| e.abs()), 0.99));
        let cap = 2.0 * r;
        for p in points.iter().filter(|p| p.2) {
            r = r.max(p.1.abs().min(cap));
        }
        if r <= 0.0 || !r.is_finite() {
            r = 1.0;
        }
        (-1.08 * r, 1.08 * r)
    }
}

/// The legend entries that apply.
#[derive(Clone, Copy, PartialEq)]
enum Key {
    Data,
    Rejected,
    Estimate,
    Band,
    Truth,
    Noise,
    Switch,
    Restart,
    Misfit,
    Clipped,
}

impl Key {
    fn label(self) -> &'static str {
        match self {
            Key::Data => "samples",
            Key::Rejected => "rejected (outlier)",
            Key::Estimate => "estimate",
            Key::Band => "estimate ±3σ",
            Key::Truth => "truth",
            Key::Noise => "noise ±3σ",
            Key::Switch => "switch to fading memory",
            Key::Restart => "misfit restart",
            Key::Misfit => "misfit flagged",
            Key::Clipped => "beyond the axis",
        }
    }
}

fn legend_keys(panels: &[PanelData], track: &Track) -> Vec<Key> {
    let any = |f: &dyn Fn(&PanelData) -> bool| panels.iter().any(f);
    let clipped = |p: &PanelData| {
        p.clip_points && p.points.iter().any(|q| q.1 < p.range.0 || q.1 > p.range.1)
    };
    [
        (any(&|p| p.points.iter().any(|q| !q.2)), Key::Data),
        (any(&|p| p.points.iter().any(|q| q.2)), Key::Rejected),
        (any(&clipped), Key::Clipped),
        (any(&|p| p.line.iter().any(Option::is_some)), Key::Estimate),
        (any(&|p| p.band.iter().any(Option::is_some)), Key::Band),
        (any(&|p| p.truth.iter().any(Option::is_some)), Key::Truth),
        (any(&|p| p.noise.iter().any(Option::is_some)), Key::Noise),
        (!track.switches.is_empty(), Key::Switch),
        (!track.restarts.is_empty(), Key::Restart),
        (track.misfit.iter().any(|&m| m), Key::Misfit),
    ]
    .into_iter()
    .filter_map(|(on, key)| on.then_some(key))
    .collect()
}

/// A drawing error of either backend.
type Err = Box<dyn std::error::Error>;

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
        Key::Rejected => area.draw(&Cross::new((x, y), 5, REJECTED.stroke_width(2))),
        Key::Clipped => area.draw(&TriangleMarker::new((x, y), 5, DATA.filled())),
        Key::Estimate => seg((x - 14, y), (x + 14, y), ESTIMATE, 2),
        Key::Band => rect(ESTIMATE.mix(0.22)),
        Key::Truth => seg((x - 14, y), (x + 14, y), TRUTH, 1),
        Key::Noise => seg((x - 14, y), (x - 4, y), NOISE, 2)
            .and_then(|_| seg((x + 4, y), (x + 14, y), NOISE, 2)),
        Key::Switch => seg((x, y - 8), (x, y - 2), SWITCH, 2)
            .and_then(|_| seg((x, y + 2), (x, y + 8), SWITCH, 2)),
        Key::Restart => seg((x, y - 8), (x, y + 8), RESTART, 2),
        Key::Misfit => rect(MISFIT.mix(0.3)),
    }?;
    Ok(())
}

/// Lays the legend out in rows across `width`; returns the rows of (key, x of its symbol).
fn legend_rows<DB: DrawingBackend<ErrorType: 'static>>(
    area: &DrawingArea<DB, Shift>,
    keys: &[Key],
    width: i32,
) -> Result<Vec<Vec<(Key, i32)>>, Err> {
    let style = font(15.0);
    // Each row's items (key, x from the row's start) and width.
    let mut rows: Vec<(Vec<(Key, i32)>, i32)> = vec![(Vec::new(), 0)];
    for &k in keys {
        let item = 32 + area.estimate_text_size(k.label(), &style)?.0 as i32 + 18;
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

fn draw<DB: DrawingBackend<ErrorType: 'static>>(
    root: &DrawingArea<DB, Shift>,
    track: &Track,
    layout: &Layout,
) -> Result<(), Err> {
    root.fill(&WHITE)?;
    let (width, height) = (layout.size.0 as i32, layout.size.1 as i32);

    // The derivative panels, then the residual panel.
    let derivatives = layout.panels.iter().map(|(k, label)| (Some(*k), label));
    let residuals = layout.residual_label.iter().map(|label| (None, label));
    let panels: Vec<PanelData> = derivatives
        .chain(residuals)
        .map(|(k, label)| panel(track, k, label))
        .collect();
    let keys = legend_keys(&panels, track);

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
    for row in legend_rows(root, &keys, width)? {
        let cy = y + 11;
        for (key, x) in row {
            symbol(root, key, (x + 14, cy))?;
            root.draw_text(key.label(), &label_style, (x + 32, cy))?;
        }
        y += 26;
    }
    y += 6;

    // Panels: derivative panels weigh 1, the residual panel 0.7; the bottom one carries the
    // time axis label.
    let (_, mut rest) = root.split_vertically(y);
    let weight = |p: &PanelData| if p.clip_points { 0.7 } else { 1.0 };
    let total: f64 = panels.iter().map(weight).sum();
    // The height less the bottom panel's time axis.
    let usable = (height - y) as f64 - 30.0;
    let mut xr = None;
    widen(&mut xr, track.t.iter().flat_map(|&t| [t, t + track.lead]));
    let x_range = padded(xr.unwrap_or((0.0, 1.0)), 0.01);
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
        let x_desc = (idx == last).then_some(layout.time_label.as_str());
        draw_panel(&area, track, panel, x_range, x_desc)?;
    }
    Ok(())
}

fn draw_panel<DB: DrawingBackend<ErrorType: 'static>>(
    area: &DrawingArea<DB, Shift>,
    track: &Track,
    p: &PanelData,
    (x0, x1): (f64, f64),
    x_desc: Option<&str>,
) -> Result<(), Err> {
    let bottom = x_desc.is_some();
    let (y0, y1) = p.range;
    let mut chart = ChartBuilder::on(area)
        .margin_left(10)
        .margin_right(25)
        .margin_top(8)
        .margin_bottom(if bottom { 8 } else { 4 })
        .x_label_area_size(if bottom { 55 } else { 28 })
        .y_label_area_size(95)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    let (x_step, y_step) = ((x1 - x0) / 10.0, (y1 - y0) / 6.0);
    let x_fmt = move |v: &f64| tick(*v, x_step);
    let y_fmt = move |v: &f64| tick(*v, y_step);
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
        .y_desc(p.label.clone());
    if let Some(desc) = x_desc {
        mesh.x_desc(desc);
    }
    mesh.draw()?;

    let n = track.t.len();
    let clamp = |v: f64| v.clamp(y0, y1);

    // Misfit spans: from each flagged row to the next row.
    if track.misfit.len() == n {
        for r in runs(n, |i| track.misfit[i]) {
            let a = track.t[r.start];
            let b = track.t[r.end.min(n - 1)].max(a);
            let span = Rectangle::new([(a, y0), (b, y1)], MISFIT.mix(0.3).filled());
            chart.draw_series([span])?;
        }
    }

    // ±3σ band.
    for r in runs(n, |i| p.line[i].is_some() && p.band[i].is_some()) {
        let edge = |i: usize, sign: f64| {
            let (l, b) = (p.line[i].unwrap_or(0.0), p.band[i].unwrap_or(0.0));
            (track.t[i] + p.shift, clamp(l + sign * b))
        };
        let poly: Vec<(f64, f64)> = (r.clone().map(|i| edge(i, 1.0)))
            .chain(r.rev().map(|i| edge(i, -1.0)))
            .collect();
        chart.draw_series([Polygon::new(poly, ESTIMATE.mix(0.22).filled())])?;
    }

    // The runs of a row-wise curve, `sign` times its values, at the times moved by `shift`.
    let curves = |v: &[Option<f64>], shift: f64, sign: f64| -> Vec<Vec<(f64, f64)>> {
        runs(n, |i| v[i].is_some())
            .into_iter()
            .map(|r| {
                r.map(|i| (track.t[i] + shift, clamp(sign * v[i].unwrap_or(0.0))))
                    .collect()
            })
            .collect()
    };

    // ±3σ noise (dashed).
    for sign in [1.0, -1.0] {
        for pts in curves(&p.noise, 0.0, sign) {
            chart.draw_series(DashedLineSeries::new(pts, 7, 5, NOISE.stroke_width(2)))?;
        }
    }

    // Samples: the points `$keep` picks, as `$shape`s at their values clamped to the range.
    let inside = |v: f64| v >= y0 && v <= y1;
    macro_rules! points {
        ($keep:expr, $shape:ident, $size:expr, $style:expr) => {
            let at = |q: &(f64, f64, bool)| (q.0, clamp(q.1));
            let shapes = p
                .points
                .iter()
                .filter($keep)
                .map(|q| $shape::new(at(q), $size, $style));
            chart.draw_series(shapes)?;
        };
    }
    points!(|q| !q.2 && inside(q.1), Circle, 2, DATA.filled());
    if p.clip_points {
        points!(|q| !inside(q.1), TriangleMarker, 5, DATA.filled());
    }

    // Truth, then the estimate over it.
    for (v, style) in [
        (&p.truth, TRUTH.stroke_width(1)),
        (&p.line, ESTIMATE.stroke_width(2)),
    ] {
        for pts in curves(v, p.shift, 1.0) {
            chart.draw_series(LineSeries::new(pts, style))?;
        }
    }

    // Rejected samples on top.
    points!(|q| q.2, Cross, 5, REJECTED.stroke_width(2));

    // Events: switches to fading memory (dashed), restarts.
    let edge = |t: f64| vec![(t, y0), (t, y1)];
    for &t in &track.switches {
        chart.draw_series(DashedLineSeries::new(edge(t), 8, 6, SWITCH.stroke_width(2)))?;
    }
    for &t in &track.restarts {
        chart.draw_series(LineSeries::new(edge(t), RESTART.stroke_width(2)))?;
    }
    Ok(())
}
