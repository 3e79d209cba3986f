//! Villien & Ostertag's Example 1 (§VI-A, eqs. 38-39, Fig. 3) as the paper ran it: a sample
//! at each zero crossing of the Doppler signal (every half period, so every `1/(2k)` m of
//! range) from 10 m before the radar until the target crosses it, the target's speed and miss
//! distance drawn at random, 300 Monte Carlo runs; the raw-sample maximum-likelihood fit (ML),
//! the same fit on the order-5 polynomial samples (PAML), the extended Kalman filter and the
//! Cramér–Rao bound, by how far the target has flown; then PAML's σ by order at the crossing.
//! Shared by the example `paml_example1` and the test `paml_examples` (included by path), so
//! the test regenerates the docs page's block.

#![allow(dead_code)]

use crate::doppler::{doppler, Doppler, Scenario, K_DOPPLER, K_JITTER, PRIOR_SIGMA, SIGMA_FLOOR};
use crate::paml_report::sig;
use nalgebra::{DMatrix, DVector};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use rayon::prelude::*;
use seqsmooth::estimate::curve::{cramer_rao_bound, fit_curve};
use seqsmooth::kalman::KalmanFilter;
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
use seqsmooth::model::observation::NonlinearObservation;
use seqsmooth::paml::PolynomialSamples;

/// Where the observation starts: `x₀`, the along-track distance to the radar (m), as eq. 39
/// prints it.
pub const START: f64 = 10.0;
/// The speeds drawn (m/s), as printed.
pub const SPEED: (f64, f64) = (1000.0, 1800.0);
/// The miss distances drawn (m): not printed. 1,200 crossings from 10 m fix it at 0.96 m.
pub const MISS: (f64, f64) = (0.5, 1.5);
/// The paper's order.
pub const ORDER: usize = 5;
/// The observation ends when the target is this far (m, along track) before the radar.
pub const ENDS: [f64; 9] = [5.0, 3.0, 2.0, 1.5, 1.0, 0.75, 0.5, 0.25, 0.0];
/// The orders tried at the crossing.
pub const ORDERS: std::ops::RangeInclusive<usize> = 5..=20;
/// PAML's σ within this share of ML's.
pub const WITHIN: f64 = 0.02;

/// One run's target and zero-crossing samples (from `t = 0` at `x = x₀` to the last
/// crossing before `x = 0`), σ from eq. 39 at the truth (known to the estimators, eq. 1).
pub fn scenario(rng: &mut impl Rng) -> Scenario {
    let v0 = rng.gen_range(SPEED.0..SPEED.1);
    let y0 = rng.gen_range(MISS.0..MISS.1);
    let truth = [START, y0, v0];
    let r0 = START.hypot(y0);
    // Each half period of the Doppler signal the range falls by λ/4 = 1/(2k).
    let step = 1.0 / (2.0 * K_DOPPLER);
    let mut times = vec![];
    let mut j = 0;
    loop {
        let r = r0 - j as f64 * step;
        if r < y0 {
            break;
        }
        times.push((START - (r * r - y0 * y0).max(0.0).sqrt()) / v0);
        j += 1;
    }
    let sigmas = times
        .iter()
        .map(|t| {
            let x = START - v0 * t;
            (K_JITTER * x.powi(4) + SIGMA_FLOOR * SIGMA_FLOOR).sqrt()
        })
        .collect();
    Scenario {
        truth,
        times,
        sigmas,
    }
}

/// The samples taken before the target is `end` metres (along track) from the radar.
fn count(sc: &Scenario, end: f64) -> usize {
    sc.times
        .iter()
        .take_while(|&&t| START - sc.truth[2] * t >= end)
        .count()
}

/// A run's errors (estimate − truth; `y₀` by its size, since `±y₀` are one track).
type Errors = [f64; 3];

fn error(p: &[f64], truth: &[f64; 3]) -> Errors {
    [p[0] - truth[0], p[1].abs() - truth[1], p[2] - truth[2]]
}

/// One run's results: at each end, the CRLB variances and ML, PAML, EKF errors (`None` where
/// a fit refused); at the crossing, PAML's errors by order.
struct Run {
    samples: usize,
    speed: f64,
    crlb: Vec<[f64; 3]>,
    ml: Vec<Option<Errors>>,
    paml: Vec<Option<Errors>>,
    ekf: Vec<Option<Errors>>,
    by_order: Vec<Option<Errors>>,
}

