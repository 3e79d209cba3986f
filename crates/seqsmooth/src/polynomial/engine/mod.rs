//! The engines the expanding- and fading-memory filters run on, and [`EngineState`]: the engine
//! one filter holds (exact or gain), behind the filter's [`PolynomialFilter`] methods.
//!
//! - [`exact`]: recursive least squares (the square-root information filter of
//!   [`crate::recursive`] with the polynomial model).
//! - [`gain`]: the fixed-gain recursion of Morrison Tables 9.1/13.1 in Reyneke's variable-step
//!   form, with its batch kernels.
//! - [`expanding_block`]: runs of even blocks folded into the expanding-memory least-squares fit.
//! - [`recursion`]: the gain recursion of one sample, the reference of every fast path.

pub(crate) mod exact;
pub(crate) mod expanding_block;
pub(crate) mod gain;
pub(crate) mod recursion;

use super::filter::{
    check_batch_lengths, check_estimates_length, check_rows, check_sigma_rows_length,
    first_invalid, no_noise_sigma, RowRule,
};
use crate::error::Error;
use crate::model::PolynomialState;
#[cfg(doc)]
use crate::polynomial::filter::PolynomialFilter;
use crate::polynomial::options::GAIN_MAX_VALUE;
pub(crate) use exact::ExactEngine;
pub(crate) use gain::{FadingGains, GainEngine};

/// Why a least-squares fit with at least `m+1` samples is not determined: its information
/// matrix is singular in doubles.
pub(crate) const SINGULAR: &str = "the fit is not determined: the weights of the samples in \
    memory leave it singular (with fading memory, a discount θ^(step/τ) that underflows, from a \
    gap of many τ, a τ far shorter than the steps or a θ near 0, forgets the earlier samples; \
    the estimate returns once m+1 samples share the memory); use a larger τ or θ";

/// Samples per chunk of [`EngineState::update_many`] with estimates: the chunk's values and
/// rows (`16 + 8(m+1)` bytes a sample) stay within the core's L2 cache between the check, the
/// run and the marking.
const FUSED_CHUNK: usize = 1024;

// The exact engine keeps a low degree's factors inline (`numeric::inline`), so that a copy of a
// filter allocates nothing (the automatic filter copies its filters' state where a decision may
// go back); boxing it would put one allocation back per copy.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub(crate) enum EngineState {
    Exact(ExactEngine),
    Gain(GainEngine),
}

/// `clone_from` into the same engine reuses its buffers (the automatic filter's review keeps
/// copies of its filters and takes them again).
impl Clone for EngineState {
    fn clone(&self) -> Self {
        match self {
            EngineState::Exact(e) => EngineState::Exact(e.clone()),
            EngineState::Gain(g) => EngineState::Gain(g.clone()),
        }
    }

    fn clone_from(&mut self, source: &Self) {
        match (self, source) {
            (EngineState::Exact(to), EngineState::Exact(from)) => to.clone_from(from),
            (EngineState::Gain(to), EngineState::Gain(from)) => to.clone_from(from),
            (to, from) => *to = from.clone(),
        }
    }
}

impl EngineState {
    pub(crate) fn samples(&self) -> u64 {
        match self {
            EngineState::Exact(e) => e.samples(),
            EngineState::Gain(g) => g.samples(),
        }
    }

    pub(crate) fn last_time(&self) -> f64 {
        match self {
            EngineState::Exact(e) => e.last_time(),
            EngineState::Gain(g) => g.last_time(),
        }
    }

    /// The sample's own check, and for the gain engine its value range
    /// ([`GAIN_MAX_VALUE`]).
    /// The prior's time, when the filter started from one (the exact engine only).
    pub(crate) fn prior_time(&self) -> Option<f64> {
        match self {
            EngineState::Exact(e) => e.prior_time(),
            EngineState::Gain(_) => None,
        }
    }

    /// The time a sample must come after: the previous sample's, or before the first, just
    /// before a prior's time (a first sample may share it).
    fn previous(&self) -> Option<f64> {
        match self.samples() {
            0 => self.prior_time().map(f64::next_down),
            _ => Some(self.last_time()),
        }
    }

    /// Whether the samples so far (with a prior, none) may determine a fit of degree `m`.
    pub(crate) fn enough_samples(&self, m: usize) -> bool {
        self.samples() > m as u64 || self.prior_time().is_some()
    }

