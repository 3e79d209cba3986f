//! [`AutoOutput`]: what the automatic filter reports for each sample — the estimate and the
//! per-sample flags (outlier, misfit, manoeuvre, restart), the noise `σ` in use, the phase and
//! the innovation statistics.

use super::phase::Phase;
#[cfg(doc)]
use super::{AutomaticFilter, MisfitResponse};
use crate::model::PolynomialState;
use crate::polynomial::options::MAX_DEGREE;
use crate::stats::ChiSquaredOutcome;

/// The result of one [`AutomaticFilter::update`], kept as [`AutomaticFilter::last_output`].
///
/// ```
/// use seqsmooth::polynomial::automatic::AutomaticFilter;
/// let mut f = AutomaticFilter::new(1, 0.9, 1.0).unwrap().with_noise_sigma(0.5).unwrap();
/// let mut out = None;
/// for n in 0..50 {
///     out = Some(f.update(n as f64, 1.0 + 0.1 * n as f64).unwrap());
/// }
/// let out = out.unwrap();
/// let x = out.derivatives().unwrap();                 // [x, x']
/// let sd = out.std_devs().unwrap();                   // their 1σ from σ = 0.5
/// assert!((x[1] - 0.1).abs() < 1e-9 && sd[0] < 0.5);
/// assert_eq!(out.noise_sigma, Some(0.5));
/// assert!(!out.outlier && !out.misfit);
/// assert_eq!(f.last_output(), Some(&out));
/// ```
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AutoOutput {
    /// The sample's time.
    pub time: f64,
    /// The estimate at `time`: derivatives `x … x^(d)` of the active degree `d`, with their
    /// mean squared error matrix `σ² V + b bᵀ` when `σ` is known or estimated (the noise's
    /// covariance plus the estimated bias [`bias`](Self::bias), see the module docs). After a
    /// rejected sample, the prediction across it. `None`, with the reason in
    /// [`withheld`](Self::withheld), until the active filter is determined and `σ` is known: no
    /// estimate is given without its σ.
    pub estimate: Option<PolynomialState>,
    /// Why [`estimate`](Self::estimate) is `None` (`None` when there is an estimate).
    pub withheld: Option<Withheld>,
    /// The active degree `d` (the final degree once settled).
    pub degree: usize,
    /// Which filter is active.
    pub phase: Phase,
    /// The noise `σ` used (given, or the running estimate once it has enough terms).
    pub noise_sigma: Option<f64>,
    /// `ν = y − ŷ(t)` against the active filter's prediction (before this sample).
    pub innovation: Option<f64>,
    /// `σ_ε = √(σ²(1 + v) + b₀²)`, the innovation's root mean square: noise, the prediction's
    /// own VRF `v` and its estimated bias `b₀`.
    pub innovation_sigma: Option<f64>,
    /// The gate half-width applied, when the gate was active.
    pub gate: Option<f64>,
    /// The estimated bias `b` of each derivative (active degree versus the next degree on the
    /// same memory) whose outer product `b bᵀ` is included in the covariance of
    /// [`estimate`](Self::estimate). `Some`: the reported σ covers noise and the estimated bias
    /// (of a start-up at a low degree, a settling degree, a manoeuvre); `None`: it covers the
    /// noise only (no covariance, the next degree not determined yet, or the degree is
    /// [`MAX_DEGREE`](crate::polynomial::MAX_DEGREE)).
    pub bias: Option<Vec<f64>>,
    /// The sample was rejected: the state was not updated.
    pub outlier: bool,
    /// The innovation chi-squared test says the model no longer fits (or a run of rejections
    /// was just taken for a manoeuvre).
    pub misfit: bool,
    /// A run of consecutive rejections was taken for a manoeuvre and applied at this sample.
    pub manoeuvre: bool,
    /// How many samples just before this one, rejected when they came, were applied with it
    /// as a manoeuvre's onset ([`manoeuvre`](Self::manoeuvre)): the `outlier` flag of those
    /// earlier outputs is revised to false. The decision on a rejected sample is final once a
    /// later sample is accepted.
    pub reinstated: usize,
    /// The final-degree memory was restarted at this sample ([`MisfitResponse::Restart`]).
    pub restart: bool,
    /// The chi-squared window after this sample (when the sample entered it).
    pub chi_squared: Option<ChiSquaredOutcome>,
    /// The final outlier decisions made at this update (`true`: rejected), on the oldest
    /// samples still waiting, in order: decisions come in sample order, so the `i`-th decision
    /// reported is on the `i`-th sample taken. A sample is decided once
    /// [`AutoConfig::review_window`](super::AutoConfig::review_window) accepted samples after it
    /// are in (by interpolation, see the module docs), or by
    /// [`AutomaticFilter::finish`](super::AutomaticFilter::finish); [`final_outliers`] collects
    /// them. At most 64 (at most 63 samples wait; beyond that the oldest keeps the gate's
    /// decision).
    pub decided: Vec<bool>,
}

