//! A filter specification: every polynomial filter of this crate from one description (its
//! kind, degree, memory, `τ` rule, engine and noise `σ`), the one factory of `seqsmooth filter`
//! and of Python's `filter_frame` and filter classes; and [`AnyFilter`], the filter it builds.
//!
//! The kinds are the memories of Morrison's book: expanding (ch. 9, every sample weighted
//! alike), fading (ch. 13, sample `k` weighted `θ^((t_n − t_k)/τ)`, Reyneke et al. 2012 on
//! irregular times), fixed (ch. 7, the newest `W` samples) and the automatic filter (expanding
//! memory switched to fading at Morrison's (13.8.8), with outlier gate, noise estimate and
//! misfit restarts). Without a given `τ`, a fading memory's is the typical time step of the
//! data ([`crate::polynomial::tau::default_tau`]), resolved by
//! [`FilterSpec::with_default_tau`] before [`FilterSpec::build`]. The rows a built filter
//! writes for a batch are [`AnyFilter::run_rows`]'s ([`crate::polynomial::rows`]).

use crate::discount::Discount;
use crate::error::{Error, Param};
use crate::model::PolynomialState;
use crate::polynomial::automatic::AutomaticFilter;
use crate::polynomial::expanding::ExpandingMemory;
use crate::polynomial::fading::FadingMemory;
use crate::polynomial::filter::PolynomialFilter;
use crate::polynomial::fixed::{FixedEngine, FixedMemory};
use crate::polynomial::options::Engine;
use crate::polynomial::prior::Prior;
use crate::polynomial::tau::default_tau;

/// Which memory a polynomial filter has.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum FilterKind {
    /// Expanding memory (Morrison ch. 9): every sample so far, weighted alike.
    Expanding,
    /// Fading memory (Morrison ch. 13): weights `θ^((t_n − t_k)/τ)`.
    Fading,
    /// Fixed memory (Morrison ch. 7): the newest `window` samples.
    Fixed,
    /// The automatic filter: expanding then fading memory, outlier gate, noise estimate,
    /// misfit restarts and degree settling.
    Automatic,
}

impl FilterKind {
    /// The kind's name, the same in every front end (`expanding`, `fading`, `fixed`, `auto`).
    pub fn name(self) -> &'static str {
        match self {
            FilterKind::Expanding => "expanding",
            FilterKind::Fading => "fading",
            FilterKind::Fixed => "fixed",
            FilterKind::Automatic => "auto",
        }
    }

    /// Whether the kind's memory is a discount per `τ` of time (fading and automatic).
    pub fn uses_tau(self) -> bool {
        matches!(self, FilterKind::Fading | FilterKind::Automatic)
    }
}

/// The description of a polynomial filter; [`build`](Self::build) makes it.
///
/// ```
/// use seqsmooth::polynomial::spec::{FilterKind, FilterSpec};
/// use seqsmooth::PolynomialFilter;
/// let spec = FilterSpec { theta: Some(0.9), ..FilterSpec::new(FilterKind::Fading, 1) };
/// // No τ given: the median time step of the data (here 0.5).
/// let spec = spec.with_default_tau(&[0.0, 0.5, 1.0], &[0; 3], true)?;
/// assert_eq!(spec.tau, Some(0.5));
/// let mut f = spec.build()?;
/// f.update_many(&[0.0, 0.5, 1.0], &[1.0, 2.0, 3.0])?; // y = 1 + 2t
/// assert!((f.estimate().unwrap().derivatives[1] - 2.0).abs() < 1e-12);
/// # Ok::<(), seqsmooth::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct FilterSpec {
    /// The memory.
    pub kind: FilterKind,
    /// The polynomial degree `m` (the automatic filter's highest).
    pub degree: usize,
    /// The discount `θ` per `τ` of fading memory and of the automatic filter, `0 < θ < 1`.
    pub theta: Option<f64>,
    /// The time `θ` applies to; `None`: the default, the median time step of the data
    /// ([`with_default_tau`](Self::with_default_tau)).
    pub tau: Option<f64>,
    /// Fading memory's discount per update instead (whatever the spacing), `0 < θ < 1`: the
    /// [`Discount::PerUpdate`] of the same name; give it without `theta`.
    pub theta_per_update: Option<f64>,
    /// The samples in a fixed memory's window, at least `m + 1`.
    pub window: Option<usize>,
    /// The engine of the expanding, fading and automatic filters.
    pub engine: Engine,
    /// The engine of fixed memory.
    pub fixed_engine: FixedEngine,
    /// The noise's σ: the estimates then carry their covariance (the automatic filter's given
    /// noise, else estimated).
    pub sigma: Option<f64>,
    /// The automatic filter's review window (accepted samples before an outlier decision is
    /// final); `None`: its default.
    pub review_window: Option<usize>,
    /// A prior for expanding and fading memory ([`Prior`]: the exact engine, with `sigma`);
    /// the other kinds refuse one.
    pub prior: Option<Prior>,
}

