//! Polynomial samples of a segment (Villien & Ostertag 2009, §II): the weighted least-squares
//! polynomial `p_s = Σ_{i=0}^{n} ⟨y, b_i⟩ b_i` (eqs. 8-9) in the basis orthonormal for the
//! samples' measure `Σ_j w_j δ(t − t_j)`, `w_j = 1/σ²(t_j)`, evaluated at the zeros `t_k*` of
//! `b_{n+1}` (eq. 37). Its coefficients are uncorrelated with unit variance, so the samples'
//! covariance is the Christoffel–Darboux kernel `Σ_i b_i(t_k*) b_i(t_l*)` (eq. 19), which is
//! `δ_kl/λ_k` at the Gauss nodes (Corollary 1, eq. 21): exactly, on the actual samples (the
//! discrete form of their eq. 6).

use super::online::SmootherGains;
use crate::error::{check_finite, Error, Param};
use crate::estimate::curve::{fit_curve, CurveFit, CurveModel};

/// A segment's `n+1` polynomial samples: at `centre + offsets[k]`, the values of the segment's
/// weighted least-squares polynomial and their variances (uncorrelated).
#[derive(Clone, Debug, PartialEq)]
pub struct PolynomialSamples {
    /// The centre of the segment's span (time units).
    pub centre: f64,
    /// `t_k* − centre`, ascending: the Gauss nodes of the samples' measure.
    pub offsets: Vec<f64>,
    /// `p_s(t_k*)`.
    pub values: Vec<f64>,
    /// `Var p_s(t_k*) = 1/λ_k` (the units of `σ²`).
    pub variances: Vec<f64>,
}

impl PolynomialSamples {
    /// The polynomial samples of degree `n` of the samples `(times[j], values[j])` with noise
    /// standard deviations `sigmas[j]` (times in any order; at least `n+1` distinct).
    ///
    /// ```
    /// use seqsmooth::paml::PolynomialSamples;
    /// // a line with no noise is its own fit: two samples of degree 1 lie on it
    /// let t = [0.0, 1.0, 2.0, 3.0, 4.0];
    /// let y = t.map(|t| 1.0 + 2.0 * t);
    /// let ps = PolynomialSamples::from_segment(&t, &y, &[0.5; 5], 1)?;
    /// for (o, v) in ps.offsets.iter().zip(&ps.values) {
    ///     assert!((v - (1.0 + 2.0 * (ps.centre + o))).abs() < 1e-12);
    /// }
    /// // equal noise: the two samples share the information, 0.25/5 · 2 each
    /// assert!(ps.variances.iter().all(|v| (v - 0.1).abs() < 1e-12));
    /// # Ok::<(), seqsmooth::Error>(())
    /// ```
    pub fn from_segment(
        times: &[f64],
        values: &[f64],
        sigmas: &[f64],
        n: usize,
    ) -> Result<Self, Error> {
        if values.len() != times.len() || sigmas.len() != times.len() {
            return Err(Error::InvalidParameter {
                name: Param::Segment,
                value: format!(
                    "{} times, {} values, {} sigmas",
                    times.len(),
                    values.len(),
                    sigmas.len()
                ),
                reason: "one value and one sigma per time".into(),
            });
        }
        check_finite("value", values)?;
        // The one engine: the layout of these times and sigmas, the values accumulated.
        let gains = SmootherGains::layout(times, sigmas, n)?;
        let mut smoother = gains.smoother();
        smoother.push_all(values)?;
        smoother.polynomial_samples()
    }

    /// The PAML estimate (V&O eqs. 3-4): the maximum-likelihood fit of `model` to these
    /// samples as measurements with their variances, by the same Levenberg–Marquardt fit as
    /// the raw samples' ([`fit_curve`]), from `start`. When `∇h` is a polynomial of degree
    /// `≤ n` in `t` and `h ∇h` one of degree `≤ 2n+1`, its normal equations are the raw ones
    /// exactly (Lemma 3); otherwise it differs by the quadrature remainder (Lemma 4, eq. 49).
    ///
    /// ```
    /// use seqsmooth::estimate::curve::{fit_curve, Curve};
    /// use seqsmooth::paml::PolynomialSamples;
    /// // a quadratic model from degree-2 samples: the raw fit, from 3 numbers instead of 200
    /// let h = Curve::new(3, |th: &[f64], t| th[0] + th[1] * t + th[2] * t * t);
    /// let t: Vec<f64> = (0..200).map(|k| k as f64 * 0.01).collect();
    /// let y: Vec<f64> = t.iter().map(|t| 1.0 - t + (40.0 * t).sin() * 0.1).collect();
    /// let s: Vec<f64> = t.iter().map(|t| 0.1 + t).collect();
    /// let raw = fit_curve(&h, &t, &y, &s, &[0.0; 3])?;
    /// let paml = PolynomialSamples::from_segment(&t, &y, &s, 2)?.fit(&h, &[0.0; 3])?;
    /// assert!((paml.parameters - &raw.parameters).amax() < 1e-9);
    /// assert!((paml.covariance - &raw.covariance).amax() < 1e-9 * raw.covariance.amax());
    /// # Ok::<(), seqsmooth::Error>(())
    /// ```
    pub fn fit<M: CurveModel + ?Sized>(&self, model: &M, start: &[f64]) -> Result<CurveFit, Error> {
        let sigmas: Vec<f64> = self.variances.iter().map(|v| v.sqrt()).collect();
        fit_curve(model, &self.times(), &self.values, &sigmas, start)
    }

    /// The samples' times `t_k*` (rounded to the times' precision; [`offsets`](Self::offsets)
    /// keep theirs).
    pub fn times(&self) -> Vec<f64> {
        self.offsets.iter().map(|o| self.centre + o).collect()
    }
}

/// The variance of a polynomial sample at `u ∈ (−1, 1)` (the segment mapped to `[−1, 1]`)
/// from Szegő's asymptotics (Villien & Ostertag eqs. 22-25), corrected: eq. 25 in eq. 21 gives
/// `σ²(t*) · 2(n+1)/N · ω_T(u)`, `ω_T(u) = 1/(π√(1 − u²))`; eq. 22 as printed lacks the 2.
/// An approximation for dense even sampling (it underestimates by 8-9 % at `n = 5`):
/// [`PolynomialSamples`] gives the exact variances.
///
/// ```
/// use seqsmooth::paml::approximate_variance;
/// // the information of the n+1 samples adds up to about N/σ² (here 0.90-0.92 of it per sample)
/// let v = approximate_variance(1.0, 5, 1000, 0.2386191860831969);
/// assert!((1000.0 * v / 4.27429 - 0.9202).abs() < 1e-3);
/// ```
pub fn approximate_variance(noise_variance: f64, n: usize, samples: usize, u: f64) -> f64 {
    2.0 * approximate_variance_as_printed(noise_variance, n, samples, u)
}

/// Eq. 22 exactly as printed, `σ²(t*) (n+1)/N ω_T(u)`: half the variance (its information over
/// the `n+1` samples adds to 2.18 `N/σ²` at `n = 5`, where it must be `N/σ²`); kept to show
/// the misprint — use [`approximate_variance`].
pub fn approximate_variance_as_printed(
    noise_variance: f64,
    n: usize,
    samples: usize,
    u: f64,
) -> f64 {
    let chebyshev = 1.0 / (std::f64::consts::PI * (1.0 - u * u).sqrt());
    noise_variance * (n + 1) as f64 / samples as f64 * chebyshev
}