/// The extended Kalman filter on the constant `θ` from `start` with covariance
/// `diag(PRIOR_SIGMA²)` (as `doppler::extended_kalman`), its estimate after each count.
fn ekf(sc: &Scenario, y: &[f64], start: &[f64; 3], counts: &[usize]) -> Vec<Option<Errors>> {
    let observation = NonlinearObservation::new(1, 3, |t, x: &DVector<f64>| {
        DVector::from_element(1, doppler(x.as_slice(), t).0)
    })
    .with_jacobian(|t, x: &DVector<f64>| {
        DMatrix::from_row_slice(1, 3, &doppler(x.as_slice(), t).1)
    });
    let p0 = DMatrix::from_diagonal(&DVector::from_iterator(
        3,
        PRIOR_SIGMA.iter().map(|s| s * s),
    ));
    let Ok(mut f) = KalmanFilter::new(
        PolynomialDynamics::new(0, 3),
        observation,
        DVector::from_column_slice(start),
        p0,
        sc.times[0],
    ) else {
        return vec![None; counts.len()];
    };
    let mut out = vec![None; counts.len()];
    for (k, ((&t, &v), s)) in sc.times.iter().zip(y).zip(&sc.sigmas).enumerate() {
        let m = Measurement {
            time: t,
            values: vec![Some(v)],
            noise: NoiseCovariance::Variances(vec![s * s]),
        };
        if f.update(&m).is_err() {
            return out;
        }
        for (o, &c) in out.iter_mut().zip(counts) {
            if c == k + 1 {
                *o = Some(error(f.state().as_slice(), &sc.truth));
            }
        }
    }
    out
}

