//! [`PolynomialFilter`]: what every polynomial filter does (take timestamped samples, give
//! estimates), and the one-pass validation of a batch of samples.

use crate::error::{Error, Param};
use crate::model::PolynomialState;

/// What every polynomial filter does: take timestamped samples, give estimates. Implemented by
/// [`ExpandingMemory`](crate::ExpandingMemory), [`FadingMemory`](crate::FadingMemory), [`FixedMemory`](crate::FixedMemory) and [`AutomaticFilter`](crate::polynomial::AutomaticFilter), so callers
/// can hold any of them behind one type.
///
/// ```
/// use seqsmooth::{Engine, ExpandingMemory, FadingMemory, PolynomialFilter};
/// let mut filters: Vec<Box<dyn PolynomialFilter>> = vec![
///     Box::new(ExpandingMemory::new(1, Engine::Exact).unwrap()),
///     Box::new(FadingMemory::new(1, 0.8, 1.0, Engine::Gain).unwrap()),
/// ];
/// for f in filters.iter_mut() {
///     for k in 0..20 {
///         f.update(k as f64, 3.0 * k as f64).unwrap();
///     }
///     assert!((f.estimate().unwrap().derivatives[1] - 3.0).abs() < 1e-12);
/// }
/// ```
pub trait PolynomialFilter: std::fmt::Debug + Send {
    /// Degree `m`.
    fn degree(&self) -> usize;
    /// Number of samples processed.
    fn samples(&self) -> u64;
    /// Processes the sample `y` at time `t` (finite, strictly after the previous time). A
    /// rejected sample leaves the filter unchanged.
    fn update(&mut self, t: f64, y: f64) -> Result<(), Error>;
    /// The estimate valid at any time `t` from the samples so far (a prediction after the
    /// newest sample, a retrodiction before it); `None` until the estimate is determined
    /// (`m+1` samples for the expanding- and fading-memory filters, a full window for the
    /// fixed-memory filter), or when it is not: [`try_estimate_at`](Self::try_estimate_at)
    /// says why. Every number of a returned estimate is finite.
    fn estimate_at(&self, t: f64) -> Option<PolynomialState>;
    /// The estimate at `t`, or why there is none: [`Error::TooFewSamples`] (before the fit is
    /// determined), [`Error::NotDetermined`] (weights that leave the fit singular in doubles,
    /// with what to change),
    /// [`Error::EstimateOutOfRange`] (a derivative or variance beyond the double range in the
    /// caller's units, say the top derivative of a fit over steps of 1e-200), or
    /// [`Error::NonFinite`] for a `t` that is not finite. The filters of this crate override
    /// it with their own reasons; the default gives [`Error::TooFewSamples`] for any `None`.
    ///
    /// ```
    /// use seqsmooth::{Engine, Error, ExpandingMemory, PolynomialFilter};
    /// let mut f = ExpandingMemory::new(2, Engine::Exact).unwrap();
    /// f.update(0.0, 1.0).unwrap();
    /// assert!(matches!(f.try_estimate(), Err(Error::TooFewSamples { needed: 3, got: 1 })));
    /// f.update(1e-200, 2.0).unwrap();
    /// f.update(2e-200, 5.0).unwrap();
    /// // d2 = 2e400: not a double in these units
    /// let e = f.try_estimate().unwrap_err();
    /// assert!(matches!(e, Error::EstimateOutOfRange { ref what } if what == "d2"), "{e}");
    /// assert!(f.estimate().is_none());
    /// ```
    fn try_estimate_at(&self, t: f64) -> Result<PolynomialState, Error> {
        self.estimate_at(t).ok_or_else(|| Error::TooFewSamples {
            needed: self.degree() + 1,
            got: self.samples() as usize,
        })
    }
    /// The time of the newest sample.
    fn last_time(&self) -> Option<f64>;
    /// The current estimate, valid at the newest sample's time.
    fn estimate(&self) -> Option<PolynomialState> {
        self.estimate_at(self.last_time()?)
    }
    /// The current estimate, or why there is none ([`try_estimate_at`](Self::try_estimate_at)
    /// at the newest sample's time).
    fn try_estimate(&self) -> Result<PolynomialState, Error> {
        match self.last_time() {
            Some(t) => self.try_estimate_at(t),
            None => Err(Error::TooFewSamples {
                needed: self.degree() + 1,
                got: 0,
            }),
        }
    }
    /// True once the estimate is determined (`m+1` samples).
    fn is_determined(&self) -> bool {
        self.samples() > self.degree() as u64
    }
    /// Processes the samples `(times[i], values[i])` in order, with the same result as
    /// [`update`](Self::update) on each. The expanding- and fading-memory filters check the
    /// whole batch in one pass and run a tight loop (see BENCHMARKS.md for the speed-up). On
    /// the first invalid sample it returns [`Error::InBatch`] with the sample's index: the
    /// samples before it are processed, it and the rest are not.
    ///
    /// ```
    /// use seqsmooth::{Engine, Error, FadingMemory, PolynomialFilter};
    /// let mut f = FadingMemory::new(1, 0.9, 1.0, Engine::Gain).unwrap();
    /// let t: Vec<f64> = (0..100).map(f64::from).collect();
    /// let y: Vec<f64> = t.iter().map(|t| 3.0 + 0.5 * t).collect();
    /// f.update_many(&t, &y).unwrap();
    /// let s = f.estimate().unwrap();
    /// assert!((s.derivatives[0] - 52.5).abs() < 1e-9 && (s.derivatives[1] - 0.5).abs() < 1e-9);
    /// // a time that goes backwards is reported with its index; the samples before it count
    /// let err = f.update_many(&[100.0, 99.0], &[53.0, 52.5]).unwrap_err();
    /// assert!(matches!(err, Error::InBatch { index: 1, .. }));
    /// assert_eq!(f.samples(), 101);
    /// ```
    fn update_many(&mut self, times: &[f64], values: &[f64]) -> Result<(), Error> {
        check_batch_lengths(times, values)?;
        for (index, (&t, &y)) in times.iter().zip(values).enumerate() {
            self.update(t, y).map_err(|e| Error::InBatch {
                index,
                source: Box::new(e),
            })?;
        }
        Ok(())
    }
    /// [`update_many`](Self::update_many) that also writes the estimate after each sample:
    /// `estimates[i·(m+1) + k]` is the `k`-th derivative at `times[i]` from the samples up to
    /// and including sample `i` (NaN while undetermined, for a derivative beyond the double
    /// range, which the expanding- and fading-memory filters mark alone and the others mark
    /// with its whole row, and for the derivatives above the degree of an estimate with fewer
    /// than `m+1`, as the automatic filter's while its degree settles;
    /// [`try_estimate_at`](Self::try_estimate_at) says why). No number written is infinite.
    /// `estimates.len()` must be
    /// `times.len()·(m+1)`. On an invalid sample the rows before it are written, the rest are
    /// left as they were. The gain engine writes from its batch kernels (no allocation per
    /// sample); the rows equal [`estimate`](Self::estimate)'s up to a rounding of the last
    /// conversion `k!/τ^k`.
    ///
    /// ```
    /// use seqsmooth::{Engine, ExpandingMemory, PolynomialFilter};
    /// let mut f = ExpandingMemory::new(1, Engine::Gain).unwrap();
    /// let t = [0.0, 1.0, 2.0, 3.0];
    /// let y = [1.0, 3.0, 5.0, 7.0]; // y = 1 + 2t
    /// let mut est = [0.0; 8];
    /// f.update_many_into(&t, &y, &mut est).unwrap();
    /// assert!(est[0].is_nan()); // one sample does not determine a line
    /// assert!((est[6] - 7.0).abs() < 1e-12 && (est[7] - 2.0).abs() < 1e-12);
    /// ```
    fn update_many_into(
        &mut self,
        times: &[f64],
        values: &[f64],
        estimates: &mut [f64],
    ) -> Result<(), Error> {
        check_batch_lengths(times, values)?;
        let w = self.degree() + 1;
        check_estimates_length(times, self.degree(), estimates)?;
        for (index, ((&t, &y), row)) in times
            .iter()
            .zip(values)
            .zip(estimates.chunks_exact_mut(w))
            .enumerate()
        {
            self.update(t, y).map_err(|e| Error::InBatch {
                index,
                source: Box::new(e),
            })?;
            write_estimate_row(row, self.estimate_at(t));
        }
        Ok(())
    }
    /// The batch σ path: [`update_many_into`](Self::update_many_into) that also writes each
    /// estimate's 1σ (the square roots of its covariance's diagonal). Row `i` of `rows` holds
    /// `2(m+1)` values, the derivatives `x, x', …, x^(m)` at `times[i]` and then their 1σ (the
    /// columns `d0..dM,s0..sM` of `seqsmooth filter --sigma`); both NaN while the filter is not
    /// determined. The filters of this crate write without a covariance matrix per sample
    /// where they can (speed: BENCHMARKS.md); the numbers are [`try_estimate_at`](Self::try_estimate_at)'s
    /// up to the rounding of the covariance's recursion.
    ///
    /// Errors: those of [`update_many_into`](Self::update_many_into) and of
    /// [`try_estimate_at`](Self::try_estimate_at) once determined, in [`Error::InBatch`]
    /// with the sample's index; `rows` of another length; a filter without a noise σ
    /// ([`Error::InvalidParameter`] naming `sigma`, at the first determined sample).
    ///
    /// ```
    /// use seqsmooth::{Engine, FadingMemory, PolynomialFilter};
    /// let mut f = FadingMemory::new(1, 0.9, 1.0, Engine::Gain).unwrap().with_noise_sigma(0.5).unwrap();
    /// let t: Vec<f64> = (0..50).map(f64::from).collect();
    /// let y: Vec<f64> = t.iter().map(|t| 1.0 + 2.0 * t).collect();
    /// let mut rows = vec![0.0; 50 * 4];
    /// f.update_many_sigma_into(&t, &y, &mut rows).unwrap();
    /// assert!(rows[0].is_nan());                             // one sample: no line yet
    /// let last = &rows[49 * 4..];
    /// assert!((last[1] - 2.0).abs() < 1e-9);                // x'
    /// let s = f.estimate().unwrap().std_devs().unwrap();
    /// assert!((last[2] - s[0]).abs() <= 1e-12 * s[0]);       // the estimate's own 1σ
    /// ```
    fn update_many_sigma_into(
        &mut self,
        times: &[f64],
        values: &[f64],
        rows: &mut [f64],
    ) -> Result<(), Error> {
        check_batch_lengths(times, values)?;
        let w = self.degree() + 1;
        check_sigma_rows_length(times, self.degree(), rows)?;
        for (index, ((&t, &y), row)) in times
            .iter()
            .zip(values)
            .zip(rows.chunks_exact_mut(2 * w))
            .enumerate()
        {
            let at = |e: Error| Error::InBatch {
                index,
                source: Box::new(e),
            };
            self.update(t, y).map_err(at)?;
            let state = match self.try_estimate_at(t) {
                Ok(s) => s,
                Err(Error::TooFewSamples { .. }) => {
                    row.fill(f64::NAN);
                    continue;
                }
                Err(e) => return Err(at(e)),
            };
            let (d, s) = row.split_at_mut(w);
            let x = &state.derivatives;
            d[..x.len()].copy_from_slice(x);
            d[x.len()..].fill(f64::NAN);
            let sd = state.std_devs().ok_or_else(|| at(no_noise_sigma()))?;
            s[..sd.len()].copy_from_slice(&sd);
            s[sd.len()..].fill(f64::NAN);
        }
        Ok(())
    }
}

