//! The one engine of whole-series smoothing, in streaming form: [`CentredSmoother`] takes the
//! samples one at a time and gives each sample's row as soon as its window is complete, in
//! memory bounded by the window; [`super::smooth`] and its relatives run it over a whole
//! series (so the batch and streaming numbers are the same, bit for bit).

use super::even::MomentFit;
use super::ring::Ring;
use super::sliding::{smoothing_refreshes, SlidingMoments};
use super::weights::{inverse_norms, legendre_values};
use super::{check_window, steps_agree};
use crate::basis::DiscreteLegendre;
use crate::error::{Error, Param};
use crate::estimate::PolynomialFit;
use crate::numeric::sigma::std_dev;

/// Where the 1σ of each smoothed row comes from (Morrison §7.5: the covariance of a window's
/// fit is `σ²` times its variance-reduction factors, `D(τ) T(r) C T(r)ᵀ D(τ)` on evenly spaced
/// samples (7.5.26)-(7.5.28), `J (RᵀR)⁻¹ Jᵀ` of the QR fit otherwise).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SmoothSigma {
    /// No 1σ.
    Off,
    /// The samples' noise σ, known (the same for every sample).
    Given(f64),
    /// σ estimated from each window's own fit: `s² = Σ r²/(W − m − 1)` over its `W` residuals
    /// (the unbiased estimate; Morrison §7.13's misfit raises it where the polynomial cannot
    /// follow the data). With Gaussian noise `(x̂ − x)/σ̂` is Student-t with `W − m − 1` degrees
    /// of freedom, so `kσ̂` covers the truth with probability `P(|t_{W−m−1}| ≤ k)` (99.2 % at
    /// `k = 3`, `W − m − 1 = 18`; ≥ 97 % from 6 degrees of freedom on). Needs `W > m + 1`.
    Estimated,
}

/// One smoothed sample: its index in the series, time, derivatives `[x, x', …, x^(m)]` and,
/// unless σ is [`SmoothSigma::Off`], their 1σ. A value beyond the double range is infinite
/// here (the callers refuse it with the row's index).
#[derive(Clone, Copy, Debug)]
pub struct SmoothedRow<'a> {
    /// 0-based index of the sample.
    pub index: usize,
    /// Its time.
    pub time: f64,
    /// The unscaled derivatives at `time`.
    pub derivatives: &'a [f64],
    /// Their 1σ.
    pub std_devs: Option<&'a [f64]>,
}

/// The fit of the newest full window.
#[derive(Clone, Debug)]
enum WindowFit {
    /// Evenly spaced: the sliding moments, evaluated on the window's mean step.
    Even { step: f64 },
    /// Irregular: the QR fit of the window's samples.
    Irregular(PolynomialFit),
}

/// Whole-series (centred) smoothing as a stream: at each sample, the least-squares polynomial
/// of degree `m` through the `window` samples most nearly centred on it, evaluated at its time
/// (Morrison (7.4.16) with `h = -L/2`; `scipy.signal.savgol_filter(mode="interp")` for odd
/// windows on evenly spaced samples), with its 1σ ([`SmoothSigma`]).
///
/// Row `n` is given once sample `n + ⌊(W−1)/2⌋` has arrived; the first window gives rows
/// `0..=⌊(W−1)/2⌋` together, and [`Self::finish`] gives the last window's remaining rows. Memory:
/// the window's samples and `O(m²)` numbers, whatever the length of the series.
///
/// A window is fitted by the sliding moments ([module docs](super#the-sliding-engine)) when its
/// `W − 1` steps all belong to one run of equal steps (each equal to the run's first step within
/// a relative `1e-9` plus the timestamps' rounding `2ε|t|`), evaluated on the window's mean step;
/// any other window by Householder QR at its actual times ([`PolynomialFit`]).
///
/// ```
/// use seqsmooth::polynomial::fixed::{smooth, CentredSmoother, SmoothSigma};
/// let t: Vec<f64> = (0..9).map(|k| 0.5 * k as f64).collect();
/// let y = [2.0, 1.0, 3.0, 2.0, 4.0, 6.0, 5.0, 7.0, 6.0];
/// let mut s = CentredSmoother::new(2, 5, SmoothSigma::Off).unwrap();
/// let mut rows = Vec::new();
/// for (&t, &y) in t.iter().zip(&y) {
///     s.push(t, y, |r| { rows.push(r.derivatives.to_vec()); Ok::<(), seqsmooth::Error>(()) }).unwrap();
/// }
/// s.finish(|r| { rows.push(r.derivatives.to_vec()); Ok::<(), seqsmooth::Error>(()) }).unwrap();
/// assert_eq!(rows, smooth(&t, &y, 2, 5).unwrap()); // the same engine, bit for bit
/// ```
#[derive(Clone, Debug)]
pub struct CentredSmoother {
    m: usize,
    window: usize,
    sigma: SmoothSigma,
    samples: Ring<(f64, f64)>,
    moments: SlidingMoments,
    fit: MomentFit,
    /// `1/c_j²` and `p_j(x)` for `x = 0..L` (row `x`), for the residuals of an estimated σ
    /// (empty otherwise).
    inv_norm: Vec<f64>,
    table: Vec<f64>,
    /// Samples taken.
    n: usize,
    /// Consecutive equal steps ending at the newest sample, and the first of them.
    run: usize,
    run_step: f64,
    last: Option<f64>,
    current: Option<WindowFit>,
    /// σ of the current window.
    window_sigma: f64,
    /// The row being given: derivatives, then 1σ.
    row: Vec<f64>,
    scratch_t: Vec<f64>,
    scratch_y: Vec<f64>,
}

