//! Reproducible manoeuvring-target scenarios for the automatic filter, and their scoring.
//!
//! Scenarios ([`track`]): one coordinate of a target moving straight at 50 m/s, accelerating
//! from t = 800 s, then straight again; sampled at jittered steps (τ = 1 s ± 30%, uniform) with
//! 5% of the samples dropped; Gaussian noise σ = 10 m (known unless stated); 2% of the samples
//! carry a ±5σ outlier. Two manoeuvres:
//!
//! - [`GENTLE`]: 0.01 m/s² for 600 s (a ship gaining 6 m/s in ten minutes; 180σ of displacement).
//!   A degree-2 filter models it exactly except at the two changes of acceleration, whose
//!   transients stay well inside the estimate's 1σ — the filter runs undisturbed. This is where
//!   coverage, outlier detection and the switch are measured.
//! - [`SHARP`]: 3 m/s² = 0.3 σ/τ² for 100 s. Unmodelled by a degree-1 filter, whose misfit flag
//!   must fire within 10 samples; a degree-2 filter restarts its memory at both changes
//!   ([`MisfitResponse::Restart`]) and must keep its coverage.
//!
//! 100 runs of 2200 samples each (fixed seeds). "After start-up" means from the first switch to
//! fading memory on.

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use seqsmooth::polynomial::automatic::{AutoOutput, AutomaticFilter, Phase};

pub const SIGMA: f64 = 10.0;
pub const SAMPLES: usize = 2200;
pub const RUNS: u64 = 100;
/// Samples after each change of acceleration left out of the coverage score: the misfit
/// detection delay bound (the flag covers an unmodelled manoeuvre from then on).
pub const DETECTION_BOUND: usize = 10;

/// A constant-acceleration segment between two straight ones.
#[derive(Clone, Copy, Debug)]
pub struct Manoeuvre {
    pub onset: f64,
    pub end: f64,
    pub accel: f64,
}

pub const GENTLE: Manoeuvre = Manoeuvre {
    onset: 800.0,
    end: 1400.0,
    accel: 0.01,
};

pub const SHARP: Manoeuvre = Manoeuvre {
    onset: 800.0,
    end: 900.0,
    accel: 3.0,
};

#[derive(Clone, Copy, Debug)]
pub struct Sample {
    pub t: f64,
    pub truth: f64,
    pub y: f64,
    pub outlier: bool,
}

/// The scenario generator (see the file docs).
pub fn track(seed: u64, man: Manoeuvre) -> Vec<Sample> {
    let mut r = StdRng::seed_from_u64(seed);
    let noise = Normal::new(0.0, SIGMA).unwrap();
    let v = 50.0;
    let position = |t: f64| {
        let mut x = v * t.min(man.onset);
        if t > man.onset {
            let d = t.min(man.end) - man.onset;
            x += v * d + 0.5 * man.accel * d * d;
            if t > man.end {
                x += (v + man.accel * (man.end - man.onset)) * (t - man.end);
            }
        }
        x
    };
    let mut out = Vec::with_capacity(SAMPLES);
    let mut t = 0.0;
    while out.len() < SAMPLES {
        t += 1.0 + 0.3 * (2.0 * r.gen::<f64>() - 1.0);
        if r.gen::<f64>() < 0.05 {
            continue; // dropout
        }
        let truth = position(t);
        let outlier = r.gen::<f64>() < 0.02;
        let sign = if r.gen::<bool>() { 1.0 } else { -1.0 };
        let y = truth + noise.sample(&mut r) + if outlier { 5.0 * SIGMA * sign } else { 0.0 };
        out.push(Sample {
            t,
            truth,
            y,
            outlier,
        });
    }
    out
}

/// Index of the first sample at or after `t`.
pub fn index_at(data: &[Sample], t: f64) -> usize {
    data.iter().position(|s| s.t >= t).unwrap()
}

#[derive(Default, Debug)]
pub struct Score {
    pub covered: usize,
    pub scored: usize,
    pub covered_all: usize,
    pub scored_all: usize,
    pub outliers: usize,
    pub flagged_outliers: usize,
    /// Outliers arriving while the memory grows back after a restart (expanding phase).
    pub regrowth_outliers: usize,
    pub regrowth_flagged: usize,
    pub good: usize,
    pub false_alarms: usize,
    pub straight: usize,
    pub straight_misfit: usize,
    pub restarts: u64,
}

