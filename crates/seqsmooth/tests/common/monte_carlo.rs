//! Monte Carlo of the variance-reduction matrices: 20 000 independent runs of a filter on pure
//! white noise (truth 0, so the estimate is the error).
//!
//! Tolerance from the sample size: for zero-mean Gaussian errors with covariance `S` the sample
//! second moment `Ŝ_ij = (1/N) Σ e_i e_j` has variance `(S_ii S_jj + S_ij²)/N`; every entry must
//! lie within 5 of those standard errors (two-sided false-alarm probability 6e-7 per entry, so
//! the ~250 entries checked by the two tests fail by chance with probability below 2e-4; the
//! seed is fixed).

use nalgebra::DMatrix;
use rand_distr::{Distribution, StandardNormal};
use seqsmooth::model::derivatives_to_scaled;
use seqsmooth::{PolynomialFilter, PolynomialState};

pub const RUNS: usize = 20_000;

/// Accumulates `Σ e eᵀ / N` of scaled states (τ = 1) for the current estimate and prediction.
pub struct Moments {
    pub current: DMatrix<f64>,
    pub predictor: DMatrix<f64>,
}

impl Moments {
    pub fn new(p: usize) -> Self {
        Self {
            current: DMatrix::zeros(p, p),
            predictor: DMatrix::zeros(p, p),
        }
    }
    pub fn add(&mut self, cur: &PolynomialState, pred: &PolynomialState) {
        for (acc, s) in [(&mut self.current, cur), (&mut self.predictor, pred)] {
            let z = derivatives_to_scaled(&s.derivatives, 1.0);
            for i in 0..z.len() {
                for j in 0..z.len() {
                    acc[(i, j)] += z[i] * z[j] / RUNS as f64;
                }
            }
        }
    }
}

pub fn check(sample: &DMatrix<f64>, vrf: &DMatrix<f64>, what: &str) {
    for i in 0..vrf.nrows() {
        for j in 0..vrf.ncols() {
            let se = ((vrf[(i, i)] * vrf[(j, j)] + vrf[(i, j)].powi(2)) / RUNS as f64).sqrt();
            let dev = (sample[(i, j)] - vrf[(i, j)]).abs();
            assert!(
                dev <= 5.0 * se,
                "{what} ({i},{j}): Monte Carlo {} vs VRF {} ({:.1} standard errors)",
                sample[(i, j)],
                vrf[(i, j)],
                dev / se
            );
        }
    }
}

/// Runs `RUNS` filters made by `make` on `n+1` samples of unit white noise at t = 0..n and
/// checks the sample moments of the estimate at t_n and of the prediction for t_n + 1 against
/// the closed-form matrices.
pub fn simulate_and_check(
    r: &mut rand::rngs::StdRng,
    make: impl Fn() -> Box<dyn PolynomialFilter>,
    n: usize,
    current: &DMatrix<f64>,
    predictor: &DMatrix<f64>,
    what: &str,
) {
    let mut acc = Moments::new(current.nrows());
    for _ in 0..RUNS {
        let mut f = make();
        for k in 0..=n {
            let y: f64 = StandardNormal.sample(r);
            f.update(k as f64, y).unwrap();
        }
        acc.add(
            &f.estimate().unwrap(),
            &f.estimate_at(n as f64 + 1.0).unwrap(),
        );
    }
    check(&acc.current, current, what);
    check(&acc.predictor, predictor, what);
}
