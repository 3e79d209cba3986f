//! Villien & Ostertag's Example 2 (§VI-B, eqs. 40-42, Fig. 5): a bullet's ballistic track
//! (eq. 41, `θ = y_f, z_f, d_v, v₀, φ, θ, γ`) seen by three ranging radars (eq. 40), 500
//! samples a radar from `d_v` before the radars' plane `x = 0` to it, noise eq. 42; the raw
//! samples' maximum-likelihood fit (ML), the same fit on each radar's 8 polynomial samples of
//! order 7 (PAML) and the Cramér–Rao bound, by observation time. The paper prints neither the
//! radars' positions nor the parameters' ranges (but `v ≈ 900 m/s`, 30 m): the constants
//! below are chosen. Shared by the example `paml_example2` and the test `paml_examples`.

#![allow(dead_code)]

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use rayon::prelude::*;
use seqsmooth::estimate::curve::{cramer_rao_bound, fit_curve, CurveModel};
use seqsmooth::paml::PolynomialSamples;
use seqsmooth::Error;

/// The radars (m), in the plane the bullet flies to (not printed).
pub const RADARS: [[f64; 3]; 3] = [[0.0, -2.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]];
/// `K` (m⁻²) and `σ₀` (m) of eq. 42, as printed.
pub const K_NOISE: f64 = 2.26e-8;
pub const SIGMA_FLOOR: f64 = 0.05;
/// Gravity (m/s²).
pub const G: f64 = 9.81;
/// Samples a radar, as printed.
pub const SAMPLES: usize = 500;
/// The order, as printed.
pub const ORDER: usize = 7;
/// The parameters' ranges (uniform; not printed but `v ≈ 900 m/s` over 30 m):
/// `y_f, z_f` (m), `d_v` (m), `v₀` (m/s), `φ` (rad), `θ` (rad), `γ` (1/m).
pub const RANGES: [(f64, f64); 7] = [
    (-1.0, 1.0),
    (-1.0, 1.0),
    (29.0, 31.0),
    (850.0, 950.0),
    (-0.087, 0.087),
    (-0.035, 0.035),
    (0.5e-3, 1.5e-3),
];
/// The prior the fits start from: the truth plus these σ.
pub const PRIOR_SIGMA: [f64; 7] = [0.2, 0.2, 0.5, 20.0, 0.01, 0.01, 2e-4];
/// The observation ends at these times (ms) and at the crossing.
pub const ENDS: [f64; 8] = [2.0, 3.0, 5.0, 7.5, 10.0, 15.0, 20.0, 25.0];
pub const NAMES: [&str; 7] = [
    "y_f (m)", "z_f (m)", "d_v (m)", "v0 (m/s)", "φ (rad)", "θ (rad)", "γ (1/m)",
];

/// Eq. 41: the bullet's position at `t`.
pub fn track(th: &[f64], t: f64) -> [f64; 3] {
    let (yf, zf, dv, v0, phi, theta, gamma) = (th[0], th[1], th[2], th[3], th[4], th[5], th[6]);
    let u = 1.0 + gamma * v0 * t;
    let along = dv - (1.0 - 1.0 / u) / gamma;
    [
        along * phi.cos(),
        along * phi.sin() + yf,
        t / u * (v0 * theta - G * t / 6.0 * (3.0 + gamma * v0 * t)) + zf - dv * theta,
    ]
}

/// Eq. 40: the range from radar `i`.
fn range(th: &[f64], t: f64, i: usize) -> f64 {
    let p = track(th, t);
    let r = RADARS[i];
    ((p[0] - r[0]).powi(2) + (p[1] - r[1]).powi(2) + (p[2] - r[2]).powi(2)).sqrt()
}

/// The rows `(t, radar)` addressed by index (the fit's "time"); Jacobian differenced.
struct Ranges {
    rows: Vec<(f64, usize)>,
}

impl CurveModel for Ranges {
    fn parameters(&self) -> usize {
        7
    }
    fn values(&self, th: &[f64], index: &[f64]) -> Result<Vec<f64>, Error> {
        Ok(index
            .iter()
            .map(|&i| {
                let (t, r) = self.rows[i as usize];
                range(th, t, r)
            })
            .collect())
    }
}

type Errors = [f64; 7];

struct Run {
    crlb: Vec<Errors>,
    ml: Vec<Option<Errors>>,
    paml: Vec<Option<Errors>>,
}