/// Checks a batch's rows of derivatives and 1σ for
/// [`PolynomialFilter::update_many_sigma_into`]: `rows.len() = times.len()·2(m+1)`.
pub(crate) fn check_sigma_rows_length(times: &[f64], m: usize, rows: &[f64]) -> Result<(), Error> {
    if rows.len() != times.len() * 2 * (m + 1) {
        return Err(Error::InvalidParameter {
            name: Param::RowsLength,
            value: rows.len().to_string(),
            reason: format!(
                "{} samples of degree {m} need {} values (one row of m+1 derivatives and their \
                 m+1 sigmas per sample)",
                times.len(),
                times.len() * 2 * (m + 1)
            ),
        });
    }
    Ok(())
}

/// The error of a filter asked for 1σ without a noise σ.
pub(crate) fn no_noise_sigma() -> Error {
    Error::InvalidParameter {
        name: Param::Sigma,
        value: "None".into(),
        reason: "the filter has no noise sigma for the 1σ: construct it with one \
                 (with_noise_sigma, sigma=...)"
            .into(),
    }
}

/// Writes one row of [`PolynomialFilter::update_many_into`]: the estimate's derivatives, NaN
/// for those it does not have (or all, without an estimate).
fn write_estimate_row(row: &mut [f64], estimate: Option<PolynomialState>) {
    let d = estimate.map_or(Vec::new(), |s| s.derivatives);
    let k = d.len().min(row.len());
    row[..k].copy_from_slice(&d[..k]);
    row[k..].fill(f64::NAN);
}

