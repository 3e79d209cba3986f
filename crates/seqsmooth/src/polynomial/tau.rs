//! The default time interval `τ` of a fading memory given by its discount `θ` per `τ`
//! (Morrison's discounted least squares (13.2.1), weights `θ^r` on an even grid; on irregular
//! times `θ^((t_n − t_k)/τ)`, Reyneke et al. §6.5): the typical time
//! step of the data, so that `θ` is the discount per typical sample, as on an even grid.
//!
//! The rule, the same in every front end (`seqsmooth filter` without `--tau`, Python's
//! `filter_frame` without `tau`): the median of the first [`TAU_STEPS`] time steps within
//! series, in row order (each row's time minus the previous time of its series), among the
//! first [`TAU_SCAN_ROWS`] rows; the mean of the middle two for an even count. A series of one
//! row has no step; when no series has two rows among all the rows there are, `τ` does not
//! matter and is 1; when the rows scanned are not all of them, there is no default and the
//! caller must give `τ`.

use crate::error::{Error, Param};
use std::collections::HashMap;

/// Time steps the default `τ` is the median of.
pub const TAU_STEPS: usize = 100;

/// Rows scanned for the steps of [`TAU_STEPS`] (with many interleaved series, the first rows
/// of each).
pub const TAU_SCAN_ROWS: usize = 1 << 16;

/// The median of `values` (the mean of the middle two for an even count); `None` for none.
///
/// ```
/// use seqsmooth::polynomial::tau::median;
/// assert_eq!(median(vec![3.0, 1.0, 2.0]), Some(2.0));
/// assert_eq!(median(vec![4.0, 1.0, 2.0, 3.0]), Some(2.5));
/// assert_eq!(median(vec![]), None);
/// ```
pub fn median(mut values: Vec<f64>) -> Option<f64> {
    values.sort_by(f64::total_cmp);
    let k = values.len();
    match k {
        0 => None,
        _ if k % 2 == 1 => Some(values[k / 2]),
        _ => Some(0.5 * values[k / 2 - 1] + 0.5 * values[k / 2]),
    }
}

/// The median of the first [`TAU_STEPS`] time steps within the series of `times` (row `i` in
/// series `series[i]`), in row order; `None` when no series has two rows.
///
/// ```
/// use seqsmooth::polynomial::tau::median_series_step;
/// // Two interleaved series: steps 2, 2 (series 0) and 5 (series 1).
/// let step = median_series_step(&[0.0, 10.0, 2.0, 15.0, 4.0], &[0, 1, 0, 1, 0]);
/// assert_eq!(step, Some(2.0));
/// assert_eq!(median_series_step(&[0.0, 1.0], &[0, 1]), None);
/// ```
pub fn median_series_step(times: &[f64], series: &[usize]) -> Option<f64> {
    let mut last: HashMap<usize, f64> = HashMap::new();
    let mut steps = Vec::with_capacity(TAU_STEPS);
    for (&t, &s) in times.iter().zip(series) {
        if let Some(prev) = last.insert(s, t) {
            steps.push(t - prev);
            if steps.len() == TAU_STEPS {
                break;
            }
        }
    }
    median(steps)
}

/// The default `τ` of the rows `times` (row `i` in series `series[i]`): the median step of
/// [`median_series_step`] over the first [`TAU_SCAN_ROWS`] rows; 1 when no series has two rows
/// and `complete` says these are all the rows. An error when there is no step among the rows
/// scanned of an input that goes on, or when the median is not a positive finite number
/// (repeated times): [`Error::NoDefault`] of [`Param::Tau`], the data's fault.
///
/// ```
/// use seqsmooth::polynomial::tau::default_tau;
/// assert_eq!(default_tau(&[0.0, 0.5, 1.5, 2.0], &[0; 4], true).unwrap(), 0.5);
/// assert_eq!(default_tau(&[3.0], &[0], true).unwrap(), 1.0);
/// assert!(default_tau(&[3.0], &[0], false).is_err());
/// assert!(default_tau(&[1.0, 1.0, 1.0], &[0; 3], true).is_err());
/// ```
pub fn default_tau(times: &[f64], series: &[usize], complete: bool) -> Result<f64, Error> {
    let rows = times.len().min(series.len());
    let head = rows.min(TAU_SCAN_ROWS);
    let tau = match median_series_step(&times[..head], &series[..head]) {
        Some(tau) => tau,
        None if complete && rows <= head => return Ok(1.0),
        None => {
            return Err(Error::NoDefault {
                param: Param::Tau,
                why: format!(
                    "no series has two rows among the first {head} rows, so there is no median \
                     time step"
                ),
            })
        }
    };
    if !(tau.is_finite() && tau > 0.0) {
        return Err(Error::NoDefault {
            param: Param::Tau,
            why: format!(
                "the median time step of the first rows, {tau}, is not a positive finite interval"
            ),
        });
    }
    Ok(tau)
}
