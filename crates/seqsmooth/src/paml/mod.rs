//! Polynomial approximation maximum likelihood (PAML; Villien & Ostertag 2009): a segment of
//! `N` samples `y(t_j)` with noise variances `σ²(t_j)` becomes `n+1` *polynomial samples* — its
//! weighted least-squares polynomial of degree `n` at the Gauss nodes of the samples' own
//! measure `Σ_j δ(t − t_j)/σ²(t_j)` — which are uncorrelated, with variances the inverse
//! Christoffel numbers, and carry the segment's information for any model `h(θ, t)` whose
//! normal equations are polynomial of degree `≤ 2n+1` (their Lemma 3).
//!
//! | concept | where | source |
//! |---|---|---|
//! | the samples' measure, its Gauss nodes and Christoffel numbers | [`crate::basis::Jacobi`], [`crate::basis::GaussRule`] | Lemma 1, Corollary 1, eqs. 21, 26 |
//! | polynomial samples of a segment | [`PolynomialSamples`] | eqs. 8-9, 19-21, 37 |
//! | the Chebyshev-weight variance approximation | [`approximate_variance`] | eqs. 22-25 (eq. 22 lacks a factor 2) |
//! | online smoothing with precomputed gains, virtual sampling | [`SmootherGains`], [`OnlineSmoother`] | §V, eqs. 34-37, Table I |
//! | the PAML estimate and the raw ML estimate, one Levenberg–Marquardt fit; the Cramér–Rao bound | [`PolynomialSamples::fit`], [`crate::estimate::curve`] | eqs. 2-4, Lemma 4 |

mod online;
mod samples;

pub use online::{OnlineSmoother, SmootherGains};
pub use samples::{approximate_variance, approximate_variance_as_printed, PolynomialSamples};