pub fn rate(a: usize, b: usize) -> f64 {
    a as f64 / b.max(1) as f64
}

impl Score {
    pub fn coverage(&self) -> f64 {
        rate(self.covered, self.scored)
    }
    pub fn coverage_all(&self) -> f64 {
        rate(self.covered_all, self.scored_all)
    }
    pub fn detection(&self) -> f64 {
        rate(self.flagged_outliers, self.outliers)
    }
    pub fn false_alarm_rate(&self) -> f64 {
        rate(self.false_alarms, self.good)
    }
    pub fn misfit_rate(&self) -> f64 {
        rate(self.straight_misfit, self.straight)
    }
    pub fn print(&self, what: &str) {
        println!(
            "{what}:\n  coverage ±3σ {:.2}% of {} scored samples (all samples after start-up: \
             {:.2}% of {})\n  outliers flagged {:.2}% of {} (of which {} in a regrowth after a \
             restart: {:.1}% flagged)\n  false alarms {:.3}% of {} good samples\n  misfit on \
             straight segments {:.2}% of {}; restarts {}",
            100.0 * self.coverage(),
            self.scored,
            100.0 * self.coverage_all(),
            self.scored_all,
            100.0 * self.detection(),
            self.outliers,
            self.regrowth_outliers,
            100.0 * rate(self.regrowth_flagged, self.regrowth_outliers),
            100.0 * self.false_alarm_rate(),
            self.good,
            100.0 * self.misfit_rate(),
            self.straight,
            self.restarts
        );
    }
}

/// Runs a fresh clone of `prototype` (a filter without samples) over every run of the scenario and scores it after the start-up. Coverage:
/// the true position inside the reported ±3σ, scored except while the misfit flag is up and
/// for [`DETECTION_BOUND`] samples after each change of acceleration (and also over all
/// samples). Straight segments: before the onset and from [`DETECTION_BOUND`] samples after the
/// end. Returns the score and the outputs of the first run.
pub fn score(prototype: &AutomaticFilter, man: Manoeuvre) -> (Score, Vec<AutoOutput>) {
    let mut total = Score::default();
    let mut first = Vec::new();
    for seed in 0..RUNS {
        let data = track(seed, man);
        let onset = index_at(&data, man.onset);
        let end = index_at(&data, man.end);
        let mut f = prototype.clone();
        let mut started = false;
        let mut outs = Vec::with_capacity(data.len());
        for (i, s) in data.iter().enumerate() {
            let o = f.update(s.t, s.y).unwrap();
            let was_started = started;
            started |= o.phase == Phase::Fading;
            if started {
                let est = o.estimate.as_ref().expect("determined after start-up");
                let sd = est.std_devs().expect("σ known or estimated")[0];
                let inside = (est.derivatives[0] - s.truth).abs() <= 3.0 * sd;
                total.scored_all += 1;
                total.covered_all += inside as usize;
                let near_change = (onset..onset + DETECTION_BOUND).contains(&i)
                    || (end..end + DETECTION_BOUND).contains(&i);
                if !o.misfit && !near_change {
                    total.scored += 1;
                    total.covered += inside as usize;
                }
                if s.outlier {
                    total.outliers += 1;
                    total.flagged_outliers += o.outlier as usize;
                    if was_started && o.phase != Phase::Fading {
                        total.regrowth_outliers += 1;
                        total.regrowth_flagged += o.outlier as usize;
                    }
                } else {
                    total.good += 1;
                    total.false_alarms += o.outlier as usize;
                }
                if i < onset || i >= end + DETECTION_BOUND {
                    total.straight += 1;
                    total.straight_misfit += o.misfit as usize;
                }
            }
            outs.push(o);
        }
        total.restarts += f.restarts();
        if seed == 0 {
            first = outs;
        }
    }
    (total, first)
}

/// The scenarios' filter with every default: degree 2, θ = 0.97 per τ = 1 s, σ estimated.
pub fn main_defaults() -> AutomaticFilter {
    AutomaticFilter::new(2, 0.97, 1.0).unwrap()
}

/// [`main_defaults`] with the noise known: σ = [`SIGMA`].
pub fn main_filter() -> AutomaticFilter {
    main_defaults().with_noise_sigma(SIGMA).unwrap()
}

/// landing.csv's rows as `[time, east, north, up]`.
pub fn landing() -> Vec<[f64; 4]> {
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