impl AutoOutput {
    /// The estimated derivatives `x, x', …` (active degree), when determined.
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// let mut f = AutomaticFilter::new(1, 0.9, 1.0).unwrap().with_noise_sigma(0.5).unwrap();
    /// assert_eq!(f.update(0.0, 4.0).unwrap().derivatives(), Some(&[4.0][..])); // degree 0 first
    /// ```
    pub fn derivatives(&self) -> Option<&[f64]> {
        self.estimate.as_ref().map(|s| s.derivatives.as_slice())
    }

    /// 1σ of each derivative, when determined and `σ` is available.
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// let mut f = AutomaticFilter::new(0, 0.9, 1.0).unwrap().with_noise_sigma(2.0).unwrap();
    /// let sd = f.update(0.0, 4.0).unwrap().std_devs().unwrap();
    /// assert!((sd[0] - 2.0).abs() < 1e-12); // one sample: its own σ
    /// ```
    pub fn std_devs(&self) -> Option<Vec<f64>> {
        self.estimate.as_ref().and_then(|s| s.std_devs())
    }
}

/// What the rows of an update write of its reported estimate (the row runner's path,
/// `AutomaticFilter::update_row`): the derivatives of [`AutoOutput::estimate`], their 1σ (the
/// square roots of its covariance's diagonal, the same numbers bit for bit) and the first
/// entry of [`AutoOutput::bias`], without the covariance matrix (no allocation, no products
/// off the diagonal).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Reported {
    pub(super) derivatives: [f64; MAX_DEGREE + 1],
    pub(super) std_devs: [f64; MAX_DEGREE + 1],
    pub(super) len: usize,
    /// `b₀`, NaN where [`AutoOutput::bias`] is `None`.
    pub(super) bias0: f64,
}

impl Default for Reported {
    fn default() -> Self {
        Self {
            derivatives: [0.0; MAX_DEGREE + 1],
            std_devs: [0.0; MAX_DEGREE + 1],
            len: 0,
            bias0: f64::NAN,
        }
    }
}

impl Reported {
    /// `x, x', …` of the active degree.
    pub(crate) fn derivatives(&self) -> &[f64] {
        &self.derivatives[..self.len]
    }

    /// Their 1σ (`σ² V + b bᵀ` widened by the calibration, its diagonal's square roots).
    pub(crate) fn std_devs(&self) -> &[f64] {
        &self.std_devs[..self.len]
    }

    /// The position's estimated bias `b₀` (NaN: none, [`AutoOutput::bias`] `None`).
    pub(crate) fn bias0(&self) -> f64 {
        self.bias0
    }
}

