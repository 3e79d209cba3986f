//! The streaming fixed-memory filter (Morrison ch. 7): the least-squares polynomial through the
//! last `window` samples, updated sample by sample.

use super::weights::{inverse_norms, legendre_values, taylor_at};
use super::{check_window, steps_agree, EVEN_STEP_TOLERANCE};
use crate::basis::DiscreteLegendre;
use crate::calculus::factorial;
use crate::error::Error;
use crate::estimate::PolynomialFit;
use crate::model::PolynomialState;
use crate::polynomial::PolynomialFilter;
use crate::scalar::{Rational, Scalar};
use nalgebra::DMatrix;

/// How a [`FixedMemory`] filter computes its window fit. All three give the same estimates on
/// evenly spaced samples (to rounding); they differ in cost and in the data they accept.
///
/// ```
/// use seqsmooth::polynomial::fixed::{FixedEngine, FixedMemory};
/// use seqsmooth::PolynomialFilter;
/// let mut out = Vec::new();
/// for engine in [FixedEngine::Direct, FixedEngine::Sliding, FixedEngine::Irregular] {
///     let mut f = FixedMemory::new(2, 7, engine).unwrap();
///     for n in 0..20 {
///         f.update(0.5 * n as f64, (0.3 * n as f64).cos()).unwrap();
///     }
///     out.push(f.estimate().unwrap().derivatives);
/// }
/// assert!((out[0][1] - out[1][1]).abs() < 1e-13 && (out[0][1] - out[2][1]).abs() < 1e-12);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
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
    /// centred, scaled Legendre basis ([`PolynomialFit`]), `O(window·m²)` per sample.
    Irregular,
}

/// The exact shift matrix `M` with `p_j(x-1) = Σ_l M_jl p_l(x)` (lower triangular, unit
/// diagonal), computed in rationals and rounded.
fn shift_matrix(m: usize, span: u64) -> Vec<f64> {
    let basis = DiscreteLegendre::new(Rational::from_integer(span.into()));
    let polys: Vec<_> = (0..=m).map(|j| basis.polynomial(j)).collect();
    let minus_one = -Rational::from_i64(1);
    let mut out = vec![0.0; (m + 1) * (m + 1)];
    for j in 0..=m {
        let mut c: Vec<Rational> = (0..=j)
            .map(|i| polys[j].taylor_coefficient(i, &minus_one))
            .collect();
        for l in (0..=j).rev() {
            let lead = polys[l].coeffs[l].clone();
            let f = c[l].clone() / lead;
            for (i, ci) in c.iter_mut().enumerate().take(l + 1) {
                *ci = ci.clone() - f.clone() * polys[l].coeffs[i].clone();
            }
            out[j * (m + 1) + l] = f.to_f64();
        }
    }
    out
}

/// `p_0(x) … p_m(x)` on `x = 0..L` by the three-term recursion (A1.1) with precomputed
/// coefficients: `p_j = (A_j x + B_j) p_{j-1} - C_j p_{j-2}`, `A_j = -2(2j-1)/(j(L-j+1))`,
/// `B_j = L(2j-1)/(j(L-j+1))`, `C_j = (j-1)(L+j)/(j(L-j+1))`.
#[derive(Clone, Debug)]
struct LegendreRecursion {
    span: f64,
    coeffs: Vec<(f64, f64, f64)>,
}

impl LegendreRecursion {
    fn new(m: usize, span: usize) -> Self {
        let l = span as f64;
        let coeffs = (0..=m)
            .map(|j| {
                if j < 2 {
                    return (0.0, 0.0, 0.0);
                }
                let jf = j as f64;
                let denom = jf * (l - jf + 1.0);
                let t = 2.0 * jf - 1.0;
                (
                    -2.0 * t / denom,
                    l * t / denom,
                    (jf - 1.0) * (l + jf) / denom,
                )
            })
            .collect();
        Self { span: l, coeffs }
    }

    /// Fills `out` (length `m+1`) with `p_0(x) … p_m(x)`.
    fn values(&self, x: f64, out: &mut [f64]) {
        out[0] = 1.0;
        if out.len() > 1 {
            out[1] = 1.0 - 2.0 * x / self.span;
        }
        for j in 2..out.len() {
            let (a, b, c) = self.coeffs[j];
            out[j] = (a * x + b) * out[j - 1] - c * out[j - 2];
        }
    }
}

/// One exact refresh accumulator: the moments `Σ y p_j(pos)` of the `L+1` samples of one
/// future window, collected as they arrive (each in its final position).
#[derive(Clone, Debug)]
struct Accumulator {
    start: u64,
    count: usize,
    sums: Vec<f64>,
}

