//! Properties over random cases (proptest, fixed seed): a degree-`m` polynomial filter of every
//! memory and engine reproduces any polynomial of degree `≤ m` — the defining property of the
//! least-squares polynomial filters (Morrison §6.3, §9.2, §13.2) — at the newest sample, in
//! every derivative. Exact engines and fixed memory on irregular times; the gain engine on even
//! steps, where it is exact (Morrison Tables 9.1, 13.1).

use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};
use seqsmooth::polynomial::fixed::{FixedEngine, FixedMemory};
use seqsmooth::{Engine, ExpandingMemory, FadingMemory, PolynomialFilter};

/// The `k`-th derivative at `t` of `p(t) = Σ_j c_j u^j`, `u = (t − t0)/T`.
fn derivative(c: &[f64], t0: f64, span: f64, t: f64, k: usize) -> f64 {
    let u = (t - t0) / span;
    let value: f64 = c
        .iter()
        .enumerate()
        .skip(k)
        .map(|(j, cj)| {
            let falling: f64 = (j - k + 1..=j).map(|i| i as f64).product();
            cj * falling * u.powi((j - k) as i32)
        })
        .sum();
    value / span.powi(k as i32)
}

/// How far rounding may move the estimate: the data's own rounding, `ε(max|y| +
/// max|t|·max|p'|)` (the values' and the times' last bits), is white noise of that size at
/// most, which the filter passes on with its noise gain `√C_kk` (its covariance for unit
/// noise); the computation's own rounding, for a backward-stable method, is of the same order.
/// `K = 1e4` allows for both.
const K: f64 = 1e4;

/// Feeds `(times, p(times))` to `filter` (which tracks its covariance for unit noise) and
/// checks every derivative of the final estimate against `p`'s, within `K` times the
/// rounding's effect.
fn reproduces(
    mut filter: impl PolynomialFilter,
    times: &[f64],
    c: &[f64],
    m: usize,
) -> Result<(), TestCaseError> {
    let (t0, span) = (times[0], times[times.len() - 1] - times[0]);
    let values: Vec<f64> = times
        .iter()
        .map(|&t| derivative(c, t0, span, t, 0))
        .collect();
    filter.update_many(times, &values).unwrap();
    let x = filter
        .estimate()
        .expect("an estimate after more than m samples");
    let cov = x
        .covariance
        .as_ref()
        .expect("the covariance for unit noise");
    let max = |f: &dyn Fn(f64) -> f64| times.iter().map(|&t| f(t).abs()).fold(0.0, f64::max);
    let slope = max(&|t| derivative(c, t0, span, t, 1));
    let noise = f64::EPSILON * (max(&|t| derivative(c, t0, span, t, 0)) + max(&|t| t) * slope);
    let t = *times.last().unwrap();
    for k in 0..=m {
        let want = derivative(c, t0, span, t, k);
        let err = (x.derivatives[k] - want).abs();
        let bound = K * noise * cov[(k, k)].sqrt();
        prop_assert!(
            err <= bound,
            "derivative {k}: {} against {want} (error {err:e}, bound {bound:e})",
            x.derivatives[k]
        );
    }
    Ok(())
}

/// Degree `m ≤ 8`, the polynomial's degree `≤ m`, `n` samples with steps `step·U(0.5, 1.5)`
/// (irregular) or `step` (even) after `t0`.
fn case() -> impl Strategy<Value = (usize, Vec<f64>, f64, f64, usize, Vec<f64>)> {
    (0usize..=8).prop_flat_map(|m| {
        (
            Just(m),
            (0..=m).prop_flat_map(|d| prop::collection::vec(-1.0f64..1.0, d + 1)),
            -1e3f64..1e3,
            prop_oneof![Just(1e-3), Just(1.0), Just(250.0)],
            (2 * m + 4)..(6 * m + 40),
            prop::collection::vec(0.5f64..1.5, 6 * m + 40),
        )
    })
}

fn config() -> Config {
    Config {
        cases: 256,
        rng_seed: RngSeed::Fixed(20_261_201),
        failure_persistence: None,
        ..Config::default()
    }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn exact_engines_and_fixed_memory_reproduce_polynomials_on_irregular_times(
        (m, c, t0, step, n, jitter) in case()
    ) {
        let mut times = vec![t0];
        for j in &jitter[..n - 1] {
            let last = *times.last().unwrap();
            times.push(last + step * j);
        }
        let expanding = ExpandingMemory::new(m, Engine::Exact).unwrap();
        reproduces(expanding.with_noise_sigma(1.0).unwrap(), &times, &c, m)?;
        for theta in [0.5, 0.95] {
            let fading = FadingMemory::new(m, theta, step, Engine::Exact).unwrap();
            reproduces(fading.with_noise_sigma(1.0).unwrap(), &times, &c, m)?;
        }
        for engine in [FixedEngine::Irregular, FixedEngine::Adaptive] {
            let fixed = FixedMemory::new(m, m + 3, engine).unwrap();
            reproduces(fixed.with_noise_sigma(1.0).unwrap(), &times, &c, m)?;
        }
    }

    #[test]
    fn every_engine_reproduces_polynomials_on_even_times(
        (m, c, t0, step, n, _jitter) in case()
    ) {
        let times: Vec<f64> = (0..n).map(|k| t0 + step * k as f64).collect();
        for engine in [Engine::Exact, Engine::Gain] {
            let expanding = ExpandingMemory::new(m, engine).unwrap();
            reproduces(expanding.with_noise_sigma(1.0).unwrap(), &times, &c, m)?;
            let fading = FadingMemory::new(m, 0.9, step, engine).unwrap();
            reproduces(fading.with_noise_sigma(1.0).unwrap(), &times, &c, m)?;
        }
        for engine in [FixedEngine::Sliding, FixedEngine::Direct, FixedEngine::Adaptive] {
            let fixed = FixedMemory::new(m, m + 3, engine).unwrap();
            reproduces(fixed.with_noise_sigma(1.0).unwrap(), &times, &c, m)?;
        }
    }
}
