//! Chi-squared and Gaussian distribution helpers (Morrison §5.6; ch02-06 spec §5.5).
//!
//! If `N ~ N(0, R)` has `d` components then `χ² = Nᵀ R⁻¹ N` is chi-squared with `d` degrees of
//! freedom (Morrison (5.6.12)); a consistency test compares it with the `(1-α)` quantile. The
//! distribution functions are statrs' (regularised incomplete gamma); the quantile is solved here
//! to full precision (statrs' generic `inverse_cdf` for the chi-squared distribution is a
//! 16-step bisection, good to about 3 digits only).

use crate::error::{Error, Param};
use statrs::distribution::{ChiSquared, Continuous, ContinuousCDF};
use statrs::function::erf::{erfc, erfc_inv};

fn check_dof(dof: f64) -> Result<ChiSquared, Error> {
    if !(dof.is_finite() && dof > 0.0) {
        return Err(Error::InvalidParameter {
            name: Param::DegreesOfFreedom,
            value: dof.to_string(),
            reason: "must be a positive finite number".into(),
        });
    }
    ChiSquared::new(dof).map_err(|e| Error::InvalidParameter {
        name: Param::DegreesOfFreedom,
        value: dof.to_string(),
        reason: e.to_string(),
    })
}

fn check_statistic(x: f64) -> Result<(), Error> {
    if x.is_nan() {
        return Err(Error::NonFinite {
            what: "value",
            value: x,
        });
    }
    Ok(())
}

fn check_probability(name: Param, p: f64) -> Result<(), Error> {
    if !(p > 0.0 && p < 1.0) {
        return Err(Error::InvalidParameter {
            name,
            value: p.to_string(),
            reason: "must lie strictly between 0 and 1".into(),
        });
    }
    Ok(())
}

/// `P(χ²_dof ≤ x)`: the chi-squared CDF (Morrison (5.6.12)-(5.6.16)). `x < 0` gives 0.
///
/// ```
/// use seqsmooth::stats::chi_squared_cdf;
/// // Morrison TV5.6: χ² = 100.25 with 2 dof is far beyond the 95% point
/// assert!(chi_squared_cdf(2.0, 100.25).unwrap() > 0.999_999);
/// // 2 dof is exponential: P = 1 - e^(-x/2)
/// assert!((chi_squared_cdf(2.0, 3.0).unwrap() - (1.0 - (-1.5f64).exp())).abs() < 1e-15);
/// ```
pub fn chi_squared_cdf(dof: f64, x: f64) -> Result<f64, Error> {
    let d = check_dof(dof)?;
    check_statistic(x)?;
    Ok(if x <= 0.0 { 0.0 } else { d.cdf(x) })
}

/// `P(χ²_dof > x)`, the upper tail (the p-value of a chi-squared test), accurate far into the
/// tail (no `1 - cdf` cancellation).
///
/// ```
/// use seqsmooth::stats::chi_squared_sf;
/// assert!((chi_squared_sf(2.0, 40.0).unwrap() - (-20.0f64).exp()).abs() < 1e-22);
/// ```
pub fn chi_squared_sf(dof: f64, x: f64) -> Result<f64, Error> {
    let d = check_dof(dof)?;
    check_statistic(x)?;
    Ok(if x <= 0.0 { 1.0 } else { d.sf(x) })
}

/// The `p` quantile of the chi-squared distribution with `dof` degrees of freedom, `p ∈ (0,1)`:
/// the `x` with `P(χ²_dof ≤ x) = p`. Wilson–Hilferty start, then safeguarded Newton on the CDF
/// (on the upper tail for `p > ½`), to relative accuracy ~1e-13 — as far as statrs' incomplete
/// gamma function allows: it returns 0 below `x ≈ 1e-15`, so lower quantiles smaller than that
/// are not resolved (1 degree of freedom: `p ≲ 1e-7`).
///
/// ```
/// use seqsmooth::stats::chi_squared_quantile;
/// assert!((chi_squared_quantile(1.0, 0.95).unwrap() - 3.841458820694124).abs() < 1e-11);
/// assert!((chi_squared_quantile(10.0, 0.99).unwrap() - 23.209251158954356).abs() < 1e-10);
/// assert!(chi_squared_quantile(3.0, 1.0).is_err());
/// ```
pub fn chi_squared_quantile(dof: f64, p: f64) -> Result<f64, Error> {
    let d = check_dof(dof)?;
    check_probability(Param::Probability, p)?;
    let upper = p > 0.5;
    let target = if upper { 1.0 - p } else { p };
    // F(x) increasing in x, with F(x) = cdf - p (lower) or (1-p) - sf (upper).
    let f = |x: f64| {
        if upper {
            target - d.sf(x)
        } else {
            d.cdf(x) - target
        }
    };
    // Wilson–Hilferty: χ²_k ≈ k (1 - 2/(9k) + z √(2/(9k)))³.
    let z = normal_quantile(p)?;
    let c = 2.0 / (9.0 * dof);
    let mut x = dof * (1.0 - c + z * c.sqrt()).powi(3);
    if !(x.is_finite() && x > 0.0) {
        x = dof.max(1e-3);
    }
    // Bracket the root.
    let (mut lo, mut hi) = (x, x);
    while f(lo) > 0.0 && lo > 1e-300 {
        lo *= 0.5;
    }
    while f(hi) < 0.0 && hi < 1e300 {
        hi *= 2.0;
    }
    if f(lo) > 0.0 {
        return Ok(lo);
    }
    for _ in 0..200 {
        let fx = f(x);
        if fx == 0.0 {
            return Ok(x);
        }
        if fx < 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        let pdf = d.pdf(x);
        let newton = x - fx / pdf;
        let next = if pdf > 0.0 && newton.is_finite() && newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        if (next - x).abs() <= 1e-14 * x.abs() || hi - lo <= 1e-15 * hi {
            return Ok(next);
        }
        x = next;
    }
    Ok(x)
}

