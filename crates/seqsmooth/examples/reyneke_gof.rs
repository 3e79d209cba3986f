//! Reyneke et al. (2012) §7.1's goodness-of-fit measure beside Morrison's χ² tests, by Monte
//! Carlo: on windows where the polynomial fits (false alarms) and where it does not
//! (detection), each test at the same false-alarm rate.
//!
//! cargo run --release -p seqsmooth --example reyneke_gof -- [--runs 4000] [--seed 1]
//!
//! A window of `N` evenly spaced samples (σ = 1) is fitted by least squares of degree `m` (the
//! paper's windowed expanding-memory filter). The truth is zero (fitted) or `c t^(m+1)` with `c`
//! set so that the fit's residuals carry a systematic part of `λ` (in units of σ², the
//! non-centrality of the residual χ²). The tests, each deciding "misfit" once per window:
//!
//! - `chi2 (Morrison)`: the window's residual sum of squares / σ² against the 99 % point of
//!   `χ²_{N−m−1}` (Morrison §5.6; [`ChiSquaredTest`]);
//! - `GOF, R known, alpha`: `G = E²/N` ([`goodness_of_fit`]) against [`gof_threshold`];
//! - `GOF, R known, 1-1/sqrt N`: `G` against the printed limit ([`reyneke_gof_limit`]);
//! - `GOF, R eq. 39, alpha`: `G` with `R` estimated on the window by eq. 39
//!   ([`reyneke_eq39_variance`]), against its 99 % point measured on fitted windows (a
//!   separate set of runs);
//! - `GOF, R eq. 39, 1-1/sqrt N`: the same `G` against the printed limit;
//! - `innovations (Morrison 14.8)`: the expanding-memory filter's 1-step innovations over the
//!   window, normalised by their predicted variance, summed over the `N − m − 1` after start-up
//!   ([`InnovationChiSquared`], the automatic filter's misfit test) against its 99 % point.

#[path = "common/papers.rs"]
mod papers;

use rand_distr::{Distribution, StandardNormal};
use seqsmooth::estimate::PolynomialFit;
use seqsmooth::stats::{
    gof_false_alarm_rate, gof_mean, gof_threshold, goodness_of_fit, reyneke_eq39_variance,
    reyneke_gof_limit, ChiSquaredTest, InnovationChiSquared,
};
use seqsmooth::{Engine, ExpandingMemory, PolynomialFilter};
use std::fmt::Write;

/// The false-alarm rate every test is set to.
const ALPHA: f64 = 0.01;
/// Windows `N` and degrees `m`.
const CASES: [(usize, usize); 3] = [(20, 1), (50, 1), (50, 2)];
/// Systematic parts `λ` of the misfit windows (0: the polynomial fits).
const LAMBDAS: [f64; 5] = [0.0, 5.0, 10.0, 20.0, 40.0];
const TESTS: [&str; 6] = [
    "chi2 (Morrison 5.6), alpha",
    "GOF, R known, alpha",
    "GOF, R known, 1-1/sqrt N",
    "GOF, R eq. 39, alpha (calibrated)",
    "GOF, R eq. 39, 1-1/sqrt N",
    "innovations (Morrison 14.8), alpha",
];

/// One window's statistics: residual χ², `G` with `R` known, `G` with eq. 39's `R`, the
/// innovations' sum.
struct Window {
    chi2: f64,
    g_known: f64,
    g_est: f64,
    innovations: bool,
    g_known_vs_chi2: bool,
}

fn window(n: usize, m: usize, c: f64, rng: &mut rand::rngs::StdRng) -> Window {
    let t: Vec<f64> = (0..n).map(|i| i as f64).collect();
    let y: Vec<f64> = t
        .iter()
        .map(|&t| c * t.powi(m as i32 + 1) + Distribution::<f64>::sample(&StandardNormal, rng))
        .collect();
    let fit = PolynomialFit::new(&t, &y, None, m).expect("window determines the fit");
    let residuals: Vec<f64> = t
        .iter()
        .zip(&y)
        .map(|(&t, &y)| y - fit.derivatives_at(t)[0])
        .collect();
    let chi2 = fit.residual_sq();
    let g_known = goodness_of_fit(&residuals, 1.0).expect("finite residuals");
    let r = reyneke_eq39_variance(&y).expect("a window of samples");
    let g_est = goodness_of_fit(&residuals, r).expect("finite residuals");
    // Morrison §14.8 on the same window: expanding memory from its start.
    let mut f = ExpandingMemory::new(m, Engine::Exact)
        .and_then(|f| f.with_noise_sigma(1.0))
        .expect("degree");
    let mut test = InnovationChiSquared::new(n - m - 1, ALPHA).expect("window, α");
    let mut misfit = false;
    for (&t, &y) in t.iter().zip(&y) {
        if let Some(p) = f.estimate_at(t) {
            let var = 1.0 + p.covariance.expect("σ tracked")[(0, 0)];
            misfit = test.push(y - p.derivatives[0], var).expect("finite").misfit;
        }
        f.update(t, y).expect("finite sample");
    }
    let chi = ChiSquaredTest::new((n - m - 1) as f64, ALPHA).expect("dof, α");
    let by_gof = g_known > gof_threshold(n, m, ALPHA).expect("window");
    Window {
        chi2,
        g_known,
        g_est,
        innovations: misfit,
        g_known_vs_chi2: by_gof == chi.rejects(chi2),
    }
}

