//! `seqsmooth demo`: the automatic filter on a built-in, deterministic manoeuvring-target track,
//! a summary, and a plot (PNG and SVG).
//!
//! The track ([`generate`]) is the east coordinate of an aircraft seen by a radar: straight at
//! 120 m/s, a standard-rate (3°/s) 180° turn from t = 140 s to 200 s, straight back; 400 samples
//! at jittered steps (1 s ± 30 %, uniform), 5 % of the samples dropped and a 12 s outage;
//! Gaussian noise σ = 15 m; 2 % of the samples carry an outlier of 6-10 σ. The numbers come from
//! an inline xorshift64* generator and the Box–Muller transform with a fixed seed, so the track
//! is the same on every run and platform. The automatic filter (degree 2, θ = 0.95 per median
//! step, noise estimated) runs on it; the plain expanding- and fading-memory filters of degree 2
//! (noise σ given), on both engines, are shown beside it for comparison.

use crate::args::{name, DemoArgs, EngineArg, Kind};
use crate::commands::shared::{filter_kind, LOOKAHEAD};
use crate::error::CliError;
use crate::io::{fmt_f64, Output};
use crate::plot::chart::{self, Layout, Track};
use seqsmooth::polynomial::automatic::{final_outliers, AutoOutput, AutomaticFilter, Phase};
use seqsmooth::polynomial::spec::FilterSpec;
use seqsmooth::polynomial::tau::median_series_step;
use seqsmooth::{PolynomialFilter, PolynomialState};
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

pub const SAMPLES: usize = 400;
/// Noise standard deviation, m.
pub const SIGMA: f64 = 15.0;
/// Speed, m/s.
const SPEED: f64 = 120.0;
/// Start of the turn, s.
pub const TURN_START: f64 = 140.0;
/// Turn rate, rad/s (3°/s).
const TURN_RATE: f64 = PI / 60.0;
/// Nominal sampling interval, s, and its uniform relative jitter.
const STEP: f64 = 1.0;
const JITTER: f64 = 0.3;
/// Probability that a sample is dropped.
const DROPOUT: f64 = 0.05;
/// The radar outage: no samples in [start, start + length), s.
pub const OUTAGE: (f64, f64) = (262.0, 12.0);
/// Probability that a sample carries an outlier, and the outlier's size range in σ.
const OUTLIER_RATE: f64 = 0.02;
pub const OUTLIER_SIZE: (f64, f64) = (6.0, 10.0);
const DEGREE: usize = 2;
/// Discount per median step, for the automatic and the plain fading-memory filters.
const THETA: f64 = 0.95;
/// Samples excluded from the error statistics as start-up.
const START_UP: usize = 50;

/// xorshift64* (Vigna 2016): a tiny deterministic generator, enough for demo noise.
struct XorShift64Star(u64);

