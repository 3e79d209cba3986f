//! Reyneke, Morrison, Kourie & de Ridder (2012), §8.1 and Fig. 1, run as printed: a
//! 4th-degree polynomial observed every τ = 0.25 s with detection probability 0.5 and additive
//! noise σ = 100, smoothed by a 4th-degree fading-memory filter with θ = 0.95.
//!
//! cargo run --release -p seqsmooth --example reyneke_fig1 -- [--runs 400] [--seed 1]
//!     [--plot docs/images/reyneke-fig1.svg]
//!
//! The paper leaves out the polynomial, the track's length and whether θ is per update or per
//! τ; chosen here: `x(t) = 1000 + 200 t − 6 t² + 0.08 t³ − 0.0003 t⁴` (metres, seconds; every
//! term matters over the track), 100 s (401 slots, as the paper's other run), θ per τ (the
//! paper's `θ_eff = θ₀^|ζ|`). The variable-step filter is the library's gain engine
//! ([`Engine::Gain`], Reyneke's fixed-gain recursion in variable-step form); the exact
//! discounted least squares on the same times ([`Engine::Exact`]) is the reference. It prints,
//! at 25, 50 and 100 s, each derivative's RMS error over the runs beside the filters' own σ.

#[path = "common/papers.rs"]
mod papers;

use plotters::prelude::*;
use rand::Rng;
use rand_distr::{Distribution, Normal};
use seqsmooth::{DiscountMode, Engine, FadingMemory, PolynomialFilter};
use std::fmt::Write;

/// The paper's parameters (§8.1).
const PD: f64 = 0.5;
const SIGMA: f64 = 100.0;
const TAU: f64 = 0.25;
const DEGREE: usize = 4;
const THETA: f64 = 0.95;
/// The track: 100 s of slots τ apart.
const SLOTS: usize = 400;
/// The times at which the table reports.
const REPORT_AT: [f64; 3] = [25.0, 50.0, 100.0];
/// `x(t)`'s coefficients `a_k`, `x = Σ a_k t^k`.
const A: [f64; 5] = [1000.0, 200.0, -6.0, 0.08, -0.0003];

/// `x^(k)(t) = Σ_{j≥k} a_j j!/(j−k)! t^(j−k)`, `k = 0..=4`.
fn truth(t: f64) -> [f64; 5] {
    std::array::from_fn(|k| {
        (k..5)
            .map(|j| {
                let falling: f64 = ((j - k + 1)..=j).map(|v| v as f64).product();
                A[j] * falling * t.powi((j - k) as i32)
            })
            .sum()
    })
}

fn filter(engine: Engine, mode: DiscountMode) -> FadingMemory {
    FadingMemory::new(DEGREE, THETA, TAU, engine)
        .and_then(|f| f.with_discount_mode(mode))
        .and_then(|f| f.with_noise_sigma(SIGMA))
        .expect("the paper's parameters are in range")
}

/// One detection: its time, sample, and each filter's derivatives and σ after it.
struct Row {
    t: f64,
    y: f64,
    gain: (Vec<f64>, Vec<f64>),
    exact: (Vec<f64>, Vec<f64>),
}

/// One run: the detections and both filters' estimates after each.
fn run(rng: &mut impl Rng, mode: DiscountMode) -> Vec<Row> {
    let noise = Normal::new(0.0, SIGMA).expect("σ > 0");
    let (mut gain, mut exact) = (filter(Engine::Gain, mode), filter(Engine::Exact, mode));
    let mut rows = Vec::new();
    for k in 0..=SLOTS {
        let t = k as f64 * TAU;
        if rng.gen::<f64>() >= PD {
            continue;
        }
        let y = truth(t)[0] + noise.sample(rng);
        gain.update(t, y).expect("finite sample");
        exact.update(t, y).expect("finite sample");
        let state = |f: &FadingMemory| {
            f.estimate()
                .map(|s| {
                    let sd = s.std_devs().expect("σ tracked");
                    (s.derivatives, sd)
                })
                .unwrap_or_default()
        };
        rows.push(Row {
            t,
            y,
            gain: state(&gain),
            exact: state(&exact),
        });
    }
    rows
}

