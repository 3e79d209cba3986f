//! Trend removal (Morrison §7.14): filter the differences from a nominal trajectory, add the
//! nominal back.

use super::smooth::{check_series, smooth};
use crate::error::{Error, Param};
use crate::model::PolynomialState;
use crate::polynomial::filter::PolynomialFilter;

/// A nominal trajectory for [`smooth_detrended`]: the nominal value and derivatives
/// `[x̄, x̄', …]` (caller's time units) at each sample. Rows shorter than `m+1` mean the
/// missing derivatives of the nominal are zero, which is right only if they are.
///
/// ```
/// use seqsmooth::polynomial::fixed::{smooth_detrended, Nominal};
/// let t = [0.0, 1.0, 2.0, 3.0, 4.0];
/// let y = [1.0, 2.0, 5.0, 10.0, 17.0]; // 1 + t²
/// let rows: Vec<Vec<f64>> = t.iter().map(|t| vec![t * t, 2.0 * t]).collect(); // t², 2t
/// let a = smooth_detrended(&t, &y, 1, 3, Nominal::Samples(&rows)).unwrap();
/// let f = |t: f64| vec![t * t, 2.0 * t];
/// let b = smooth_detrended(&t, &y, 1, 3, Nominal::Function(&f)).unwrap();
/// assert_eq!(a, b);
/// assert!((a[2][0] - 5.0).abs() < 1e-12 && (a[2][1] - 4.0).abs() < 1e-12);
/// ```
#[derive(Clone, Copy)]
pub enum Nominal<'a> {
    /// A function of time.
    Function(&'a dyn Fn(f64) -> Vec<f64>),
    /// One row per sample, in the order of the samples.
    Samples(&'a [Vec<f64>]),
}

impl std::fmt::Debug for Nominal<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Nominal::Function(_) => f.write_str("Nominal::Function(..)"),
            Nominal::Samples(s) => write!(f, "Nominal::Samples({} rows)", s.len()),
        }
    }
}

impl Nominal<'_> {
    fn at(&self, k: usize, t: f64) -> Vec<f64> {
        match self {
            Nominal::Function(f) => f(t),
            Nominal::Samples(s) => s[k].clone(),
        }
    }
}

fn check_nominal_row(row: &[f64]) -> Result<(), Error> {
    if row.is_empty() {
        return Err(Error::InvalidParameter {
            name: Param::Nominal,
            value: "[]".into(),
            reason: "each nominal row needs at least the value".into(),
        });
    }
    crate::error::check_finite("value", row)?;
    Ok(())
}

/// [`smooth`] with trend removal (Morrison (7.14.5)-(7.14.8)): smooths the differences
/// `δy_k = y_k − x̄(t_k)` from the nominal trajectory and adds the nominal value and derivatives
/// back, `x*^(i) = δx*^(i) + x̄^(i)`. The bias then depends on how far the truth is from the
/// nominal rather than on the truth itself ((7.14.12)-(7.14.13): for `m = 1` the bias
/// `∝ |α₂ − ᾱ₂|` instead of `|α₂|`), which allows a lower degree and a longer window.
///
/// ```
/// use seqsmooth::polynomial::fixed::{smooth_detrended, Nominal};
/// let t: Vec<f64> = (0..50).map(|k| 0.1 * k as f64).collect();
/// // truth = nominal + a line: the differences are a polynomial of degree ≤ m, no bias left
/// let y: Vec<f64> = t.iter().map(|t| t.sin() + 0.3 - 0.2 * t).collect();
/// let nominal = |t: f64| vec![t.sin(), t.cos()];
/// let s = smooth_detrended(&t, &y, 1, 21, Nominal::Function(&nominal)).unwrap();
/// assert!((s[25][0] - y[25]).abs() < 1e-12);
/// assert!((s[49][1] - (4.9_f64.cos() - 0.2)).abs() < 1e-11);
/// // without the nominal, the sine's curvature biases the straight-line fit
/// let plain = seqsmooth::polynomial::fixed::smooth(&t, &y, 1, 21).unwrap();
/// assert!((plain[25][0] - y[25]).abs() > 1e-2);
/// ```
pub fn smooth_detrended(
    times: &[f64],
    values: &[f64],
    m: usize,
    window: usize,
    nominal: Nominal<'_>,
) -> Result<Vec<Vec<f64>>, Error> {
    check_series(times, values)?;
    if let Nominal::Samples(s) = nominal {
        if s.len() != times.len() {
            return Err(Error::InvalidParameter {
                name: Param::Nominal,
                value: format!("{} rows", s.len()),
                reason: format!("one row per sample is needed ({} samples)", times.len()),
            });
        }
    }
    let rows: Vec<Vec<f64>> = times
        .iter()
        .enumerate()
        .map(|(k, &t)| nominal.at(k, t))
        .collect();
    for r in &rows {
        check_nominal_row(r)?;
    }
    let diffs: Vec<f64> = values.iter().zip(&rows).map(|(y, r)| y - r[0]).collect();
    let mut out = smooth(times, &diffs, m, window)?;
    for (o, r) in out.iter_mut().zip(&rows) {
        for (v, nv) in o.iter_mut().zip(r.iter()) {
            *v += nv;
        }
    }
    Ok(out)
}

