//! Must-show 3 of the honest automatic filter: Monte Carlo on a real track and on simulated
//! turning tracks, every row that reports a σ scored (start-up included).
//!
//! - `landing`: `tests/data/landing.csv` (a smooth approach-and-landing trajectory, see
//!   `tests/data/README.md`), east, north and up separately, plus white Gaussian noise of
//!   σ = 1 m and 10 m; degree 2, θ = 0.95 per τ = 2.72 s (the nominal step), σ estimated.
//! - `turning`: `x(t) = A sin(2πt/P + φ) + 50 t` (φ uniform per run), steps 1 s ± 40% (uniform),
//!   σ = 10 m, 2% outliers of 5-10σ (uniform size, random sign), 600 samples; degree 2,
//!   θ = 0.95 per 1 s. A gentle turn (A = 5 km, P = 1000 s) and a sharp one (A = 1 km,
//!   P = 120 s: 2.7 m/s², far beyond what θ = 0.95 follows within σ).
//!
//! 200 runs each (seeds 0-199). Scored: ±3σ coverage of the truth over every row with an
//! estimate and a σ, as the row reported it; each sample's final outlier decision
//! (`final_outliers` of the outputs and `finish`: the review's decision by interpolation, see
//! `polynomial::automatic::review`; `seqsmooth filter` writes the same); `σ̂/σ` after the last
//! sample (RMS relative error over the runs).
//! Tolerances from the sample size: the pooled coverage over ~93 000 rows (landing) or ~120 000
//! (turning) has a binomial standard error of 0.05% at 97% (runs are correlated within a track,
//! the per-run spread is printed as its standard error over 200 runs); good-sample rejections at
//! 1% have an SE of 0.03%; outlier detection over ~2 400 outliers at 95% an SE of 0.45%; the
//! RMS of σ̂/σ − 1 over 200 runs is known to ±5% of itself. The thresholds are the issue's,
//! asserted as they are on every scenario.

mod common;

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use seqsmooth::polynomial::automatic::{final_outliers, AutomaticFilter};

struct Sample {
    t: f64,
    truth: f64,
    y: f64,
    outlier: bool,
}

use common::automatic::landing;

fn landing_run(rows: &[[f64; 4]], col: usize, sigma: f64, seed: u64) -> Vec<Sample> {
    let mut r = StdRng::seed_from_u64(seed);
    let n = Normal::new(0.0, sigma).unwrap();
    rows.iter()
        .map(|row| Sample {
            t: row[0],
            truth: row[col],
            y: row[col] + n.sample(&mut r),
            outlier: false,
        })
        .collect()
}

fn turning_run(amp: f64, period: f64, sigma: f64, seed: u64) -> Vec<Sample> {
    let mut r = StdRng::seed_from_u64(seed);
    let n = Normal::new(0.0, sigma).unwrap();
    let phase = r.gen::<f64>() * std::f64::consts::TAU;
    let w = std::f64::consts::TAU / period;
    let mut t = 0.0;
    let mut out = Vec::new();
    while out.len() < 600 {
        t += 1.0 + 0.4 * (2.0 * r.gen::<f64>() - 1.0);
        let truth = amp * (w * t + phase).sin() + 50.0 * t;
        let outlier = r.gen::<f64>() < 0.02;
        let size = sigma * r.gen_range(5.0..10.0) * if r.gen::<bool>() { 1.0 } else { -1.0 };
        out.push(Sample {
            t,
            truth,
            y: truth + n.sample(&mut r) + if outlier { size } else { 0.0 },
            outlier,
        });
    }
    out
}

#[derive(Default, Debug)]
struct Score {
    rows: usize,
    no_sigma: usize,
    reported: usize,
    covered: usize,
    good: usize,
    good_rejected: usize,
    outliers: usize,
    outliers_rejected: usize,
    misfit: usize,
    sigma_err2: f64,
    sigma_ratio: f64,
    runs: usize,
    run_coverage: Vec<f64>,
}

