//! Villien & Ostertag's Example 1 (§VI-A, Fig. 3) reproduced: Monte Carlo runs of the raw-data
//! maximum-likelihood fit (Levenberg–Marquardt on the N samples), PAML (the same fit on the
//! n+1 polynomial samples), the extended Kalman filter on the constant parameters, and the
//! Cramér–Rao bound, for observation spans of 150 to 1200 samples.
//!
//! cargo run --release -p seqsmooth --example paml_doppler -- [--runs 300] [--order 5]
//!     [--miss 1.0] [--seed 1] [--plot docs/images/paml_doppler_n5.png]
//!
//! It prints, for each span, each parameter's σ by method (the RMS error about the truth) and
//! the share of runs in which PAML is within 1 % of the ML σ of the ML estimate; then the time
//! of one fit on the raw and on the polynomial samples.

#[path = "../tests/common/doppler.rs"]
mod doppler;

use doppler::{extended_kalman, prior, Doppler, Scenario, SAMPLES};
use nalgebra::{DMatrix, DVector};
use plotters::prelude::*;
use rand::rngs::StdRng;
use rand::SeedableRng;
use seqsmooth::estimate::curve::{cramer_rao_bound, fit_curve};
use seqsmooth::paml::PolynomialSamples;
use std::time::Instant;

struct Args {
    runs: usize,
    order: usize,
    miss: f64,
    seed: u64,
    plot: Option<String>,
}

fn args() -> Args {
    let mut a = Args {
        runs: 300,
        order: 5,
        miss: 1.0,
        seed: 1,
        plot: None,
    };
    let v: Vec<String> = std::env::args().skip(1).collect();
    for pair in v.chunks(2) {
        let value = pair.get(1).expect("every option takes a value");
        match pair[0].as_str() {
            "--runs" => a.runs = value.parse().expect("--runs N"),
            "--order" => a.order = value.parse().expect("--order N"),
            "--miss" => a.miss = value.parse().expect("--miss METRES"),
            "--seed" => a.seed = value.parse().expect("--seed N"),
            "--plot" => a.plot = Some(value.clone()),
            other => panic!("unknown option {other}"),
        }
    }
    a
}

/// σ by method for one span: `[crlb, crlb with the prior, ml, paml, ekf][parameter]`, and
/// PAML's agreement.
struct Span {
    samples: usize,
    /// Runs in which a fit did not converge or left a parameter undetermined.
    failed: usize,
    sigma: [[f64; 3]; 5],
    within: [f64; 3],
    within_all: f64,
    largest: [f64; 3],
}

fn rms(errors: &[[f64; 3]]) -> [f64; 3] {
    let mut s = [0.0; 3];
    for e in errors {
        for i in 0..3 {
            s[i] += e[i] * e[i];
        }
    }
    s.map(|v| (v / errors.len() as f64).sqrt())
}

fn span(full: &Scenario, samples: usize, a: &Args) -> Span {
    let sc = full.first(samples);
    let mut rng = StdRng::seed_from_u64(a.seed);
    let crlb = cramer_rao_bound(&Doppler, &sc.truth, &sc.times, &sc.sigmas).expect("CRLB");
    // The bound for an estimator that also has the prior (the EKF's): (F + P₀⁻¹)⁻¹.
    let prior_information = DMatrix::from_diagonal(&DVector::from_iterator(
        3,
        doppler::PRIOR_SIGMA.iter().map(|s| 1.0 / (s * s)),
    ));
    let with_prior = (crlb.clone().try_inverse().expect("F") + prior_information)
        .try_inverse()
        .expect("F + P0^-1");
    let (mut ml, mut pa, mut ekf) = (vec![], vec![], vec![]);
    let mut failed = 0;
    for _ in 0..a.runs {
        let y = sc.measure(&mut rng);
        let start = prior(&sc.truth, &mut rng);
        let raw = fit_curve(&Doppler, &sc.times, &y, &sc.sigmas, &start);
        let ps = PolynomialSamples::from_segment(&sc.times, &y, &sc.sigmas, a.order)
            .and_then(|ps| ps.fit(&Doppler, &start));
        let k = extended_kalman(&sc, &y, &start);
        // y₀ enters as y₀² only: ±y₀ are the same track.
        let err = |p: &[f64]| {
            [
                p[0] - sc.truth[0],
                p[1].abs() - sc.truth[1],
                p[2] - sc.truth[2],
            ]
        };
        let (Ok(raw), Ok(ps), Ok(k)) = (raw, ps, k) else {
            failed += 1;
            continue;
        };
        ml.push(err(raw.parameters.as_slice()));
        pa.push(err(ps.parameters.as_slice()));
        ekf.push(err(k.as_slice()));
    }
    let ml_sigma = rms(&ml);
    let mut within = [0.0; 3];
    let mut within_all = 0.0;
    let mut largest = [0.0f64; 3];
    for (m, p) in ml.iter().zip(&pa) {
        let d = [0, 1, 2].map(|i| (p[i] - m[i]).abs() / ml_sigma[i]);
        for i in 0..3 {
            within[i] += f64::from(u8::from(d[i] <= 0.01));
            largest[i] = largest[i].max(d[i]);
        }
        within_all += f64::from(u8::from(d.iter().all(|&d| d <= 0.01)));
    }
    let n = ml.len() as f64;
    Span {
        samples,
        failed,
        sigma: [
            [0, 1, 2].map(|i| crlb[(i, i)].sqrt()),
            [0, 1, 2].map(|i| with_prior[(i, i)].sqrt()),
            ml_sigma,
            rms(&pa),
            rms(&ekf),
        ],
        within: within.map(|w| w / n),
        within_all: within_all / n,
        largest,
    }
}

