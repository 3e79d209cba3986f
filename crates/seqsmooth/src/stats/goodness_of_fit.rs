//! Reyneke et al.'s goodness-of-fit measure (§7.1) and what it is in Morrison's terms.
//!
//! Over the last `N` samples of a windowed expanding-memory filter of degree `m` (the
//! least-squares polynomial of the window), Reyneke et al. §7.1 form
//!
//! `E² = Σ_{i=1..N} [y_i − (Ψ(ζ_i) Z_η)₀]² R⁻¹`,
//!
//! the squared residuals of the window's fit in units of the noise variance `R` (known, or
//! estimated by their eq. 39), and say that the measure "empirically converges to `1 − 1/√N`".
//! Only a per-sample measure can approach a limit below 1, so the measure here is
//! `G = E²/N` ([`goodness_of_fit`]); the printed limit is [`reyneke_gof_limit`].
//!
//! With `R` known and Gaussian noise, `E²` is the residual sum of squares of a least-squares fit
//! of `m + 1` parameters in units of `σ²`, so it is `χ²` with `N − m − 1` degrees of freedom
//! (Morrison §5.6, (5.6.12); its mean `N − m − 1` is (6.10.24) turned round). Hence:
//!
//! - `E[G] = 1 − (m+1)/N` exactly ([`gof_mean`]), not `1 − 1/√N`: the two agree only at
//!   `N = (m+1)²`;
//! - a limit `c` used as a threshold (`G > c`: misfit) has the false-alarm rate
//!   `P(χ²_{N−m−1} > N c)` ([`gof_false_alarm_rate`]); at the printed `c = 1 − 1/√N` it is
//!   large (0.63 for `N = 20` and 0.68 for `N = 50` at degree 1: docs/reyneke.md), so the printed
//!   limit is a typical value, not a test;
//! - at a given false-alarm rate `α` the threshold is `χ²_{N−m−1}(1 − α)/N`
//!   ([`gof_threshold`]): the same decisions as Morrison's χ² test of the residuals, so with `R`
//!   known the measure detects a misfit exactly as well as that test, no better and no worse.
//!
//! With `R` estimated from the same window (eq. 39) the statistic is no longer `χ²`, and a
//! misfit also inflates the estimate of `R`; the example `reyneke_gof` measures what that costs
//! (docs/reyneke.md).

use super::chi_squared::{chi_squared_quantile, chi_squared_sf};
use crate::error::{Error, Param};

fn check_window(n: usize, m: usize) -> Result<usize, Error> {
    if n <= m + 1 {
        return Err(Error::InvalidParameter {
            name: Param::Window,
            value: n.to_string(),
            reason: format!(
                "a fit of degree {m} leaves no residual degree of freedom unless the window \
                 holds more than {} samples",
                m + 1
            ),
        });
    }
    Ok(n - m - 1)
}

/// `G = E²/N = (1/N) Σ r_i²/R`: Reyneke et al.'s §7.1 goodness of fit of the `N` residuals
/// `r_i = y_i − p(t_i)` of a window's fit, `R > 0` the noise variance (known, or estimated by
/// [`crate::stats::reyneke_eq39_variance`]). A non-finite residual or an empty window is an
/// error.
///
/// ```
/// use seqsmooth::stats::goodness_of_fit;
/// assert_eq!(goodness_of_fit(&[1.0, -1.0, 2.0, 0.0], 2.0).unwrap(), 0.75); // (1 + 1 + 4)/2/4
/// assert!(goodness_of_fit(&[], 1.0).is_err());
/// assert!(goodness_of_fit(&[1.0], 0.0).is_err());
/// assert!(goodness_of_fit(&[f64::NAN], 1.0).is_err());
/// assert!(goodness_of_fit(&[1e200], 1.0).is_err()); // overflows: refused, not infinity
/// ```
pub fn goodness_of_fit(residuals: &[f64], variance: f64) -> Result<f64, Error> {
    if residuals.is_empty() {
        return Err(Error::InvalidParameter {
            name: Param::Window,
            value: "0".into(),
            reason: "the measure needs at least one residual".into(),
        });
    }
    if !(variance.is_finite() && variance > 0.0) {
        return Err(Error::InvalidParameter {
            name: Param::NoiseVariance,
            value: variance.to_string(),
            reason: "must be a positive finite number".into(),
        });
    }
    if let Some(&r) = residuals.iter().find(|r| !r.is_finite()) {
        return Err(Error::NonFinite {
            what: "residual",
            value: r,
        });
    }
    let g = residuals.iter().map(|r| r * r).sum::<f64>() / variance / residuals.len() as f64;
    if !g.is_finite() {
        // Residuals near 1e155, or a variance near the smallest normal: the measure overflows.
        return Err(Error::NonFinite {
            what: "goodness-of-fit measure (the residuals' squares over the variance overflow)",
            value: g,
        });
    }
    Ok(g)
}