/// The residual sum of squares of the degree-`m` fit of `t^(m+1)` on the window (noise-free):
/// `c = √(λ / this)` puts `λ` in the residuals.
fn unit_misfit(n: usize, m: usize) -> f64 {
    let t: Vec<f64> = (0..n).map(|i| i as f64).collect();
    let y: Vec<f64> = t.iter().map(|t| t.powi(m as i32 + 1)).collect();
    PolynomialFit::new(&t, &y, None, m)
        .expect("fit")
        .residual_sq()
}

fn share(w: &[Window], f: impl Fn(&Window) -> bool) -> f64 {
    w.iter().filter(|w| f(w)).count() as f64 / w.len() as f64
}

/// The printed tables at `runs` windows per case from `seed` (the block docs/reyneke.md holds).
pub fn report(runs: usize, seed: u64) -> String {
    let mut out = String::new();
    writeln!(
        out,
        "Reyneke et al. 7.1 GOF vs Morrison's chi-squared tests: alpha = {ALPHA}, sigma = 1, {runs} windows per cell, seed {seed}"
    )
    .unwrap();
    for (case, &(n, m)) in CASES.iter().enumerate() {
        let unit = unit_misfit(n, m);
        let cell = |k: usize, lambda: f64, s: u64| {
            let c = (lambda / unit).sqrt();
            papers::monte_carlo(runs, s.wrapping_add((case * 10 + k) as u64), |_, rng| {
                window(n, m, c, rng)
            })
        };
        // The eq. 39 measure's 99 % point on fitted windows, from runs of their own.
        let mut calib: Vec<f64> = cell(9, 0.0, seed ^ 0xCA11B)
            .iter()
            .map(|w| w.g_est)
            .collect();
        calib.sort_by(f64::total_cmp);
        let c39 = calib[((1.0 - ALPHA) * calib.len() as f64) as usize - 1];
        let chi = ChiSquaredTest::new((n - m - 1) as f64, ALPHA).expect("dof, α");
        let (g_alpha, limit) = (
            gof_threshold(n, m, ALPHA).unwrap(),
            reyneke_gof_limit(n).unwrap(),
        );
        let cells: Vec<Vec<Window>> = LAMBDAS
            .iter()
            .enumerate()
            .map(|(k, &l)| cell(k, l, seed))
            .collect();
        let fitted = &cells[0];
        let mean = |f: fn(&Window) -> f64| fitted.iter().map(f).sum::<f64>() / fitted.len() as f64;
        writeln!(out).unwrap();
        writeln!(
            out,
            "N = {n}, m = {m}: mean G on fitted windows {:.4} (R known), {:.4} (R eq. 39); E[G] = 1-(m+1)/N = {:.4}; printed limit 1-1/sqrt N = {:.4}",
            mean(|w| w.g_known),
            mean(|w| w.g_est),
            gof_mean(n, m).unwrap(),
            limit
        )
        .unwrap();
        writeln!(
            out,
            "thresholds on G: alpha {g_alpha:.4}; eq. 39 calibrated {c39:.4}; printed limit {limit:.4} (false-alarm rate with R known, chi2 theory: {:.3})",
            gof_false_alarm_rate(n, m, limit).unwrap()
        )
        .unwrap();
        writeln!(
            out,
            "GOF with R known at alpha and the chi2 test: same decision in {:.4} of the windows",
            cells.iter().flatten().filter(|w| w.g_known_vs_chi2).count() as f64
                / (cells.len() * runs) as f64
        )
        .unwrap();
        write!(out, "{:36} |", "P(misfit) by test \\ lambda").unwrap();
        for l in LAMBDAS {
            write!(out, " {l:6.0}").unwrap();
        }
        writeln!(out).unwrap();
        let decide: [&dyn Fn(&Window) -> bool; 6] = [
            &|w| chi.rejects(w.chi2),
            &|w| w.g_known > g_alpha,
            &|w| w.g_known > limit,
            &|w| w.g_est > c39,
            &|w| w.g_est > limit,
            &|w| w.innovations,
        ];
        for (name, d) in TESTS.iter().zip(decide) {
            write!(out, "{name:36} |").unwrap();
            for w in &cells {
                write!(out, " {:6.3}", share(w, d)).unwrap();
            }
            writeln!(out).unwrap();
        }
    }
    out
}

fn main() {
    let a = papers::args(4000, 1);
    print!("{}", report(a.runs, a.seed));
}