/// Evenly spaced core: the moments `μ_j = Σ_{x=0..L} y(x) p_j(x)` of the window
/// (`x = 0` oldest), from which `β_j = μ_j / c_j²` are the Legendre coefficients of the fit.
#[derive(Clone, Debug)]
struct EvenCore {
    m: usize,
    span: usize,
    sliding: bool,
    ring: Vec<f64>,
    head: usize,
    /// Direct engine: `p_j(x)` at `x = 0..=L`, row `x`, `m+1` per row (empty for the sliding
    /// engine, which evaluates `p_j(x)` by the recursion as samples arrive: no `O(L·m)` table).
    table: Vec<f64>,
    recursion: LegendreRecursion,
    inv_norm: Vec<f64>,
    shift: Vec<f64>,
    mu: Vec<f64>,
    mu_valid: bool,
    accs: Vec<Accumulator>,
    scratch: Vec<f64>,
    basis: DiscreteLegendre<f64>,
    /// `T(L)`: the Taylor matrix at the newest sample (the current estimate's).
    taylor_end: DMatrix<f64>,
}

impl EvenCore {
    fn new(m: usize, window: usize, sliding: bool, refreshes: usize) -> Self {
        let span = window - 1;
        let basis = DiscreteLegendre::new(span as f64);
        let mut table = Vec::new();
        if !sliding {
            table.reserve(window * (m + 1));
            for x in 0..window {
                table.extend(legendre_values(m, &basis, &(x as f64)));
            }
        }
        let (shift, accs) = if sliding {
            let q = refreshes.clamp(1, window);
            let period = window.div_ceil(q);
            let accs = (0..q)
                .map(|a| Accumulator {
                    start: (a * period) as u64,
                    count: 0,
                    sums: vec![0.0; m + 1],
                })
                .collect();
            (shift_matrix(m, span as u64), accs)
        } else {
            (Vec::new(), Vec::new())
        };
        Self {
            m,
            span,
            sliding,
            ring: Vec::with_capacity(window.min(1 << 16)),
            head: 0,
            inv_norm: inverse_norms(m, &basis),
            table,
            recursion: LegendreRecursion::new(m, span),
            shift,
            mu: vec![0.0; m + 1],
            mu_valid: false,
            accs,
            scratch: vec![0.0; m + 1],
            taylor_end: taylor_at(m, &basis, &(span as f64)),
            basis,
        }
    }

    fn window(&self) -> usize {
        self.span + 1
    }

    /// Processes the sample with 0-based index `n`.
    fn update(&mut self, n: u64, y: f64) {
        let w = self.window();
        let p = self.m + 1;
        let old = if self.ring.len() < w {
            self.ring.push(y);
            None
        } else {
            let o = self.ring[self.head];
            self.ring[self.head] = y;
            self.head += 1;
            if self.head == w {
                self.head = 0;
            }
            Some(o)
        };
        if !self.sliding {
            if self.ring.len() == w {
                self.mu.iter_mut().for_each(|v| *v = 0.0);
                let (newer, older) = self.ring.split_at(self.head);
                for (x, &yv) in older.iter().chain(newer.iter()).enumerate() {
                    let row = &self.table[x * p..(x + 1) * p];
                    for (m, r) in self.mu.iter_mut().zip(row) {
                        *m += yv * r;
                    }
                }
                self.mu_valid = true;
            }
            return;
        }
        // Sliding step: μ' = M (μ − y_old 𝟙) + y_new (p_j(L))_j, p_j(0) = 1, p_j(L) = (-1)^j.
        if let (true, Some(o)) = (self.mu_valid, old) {
            for (s, m) in self.scratch.iter_mut().zip(&self.mu) {
                *s = m - o;
            }
            for j in 0..p {
                let row = &self.shift[j * p..j * p + j + 1];
                let mut acc = 0.0;
                for (r, s) in row.iter().zip(&self.scratch) {
                    acc += r * s;
                }
                self.mu[j] = if j % 2 == 0 { acc + y } else { acc - y };
            }
        }
        // Exact refreshes.
        for acc in self.accs.iter_mut() {
            if n < acc.start {
                continue;
            }
            self.recursion.values(acc.count as f64, &mut self.scratch);
            for (s, r) in acc.sums.iter_mut().zip(&self.scratch) {
                *s += y * r;
            }
            acc.count += 1;
            if acc.count == w {
                self.mu.copy_from_slice(&acc.sums);
                self.mu_valid = true;
                acc.count = 0;
                acc.sums.iter_mut().for_each(|v| *v = 0.0);
            }
        }
    }