/// `1 − 1/√N`, the value Reyneke et al. §7.1 say the measure "empirically converges to" on a
/// window of `N ≥ 1` samples.
///
/// ```
/// use seqsmooth::stats::reyneke_gof_limit;
/// assert_eq!(reyneke_gof_limit(100).unwrap(), 0.9);
/// assert!(reyneke_gof_limit(0).is_err());
/// ```
pub fn reyneke_gof_limit(n: usize) -> Result<f64, Error> {
    if n == 0 {
        return Err(Error::InvalidParameter {
            name: Param::Window,
            value: "0".into(),
            reason: "must be at least 1 sample".into(),
        });
    }
    Ok(1.0 - 1.0 / (n as f64).sqrt())
}

/// `E[G] = (N − m − 1)/N`: the measure's mean on a window of `N` samples fitted with degree `m`
/// when the polynomial fits and `R` is the true variance (Morrison (6.10.24): the residual sum
/// of squares has mean `(N − m − 1) σ²`). Needs `N > m + 1`.
///
/// ```
/// use seqsmooth::stats::{gof_mean, reyneke_gof_limit};
/// assert_eq!(gof_mean(100, 1).unwrap(), 0.98);
/// // the printed limit is the mean only where N = (m + 1)²
/// assert!((gof_mean(9, 2).unwrap() - reyneke_gof_limit(9).unwrap()).abs() < 1e-15);
/// assert!(gof_mean(3, 2).is_err());
/// ```
pub fn gof_mean(n: usize, m: usize) -> Result<f64, Error> {
    let dof = check_window(n, m)?;
    Ok(dof as f64 / n as f64)
}

/// The false-alarm rate of the threshold `limit` on the measure (`G > limit`: misfit), window
/// `N`, degree `m`, `R` known, Gaussian noise: `P(χ²_{N−m−1} > N · limit)`.
///
/// ```
/// use seqsmooth::stats::{gof_false_alarm_rate, reyneke_gof_limit};
/// // the printed limit as a threshold: most good fits fail it
/// let n = 20;
/// let p = gof_false_alarm_rate(n, 1, reyneke_gof_limit(n).unwrap()).unwrap();
/// assert!(p > 0.5);
/// ```
pub fn gof_false_alarm_rate(n: usize, m: usize, limit: f64) -> Result<f64, Error> {
    let dof = check_window(n, m)?;
    if limit.is_nan() {
        return Err(Error::NonFinite {
            what: "limit",
            value: limit,
        });
    }
    chi_squared_sf(dof as f64, n as f64 * limit)
}

/// The threshold on the measure with false-alarm rate `α ∈ (0,1)`, window `N`, degree `m`,
/// `R` known: `χ²_{N−m−1}(1 − α)/N`. `G` above it exactly when Morrison's χ² test of the
/// window's residuals ([`crate::stats::ChiSquaredTest`] with `N − m − 1` degrees of freedom)
/// rejects: the two are one test.
///
/// ```
/// use seqsmooth::stats::{gof_threshold, ChiSquaredTest};
/// let (n, m, alpha) = (20, 1, 0.01);
/// let c = gof_threshold(n, m, alpha).unwrap();
/// let chi = ChiSquaredTest::new((n - m - 1) as f64, alpha).unwrap();
/// assert!((c * n as f64 - chi.threshold()).abs() < 1e-12);
/// ```
pub fn gof_threshold(n: usize, m: usize, alpha: f64) -> Result<f64, Error> {
    let dof = check_window(n, m)?;
    if !(alpha > 0.0 && alpha < 1.0) {
        return Err(Error::InvalidParameter {
            name: Param::FalseAlarmRate,
            value: alpha.to_string(),
            reason: "must lie strictly between 0 and 1".into(),
        });
    }
    Ok(chi_squared_quantile(dof as f64, 1.0 - alpha)? / n as f64)
}
