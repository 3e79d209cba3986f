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
