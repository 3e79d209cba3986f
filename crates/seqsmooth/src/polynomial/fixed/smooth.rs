//! Whole-series (non-causal) smoothing with centred fixed-memory windows: the counterpart of
//! `scipy.signal.savgol_filter(…, mode="interp")`, with derivatives.

use super::centred::{CentredSmoother, SmoothSigma};
use super::check_window;
use crate::error::{Error, Param};
use crate::polynomial::filter::{check_estimates_length, first_invalid};

/// Checks lengths, finiteness and strictly increasing times: the first sample that
/// [`crate::error::check_sample`] rejects is the error.
pub(crate) fn check_series(times: &[f64], values: &[f64]) -> Result<(), Error> {
    crate::error::check_lengths(
        Param::InputLengths,
        times,
        values,
        "times and values must have the same length",
    )?;
    let k = first_invalid(times, values, None);
    match times.get(k) {
        Some(&t) => crate::error::check_sample(t, values[k], k.checked_sub(1).map(|p| times[p])),
        None => Ok(()),
    }
}

/// The times `0, δ, 2δ, …` of `n` evenly spaced samples (`savgol_filter`'s `delta`), the step
/// `δ` positive and finite ([`Param::Step`]).
///
/// ```
/// use seqsmooth::polynomial::fixed::even_times;
/// assert_eq!(even_times(3, 0.5).unwrap(), [0.0, 0.5, 1.0]);
/// assert!(even_times(3, 0.0).is_err() && even_times(3, f64::NAN).is_err());
/// ```
pub fn even_times(n: usize, step: f64) -> Result<Vec<f64>, Error> {
    if !(step.is_finite() && step > 0.0) {
        return Err(Error::InvalidParameter {
            name: Param::Step,
            value: step.to_string(),
            reason: "must be a positive finite number".into(),
        });
    }
    Ok((0..n).map(|i| i as f64 * step).collect())
}

/// Smooths a whole series: at each sample, the least-squares polynomial of degree `m` through
/// the `window` samples most nearly centred on it, evaluated at that sample's time. Returns,
/// for every sample, the unscaled derivatives `[x, x', …, x^(m)]` in the caller's time units.
///
/// - **Evenly spaced** windows (their `W − 1` steps one run of equal steps: each within a
///   relative `1e-9` of the run's first, plus the timestamps' own rounding `2ε|t|`): the fit
///   `W(h) Y` with the centred weights `D(Δt) W(-L/2)` (Morrison (7.4.16) with `h = -L/2`; `Δt`
///   the window's mean step) at the sample `⌊L/2⌋` after the window's start, by the sliding
///   engine of [`super::FixedMemory`] (the window's discrete Legendre moments slid one sample
///   at a time, `O(m²)` per sample at any window; see the
///   [module docs](super#the-sliding-engine)); the first and last `⌊L/2⌋` (or `⌈L/2⌉`) samples
///   take the fit of the first (last) full window evaluated at their own times. For odd
///   `window` this is `scipy.signal.savgol_filter(y, window, m, deriv=k, delta=Δt,
///   mode="interp")` for each `k`. (For even `window` each sample sits half a step after the
///   window centre, `h = -(L+1)/2`; savgol evaluates at the half-sample centre instead.)
/// - **Irregular** windows: the same windows (by sample count), each fitted by Householder QR
///   in a centred Legendre basis ([`crate::estimate::PolynomialFit`]).
///
/// This is [`CentredSmoother`] run over the series (one engine: the rows are its rows, bit for
/// bit); [`smooth_with_sigma_into`] gives their 1σ too.
///
/// Errors: `window < m+1`, `window` longer than the series, `m > MAX_DEGREE`, NaN or
/// infinite input, non-increasing times, mismatched lengths; a derivative beyond the double
/// range ([`Error::EstimateOutOfRange`] in [`Error::InBatch`] naming the sample): no number
/// returned is NaN or infinite.
///
/// ```
/// use seqsmooth::polynomial::fixed::smooth;
/// let t: Vec<f64> = (0..9).map(|k| 0.5 * k as f64).collect();
/// let y = [2.0, 1.0, 3.0, 2.0, 4.0, 6.0, 5.0, 7.0, 6.0];
/// let s = smooth(&t, &y, 2, 5).unwrap();
/// // interior: savgol_coeffs(5, 2) = (-3, 12, 17, 12, -3)/35 (= Morrison T7-06 W(-2), row 0)
/// let want = (-3.0 * 1.0 + 12.0 * 3.0 + 17.0 * 2.0 + 12.0 * 4.0 - 3.0 * 6.0) / 35.0;
/// assert!((s[3][0] - want).abs() < 1e-14);
/// assert_eq!(s[0].len(), 3); // x, x', x'' at every sample
/// ```
pub fn smooth(
    times: &[f64],
    values: &[f64],
    m: usize,
    window: usize,
) -> Result<Vec<Vec<f64>>, Error> {
    check_window(m, window)?;
    let mut out = vec![0.0; times.len() * (m + 1)];
    smooth_into(times, values, m, window, &mut out)?;
    Ok(out.chunks_exact(m + 1).map(<[f64]>::to_vec).collect())
}

