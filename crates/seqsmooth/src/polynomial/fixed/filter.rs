//! The streaming fixed-memory filter (Morrison ch. 7): the least-squares polynomial through the
//! last `window` samples, updated sample by sample.

use super::even::EvenWindow;
use super::irregular::IrregularWindow;
use super::ring::Ring;
use super::sliding::default_refreshes;
use super::{check_window, steps_agree, steps_equal, EVEN_STEP_TOLERANCE};
use crate::error::{Error, Param};
use crate::model::PolynomialState;
use crate::polynomial::filter::PolynomialFilter;

/// How a [`FixedMemory`] filter computes its window fit. All give the same estimates on evenly
/// spaced samples (to rounding); they differ in cost and in the data they accept.
///
/// ```
/// use seqsmooth::polynomial::fixed::{FixedEngine, FixedMemory};
/// use seqsmooth::PolynomialFilter;
/// let mut out = Vec::new();
/// for engine in [FixedEngine::Direct, FixedEngine::Sliding, FixedEngine::Irregular, FixedEngine::Adaptive] {
///     let mut f = FixedMemory::new(2, 7, engine).unwrap();
///     for n in 0..20 {
///         f.update(0.5 * n as f64, (0.3 * n as f64).cos()).unwrap();
///     }
///     out.push(f.estimate().unwrap().derivatives);
/// }
/// assert!((out[0][1] - out[1][1]).abs() < 1e-13 && (out[0][1] - out[2][1]).abs() < 1e-12);
/// assert_eq!(out[1], out[3]); // evenly spaced: Adaptive runs the sliding engine
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum FixedEngine {
    /// Evenly spaced samples; each update recomputes the window's discrete Legendre
    /// coefficients `β = C B Y_(n)` from the stored window (the factor `C B` of
    /// `W(h) = T(L+h) C B`, (7.4.10)): `O(L·m)` per sample.
    Direct,
    /// Evenly spaced samples; the sliding recursion of the window moments (add the newest
    /// sample, remove the oldest, re-express in the shifted basis), `O(m²)` per sample whatever
    /// the window, with exact refreshes that keep its error bounded (see the
    /// [module docs](super#the-sliding-engine)).
    #[default]
    Sliding,
    /// Any strictly increasing timestamps: each update refits the window by Householder QR in a
    /// centred, scaled Legendre basis ([`crate::estimate::PolynomialFit`]), `O(window·m²)` per
    /// sample.
    Irregular,
    /// Any strictly increasing timestamps: [`FixedEngine::Sliding`] while the steps are even
    /// to a relative 1e-12 (no allowance for the timestamps' rounding, so that Unix-time
    /// samples are fitted as they are), and at the first uneven step the newest `window` samples are replayed into
    /// [`FixedEngine::Irregular`], which carries on (the same least-squares fit either way, up
    /// to rounding). [`FixedMemory::engine`] names the engine running now.
    Adaptive,
}

/// The window fit a [`FixedMemory`] runs: on evenly spaced samples (direct or sliding moments)
/// or on any timestamps (QR).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
enum WindowFit {
    Even(Box<EvenWindow>),
    Irregular(Box<IrregularWindow>),
}

/// Fixed-memory polynomial filter of degree `m` over the last `window = L+1` samples (Morrison
/// ch. 7): after each sample, the least-squares polynomial through the window, with its
/// derivatives at any time (current estimate, prediction, centre of the window, retrodiction)
/// and, given the noise σ, their covariance `σ² D(τ) W(h) W(h)ᵀ D(τ)` (7.5.26)-(7.5.28).
/// Until `window` samples have arrived [`PolynomialFilter::estimate_at`] returns `None`: the
/// filter does not extrapolate a shorter fit.
///
/// The even-spacing engines ([`FixedEngine::Sliding`], the default, and
/// [`FixedEngine::Direct`]) take the sampling interval from the data: every step must equal
/// the first step `t_1 - t_0` to within a relative `1e-9` plus the rounding of the timestamps
/// (`2ε|t|`); a sample that deviates is rejected with an error naming it (use
/// [`FixedEngine::Irregular`] or [`FixedEngine::Adaptive`] for such data). The interval used
/// for derivatives is the mean step `(t_n - t_0)/n`.
///
/// ```
/// use seqsmooth::polynomial::fixed::{FixedEngine, FixedMemory};
/// use seqsmooth::PolynomialFilter;
/// // T7-08: Y = (y_n, …, y_{n-4}) = (5, 3, 4, 2, 1), m = 1, L = 4: Z*_{n,n} = (24/5, 9/10)
/// let mut f = FixedMemory::new(1, 5, FixedEngine::Sliding).unwrap();
/// for (n, y) in [1.0, 2.0, 4.0, 3.0, 5.0].iter().enumerate() {
///     assert!(f.estimate().is_none()); // the window is not full yet
///     f.update(n as f64, *y).unwrap();
/// }
/// let s = f.estimate().unwrap();
/// assert!((s.derivatives[0] - 4.8).abs() < 1e-14 && (s.derivatives[1] - 0.9).abs() < 1e-14);
/// let centre = f.estimate_at(2.0).unwrap(); // h = -L/2: (3, 9/10)
/// assert!((centre.derivatives[0] - 3.0).abs() < 1e-14);
/// ```
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct FixedMemory {
    m: usize,
    window: usize,
    engine: FixedEngine,
    sigma: Option<f64>,
    n: u64,
    t_first: f64,
    t_last: f64,
    first_step: f64,
    fit: WindowFit,
    /// [`FixedEngine::Adaptive`] while the sliding engine runs: the window's times, for the
    /// replay into the irregular engine at the first uneven step.
    times: Option<Ring<f64>>,
}