    /// Starts from `prior` (degree `m`): the exact engine with a noise σ, before any sample;
    /// the gain engine's fixed gains refuse it.
    pub(crate) fn set_prior(
        &mut self,
        m: usize,
        prior: &crate::polynomial::prior::Prior,
    ) -> Result<(), Error> {
        use crate::error::Param;
        prior.check_degree(m)?;
        let refuse = |value: &str, reason: &str| Error::InvalidParameter {
            name: Param::Prior,
            value: value.into(),
            reason: reason.into(),
        };
        if self.samples() > 0 {
            return Err(refuse(
                "after the first sample",
                "a prior is where the filter starts: give it before any sample",
            ));
        }
        match self {
            EngineState::Gain(_) => Err(refuse(
                "on the gain engine",
                "the fixed gains (Morrison Tables 9.1, 13.1) assume no prior information: use \
                 the exact engine",
            )),
            EngineState::Exact(e) => match e.sigma() {
                None => Err(refuse(
                    "without the noise sigma",
                    "the prior is weighed against the samples by their noise: give sigma",
                )),
                Some(sigma) => {
                    let (rows, values) = prior.rows(sigma);
                    e.set_prior(prior.time, &rows, &values);
                    Ok(())
                }
            },
        }
    }

    fn check(&self, t: f64, y: f64) -> Result<(), Error> {
        let previous = self.previous();
        crate::error::check_sample(t, y, previous).map_err(|e| match (e, self.prior_time()) {
            // Before the first sample the bound is the prior's time itself.
            (Error::TimeNotIncreasing { time, .. }, Some(p)) if self.samples() == 0 => {
                Error::TimeNotIncreasing { time, previous: p }
            }
            (e, _) => e,
        })?;
        if matches!(self, EngineState::Gain(_)) && y.abs() > GAIN_MAX_VALUE {
            return Err(Error::GainValueOutOfRange {
                value: y,
                max: GAIN_MAX_VALUE,
            });
        }
        Ok(())
    }

    pub(crate) fn update(&mut self, t: f64, y: f64) -> Result<(), Error> {
        self.check(t, y)?;
        match self {
            EngineState::Exact(e) => e.update(t, y),
            EngineState::Gain(g) => g.update(t, y),
        }
        Ok(())
    }

    /// A batch: the samples checked ([`first_invalid`], and the gain engine's value range),
    /// the valid ones run, the estimates' rows (if asked) with numbers beyond the double range
    /// marked NaN, and the first bad sample (if any) reported by its index.
    ///
    /// With estimates the batch goes in chunks of [`FUSED_CHUNK`] samples, each checked, run
    /// and marked while its numbers are in cache (one pass over memory instead of four); the
    /// per-sample kernels that write every estimate give the same numbers in any chunking.
    /// Without, the whole batch is one run (the gain engine's block maps span it).
    pub(crate) fn update_many(
        &mut self,
        m: usize,
        times: &[f64],
        values: &[f64],
        estimates: Option<&mut [f64]>,
    ) -> Result<(), Error> {
        check_batch_lengths(times, values)?;
        if let Some(out) = &estimates {
            check_estimates_length(times, m, out)?;
        }
        let w = m + 1;
        let chunk = match estimates {
            Some(_) => FUSED_CHUNK,
            None => times.len().max(1),
        };
        let mut estimates = estimates;
        for start in (0..times.len()).step_by(chunk) {
            let end = (start + chunk).min(times.len());
            let out = estimates.as_deref_mut().map(|o| &mut o[start * w..end * w]);
            let valid = start + self.run_valid(m, &times[start..end], &values[start..end], out);
            if valid < end {
                return Err(self.rejection(times, values, valid));
            }
        }
        Ok(())
    }

    /// The error of sample `valid`, the first that [`first_invalid`] (or the gain engine's value
    /// range) rejected: its own check's, with its index.
    fn rejection(&self, times: &[f64], values: &[f64], valid: usize) -> Error {
        match self.check(times[valid], values[valid]) {
            Err(e) => Error::InBatch {
                index: valid,
                source: Box::new(e),
            },
            Ok(()) => unreachable!("first_invalid and check disagree at {valid}"),
        }
    }