fn run(seed: u64, index: usize) -> Run {
    let mut rng = StdRng::seed_from_u64(seed ^ (index as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let truth: Errors = RANGES.map(|(a, b)| rng.gen_range(a..b));
    let (dv, v0, gamma) = (truth[2], truth[3], truth[6]);
    // The time the bullet has flown d_v: v₀t/(1 + γv₀t) = d_v.
    let t_end = dv / (v0 * (1.0 - gamma * dv));
    let times: Vec<f64> = (0..SAMPLES)
        .map(|k| t_end * k as f64 / (SAMPLES - 1) as f64)
        .collect();
    // Eq. 42 with the run's own distance to go, d_v − v₀t/(1 + γv₀t).
    let sigmas: Vec<f64> = times
        .iter()
        .map(|&t| {
            let go = dv - v0 * t / (1.0 + gamma * v0 * t);
            (K_NOISE * go.powi(4) + SIGMA_FLOOR * SIGMA_FLOOR).sqrt()
        })
        .collect();
    let y: Vec<[f64; 3]> = times
        .iter()
        .zip(&sigmas)
        .map(|(&t, s)| {
            [0, 1, 2].map(|i| range(&truth, t, i) + s * rng.sample::<f64, _>(StandardNormal))
        })
        .collect();
    let mut start = truth;
    for (v, s) in start.iter_mut().zip(PRIOR_SIGMA) {
        *v += s * rng.sample::<f64, _>(StandardNormal);
    }
    let prior = start;
    let mut counts: Vec<usize> = ENDS
        .iter()
        .map(|&ms| times.iter().take_while(|&&t| t <= ms * 1e-3).count())
        .collect();
    counts.push(SAMPLES);
    let err = |p: &[f64]| -> Errors { std::array::from_fn(|i| p[i] - truth[i]) };
    let (mut crlb, mut ml, mut paml) = (vec![], vec![], vec![]);
    for &c in &counts {
        let rows: Vec<(f64, usize)> = (0..3)
            .flat_map(|r| times[..c].iter().map(move |&t| (t, r)))
            .collect();
        let index: Vec<f64> = (0..rows.len()).map(|i| i as f64).collect();
        let values: Vec<f64> = (0..3)
            .flat_map(|r| y[..c].iter().map(move |v| v[r]))
            .collect();
        let noise: Vec<f64> = (0..3).flat_map(|_| sigmas[..c].iter().copied()).collect();
        let model = Ranges { rows };
        crlb.push(
            cramer_rao_bound(&model, &truth, &index, &noise)
                .map(|b| std::array::from_fn(|i| b[(i, i)]))
                .unwrap_or([f64::NAN; 7]),
        );
        let raw = fit_curve(&model, &index, &values, &noise, &start);
        // PAML: each radar's 8 polynomial samples.
        let mut rows = vec![];
        let (mut pv, mut ps_sigma) = (vec![], vec![]);
        let mut ok = true;
        for r in 0..3 {
            let v: Vec<f64> = y[..c].iter().map(|v| v[r]).collect();
            match PolynomialSamples::from_segment(&times[..c], &v, &sigmas[..c], ORDER) {
                Ok(ps) => {
                    for ((t, v), var) in ps.times().into_iter().zip(ps.values).zip(ps.variances) {
                        rows.push((t, r));
                        pv.push(v);
                        ps_sigma.push(var.sqrt());
                    }
                }
                Err(_) => ok = false,
            }
        }
        let index: Vec<f64> = (0..rows.len()).map(|i| i as f64).collect();
        let p = if ok {
            fit_curve(&Ranges { rows }, &index, &pv, &ps_sigma, &start).ok()
        } else {
            None
        };
        paml.push(p.map(|f| err(f.parameters.as_slice())));
        ml.push(raw.as_ref().ok().map(|f| err(f.parameters.as_slice())));
        // The next span starts from this ML fit when it knows every parameter better than
        // the prior, else from the prior.
        start = match raw {
            Ok(f) if f.std_devs().iter().zip(PRIOR_SIGMA).all(|(s, p)| *s < p) => {
                std::array::from_fn(|i| f.parameters[i])
            }
            _ => prior,
        };
    }
    Run { crlb, ml, paml }
}

pub struct Report {
    /// By end: `[crlb, ml, paml][parameter]`.
    pub sigma: Vec<[Errors; 3]>,
    pub text: String,
}

fn rms(v: &[Errors]) -> Errors {
    let n = v.len().max(1) as f64;
    std::array::from_fn(|i| (v.iter().map(|e| e[i] * e[i]).sum::<f64>() / n).sqrt())
}

pub fn report(runs: usize, seed: u64) -> Report {
    let all: Vec<Run> = (0..runs).into_par_iter().map(|i| run(seed, i)).collect();
    let sig = |v: f64| crate::paml_report::sig(v, 3);
    let mut text = format!(
        "Example 2: {runs} runs, seed {seed}; radars at {RADARS:?} m; {SAMPLES} samples a radar \
         to the plane x = 0; PAML order {ORDER}\n\n"
    );
    text.push_str("| observation (ms) | failed | CRLB y_f | ML y_f | PAML y_f | CRLB θ | ML θ | PAML θ | PAML/ML y_f | PAML/ML θ |\n");
    text.push_str("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    let mut sigma = vec![];
    for e in 0..=ENDS.len() {
        let ok: Vec<&Run> = all
            .iter()
            .filter(|r| r.ml[e].is_some() && r.paml[e].is_some())
            .collect();
        let n = ok.len().max(1) as f64;
        let crlb: Errors =
            std::array::from_fn(|i| (ok.iter().map(|r| r.crlb[e][i]).sum::<f64>() / n).sqrt());
        let ml = rms(&ok.iter().filter_map(|r| r.ml[e]).collect::<Vec<_>>());
        let pa = rms(&ok.iter().filter_map(|r| r.paml[e]).collect::<Vec<_>>());
        let label = ENDS
            .get(e)
            .map(|m| m.to_string())
            .unwrap_or_else(|| "all (to x = 0)".into());
        text.push_str(&format!(
            "| {label} | {} | {} | {} | {} | {} | {} | {} | {:.3} | {:.3} |\n",
            runs - ok.len(),
            sig(crlb[0]),
            sig(ml[0]),
            sig(pa[0]),
            sig(crlb[5]),
            sig(ml[5]),
            sig(pa[5]),
            pa[0] / ml[0],
            pa[5] / ml[5],
        ));
        sigma.push([crlb, ml, pa]);
    }
    text.push_str("\nAt the plane x = 0, every parameter:\n\n| parameter | CRLB | ML | PAML | PAML / ML |\n|---|---:|---:|---:|---:|\n");
    let last = sigma.last().expect("spans");
    for (i, name) in NAMES.iter().enumerate() {
        text.push_str(&format!(
            "| {name} | {} | {} | {} | {:.3} |\n",
            sig(last[0][i]),
            sig(last[1][i]),
            sig(last[2][i]),
            last[2][i] / last[1][i]
        ));
    }
    Report { sigma, text }
}