impl FixedMemory {
    /// A filter of degree `m` over the last `window` samples (`window ≥ m+1`; `L = window-1`).
    /// Errors: `m > MAX_DEGREE`, `window < m+1`, `window > 2³²`.
    ///
    /// ```
    /// use seqsmooth::polynomial::fixed::{FixedEngine, FixedMemory};
    /// assert!(FixedMemory::new(2, 3, FixedEngine::Sliding).is_ok());  // interpolation
    /// assert!(FixedMemory::new(2, 2, FixedEngine::Sliding).is_err()); // too short a window
    /// ```
    pub fn new(m: usize, window: usize, engine: FixedEngine) -> Result<Self, Error> {
        check_window(m, window)?;
        Ok(Self {
            m,
            window,
            engine,
            sigma: None,
            n: 0,
            t_first: f64::NAN,
            t_last: f64::NAN,
            first_step: f64::NAN,
            fit: Self::make_fit(m, window, engine, default_refreshes(m)),
            times: (engine == FixedEngine::Adaptive).then(|| Ring::new(window)),
        })
    }

    fn make_fit(m: usize, window: usize, engine: FixedEngine, refreshes: usize) -> WindowFit {
        let even = |refreshes| WindowFit::Even(Box::new(EvenWindow::new(m, window, refreshes)));
        match engine {
            FixedEngine::Direct => even(None),
            FixedEngine::Sliding | FixedEngine::Adaptive => even(Some(refreshes)),
            FixedEngine::Irregular => {
                WindowFit::Irregular(Box::new(IrregularWindow::new(m, window)))
            }
        }
    }

    /// Reports the covariance of the estimates for white measurement noise of standard
    /// deviation `sigma` (exact for the window fit: `σ² D W(h) W(h)ᵀ D`, or `σ² (AᵀA)⁻¹` mapped
    /// to derivatives for irregular samples).
    ///
    /// ```
    /// use seqsmooth::polynomial::fixed::{FixedEngine, FixedMemory};
    /// use seqsmooth::PolynomialFilter;
    /// let mut f = FixedMemory::new(1, 11, FixedEngine::Direct).unwrap().with_noise_sigma(2.0).unwrap();
    /// for n in 0..11 { f.update(n as f64, 0.0).unwrap(); }
    /// // (7.5.16): Var(x) = σ² 2(2L+1)/((L+2)(L+1)) at L = 10
    /// let v = f.estimate().unwrap().covariance.unwrap()[(0, 0)];
    /// assert!((v - 4.0 * 42.0 / 132.0).abs() < 1e-14);
    /// ```
    pub fn with_noise_sigma(mut self, sigma: f64) -> Result<Self, Error> {
        crate::polynomial::options::check_noise_sigma(sigma)?;
        self.sigma = Some(sigma);
        Ok(self)
    }

    /// Sets the number `q` of staggered exact-refresh accumulators of the sliding engine (an
    /// exact refresh every `⌈window/q⌉` samples, `O(q·m)` extra work per sample; default
    /// `q = 2^⌊(m-1)/2⌋`: 1 for `m ≤ 2`, 2 for `m ≤ 4`, 4 for `m ≤ 6`, 8 for `m ≤ 8`, …). Must
    /// be set before the first sample; used by [`FixedEngine::Sliding`] and the sliding phase of
    /// [`FixedEngine::Adaptive`], ignored by the other engines.
    ///
    /// ```
    /// use seqsmooth::polynomial::fixed::{FixedEngine, FixedMemory};
    /// let f = FixedMemory::new(2, 100, FixedEngine::Sliding).unwrap().with_refreshes(4).unwrap();
    /// assert_eq!(f.refresh_period(), Some(25));
    /// ```
    pub fn with_refreshes(mut self, q: usize) -> Result<Self, Error> {
        if self.n > 0 || q == 0 {
            return Err(Error::InvalidParameter {
                name: Param::Refreshes,
                value: q.to_string(),
                reason: "must be at least 1 and set before the first sample".into(),
            });
        }
        if let WindowFit::Even(w) = &mut self.fit {
            w.set_refreshes(q);
        }
        Ok(self)
    }