/// The standard normal quantile `Φ⁻¹(p)`, `p ∈ (0,1)`.
///
/// ```
/// use seqsmooth::stats::normal_quantile;
/// assert!((normal_quantile(0.975).unwrap() - 1.959963984540054).abs() < 1e-12);
/// ```
pub fn normal_quantile(p: f64) -> Result<f64, Error> {
    check_probability(Param::Probability, p)?;
    Ok(-std::f64::consts::SQRT_2 * erfc_inv(2.0 * p))
}

/// The two-sided Gaussian tail `P(|Z| > k) = erfc(k/√2)`: the false-alarm rate of a `k`-sigma
/// gate on a correctly scaled Gaussian innovation (`k = 3`: 0.0027).
///
/// ```
/// use seqsmooth::stats::two_sided_tail;
/// assert!((two_sided_tail(3.0).unwrap() - 0.0026997960632601866).abs() < 1e-12);
/// ```
pub fn two_sided_tail(k: f64) -> Result<f64, Error> {
    if k.is_nan() || k < 0.0 {
        return Err(Error::InvalidParameter {
            name: Param::GateMultiplier,
            value: k.to_string(),
            reason: "must be a non-negative number".into(),
        });
    }
    Ok(erfc(k / std::f64::consts::SQRT_2))
}

/// The gate multiplier `k` with `P(|Z| > k) = α` (two-sided), `α ∈ (0,1)`.
///
/// ```
/// use seqsmooth::stats::two_sided_threshold;
/// assert!((two_sided_threshold(0.01).unwrap() - 2.5758293035489).abs() < 1e-10);
/// ```
pub fn two_sided_threshold(alpha: f64) -> Result<f64, Error> {
    check_probability(Param::FalseAlarmRate, alpha)?;
    Ok(std::f64::consts::SQRT_2 * erfc_inv(alpha))
}

/// A chi-squared consistency test at significance `α` (Morrison §5.6): reject when the statistic
/// exceeds the `(1-α)` quantile of `χ²_dof`.
///
/// ```
/// use seqsmooth::stats::ChiSquaredTest;
/// let t = ChiSquaredTest::new(2.0, 0.05).unwrap();
/// assert!(t.rejects(100.25));     // Morrison TV5.6
/// assert!(!t.rejects(1.0));
/// assert!((t.threshold() - 5.991464547107979).abs() < 1e-10);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChiSquaredTest {
    dof: f64,
    alpha: f64,
    threshold: f64,
}

impl ChiSquaredTest {
    /// The test with `dof > 0` degrees of freedom and false-alarm rate `α ∈ (0,1)`.
    ///
    /// ```
    /// use seqsmooth::stats::ChiSquaredTest;
    /// assert!(ChiSquaredTest::new(3.0, 0.01).is_ok());
    /// assert!(ChiSquaredTest::new(3.0, 1.5).is_err());
    /// ```
    pub fn new(dof: f64, alpha: f64) -> Result<Self, Error> {
        check_probability(Param::Significance, alpha)?;
        let threshold = chi_squared_quantile(dof, 1.0 - alpha)?;
        Ok(Self {
            dof,
            alpha,
            threshold,
        })
    }

    /// Degrees of freedom.
    ///
    /// ```
    /// use seqsmooth::stats::ChiSquaredTest;
    /// assert_eq!(ChiSquaredTest::new(3.0, 0.01).unwrap().dof(), 3.0);
    /// ```
    pub fn dof(&self) -> f64 {
        self.dof
    }

    /// The significance (false-alarm rate) `α`.
    ///
    /// ```
    /// use seqsmooth::stats::ChiSquaredTest;
    /// assert_eq!(ChiSquaredTest::new(3.0, 0.01).unwrap().alpha(), 0.01);
    /// ```
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// The `(1-α)` quantile the statistic is compared with.
    ///
    /// ```
    /// use seqsmooth::stats::{chi_squared_quantile, ChiSquaredTest};
    /// let t = ChiSquaredTest::new(4.0, 0.05).unwrap();
    /// assert_eq!(t.threshold(), chi_squared_quantile(4.0, 0.95).unwrap());
    /// ```
    pub fn threshold(&self) -> f64 {
        self.threshold
    }

    /// True when `statistic` exceeds the threshold (a NaN statistic is rejected).
    ///
    /// ```
    /// use seqsmooth::stats::ChiSquaredTest;
    /// let t = ChiSquaredTest::new(1.0, 0.05).unwrap(); // threshold 3.84
    /// assert!(t.rejects(4.0) && !t.rejects(3.0) && t.rejects(f64::NAN));
    /// ```
    pub fn rejects(&self, statistic: f64) -> bool {
        statistic.is_nan() || statistic > self.threshold
    }

    /// The p-value `P(χ²_dof > statistic)`.
    ///
    /// ```
    /// use seqsmooth::stats::ChiSquaredTest;
    /// let t = ChiSquaredTest::new(2.0, 0.05).unwrap();
    /// // χ²₂ is exponential with mean 2: P(χ²₂ > x) = e^(−x/2)
    /// assert!((t.p_value(2.0).unwrap() - (-1.0f64).exp()).abs() < 1e-12);
    /// ```
    pub fn p_value(&self, statistic: f64) -> Result<f64, Error> {
        chi_squared_sf(self.dof, statistic)
    }
}