    /// Runs the samples of `times`, `values` up to the first one [`first_invalid`] (or the
    /// gain engine's value range) rejects, writing their rows into `out` if given; returns
    /// how many it ran.
    fn run_valid(
        &mut self,
        m: usize,
        times: &[f64],
        values: &[f64],
        out: Option<&mut [f64]>,
    ) -> usize {
        let mut valid = first_invalid(times, values, self.previous());
        if matches!(self, EngineState::Gain(_)) {
            let ys = &values[..valid];
            // Branch-free first (so that it vectorises), searched only when it fails.
            if ys
                .iter()
                .fold(false, |any, y| any | (y.abs() > GAIN_MAX_VALUE))
            {
                valid = ys
                    .iter()
                    .position(|y| y.abs() > GAIN_MAX_VALUE)
                    .unwrap_or(valid);
            }
        }
        let (ts, ys) = (&times[..valid], &values[..valid]);
        match (&mut *self, out) {
            (EngineState::Exact(e), None) => ts.iter().zip(ys).for_each(|(&t, &y)| e.update(t, y)),
            (EngineState::Exact(e), Some(out)) => {
                for ((&t, &y), row) in ts.iter().zip(ys).zip(out.chunks_exact_mut(m + 1)) {
                    e.update(t, y);
                    if !e.derivatives_into(t, row) {
                        row.fill(f64::NAN);
                    }
                }
                mark_out_of_range(&mut out[..valid * (m + 1)]);
            }
            (EngineState::Gain(g), None) => g.update_many(ts, ys),
            (EngineState::Gain(g), Some(out)) => {
                // The gain engine marks as it writes.
                g.update_many_into(ts, ys, &mut out[..valid * (m + 1)]);
            }
        }
        valid
    }

    /// The position at `t` and its variance (with the tracked `σ`), both finite, or `None`
    /// (not determined, no tracked `σ`, or beyond the double range): the exact engine without
    /// allocating, the gain engine from its estimate.
    pub(crate) fn position_at(&self, m: usize, t: f64) -> Option<(f64, f64)> {
        if !self.enough_samples(m) || !t.is_finite() {
            return None;
        }
        let (x, v) = match self {
            EngineState::Exact(e) => e.position_at(t)?,
            EngineState::Gain(g) => {
                let (x, c) = g.estimate_at(t);
                (x[0], c?[(0, 0)])
            }
        };
        (x.is_finite() && v.is_finite()).then_some((x, v))
    }

    /// The derivatives at `t` and their variances (the covariance's diagonal with the tracked
    /// `σ`) into `x` and `var` (`m + 1` each), all finite, or false: the exact engine without
    /// allocating, the gain engine (or an exact one whose unit is out of range) from its
    /// estimate.
    pub(crate) fn variances_at(&self, m: usize, t: f64, x: &mut [f64], var: &mut [f64]) -> bool {
        let p = m + 1;
        let done = match self {
            EngineState::Exact(e) => e.variances_at(t, x, var),
            EngineState::Gain(_) => false,
        };
        if !done {
            let Ok(s) = self.try_estimate_at(m, t) else {
                return false;
            };
            let Some(c) = s.covariance else {
                return false;
            };
            x[..p].copy_from_slice(&s.derivatives);
            for (k, v) in var[..p].iter_mut().enumerate() {
                *v = c[(k, k)];
            }
        }
        x[..p].iter().chain(&var[..p]).all(|v| v.is_finite())
    }

    /// [`Self::try_estimate_at`]'s derivatives and its covariance's diagonal into `x` and `var`
    /// (`m + 1` each), the same numbers bit for bit, without allocating: the exact engine's
    /// [`ExactEngine::estimate_diagonal_into`]. `false` where that does not answer (the gain
    /// engine, not determined, a number beyond its range: the caller takes the estimate).
    pub(crate) fn estimate_diagonal_at(
        &self,
        m: usize,
        t: f64,
        x: &mut [f64],
        var: &mut [f64],
    ) -> bool {
        if !self.enough_samples(m) || !t.is_finite() {
            return false;
        }
        match self {
            EngineState::Exact(e) => e.estimate_diagonal_into(t, x, var),
            EngineState::Gain(_) => false,
        }
    }

