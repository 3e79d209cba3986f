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
//! - in every panel, the spans without samples (shaded grey), the spans where the misfit flag
//!   is up (shaded orange), the switches to fading memory (green dashed lines) and the
//!   restarts (purple lines).
//!
//! A series with more points than the plot has pixel columns is drawn decimated per pixel
//! column ([`crate::decimate`]), and its samples as a thin line rather than dots. Axes whose
//! values share many leading digits or are very large or small are drawn in tick units with
//! an offset and a power of ten, said in the axis label ([`crate::ticks`]).
//!
//! Axis ranges ignore the start-up transients of the estimates (the 1st-99th percentile of the
//! estimates widened by the truth); a residual or band beyond the range is clipped to its edge,
//! where a clipped residual is drawn as a triangle. The PNG's text is drawn with the embedded
//! DejaVu Sans (no system fonts are read); the SVG names the family `DejaVu Sans, sans-serif`.

use crate::decimate::min_max;
use crate::error::CliError;
use crate::ticks::Scale;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{register_font, FontStyle};
use std::path::Path;
use std::sync::OnceLock;

/// DejaVu Sans (Bitstream Vera licence, see `assets/LICENSE-DejaVu.txt`).
static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");
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
    /// Whether each row is past the start-up (its estimate of the full degree; empty: every
    /// row): the residual and error panels' ranges leave the others out.
    pub settled: Vec<bool>,
    /// Spans `(from, to)` with no samples (e.g. a sensor outage), shaded in every panel.
    pub outages: Vec<(f64, f64)>,
    /// The estimates are valid at `t + lead`: drawn there, and compared with the sample at
    /// that time where there is one ([`samples_at_lead`]).
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
const MISFIT: RGBColor = RGBColor(255, 170, 60);
const TRUTH_ERROR: RGBColor = RGBColor(0, 130, 140);
const OUTAGE: RGBColor = RGBColor(150, 150, 150);

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

pub use crate::ticks::tick;

/// The rows whose estimate has a sample at its own time `t + lead`: for each row, the index
/// of the sample whose time is within a thousandth of the median step of `t + lead` (every
/// row itself for `lead = 0`). `t` is strictly increasing.
///
/// ```
/// use seqsmooth_cli::chart::samples_at_lead;
/// let t = [0.0, 0.1, 0.2, 0.30000000000000004, 0.4];
/// assert_eq!(samples_at_lead(&t, 0.2), vec![Some(2), Some(3), Some(4), None, None]);
/// assert_eq!(samples_at_lead(&t, 0.0)[1], Some(1));
/// ```
pub fn samples_at_lead(t: &[f64], lead: f64) -> Vec<Option<usize>> {
    if lead == 0.0 {
        return (0..t.len()).map(Some).collect();
    }
    let steps = t.windows(2).map(|w| w[1] - w[0]);
    let tol = 1e-3 * quantile(steps, 0.5).unwrap_or(0.0);
    t.iter()
        .map(|&ti| {
            let at = ti + lead;
            let j = t.partition_point(|&s| s < at);
            [j.checked_sub(1), Some(j)]
                .into_iter()
                .flatten()
                .filter(|&j| j < t.len() && (t[j] - at).abs() <= tol)
                .min_by(|&a, &b| (t[a] - at).abs().total_cmp(&(t[b] - at).abs()))
        })
        .collect()
}

/// What a panel shows.
#[derive(Clone, Copy, PartialEq)]
enum What {
    /// The estimate of derivative `k`, with the samples for `k = 0` and the truth.
    Derivative(usize),
    /// The error `d_k − truth_k` about zero (the truth), with the samples' `y − truth` for
    /// `k = 0`.
    Error(usize),
    /// `y − d0` about zero (the estimate), with `truth − d0`.
    Residual,
}