impl FilterSpec {
    /// A filter of `kind` and `degree`, every other setting at its default (no `θ`, `τ` or
    /// window yet, the exact engine, fixed memory's adaptive engine, no noise σ).
    pub fn new(kind: FilterKind, degree: usize) -> Self {
        Self {
            kind,
            degree,
            theta: None,
            tau: None,
            theta_per_update: None,
            window: None,
            engine: Engine::Exact,
            fixed_engine: FixedEngine::Adaptive,
            sigma: None,
            review_window: None,
            prior: None,
        }
    }

    /// The spec with its `τ` resolved: a fading memory's (and the automatic filter's) without
    /// one given gets the default of the rows `times` of series `series`
    /// ([`default_tau`], `complete` saying whether they are all the rows); the other kinds,
    /// and a given `τ`, are left as they are.
    pub fn with_default_tau(
        mut self,
        times: &[f64],
        series: &[usize],
        complete: bool,
    ) -> Result<Self, Error> {
        if self.kind.uses_tau() && self.tau.is_none() {
            self.tau = Some(default_tau(times, series, complete)?);
        }
        Ok(self)
    }

    /// Whether the rows of [`AnyFilter::run_rows`] carry the 1σ `s0..sM`: with a noise σ, and
    /// always for the automatic filter (from its given or estimated noise).
    pub fn writes_sigma(&self) -> bool {
        self.sigma.is_some() || self.kind == FilterKind::Automatic
    }

    /// The filter. Every setting is checked by the filter it builds (degree, `θ`, `τ`, window,
    /// engine, σ); a setting the kind needs and the spec lacks (`θ`, `τ`, the window) is an
    /// [`Error::InvalidParameter`] naming it.
    pub fn build(&self) -> Result<AnyFilter, Error> {
        let m = self.degree;
        let need = |value: Option<f64>, name| value.ok_or_else(|| needs(name, self.kind));
        if self.prior.is_some() && !matches!(self.kind, FilterKind::Expanding | FilterKind::Fading)
        {
            return Err(Error::InvalidParameter {
                name: Param::Prior,
                value: format!("for kind {}", self.kind.name()),
                reason: "a prior is for expanding and fading memory".into(),
            });
        }
        let inner = match self.kind {
            FilterKind::Expanding => {
                let f = ExpandingMemory::new(m, self.engine)?;
                let f = noise(f, self.sigma, ExpandingMemory::with_noise_sigma)?;
                Inner::Expanding(Box::new(match &self.prior {
                    Some(p) => f.with_prior(p)?,
                    None => f,
                }))
            }
            FilterKind::Fading => {
                let f = match self.theta_per_update {
                    // Per update: a `τ` filled in by the default rule means nothing here.
                    Some(_) => {
                        let tau = self.theta.and(self.tau);
                        let discount =
                            Discount::from_names(self.theta, tau, self.theta_per_update)?
                                .expect("theta_per_update is given");
                        FadingMemory::from_discount(m, discount, self.engine)?
                    }
                    None => {
                        let (theta, tau) =
                            (need(self.theta, Param::Theta)?, need(self.tau, Param::Tau)?);
                        FadingMemory::new(m, theta, tau, self.engine)?
                    }
                };
                let f = noise(f, self.sigma, FadingMemory::with_noise_sigma)?;
                Inner::Fading(Box::new(match &self.prior {
                    Some(p) => f.with_prior(p)?,
                    None => f,
                }))
            }
            FilterKind::Fixed => {
                let window = self.window.ok_or_else(|| needs(Param::Window, self.kind))?;
                let f = FixedMemory::new(m, window, self.fixed_engine)?;
                let f = noise(f, self.sigma, FixedMemory::with_noise_sigma)?;
                Inner::Fixed(Box::new(f), window)
            }
            FilterKind::Automatic => {
                let (theta, tau) = (need(self.theta, Param::Theta)?, need(self.tau, Param::Tau)?);
                let f = AutomaticFilter::new(m, theta, tau)?.with_engine(self.engine)?;
                let mut f = noise(f, self.sigma, AutomaticFilter::with_noise_sigma)?;
                if let Some(n) = self.review_window {
                    f = f.with_review_window(n)?;
                }
                Inner::Automatic(Box::new(f))
            }
        };
        Ok(AnyFilter {
            inner,
            rows: 0,
            kind: self.kind,
        })
    }
}

/// `f` with the noise `sigma` when given.
fn noise<F>(f: F, sigma: Option<f64>, with: fn(F, f64) -> Result<F, Error>) -> Result<F, Error> {
    match sigma {
        Some(s) => with(f, s),
        None => Ok(f),
    }
}

/// The setting `name` that `kind` needs and was not given.
fn needs(name: Param, kind: FilterKind) -> Error {
    Error::InvalidParameter {
        name,
        value: "(none)".into(),
        reason: format!("kind {} needs {}", kind.name(), name.name()),
    }
}

