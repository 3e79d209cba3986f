//! Whole-series (non-causal) smoothing with centred fixed-memory windows: the counterpart of
//! `scipy.signal.savgol_filter(…, mode="interp")`, with derivatives.

use super::even::{apply_upper, MomentFit};
use super::irregular::IrregularWindow;
use super::sliding::{smoothing_refreshes, SlidingMoments};
use super::{check_window, steps_agree};
use crate::error::Error;
use crate::polynomial::filter::{check_estimates_length, first_invalid};
use std::ops::Range;

/// Checks lengths, finiteness and strictly increasing times: the first sample that
/// [`crate::error::check_sample`] rejects is the error.
pub(crate) fn check_series(times: &[f64], values: &[f64]) -> Result<(), Error> {
    crate::error::check_lengths(
        "input lengths",
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

/// True when every step equals the first (the rule of [`steps_agree`]).
pub(crate) fn is_evenly_spaced(times: &[f64]) -> bool {
    if times.len() < 3 {
        return true;
    }
    let first = times[1] - times[0];
    let t_scale = times[0].abs().max(times[times.len() - 1].abs());
    times
        .windows(2)
        .all(|w| steps_agree(w[1] - w[0], first, t_scale))
}

/// The samples the full window starting at `start` serves (savgol's "interp" mode): the one
/// `⌊L/2⌋` after its start and, for the first (last) window, every sample before (after) it.
fn rows_served(start: usize, window: usize, len: usize) -> Range<usize> {
    let centre = start + (window - 1) / 2;
    let first = if start == 0 { 0 } else { centre };
    let end = if start + window == len {
        len
    } else {
        centre + 1
    };
    first..end
}

/// The window fits of a series, taken window by window.
trait SeriesWindows {
    /// Takes sample `n` of the series (the samples arrive in order).
    fn push(&mut self, n: usize) -> Result<(), Error>;
    /// Writes the derivatives at sample `row` of the fit of the full window starting at `start`
    /// (the newest window pushed).
    fn row(&self, row: usize, start: usize, out: &mut [f64]);
}

/// Every sample's row, in order, from the fits of the series' `len - window + 1` windows, into
/// `out` (`len` rows of `p` values).
fn centred_rows(
    len: usize,
    window: usize,
    mut fits: impl SeriesWindows,
    out: &mut [f64],
) -> Result<(), Error> {
    let p = out.len() / len;
    for n in 0..len {
        fits.push(n)?;
        if let Some(start) = (n + 1).checked_sub(window) {
            for row in rows_served(start, window, len) {
                fits.row(row, start, &mut out[row * p..(row + 1) * p]);
            }
        }
    }
    Ok(())
}

/// Evenly spaced samples: the sliding moments of each window, evaluated through `D(τ) T(r) C`
/// (kept for the centre row, computed for the edge rows).
struct EvenSeries<'a> {
    values: &'a [f64],
    window: usize,
    moments: SlidingMoments,
    fit: MomentFit,
    step: f64,
    centre: Vec<f64>,
}

impl SeriesWindows for EvenSeries<'_> {
    fn push(&mut self, n: usize) -> Result<(), Error> {
        let old = n.checked_sub(self.window).map(|k| self.values[k]);
        self.moments.push(n as u64, self.values[n], old);
        Ok(())
    }

    fn row(&self, row: usize, start: usize, out: &mut [f64]) {
        let mu = self.moments.moments().expect("the window is full");
        let r = row - start;
        if r == (self.window - 1) / 2 {
            apply_upper(&self.centre, mu, out);
        } else {
            apply_upper(&self.fit.evaluator(r as f64, self.step), mu, out);
        }
    }
}

/// Irregular samples: each window's QR fit, evaluated at the sample's time.
struct IrregularSeries<'a> {
    times: &'a [f64],
    values: &'a [f64],
    fits: IrregularWindow,
}

impl SeriesWindows for IrregularSeries<'_> {
    fn push(&mut self, n: usize) -> Result<(), Error> {
        self.fits.update(self.times[n], self.values[n])
    }

    fn row(&self, row: usize, _start: usize, out: &mut [f64]) {
        let fit = self.fits.fit().expect("the window is full");
        out.copy_from_slice(&fit.derivatives_at(self.times[row]));
    }
}

/// Smooths a whole series: at each sample, the least-squares polynomial of degree `m` through
/// the `window` samples most nearly centred on it, evaluated at that sample's time. Returns,
/// for every sample, the unscaled derivatives `[x, x', …, x^(m)]` in the caller's time units.
///
/// - **Evenly spaced** times (every step within a relative `1e-9` of the first, plus the
///   timestamps' own rounding, `2ε|t|`): the fit of each window `W(h) Y` with the centred
///   weights `D(Δt) W(-L/2)` (Morrison (7.4.16) with `h = -L/2`; `Δt` the mean step) at the
///   sample `⌊L/2⌋` after the window's start, by the sliding engine of [`super::FixedMemory`]
///   (the window's discrete Legendre moments slid one sample at a time, `O(m²)` per sample at
///   any window; see the [module docs](super#the-sliding-engine)); the first and last `⌊L/2⌋`
///   (or `⌈L/2⌉`) samples take the fit of the first (last) full window evaluated at their own
///   times. For odd `window` this is `scipy.signal.savgol_filter(y, window, m, deriv=k,
///   delta=Δt, mode="interp")` for each `k`. (For even `window` each sample sits half a step
///   after the window centre, `h = -(L+1)/2`; savgol evaluates at the half-sample centre
///   instead.)
/// - **Irregular** times: the same windows (by sample count), each fitted by Householder QR
///   in a centred Legendre basis ([`crate::estimate::PolynomialFit`]).
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
        return Err(Error::TooFewSamples {
            needed: window,
            got: len,
        });
    }
    check_estimates_length(times, m, estimates)?;
    let fitted = if is_evenly_spaced(times) {
        let span = window - 1;
        let step = if len >= 2 {
            (times[len - 1] - times[0]) / (len - 1) as f64
        } else {
            1.0
        };
        let fit = MomentFit::new(m, span, span / 2);
        let even = EvenSeries {
            values,
            window,
            moments: SlidingMoments::new(m, window, smoothing_refreshes(m), true),
            centre: fit.evaluator((span / 2) as f64, step),
            fit,
            step,
        };
        centred_rows(len, window, even, estimates)
    } else {
        let irregular = IrregularSeries {
            times,
            values,
            fits: IrregularWindow::new(m, window),
        };
        centred_rows(len, window, irregular, estimates)
    };
    fitted?;
    match estimates.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(Error::InBatch {
            index: i / (m + 1),
            source: Box::new(Error::EstimateOutOfRange {
                what: format!("d{}", i % (m + 1)),
            }),
        }),
    }
}
