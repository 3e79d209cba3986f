//! Shared by the engine tests: runs a filter against batch least-squares oracles and reports the
//! largest relative error.

use super::*;
use seqsmooth::{Engine, ExpandingMemory, FadingMemory, PolynomialFilter};

/// Relative tolerance required by the issue.
pub const TOL: f64 = 1e-9;

/// Per-derivative floors for the relative error: 1e-3 of the largest magnitude the oracle
/// reaches over the run (a derivative that crosses zero is judged against its own scale).
pub fn floors(oracle: &[Vec<f64>]) -> Vec<f64> {
    let p = oracle[0].len();
    (0..p)
        .map(|k| 1e-3 * oracle.iter().map(|v| v[k].abs()).fold(1e-300, f64::max))
        .collect()
}

pub type Filter = Box<dyn PolynomialFilter>;

/// Derivatives of the estimate valid at `t`.
pub fn at(f: &Filter, t: f64) -> Option<Vec<f64>> {
    f.estimate_at(t).map(|s| s.derivatives)
}

/// Runs the filter and, for every sample index in `check`, compares the current estimate and
/// the estimate at the next sample's time (the 1-step prediction) with the oracle fit.
/// Returns the largest relative error.
pub fn compare(
    mut filter: Filter,
    times: &[f64],
    ys: &[f64],
    m: usize,
    check: impl Fn(usize) -> bool,
    weights: impl Fn(usize) -> Option<Vec<f64>>,
) -> f64 {
    let mut got = Vec::new();
    let mut want = Vec::new();
    for n in 0..times.len() - 1 {
        filter.update(times[n], ys[n]).unwrap();
        if n < m {
            assert!(
                at(&filter, times[n]).is_none(),
                "estimate before m+1 samples"
            );
            continue;
        }
        if !check(n) {
            continue;
        }
        let w = weights(n);
        let fit = batch_fit(&times[..=n], &ys[..=n], w.as_deref(), m);
        for at in [times[n], times[n + 1]] {
            got.push(filter.estimate_at(at).expect("determined").derivatives);
            want.push(fit.derivatives_at(at));
        }
    }
    let fl = floors(&want);
    got.iter()
        .zip(&want)
        .map(|(a, b)| rel_err(a, b, &fl))
        .fold(0.0, f64::max)
}

/// A smooth bounded signal whose derivatives all matter over a fading memory of a few tens of
/// samples (a polynomial truth over a long run would leave the high derivatives far below the
/// rounding of the values, and no oracle could judge them relatively), plus noise.
pub fn wavy(times: &[f64], scale: f64, sigma: f64, seed: u64) -> Vec<f64> {
    use rand_distr::{Distribution, Normal};
    let mut r = rng(seed);
    let noise = Normal::new(0.0, sigma).unwrap();
    times
        .iter()
        .map(|&t| {
            (t / (15.0 * scale)).sin()
                + 0.5 * (t / (23.0 * scale) + 1.0).cos()
                + noise.sample(&mut r)
        })
        .collect()
}

/// Exact discounted least squares at sample `n` with weights `(p/q)^(n-k)` on the evenly
/// spaced `times` (step `step`), evaluated at `at` (a sample time or one step beyond).
pub fn exact_discounted(
    times: &[f64],
    ys: &[f64],
    n: usize,
    pq: (u64, u64),
    m: usize,
    at: f64,
) -> Vec<f64> {
    let step = times[1] - times[0];
    let u: Vec<i64> = times[..=n]
        .iter()
        .map(|t| ((t - at) / step).round() as i64)
        .collect();
    exact_discounted_even(&u, &ys[..=n], pq.0, pq.1, m, step)
}

pub fn compare_fading_exact(
    f: &mut FadingMemory,
    times: &[f64],
    ys: &[f64],
    m: usize,
    theta_per_sample: (u64, u64),
    checks: &[usize],
) -> f64 {
    let mut got = Vec::new();
    let mut want = Vec::new();
    for n in 0..times.len() - 1 {
        f.update(times[n], ys[n]).unwrap();
        if checks.contains(&n) {
            for at in [times[n], times[n + 1]] {
                got.push(f.estimate_at(at).unwrap().derivatives);
                want.push(exact_discounted(times, ys, n, theta_per_sample, m, at));
            }
        }
    }
    let fl = floors(&want);
    got.iter()
        .zip(&want)
        .map(|(a, b)| rel_err(a, b, &fl))
        .fold(0.0, f64::max)
}

/// An expanding- or fading-memory (θ = 0.8 per 0.2) filter, with covariance when `sigma` is set.
pub fn test_filter(fading: bool, engine: Engine, m: usize, sigma: Option<f64>) -> Filter {
    match (fading, sigma) {
        (false, None) => Box::new(ExpandingMemory::new(m, engine).unwrap()),
        (false, Some(s)) => Box::new(
            ExpandingMemory::new(m, engine)
                .unwrap()
                .with_noise_sigma(s)
                .unwrap(),
        ),
        (true, None) => Box::new(FadingMemory::new(m, 0.8, 0.2, engine).unwrap()),
        (true, Some(s)) => Box::new(
            FadingMemory::new(m, 0.8, 0.2, engine)
                .unwrap()
                .with_noise_sigma(s)
                .unwrap(),
        ),
    }
}