    /// Unscaled derivatives (and scaled covariance factor) at `r` on the window axis.
    fn estimate(&self, r: f64, step: f64, sigma: Option<f64>) -> (Vec<f64>, Option<DMatrix<f64>>) {
        let computed;
        let t = if r == self.span as f64 {
            &self.taylor_end
        } else {
            computed = taylor_at(self.m, &self.basis, &r);
            &computed
        };
        let mut x = Vec::with_capacity(self.m + 1);
        let mut scale = 1.0;
        for i in 0..=self.m {
            if i > 0 {
                scale *= i as f64 / step;
            }
            let mut acc = 0.0;
            for j in i..=self.m {
                // T(r) is upper triangular: dⁱp_j/drⁱ = 0 for j < i.
                acc += t[(i, j)] * self.mu[j] * self.inv_norm[j];
            }
            x.push(acc * scale);
        }
        let cov = sigma.map(|s| {
            let scale: Vec<f64> = (0..=self.m)
                .map(|i| factorial::<f64>(i) / step.powi(i as i32))
                .collect();
            DMatrix::from_fn(self.m + 1, self.m + 1, |i, k| {
                let v: f64 = (0..=self.m)
                    .map(|j| t[(i, j)] * t[(k, j)] * self.inv_norm[j])
                    .sum();
                v * scale[i] * scale[k] * s * s
            })
        });
        (x, cov)
    }
}

/// Irregular core: the window's samples, refitted by QR after each update.
#[derive(Clone, Debug)]
struct IrregularCore {
    m: usize,
    window: usize,
    times: Vec<f64>,
    values: Vec<f64>,
    head: usize,
    fit: Option<PolynomialFit>,
    scratch_t: Vec<f64>,
    scratch_y: Vec<f64>,
}

impl IrregularCore {
    fn update(&mut self, t: f64, y: f64) -> Result<(), Error> {
        if self.times.len() < self.window {
            self.times.push(t);
            self.values.push(y);
        } else {
            self.times[self.head] = t;
            self.values[self.head] = y;
            self.head = (self.head + 1) % self.window;
        }
        if self.times.len() == self.window {
            self.scratch_t.clear();
            self.scratch_y.clear();
            self.scratch_t.extend_from_slice(&self.times[self.head..]);
            self.scratch_t.extend_from_slice(&self.times[..self.head]);
            self.scratch_y.extend_from_slice(&self.values[self.head..]);
            self.scratch_y.extend_from_slice(&self.values[..self.head]);
            self.fit = Some(PolynomialFit::new(
                &self.scratch_t,
                &self.scratch_y,
                None,
                self.m,
            )?);
        }
        Ok(())
    }
}

#[derive(Clone, Debug)]
enum Core {
    Even(Box<EvenCore>),
    Irregular(Box<IrregularCore>),
}

