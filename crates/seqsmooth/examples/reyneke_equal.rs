//! Reyneke et al. (2012) §8.1's claim, measured: "when choosing a constant update rate the
//! variable-step and original polynomial filters render near identical state vector estimates
//! ... Σ (Z_vstep − Z_original)² < 10⁻¹⁰ over the total track-time of 100 s (τ = 1 s)", the
//! 1-step predictor compared after a one-batch prediction `Z*_{η+1} = Ψ(1) Z_η`.
//!
//! cargo run --release -p seqsmooth --example reyneke_equal -- [--runs 100] [--seed 1]
//!
//! The track of `reyneke_fig1` (the same 4th-degree polynomial, σ = 100, degree 4) sampled every
//! τ = 1 s from 0 to 100 s (101 samples, no missed detections), run through
//! - the variable-step filters: the library's gain engine ([`Engine::Gain`]: Reyneke's
//!   recursion in `Ψ` form, `η`, `ζ`), expanding memory and fading memory θ = 0.95 (the
//!   paper's) and 0.8;
//! - the original filters of Morrison ch. 9 and 13: the current estimate by the library's
//!   banks ([`ExpandingBank`], [`FadingBank`]: Table 9.1 / 13.1 with `Φ(1)`, plain `f64` from
//!   a zero state), and the 1-step predictor `Z*_{n+1,n} = Φ(1) Z*_{n,n−1} + Φ(1) H ε_n`
//!   written out here from the library's gains ([`GainForm::Predictor`]);
//! - and, for scale, the exact least squares ([`Engine::Exact`]).
//!
//! Each state is compared as derivatives `x^(k)`, `k = 0..4` (with τ = 1 the paper's
//! normalised `Ψ` state); it prints, over the runs, the largest sum of squared differences over
//! the track and the largest single difference, absolute and relative to the state's size.

#[path = "common/papers.rs"]
mod papers;

use rand_distr::{Distribution, Normal};
use seqsmooth::model::phi;
use seqsmooth::polynomial::bank::{ExpandingBank, FadingBank};
use seqsmooth::polynomial::expanding::gains::expanding_gains;
use seqsmooth::polynomial::fading::gains::fading_gains;
use seqsmooth::polynomial::form::GainForm;
use seqsmooth::polynomial::SwitchRule;
use seqsmooth::{Engine, ExpandingMemory, FadingMemory, PolynomialFilter};
use std::fmt::Write;

const DEGREE: usize = 4;
/// The paper's θ, and a smaller one: with θ = 0.95 the fading filters switch from their
/// expanding-memory start at sample `⌊6.6321/(1 − θ)⌋ = 132` (Table 1), after the 101 samples,
/// so only θ = 0.8 (switch at 33) runs the fading gains within the track.
const THETAS: [f64; 2] = [0.95, 0.8];
const SIGMA: f64 = 100.0;
/// Samples at t = 0, 1, …, 100 s.
const SAMPLES: usize = 101;
/// The track of `reyneke_fig1`: `x = Σ a_k t^k`.
const A: [f64; 5] = [1000.0, 200.0, -6.0, 0.08, -0.0003];

/// Morrison's original 1-step predictor (eq. 29 of the paper; Tables 9.1, 13.1 with
/// `Φ(1) H`), scaled state `z_k = x^(k)/k!` at τ = 1, from a zero state.
struct Predictor {
    z: Vec<f64>,
    n: u64,
    fading_from: Option<u64>,
    fading: Vec<f64>,
}

impl Predictor {
    fn new(theta: Option<f64>) -> Self {
        let (fading_from, fading) = match theta {
            Some(th) => (
                Some(
                    SwitchRule::Position
                        .switch_index(DEGREE, th)
                        .expect("θ in range"),
                ),
                fading_gains(DEGREE, th, GainForm::Predictor),
            ),
            None => (None, Vec::new()),
        };
        Self {
            z: vec![0.0; DEGREE + 1],
            n: 0,
            fading_from,
            fading,
        }
    }

    /// Folds in `y_n`; the state is then `Z*_{n+1,n}`.
    fn update(&mut self, y: f64) {
        let eps = y - self.z[0];
        let g = match self.fading_from {
            Some(n0) if self.n >= n0 => self.fading.clone(),
            _ => expanding_gains(DEGREE, self.n, GainForm::Predictor),
        };
        let p = phi::<f64>(DEGREE, 1.0);
        self.z = (0..=DEGREE)
            .map(|i| (i..=DEGREE).map(|j| p[(i, j)] * self.z[j]).sum::<f64>() + g[i] * eps)
            .collect();
        self.n += 1;
    }

    /// `x^(k) = k! z_k`.
    fn derivatives(&self) -> Vec<f64> {
        let mut f = 1.0;
        (0..=DEGREE)
            .map(|k| {
                if k > 0 {
                    f *= k as f64;
                }
                f * self.z[k]
            })
            .collect()
    }
}