impl CentredSmoother {
    /// Degree `m` over windows of `window` samples.
    ///
    /// Errors: `window < m+1`, `m > MAX_DEGREE`, a given σ not positive and finite, an
    /// estimated σ with `window = m + 1` (no residuals to estimate it from).
    pub fn new(m: usize, window: usize, sigma: SmoothSigma) -> Result<Self, Error> {
        check_window(m, window)?;
        match sigma {
            SmoothSigma::Given(s) if !(s.is_finite() && s > 0.0) => {
                return Err(Error::InvalidParameter {
                    name: Param::Sigma,
                    value: s.to_string(),
                    reason: "the noise sigma must be positive and finite".into(),
                })
            }
            SmoothSigma::Estimated if window <= m + 1 => {
                return Err(Error::InvalidParameter {
                    name: Param::Window,
                    value: window.to_string(),
                    reason: format!(
                        "a window of {window} samples has no residuals about its degree-{m} fit \
                         to estimate the noise sigma from: take a window of at least {} samples \
                         or give the noise sigma",
                        m + 2
                    ),
                })
            }
            _ => {}
        }
        let span = window - 1;
        let (inv_norm, table) = if sigma == SmoothSigma::Estimated {
            let basis = DiscreteLegendre::new(span as f64);
            let table = (0..window)
                .flat_map(|x| legendre_values(m, &basis, &(x as f64)))
                .collect();
            (inverse_norms(m, &basis), table)
        } else {
            (Vec::new(), Vec::new())
        };
        Ok(Self {
            m,
            window,
            sigma,
            samples: Ring::new(window),
            moments: SlidingMoments::new(m, window, smoothing_refreshes(m), true),
            fit: MomentFit::new(m, span, span / 2),
            inv_norm,
            table,
            n: 0,
            run: 0,
            run_step: 0.0,
            last: None,
            current: None,
            window_sigma: f64::NAN,
            row: vec![0.0; 2 * (m + 1)],
            scratch_t: Vec::new(),
            scratch_y: Vec::new(),
        })
    }

    /// The degree `m`.
    pub fn degree(&self) -> usize {
        self.m
    }

    /// Samples taken so far.
    pub fn samples(&self) -> usize {
        self.n
    }

