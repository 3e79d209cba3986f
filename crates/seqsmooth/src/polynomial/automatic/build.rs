//! Building the automatic filter: [`AutomaticFilter::new`] from the required degree, discount
//! and interval, the checked `with_*` builders (each changes its [`AutoConfig`] fields and
//! checks every setting again); the filters a configuration runs are its parts' (see
//! [`super::state`]).

use super::config::AutoConfig;
use super::filter::AutomaticFilter;
use super::misfit::MisfitResponse;
use super::noise::NoiseSource;
use super::outlier::OutlierRule;
use super::review::Review;
use super::state::State;
use crate::error::Error;
use crate::polynomial::fading::switch::SwitchRule;
use crate::polynomial::options::check_not_started;
use crate::polynomial::options::{DiscountMode, Engine};

/// The `with_*` builders of [`AutomaticFilter`]: each changes the fields of its
/// [`AutoConfig`] given on the right, and checks every setting again (an error after the first
/// sample).
macro_rules! builders {
    ($($(#[$doc:meta])* $name:ident($($arg:ident: $ty:ty),+) => $($field:ident = $value:expr),+;)+) => {
        $(
            $(#[$doc])*
            pub fn $name(self, $($arg: $ty),+) -> Result<Self, Error> {
                self.reconfigure(|c| {
                    $(c.$field = $value;)+
                })
            }
        )+
    };
}

impl AutomaticFilter {
    /// The filter of a checked configuration.
    pub(super) fn build(config: AutoConfig) -> Result<Self, Error> {
        config.validate()?;
        let review = Review::new(&config);
        Ok(Self {
            state: State::new(config)?,
            review,
            last_output: None,
        })
    }

    /// A filter of final degree `m`, discount `θ ∈ (0,1)` per nominal interval `τ > 0`, with
    /// every other setting at its default (see [`AutoConfig`]); change them with the `with_*`
    /// builders before the first sample.
    ///
    /// ```
    /// use seqsmooth::polynomial::automatic::AutomaticFilter;
    /// use seqsmooth::Error;
    /// let mut f = AutomaticFilter::new(2, 0.95, 0.5).unwrap();
    /// let out = f.update(0.0, 1.0).unwrap();
    /// assert_eq!(out.degree, 0);                       // the ladder starts at degree 0
    /// assert!(out.noise_sigma.is_none());               // not estimated yet: no estimate
    /// assert!(out.estimate.is_none() && out.withheld.is_some());
    /// let mut f = AutomaticFilter::new(2, 0.95, 0.5)?.with_noise_sigma(0.1)?;
    /// assert_eq!(f.update(0.0, 1.0)?.derivatives(), Some(&[1.0][..])); // σ given
    /// assert!(matches!(AutomaticFilter::new(2, 1.5, 1.0), Err(Error::ThetaOutOfRange { .. })));
    /// # Ok::<(), Error>(())
    /// ```
    pub fn new(m: usize, theta: f64, tau: f64) -> Result<Self, Error> {
        Self::build(AutoConfig::new(m, theta, tau))
    }

    /// The same filter with one setting changed and every setting checked again; an error
    /// after the first sample.
    fn reconfigure(self, change: impl FnOnce(&mut AutoConfig)) -> Result<Self, Error> {
        check_not_started(
            self.state.last_time().is_some(),
            "the automatic filter's settings",
        )?;
        let mut config = self.state.config().clone();
        change(&mut config);
        Self::build(config)
    }

    builders! {
        /// The engine of every internal filter (default [`Engine::Exact`], right on irregular
        /// samples).
        ///
        /// ```
        /// use seqsmooth::polynomial::automatic::AutomaticFilter;
        /// use seqsmooth::Engine;
        /// let mut exact = AutomaticFilter::new(1, 0.9, 1.0).unwrap().with_noise_sigma(1.0).unwrap();
        /// let mut gain = exact.clone().with_engine(Engine::Gain).unwrap();
        /// for n in 0..60 {
        ///     exact.update(n as f64, 0.5 * n as f64).unwrap();
        ///     gain.update(n as f64, 0.5 * n as f64).unwrap();
        /// }
        /// // on even samples the engines agree
        /// let (a, b) = (exact.estimate().unwrap(), gain.estimate().unwrap());
        /// assert!((a.derivatives[1] - b.derivatives[1]).abs() < 1e-9);
        /// ```
        with_engine(engine: Engine) => engine = engine;

        /// Discounting by time (default [`DiscountMode::PerTime`]) or by sample.
        ///
        /// ```
        /// # use seqsmooth::polynomial::automatic::AutomaticFilter;
        /// use seqsmooth::DiscountMode;
        /// let f = AutomaticFilter::new(1, 0.9, 1.0)?.with_discount_mode(DiscountMode::PerUpdate)?;
        /// assert_eq!(f.config().discount, DiscountMode::PerUpdate);
        /// # Ok::<(), seqsmooth::Error>(())
        /// ```
        with_discount_mode(mode: DiscountMode) => discount = mode;

        /// When the final degree moves from expanding to fading memory (default
        /// [`SwitchRule::Position`]); checked for the degree.
        ///
        /// ```
        /// use seqsmooth::polynomial::automatic::AutomaticFilter;
        /// use seqsmooth::polynomial::SwitchRule;
        /// let f = AutomaticFilter::new(1, 0.9, 1.0).unwrap();
        /// assert!(f.clone().with_switch_rule(SwitchRule::Derivative(2)).is_err());
        /// let mut f = f.with_switch_rule(SwitchRule::AtSample(5)).unwrap().with_noise_sigma(1.0).unwrap();
        /// for n in 0..10 {
        ///     f.update(n as f64, n as f64).unwrap();
        /// }
        /// assert_eq!(f.switched_at(), Some(5));
        /// ```
        with_switch_rule(rule: SwitchRule) => switch_rule = rule;

        /// The measurement noise `σ > 0`, when known (by default it is estimated, see
        /// [`with_noise_source`](Self::with_noise_source)).
        ///
        /// ```
        /// use seqsmooth::polynomial::automatic::AutomaticFilter;
        /// let f = AutomaticFilter::new(1, 0.9, 1.0).unwrap();
        /// assert!(f.clone().with_noise_sigma(0.0).is_err());
        /// assert_eq!(f.with_noise_sigma(0.3).unwrap().noise_sigma(), Some(0.3));
        /// ```
        with_noise_sigma(sigma: f64) => noise_sigma = Some(sigma);

        /// How `σ` is estimated when not given (default [`NoiseSource::Differences`] over all
        /// samples).
        ///
        /// ```
        /// use seqsmooth::polynomial::automatic::{AutomaticFilter, NoiseSource};
        /// let source = NoiseSource::Innovations { window: None };
        /// match AutomaticFilter::new(1, 0.9, 1.0).and_then(|f| f.with_noise_source(source)) {
        ///     Ok(f) => assert_eq!(f.config().noise_source, source),
        ///     Err(e) => panic!("{e}"),
        /// }
        /// ```
        with_noise_source(source: NoiseSource) => noise_source = source;

        /// The screen `c > 0` of the difference noise estimate (default 3; infinity: none): a
        /// difference beyond `c σ̂` and the `m + 1` after it are left out of `σ̂`
        /// ([`crate::stats::DifferenceNoise::with_screen`]).
        ///
        /// ```
        /// use seqsmooth::polynomial::automatic::AutomaticFilter;
        /// let f = AutomaticFilter::new(1, 0.9, 1.0).unwrap();
        /// assert_eq!(f.config().noise_screen, 3.0);
        /// assert!(f.clone().with_noise_screen(0.0).is_err());
        /// assert!(f.with_noise_screen(f64::INFINITY).is_ok());
        /// ```
        with_noise_screen(c: f64) => noise_screen = c;

        /// The outlier gate (default [`OutlierRule::morrison`]).
        ///
        /// ```
        /// use seqsmooth::polynomial::automatic::{AutomaticFilter, OutlierRule};
        /// let mut f = AutomaticFilter::new(0, 0.9, 1.0).unwrap()
        ///     .with_noise_sigma(0.1).unwrap()
        ///     .with_outlier_rule(OutlierRule::Off).unwrap();
        /// let flags: Vec<bool> = [1.0, 1.0, 1.0, 50.0].iter().enumerate()
        ///     .map(|(n, y)| f.update(n as f64, *y).unwrap().outlier)
        ///     .collect();
        /// assert_eq!(flags, [false; 4]); // no gate: the spike is taken
        /// ```
        with_outlier_rule(rule: OutlierRule) => outliers = rule;

        /// The gate is applied only while the 1-step prediction VRF is at most `v > 0` (default
        /// [`GATE_MAX_VRF`](super::GATE_MAX_VRF); infinity: always).
        ///
        /// ```
        /// # fn main() -> Result<(), seqsmooth::Error> {
        /// use seqsmooth::polynomial::automatic::AutomaticFilter;
        /// let always = AutomaticFilter::new(1, 0.9, 1.0)?.with_gate_max_vrf(f64::INFINITY)?;
        /// assert!(always.config().gate_max_vrf.is_infinite());
        /// assert!(always.with_gate_max_vrf(-1.0).is_err());
        /// # Ok(())
        /// # }
        /// ```
        with_gate_max_vrf(v: f64) => gate_max_vrf = v;

        /// A run of `n` consecutive rejections is a manoeuvre, applied after all (`0`: never;
        /// default 3).
        ///
        /// ```
        /// use seqsmooth::polynomial::automatic::AutomaticFilter;
        /// let mut f = AutomaticFilter::new(0, 0.9, 1.0).unwrap().with_noise_sigma(0.1).unwrap()
        ///     .with_max_consecutive_rejections(0).unwrap();
        /// for n in 0..20 { f.update(n as f64, 0.0).unwrap(); }
        /// for n in 20..30 { f.update(n as f64, 10.0).unwrap(); } // a step, never accepted
        /// assert_eq!(f.rejected(), 10);
        /// ```
        with_max_consecutive_rejections(n: usize) => max_consecutive_rejections = n;

        /// A run of `n ≥ 2` consecutive rejections all on the same side of the prediction is a
        /// manoeuvre, applied after all (default 0: off; 1: off; off too when
        /// [`with_max_consecutive_rejections`](Self::with_max_consecutive_rejections) is 0).
        ///
        /// ```
        /// use seqsmooth::polynomial::automatic::AutomaticFilter;
        /// let run = |n| {
        ///     let mut f = AutomaticFilter::new(0, 0.9, 1.0).unwrap().with_noise_sigma(0.1).unwrap()
        ///         .with_same_side_rejections(n).unwrap();
        ///     for k in 0..20 { f.update(k as f64, 0.0).unwrap(); }
        ///     // a step: 2 rejections on one side are a manoeuvre at n = 2, 3 at n = 0 (the run limit)
        ///     (20..23).map(|k| f.update(k as f64, 10.0).unwrap().outlier).collect::<Vec<_>>()
        /// };
        /// assert_eq!(run(2), [true, false, false]);
        /// assert_eq!(run(0), [true, true, false]);
        /// ```
        with_same_side_rejections(n: usize) => same_side_rejections = n;


        /// The innovation chi-squared window `K ≥ 1` (default 10).
        ///
        /// ```
        /// use seqsmooth::polynomial::automatic::AutomaticFilter;
        /// for (k, ok) in [(0, false), (1, true), (50, true)] {
        ///     assert_eq!(AutomaticFilter::new(1, 0.9, 1.0).unwrap().with_misfit_window(k).is_ok(), ok);
        /// }
        /// ```
        with_misfit_window(window: usize) => misfit_window = window;

        /// The per-sample false-alarm rate `α ∈ (0,1)` of the misfit test (default 0.01).
        ///
        /// ```
        /// use seqsmooth::polynomial::automatic::AutomaticFilter;
        /// let f = AutomaticFilter::new(1, 0.9, 1.0).unwrap();
        /// let ok: Vec<bool> = [0.0, 0.05, 1.0].iter().map(|&a| f.clone().with_misfit_alpha(a).is_ok()).collect();
        /// assert_eq!(ok, [false, true, false]);
        /// ```
        with_misfit_alpha(alpha: f64) => misfit_alpha = alpha;

        /// The accepted samples on each side of a sample by which its final outlier decision is
        /// made ([review](crate::polynomial::automatic), step 6; default `m + 4`; 0: the gate's decision at the time, final
        /// once a later sample is accepted). At most [`MAX_REVIEW_WINDOW`](super::MAX_REVIEW_WINDOW), and 0 or at least
        /// `(m + 4)/2`.
        ///
        /// ```
        /// use seqsmooth::polynomial::automatic::AutomaticFilter;
        /// let f = AutomaticFilter::new(2, 0.9, 1.0).unwrap();
        /// assert_eq!(f.config().review_window, 6);
        /// assert!(f.clone().with_review_window(0).is_ok());
        /// assert!(f.clone().with_review_window(2).is_err()); // 4 samples: a cubic has no check
        /// assert!(f.with_review_window(3).is_ok());
        /// ```
        with_review_window(window: usize) => review_window = window;

        /// What the filter does when the model no longer fits (default
        /// [`MisfitResponse::Restart`] at `α = 10⁻⁴`).
        ///
        /// ```
        /// use seqsmooth::polynomial::automatic::{AutomaticFilter, MisfitResponse};
        /// let f = AutomaticFilter::new(1, 0.9, 1.0).unwrap();
        /// let e = f.clone().with_misfit_response(MisfitResponse::Restart { alpha: 1.0 }).unwrap_err();
        /// assert!(e.to_string().contains("restart significance"));
        /// let flag = f.with_misfit_response(MisfitResponse::Flag).unwrap();
        /// assert_eq!(flag.config().misfit_response, MisfitResponse::Flag);
        /// ```
        with_misfit_response(response: MisfitResponse) => misfit_response = response;

        /// The number `J ≤` [`MAX_MEMORY_LEVELS`](super::MAX_MEMORY_LEVELS) of shorter memories
        /// `θ⁴, θ¹⁶, …, θ^(4^J)` the final degree may use (default 1; 0: the configured `θ` only);
        /// see [`memory`](Self::memory). A rung with `θ^(4^j) < 10⁻³` is not built (at 1: none
        /// for `θ < 0.178`; all 8 only for `θ ≥ 0.999895`). Before 2026-12-07 the ladder was
        /// `θ^(2^j)` and the most 16: 9 to 16 are now refused. A filter restored from a state
        /// saved before 2026-12-07 keeps the memories it was saved with
        /// ([`AutoConfig::memory_levels`](super::AutoConfig::memory_levels)).
        ///
        /// ```
        /// use seqsmooth::polynomial::automatic::AutomaticFilter;
        /// let f = AutomaticFilter::new(2, 0.95, 1.0).unwrap();
        /// assert_eq!(f.config().memory_levels, 1);
        /// assert_eq!(f.with_memory_levels(0).unwrap().config().memory_levels, 0);
        /// ```
        with_memory_levels(levels: usize) => memory_levels = levels;

        /// The first degree `d₀ ≤ m` of the quick-settling ladder (default 0; `m` disables it).
        ///
        /// ```
        /// use seqsmooth::polynomial::automatic::AutomaticFilter;
        /// let f = AutomaticFilter::new(2, 0.9, 1.0).unwrap();
        /// assert!(f.clone().with_start_degree(3).is_err());
        /// assert_eq!(f.with_start_degree(2).unwrap().active_degree(), 2);
        /// ```
        with_start_degree(degree: usize) => start_degree = degree;

        /// The ladder's candidate degree takes over once its current position VRF is at most
        /// `vrf > 0` (default ½) and its top derivative moved by less than its 1σ at each of
        /// `stable` updates (default 3).
        ///
        /// ```
        /// use seqsmooth::polynomial::automatic::AutomaticFilter;
        /// let f = AutomaticFilter::new(2, 0.9, 1.0).unwrap();
        /// assert!(f.clone().with_settling(0.0, 3).is_err());
        /// let c = f.with_settling(0.25, 5).unwrap().config().clone();
        /// assert_eq!((c.settle_vrf, c.settle_stable), (0.25, 5));
        /// ```
        with_settling(vrf: f64, stable: usize) => settle_vrf = vrf, settle_stable = stable;
    }
}
