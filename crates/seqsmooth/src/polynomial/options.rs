//! The shared vocabulary of the expanding- and fading-memory filters: which [`Engine`] a filter
//! runs on, how fading memory discounts ([`DiscountMode`], the tag of [`Discount`]), the largest degree, and the checks of
//! their parameters.

use crate::error::{Error, Param};

/// The largest degree the filters accept. The exact engine's accuracy against an independent
/// batch QR fit is measured in the tests up to this degree.
///
/// ```
/// use seqsmooth::polynomial::MAX_DEGREE;
/// use seqsmooth::{Engine, Error, ExpandingMemory};
/// assert!(ExpandingMemory::new(MAX_DEGREE, Engine::Exact).is_ok());
/// assert!(matches!(ExpandingMemory::new(MAX_DEGREE + 1, Engine::Exact), Err(Error::DegreeOutOfRange { .. })));
/// ```
pub const MAX_DEGREE: usize = 24;

// The noise estimators take differences of order up to `m + 1` for every degree the filters take.
const _: () = assert!(crate::stats::MAX_DIFFERENCE_ORDER == MAX_DEGREE + 1);

/// Which computation a filter uses (see the [module docs](crate::polynomial)).
///
/// ```
/// use seqsmooth::{Engine, ExpandingMemory, PolynomialFilter};
/// assert_eq!(Engine::default(), Engine::Exact);
/// // on even samples both engines are exact least squares
/// for engine in [Engine::Exact, Engine::Gain] {
///     let mut f = ExpandingMemory::new(1, engine).unwrap();
///     for n in 0..10 { f.update(n as f64, 2.0 * n as f64).unwrap(); }
///     assert!((f.estimate().unwrap().derivatives[1] - 2.0).abs() < 1e-12);
/// }
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum Engine {
    /// Recursive least squares, exact on any timestamps.
    #[default]
    Exact,
    /// Fixed-gain recursion, exact on evenly spaced samples.
    Gain,
}

/// How a fading-memory filter discounts old samples: the tag of the one [`Discount`] type of
/// every fading memory (defined in [`crate::discount`]).
///
/// ```
/// use seqsmooth::{DiscountMode, Engine, FadingMemory, PolynomialFilter};
/// assert_eq!(DiscountMode::default(), DiscountMode::PerTime);
/// let mut f = FadingMemory::new(0, 0.5, 1.0, Engine::Exact).unwrap()
///     .with_discount_mode(DiscountMode::PerUpdate).unwrap();
/// for (t, y) in [(0.0, 0.0), (10.0, 3.0)] { f.update(t, y).unwrap(); }
/// // weights 1/2 and 1 whatever the gap: (0·½ + 3·1)/(½ + 1) = 2
/// assert!((f.estimate().unwrap().derivatives[0] - 2.0).abs() < 1e-12);
/// ```
pub use crate::discount::{Discount, DiscountMode};

/// The highest degree of the gain engine and of the banks, which run the same fixed-gain
/// recursion (Morrison Tables 9.1, 13.1). The recursion's transition `(I − h e₀ᵀ) Φ` has one
/// eigenvalue of multiplicity `m+1` (at 0 or θ), so a perturbation of size `δ` — the rounding
/// of the gains, or a step that differs from the one the gains are scaled for — moves its
/// eigenvalues by about `δ^(1/(m+1))`: at high degree even a small irregularity pushes them out
/// of the unit circle and the estimate diverges. Measured against the exact engine (ACCURACY.md,
/// "The gain engine's degree bound"), on steps jittered by ±20%, in units of the exact
/// estimate's σ, median and largest over 10 seeds: at degree 10 0.5σ and 6.5σ (expanding
/// memory; at 8 0.15σ and 0.7σ), at 12 4σ and 36σ, at 14 63σ and 1.6e3σ, at 16 6.6e3σ and
/// 7.8e5σ, growing without bound (fading memory, θ = 0.99: 1.1σ at 10, 120σ at 12).
///
/// ```
/// use seqsmooth::polynomial::GAIN_MAX_DEGREE;
/// use seqsmooth::{Engine, Error, ExpandingMemory};
/// assert!(ExpandingMemory::new(GAIN_MAX_DEGREE, Engine::Gain).is_ok());
/// assert!(ExpandingMemory::new(GAIN_MAX_DEGREE + 1, Engine::Exact).is_ok());
/// assert!(matches!(
///     ExpandingMemory::new(GAIN_MAX_DEGREE + 1, Engine::Gain),
///     Err(Error::GainDegreeOutOfRange { degree: 11, max: 10 })
/// ));
/// ```
pub const GAIN_MAX_DEGREE: usize = 10;

/// The largest sample magnitude the gain engine accepts, 2^960 (about 9.7e288): its state is
/// carried in double words, whose error-free product (Dekker's) splits each operand and needs
/// it below 2^996; the state's coefficients stay within a few thousand times the values'
/// magnitude at every supported degree. The exact engine has no such limit.
///
/// ```
/// use seqsmooth::polynomial::GAIN_MAX_VALUE;
/// use seqsmooth::{Engine, Error, ExpandingMemory, PolynomialFilter};
/// let mut f = ExpandingMemory::new(1, Engine::Gain).unwrap();
/// assert!(matches!(f.update(0.0, 1e300), Err(Error::GainValueOutOfRange { .. })));
/// assert!(f.update(0.0, GAIN_MAX_VALUE).is_ok());
/// assert_eq!(GAIN_MAX_VALUE, 2f64.powi(960));
/// ```
pub const GAIN_MAX_VALUE: f64 = 9.7453140114e288;

