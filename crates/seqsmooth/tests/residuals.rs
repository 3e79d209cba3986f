//! The residual variance of a least-squares fit (`seqsmooth::estimate::PolynomialFit::residual_variance`):
//! unbiased and χ²-distributed, and the recursive residuals sum to the batch residual.
//!
//! Monte Carlo tolerances come from the sample size: a mean of `R` independent terms is checked
//! to within 4.5 of its standard errors (two-sided false-alarm probability 7e-6 per check; the
//! seeds are fixed, so the tests are reproducible), and a rate `p` from `N` trials to within
//! 4.5 `√(p(1-p)/N)`.

mod common;

use common::stats::*;
use rand::Rng;
use rand_distr::{Distribution, Normal};
use seqsmooth::estimate::PolynomialFit;
use seqsmooth::stats::{chi_squared_quantile, residual_variance, Welford};
use seqsmooth::{Engine, Error, ExpandingMemory, PolynomialFilter};

#[test]
fn residual_variance_is_unbiased_and_chi_squared() {
    // Morrison (6.10.21)/(6.10.24): E{e°} = σ²(N_O − N_X); e°/σ² ~ χ²_{N_O−N_X} (standard).
    let (runs, n, m, sigma) = (4000, 25, 2, 0.3);
    let dof = (n - m - 1) as f64;
    let q95 = chi_squared_quantile(dof, 0.95).unwrap();
    let mut w = Welford::new();
    let mut above = 0;
    let mut r = rng(610);
    let noise = Normal::new(0.0, sigma).unwrap();
    for _ in 0..runs {
        let t: Vec<f64> = (0..n).map(|k| k as f64 + 0.4 * r.gen::<f64>()).collect();
        let y: Vec<f64> = t
            .iter()
            .map(|t| 1.0 + 0.2 * t - 0.05 * t * t + noise.sample(&mut r))
            .collect();
        let fit = PolynomialFit::new(&t, &y, None, m).unwrap();
        let s2 = fit.residual_variance().unwrap();
        w.push(s2).unwrap();
        if s2 * dof / (sigma * sigma) > q95 {
            above += 1;
        }
    }
    let mean = w.mean().unwrap();
    let se = sigma * sigma * (2.0 / dof / runs as f64).sqrt();
    let rate = above as f64 / runs as f64;
    assert!((mean - sigma * sigma).abs() < Z * se);
    assert!((rate - 0.05).abs() < Z * (0.05 * 0.95 / runs as f64).sqrt());
    assert!(residual_variance(-1.0, 10, 2).is_err());
    assert!(residual_variance(f64::NAN, 10, 2).is_err());
    assert!(matches!(
        residual_variance(1.0, 2, 2),
        Err(Error::TooFewSamples { .. })
    ));
}

#[test]
fn recursive_residuals_sum_to_the_batch_residual() {
    // For expanding memory the normalised innovations ν²/(1+v) are the recursive residuals:
    // their sum over samples m+1.. equals the batch fit's residual sum of squares.
    let mut r = rng(9);
    let m = 2;
    let t: Vec<f64> = (0..200)
        .map(|k| k as f64 * 0.3 + 0.1 * r.gen::<f64>())
        .collect();
    let y: Vec<f64> = t
        .iter()
        .map(|t| 4.0 - t + 0.1 * t * t + gauss(&mut r))
        .collect();
    let mut f = ExpandingMemory::new(m, Engine::Exact)
        .unwrap()
        .with_noise_sigma(1.0)
        .unwrap();
    let mut sum = 0.0;
    for (&tk, &yk) in t.iter().zip(&y) {
        if let Some(p) = f.estimate_at(tk) {
            let v = p.covariance.as_ref().unwrap()[(0, 0)];
            sum += (yk - p.derivatives[0]).powi(2) / (1.0 + v);
        }
        f.update(tk, yk).unwrap();
    }
    let fit = PolynomialFit::new(&t, &y, None, m).unwrap();
    assert!((sum - fit.residual_sq()).abs() < 1e-9 * fit.residual_sq());
}