fn run(seed: u64, index: usize) -> Run {
    let mut rng = StdRng::seed_from_u64(seed ^ (index as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let full = scenario(&mut rng);
    let y = full.measure(&mut rng);
    // The start (the prior knowledge of the paper's "good prior"): the truth with PRIOR_SIGMA.
    let mut start = full.truth;
    for (v, s) in start.iter_mut().zip(PRIOR_SIGMA) {
        *v += s * rng.sample::<f64, _>(StandardNormal);
    }
    let counts: Vec<usize> = ENDS.iter().map(|&e| count(&full, e)).collect();
    let (mut crlb, mut ml, mut paml) = (vec![], vec![], vec![]);
    // Each span's fits start where the previous span's ML fit ended when that fit knows every
    // parameter better than the prior does, else at the prior: ML and PAML share the start.
    let mut from = start;
    for &c in &counts {
        let sc = full.first(c);
        let b = cramer_rao_bound(&Doppler, &sc.truth, &sc.times, &sc.sigmas)
            .map(|b| [b[(0, 0)], b[(1, 1)], b[(2, 2)]])
            .unwrap_or([f64::NAN; 3]);
        crlb.push(b);
        let raw = fit_curve(&Doppler, &sc.times, &y[..c], &sc.sigmas, &from);
        let ps = PolynomialSamples::from_segment(&sc.times, &y[..c], &sc.sigmas, ORDER)
            .and_then(|ps| ps.fit(&Doppler, &from));
        paml.push(ps.ok().map(|f| error(f.parameters.as_slice(), &sc.truth)));
        ml.push(
            raw.as_ref()
                .ok()
                .map(|f| error(f.parameters.as_slice(), &sc.truth)),
        );
        if c == full.times.len() {
            break;
        }
        from = match raw {
            Ok(f) if f.std_devs().iter().zip(PRIOR_SIGMA).all(|(s, p)| *s < p) => {
                [f.parameters[0], f.parameters[1].abs(), f.parameters[2]]
            }
            _ => start,
        };
    }
    let by_order = ORDERS
        .map(|n| {
            PolynomialSamples::from_segment(&full.times, &y, &full.sigmas, n)
                .and_then(|ps| ps.fit(&Doppler, &from))
                .ok()
                .map(|f| error(f.parameters.as_slice(), &full.truth))
        })
        .collect();
    Run {
        samples: full.times.len(),
        speed: full.truth[2],
        crlb,
        ml,
        ekf: ekf(&full, &y, &start, &counts),
        paml,
        by_order,
    }
}

/// The report's numbers, for the table and the plot.
pub struct Report {
    pub runs: usize,
    /// By end: `[crlb, ml, paml, ekf][parameter]` (RMS over the runs in which ML and PAML
    /// both converged; the CRLB's the root mean variance over the same runs).
    pub sigma: Vec<[[f64; 3]; 4]>,
    /// By end: the runs in which ML or PAML refused.
    pub failed: Vec<usize>,
    /// By end: the mean duration (s) of the observation.
    pub duration: Vec<f64>,
    /// By order at the crossing: PAML σ / ML σ per parameter.
    pub ratio: Vec<[f64; 3]>,
    /// The mean and range of the samples per run.
    pub samples: (f64, usize, usize),
    pub text: String,
}

fn rms(v: &[Errors]) -> [f64; 3] {
    let n = v.len().max(1) as f64;
    [0, 1, 2].map(|i| (v.iter().map(|e| e[i] * e[i]).sum::<f64>() / n).sqrt())
}

/// Runs `runs` Monte Carlo runs from `seed` (each run's generator seeded from the seed and
/// its index, so the result is the same on any number of threads).
pub fn report(runs: usize, seed: u64) -> Report {
    let all: Vec<Run> = (0..runs).into_par_iter().map(|i| run(seed, i)).collect();
    let mut sigma = vec![];
    let mut failed = vec![];
    for e in 0..ENDS.len() {
        let ok: Vec<&Run> = all
            .iter()
            .filter(|r| r.ml[e].is_some() && r.paml[e].is_some())
            .collect();
        failed.push(runs - ok.len());
        let n = ok.len().max(1) as f64;
        let crlb = [0, 1, 2].map(|i| (ok.iter().map(|r| r.crlb[e][i]).sum::<f64>() / n).sqrt());
        let pick = |f: &dyn Fn(&Run) -> Option<Errors>| -> Vec<Errors> {
            ok.iter().filter_map(|r| f(r)).collect()
        };
        let ml = rms(&pick(&|r| r.ml[e]));
        let paml = rms(&pick(&|r| r.paml[e]));
        let ekf = rms(&pick(&|r| r.ekf[e]));
        sigma.push([crlb, ml, paml, ekf]);
    }
    // The time to fly from x₀ to `end`, (x₀ − end)/v₀, averaged over the runs.
    let duration: Vec<f64> = ENDS
        .iter()
        .map(|&end| all.iter().map(|r| (START - end) / r.speed).sum::<f64>() / runs as f64)
        .collect();
    // At the crossing, PAML by order against ML over the runs where all converged.
    let last = ENDS.len() - 1;
    let ok: Vec<&Run> = all
        .iter()
        .filter(|r| r.ml[last].is_some() && r.by_order.iter().all(Option::is_some))
        .collect();
    let ml_full = rms(&ok.iter().filter_map(|r| r.ml[last]).collect::<Vec<_>>());
    let ratio: Vec<[f64; 3]> = (0..ORDERS.count())
        .map(|k| {
            let p = rms(&ok.iter().filter_map(|r| r.by_order[k]).collect::<Vec<_>>());
            [0, 1, 2].map(|i| p[i] / ml_full[i])
        })
        .collect();
    let counts: Vec<usize> = all.iter().map(|r| r.samples).collect();
    let samples = (
        counts.iter().sum::<usize>() as f64 / runs.max(1) as f64,
        counts.iter().copied().min().unwrap_or(0),
        counts.iter().copied().max().unwrap_or(0),
    );
    let mut text = String::new();
    let mut w = |s: String| {
        text.push_str(&s);
        text.push('\n');
    };
    w(format!(
        "Example 1: {runs} runs, seed {seed}; v0 uniform on {}-{} m/s, y0 uniform on {}-{} m, \
         x0 = {START} m; {:.0} zero crossings a run on average ({}-{})",
        SPEED.0, SPEED.1, MISS.0, MISS.1, samples.0, samples.1, samples.2
    ));
    w(String::new());
    w(
        "σ by how far the target is from the radar when the observation ends (RMS over the runs; \
       CRLB: root mean bound)"
            .into(),
    );
    w(String::new());
    w("| to the radar (m) | mean span (ms) | failed | CRLB x0 | ML x0 | PAML-5 x0 | EKF x0 | CRLB y0 | ML y0 | PAML-5 y0 | EKF y0 | CRLB v0 | ML v0 | PAML-5 v0 |".into());
    w("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|".into());
    for (e, end) in ENDS.iter().enumerate() {
        let s = &sigma[e];
        w(format!(
            "| {end} | {:.2} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            duration[e] * 1e3,
            failed[e],
            sig(s[0][0], 3),
            sig(s[1][0], 3),
            sig(s[2][0], 3),
            sig(s[3][0], 3),
            sig(s[0][1], 3),
            sig(s[1][1], 3),
            sig(s[2][1], 3),
            sig(s[3][1], 3),
            sig(s[0][2], 3),
            sig(s[1][2], 3),
            sig(s[2][2], 3),
        ));
    }
    w(String::new());
    w(format!(
        "PAML σ / ML σ at the crossing, by order ({} runs where every fit converged)",
        ok.len()
    ));
    w(String::new());
    w("| order n | x0 | y0 | v0 |".into());
    w("|---:|---:|---:|---:|".into());
    for (n, r) in ORDERS.zip(&ratio) {
        w(format!(
            "| {n} | {} | {} | {} |",
            sig(r[0], 4),
            sig(r[1], 4),
            sig(r[2], 4)
        ));
    }
    let first = ORDERS
        .zip(&ratio)
        .find(|(_, r)| r.iter().all(|q| (q - 1.0).abs() <= WITHIN))
        .map(|(n, _)| n.to_string())
        .unwrap_or_else(|| format!("none up to {}", ORDERS.end()));
    w(String::new());
    w(format!(
        "lowest order with PAML σ within {} % of ML σ (x0, y0, v0): {first}",
        WITHIN * 100.0
    ));
    Report {
        runs,
        sigma,
        failed,
        duration,
        ratio,
        samples,
        text,
    }
}