/// [`check_degree`], and for the gain engine [`GAIN_MAX_DEGREE`].
pub(crate) fn check_engine_degree(m: usize, engine: Engine) -> Result<(), Error> {
    check_degree(m)?;
    if engine == Engine::Gain && m > GAIN_MAX_DEGREE {
        return Err(Error::GainDegreeOutOfRange {
            degree: m,
            max: GAIN_MAX_DEGREE,
        });
    }
    Ok(())
}

/// The polynomial degree's range: `m ≤ MAX_DEGREE` (every front end's check).
///
/// ```
/// use seqsmooth::polynomial::{check_degree, MAX_DEGREE};
/// assert!(check_degree(MAX_DEGREE).is_ok() && check_degree(MAX_DEGREE + 1).is_err());
/// ```
pub fn check_degree(m: usize) -> Result<(), Error> {
    crate::error::check_degree_at_most(m, MAX_DEGREE)
}

/// The polynomial model of degree `m` on `axes` axes (the Kalman, Bayes and unscented filters'
/// `PolynomialDynamics`): `m ≤ MAX_DEGREE` ([`check_degree`]), at least one axis; its number
/// of states `(m + 1) · axes`.
///
/// ```
/// use seqsmooth::polynomial::{check_model, MAX_DEGREE};
/// assert_eq!(check_model(1, 3).unwrap(), 6);
/// assert!(check_model(1, 0).is_err() && check_model(MAX_DEGREE + 1, 1).is_err());
/// assert!(check_model(2, usize::MAX).is_err()); // its states would not fit a usize
/// ```
pub fn check_model(m: usize, axes: usize) -> Result<usize, Error> {
    check_degree(m)?;
    let refuse = |reason: &str| Error::InvalidParameter {
        name: Param::Axes,
        value: axes.to_string(),
        reason: reason.into(),
    };
    if axes == 0 {
        return Err(refuse("at least 1"));
    }
    (m + 1)
        .checked_mul(axes)
        .ok_or_else(|| refuse("too many: the model's states must fit in memory"))
}

/// The range of a derivative `k` asked of a filter's estimate without its degree at hand (the
/// command's `plot --derivative`): `k ≤ MAX_DEGREE`, as no filter estimates more.
///
/// ```
/// use seqsmooth::polynomial::{check_derivative, MAX_DEGREE};
/// assert!(check_derivative(MAX_DEGREE).is_ok() && check_derivative(MAX_DEGREE + 1).is_err());
/// ```
pub fn check_derivative(k: usize) -> Result<(), Error> {
    if k > MAX_DEGREE {
        return Err(Error::InvalidParameter {
            name: Param::Derivative,
            value: k.to_string(),
            reason: format!("at most {MAX_DEGREE}, the largest supported degree"),
        });
    }
    Ok(())
}

/// The range of a lead `H` in time units (an estimate at `t + H`; negative: retrodiction):
/// finite. The row runner's check ([`crate::polynomial::rows`]) and the command's `--lead`.
///
/// ```
/// use seqsmooth::polynomial::check_lead;
/// assert!(check_lead(-2.5).is_ok() && check_lead(f64::INFINITY).is_err() && check_lead(f64::NAN).is_err());
/// ```
pub fn check_lead(lead: f64) -> Result<(), Error> {
    if !lead.is_finite() {
        return Err(Error::InvalidParameter {
            name: Param::Lead,
            value: lead.to_string(),
            reason: "must be a finite number".into(),
        });
    }
    Ok(())
}

pub use crate::discount::{check_tau, check_theta, check_theta_of};

/// The measurement noise's 1σ: a positive finite number whose variance `σ²` is a normal,
/// finite double (`1.5e-154 ≲ σ ≲ 1.3e154`): below, the variance is zero or subnormal and the
/// innovation statistics that divide by it are meaningless; above, it is infinite. Such values
/// want rescaling (other units), not a filter. (Inside the range a covariance `σ² · VRF`,
/// scaled by `k!/τ^k`, can still leave the double range at extreme scales.)
pub(crate) fn check_noise_sigma(sigma: f64) -> Result<(), Error> {
    if crate::model::measurement::is_usable_sigma(sigma) {
        return Ok(());
    }
    let reason = if sigma.is_finite() && sigma > 0.0 {
        "its square (the noise variance) is not a normal double: it must lie between about \
         1.5e-154 and 1.3e154; rescale the values (e.g. to other units)"
    } else {
        "must be a positive finite number"
    };
    Err(Error::InvalidParameter {
        name: Param::NoiseSigma,
        // `{:?}`: 1e-300 as such, not as 300 digits.
        value: format!("{sigma:?}"),
        reason: reason.into(),
    })
}

/// Settings are fixed once a filter has taken its first sample: an error naming `what` to set
/// before the first update when `started`.
pub(crate) fn check_not_started(started: bool, what: &str) -> Result<(), Error> {
    if started {
        return Err(Error::InvalidParameter {
            name: Param::Configuration,
            value: "change after the first sample".into(),
            reason: format!("set {what} before the first update"),
        });
    }
    Ok(())
}