    /// The batch σ path ([`PolynomialFilter::update_many_sigma_into`]): rows of `2(m+1)`,
    /// the derivatives and their 1σ after each sample, in chunks of [`FUSED_CHUNK`] as
    /// [`Self::update_many`]; without a covariance matrix per sample (the gain engine's
    /// `std_devs_into`, its plain kernels once the covariance is steady), then checked as
    /// [`Self::try_estimate_at`] checks an estimate (a number beyond the double range, a fit
    /// not determined: the row's error).
    pub(crate) fn update_many_sigma(
        &mut self,
        m: usize,
        times: &[f64],
        values: &[f64],
        rows: &mut [f64],
    ) -> Result<(), Error> {
        check_batch_lengths(times, values)?;
        check_sigma_rows_length(times, m, rows)?;
        let w = m + 1;
        let before = self.samples();
        if !self.tracks_covariance() {
            // Rows NaN until determined; the first determined sample is the error.
            let first =
                usize::try_from((w as u64).saturating_sub(before + 1)).unwrap_or(usize::MAX);
            let end = first.saturating_add(1).min(times.len());
            self.update_many(m, &times[..end], &values[..end], None)?;
            rows[..end * 2 * w].fill(f64::NAN);
            if end > first {
                return Err(Error::InBatch {
                    index: first,
                    source: Box::new(no_noise_sigma()),
                });
            }
            return Ok(());
        }
        for start in (0..times.len()).step_by(FUSED_CHUNK) {
            let end = (start + FUSED_CHUNK).min(times.len());
            let (ts, ys) = (&times[start..end], &values[start..end]);
            let out = &mut rows[start * 2 * w..end * 2 * w];
            let valid = start + self.run_valid_sigma(m, ts, ys, out);
            check_sigma_rows(
                &rows[start * 2 * w..valid * 2 * w],
                w,
                before + start as u64,
                start,
            )?;
            if valid < end {
                return Err(self.rejection(times, values, valid));
            }
        }
        Ok(())
    }

    /// [`Self::run_valid`] for [`Self::update_many_sigma`].
    fn run_valid_sigma(
        &mut self,
        m: usize,
        times: &[f64],
        values: &[f64],
        rows: &mut [f64],
    ) -> usize {
        let mut valid = first_invalid(times, values, self.previous());
        if matches!(self, EngineState::Gain(_)) {
            valid = values[..valid]
                .iter()
                .position(|y| y.abs() > GAIN_MAX_VALUE)
                .unwrap_or(valid);
        }
        let (ts, ys) = (&times[..valid], &values[..valid]);
        let w = m + 1;
        match self {
            EngineState::Gain(g) => g.update_many_sigma_into(ts, ys, &mut rows[..valid * 2 * w]),
            EngineState::Exact(e) => {
                for ((&t, &y), row) in ts.iter().zip(ys).zip(rows.chunks_exact_mut(2 * w)) {
                    e.update(t, y);
                    let (d, s) = row.split_at_mut(w);
                    if !(e.derivatives_into(t, d) && e.batch_std_devs_into(t, s)) {
                        row.fill(f64::NAN);
                    }
                }
            }
        }
        valid
    }

    fn tracks_covariance(&self) -> bool {
        match self {
            EngineState::Exact(e) => e.tracks_covariance(),
            EngineState::Gain(g) => g.tracks_covariance(),
        }
    }

    /// The estimate at `t`, finite in every number, or why there is none
    /// ([`PolynomialFilter::try_estimate_at`]).
    pub(crate) fn try_estimate_at(&self, m: usize, t: f64) -> Result<PolynomialState, Error> {
        crate::error::check_finite("time", &[t])?;
        let samples = self.samples();
        if !self.enough_samples(m) {
            return Err(Error::TooFewSamples {
                needed: m + 1,
                got: samples as usize,
            });
        }
        let (derivatives, covariance) = match self {
            EngineState::Exact(e) => e.estimate_at(t).ok_or_else(|| Error::NotDetermined {
                samples,
                why: SINGULAR.into(),
            })?,
            EngineState::Gain(g) => g.estimate_at(t),
        };
        PolynomialState {
            time: t,
            derivatives,
            covariance,
        }
        .checked()
    }

    pub(crate) fn track_covariance(&mut self, sigma: f64) -> Result<(), Error> {
        crate::polynomial::options::check_noise_sigma(sigma)?;
        match self {
            EngineState::Exact(e) => e.track_covariance(sigma),
            EngineState::Gain(g) => g.track_covariance(sigma),
        }
        Ok(())
    }
}