/// A polynomial filter of any kind, as [`FilterSpec::build`] makes it, with the rows it has run
/// (the automatic filter's rejected samples included). Cloning a new one is how each series of
/// many gets its filter.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct AnyFilter {
    pub(crate) inner: Inner,
    /// The samples offered so far (accepted or not).
    pub(crate) rows: u64,
    kind: FilterKind,
}

/// The filter itself.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub(crate) enum Inner {
    Expanding(Box<ExpandingMemory>),
    Fading(Box<FadingMemory>),
    /// Fixed memory over `window` samples.
    Fixed(Box<FixedMemory>, usize),
    Automatic(Box<AutomaticFilter>),
}

impl AnyFilter {
    /// The filter's kind.
    pub fn kind(&self) -> FilterKind {
        self.kind
    }

    /// The automatic filter, to act on between batches (its
    /// [`finish`](AutomaticFilter::finish) at the end of a series); `None` for the other kinds.
    pub fn automatic_mut(&mut self) -> Option<&mut AutomaticFilter> {
        match &mut self.inner {
            Inner::Automatic(f) => Some(f),
            _ => None,
        }
    }

    /// The automatic filter itself; `None` for the other kinds.
    ///
    /// ```
    /// use seqsmooth::polynomial::spec::{FilterKind, FilterSpec};
    /// let spec = FilterSpec { theta: Some(0.9), tau: Some(1.0), review_window: Some(9), ..FilterSpec::new(FilterKind::Automatic, 2) };
    /// assert_eq!(spec.build()?.into_automatic().unwrap().config().review_window, 9);
    /// assert!(FilterSpec::new(FilterKind::Expanding, 2).build()?.into_automatic().is_none());
    /// # Ok::<(), seqsmooth::Error>(())
    /// ```
    pub fn into_automatic(self) -> Option<AutomaticFilter> {
        match self.inner {
            Inner::Automatic(f) => Some(*f),
            _ => None,
        }
    }

    pub(crate) fn filter(&self) -> &dyn PolynomialFilter {
        match &self.inner {
            Inner::Expanding(f) => f.as_ref(),
            Inner::Fading(f) => f.as_ref(),
            Inner::Fixed(f, _) => f.as_ref(),
            Inner::Automatic(f) => f.as_ref(),
        }
    }

    pub(crate) fn filter_mut(&mut self) -> &mut dyn PolynomialFilter {
        match &mut self.inner {
            Inner::Expanding(f) => f.as_mut(),
            Inner::Fading(f) => f.as_mut(),
            Inner::Fixed(f, _) => f.as_mut(),
            Inner::Automatic(f) => f.as_mut(),
        }
    }
}

impl PolynomialFilter for AnyFilter {
    fn degree(&self) -> usize {
        self.filter().degree()
    }
    fn samples(&self) -> u64 {
        self.filter().samples()
    }
    fn update(&mut self, t: f64, y: f64) -> Result<(), Error> {
        self.filter_mut().update(t, y)?;
        self.rows += 1;
        Ok(())
    }
    fn estimate_at(&self, t: f64) -> Option<PolynomialState> {
        self.filter().estimate_at(t)
    }
    fn try_estimate_at(&self, t: f64) -> Result<PolynomialState, Error> {
        self.filter().try_estimate_at(t)
    }
    fn last_time(&self) -> Option<f64> {
        self.filter().last_time()
    }
    fn estimate(&self) -> Option<PolynomialState> {
        self.filter().estimate()
    }
    fn try_estimate(&self) -> Result<PolynomialState, Error> {
        self.filter().try_estimate()
    }
    fn is_determined(&self) -> bool {
        self.filter().is_determined()
    }
    fn update_many(&mut self, times: &[f64], values: &[f64]) -> Result<(), Error> {
        let done = self.filter_mut().update_many(times, values);
        self.count(times.len(), done)
    }
    fn update_many_into(&mut self, t: &[f64], y: &[f64], out: &mut [f64]) -> Result<(), Error> {
        let done = self.filter_mut().update_many_into(t, y, out);
        self.count(t.len(), done)
    }
    fn update_many_sigma_into(
        &mut self,
        t: &[f64],
        y: &[f64],
        rows: &mut [f64],
    ) -> Result<(), Error> {
        let done = self.filter_mut().update_many_sigma_into(t, y, rows);
        self.count(t.len(), done)
    }
}

impl AnyFilter {
    /// Counts the rows a batch of `n` took (up to a refused one) and passes its result on.
    pub(crate) fn count(&mut self, n: usize, result: Result<(), Error>) -> Result<(), Error> {
        self.rows += match &result {
            Ok(()) => n,
            Err(Error::InBatch { index, .. }) => *index,
            Err(_) => 0,
        } as u64;
        result
    }
}