/// The comparisons, in the order printed.
const PAIRS: [&str; 7] = [
    "expanding, current: gain engine vs ExpandingBank",
    "expanding, 1-step:  gain engine Psi(1) vs predictor",
    "expanding, current: exact engine vs ExpandingBank",
    "fading 0.95, current: gain engine vs FadingBank",
    "fading 0.95, 1-step:  gain engine Psi(1) vs predictor",
    "fading 0.8,  current: gain engine vs FadingBank",
    "fading 0.8,  1-step:  gain engine Psi(1) vs predictor",
];

/// One comparison over a track: the sum of squared differences, the largest difference and
/// the largest difference relative to `max(|x^(k)|, 1)`.
#[derive(Clone, Copy, Default)]
struct Gap {
    sum_sq: f64,
    max: f64,
    rel: f64,
}

impl Gap {
    fn add(&mut self, a: &[f64], b: &[f64]) {
        for (x, y) in a.iter().zip(b) {
            let d = x - y;
            self.sum_sq += d * d;
            self.max = self.max.max(d.abs());
            self.rel = self.rel.max(d.abs() / x.abs().max(1.0));
        }
    }

    fn worst(self, o: Gap) -> Gap {
        Gap {
            sum_sq: self.sum_sq.max(o.sum_sq),
            max: self.max.max(o.max),
            rel: self.rel.max(o.rel),
        }
    }
}

fn run(rng: &mut rand::rngs::StdRng) -> [Gap; 7] {
    let noise = Normal::new(0.0, SIGMA).expect("σ > 0");
    let mut g = [Gap::default(); 7];
    let mut e_gain = ExpandingMemory::new(DEGREE, Engine::Gain).expect("degree");
    let mut e_exact = ExpandingMemory::new(DEGREE, Engine::Exact).expect("degree");
    let mut e_bank = ExpandingBank::new(DEGREE, 1.0, 1).expect("bank");
    let mut e_pred = Predictor::new(None);
    let mut f_gain =
        THETAS.map(|th| FadingMemory::new(DEGREE, th, 1.0, Engine::Gain).expect("θ, τ"));
    let mut f_bank = THETAS.map(|th| FadingBank::new(DEGREE, th, 1.0, 1).expect("bank"));
    let mut f_pred = THETAS.map(|th| Predictor::new(Some(th)));
    for n in 0..SAMPLES {
        let t = n as f64;
        let y = A.iter().rev().fold(0.0, |acc, a| acc * t + a) + noise.sample(rng);
        e_gain.update(t, y).expect("finite sample");
        e_exact.update(t, y).expect("finite sample");
        e_bank.update(&[y]).expect("finite sample");
        e_pred.update(y);
        for i in 0..THETAS.len() {
            f_gain[i].update(t, y).expect("finite sample");
            f_bank[i].update(&[y]).expect("finite sample");
            f_pred[i].update(y);
        }
        if n < DEGREE {
            continue; // not determined yet: the comparison starts with a state
        }
        let now = |f: &dyn PolynomialFilter| f.estimate().expect("determined").derivatives;
        let next =
            |f: &dyn PolynomialFilter| f.estimate_at(t + 1.0).expect("determined").derivatives;
        let eb = e_bank.estimate(0).expect("determined");
        g[0].add(&now(&e_gain), &eb);
        g[1].add(&next(&e_gain), &e_pred.derivatives());
        g[2].add(&now(&e_exact), &eb);
        for i in 0..THETAS.len() {
            g[3 + 2 * i].add(
                &now(&f_gain[i]),
                &f_bank[i].estimate(0).expect("determined"),
            );
            g[4 + 2 * i].add(&next(&f_gain[i]), &f_pred[i].derivatives());
        }
    }
    g
}

/// The printed table at `runs` runs from `seed` (the block docs/reyneke.md holds).
pub fn report(runs: usize, seed: u64) -> String {
    let all = papers::monte_carlo(runs, seed, |_, rng| run(rng));
    let worst = all.iter().fold([Gap::default(); 7], |acc, g| {
        std::array::from_fn(|i| acc[i].worst(g[i]))
    });
    let mut out = String::new();
    writeln!(
        out,
        "Reyneke et al. 8.1: variable-step vs original filters, tau = 1 s, 0..100 s, degree {DEGREE}, sigma = {SIGMA}; worst of {runs} runs, seed {seed}"
    )
    .unwrap();
    writeln!(
        out,
        "{:54} | sum sq diff | max |diff| | max rel diff",
        "comparison (x^(k), k = 0..4, samples 4..100)"
    )
    .unwrap();
    for (name, g) in PAIRS.iter().zip(worst) {
        writeln!(
            out,
            "{name:54} | {:11.2e} | {:10.2e} | {:12.2e}",
            g.sum_sq, g.max, g.rel
        )
        .unwrap();
    }
    out
}

fn main() {
    let a = papers::args(100, 1);
    print!("{}", report(a.runs, a.seed));
}