impl Score {
    fn add(&mut self, proto: &AutomaticFilter, data: &[Sample], sigma: f64) {
        let mut f = proto.clone();
        let (c0, r0) = (self.covered, self.reported);
        let mut outs = Vec::with_capacity(data.len());
        for s in data {
            let o = f.update(s.t, s.y).unwrap();
            self.rows += 1;
            if let Some(est) = &o.estimate {
                match est.std_devs() {
                    Some(sd) => {
                        self.reported += 1;
                        self.covered +=
                            ((est.derivatives[0] - s.truth).abs() <= 3.0 * sd[0]) as usize;
                    }
                    None => self.no_sigma += 1,
                }
            }
            self.misfit += o.misfit as usize;
            outs.push(o);
        }
        // A rejection is final once a later sample is taken: a run applied after all as a
        // manoeuvre's onset is not rejected.
        let tail = f.finish();
        for (s, rejected) in data.iter().zip(final_outliers(&outs, &tail)) {
            if s.outlier {
                self.outliers += 1;
                self.outliers_rejected += rejected as usize;
            } else {
                self.good += 1;
                self.good_rejected += rejected as usize;
            }
        }
        self.run_coverage
            .push((self.covered - c0) as f64 / (self.reported - r0).max(1) as f64);
        let r = f.noise_sigma().unwrap() / sigma;
        self.sigma_err2 += (r - 1.0).powi(2);
        self.sigma_ratio += r;
        self.runs += 1;
    }
    fn coverage(&self) -> f64 {
        self.covered as f64 / self.reported.max(1) as f64
    }
    fn good_rejected(&self) -> f64 {
        self.good_rejected as f64 / self.good.max(1) as f64
    }
    fn detection(&self) -> f64 {
        self.outliers_rejected as f64 / self.outliers.max(1) as f64
    }
    fn sigma_rms(&self) -> f64 {
        (self.sigma_err2 / self.runs as f64).sqrt()
    }
    /// Standard error of the mean per-run coverage over the runs.
    fn coverage_se(&self) -> f64 {
        common::stats::standard_error_of_mean(&self.run_coverage)
    }
    fn print(&self, what: &str) {
        let p = |a: usize, b: usize| 100.0 * a as f64 / b.max(1) as f64;
        println!(
            "{what}: coverage {:.2}% (SE over runs {:.2}%) of {} (estimate without σ {}), good rejected {:.3}% of {}, outliers rejected {:.2}% of {}, misfit {:.2}%, σ̂/σ mean {:.4} rms err {:.4}",
            p(self.covered, self.reported),
            100.0 * self.coverage_se(),
            self.reported,
            self.no_sigma,
            p(self.good_rejected, self.good),
            self.good,
            p(self.outliers_rejected, self.outliers),
            self.outliers,
            p(self.misfit, self.rows),
            self.sigma_ratio / self.runs as f64,
            (self.sigma_err2 / self.runs as f64).sqrt()
        );
    }
}

const RUNS: u64 = 200;

/// Every scenario's name and score.
fn scenarios() -> Vec<(String, Score, bool)> {
    let rows = landing();
    let mut out = Vec::new();
    let proto = AutomaticFilter::new(2, 0.95, 2.72).unwrap();
    for sigma in [1.0, 10.0] {
        for (col, name) in [(1, "east"), (2, "north"), (3, "up")] {
            let mut s = Score::default();
            for seed in 0..RUNS {
                s.add(&proto, &landing_run(&rows, col, sigma, seed), sigma);
            }
            let what = format!("landing {name} σ = {sigma} m");
            s.print(&what);
            out.push((what, s, false));
        }
    }
    let proto = AutomaticFilter::new(2, 0.95, 1.0).unwrap();
    for (amp, period) in [(5000.0, 1000.0), (1000.0, 120.0)] {
        let mut s = Score::default();
        for seed in 0..RUNS {
            s.add(&proto, &turning_run(amp, period, 10.0, seed), 10.0);
        }
        let what = format!("turning A = {amp} m, P = {period} s, σ = 10 m");
        s.print(&what);
        out.push((what, s, true));
    }
    out
}

/// The thresholds that `s` misses.
fn misses(s: &Score, outliers: bool) -> Vec<String> {
    let mut m = Vec::new();
    if s.coverage() < 0.97 {
        m.push(format!("coverage {:.4} < 0.97", s.coverage()));
    }
    if s.good_rejected() > 0.01 {
        m.push(format!("good rejected {:.4} > 0.01", s.good_rejected()));
    }
    if outliers && s.detection() < 0.95 {
        m.push(format!("outliers rejected {:.4} < 0.95", s.detection()));
    }
    if s.sigma_rms() > 0.10 {
        m.push(format!("σ̂ RMS error {:.4} > 0.10", s.sigma_rms()));
    }
    m
}

#[test]
fn must_show_3_every_threshold() {
    let all = scenarios();
    assert_eq!(all.len(), 8);
    let failed: Vec<String> = all
        .iter()
        .flat_map(|(w, s, o)| misses(s, *o).into_iter().map(move |m| format!("{w}: {m}")))
        .collect();
    assert!(failed.is_empty(), "{failed:#?}");
}
