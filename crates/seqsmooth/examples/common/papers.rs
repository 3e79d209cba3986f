//! What the papers' experiment programs share: the `--runs`/`--seed`/`--plot` options, seeded
//! Monte Carlo runs on the rayon pool (the same numbers whatever the number of threads), and
//! the embedded font of the SVG plots.

#![allow(dead_code)]

use plotters::prelude::*;
use rand::rngs::StdRng;
use rand::SeedableRng;
use rayon::prelude::*;

/// The options every experiment takes.
pub struct Args {
    pub runs: usize,
    pub seed: u64,
    pub plot: Option<String>,
}

/// `--runs N --seed S [--plot FILE.svg]` from the command line, with the program's defaults.
pub fn args(runs: usize, seed: u64) -> Args {
    let mut a = Args {
        runs,
        seed,
        plot: None,
    };
    let v: Vec<String> = std::env::args().skip(1).collect();
    for pair in v.chunks(2) {
        let value = pair.get(1).expect("every option takes a value");
        match pair[0].as_str() {
            "--runs" => a.runs = value.parse().expect("--runs N"),
            "--seed" => a.seed = value.parse().expect("--seed N"),
            "--plot" => a.plot = Some(value.clone()),
            other => panic!("unknown option {other} (--runs N, --seed S, --plot FILE.svg)"),
        }
    }
    assert!(a.runs > 0, "--runs must be at least 1");
    a
}

/// Run `i`'s generator: one stream per run, from the seed and the run's index.
pub fn rng(seed: u64, run: usize) -> StdRng {
    StdRng::seed_from_u64(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ run as u64)
}

/// `f(run, rng)` for every run on the rayon pool, in the order of the runs.
pub fn monte_carlo<T: Send>(
    runs: usize,
    seed: u64,
    f: impl Fn(usize, &mut StdRng) -> T + Sync,
) -> Vec<T> {
    (0..runs)
        .into_par_iter()
        .map(|i| f(i, &mut rng(seed, i)))
        .collect()
}

/// `√(mean of x²)`.
pub fn rms(x: impl IntoIterator<Item = f64>) -> f64 {
    let (mut s, mut n) = (0.0, 0usize);
    for v in x {
        s += v * v;
        n += 1;
    }
    (s / n.max(1) as f64).sqrt()
}

/// DejaVu Sans, the command's embedded font (Bitstream Vera licence, beside it in
/// `crates/seqsmooth-cli/assets/`): plotters reads no system fonts here.
static FONT: &[u8] = include_bytes!("../../../seqsmooth-cli/assets/DejaVuSans.ttf");

/// An SVG drawing area of `size` pixels at `path`, white, with the font registered.
pub fn svg(
    path: &str,
    size: (u32, u32),
) -> Result<DrawingArea<SVGBackend<'_>, plotters::coord::Shift>, Box<dyn std::error::Error>> {
    plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
        .map_err(|_| "the embedded font could not be loaded")?;
    let root = SVGBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE)?;
    Ok(root)
}

/// The chart's legend at `at`, boxed on white.
pub fn legend<'a, DB: DrawingBackend + 'a, CT: plotters::coord::CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    at: SeriesLabelPosition,
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    chart
        .configure_series_labels()
        .position(at)
        .background_style(WHITE)
        .border_style(BLACK)
        .draw()?;
    Ok(())
}

/// The range `[lo, hi]` of finite values, widened by 5 % (and to a unit span when flat).
pub fn range(values: impl IntoIterator<Item = f64>) -> std::ops::Range<f64> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.into_iter().filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if lo >= hi {
        return (lo - 0.5)..(lo + 0.5);
    }
    let pad = 0.05 * (hi - lo);
    (lo - pad)..(hi + pad)
}
