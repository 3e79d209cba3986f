//! Shared by the engine tests and the `accuracy_engines` example: runs a filter against batch
//! least-squares oracles and reports the largest relative error, for the runs the tests assert
//! and the example prints.

use super::*;
use seqsmooth::{DiscountMode, Engine, ExpandingMemory, FadingMemory, PolynomialFilter};

/// Relative tolerance required of both engines against least squares, degrees 0-8.
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

/// Expanding memory on 200 even samples (`t = 5 + k/4`) of a noisy degree-`m` polynomial, both
/// engines against batch QR at every sample: `(exact, gain)`.
pub fn expanding_even_errors(m: usize) -> (f64, f64) {
    let times = even_times(200, 5.0, 0.25);
    let ys = noisy_polynomial(&times, m, 50.0, 0.3, 100 + m as u64);
    let run = |engine| {
        compare(
            Box::new(ExpandingMemory::new(m, engine).unwrap()),
            &times,
            &ys,
            m,
            |_| true,
            |_| None,
        )
    };
    (run(Engine::Exact), run(Engine::Gain))
}

/// Expanding memory over 10⁵ even samples, against batch QR at samples 999, 9 999 and 99 999.
pub fn expanding_long_run_error(m: usize, engine: Engine) -> f64 {
    let n = 100_001;
    let times = even_times(n, 0.0, 1e-3);
    let ys = noisy_polynomial(&times, m, 100.0, 0.1, 7 + m as u64);
    let checkpoints = [999usize, 9_999, 99_999];
    compare(
        Box::new(ExpandingMemory::new(m, engine).unwrap()),
        &times,
        &ys,
        m,
        |k| checkpoints.contains(&k),
        |_| None,
    )
}

/// The exact expanding-memory engine on 150 jittered (±40 %) and 150 random (Poisson) samples,
/// against batch QR at every sample: `[(label, error)]`.
pub fn expanding_irregular_errors(m: usize) -> Vec<(&'static str, f64)> {
    [
        ("jittered", jittered_times(150, 0.1, 0.4, 11 + m as u64)),
        ("random", random_times(150, 0.1, 21 + m as u64)),
    ]
    .into_iter()
    .map(|(label, times)| {
        let ys = noisy_polynomial(&times, m, 15.0, 0.2, 31 + m as u64);
        let err = compare(
            Box::new(ExpandingMemory::new(m, Engine::Exact).unwrap()),
            &times,
            &ys,
            m,
            |_| true,
            |_| None,
        );
        (label, err)
    })
    .collect()
}

/// Discount weights of samples `0..=n`: `θ^((t_n - t_k)/τ)` per time, `θ^(n-k)` per update.
pub fn discount_weights(
    times: &[f64],
    n: usize,
    theta: f64,
    tau: f64,
    mode: DiscountMode,
) -> Vec<f64> {
    (0..=n)
        .map(|k| match mode {
            DiscountMode::PerTime => theta.powf((times[n] - times[k]) / tau),
            DiscountMode::PerUpdate => theta.powi((n - k) as i32),
        })
        .collect()
}

/// The exact fading-memory engine (θ = 0.93 per τ = 0.1) on 400 jittered (±50 %) samples,
/// against discounted batch QR (samples before 60 and every 7th): the error for `mode`.
pub fn fading_irregular_error(m: usize, mode: DiscountMode) -> f64 {
    let theta = 0.93;
    let tau = 0.1;
    let times = jittered_times(400, 0.1, 0.5, 61 + m as u64);
    let ys = noisy_polynomial(&times, m, 10.0, 0.2, 71 + m as u64);
    let f = FadingMemory::new(m, theta, tau, Engine::Exact)
        .unwrap()
        .with_discount_mode(mode)
        .unwrap();
    compare(
        Box::new(f),
        &times,
        &ys,
        m,
        |n| n < 60 || n % 7 == 0,
        |n| Some(discount_weights(&times, n, theta, tau, mode)),
    )
}

/// Fading memory (θ = 9/10, τ = 1) on 1000 even samples against exact rational discounted
/// least squares: the gain engine from sample 700 on (after the switch transient), the exact
/// engine from the first determinable sample. `(gain, exact)`.
pub fn fading_even_errors(m: usize) -> (f64, f64) {
    let theta = (9, 10);
    let times = even_times(1000, 0.0, 1.0);
    let ys = dyadic(&wavy(&times, 1.0, 0.01, 81 + m as u64));
    let mut gain = FadingMemory::new(m, 0.9, 1.0, Engine::Gain).unwrap();
    let g = compare_fading_exact(&mut gain, &times, &ys, m, theta, &[700, 850, 998]);
    let mut exact = FadingMemory::new(m, 0.9, 1.0, Engine::Exact).unwrap();
    let checks: Vec<usize> = [m, m + 1, m + 5, 40, 200, 998]
        .into_iter()
        .filter(|&n| n >= m)
        .collect();
    let e = compare_fading_exact(&mut exact, &times, &ys, m, theta, &checks);
    (g, e)
}

/// The exact engine at high degree (the conditioning limit of the centred monomial
/// square-root information form): 2000 jittered (±30 %) samples, against batch QR in the
/// Legendre basis at samples m, m+5, 100, 500, 1998. `(expanding, fading θ = 0.99)`.
pub fn high_degree_errors(m: usize) -> (f64, f64) {
    let times = jittered_times(2000, 0.01, 0.3, 111 + m as u64);
    let ys = noisy_polynomial(&times, m, 20.0, 1e-3, 121 + m as u64);
    let check = [m, m + 5, 100, 500, 1998];
    let expanding = compare(
        Box::new(ExpandingMemory::new(m, Engine::Exact).unwrap()),
        &times,
        &ys,
        m,
        |n| check.contains(&n),
        |_| None,
    );
    let theta = 0.99;
    let fading = compare(
        Box::new(FadingMemory::new(m, theta, 0.01, Engine::Exact).unwrap()),
        &times,
        &ys,
        m,
        |n| check.contains(&n),
        |n| {
            Some(discount_weights(
                &times,
                n,
                theta,
                0.01,
                DiscountMode::PerTime,
            ))
        },
    );
    (expanding, fading)
}