/// Checks `estimates.len() = times.len()·(m+1)` for [`PolynomialFilter::update_many_into`].
pub(crate) fn check_estimates_length(
    times: &[f64],
    m: usize,
    estimates: &[f64],
) -> Result<(), Error> {
    if estimates.len() != times.len() * (m + 1) {
        return Err(Error::InvalidParameter {
            name: Param::EstimatesLength,
            value: estimates.len().to_string(),
            reason: format!(
                "{} samples of degree {m} need {} values (one row of m+1 derivatives per sample)",
                times.len(),
                times.len() * (m + 1)
            ),
        });
    }
    Ok(())
}

/// One time per value in a batch.
pub(crate) fn check_batch_lengths(times: &[f64], values: &[f64]) -> Result<(), Error> {
    crate::error::check_lengths(
        Param::BatchLengths,
        times,
        values,
        "a batch needs one time per value",
    )
}

/// The row rule's parameters for [`check_rows`]: rows of `stride` cells, the first
/// `needed − 1` of a filter's rows undetermined; from there a row whose first `blank` cells are
/// all NaN is a fit not determined (skipped while its cell `withheld`, if any, is NaN), and its
/// first `checked` cells must be finite.
pub(crate) struct RowRule<'a> {
    pub stride: usize,
    pub needed: usize,
    pub blank: usize,
    pub checked: usize,
    pub withheld: Option<usize>,
    /// Why a fit is not determined.
    pub why: &'a str,
}