/// The last determined row at or before `t`.
fn at(rows: &[Row], t: f64) -> Option<&Row> {
    rows.iter()
        .rev()
        .find(|r| r.t <= t && !r.gain.0.is_empty() && !r.exact.0.is_empty())
}

/// The printed table at `runs` runs from `seed` (the block docs/reyneke.md holds).
pub fn report(runs: usize, seed: u64) -> String {
    let all = papers::monte_carlo(runs, seed, |_, rng| run(rng, DiscountMode::PerTime));
    let mut out = String::new();
    writeln!(
        out,
        "Reyneke et al. Fig. 1: degree {DEGREE}, theta = {THETA} per tau = {TAU} s, PD = {PD}, sigma = {SIGMA}; {runs} runs, seed {seed}"
    )
    .unwrap();
    let detections: usize = all.iter().map(Vec::len).sum();
    writeln!(
        out,
        "detections per run: {:.1} of {} slots",
        detections as f64 / runs as f64,
        SLOTS + 1
    )
    .unwrap();
    writeln!(
        out,
        "  t (s)  k | RMS err gain  mean sigma gain | RMS err exact  mean sigma exact | RMS(gain - exact)"
    )
    .unwrap();
    for &t in &REPORT_AT {
        let rows: Vec<&Row> = all.iter().filter_map(|r| at(r, t)).collect();
        for k in 0..=DEGREE {
            let err = |f: fn(&Row) -> &(Vec<f64>, Vec<f64>)| {
                papers::rms(rows.iter().map(|r| f(r).0[k] - truth(r.t)[k]))
            };
            let sd = |f: fn(&Row) -> &(Vec<f64>, Vec<f64>)| {
                rows.iter().map(|r| f(r).1[k]).sum::<f64>() / rows.len() as f64
            };
            let gap = papers::rms(rows.iter().map(|r| r.gain.0[k] - r.exact.0[k]));
            writeln!(
                out,
                "{:7.0} {k:2} | {:12.4e} {:16.4e} | {:13.4e} {:17.4e} | {:.4e}",
                t,
                err(|r| &r.gain),
                sd(|r| &r.gain),
                err(|r| &r.exact),
                sd(|r| &r.exact),
                gap
            )
            .unwrap();
        }
    }
    // The paper's other reading of θ (§6.1: "or by simply updating with θ₀"): θ per update, on
    // the same data (the same seed draws the same detections and noise).
    let per_update = papers::monte_carlo(runs, seed, |_, rng| run(rng, DiscountMode::PerUpdate));
    writeln!(out, "theta per update instead: position (k = 0)").unwrap();
    for &t in &REPORT_AT {
        let rows: Vec<&Row> = per_update.iter().filter_map(|r| at(r, t)).collect();
        let err = |f: fn(&Row) -> &(Vec<f64>, Vec<f64>)| {
            papers::rms(rows.iter().map(|r| f(r).0[0] - truth(r.t)[0]))
        };
        let sd = |f: fn(&Row) -> &(Vec<f64>, Vec<f64>)| {
            rows.iter().map(|r| f(r).1[0]).sum::<f64>() / rows.len() as f64
        };
        writeln!(
            out,
            "{t:7.0}  0 | {:12.4e} {:16.4e} | {:13.4e} {:17.4e} |",
            err(|r| &r.gain),
            sd(|r| &r.gain),
            err(|r| &r.exact),
            sd(|r| &r.exact)
        )
        .unwrap();
    }
    out
}

fn main() {
    let a = papers::args(400, 1);
    print!("{}", report(a.runs, a.seed));
    if let Some(path) = &a.plot {
        let rows = run(&mut papers::rng(a.seed, 0), DiscountMode::PerTime);
        plot(path, &rows).expect("plot");
        println!("plot: {path} (run 0 of seed {})", a.seed);
    }
}