fn main() {
    let a = args();
    let full = Scenario::new(a.miss, SAMPLES);
    println!(
        "Example 1: x0 = 10 m, y0 = {} m, v0 = 1800 m/s; {} runs; PAML order {}; the RMS error \
         about the truth",
        a.miss, a.runs, a.order
    );
    println!(
        "| samples | span (ms) | parameter | CRLB σ | CRLB σ with the prior | ML σ | PAML σ | EKF σ | PAML within 1 % of ML σ | largest abs(PAML − ML)/σ |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let names = ["x0 (m)", "y0 (m)", "v0 (m/s)"];
    let spans: Vec<Span> = (0..=8).map(|k| span(&full, 600 + 75 * k, &a)).collect();
    for s in &spans {
        for (i, name) in names.iter().enumerate() {
            println!(
                "| {} | {:.1} | {} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.1} % | {:.3} |",
                s.samples,
                s.samples as f64 * doppler::STEP * 1e3,
                name,
                s.sigma[0][i],
                s.sigma[1][i],
                s.sigma[2][i],
                s.sigma[3][i],
                s.sigma[4][i],
                100.0 * s.within[i],
                s.largest[i],
            );
        }
        println!(
            "|  |  | all three within 1 % ({} runs failed) |  |  |  |  |  | {:.1} % |  |",
            s.failed,
            100.0 * s.within_all
        );
    }

    // One fit's time, raw and polynomial samples (the criterion bench `paml` measures it).
    let mut rng = StdRng::seed_from_u64(a.seed);
    let y = full.measure(&mut rng);
    let start = prior(&full.truth, &mut rng);
    let ps = PolynomialSamples::from_segment(&full.times, &y, &full.sigmas, a.order).unwrap();
    let reps = 200;
    let clock = Instant::now();
    for _ in 0..reps {
        std::hint::black_box(fit_curve(&Doppler, &full.times, &y, &full.sigmas, &start).unwrap());
    }
    let raw = clock.elapsed().as_secs_f64() / reps as f64;
    let clock = Instant::now();
    for _ in 0..reps {
        std::hint::black_box(ps.fit(&Doppler, &start).unwrap());
    }
    let paml = clock.elapsed().as_secs_f64() / reps as f64;
    println!(
        "one fit: raw {:.1} µs, polynomial samples {:.2} µs ({:.0}x)",
        raw * 1e6,
        paml * 1e6,
        raw / paml
    );

    if let Some(path) = &a.plot {
        plot(path, &spans, a.order).expect("plot");
        println!("plot: {path}");
    }
}

/// DejaVu Sans, the command's embedded font (Bitstream Vera licence, beside it in
/// `crates/seqsmooth-cli/assets/`): plotters reads no system fonts here.
static FONT: &[u8] = include_bytes!("../../seqsmooth-cli/assets/DejaVuSans.ttf");

/// The plot as SVG, or PNG when `path` ends in `.png`.
fn plot(path: &str, spans: &[Span], order: usize) -> Result<(), Box<dyn std::error::Error>> {
    plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
        .map_err(|_| "the embedded font could not be loaded")?;
    if path.ends_with(".png") {
        draw(
            BitMapBackend::new(path, (960, 420)).into_drawing_area(),
            spans,
            order,
        )
    } else {
        draw(
            SVGBackend::new(path, (960, 420)).into_drawing_area(),
            spans,
            order,
        )
    }
}

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    spans: &[Span],
    order: usize,
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let panels = root.split_evenly((1, 2));
    let methods = [
        ("CRLB", BLACK),
        ("CRLB with the prior", MAGENTA),
        ("ML (raw)", BLUE),
        ("PAML", RED),
        ("EKF", GREEN),
    ];
    for (panel, (i, label)) in panels.iter().zip([(0usize, "x0 (m)"), (1, "y0 (m)")]) {
        let ms = |s: &Span| s.samples as f64 * doppler::STEP * 1e3;
        let lo = spans
            .iter()
            .flat_map(|s| s.sigma.iter().map(|m| m[i]))
            .fold(f64::INFINITY, f64::min);
        let hi = spans
            .iter()
            .flat_map(|s| s.sigma.iter().map(|m| m[i]))
            .fold(0.0, f64::max);
        let mut chart = ChartBuilder::on(panel)
            .caption(
                format!("σ of {label}, PAML order {order}"),
                ("sans-serif", 18),
            )
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(56)
            .build_cartesian_2d(0.0..5.0, (lo * 0.8..hi * 1.25).log_scale())?;
        chart
            .configure_mesh()
            .x_desc("observation span (ms)")
            .y_desc(format!("σ of {label}"))
            .draw()?;
        for (m, (name, colour)) in methods.iter().enumerate() {
            chart
                .draw_series(LineSeries::new(
                    spans.iter().map(|s| (ms(s), s.sigma[m][i])),
                    colour,
                ))?
                .label(*name)
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
