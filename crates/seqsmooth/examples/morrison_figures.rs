//! Morrison (1969), Figs. 13.2-13.5 (the fading-memory filter's start-up transients) and
//! Figs. 14.1-14.3 (the stress functions and `P_{n,n}(β)` of the generalized fading-memory
//! filter), simulated from the library.
//!
//! cargo run --release -p seqsmooth --example morrison_figures -- [--runs 400] [--seed 1]
//!     [--plot docs/images]
//!
//! Figs. 13.2-13.5 (§13.8): zero signal, white noise σ = 5 ft, τ = 0.05 s; a fading-memory
//! 1-step predictor of degree 2 (θ = 0.942) and 3 (θ = 0.945), started by interpolation of the
//! first `m + 1` observations (Figs. 13.2, 13.4: the library's gain engine switched to the
//! fading gains at sample `m + 1`, [`SwitchRule::AtSample`]) or by the expanding-memory filter
//! switched at `n₀ = 75` and `100` (Figs. 13.3, 13.5: the default [`SwitchRule::Position`]).
//! The plotted quantity is the error in `D² x*_{n+1,n}`. Printed: its RMS over the runs at
//! chosen `n` beside the library's σ of that estimate, and the steady-state σ (Table 13.3's
//! VRF).
//!
//! Fig. 14.1: the stress `β^(t_n − t_k)` each sample gets, recovered from the library's
//! fading-memory filter of degree 0 by feeding it one unit impulse at a time.
//! Figs. 14.2-14.3 (§14.7): the diagonal of `P_{n,n}(β)` of the fading Bayes filter for
//! `Φ = [[1, τ], [0, 1]]`, `M = (1, 0)` and `M = (0, 1)`; the book does not give `τ`, `R` or
//! the start, chosen: τ = 1, R = 1, prior `P = I` at `t = 0` (as for Figs. 10.1-10.2).

#[path = "common/papers.rs"]
mod papers;

use nalgebra::{DMatrix, DVector};
use plotters::prelude::*;
use rand_distr::{Distribution, Normal};
use seqsmooth::kalman::{BayesFilter, Discount};
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
use seqsmooth::model::observation::LinearObservation;
use seqsmooth::polynomial::fading::vrf::fading_vrf;
use seqsmooth::polynomial::form::EstimateForm;
use seqsmooth::polynomial::SwitchRule;
use seqsmooth::{Engine, ExpandingMemory, FadingMemory, PolynomialFilter};
use std::fmt::Write;

const SIGMA: f64 = 5.0;
const TAU: f64 = 0.05;
/// Samples per start-up run (20 s).
const STEPS: usize = 400;
/// The `n` at which the table reports.
const REPORT_N: [usize; 10] = [5, 10, 20, 40, 60, 80, 100, 150, 200, 400];
/// `(figure pair, degree, θ)`.
const CASES: [(&str, usize, f64); 2] = [("13.2/13.3", 2, 0.942), ("13.4/13.5", 3, 0.945)];

/// The two starts of §13.8.
#[derive(Clone, Copy)]
enum Start {
    Interpolation,
    Expanding,
}

fn predictor(m: usize, theta: f64, start: Start) -> FadingMemory {
    let rule = match start {
        Start::Interpolation => SwitchRule::AtSample(m as u64 + 1),
        Start::Expanding => SwitchRule::Position,
    };
    FadingMemory::new(m, theta, TAU, Engine::Gain)
        .and_then(|f| f.with_switch_rule(rule))
        .and_then(|f| f.with_noise_sigma(SIGMA))
        .expect("the book's parameters are in range")
}

/// One run: `(D² x*_{n+1,n}, its σ)` for `n = 0..STEPS` (NaN before the state is determined).
fn startup(m: usize, theta: f64, start: Start, rng: &mut rand::rngs::StdRng) -> Vec<(f64, f64)> {
    let noise = Normal::new(0.0, SIGMA).expect("σ > 0");
    let mut f = predictor(m, theta, start);
    (0..STEPS)
        .map(|n| {
            let t = n as f64 * TAU;
            f.update(t, noise.sample(rng)).expect("finite sample");
            match f.estimate_at(t + TAU) {
                Some(s) => (
                    s.derivatives[2],
                    s.covariance.expect("σ tracked")[(2, 2)].sqrt(),
                ),
                None => (f64::NAN, f64::NAN),
            }
        })
        .collect()
}