/// Why an [`AutoOutput`] has no estimate: the automatic filter gives an estimate only with its
/// σ (the mean squared error `σ² V + b bᵀ`, see the module docs), or none with the reason.
///
/// ```
/// use seqsmooth::polynomial::automatic::{AutomaticFilter, Withheld, MIN_NOISE_TERMS};
/// let mut f = AutomaticFilter::new(2, 0.9, 1.0).unwrap(); // σ estimated
/// let outs: Vec<_> = (0..12).map(|n| f.update(n as f64, (n * n % 7) as f64).unwrap()).collect();
/// // σ from the third differences needs MIN_NOISE_TERMS of them: 3 + 5 = 8 samples
/// assert_eq!(Withheld::noise_samples(2), 3 + MIN_NOISE_TERMS);
/// assert!(outs[..7].iter().all(|o| o.estimate.is_none() && o.withheld == Some(Withheld::NoiseUnknown)));
/// assert!(outs[7..].iter().all(|o| o.withheld.is_none() && o.std_devs().is_some()));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Withheld {
    /// The noise `σ` is not given and not estimated yet: the `(m+1)`-th differences need
    /// [`MIN_NOISE_TERMS`](super::MIN_NOISE_TERMS) terms, `m + 1 +` that many samples
    /// ([`noise_samples`](Self::noise_samples)); give `σ` to have estimates from the first
    /// sample.
    NoiseUnknown,
    /// The active filter's fit is not determined (too few samples, or singular in doubles).
    NotDetermined,
    /// A number of the estimate or its covariance is beyond the double range
    /// ([`AutomaticFilter::try_estimate`](super::AutomaticFilter::try_estimate) names it).
    OutOfRange,
}

impl Withheld {
    /// The accepted samples after which [`Withheld::NoiseUnknown`] ends for final degree `m`
    /// with the default noise source (the innovations' source needs as many).
    pub fn noise_samples(m: usize) -> usize {
        m + 1 + super::MIN_NOISE_TERMS
    }

    /// The reason in words.
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::Withheld;
    /// assert!(Withheld::NoiseUnknown.reason().contains("σ"));
    /// ```
    pub fn reason(&self) -> &'static str {
        match self {
            Withheld::NoiseUnknown => {
                "the noise σ is not known yet (give it, or wait for its estimate)"
            }
            Withheld::NotDetermined => "the fit is not determined yet",
            Withheld::OutOfRange => "a number of the estimate is beyond the double range",
        }
    }
}

/// The final outlier decision of each of a series' outputs, in order: the decisions reported
/// ([`AutoOutput::decided`], in sample order), then `tail` (what
/// [`AutomaticFilter::finish`](super::AutomaticFilter::finish) returned, or nothing), and for
/// any sample still undecided its provisional flag [`AutoOutput::outlier`].
///
/// ```
/// use seqsmooth::polynomial::automatic::{final_outliers, AutomaticFilter};
/// let mut f = AutomaticFilter::new(0, 0.9, 1.0).unwrap().with_noise_sigma(0.1).unwrap()
///     .with_review_window(0).unwrap();                            // the gate's decisions
/// let mut outs = Vec::new();
/// for n in 0..20 { outs.push(f.update(n as f64, 0.0).unwrap()); }
/// outs.push(f.update(20.0, 5.0).unwrap());                     // an outlier
/// outs.push(f.update(21.0, 0.0).unwrap());
/// for n in 22..25 { outs.push(f.update(n as f64, 9.0).unwrap()); } // a step: 3 rejections
/// let flags = final_outliers(&outs, &[]);
/// assert_eq!(outs[22..25].iter().map(|o| o.outlier).collect::<Vec<_>>(), [true, true, false]);
/// assert_eq!(outs[24].reinstated, 2);
/// assert_eq!(flags.iter().filter(|&&r| r).count(), 1);      // only the outlier stays rejected
/// assert!(flags[20] && !flags[22] && !flags[23]);
/// assert_eq!(f.rejected(), 1);
/// ```
pub fn final_outliers(outputs: &[AutoOutput], tail: &[bool]) -> Vec<bool> {
    let mut flags: Vec<bool> = outputs
        .iter()
        .flat_map(|o| o.decided.iter().copied())
        .chain(tail.iter().copied())
        .take(outputs.len())
        .collect();
    let decided = flags.len();
    flags.extend(outputs[decided..].iter().map(|o| o.outlier));
    flags
}
