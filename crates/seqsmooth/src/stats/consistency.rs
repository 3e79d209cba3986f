//! Filter consistency at run time: the normalised estimation error squared (NEES) against a
//! known truth, and the chi-squared interval of the mean of NEES or NIS over many runs.
//!
//! When a filter is consistent (its model holds, its errors are Gaussian and its reported
//! covariance is the covariance of its errors), the error `e = X̂ − X` of an `n`-state estimate
//! with covariance `S` gives `NEES = eᵀ S⁻¹ e ~ χ²(n)`, and the innovation `ν` of a
//! `p`-component update with covariance `V` gives `NIS = νᵀ V⁻¹ ν ~ χ²(p)` (Morrison §14.8 for
//! the innovation test, (5.6.12) for the quadratic form; NEES and NIS by these names are
//! Bar-Shalom, Li and Kirubarajan's, *Estimation with Applications to Tracking and Navigation*).
//! The sum of `N` independent such values is `χ²(n N)`, so their mean lies in
//! `[χ²_{nN}((1−c)/2), χ²_{nN}((1+c)/2)] / N` with probability `c`: [`mean_interval`], and
//! [`ConsistencyTest`] accumulating the values. A mean above the interval means the filter is
//! over-confident (its covariance too small), below it under-confident.
//!
//! The quantiles are [`chi_squared_quantile`]'s (full precision; statrs' own `inverse_cdf` for
//! the chi-squared distribution is a 16-step bisection).

use super::chi_squared::chi_squared_quantile;
use crate::error::{Error, Param};
use nalgebra::{DMatrix, DVector};

/// Entries `S_ij` and `S_ji` of a covariance may differ by this fraction of `√(S_ii S_jj)`
/// (a filter's rounding passes; a transposed or unrelated matrix does not).
const SYMMETRY_TOLERANCE: f64 = 1e-10;

/// The normalised estimation error squared `NEES = eᵀ S⁻¹ e`, `e = estimate − truth`, by the
/// Cholesky factor `S = L Lᵀ`: `NEES = |L⁻¹ e|²` (no inverse is formed). `χ²(n)` for an
/// `n`-state estimate of a consistent filter.
///
/// The covariance must be symmetric (to 1e-10 of `√(S_ii S_jj)` per entry; the two triangles
/// are averaged) and positive definite to working precision: each Cholesky pivot (the variance
/// of a component given the earlier ones) must exceed `n ε` times the component's variance,
/// else the error names the component at which `S` is singular or indefinite.
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::stats::consistency::nees;
/// // S = [[4, 2], [2, 2]], e = (2, 0): S⁻¹ = [[1/2, −1/2], [−1/2, 1]], eᵀ S⁻¹ e = 2.
/// let s = DMatrix::from_row_slice(2, 2, &[4.0, 2.0, 2.0, 2.0]);
/// let x = DVector::from_vec(vec![3.0, -1.0]);
/// let truth = DVector::from_vec(vec![1.0, -1.0]);
/// assert!((nees(&x, &s, &truth).unwrap() - 2.0).abs() < 1e-15);
/// // singular: the second component is the first
/// let singular = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 1.0, 1.0]);
/// assert!(nees(&x, &singular, &truth).is_err());
/// ```
pub fn nees(
    estimate: &DVector<f64>,
    covariance: &DMatrix<f64>,
    truth: &DVector<f64>,
) -> Result<f64, Error> {
    let n = estimate.len();
    let bad = |name: Param, value: String, reason: String| Error::InvalidParameter {
        name,
        value,
        reason,
    };
    if n == 0 {
        return Err(bad(
            Param::Estimate,
            "of length 0".into(),
            "must have at least one component".into(),
        ));
    }
    if truth.len() != n {
        return Err(bad(
            Param::Truth,
            format!("of length {}", truth.len()),
            format!("the estimate has {n} components"),
        ));
    }
    if covariance.shape() != (n, n) {
        return Err(bad(
            Param::Covariance,
            format!("{}x{}", covariance.nrows(), covariance.ncols()),
            format!("must be {n}x{n}: the estimate has {n} components"),
        ));
    }
    for (what, xs) in [
        ("estimate entry", estimate.as_slice()),
        ("truth entry", truth.as_slice()),
        ("covariance entry", covariance.as_slice()),
    ] {
        if let Some(&value) = xs.iter().find(|v| !v.is_finite()) {
            return Err(Error::NonFinite { what, value });
        }
    }
    for j in 0..n {
        for i in j + 1..n {
            let (a, b) = (covariance[(i, j)], covariance[(j, i)]);
            let scale = (covariance[(i, i)] * covariance[(j, j)]).abs().sqrt();
            if (a - b).abs() > SYMMETRY_TOLERANCE * scale {
                return Err(bad(
                    Param::Covariance,
                    format!("entries ({i}, {j}) = {a:e} and ({j}, {i}) = {b:e}"),
                    format!(
                        "must be symmetric (to {SYMMETRY_TOLERANCE:e} of the square root of \
                         the product of their variances)"
                    ),
                ));
            }
        }
    }
    // S = L Lᵀ column by column (lower triangle of the symmetrised S), then z = L⁻¹ e forward.
    let mut l = DMatrix::<f64>::zeros(n, n);
    let floor = n as f64 * f64::EPSILON;
    for j in 0..n {
        let variance = covariance[(j, j)];
        let pivot = variance - (0..j).map(|k| l[(j, k)] * l[(j, k)]).sum::<f64>();
        if pivot.is_nan() || pivot <= floor * variance {
            return Err(bad(
                Param::Covariance,
                format!(
                    "with variance {variance:e} of component {j} and {pivot:e} of it given \
                     components 0..{j}"
                ),
                format!(
                    "not positive definite to working precision: the variance of component \
                     {j} given the earlier ones is not above {floor:e} of its own (S is \
                     singular or indefinite there)"
                ),
            ));
        }
        let d = pivot.sqrt();
        l[(j, j)] = d;
        for i in j + 1..n {
            let sij = 0.5 * (covariance[(i, j)] + covariance[(j, i)]);
            l[(i, j)] = (sij - (0..j).map(|k| l[(i, k)] * l[(j, k)]).sum::<f64>()) / d;
        }
    }
    let mut z = estimate - truth;
    for i in 0..n {
        let zi = (z[i] - (0..i).map(|k| l[(i, k)] * z[k]).sum::<f64>()) / l[(i, i)];
        z[i] = zi;
    }
    let value = z.norm_squared();
    if !value.is_finite() {
        return Err(Error::EstimateOutOfRange {
            what: "normalised estimation error squared".into(),
        });
    }
    Ok(value)
}