/// The steady-state σ of `D² x*_{n+1,n}`: `(2!/τ²) σ √VRF₂₂` (Table 13.3, 1-step prediction).
fn steady_sigma(m: usize, theta: f64) -> f64 {
    let v = fading_vrf::<f64>(m, theta, EstimateForm::Predictor).expect("θ")[(2, 2)];
    2.0 / (TAU * TAU) * SIGMA * v.sqrt()
}

/// Fig. 14.1: the weight of a sample of age `a` relative to the newest, as the library's
/// degree-0 filter applies it (β = 1: expanding memory).
fn stress(beta: f64, age: usize, last: usize) -> f64 {
    let response = |at: usize| {
        let mut f: Box<dyn PolynomialFilter> = if beta < 1.0 {
            Box::new(FadingMemory::new(0, beta, 1.0, Engine::Exact).expect("β"))
        } else {
            Box::new(ExpandingMemory::new(0, Engine::Exact).expect("degree"))
        };
        for k in 0..=last {
            f.update(k as f64, if k == at { 1.0 } else { 0.0 })
                .expect("sample");
        }
        f.estimate().expect("determined").derivatives[0]
    };
    response(last - age) / response(last)
}

const BETAS_14_1: [f64; 6] = [0.2, 0.5, 0.8, 0.9, 0.95, 1.0];
const AGES: usize = 40;
const BETAS_14_3: [f64; 5] = [0.5, 0.7, 0.9, 0.95, 1.0];
const P_STEPS: usize = 60;

/// Figs. 14.2-14.3: `(p00, p11)` of `P_{n,n}(β)` for `n = 1..=P_STEPS` (`None`: the filter
/// refuses, the information no longer determining the state to working accuracy).
fn p_diagonal(beta: f64, m: [f64; 2]) -> Vec<Option<(f64, f64)>> {
    let obs = LinearObservation::new(DMatrix::from_row_slice(1, 2, &m)).expect("M");
    let mut f = BayesFilter::new(PolynomialDynamics::new(1, 1), obs, 0.0)
        .and_then(|f| f.with_prior(&DVector::zeros(2), &DMatrix::identity(2, 2)))
        .expect("model");
    if beta < 1.0 {
        f = f
            .with_fading(Discount::PerUpdate { theta: beta })
            .expect("β");
    }
    (1..=P_STEPS)
        .map(|n| {
            f.update(&Measurement {
                time: n as f64,
                values: vec![Some(0.0)],
                noise: NoiseCovariance::Identity,
            })
            .expect("measurement");
            let p = if beta < 1.0 {
                f.information_covariance()
            } else {
                f.covariance()
            };
            p.map(|p| (p[(0, 0)], p[(1, 1)]))
        })
        .collect()
}

fn cell(p: Option<(f64, f64)>, k: usize) -> String {
    match p {
        Some(p) => format!("{:9.3e}", if k == 0 { p.0 } else { p.1 }),
        None => format!("{:>9}", "refused"),
    }
}