/// [`smooth`] into `estimates`, one row of `m+1` derivatives per sample (row-major, the
/// layout of [`crate::PolynomialFilter::update_many_into`] and of numpy's `(len, m+1)`
/// arrays), without allocating per sample.
///
/// Errors: those of [`smooth`], and `estimates.len() ≠ times.len()·(m+1)`. A derivative
/// beyond the double range is [`Error::EstimateOutOfRange`] inside [`Error::InBatch`] with the
/// first such sample's index (the estimates are written, that one and later ones unusable).
///
/// ```
/// use seqsmooth::polynomial::fixed::{smooth, smooth_into};
/// let t: Vec<f64> = (0..9).map(|k| 0.5 * k as f64).collect();
/// let y = [2.0, 1.0, 3.0, 2.0, 4.0, 6.0, 5.0, 7.0, 6.0];
/// let mut flat = vec![0.0; 9 * 3];
/// smooth_into(&t, &y, 2, 5, &mut flat).unwrap();
/// assert_eq!(flat.chunks(3).map(<[f64]>::to_vec).collect::<Vec<_>>(), smooth(&t, &y, 2, 5).unwrap());
/// assert!(smooth_into(&t, &y, 2, 5, &mut flat[..26]).is_err());
/// ```
pub fn smooth_into(
    times: &[f64],
    values: &[f64],
    m: usize,
    window: usize,
    estimates: &mut [f64],
) -> Result<(), Error> {
    check_window(m, window)?;
    check_series(times, values)?;
    let len = times.len();
    if window > len {
        return Err(Error::TooFewSamplesFor {
            param: Param::Window,
            needed: window,
            got: len,
        });
    }
    check_estimates_length(times, m, estimates)?;
    run_series(times, values, m, window, SmoothSigma::Off, estimates, None)?;
    first_out_of_range(estimates, "d", m)
}

/// [`smooth_into`] with the 1σ of every derivative into `std_devs` (the same layout): from
/// each window fit's covariance (Morrison §7.5: `σ²` times the variance-reduction factors of the
/// row's point in its window, (7.5.26)-(7.5.28), or of the QR fit for irregular windows), with
/// the noise σ `sigma` when given, else estimated from each window's residuals
/// ([`SmoothSigma::Estimated`]: `s² = Σ r²/(W − m − 1)`, Student-t coverage with
/// `W − m − 1` degrees of freedom).
///
/// Errors: those of [`smooth_into`]; `std_devs` of another length; a given σ not positive and
/// finite; an estimated σ with `window = m + 1`. A derivative or 1σ beyond the double range is
/// [`Error::EstimateOutOfRange`] in [`Error::InBatch`] with the first such sample's index.
///
/// ```
/// use seqsmooth::polynomial::fixed::{smooth_into, smooth_with_sigma_into};
/// let t: Vec<f64> = (0..9).map(|k| k as f64).collect();
/// let y = [2.0, 1.0, 3.0, 2.0, 4.0, 6.0, 5.0, 7.0, 6.0];
/// let (mut d, mut s) = (vec![0.0; 9 * 2], vec![0.0; 9 * 2]);
/// smooth_with_sigma_into(&t, &y, 1, 5, Some(0.5), &mut d, &mut s).unwrap();
/// // the centre of a 5-sample line fit: Var(x) = σ²/5
/// assert!((s[4 * 2] - 0.5 / 5f64.sqrt()).abs() < 1e-15);
/// let mut plain = vec![0.0; 9 * 2];
/// smooth_into(&t, &y, 1, 5, &mut plain).unwrap();
/// assert_eq!(plain, d);
/// smooth_with_sigma_into(&t, &y, 1, 5, None, &mut d, &mut s).unwrap(); // σ from the residuals
/// assert!(s.iter().all(|v| v.is_finite() && *v > 0.0));
/// ```
pub fn smooth_with_sigma_into(
    times: &[f64],
    values: &[f64],
    m: usize,
    window: usize,
    sigma: Option<f64>,
    estimates: &mut [f64],
    std_devs: &mut [f64],
) -> Result<(), Error> {
    check_window(m, window)?;
    check_series(times, values)?;
    if window > times.len() {
        return Err(Error::TooFewSamplesFor {
            param: Param::Window,
            needed: window,
            got: times.len(),
        });
    }
    check_estimates_length(times, m, estimates)?;
    check_estimates_length(times, m, std_devs)?;
    let sigma = sigma.map_or(SmoothSigma::Estimated, SmoothSigma::Given);
    run_series(
        times,
        values,
        m,
        window,
        sigma,
        estimates,
        Some(&mut *std_devs),
    )?;
    first_out_of_range(estimates, "d", m)?;
    first_out_of_range(std_devs, "s", m)
}

/// The first value of `rows` (rows of `m+1`) that is not finite, as the error naming its
/// sample and column (`{prefix}{k}`).
fn first_out_of_range(rows: &[f64], prefix: &str, m: usize) -> Result<(), Error> {
    match rows.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(Error::InBatch {
            index: i / (m + 1),
            source: Box::new(Error::EstimateOutOfRange {
                what: format!("{prefix}{}", i % (m + 1)),
            }),
        }),
    }
}

/// Runs the checked series through [`CentredSmoother`], each row into its place.
fn run_series(
    times: &[f64],
    values: &[f64],
    m: usize,
    window: usize,
    sigma: SmoothSigma,
    estimates: &mut [f64],
    mut std_devs: Option<&mut [f64]>,
) -> Result<(), Error> {
    let p = m + 1;
    let mut smoother = CentredSmoother::new(m, window, sigma)?;
    let mut put = |row: super::centred::SmoothedRow<'_>| -> Result<(), Error> {
        let at = row.index * p..(row.index + 1) * p;
        estimates[at.clone()].copy_from_slice(row.derivatives);
        if let (Some(out), Some(s)) = (std_devs.as_deref_mut(), row.std_devs) {
            out[at].copy_from_slice(s);
        }
        Ok(())
    };
    for (&t, &y) in times.iter().zip(values) {
        smoother.push(t, y, &mut put)?;
    }
    smoother.finish(&mut put)
}