/// Fig. 1 as the paper draws it: (a) position and position errors, (b) the 4th-degree state
/// vector, for one run.
fn plot(path: &str, rows: &[Row]) -> Result<(), Box<dyn std::error::Error>> {
    let root = papers::svg(path, (1100, 900))?;
    let (top, bottom) = root.split_vertically(520);
    let (pos, errs) = top.split_vertically(280);
    let rows: Vec<&Row> = rows.iter().filter(|r| !r.gain.0.is_empty()).collect();
    let tmax = SLOTS as f64 * TAU;

    let mut c = ChartBuilder::on(&pos)
        .caption(
            "(a) position: truth, detections (PD 0.5, σ 100) and the variable-step filter",
            ("sans-serif", 16),
        )
        .margin(8)
        .x_label_area_size(28)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..tmax, papers::range(rows.iter().map(|r| r.y)))?;
    c.configure_mesh().x_desc("t (s)").y_desc("x (m)").draw()?;
    c.draw_series(
        rows.iter()
            .map(|r| Circle::new((r.t, r.y), 2, RGBColor(150, 150, 150).filled())),
    )?
    .label("detections")
    .legend(|(x, y)| Circle::new((x + 8, y), 3, RGBColor(150, 150, 150).filled()));
    c.draw_series(LineSeries::new(
        (0..=SLOTS).map(|k| (k as f64 * TAU, truth(k as f64 * TAU)[0])),
        BLACK,
    ))?
    .label("truth")
    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BLACK));
    c.draw_series(LineSeries::new(
        rows.iter().map(|r| (r.t, r.gain.0[0])),
        RED,
    ))?
    .label("filter (gain engine)")
    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], RED));
    papers::legend(&mut c, SeriesLabelPosition::UpperLeft)?;

    let err = |r: &Row, f: fn(&Row) -> &(Vec<f64>, Vec<f64>)| f(r).0[0] - truth(r.t)[0];
    let bound = rows
        .iter()
        .filter(|r| r.t > 10.0)
        .map(|r| 3.0 * r.gain.1[0])
        .fold(0.0, f64::max);
    let mut c = ChartBuilder::on(&errs)
        .caption(
            "position error: gain engine, exact least squares, ±σ of the gain engine",
            ("sans-serif", 16),
        )
        .margin(8)
        .x_label_area_size(28)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..tmax, -bound..bound)?;
    c.configure_mesh()
        .x_desc("t (s)")
        .y_desc("error (m)")
        .draw()?;
    for sign in [-1.0, 1.0] {
        c.draw_series(LineSeries::new(
            rows.iter().map(|r| (r.t, sign * r.gain.1[0])),
            RGBColor(120, 120, 255),
        ))?;
    }
    c.draw_series(LineSeries::new(
        rows.iter().map(|r| (r.t, err(r, |r| &r.exact))),
        GREEN,
    ))?
    .label("exact")
    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], GREEN));
    c.draw_series(LineSeries::new(
        rows.iter().map(|r| (r.t, err(r, |r| &r.gain))),
        RED,
    ))?
    .label("gain")
    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], RED));
    papers::legend(&mut c, SeriesLabelPosition::UpperRight)?;

    let names = [
        "x (m)",
        "x' (m/s)",
        "x'' (m/s²)",
        "x''' (m/s³)",
        "x'''' (m/s⁴)",
    ];
    for (k, panel) in bottom.split_evenly((1, 5)).iter().enumerate() {
        let late: Vec<&&Row> = rows.iter().filter(|r| r.t > 10.0).collect();
        let y = papers::range(late.iter().flat_map(|r| {
            [
                r.gain.0[k] - r.gain.1[k],
                r.gain.0[k] + r.gain.1[k],
                truth(r.t)[k],
            ]
        }));
        let mut c = ChartBuilder::on(panel)
            .caption(format!("(b) {}", names[k]), ("sans-serif", 14))
            .margin(6)
            .x_label_area_size(26)
            .y_label_area_size(48)
            .build_cartesian_2d(10.0..tmax, y)?;
        c.configure_mesh()
            .x_labels(4)
            .y_labels(6)
            .x_desc("t (s)")
            .draw()?;
        for sign in [-1.0, 1.0] {
            c.draw_series(LineSeries::new(
                late.iter().map(|r| (r.t, r.gain.0[k] + sign * r.gain.1[k])),
                RGBColor(120, 120, 255),
            ))?;
        }
        c.draw_series(LineSeries::new(
            late.iter().map(|r| (r.t, r.gain.0[k])),
            RED,
        ))?;
        c.draw_series(LineSeries::new(
            (40..=SLOTS).map(|i| (i as f64 * TAU, truth(i as f64 * TAU)[k])),
            BLACK,
        ))?;
    }
    root.present()?;
    Ok(())
}