/// The printed tables at `runs` runs from `seed` (the block docs/morrison.md holds).
pub fn report(runs: usize, seed: u64) -> String {
    let mut out = String::new();
    writeln!(
        out,
        "Morrison Figs. 13.2-13.5: error in D2 x*(n+1,n) (ft/s^2), zero signal, sigma = {SIGMA} ft, tau = {TAU} s; RMS over {runs} runs, seed {seed}"
    )
    .unwrap();
    for (case, &(fig, m, theta)) in CASES.iter().enumerate() {
        let n0 = SwitchRule::Position.switch_index(m, theta).expect("θ");
        writeln!(
            out,
            "Figs. {fig}: degree {m}, theta = {theta}; expanding start switched at n0 = {n0}; steady-state sigma {:.4}",
            steady_sigma(m, theta)
        )
        .unwrap();
        writeln!(
            out,
            "     n | interpolation: RMS err    sigma | expanding: RMS err    sigma"
        )
        .unwrap();
        let go = |start: Start, s: u64| {
            papers::monte_carlo(runs, s, |_, rng| startup(m, theta, start, rng))
        };
        let s = seed.wrapping_add(case as u64 * 2);
        let (interp, expand) = (go(Start::Interpolation, s), go(Start::Expanding, s + 1));
        for &n in &REPORT_N {
            let i = n - 1;
            writeln!(
                out,
                "{n:6} | {:20.4e} {:8.4e} | {:16.4e} {:8.4e}",
                papers::rms(interp.iter().map(|r| r[i].0)),
                interp[0][i].1,
                papers::rms(expand.iter().map(|r| r[i].0)),
                expand[0][i].1
            )
            .unwrap();
        }
    }
    writeln!(out).unwrap();
    writeln!(
        out,
        "Fig. 14.1: stress of a sample of age a (relative to the newest), from the library's degree-0 filters"
    )
    .unwrap();
    write!(out, "  beta |").unwrap();
    for a in [1, 5, 10, 20, 40] {
        write!(out, "  a = {a:2}  ").unwrap();
    }
    writeln!(out, "| max |stress - beta^a|").unwrap();
    for beta in BETAS_14_1 {
        write!(out, "{beta:6} |").unwrap();
        for a in [1, 5, 10, 20, 40] {
            write!(out, " {:9.3e}", stress(beta, a, AGES)).unwrap();
        }
        let gap = (0..=AGES)
            .map(|a| (stress(beta, a, AGES) - beta.powi(a as i32)).abs())
            .fold(0.0, f64::max);
        writeln!(out, " | {gap:.1e}").unwrap();
    }
    writeln!(out).unwrap();
    writeln!(
        out,
        "Figs. 14.2/14.3: diagonal of P(n,n)(beta), Phi = [[1, 1], [0, 1]], R = 1, prior P = I"
    )
    .unwrap();
    for (name, m) in [("M = (1, 0)", [1.0, 0.0]), ("M = (0, 1)", [0.0, 1.0])] {
        writeln!(
            out,
            "{name}    n:       1         5        10        20        60 | limit (count-based, M = (1, 0))"
        )
        .unwrap();
        for beta in BETAS_14_3 {
            let p = p_diagonal(beta, m);
            for (k, label) in ["p00", "p11"].iter().enumerate() {
                write!(out, "beta {beta:4} {label}:").unwrap();
                for n in [1, 5, 10, 20, 60] {
                    write!(out, " {}", cell(p[n - 1], k)).unwrap();
                }
                let limit = match (m[0] == 1.0, beta < 1.0, k) {
                    (true, true, 0) => format!("{:.3e}", 1.0 - beta * beta),
                    (true, true, _) => format!("{:.3e}", (1.0 - beta).powi(3) / beta),
                    (true, false, _) => "0".into(),
                    _ => "-".into(),
                };
                writeln!(out, " | {limit}").unwrap();
            }
        }
    }
    out
}

fn main() {
    let a = papers::args(400, 1);
    print!("{}", report(a.runs, a.seed));
    if let Some(dir) = &a.plot {
        let start = format!("{dir}/morrison-fig13.svg");
        plot_startup(&start, a.seed).expect("plot");
        let fading = format!("{dir}/morrison-fig14.svg");
        plot_fading(&fading).expect("plot");
        println!("plots: {start}, {fading}");
    }
}