/// One panel's y data, relative to the estimate (residual panel) or the truth (error panel).
struct PanelData {
    label: String,
    /// Points: (time, value, rejected).
    points: Vec<(f64, f64, bool)>,
    /// The row of each point.
    point_rows: Vec<usize>,
    /// Whether each row is past the start-up (the relative panels' range is of those only).
    settled: Vec<bool>,
    /// The centre line (the estimate, its error, or zero) by row.
    line: Vec<Option<f64>>,
    /// The ±3σ half-width by row.
    band: Vec<Option<f64>>,
    /// The truth (zero in an error panel, truth − estimate in the residual panel) by row.
    truth: Vec<Option<f64>>,
    /// What the truth line is, for the legend.
    truth_key: Key,
    /// ±3σ noise lines by row.
    noise: Vec<Option<f64>>,
    /// The x offset of the line, band and truth (the lead), and of the truth alone.
    shift: f64,
    truth_shift: f64,
    range: (f64, f64),
    /// Clip points beyond the range to the edge (residual and error panels).
    clip_points: bool,
}

/// The panel showing `what` of `track`; `at[i]` is the sample at row `i`'s estimate time.
fn panel(track: &Track, what: What, label: &str, at: &[Option<usize>]) -> PanelData {
    let n = track.t.len();
    let j = match what {
        What::Derivative(k) | What::Error(k) => k,
        What::Residual => 0,
    };
    let cell = |v: &[Vec<Option<f64>>], i: usize| v.get(j).and_then(|v| v.get(i)).copied()?;
    let truth = |i: usize| track.truth.get(j).and_then(|x| x.get(i)).copied();
    // The sample at row i's estimate time, and the value every row's numbers are relative to.
    let own = |i: usize| at.get(i).copied().flatten();
    let base = |i: usize| match what {
        What::Derivative(_) => Some(0.0),
        What::Error(_) => own(i).and_then(truth),
        What::Residual => own(i).and(cell(&track.d, i)),
    };
    let rejected = |i: usize| track.rejected.get(i) == Some(&true);
    // Each point with its row: (row, time, value, rejected).
    let points: Vec<(usize, (f64, f64, bool))> = match what {
        What::Derivative(0) => (0..n)
            .map(|i| (i, (track.t[i], track.y[i], rejected(i))))
            .collect(),
        What::Error(0) => (0..n)
            .filter_map(|i| truth(i).map(|x| (i, (track.t[i], track.y[i] - x, rejected(i)))))
            .collect(),
        What::Residual => (0..n)
            .filter_map(|i| {
                let s = own(i)?;
                base(i).map(|b| (i, (track.t[s], track.y[s] - b, rejected(s))))
            })
            .collect(),
        _ => Vec::new(),
    };
    let (point_rows, points) = points.into_iter().unzip();
    // The rows after the start-up (all of them when none is marked settled).
    let settled = if track.settled.len() == n && track.settled.contains(&true) {
        track.settled.clone()
    } else {
        vec![true; n]
    };
    let rows = |f: &dyn Fn(usize, f64) -> Option<f64>| -> Vec<Option<f64>> {
        (0..n).map(|i| base(i).and_then(|b| f(i, b))).collect()
    };
    let relative = what != What::Derivative(j);
    let noise = |i: usize| {
        track
            .noise
            .get(i)
            .copied()
            .flatten()
            .filter(|_| relative && j == 0)
    };
    let mut p = PanelData {
        label: label.to_string(),
        points,
        point_rows,
        settled,
        line: rows(&|i, b| cell(&track.d, i).map(|d| d - b)),
        band: rows(&|i, _| cell(&track.s, i).map(|s| 3.0 * s)),
        truth: match what {
            What::Derivative(_) => (0..n).map(truth).collect(),
            What::Error(_) => rows(&|_, _| Some(0.0)),
            What::Residual => rows(&|i, b| own(i).and_then(truth).map(|x| x - b)),
        },
        truth_key: if what == What::Residual {
            Key::TruthError
        } else {
            Key::Truth
        },
        noise: (0..n).map(|i| noise(i).map(|s| 3.0 * s)).collect(),
        shift: track.lead,
        truth_shift: if relative { track.lead } else { 0.0 },
        range: (0.0, 1.0),
        clip_points: relative,
    };
    p.range = if p.clip_points {
        p.relative_range()
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

    /// Symmetric: the 99th percentile of |value| of the accepted samples, every rejected one
    /// up to twice that, the ±3σ noise and the settled band, the truth's and the line's
    /// distance from zero; of the rows past the start-up.
    fn relative_range(&self) -> (f64, f64) {
        let settled = |k: &usize| self.settled[*k];
        let points = || {
            let rows = self.point_rows.iter();
            rows.zip(&self.points)
                .filter(|(k, _)| settled(k))
                .map(|(_, p)| p)
        };
        let rows = |v: &[Option<f64>]| -> Vec<f64> {
            v.iter()
                .zip(&self.settled)
                .filter(|r| *r.1)
                .filter_map(|r| *r.0)
                .map(f64::abs)
                .collect()
        };
        let q = |v: Vec<f64>, p| quantile(v, p).unwrap_or(0.0);
        let mut r = q(points().filter(|p| !p.2).map(|p| p.1.abs()).collect(), 0.99)
            .max(q(rows(&self.noise), 0.9))
            .max(q(rows(&self.band), 0.9))
            .max(q(rows(&self.truth), 0.99))
            .max(q(rows(&self.line), 0.99));
        let cap = 2.0 * r;
        for p in points().filter(|p| p.2) {
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
    fn label(self) -> &'static str {
        match self {
            Key::Data => "samples",
            Key::DataLine => "samples (too dense for dots: joined)",
            Key::Rejected => "rejected (outlier)",
            Key::Estimate => "estimate",
            Key::Band => "estimate ±3σ",
            Key::Truth => "truth",
            Key::TruthError => "truth − estimate",
            Key::Noise => "noise ±3σ",
            Key::Switch => "switch to fading memory",
            Key::Restart => "misfit restart",
            Key::Misfit => "misfit flagged",
            Key::Outage => "no samples (outage)",
            Key::Clipped => "beyond the axis",
        }
    }
}

/// Samples drawn as dots up to one per this many pixel columns, else joined by a line.
const DOTS_PER_PIXEL: f64 = 0.5;

/// Whether the panel's samples are too many for dots across `columns` pixels.
fn dense(p: &PanelData, columns: u32) -> bool {
    p.points.iter().filter(|q| !q.2).count() as f64 > DOTS_PER_PIXEL * f64::from(columns)
}

fn legend_keys(panels: &[PanelData], track: &Track, columns: u32) -> Vec<Key> {
    let any = |f: &dyn Fn(&PanelData) -> bool| panels.iter().any(f);
    let clipped = |p: &PanelData| {
        p.clip_points && p.points.iter().any(|q| q.1 < p.range.0 || q.1 > p.range.1)
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
        (track.misfit.iter().any(|&m| m), Key::Misfit),
        (!track.outages.is_empty(), Key::Outage),
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
        Key::DataLine => seg((x - 14, y), (x + 14, y), DATA, 1),
        Key::Rejected => area.draw(&Cross::new((x, y), 5, REJECTED.stroke_width(2))),
        Key::Clipped => area.draw(&TriangleMarker::new((x, y), 5, DATA.filled())),
        Key::Estimate => seg((x - 14, y), (x + 14, y), ESTIMATE, 2),
        Key::Band => rect(ESTIMATE.mix(0.22)),
        Key::Truth => seg((x - 14, y), (x + 14, y), TRUTH, 1),
        Key::TruthError => seg((x - 14, y), (x + 14, y), TRUTH_ERROR, 2),
        Key::Noise => seg((x - 14, y), (x - 4, y), NOISE, 2)
            .and_then(|_| seg((x + 4, y), (x + 14, y), NOISE, 2)),
        Key::Switch => seg((x, y - 8), (x, y - 2), SWITCH, 2)
            .and_then(|_| seg((x, y + 2), (x, y + 8), SWITCH, 2)),
        Key::Restart => seg((x, y - 8), (x, y + 8), RESTART, 2),
        Key::Misfit => rect(MISFIT.mix(0.3)),
        Key::Outage => rect(OUTAGE.mix(0.35)),
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

/// The panels of `layout` drawn from `track`, top to bottom.
fn panels(track: &Track, layout: &Layout) -> Vec<PanelData> {
    let at = samples_at_lead(&track.t, track.lead);
    let errors = layout.errors.iter().map(|(k, l)| (What::Error(*k), l));
    let derivatives = layout.panels.iter().map(|(k, l)| (What::Derivative(*k), l));
    let residuals = layout.residual_label.iter().map(|l| (What::Residual, l));
    errors
        .chain(derivatives)
        .chain(residuals)
        .map(|(what, label)| panel(track, what, label, &at))
        .collect()
}

/// The plot width in pixels (the image less the axis label area and margins).
fn plot_columns(layout: &Layout) -> u32 {
    layout.size.0.saturating_sub(130).max(1)
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
    for row in legend_rows(root, &keys, width)? {
        let cy = y + 11;
        for (key, x) in row {
            symbol(root, key, (x + 14, cy))?;
            root.draw_text(key.label(), &label_style, (x + 32, cy))?;
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

    // Outages, then the misfit spans: from each flagged row to the next row.
    for &(a, b) in &track.outages {
        chart.draw_series([shade(a, b, OUTAGE.mix(0.35))])?;
    }
    if track.misfit.len() == n {
        for r in runs(n, |i| track.misfit[i]) {
            let a = track.t[r.start];
            let b = track.t[r.end.min(n - 1)].max(a);
            chart.draw_series([shade(a, b, MISFIT.mix(0.3))])?;
        }
    }

    // ±3σ band: each edge decimated on its own.
    for r in runs(n, |i| p.line[i].is_some() && p.band[i].is_some()) {
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
        runs(n, |i| v[i].is_some())
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

    // Samples: the points `$keep` picks, as `$shape`s at their values clamped to the range;
    // too many for dots, the accepted ones are joined by a thin line instead.
    let inside = |v: f64| v >= y0 && v <= y1;
    macro_rules! points {
        ($keep:expr, $shape:ident, $size:expr, $style:expr) => {
            let at = |q: &(f64, f64, bool)| (ax(q.0), clamp(q.1));
            let shapes = p
                .points
                .iter()
                .filter($keep)
                .map(|q| $shape::new(at(q), $size, $style));
            chart.draw_series(shapes)?;
        };
    }
    if dense(p, columns) {
        let accepted = p.points.iter().filter(|q| !q.2);
        let line = thin(accepted.map(|q| (ax(q.0), clamp(q.1))).collect());
        chart.draw_series(LineSeries::new(line, DATA.stroke_width(1)))?;
    } else {
        points!(|q| !q.2 && inside(q.1), Circle, 2, DATA.filled());
    }
    if p.clip_points {
        points!(|q| !inside(q.1), TriangleMarker, 5, DATA.filled());
    }

    // Truth, then the estimate over it.
    let truth_style = match p.truth_key {
        Key::TruthError => TRUTH_ERROR.stroke_width(2),
        _ => TRUTH.stroke_width(1),
    };
    for (v, shift, style) in [
        (&p.truth, p.truth_shift, truth_style),
        (&p.line, p.shift, ESTIMATE.stroke_width(2)),
    ] {
        for pts in curves(v, shift, 1.0) {
            chart.draw_series(segments(pts, style, split))?;
        }
    }

    // Rejected samples on top.
    points!(|q| q.2, Cross, 5, REJECTED.stroke_width(2));

    // Events: switches to fading memory (dashed), restarts.
    let edge = |t: f64| vec![(ax(t), top), (ax(t), floor)];
    for &t in &track.switches {
        chart.draw_series(DashedLineSeries::new(edge(t), 8, 6, SWITCH.stroke_width(2)))?;
    }
    for &t in &track.restarts {
        chart.draw_series(LineSeries::new(edge(t), RESTART.stroke_width(2)))?;
    }
    Ok(())
}