fn check_confidence(confidence: f64) -> Result<(), Error> {
    if !(confidence > 0.0 && confidence < 1.0) {
        return Err(Error::InvalidParameter {
            name: Param::Confidence,
            value: confidence.to_string(),
            reason: "must lie strictly between 0 and 1".into(),
        });
    }
    Ok(())
}

fn check_dof(dof: usize) -> Result<(), Error> {
    if dof == 0 {
        return Err(Error::InvalidParameter {
            name: Param::DegreesOfFreedom,
            value: "0".into(),
            reason: "must be at least 1".into(),
        });
    }
    Ok(())
}

/// The interval of the mean of values whose sum is `χ²(total_dof)`, over `runs` values.
fn interval(total_dof: usize, runs: usize, confidence: f64) -> Result<(f64, f64), Error> {
    check_confidence(confidence)?;
    let k = total_dof as f64;
    let lo = chi_squared_quantile(k, 0.5 * (1.0 - confidence))?;
    let hi = chi_squared_quantile(k, 0.5 * (1.0 + confidence))?;
    Ok((lo / runs as f64, hi / runs as f64))
}

/// The two-sided `confidence` interval of the mean of `runs` independent `χ²(dof_per_run)`
/// values: `[χ²_{dof·runs}((1−c)/2), χ²_{dof·runs}((1+c)/2)] / runs`. `dof_per_run ≥ 1`,
/// `runs ≥ 1`, `0 < confidence < 1`; the quantiles are [`chi_squared_quantile`]'s (relative
/// accuracy ~1e-13; lower quantiles below ~1e-15 are not resolved).
///
/// ```
/// use seqsmooth::stats::consistency::mean_interval;
/// // one χ²(1) value: the 0.5% and 99.5% points of the table, 3.927e-5 and 7.879
/// let (lo, hi) = mean_interval(1, 1, 0.99).unwrap();
/// assert!((lo - 3.927e-5).abs() < 1e-8 && (hi - 7.879).abs() < 1e-3);
/// // the mean of 2,000 NEES of 4 states: within 4 ± 0.17 at 99%
/// let (lo, hi) = mean_interval(4, 2000, 0.99).unwrap();
/// assert!(3.83 < lo && lo < 3.85 && 4.16 < hi && hi < 4.18);
/// assert!(mean_interval(0, 10, 0.95).is_err() && mean_interval(2, 10, 1.0).is_err());
/// ```
pub fn mean_interval(
    dof_per_run: usize,
    runs: usize,
    confidence: f64,
) -> Result<(f64, f64), Error> {
    check_dof(dof_per_run)?;
    if runs == 0 {
        return Err(Error::TooFewSamples { needed: 1, got: 0 });
    }
    let total = dof_per_run
        .checked_mul(runs)
        .ok_or_else(|| Error::InvalidParameter {
            name: Param::Runs,
            value: runs.to_string(),
            reason: format!("times {dof_per_run} degrees of freedom overflows"),
        })?;
    check_confidence(confidence)?;
    interval(total, runs, confidence)
}