/// The default number of staggered refresh accumulators of the sliding engine for degree `m`
/// (an exact refresh every `⌈(L+1)/q⌉` samples); see the module docs for the measurements.
pub(crate) fn default_refreshes(m: usize) -> usize {
    // 1, 1, 1, 2, 2, 4, 4, 8, 8, 16, 16, …: a carried error is extrapolated over at most
    // 1/q of a window, where p_m grows by a factor that stays near 10 for every m.
    1 << (m.saturating_sub(1) / 2).min(20)
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
/// [`FixedEngine::Irregular`] for such data). The interval used for derivatives is the mean
/// step `(t_n - t_0)/n`.
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
#[derive(Clone, Debug)]
pub struct FixedMemory {
    m: usize,
    window: usize,
    engine: FixedEngine,
    refreshes: usize,
    sigma: Option<f64>,
    n: u64,
    t_first: f64,
    t_last: f64,
    first_step: f64,
    core: Core,
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
        let refreshes = default_refreshes(m);
        let core = Self::make_core(m, window, engine, refreshes);
        Ok(Self {
            m,
            window,
            engine,
            refreshes,
            sigma: None,
            n: 0,
            t_first: f64::NAN,
            t_last: f64::NAN,
            first_step: f64::NAN,
            core,
        })
    }

    fn make_core(m: usize, window: usize, engine: FixedEngine, refreshes: usize) -> Core {
        match engine {
            FixedEngine::Direct => Core::Even(Box::new(EvenCore::new(m, window, false, 0))),
            FixedEngine::Sliding => Core::Even(Box::new(EvenCore::new(m, window, true, refreshes))),
            FixedEngine::Irregular => Core::Irregular(Box::new(IrregularCore {
                m,
                window,
                times: Vec::with_capacity(window.min(1 << 16)),
                values: Vec::with_capacity(window.min(1 << 16)),
                head: 0,
                fit: None,
                scratch_t: Vec::new(),
                scratch_y: Vec::new(),
            })),
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
        if !(sigma.is_finite() && sigma > 0.0) {
            return Err(Error::InvalidParameter {
                name: "noise sigma",
                value: sigma.to_string(),
                reason: "must be a positive finite number".into(),
            });
        }
        self.sigma = Some(sigma);
        Ok(self)
    }

    /// Sets the number `q` of staggered exact-refresh accumulators of the sliding engine (an
    /// exact refresh every `⌈window/q⌉` samples, `O(q·m)` extra work per sample; default
    /// `q = 2^⌊(m-1)/2⌋`: 1 for `m ≤ 2`, 2 for `m ≤ 4`, 4 for `m ≤ 6`, 8 for `m ≤ 8`, …). Must be set before the first sample; ignored by the
    /// other engines.
    ///
    /// ```
    /// use seqsmooth::polynomial::fixed::{FixedEngine, FixedMemory};
    /// let f = FixedMemory::new(2, 100, FixedEngine::Sliding).unwrap().with_refreshes(4).unwrap();
    /// assert_eq!(f.refresh_period(), Some(25));
    /// ```
    pub fn with_refreshes(mut self, q: usize) -> Result<Self, Error> {
        if self.n > 0 || q == 0 {
            return Err(Error::InvalidParameter {
                name: "refreshes",
                value: q.to_string(),
                reason: "must be at least 1 and set before the first sample".into(),
            });
        }
        self.refreshes = q;
        self.core = Self::make_core(self.m, self.window, self.engine, q);
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

    /// The engine.
    ///
    /// ```
    /// use seqsmooth::polynomial::fixed::{FixedEngine, FixedMemory};
    /// let f = FixedMemory::new(1, 9, FixedEngine::default()).unwrap();
    /// assert_eq!(f.engine(), FixedEngine::Sliding);
    /// ```
    pub fn engine(&self) -> FixedEngine {
        self.engine
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
        match self.engine {
            FixedEngine::Sliding => {
                Some(self.window.div_ceil(self.refreshes.clamp(1, self.window)))
            }
            _ => None,
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
        match self.core {
            Core::Even(_) if self.n >= 2 => {
                Some((self.t_last - self.t_first) / (self.n - 1) as f64)
            }
            _ => None,
        }
    }

    fn check_sample(&self, t: f64, y: f64) -> Result<(), Error> {
        crate::error::check_sample(t, y, (self.n > 0).then_some(self.t_last))?;
        if let Core::Even(_) = self.core {
            if self.n >= 2 {
                let step = t - self.t_last;
                if !steps_agree(step, self.first_step, self.t_first.abs().max(t.abs())) {
                    return Err(Error::InvalidParameter {
                        name: "sample time",
                        value: t.to_string(),
                        reason: format!(
                            "sample {} (0-based) follows the previous one after {step}, which \
                             differs from the first step {} by more than a relative {:e} (plus \
                             the rounding of the timestamps); the even-spacing engines need \
                             evenly spaced samples (use FixedEngine::Irregular)",
                            self.n, self.first_step, EVEN_STEP_TOLERANCE
                        ),
                    });
                }
            }
        }
        Ok(())
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
        self.check_sample(t, y)?;
        match &mut self.core {
            Core::Even(c) => c.update(self.n, y),
            Core::Irregular(c) => c.update(t, y)?,
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
        if self.n < self.window as u64 || !t.is_finite() {
            return None;
        }
        let (derivatives, covariance) = match &self.core {
            Core::Even(c) => {
                if !c.mu_valid {
                    return None;
                }
                let step = self.step().unwrap_or(1.0);
                let r = c.span as f64 + (t - self.t_last) / step;
                c.estimate(r, step, self.sigma)
            }
            Core::Irregular(c) => {
                let fit = c.fit.as_ref()?;
                let cov = self.sigma.map(|s| fit.covariance_at(t) * (s * s));
                (fit.derivatives_at(t), cov)
            }
        };
        Some(PolynomialState {
            time: t,
            derivatives,
            covariance,
        })
    }

    fn last_time(&self) -> Option<f64> {
        (self.n > 0).then_some(self.t_last)
    }

    fn is_determined(&self) -> bool {
        self.n >= self.window as u64
    }
}