    /// The window length in samples (`L+1`).
    ///
    /// ```
    /// use seqsmooth::polynomial::fixed::{FixedEngine, FixedMemory};
    /// let f = FixedMemory::new(1, 21, FixedEngine::Direct).unwrap();
    /// assert_eq!((f.window(), f.engine(), f.refresh_period()), (21, FixedEngine::Direct, None));
    /// ```
    pub fn window(&self) -> usize {
        self.window
    }

    /// The engine running now: the one asked for, except that [`FixedEngine::Adaptive`] reports
    /// [`FixedEngine::Sliding`] until the first uneven step and [`FixedEngine::Irregular`] from
    /// then on.
    ///
    /// ```
    /// use seqsmooth::polynomial::fixed::{FixedEngine, FixedMemory};
    /// use seqsmooth::PolynomialFilter;
    /// let f = FixedMemory::new(1, 9, FixedEngine::default()).unwrap();
    /// assert_eq!(f.engine(), FixedEngine::Sliding);
    /// let mut a = FixedMemory::new(1, 3, FixedEngine::Adaptive).unwrap();
    /// for t in [0.0, 1.0, 2.0, 3.0] { a.update(t, t).unwrap(); }
    /// assert_eq!(a.engine(), FixedEngine::Sliding);
    /// a.update(3.5, 3.5).unwrap(); // uneven: the newest 3 samples replayed into QR
    /// assert_eq!(a.engine(), FixedEngine::Irregular);
    /// assert!((a.estimate().unwrap().derivatives[1] - 1.0).abs() < 1e-12);
    /// ```
    pub fn engine(&self) -> FixedEngine {
        match (self.engine, &self.fit) {
            (FixedEngine::Adaptive, WindowFit::Even(_)) => FixedEngine::Sliding,
            (FixedEngine::Adaptive, WindowFit::Irregular(_)) => FixedEngine::Irregular,
            (engine, _) => engine,
        }
    }

    /// The sliding engine's refresh period in samples: `⌈window/q⌉` (`None` for the other
    /// engines).
    ///
    /// ```
    /// use seqsmooth::polynomial::fixed::{FixedEngine, FixedMemory};
    /// // default q = 2^⌊(m-1)/2⌋: 1 at m = 2, 4 at m = 6
    /// assert_eq!(FixedMemory::new(2, 101, FixedEngine::Sliding).unwrap().refresh_period(), Some(101));
    /// assert_eq!(FixedMemory::new(6, 101, FixedEngine::Sliding).unwrap().refresh_period(), Some(26));
    /// ```
    pub fn refresh_period(&self) -> Option<usize> {
        match &self.fit {
            WindowFit::Even(w) => w.refresh_period(),
            WindowFit::Irregular(_) => None,
        }
    }

    /// The sampling interval the even-spacing engines use: the mean step so far
    /// (`None` before the second sample and for the irregular engine).
    ///
    /// ```
    /// use seqsmooth::polynomial::fixed::{FixedEngine, FixedMemory};
    /// use seqsmooth::PolynomialFilter;
    /// let mut f = FixedMemory::new(1, 5, FixedEngine::Sliding).unwrap();
    /// f.update(10.0, 1.0).unwrap();
    /// assert_eq!(f.step(), None);
    /// f.update(10.25, 1.0).unwrap();
    /// assert_eq!(f.step(), Some(0.25));
    /// ```
    pub fn step(&self) -> Option<f64> {
        match self.fit {
            WindowFit::Even(_) if self.n >= 2 => {
                Some((self.t_last - self.t_first) / (self.n - 1) as f64)
            }
            _ => None,
        }
    }

    /// Whether `t` follows the previous sample after a step the even-spacing engines cannot
    /// take ([`steps_agree`]; for the adaptive engine the stricter [`steps_equal`]).
    fn uneven_step(&self, t: f64) -> bool {
        let step = t - self.t_last;
        matches!(self.fit, WindowFit::Even(_))
            && self.n >= 2
            && if self.engine == FixedEngine::Adaptive {
                !steps_equal(step, self.first_step)
            } else {
                !steps_agree(step, self.first_step, self.t_first.abs().max(t.abs()))
            }
    }

