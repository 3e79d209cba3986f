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
//! | polynomial samples of a segment, their largest degree | [`PolynomialSamples`], [`MAX_DEGREE`] | eqs. 8-9, 19-21, 37 |
//! | the Chebyshev-weight variance approximation | [`approximate_variance`] | eqs. 22-25 (eq. 22 lacks a factor 2) |
//! | online smoothing with precomputed gains, virtual sampling | [`SmootherGains`], [`OnlineSmoother`] | §V, eqs. 34-37, Table I |
//! | the PAML estimate and the raw ML estimate, one Levenberg–Marquardt fit; the Cramér–Rao bound | [`PolynomialSamples::fit`], [`crate::estimate::curve`] | eqs. 2-4, Lemma 4 |

use crate::error::{Error, Param};

mod online;
mod samples;

/// The largest degree `n` of polynomial samples: they are computed in the polynomials
/// orthonormal for the segment's own samples (Lanczos in double-word arithmetic), which stay
/// well conditioned beyond the filters' monomial state (`polynomial::MAX_DEGREE`), and the
/// samples are values at Gauss nodes, not derivatives.
///
/// ```
/// use seqsmooth::paml::{PolynomialSamples, MAX_DEGREE};
/// use seqsmooth::Error;
/// let t: Vec<f64> = (0..40).map(f64::from).collect();
/// assert!(PolynomialSamples::from_segment(&t, &t, &[1.0; 40], MAX_DEGREE).is_ok());
/// assert!(matches!(
///     PolynomialSamples::from_segment(&t, &t, &[1.0; 40], MAX_DEGREE + 1),
///     Err(Error::DegreeOutOfRange { degree: 31, max: 30 })
/// ));
/// ```
pub const MAX_DEGREE: usize = 30;

/// The range of a segment's degree `n`: `n ≤ MAX_DEGREE` (the constructors' check, and every
/// front end's).
///
/// ```
/// use seqsmooth::paml::{check_degree, MAX_DEGREE};
/// assert!(check_degree(MAX_DEGREE).is_ok() && check_degree(MAX_DEGREE + 1).is_err());
/// ```
pub fn check_degree(n: usize) -> Result<(), Error> {
    crate::error::check_degree_at_most(n, MAX_DEGREE)
}

/// The range of the length of the segments a series is cut into (in its time units, the
/// command's `paml --segment`): positive and finite.
///
/// ```
/// use seqsmooth::paml::check_segment_length;
/// assert!(check_segment_length(2.5).is_ok());
/// assert!(check_segment_length(0.0).is_err() && check_segment_length(f64::INFINITY).is_err());
/// ```
pub fn check_segment_length(seconds: f64) -> Result<(), Error> {
    if !(seconds.is_finite() && seconds > 0.0) {
        return Err(Error::InvalidParameter {
            name: Param::SegmentLength,
            value: seconds.to_string(),
            reason: "must be a positive finite number".into(),
        });
    }
    Ok(())
}

pub use online::{OnlineSmoother, SmootherGains};
pub use samples::{approximate_variance, approximate_variance_as_printed, PolynomialSamples};