    /// Takes the sample `(t, y)` and gives `emit` the rows it completes (none until the first
    /// window is full, then `⌊(W+1)/2⌋` rows, then one per sample), in order.
    ///
    /// Errors: a NaN or infinite sample or a time not after the previous one (nothing is
    /// taken), a window whose QR fit fails, and `emit`'s own.
    pub fn push<E: From<Error>>(
        &mut self,
        t: f64,
        y: f64,
        mut emit: impl FnMut(SmoothedRow<'_>) -> Result<(), E>,
    ) -> Result<(), E> {
        crate::error::check_sample(t, y, self.last)?;
        if let Some(prev) = self.last {
            let step = t - prev;
            if self.run > 0 && steps_agree(step, self.run_step, prev.abs().max(t.abs())) {
                self.run += 1;
            } else {
                (self.run, self.run_step) = (1, step);
            }
        }
        self.last = Some(t);
        let old = self.samples.push((t, y)).map(|(_, y)| y);
        self.moments.push(self.n as u64, y, old);
        self.n += 1;
        if !self.samples.is_full() {
            return Ok(());
        }
        self.fit_window()?;
        let start = self.n - self.window;
        let centre = (self.window - 1) / 2;
        let first = if start == 0 { 0 } else { centre };
        for r in first..=centre {
            self.give(start, r, &mut emit)?;
        }
        Ok(())
    }

    /// Gives `emit` the rows after the last window's centre: the end of the series.
    ///
    /// Errors: fewer samples than the window ([`Error::TooFewSamplesFor`] the window), and `emit`'s own.
    pub fn finish<E: From<Error>>(
        mut self,
        mut emit: impl FnMut(SmoothedRow<'_>) -> Result<(), E>,
    ) -> Result<(), E> {
        if self.n < self.window {
            return Err(Error::TooFewSamplesFor {
                param: Param::Window,
                needed: self.window,
                got: self.n,
            }
            .into());
        }
        let start = self.n - self.window;
        for r in (self.window - 1) / 2 + 1..self.window {
            self.give(start, r, &mut emit)?;
        }
        Ok(())
    }

    /// Fits the newest full window and, for an estimated σ, its residuals' σ.
    fn fit_window(&mut self) -> Result<(), Error> {
        let w = self.window;
        let p = self.m + 1;
        let even = self.run + 1 >= w;
        let fit = if even {
            let step = if w > 1 {
                (self.samples.get(w - 1).0 - self.samples.get(0).0) / (w - 1) as f64
            } else {
                1.0
            };
            WindowFit::Even { step }
        } else {
            self.scratch_t.clear();
            self.scratch_y.clear();
            for &(t, y) in self.samples.iter() {
                self.scratch_t.push(t);
                self.scratch_y.push(y);
            }
            WindowFit::Irregular(PolynomialFit::new(
                &self.scratch_t,
                &self.scratch_y,
                None,
                self.m,
            )?)
        };
        self.window_sigma = match self.sigma {
            SmoothSigma::Off => f64::NAN,
            SmoothSigma::Given(s) => s,
            SmoothSigma::Estimated => {
                let rss = match &fit {
                    WindowFit::Irregular(f) => f.residual_sq(),
                    WindowFit::Even { .. } => {
                        let mu = self.moments.moments().expect("the window is full");
                        let beta = &mut self.row[..p];
                        for ((b, m), c) in beta.iter_mut().zip(mu).zip(&self.inv_norm) {
                            *b = m * c;
                        }
                        self.samples
                            .iter()
                            .zip(self.table.chunks_exact(p))
                            .map(|(&(_, y), px)| {
                                let r = y - px.iter().zip(&*beta).map(|(a, b)| a * b).sum::<f64>();
                                r * r
                            })
                            .sum()
                    }
                };
                (rss / (w - p) as f64).sqrt()
            }
        };
        self.current = Some(fit);
        Ok(())
    }

    /// Gives row `r` (on the window axis) of the window starting at sample `start`.
    fn give<E>(
        &mut self,
        start: usize,
        r: usize,
        emit: &mut impl FnMut(SmoothedRow<'_>) -> Result<(), E>,
    ) -> Result<(), E> {
        let p = self.m + 1;
        let time = self.samples.get(r).0;
        let (d, s) = self.row.split_at_mut(p);
        let sigma = self.sigma != SmoothSigma::Off;
        match self.current.as_ref().expect("a window is fitted") {
            WindowFit::Even { step } => {
                let mu = self.moments.moments().expect("the window is full");
                self.fit.derivatives_into(mu, r as f64, *step, d);
                if sigma {
                    self.fit
                        .std_devs_into(r as f64, *step, self.window_sigma, s);
                }
            }
            WindowFit::Irregular(fit) => {
                d.copy_from_slice(&fit.derivatives_at(time));
                if sigma {
                    let cov = fit.covariance_at(time);
                    for (i, v) in s.iter_mut().enumerate() {
                        *v = self.window_sigma * std_dev(cov[(i, i)]);
                    }
                }
            }
        }
        emit(SmoothedRow {
            index: start + r,
            time,
            derivatives: d,
            std_devs: sigma.then_some(&*s),
        })
    }
}
