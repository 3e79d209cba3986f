//! Scratch measurement harness (replaced by the final test).

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use seqsmooth::polynomial::automatic::AutomaticFilter;

struct Sample {
    t: f64,
    truth: f64,
    y: f64,
    outlier: bool,
}

fn landing() -> Vec<[f64; 4]> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/landing.csv");
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|c| c.parse().unwrap()).collect();
            [v[0], v[1], v[2], v[3]]
        })
        .collect()
}

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
}

impl Score {
    fn add(&mut self, proto: &AutomaticFilter, data: &[Sample], sigma: f64) {
        let mut f = proto.clone();
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
            if s.outlier {
                self.outliers += 1;
                self.outliers_rejected += o.outlier as usize;
            } else {
                self.good += 1;
                self.good_rejected += o.outlier as usize;
            }
            self.misfit += o.misfit as usize;
        }
        let r = f.noise_sigma().unwrap() / sigma;
        self.sigma_err2 += (r - 1.0).powi(2);
        self.sigma_ratio += r;
        self.runs += 1;
    }
    fn print(&self, what: &str) {
        let p = |a: usize, b: usize| 100.0 * a as f64 / b.max(1) as f64;
        println!(
            "{what}: coverage {:.2}% of {} (no σ {}), good rejected {:.3}% of {}, outliers rejected {:.2}% of {}, misfit {:.2}%, σ̂/σ mean {:.4} rms err {:.4}",
            p(self.covered, self.reported),
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

#[test]
fn measure() {
    let rows = landing();
    let proto = AutomaticFilter::new(2, 0.95, 2.72).unwrap();
    for sigma in [1.0, 10.0] {
        for (col, name) in [(1, "east"), (2, "north"), (3, "up")] {
            let mut s = Score::default();
            for seed in 0..200 {
                s.add(&proto, &landing_run(&rows, col, sigma, seed), sigma);
            }
            s.print(&format!("landing {name} σ {sigma}"));
        }
    }
    let proto = AutomaticFilter::new(2, 0.95, 1.0).unwrap();
    for sigma in [1.0, 10.0] {
        for (amp, period) in [(5000.0, 600.0), (5000.0, 1000.0), (1000.0, 120.0)] {
            let mut s = Score::default();
            for seed in 0..200 {
                s.add(&proto, &turning_run(amp, period, sigma, seed), sigma);
            }
            s.print(&format!("turning A {amp} P {period} σ {sigma}"));
        }
    }
}

#[test]
fn trace() {
    let rows = landing();
    let proto = AutomaticFilter::new(2, 0.95, 2.72).unwrap();
    let data = landing_run(&rows, 1, 10.0, 3);
    let mut f = proto.clone();
    for (i, s) in data.iter().enumerate() {
        let o = f.update(s.t, s.y).unwrap();
        let (e, sd) = match &o.estimate {
            Some(est) => (est.derivatives[0] - s.truth, est.std_devs().map_or(f64::NAN, |v| v[0])),
            None => (f64::NAN, f64::NAN),
        };
        if i < 60 || (e / sd).abs() > 3.0 || o.restart {
            println!("{i:3} t {:7.2} d{} {:?} err {:9.2} sd {:7.2} z {:6.1} out {} mis {} rst {} σ {:?}", s.t, o.degree, o.phase, e, sd, e / sd, o.outlier as u8, o.misfit as u8, o.restart as u8, o.noise_sigma);
        }
    }
}
