//! Shared by the statistics tests: the Monte Carlo tolerance and a Gaussian source.

use rand::rngs::StdRng;
use rand_distr::{Distribution, StandardNormal};

/// Monte Carlo checks allow 4.5 standard errors (two-sided false-alarm probability 7e-6).
pub const Z: f64 = 4.5;

#[allow(unused_imports)]
pub use super::rng;

pub fn gauss(r: &mut StdRng) -> f64 {
    StandardNormal.sample(r)
}

/// The standard error of the mean of `xs` (the sample standard deviation over `√n`): how far
/// a Monte Carlo mean of per-run figures may wander from its expectation.
pub fn standard_error_of_mean(xs: &[f64]) -> f64 {
    let n = xs.len() as f64;
    let mean = xs.iter().sum::<f64>() / n;
    let var = xs.iter().map(|c| (c - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (var / n).sqrt()
}