/// Accumulates NEES or NIS values and tests their mean against its chi-squared interval:
/// after `N` values of `dof` degrees of freedom each, `mean = Σ v / N` and
/// `N · mean ~ χ²(dof · N)` when the filter is consistent. NEES of an `n`-state estimate is
/// `χ²(n)`; NIS of a `p`-component update is `χ²(p)` (Morrison §14.8). Values of another
/// number of degrees of freedom (an update with a missing component) go in by
/// [`Self::push_with_dof`]: the sum is then `χ²` of the summed degrees of freedom.
///
/// ```
/// use seqsmooth::stats::consistency::ConsistencyTest;
/// let mut t = ConsistencyTest::new(2).unwrap(); // NIS of 2-component updates
/// for v in [1.5, 2.5, 1.0, 3.0] {
///     t.push(v).unwrap();
/// }
/// assert_eq!(t.mean(), Some(2.0));
/// assert!(t.contains(0.99).unwrap());
/// t.push(60.0).unwrap(); // an innovation far off the model
/// assert!(!t.contains(0.99).unwrap());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConsistencyTest {
    dof: usize,
    total_dof: usize,
    sum: f64,
    runs: usize,
}

impl ConsistencyTest {
    /// An empty test of values with `dof ≥ 1` degrees of freedom each.
    ///
    /// ```
    /// use seqsmooth::stats::consistency::ConsistencyTest;
    /// assert_eq!(ConsistencyTest::new(6).unwrap().dof(), 6);
    /// assert!(ConsistencyTest::new(0).is_err());
    /// ```
    pub fn new(dof: usize) -> Result<Self, Error> {
        check_dof(dof)?;
        Ok(Self {
            dof,
            total_dof: 0,
            sum: 0.0,
            runs: 0,
        })
    }

    /// Adds a value of [`Self::dof`] degrees of freedom: `Σ v += value`, `N += 1`. A negative or
    /// non-finite value is refused and leaves the test unchanged.
    ///
    /// ```
    /// use seqsmooth::stats::consistency::ConsistencyTest;
    /// let mut t = ConsistencyTest::new(1).unwrap();
    /// t.push(0.5).unwrap();
    /// assert!(t.push(-1.0).is_err() && t.push(f64::NAN).is_err());
    /// assert_eq!(t.runs(), 1);
    /// ```
    pub fn push(&mut self, value: f64) -> Result<(), Error> {
        self.push_with_dof(value, self.dof)
    }

    /// Adds a value of `dof ≥ 1` degrees of freedom (the NIS of an update with only some
    /// components present: `dof` = the components used).
    ///
    /// ```
    /// use seqsmooth::stats::consistency::ConsistencyTest;
    /// let mut t = ConsistencyTest::new(2).unwrap();
    /// t.push(2.0).unwrap();
    /// t.push_with_dof(1.0, 1).unwrap(); // one component missing
    /// assert_eq!(t.total_dof(), 3);
    /// ```
    pub fn push_with_dof(&mut self, value: f64, dof: usize) -> Result<(), Error> {
        check_dof(dof)?;
        if !value.is_finite() {
            return Err(Error::NonFinite {
                what: "value",
                value,
            });
        }
        if value < 0.0 {
            return Err(Error::InvalidParameter {
                name: Param::NeesOrNisValue,
                value: value.to_string(),
                reason: "must be non-negative (a quadratic form in a positive definite matrix)"
                    .into(),
            });
        }
        let total_dof = self
            .total_dof
            .checked_add(dof)
            .ok_or_else(|| Error::InvalidParameter {
                name: Param::DegreesOfFreedom,
                value: dof.to_string(),
                reason: "overflow the test's running total".into(),
            })?;
        self.total_dof = total_dof;
        self.sum += value;
        self.runs += 1;
        Ok(())
    }