/// Figs. 13.2-13.5 for one run each (the first run of the table's seeds): |error| and σ of
/// `D² x*_{n+1,n}`, log scale.
fn plot_startup(path: &str, seed: u64) -> Result<(), Box<dyn std::error::Error>> {
    let root = papers::svg(path, (1100, 760))?;
    let panels = root.split_evenly((2, 2));
    for (case, &(_, m, theta)) in CASES.iter().enumerate() {
        let s = seed.wrapping_add(case as u64 * 2);
        for (j, (start, fig, how)) in [
            (
                Start::Interpolation,
                2 + 2 * case,
                "initialized by interpolation",
            ),
            (
                Start::Expanding,
                3 + 2 * case,
                "initialized by expanding memory",
            ),
        ]
        .into_iter()
        .enumerate()
        {
            let run = startup(m, theta, start, &mut papers::rng(s + j as u64, 0));
            let mut c = ChartBuilder::on(&panels[2 * case + j])
                .caption(
                    format!("Fig. 13.{fig}: degree {m}, θ = {theta}, {how}"),
                    ("sans-serif", 15),
                )
                .margin(8)
                .x_label_area_size(30)
                .y_label_area_size(60)
                .build_cartesian_2d(0.0..STEPS as f64, (1e-1..1e6).log_scale())?;
            c.configure_mesh()
                .x_desc("n")
                .y_desc("|error of D²x*(n+1,n)| (ft/s²)")
                .draw()?;
            let pts = |f: fn(&(f64, f64)) -> f64| {
                run.iter()
                    .enumerate()
                    .filter(move |(_, r)| f(r).is_finite() && f(r) > 1e-1)
                    .map(move |(n, r)| ((n + 1) as f64, f(r).min(1e6)))
                    .collect::<Vec<_>>()
            };
            c.draw_series(LineSeries::new(pts(|r| r.0.abs()), RED))?
                .label("|error|, one run")
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], RED));
            c.draw_series(LineSeries::new(pts(|r| r.1), BLUE))?
                .label("σ (library)")
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BLUE));
            let ss = steady_sigma(m, theta);
            c.draw_series(LineSeries::new(
                [(0.0, ss), (STEPS as f64, ss)],
                RGBColor(120, 120, 120),
            ))?
            .label("steady-state σ")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], RGBColor(120, 120, 120)));
            papers::legend(&mut c, SeriesLabelPosition::UpperRight)?;
        }
    }
    root.present()?;
    Ok(())
}

/// Figs. 14.1-14.3.
fn plot_fading(path: &str) -> Result<(), Box<dyn std::error::Error>> {
    let root = papers::svg(path, (1200, 400))?;
    let panels = root.split_evenly((1, 3));
    let colours = [RED, MAGENTA, BLUE, CYAN, GREEN, BLACK];
    let mut c = ChartBuilder::on(&panels[0])
        .caption("Fig. 14.1: stress functions", ("sans-serif", 15))
        .margin(8)
        .x_label_area_size(30)
        .y_label_area_size(44)
        .build_cartesian_2d(0.0..AGES as f64, 0.0..1.05)?;
    c.configure_mesh()
        .x_desc("age t_n − t_k")
        .y_desc("stress")
        .draw()?;
    for (i, beta) in BETAS_14_1.into_iter().enumerate() {
        let colour = colours[i];
        c.draw_series(LineSeries::new(
            (0..=AGES).map(|a| (a as f64, stress(beta, a, AGES))),
            colour,
        ))?
        .label(format!("β = {beta}"))
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], colour));
    }
    papers::legend(&mut c, SeriesLabelPosition::UpperRight)?;
    for (k, (fig, name)) in [("14.2", "p00"), ("14.3", "p11")].into_iter().enumerate() {
        let mut c = ChartBuilder::on(&panels[k + 1])
            .caption(
                format!("Fig. {fig}: {name} of P(n,n)(β), M = (1, 0)"),
                ("sans-serif", 15),
            )
            .margin(8)
            .x_label_area_size(30)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..P_STEPS as f64, (1e-6..2.0).log_scale())?;
        c.configure_mesh().x_desc("n").y_desc(name).draw()?;
        for (i, beta) in BETAS_14_3.into_iter().enumerate() {
            let colour = colours[i + 1];
            let p = p_diagonal(beta, [1.0, 0.0]);
            c.draw_series(LineSeries::new(
                p.iter().enumerate().filter_map(|(n, p)| {
                    p.map(|p| ((n + 1) as f64, if k == 0 { p.0 } else { p.1 }))
                }),
                colour,
            ))?
            .label(format!("β = {beta}"))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], colour));
        }
        papers::legend(&mut c, SeriesLabelPosition::LowerLeft)?;
    }
    root.present()?;
    Ok(())
}