/// The row rule over `rows` (the filter's rows before them `before`): no cell infinite, and
/// the determined rows as [`RowRule`] says; the first refused row as [`Error::InBatch`] with
/// its index in `rows` (a refused cell named by `name(k)`). The fast path is one branch-free
/// pass (vectorised); only a batch with an empty or infinite cell where it may not be is
/// searched row by row.
pub(crate) fn check_rows(
    rows: &[f64],
    rule: &RowRule<'_>,
    before: u64,
    name: impl Fn(usize) -> String,
) -> Result<(), Error> {
    let stride = rule.stride;
    let undetermined = usize::try_from((rule.needed as u64).saturating_sub(before + 1));
    let first = undetermined
        .unwrap_or(usize::MAX)
        .saturating_mul(stride)
        .min(rows.len());
    if !rows[..first].iter().any(|v| v.is_infinite())
        && rows[first..].iter().fold(true, |ok, &v| ok & finite(v))
    {
        return Ok(());
    }
    for (i, row) in rows.chunks_exact(stride).enumerate() {
        let refused = |e: Error| {
            Err(Error::InBatch {
                index: i,
                source: Box::new(e),
            })
        };
        let out_of_range = |k: usize| refused(Error::EstimateOutOfRange { what: name(k) });
        if let Some(k) = row.iter().position(|v| v.is_infinite()) {
            return out_of_range(k);
        }
        let samples = before + i as u64 + 1;
        if samples < rule.needed as u64 || rule.withheld.is_some_and(|k| row[k].is_nan()) {
            continue;
        }
        if row[..rule.blank].iter().all(|v| v.is_nan()) {
            return refused(Error::NotDetermined {
                samples,
                why: rule.why.into(),
            });
        }
        if let Some(k) = row[..rule.checked].iter().position(|v| !v.is_finite()) {
            return out_of_range(k);
        }
    }
    Ok(())
}

/// `x` is neither NaN nor infinite: `x − x` is `0` exactly then (`NaN` otherwise); as
/// arithmetic it vectorises better in [`first_invalid`] than `f64::is_finite` (speed: see
/// BENCHMARKS.md).
#[inline(always)]
#[allow(clippy::eq_op)]
pub(crate) fn finite(x: f64) -> bool {
    x - x == 0.0
}

/// The index of the first sample of a batch that [`crate::error::check_sample`] rejects
/// (`times.len()` when all pass): a branch-free pass over blocks, located exactly only when a
/// block fails.
pub(crate) fn first_invalid(times: &[f64], values: &[f64], previous: Option<f64>) -> usize {
    const CHUNK: usize = 256;
    let mut prev = previous.unwrap_or(f64::NEG_INFINITY);
    for (c, (tc, yc)) in times.chunks(CHUNK).zip(values.chunks(CHUNK)).enumerate() {
        // Branch-free over the chunk, so that it vectorises (`t > p` is false for NaN or a time
        // not after the previous one).
        let n = tc.len();
        let mut ok = (tc[0] > prev) & finite(tc[0]) & finite(yc[0]);
        for ((&t, &p), &y) in tc[1..].iter().zip(&tc[..n - 1]).zip(&yc[1..]) {
            ok &= (t > p) & finite(t) & finite(y);
        }
        if !ok {
            let mut p = (c > 0 || previous.is_some()).then_some(prev);
            for (j, (&t, &y)) in tc.iter().zip(yc).enumerate() {
                if crate::error::check_sample(t, y, p).is_err() {
                    return c * CHUNK + j;
                }
                p = Some(t);
            }
        }
        prev = tc[n - 1];
    }
    times.len()
}
