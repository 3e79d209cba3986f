//! Whole-series (non-causal) smoothing with centred fixed-memory windows: the counterpart of
//! `scipy.signal.savgol_filter(…, mode="interp")`, with derivatives.

use super::even::MomentFit;
use super::irregular::IrregularWindow;
use super::sliding::{smoothing_refreshes, SlidingMoments};
use super::{check_window, steps_agree};
use crate::error::Error;
use std::ops::Range;

/// Checks lengths, finiteness and strictly increasing times.
pub(crate) fn check_series(times: &[f64], values: &[f64]) -> Result<(), Error> {
    crate::error::check_lengths(
        "input lengths",
        times,
        values,
        "times and values must have the same length",
    )?;
    for (k, (&t, &y)) in times.iter().zip(values).enumerate() {
        crate::error::check_sample(t, y, k.checked_sub(1).map(|p| times[p]))?;
    }
    Ok(())
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
    /// The derivatives at sample `row` of the fit of the full window starting at `start` (the
    /// newest window pushed).
    fn row(&self, row: usize, start: usize) -> Vec<f64>;
}

/// Every sample's row, in order, from the fits of the series' `len - window + 1` windows.
fn centred_rows(
    len: usize,
    window: usize,
    mut fits: impl SeriesWindows,
) -> Result<Vec<Vec<f64>>, Error> {
    let mut out = Vec::with_capacity(len);
    for n in 0..len {
        fits.push(n)?;
        if let Some(start) = (n + 1).checked_sub(window) {
            for row in rows_served(start, window, len) {
                out.push(fits.row(row, start));
            }
        }
    }
    Ok(out)
}

/// Evenly spaced samples: the sliding moments of each window, evaluated through `T(r)`.
struct EvenSeries<'a> {
    values: &'a [f64],
    window: usize,
    moments: SlidingMoments,
    fit: MomentFit,
    step: f64,
}

impl SeriesWindows for EvenSeries<'_> {
    fn push(&mut self, n: usize) -> Result<(), Error> {
        let old = n.checked_sub(self.window).map(|k| self.values[k]);
        self.moments.push(n as u64, self.values[n], old);
        Ok(())
    }

    fn row(&self, row: usize, start: usize) -> Vec<f64> {
        let mu = self.moments.moments().expect("the window is full");
        self.fit.derivatives(mu, (row - start) as f64, self.step)
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

    fn row(&self, row: usize, _start: usize) -> Vec<f64> {
        let fit = self.fits.fit().expect("the window is full");
        fit.derivatives_at(self.times[row])
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
/// infinite input, non-increasing times, mismatched lengths.
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
    check_series(times, values)?;
    let len = times.len();
    if window > len {
        return Err(Error::TooFewSamples {
            needed: window,
            got: len,
        });
    }
    if is_evenly_spaced(times) {
        let span = window - 1;
        let step = if len >= 2 {
            (times[len - 1] - times[0]) / (len - 1) as f64
        } else {
            1.0
        };
        let even = EvenSeries {
            values,
            window,
            moments: SlidingMoments::new(m, window, smoothing_refreshes(m), true),
            fit: MomentFit::new(m, span, span / 2),
            step,
        };
        centred_rows(len, window, even)
    } else {
        let irregular = IrregularSeries {
            times,
            values,
            fits: IrregularWindow::new(m, window),
        };
        centred_rows(len, window, irregular)
    }
}
