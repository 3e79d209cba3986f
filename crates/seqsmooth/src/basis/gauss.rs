//! Gauss quadrature for any positive measure by Golub–Welsch: the `n+1` nodes are the
//! eigenvalues of the Jacobi matrix (the zeros of `b_{n+1}`, Villien & Ostertag 2009,
//! Lemma 1), and the weights the Christoffel numbers
//! `λ_k = 1/Σ_{i=0}^{n} b_i(t_k)²` (their eq. 21 and App. eq. 46), so that
//! `Σ_k λ_k f(t_k) = ∫ f dμ` for every polynomial of degree `≤ 2n+1` (their Lemma 3, eq. 26).
//!
//! The weights come from the recurrence at the nodes rather than from the eigenvectors' first
//! components (Golub and Welsch's own formula, `μ₀ v_{0k}²`): the two are the same number, but
//! the recurrence keeps the small weights at the ends of the interval to relative accuracy.

use super::jacobi::Jacobi;
use crate::error::Error;
use nalgebra::{DMatrix, SymmetricEigen};

/// Iterations the symmetric eigensolver may take before [`GaussRule::new`] gives up.
const EIGEN_ITERATIONS: usize = 10_000;

/// A Gauss rule: nodes (ascending) and their weights (`Σ λ_k = μ₀`). The nodes are kept as
/// offsets from the interval's centre, which carry their full precision where the times
/// themselves are large (Unix-epoch seconds round to 2.4e-7 s).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GaussRule {
    /// The centre `c` of the measure's interval (time units).
    pub centre: f64,
    /// `t_k − c`, ascending: the zeros of `b_{n+1}` from the centre.
    pub offsets: Vec<f64>,
    /// `λ_0 … λ_n`, the Christoffel numbers.
    pub weights: Vec<f64>,
}

impl GaussRule {
    /// The `n+1`-node rule of the measure whose recurrence is `jacobi`.
    ///
    /// ```
    /// use seqsmooth::basis::{GaussRule, Jacobi};
    /// // Gauss–Legendre, 2 nodes: ±1/√3, weights 1
    /// let g = GaussRule::new(&Jacobi::legendre(1, -1.0, 1.0)?)?;
    /// assert!((g.nodes()[1] - 1.0 / 3f64.sqrt()).abs() < 1e-15);
    /// assert!(g.weights.iter().all(|w| (w - 1.0).abs() < 1e-15));
    /// // exact for degree ≤ 3: ∫ t³ + t² dt over [-1, 1] = 2/3
    /// assert!((g.integrate(|t| t.powi(3) + t * t) - 2.0 / 3.0).abs() < 1e-15);
    /// # Ok::<(), seqsmooth::Error>(())
    /// ```
    pub fn new(jacobi: &Jacobi) -> Result<Self, Error> {
        let size = jacobi.alpha.len();
        let mut j = DMatrix::zeros(size, size);
        for (k, &a) in jacobi.alpha.iter().enumerate() {
            j[(k, k)] = a;
        }
        for (k, &b) in jacobi.beta.iter().enumerate() {
            j[(k, k + 1)] = b;
            j[(k + 1, k)] = b;
        }
        if let Some(&value) = j.iter().find(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "recurrence coefficient",
                value,
            });
        }
        let eigen = SymmetricEigen::try_new(j, f64::EPSILON, EIGEN_ITERATIONS).ok_or(
            Error::EigenNotConverged {
                size,
                iterations: EIGEN_ITERATIONS,
            },
        )?;
        let mut u: Vec<f64> = eigen.eigenvalues.iter().copied().collect();
        u.sort_by(f64::total_cmp);
        let offsets: Vec<f64> = u.iter().map(|u| jacobi.half * u).collect();
        let weights = offsets
            .iter()
            .map(|&o| {
                let b = jacobi.orthonormal_at_offset(o);
                1.0 / b.iter().map(|b| b * b).sum::<f64>()
            })
            .collect();
        Ok(Self {
            centre: jacobi.centre,
            offsets,
            weights,
        })
    }

    /// The nodes `t_k = c + (t_k − c)` (time units; rounded to the times' precision).
    pub fn nodes(&self) -> Vec<f64> {
        self.offsets.iter().map(|o| self.centre + o).collect()
    }

    /// `Σ_k λ_k f(t_k)`.
    pub fn integrate(&self, f: impl Fn(f64) -> f64) -> f64 {
        self.integrate_offsets(|o| f(self.centre + o))
    }

    /// `Σ_k λ_k g(t_k − c)`: [`integrate`](Self::integrate) with `g` given the offset from the
    /// centre (full precision for large times).
    pub fn integrate_offsets(&self, g: impl Fn(f64) -> f64) -> f64 {
        self.offsets
            .iter()
            .zip(&self.weights)
            .map(|(&o, w)| w * g(o))
            .sum()
    }
}