    fn uneven_step_error(&self, t: f64) -> Error {
        Error::InvalidParameter {
            name: Param::SampleTime,
            value: t.to_string(),
            reason: format!(
                "sample {} (0-based) follows the previous one after {}, which differs from the \
                 first step {} by more than a relative {:e} (plus the rounding of the \
                 timestamps); the even-spacing engines need evenly spaced samples (use \
                 FixedEngine::Irregular)",
                self.n,
                t - self.t_last,
                self.first_step,
                EVEN_STEP_TOLERANCE
            ),
        }
    }

    /// [`FixedEngine::Adaptive`] at the first uneven step: the window's samples replayed into
    /// the irregular engine.
    fn switch_to_irregular(&mut self) {
        let (WindowFit::Even(even), Some(times)) = (&self.fit, self.times.take()) else {
            unreachable!("only the adaptive engine switches, and only once");
        };
        let samples = times.iter().copied().zip(even.values().copied());
        self.fit = WindowFit::Irregular(Box::new(IrregularWindow::with_samples(
            self.m,
            self.window,
            samples,
        )));
    }
}

impl PolynomialFilter for FixedMemory {
    fn degree(&self) -> usize {
        self.m
    }

    fn samples(&self) -> u64 {
        self.n
    }

    fn update(&mut self, t: f64, y: f64) -> Result<(), Error> {
        crate::error::check_sample(t, y, (self.n > 0).then_some(self.t_last))?;
        if self.uneven_step(t) {
            if self.engine != FixedEngine::Adaptive {
                return Err(self.uneven_step_error(t));
            }
            self.switch_to_irregular();
        }
        match &mut self.fit {
            WindowFit::Even(w) => w.update(self.n, y),
            WindowFit::Irregular(w) => w.update(t, y)?,
        }
        if let Some(times) = &mut self.times {
            times.push(t);
        }
        if self.n == 0 {
            self.t_first = t;
        } else if self.n == 1 {
            self.first_step = t - self.t_last;
        }
        self.t_last = t;
        self.n += 1;
        Ok(())
    }

    fn estimate_at(&self, t: f64) -> Option<PolynomialState> {
        self.try_estimate_at(t).ok()
    }

    fn try_estimate_at(&self, t: f64) -> Result<PolynomialState, Error> {
        crate::error::check_finite("time", &[t])?;
        if self.n < self.window as u64 {
            return Err(Error::TooFewSamples {
                needed: self.window,
                got: self.n as usize,
            });
        }
        let singular = || Error::NotDetermined {
            samples: self.n,
            why: "the window's least-squares fit is singular in doubles (times or values at \
                  the ends of the double range); rescale the times or values"
                .into(),
        };
        let (derivatives, covariance) = match &self.fit {
            WindowFit::Even(w) => {
                let step = self.step().unwrap_or(1.0);
                let r = (self.window - 1) as f64 + (t - self.t_last) / step;
                w.estimate(r, step, self.sigma).ok_or_else(singular)?
            }
            WindowFit::Irregular(w) => {
                let fit = w.fit().ok_or_else(singular)?;
                let cov = self.sigma.map(|s| fit.covariance_at(t) * (s * s));
                (fit.derivatives_at(t), cov)
            }
        };
        PolynomialState {
            time: t,
            derivatives,
            covariance,
        }
        .checked()
    }

    fn last_time(&self) -> Option<f64> {
        (self.n > 0).then_some(self.t_last)
    }

    fn is_determined(&self) -> bool {
        self.n >= self.window as u64
    }
}

impl FixedMemory {
    /// The invariants of a restored filter ([`crate::persist`]): degree and window in range,
    /// the window's rings of its length.
    pub(crate) fn check_saved(&self) -> Result<(), String> {
        if self.m > crate::polynomial::options::MAX_DEGREE || self.window < self.m + 1 {
            return Err(format!(
                "degree {} or window {} is out of range",
                self.m, self.window
            ));
        }
        let ring_ok = match &self.fit {
            WindowFit::Even(e) => e.check_saved(self.m, self.window),
            WindowFit::Irregular(i) => i.check_saved(self.m, self.window),
        };
        let times_ok = self
            .times
            .as_ref()
            .is_none_or(|r| r.check_saved(self.window));
        if !(ring_ok && times_ok) {
            return Err(format!(
                "window's samples are not of its length {}",
                self.window
            ));
        }
        Ok(())
    }
}