/// The rows of [`EngineState::update_many_sigma`] checked by the row rule ([`check_rows`]),
/// as an estimate is: from the determined ones on (`before` samples before the first row,
/// which is sample `first` of the batch), a row whose derivatives are all NaN is a fit not
/// determined, any other number that is not finite (a 1σ included) one beyond the double
/// range — the row's error.
fn check_sigma_rows(rows: &[f64], w: usize, before: u64, first: usize) -> Result<(), Error> {
    let rule = RowRule {
        stride: 2 * w,
        needed: w,
        blank: w,
        checked: 2 * w,
        withheld: None,
        why: SINGULAR,
    };
    let name = |k: usize| match k < w {
        true => format!("d{k}"),
        false => format!("s{}", k - w),
    };
    check_rows(rows, &rule, before, name).map_err(|e| match e {
        Error::InBatch { index, source } => Error::InBatch {
            index: index + first,
            source,
        },
        e => e,
    })
}

/// Marks each number of `rows` beyond the double range (infinite) as NaN, "no estimate", as
/// [`PolynomialFilter::update_many_into`] documents: only that derivative, the others of its
/// row stand ([`PolynomialFilter::try_estimate_at`] names it).
fn mark_out_of_range(rows: &mut [f64]) {
    for v in rows.iter_mut() {
        *v = gain::out_of_range_as_nan(*v);
    }
}

/// Implements [`PolynomialFilter`] for a filter type with fields `m` (degree) and `core`
/// ([`EngineState`]).
macro_rules! impl_polynomial_filter {
    ($ty:ty) => {
        impl PolynomialFilter for $ty {
            fn degree(&self) -> usize {
                self.m
            }
            fn samples(&self) -> u64 {
                self.core.samples()
            }
            fn update(&mut self, t: f64, y: f64) -> Result<(), Error> {
                self.core.update(t, y)
            }
            fn update_many(&mut self, times: &[f64], values: &[f64]) -> Result<(), Error> {
                self.core.update_many(self.m, times, values, None)
            }
            #[rustfmt::skip]
            fn update_many_into(&mut self, times: &[f64], values: &[f64], estimates: &mut [f64]) -> Result<(), Error> {
                self.core
                    .update_many(self.m, times, values, Some(estimates))
            }
            fn update_many_sigma_into(&mut self, times: &[f64], values: &[f64], rows: &mut [f64]) -> Result<(), Error> {
                self.core.update_many_sigma(self.m, times, values, rows)
            }
            fn estimate_at(&self, t: f64) -> Option<PolynomialState> {
                self.core.try_estimate_at(self.m, t).ok()
            }
            fn try_estimate_at(&self, t: f64) -> Result<PolynomialState, Error> {
                self.core.try_estimate_at(self.m, t)
            }
            fn last_time(&self) -> Option<f64> {
                (self.core.samples() > 0).then(|| self.core.last_time())
            }
            fn is_determined(&self) -> bool {
                self.core.enough_samples(self.m)
            }
        }
    };
}
pub(crate) use impl_polynomial_filter;

/// Helpers of the engines' unit tests.
impl EngineState {
    /// The invariants of a restored engine of degree `m` ([`crate::persist`]).
    pub(crate) fn check_saved(&self, m: usize) -> Result<(), String> {
        match self {
            EngineState::Exact(e) => e.check_saved(m),
            EngineState::Gain(g) => g.check_saved(m),
        }
    }
}

#[cfg(test)]
pub(crate) mod testing {
    /// Errors of `z` against `want`, per degree, in units of the span `S`:
    /// `|Δz_k| S^k / max_j |want_j| S^j` (the error of Taylor coefficients about the newest
    /// sample, each in units of the whole span).
    pub(crate) fn scaled_errors(z: &[f64], want: &[f64], span: f64) -> Vec<f64> {
        let scale = want
            .iter()
            .enumerate()
            .map(|(j, w)| w.abs() * span.powi(j as i32))
            .fold(f64::MIN_POSITIVE, f64::max);
        z.iter()
            .zip(want)
            .enumerate()
            .map(|(k, (a, b))| (a - b).abs() * span.powi(k as i32) / scale)
            .collect()
    }
}