/// Any [`PolynomialFilter`] run on the differences from a nominal trajectory, with the nominal
/// added back to every estimate (Morrison §7.14, (7.14.5)-(7.14.8)). `nominal(t)` returns the
/// nominal value and derivatives `[x̄, x̄', …]` at `t` (missing derivatives count as zero). The
/// covariance is the inner filter's (the nominal is deterministic).
///
/// ```
/// use seqsmooth::polynomial::fixed::{Detrended, FixedEngine, FixedMemory};
/// use seqsmooth::PolynomialFilter;
/// let inner = FixedMemory::new(1, 21, FixedEngine::Sliding).unwrap();
/// let mut f = Detrended::new(inner, |t: f64| vec![t.sin(), t.cos()]);
/// for k in 0..40 {
///     let t = 0.1 * k as f64;
///     f.update(t, t.sin() + 0.5 * t).unwrap(); // nominal + a line: no bias left
/// }
/// let s = f.estimate().unwrap();
/// assert!((s.derivatives[1] - (3.9_f64.cos() + 0.5)).abs() < 1e-9);
/// ```
pub struct Detrended<F, N> {
    filter: F,
    nominal: N,
}

impl<F: std::fmt::Debug, N> std::fmt::Debug for Detrended<F, N> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Detrended")
            .field("filter", &self.filter)
            .finish_non_exhaustive()
    }
}

impl<F: PolynomialFilter, N: Fn(f64) -> Vec<f64> + Send> Detrended<F, N> {
    /// Wraps `filter` with the nominal trajectory `nominal`.
    ///
    /// ```
    /// use seqsmooth::polynomial::fixed::Detrended;
    /// use seqsmooth::{Engine, ExpandingMemory, PolynomialFilter};
    /// // any PolynomialFilter can be wrapped, e.g. an expanding-memory filter
    /// let mut f = Detrended::new(ExpandingMemory::new(1, Engine::Exact).unwrap(), |t: f64| vec![t * t, 2.0 * t]);
    /// for k in 0..5 {
    ///     let t = k as f64;
    ///     f.update(t, t * t + 1.0).unwrap();
    /// }
    /// let s = f.estimate().unwrap();
    /// assert!((s.derivatives[0] - 17.0).abs() < 1e-12 && (s.derivatives[1] - 8.0).abs() < 1e-12);
    /// ```
    pub fn new(filter: F, nominal: N) -> Self {
        Self { filter, nominal }
    }

    /// The inner filter (it sees the differences from the nominal).
    ///
    /// ```
    /// use seqsmooth::polynomial::fixed::{Detrended, FixedEngine, FixedMemory};
    /// use seqsmooth::PolynomialFilter;
    /// let mut f = Detrended::new(FixedMemory::new(0, 2, FixedEngine::Direct).unwrap(), |t: f64| vec![t]);
    /// f.update(1.0, 1.5).unwrap();
    /// f.update(2.0, 2.5).unwrap();
    /// assert_eq!(f.inner().estimate().unwrap().derivatives, vec![0.5]); // mean of y - t
    /// assert_eq!(f.estimate().unwrap().derivatives, vec![2.5]);
    /// ```
    pub fn inner(&self) -> &F {
        &self.filter
    }
}

impl<F: PolynomialFilter, N: Fn(f64) -> Vec<f64> + Send> PolynomialFilter for Detrended<F, N> {
    fn degree(&self) -> usize {
        self.filter.degree()
    }

    fn samples(&self) -> u64 {
        self.filter.samples()
    }

    fn update(&mut self, t: f64, y: f64) -> Result<(), Error> {
        if !t.is_finite() {
            return Err(Error::NonFinite {
                what: "time",
                value: t,
            });
        }
        let row = (self.nominal)(t);
        check_nominal_row(&row)?;
        self.filter.update(t, y - row[0])
    }

    fn estimate_at(&self, t: f64) -> Option<PolynomialState> {
        self.try_estimate_at(t).ok()
    }

    fn try_estimate_at(&self, t: f64) -> Result<PolynomialState, Error> {
        let mut s = self.filter.try_estimate_at(t)?;
        let row = (self.nominal)(t);
        for (v, nv) in s.derivatives.iter_mut().zip(row.iter()) {
            *v += nv;
        }
        s.checked()
    }

    fn last_time(&self) -> Option<f64> {
        self.filter.last_time()
    }

    fn is_determined(&self) -> bool {
        self.filter.is_determined()
    }
}