impl XorShift64Star {
    fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in the open interval (0, 1).
    fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// Standard normal (Box–Muller, cosine branch).
    fn gaussian(&mut self) -> f64 {
        let u1 = self.uniform();
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

/// One sample of the track with its truth.
#[derive(Clone, Copy, Debug)]
pub struct Point {
    /// Time, s.
    pub t: f64,
    /// Measured east position, m.
    pub y: f64,
    /// True east position, m.
    pub x: f64,
    /// True east velocity, m/s.
    pub v: f64,
    /// Whether the sample carries an outlier.
    pub outlier: bool,
}

/// The end of the turn, s (half a circle at the turn rate).
pub fn turn_end() -> f64 {
    TURN_START + PI / TURN_RATE
}

/// The true east position and velocity at `t`.
pub fn truth(t: f64) -> (f64, f64) {
    let radius = SPEED / TURN_RATE;
    let x1 = SPEED * TURN_START;
    if t <= TURN_START {
        (SPEED * t, SPEED)
    } else if t <= turn_end() {
        let phi = TURN_RATE * (t - TURN_START);
        (x1 + radius * phi.sin(), SPEED * phi.cos())
    } else {
        (x1 - SPEED * (t - turn_end()), -SPEED)
    }
}

/// The demo track (see the module docs).
pub fn generate() -> Vec<Point> {
    let mut rng = XorShift64Star(0x5EED_5EED_2012_1969);
    let mut out = Vec::with_capacity(SAMPLES);
    let mut t = 0.0;
    let mut first = true;
    while out.len() < SAMPLES {
        if !first {
            t += STEP * (1.0 + JITTER * (2.0 * rng.uniform() - 1.0));
        }
        first = false;
        let dropped = rng.uniform() < DROPOUT;
        let in_outage = t >= OUTAGE.0 && t < OUTAGE.0 + OUTAGE.1;
        let noise = SIGMA * rng.gaussian();
        let outlier = rng.uniform() < OUTLIER_RATE;
        let size = OUTLIER_SIZE.0 + (OUTLIER_SIZE.1 - OUTLIER_SIZE.0) * rng.uniform();
        let sign = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
        if dropped || in_outage {
            continue;
        }
        let (x, v) = truth(t);
        let y = x + noise + if outlier { sign * size * SIGMA } else { 0.0 };
        out.push(Point {
            t,
            y,
            x,
            v,
            outlier,
        });
    }
    out
}

/// The estimates of a plain filter (noise σ given) at every sample.
type Estimates = Vec<Option<PolynomialState>>;

fn run_plain(
    data: &[Point],
    kind: Kind,
    engine: EngineArg,
    tau: f64,
) -> Result<Estimates, CliError> {
    let spec = FilterSpec {
        theta: Some(THETA),
        tau: Some(tau),
        engine: engine.into(),
        sigma: Some(SIGMA),
        ..FilterSpec::new(filter_kind(kind), DEGREE)
    };
    let mut f = spec.build().map_err(CliError::from)?;
    let mut estimates = Vec::with_capacity(data.len());
    for p in data {
        f.update(p.t, p.y).map_err(CliError::from)?;
        estimates.push(f.estimate_at(p.t));
    }
    Ok(estimates)
}

/// Three significant digits, scientific below 0.001 or from 10⁵ on.
fn short(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 {
        "0".into()
    } else if (1e-3..1e5).contains(&a) {
        let decimals = (2 - a.log10().floor() as i32).max(0) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.2e}")
    }
}

fn rms(v: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = v.fold((0.0, 0usize), |(s, n), e| (s + e * e, n + 1));
    (s / n.max(1) as f64).sqrt()
}

/// One row of the error table: RMS errors of x and x', the largest |error of x|, and the share
/// of samples whose true position is inside the reported ±3σ.
fn error_row(
    name: &str,
    engine: &str,
    est: &[Option<PolynomialState>],
    data: &[Point],
) -> Vec<String> {
    let after = || {
        est.iter()
            .zip(data)
            .skip(START_UP)
            .filter_map(|(e, p)| e.as_ref().map(|e| (e, p)))
            .filter(|(e, _)| e.derivatives.len() > 1)
    };
    type Scored<'a> = (&'a PolynomialState, &'a Point);
    let x_err = |(e, p): Scored| e.derivatives[0] - p.x;
    let within = |&(e, p): &Scored| {
        e.std_devs()
            .is_some_and(|s| x_err((e, p)).abs() <= 3.0 * s[0])
    };
    let (scored, inside) = (after().count(), after().filter(within).count());
    vec![
        name.to_string(),
        engine.to_string(),
        short(rms(after().map(x_err))),
        short(rms(after().map(|(e, p)| e.derivatives[1] - p.v))),
        short(after().map(|q| x_err(q).abs()).fold(0.0, f64::max)),
        format!("{:.1} %", 100.0 * inside as f64 / scored.max(1) as f64),
    ]
}

/// The plot's two file names for the path prefix `prefix` (a trailing `.png` or `.svg` is
/// dropped first).
pub fn plot_paths(prefix: &Path) -> [PathBuf; 2] {
    let base = if chart::Format::from_path(prefix).is_some() {
        prefix.with_extension("")
    } else {
        prefix.to_path_buf()
    };
    let with = |ext: &str| {
        let mut s = base.clone().into_os_string();
        s.push(ext);
        PathBuf::from(s)
    };
    [with(".png"), with(".svg")]
}

/// The automatic filter's run as a plot track.
fn track(data: &[Point], outs: &[AutoOutput], rejected: Vec<bool>) -> Track {
    // Row by row, `f` of the estimate where there is one.
    let rows = |f: &dyn Fn(&PolynomialState) -> Option<f64>| -> Vec<Option<f64>> {
        outs.iter()
            .map(|o| o.estimate.as_ref().and_then(f))
            .collect()
    };
    let fading = |i: usize| outs[i].phase == Phase::Fading;
    let switches = (0..outs.len()).filter(|&i| fading(i) && (i == 0 || !fading(i - 1)));
    let t: Vec<f64> = data.iter().map(|p| p.t).collect();
    let misfit: Vec<bool> = outs.iter().map(|o| o.misfit).collect();
    Track {
        // The outages by the plot's own rule (the 12 s one), as `seqsmooth plot` finds them.
        outages: chart::outages(&t),
        misfit: chart::flag_spans(&t, &misfit),
        t,
        y: data.iter().map(|p| p.y).collect(),
        d: (0..=DEGREE)
            .map(|k| rows(&|e| e.derivatives.get(k).copied()))
            .collect(),
        s: (0..=DEGREE)
            .map(|k| rows(&|e| e.std_devs()?.get(k).copied()))
            .collect(),
        truth: vec![
            data.iter().map(|p| p.x).collect(),
            data.iter().map(|p| p.v).collect(),
        ],
        noise: outs.iter().map(|o| o.noise_sigma).collect(),
        rejected,
        switches: switches.map(|i| outs[i].time).collect(),
        restarts: outs.iter().filter(|o| o.restart).map(|o| o.time).collect(),
        settled: outs
            .iter()
            .map(|o| {
                o.estimate
                    .as_ref()
                    .is_some_and(|e| e.derivatives.len() > DEGREE)
            })
            .collect(),
        ..Track::default()
    }
}

fn layout(tau: f64) -> Layout {
    Layout {
        title: "seqsmooth demo: automatic filter on a turning aircraft (east coordinate)".into(),
        subtitle: format!(
            "degree {DEGREE}, θ = {THETA} per τ = {tau:.3} s, noise σ estimated; \
             {SAMPLES} radar samples, σ = {SIGMA} m, jittered steps, dropouts, 6-10σ outliers"
        ),
        time_label: "time (s)".into(),
        // The position itself spans 30 km against σ = 15 m: its error is what can be seen.
        errors: vec![(0, "east position error: estimate − truth (m)".into())],
        panels: vec![(1, "east velocity (m/s)".into())],
        residual_label: Some("residual y − estimate (m)".into()),
        size: (1400, Layout::default_height(2, true)),
    }
}

fn times_list(times: &[f64]) -> String {
    if times.is_empty() {
        return "none".into();
    }
    let list: Vec<String> = times.iter().map(|t| format!("{t:.1}")).collect();
    format!("t = {} s", list.join(", "))
}

pub fn run(cfg: &DemoArgs) -> Result<(), CliError> {
    let data = generate();
    let head: Vec<f64> = data.iter().take(LOOKAHEAD).map(|p| p.t).collect();
    let tau = median_series_step(&head, &vec![0; head.len()]).unwrap_or(1.0);

    let mut auto = AutomaticFilter::new(DEGREE, THETA, tau).map_err(CliError::from)?;
    let mut outs = Vec::with_capacity(data.len());
    for p in &data {
        outs.push(auto.update(p.t, p.y).map_err(CliError::from)?);
    }
    let auto_estimates: Estimates = outs.iter().map(|o| o.estimate.clone()).collect();
    let header = [
        "filter",
        "engine",
        "rms err x",
        "rms err x'",
        "max |err x|",
        "x within ±3σ",
    ];
    let mut table = vec![header.map(String::from).to_vec()];
    table.push(error_row("automatic", "exact", &auto_estimates, &data));
    let mut fading_exact = Vec::new();
    for kind in [Kind::Expanding, Kind::Fading] {
        for engine in [EngineArg::Exact, EngineArg::Gain] {
            let estimates = run_plain(&data, kind, engine, tau)?;
            table.push(error_row(&name(kind), &name(engine), &estimates, &data));
            if (kind, engine) == (Kind::Fading, EngineArg::Exact) {
                fading_exact = estimates;
            }
        }
    }

    let outliers = data.iter().filter(|p| p.outlier).count();
    // The decisions still waiting at the end of the track, with the samples there are.
    let tail = auto.finish();
    let flags = final_outliers(&outs, &tail);
    let rejected = flags.iter().filter(|&&r| r).count();
    let caught = flags
        .iter()
        .zip(&data)
        .filter(|(&r, p)| r && p.outlier)
        .count();
    let plot_track = track(&data, &outs, flags.clone());
    let (switches, restarts) = (&plot_track.switches, &plot_track.restarts);
    let span = data[SAMPLES - 1].t - data[0].t;

    let mut w = Output::stdout();
    let text = format!(
        "seqsmooth demo: the east coordinate of an aircraft through a 180° turn, {SAMPLES} radar \
         samples over {span:.0} s\n  \
         truth: straight at {SPEED} m/s, a {:.0}°/s turn from t = {TURN_START} to {:.0} s, \
         straight back\n  \
         sampling: steps {STEP} s ± {:.0} %, {:.0} % dropped, no samples for {} s from t = {} s; \
         noise σ = {SIGMA} m; {outliers} outliers of {}-{}σ\n\
         automatic filter: degree {DEGREE}, θ = {THETA} per τ = {tau:.4} s (the median step), \
         noise estimated\n  \
         rejected {} samples (final decisions): {caught} of the {outliers} outliers, {} good\n  \
         switch from expanding to fading memory: {}\n  \
         misfit restarts: {}; misfit flagged on {} samples\n  \
         noise σ estimated at the end: {} m (true {SIGMA} m)\n\
         Errors against the truth over samples {START_UP}..{} (the plain expanding- and \
         fading-memory filters\nare given σ, reject nothing and never restart):\n\n",
        TURN_RATE.to_degrees(),
        turn_end(),
        100.0 * JITTER,
        100.0 * DROPOUT,
        OUTAGE.1,
        OUTAGE.0,
        OUTLIER_SIZE.0,
        OUTLIER_SIZE.1,
        rejected,
        rejected - caught,
        times_list(switches),
        if restarts.is_empty() {
            "none".to_string()
        } else {
            format!("{} at {}", restarts.len(), times_list(restarts))
        },
        outs.iter().filter(|o| o.misfit).count(),
        auto.noise_sigma().map_or_else(|| "-".to_string(), short),
        SAMPLES - 1
    );
    w.write(text.as_bytes())?;
    w.aligned(&table, 2)?;
    w.finish()?;

    if let Some(path) = &cfg.output {
        let mut out = Output::create(Some(path))?;
        out.write(b"t,y,d0,d1,d2,s0,s1,s2\n")?;
        for (p, e) in data.iter().zip(&fading_exact) {
            let d = e
                .as_ref()
                .map(|e| (e.derivatives.clone(), e.std_devs().unwrap_or_default()));
            let (d, s) = d.unwrap_or_default();
            let cells = (0..=DEGREE)
                .map(|k| d.get(k))
                .chain((0..=DEGREE).map(|k| s.get(k)));
            let mut row = vec![fmt_f64(p.t), fmt_f64(p.y)];
            row.extend(cells.map(|v| v.map_or_else(String::new, |&v| fmt_f64(v))));
            out.row(&row)?;
        }
        let name = out.name.clone();
        out.finish()?;
        eprintln!(
            "wrote the fading-memory (exact engine) output to {name}: columns t,y,d0..d2,s0..s2"
        );
    }
    if let Some(prefix) = Some(&cfg.plot).filter(|_| !cfg.no_plot) {
        let (l, paths) = (layout(tau), plot_paths(prefix));
        for p in &paths {
            chart::write(&plot_track, &l, p)?;
        }
        eprintln!(
            "wrote the plot to '{}' and '{}'",
            paths[0].display(),
            paths[1].display()
        );
    }
    Ok(())
}
