//! Whole-series (non-causal) smoothing with centred fixed-memory windows: the counterpart of
//! `scipy.signal.savgol_filter(…, mode="interp")`, with derivatives.

use super::weights::{inverse_norms, legendre_values, taylor_at, weights_unscaled};
use super::{check_window, steps_agree};
use crate::basis::DiscreteLegendre;
use crate::calculus::factorial;
use crate::error::Error;
use crate::estimate::PolynomialFit;

/// Checks lengths, finiteness and strictly increasing times.
pub(crate) fn check_series(times: &[f64], values: &[f64]) -> Result<(), Error> {
    if times.len() != values.len() {
        return Err(Error::InvalidParameter {
            name: "input lengths",
            value: format!("{} times, {} values", times.len(), values.len()),
            reason: "times and values must have the same length".into(),
        });
    }
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

/// Index of the first sample of the window used for sample `n`: the window of `window` samples
/// most nearly centred on `n` (`⌊L/2⌋` samples before it), clamped to the series.
fn window_start(n: usize, window: usize, len: usize) -> usize {
    let half = (window - 1) / 2;
    n.saturating_sub(half).min(len - window)
}

/// Smooths a whole series: at each sample, the least-squares polynomial of degree `m` through
/// the `window` samples most nearly centred on it, evaluated at that sample's time. Returns,
/// for every sample, the unscaled derivatives `[x, x', …, x^(m)]` in the caller's time units.
///
/// - **Evenly spaced** times (every step within a relative `1e-9` of the first, plus the
///   timestamps' own rounding, `2ε|t|`): interior
///   samples use the centred weights `D(Δt) W(-L/2)` (Morrison (7.4.16) with `h = -L/2`;
///   `Δt` the mean step) as a convolution; the first and last `⌊L/2⌋` (or `⌈L/2⌉`) samples
///   take the fit of the first (last) full window evaluated at their own times. For odd
///   `window` this is exactly `scipy.signal.savgol_filter(y, window, m, deriv=k, delta=Δt,
///   mode="interp")` for each `k`. (For even `window` each sample sits half a step after the
///   window centre, `h = -(L+1)/2`; savgol evaluates at the half-sample centre instead.)
/// - **Irregular** times: the same windows (by sample count), each fitted by Householder QR
///   in a centred Legendre basis ([`PolynomialFit`]).
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
        smooth_even(times, values, m, window)
    } else {
        smooth_irregular(times, values, m, window)
    }
}

fn smooth_even(
    times: &[f64],
    values: &[f64],
    m: usize,
    window: usize,
) -> Result<Vec<Vec<f64>>, Error> {
    let len = times.len();
    let span = window - 1;
    let step = if len >= 2 {
        (times[len - 1] - times[0]) / (len - 1) as f64
    } else {
        1.0
    };
    let half = span / 2;
    // Interior samples n with start n - half: r = half, h = half - L.
    let w = weights_unscaled(m, span as u64, half as f64 - span as f64, step)?;
    let mut out = vec![Vec::new(); len];
    let basis = DiscreteLegendre::new(span as f64);
    let inv = inverse_norms(m, &basis);
    let scale: Vec<f64> = (0..=m)
        .map(|i| factorial::<f64>(i) / step.powi(i as i32))
        .collect();
    // Legendre coefficients β of the window starting at s (x = 0 oldest).
    let beta = |s: usize| -> Vec<f64> {
        let mut mu = vec![0.0; m + 1];
        for x in 0..window {
            let p = legendre_values(m, &basis, &(x as f64));
            for j in 0..=m {
                mu[j] += values[s + x] * p[j];
            }
        }
        mu.iter().zip(&inv).map(|(a, b)| a * b).collect()
    };
    // Row i of the weights in window order (oldest sample first), contiguous: column k of `w`
    // multiplies y_{newest - k}.
    let kernels: Vec<Vec<f64>> = (0..=m)
        .map(|i| (0..window).rev().map(|k| w[(i, k)]).collect())
        .collect();
    let mut edge_fits: Vec<(usize, Vec<f64>)> = Vec::new();
    for (n, row) in out.iter_mut().enumerate() {
        let s = window_start(n, window, len);
        if n - s == half {
            let ys = &values[s..s + window];
            *row = kernels.iter().map(|k| dot(k, ys)).collect();
        } else {
            let b = match edge_fits.iter().find(|(st, _)| *st == s) {
                Some((_, b)) => b.clone(),
                None => {
                    let b = beta(s);
                    edge_fits.push((s, b.clone()));
                    b
                }
            };
            let t = taylor_at(m, &basis, &((n - s) as f64));
            *row = (0..=m)
                .map(|i| (0..=m).map(|j| t[(i, j)] * b[j]).sum::<f64>() * scale[i])
                .collect();
        }
    }
    Ok(out)
}

/// `Σ a_i b_i` with four partial sums (so the loop vectorises).
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let tail: f64 = ca
        .remainder()
        .iter()
        .zip(cb.remainder())
        .map(|(x, y)| x * y)
        .sum();
    for (x, y) in ca.zip(cb) {
        for l in 0..4 {
            acc[l] += x[l] * y[l];
        }
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

fn smooth_irregular(
    times: &[f64],
    values: &[f64],
    m: usize,
    window: usize,
) -> Result<Vec<Vec<f64>>, Error> {
    let len = times.len();
    let mut out = Vec::with_capacity(len);
    let mut cached: Option<(usize, PolynomialFit)> = None;
    for n in 0..len {
        let s = window_start(n, window, len);
        if cached.as_ref().map(|(st, _)| *st) != Some(s) {
            let fit = PolynomialFit::new(&times[s..s + window], &values[s..s + window], None, m)?;
            cached = Some((s, fit));
        }
        let fit = &cached.as_ref().expect("fitted above").1;
        out.push(fit.derivatives_at(times[n]));
    }
    Ok(out)
}