    /// Degrees of freedom of a value given to [`Self::push`].
    ///
    /// ```
    /// use seqsmooth::stats::consistency::ConsistencyTest;
    /// assert_eq!(ConsistencyTest::new(3).unwrap().dof(), 3);
    /// ```
    pub fn dof(&self) -> usize {
        self.dof
    }

    /// The summed degrees of freedom of the values so far (`dof · N` without
    /// [`Self::push_with_dof`]).
    ///
    /// ```
    /// use seqsmooth::stats::consistency::ConsistencyTest;
    /// let mut t = ConsistencyTest::new(3).unwrap();
    /// t.push(1.0).unwrap();
    /// t.push(4.0).unwrap();
    /// assert_eq!(t.total_dof(), 6);
    /// ```
    pub fn total_dof(&self) -> usize {
        self.total_dof
    }

    /// The number of values `N`.
    ///
    /// ```
    /// use seqsmooth::stats::consistency::ConsistencyTest;
    /// assert_eq!(ConsistencyTest::new(3).unwrap().runs(), 0);
    /// ```
    pub fn runs(&self) -> usize {
        self.runs
    }

    /// The sum `Σ v` of the values.
    ///
    /// ```
    /// use seqsmooth::stats::consistency::ConsistencyTest;
    /// let mut t = ConsistencyTest::new(1).unwrap();
    /// t.push(1.25).unwrap();
    /// t.push(0.5).unwrap();
    /// assert_eq!(t.sum(), 1.75);
    /// ```
    pub fn sum(&self) -> f64 {
        self.sum
    }

    /// The mean `Σ v / N`, `None` before the first value.
    ///
    /// ```
    /// use seqsmooth::stats::consistency::ConsistencyTest;
    /// let mut t = ConsistencyTest::new(1).unwrap();
    /// assert_eq!(t.mean(), None);
    /// t.push(3.0).unwrap();
    /// t.push(1.0).unwrap();
    /// assert_eq!(t.mean(), Some(2.0));
    /// ```
    pub fn mean(&self) -> Option<f64> {
        (self.runs > 0).then(|| self.sum / self.runs as f64)
    }

    /// The two-sided `confidence` interval of the mean:
    /// `[χ²_K((1−c)/2), χ²_K((1+c)/2)] / N`, `K` = [`Self::total_dof`] (equal to
    /// [`mean_interval`]`(dof, N, c)` without [`Self::push_with_dof`]). An error before the
    /// first value or for `confidence` outside `(0, 1)`.
    ///
    /// ```
    /// use seqsmooth::stats::consistency::{mean_interval, ConsistencyTest};
    /// let mut t = ConsistencyTest::new(2).unwrap();
    /// assert!(t.interval(0.95).is_err());
    /// for _ in 0..10 {
    ///     t.push(2.0).unwrap();
    /// }
    /// assert_eq!(t.interval(0.95).unwrap(), mean_interval(2, 10, 0.95).unwrap());
    /// ```
    pub fn interval(&self, confidence: f64) -> Result<(f64, f64), Error> {
        if self.runs == 0 {
            return Err(Error::TooFewSamples { needed: 1, got: 0 });
        }
        interval(self.total_dof, self.runs, confidence)
    }

    /// Whether the mean lies in [`Self::interval`]`(confidence)`: `lo ≤ Σ v / N ≤ hi` (a
    /// consistent filter fails with probability `1 − confidence`).
    ///
    /// ```
    /// use seqsmooth::stats::consistency::ConsistencyTest;
    /// let mut t = ConsistencyTest::new(1).unwrap();
    /// for _ in 0..100 {
    ///     t.push(0.1).unwrap(); // far too small: an under-confident filter
    /// }
    /// assert!(!t.contains(0.99).unwrap());
    /// ```
    pub fn contains(&self, confidence: f64) -> Result<bool, Error> {
        let (lo, hi) = self.interval(confidence)?;
        let mean = self.sum / self.runs as f64;
        Ok(lo <= mean && mean <= hi)
    }
}
