//! The discount of a fading memory, one type for every filter that forgets: the polynomial
//! [`FadingMemory`](crate::FadingMemory), the fading Bayes filter
//! ([`BayesFilter::with_fading`](crate::kalman::BayesFilter::with_fading)) and the fading
//! Kalman filter ([`KalmanFilter::with_fading`](crate::kalman::KalmanFilter::with_fading)).
//!
//! A discount `θ ∈ (0, 1)` has one of two meanings, and the type names which:
//!
//! - [`Discount::PerTime`] `{ theta, tau }`: `θ` per span `τ` of time. An observation `Δt`
//!   older than the newest weighs `θ^(Δt/τ)` (Morrison's discounted least squares (13.2.1) on
//!   irregular times, Reyneke et al. §6.5; Morrison's `β^(t_n − t_k)` of (14.2.10) with
//!   `β = θ^(1/τ)`, so `β` per unit of time is `θ = β`, `τ = 1`).
//! - [`Discount::PerUpdate`] `{ theta }`: `θ` per update, whatever the spacing: the `k`-th
//!   newest observation weighs `θ^k` (Morrison (14.2.12)).
//!
//! The same names on the command line (`--theta T --tau TAU`, `--theta-per-update T`) and in
//! Python (`theta=…, tau=…`, `theta_per_update=…`); docs/names.md lists them.

use crate::error::{Error, Param};

/// A fading memory's discount: `θ` per span `τ` of time, or `θ` per update (the module docs).
/// Built by [`Discount::per_time`] and [`Discount::per_update`], which check `0 < θ < 1` and
/// `τ > 0` finite; a variant written out is checked by every filter that takes it.
///
/// ```
/// use seqsmooth::discount::Discount;
/// use seqsmooth::Error;
/// let d = Discount::per_time(0.9, 0.5).unwrap();
/// assert_eq!(d, Discount::PerTime { theta: 0.9, tau: 0.5 });
/// assert_eq!((d.theta(), d.tau()), (0.9, Some(0.5)));
/// assert_eq!(Discount::per_update(0.9).unwrap().tau(), None);
/// assert_eq!(Discount::per_update(1.0), Err(Error::ThetaOutOfRange { theta: 1.0 }));
/// assert_eq!(Discount::per_time(0.9, 0.0), Err(Error::TauOutOfRange { tau: 0.0 }));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Discount {
    /// `θ` per span `τ` of time: an observation `Δt` old weighs `θ^(Δt/τ)`.
    PerTime {
        /// The discount over one span `τ`, `0 < θ < 1`.
        theta: f64,
        /// The span of time `θ` applies to, in the times' units, `τ > 0`.
        tau: f64,
    },
    /// `θ` per update: the `k`-th newest observation weighs `θ^k`, whatever the spacing.
    PerUpdate {
        /// The discount per update, `0 < θ < 1`.
        theta: f64,
    },
}

/// Which of [`Discount`]'s two meanings, where `θ` and `τ` are given apart from it (the
/// automatic filter's [`with_discount_mode`](crate::polynomial::automatic::AutomaticFilter)).
///
/// ```
/// use seqsmooth::discount::{Discount, DiscountMode};
/// assert_eq!(DiscountMode::default(), DiscountMode::PerTime);
/// assert_eq!(Discount::per_update(0.5).unwrap().mode(), DiscountMode::PerUpdate);
/// assert_eq!(DiscountMode::PerTime.with(0.9, 2.0).unwrap(), Discount::PerTime { theta: 0.9, tau: 2.0 });
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum DiscountMode {
    /// [`Discount::PerTime`]: `θ` per `τ` of elapsed time, weight `θ^((t_n - t_k)/τ)`.
    #[default]
    PerTime,
    /// [`Discount::PerUpdate`]: `θ` per sample whatever the spacing, weight `θ^(n-k)`.
    PerUpdate,
}

impl DiscountMode {
    /// The checked discount of this meaning: `θ` per `τ`, or `θ` per update (`τ` unused).
    pub fn with(self, theta: f64, tau: f64) -> Result<Discount, Error> {
        match self {
            DiscountMode::PerTime => Discount::per_time(theta, tau),
            DiscountMode::PerUpdate => Discount::per_update(theta),
        }
    }
}

impl Discount {
    /// `θ` per span `τ` of time, checked: `0 < θ < 1`, `τ > 0` finite.
    pub fn per_time(theta: f64, tau: f64) -> Result<Self, Error> {
        Self::PerTime { theta, tau }.checked()
    }

    /// `θ` per update, checked: `0 < θ < 1`.
    pub fn per_update(theta: f64) -> Result<Self, Error> {
        Self::PerUpdate { theta }.checked()
    }

    /// The discount as the front ends name it: `theta` with `tau` (per span of time) or
    /// `theta_per_update`, at most one of the two; `None` for none. `theta` without `tau` is
    /// refused (naming both), as is `tau` alone.
    ///
    /// ```
    /// use seqsmooth::discount::Discount;
    /// assert_eq!(Discount::from_names(Some(0.9), Some(2.0), None).unwrap(),
    ///            Some(Discount::PerTime { theta: 0.9, tau: 2.0 }));
    /// assert_eq!(Discount::from_names(None, None, Some(0.9)).unwrap(),
    ///            Some(Discount::PerUpdate { theta: 0.9 }));
    /// assert_eq!(Discount::from_names(None, None, None).unwrap(), None);
    /// assert!(Discount::from_names(Some(0.9), None, None).is_err());
    /// assert!(Discount::from_names(Some(0.9), Some(1.0), Some(0.9)).is_err());
    /// ```
    pub fn from_names(
        theta: Option<f64>,
        tau: Option<f64>,
        theta_per_update: Option<f64>,
    ) -> Result<Option<Self>, Error> {
        let refuse = |value: String, reason: &str| {
            Err(Error::InvalidParameter {
                name: Param::Discount,
                value,
                reason: reason.into(),
            })
        };
        match (theta, tau, theta_per_update) {
            (None, None, None) => Ok(None),
            (Some(theta), Some(tau), None) => Self::per_time(theta, tau).map(Some),
            (None, None, Some(theta)) => Self::per_update(theta).map(Some),
            (Some(theta), None, None) => refuse(
                format!("theta {theta} without tau"),
                "theta is the discount per span tau of time: give tau too, or give \
                 theta_per_update for a discount per update",
            ),
            (None, Some(tau), None) => refuse(
                format!("tau {tau} without theta"),
                "tau is the span of time theta applies to: give theta too",
            ),
            (_, _, Some(_)) => refuse(
                "theta and theta_per_update".into(),
                "give one discount: theta with tau (per span of time), or theta_per_update",
            ),
        }
    }

    /// `θ`, whichever the meaning.
    pub fn theta(self) -> f64 {
        match self {
            Discount::PerTime { theta, .. } | Discount::PerUpdate { theta } => theta,
        }
    }

    /// `τ` of a discount per span of time; `None` per update.
    pub fn tau(self) -> Option<f64> {
        match self {
            Discount::PerTime { tau, .. } => Some(tau),
            Discount::PerUpdate { .. } => None,
        }
    }

    /// Which meaning.
    pub fn mode(self) -> DiscountMode {
        match self {
            Discount::PerTime { .. } => DiscountMode::PerTime,
            Discount::PerUpdate { .. } => DiscountMode::PerUpdate,
        }
    }

    /// The same meaning with another `θ`, checked.
    pub fn with_theta(self, theta: f64) -> Result<Self, Error> {
        match self {
            Discount::PerTime { tau, .. } => Self::per_time(theta, tau),
            Discount::PerUpdate { .. } => Self::per_update(theta),
        }
    }

    /// Refuses `θ` outside `(0, 1)` ([`Error::ThetaOutOfRange`]) and `τ` not positive and
    /// finite ([`Error::TauOutOfRange`]).
    pub fn checked(self) -> Result<Self, Error> {
        check_theta(self.theta())?;
        if let Some(tau) = self.tau() {
            check_tau(tau)?;
        }
        Ok(self)
    }

    /// The factor `f ∈ (0, 1)` the information so far is multiplied by at an update `elapsed`
    /// after the previous one: `θ^(|elapsed|/τ)` or `θ`. Refused when it underflows.
    pub(crate) fn factor_over(self, elapsed: f64) -> Result<f64, Error> {
        let f = match self {
            Discount::PerTime { theta, tau } => theta.powf(elapsed.abs() / tau),
            Discount::PerUpdate { theta } => theta,
        };
        if f > 0.0 && f.is_normal() {
            Ok(f)
        } else {
            Err(Error::InvalidParameter {
                name: Param::DiscountOverStep,
                value: format!("{f:e} over {elapsed} since the last update"),
                reason: "underflows: the memory holds nothing; raise theta or tau, or update \
                         more often"
                    .into(),
            })
        }
    }
}

/// The range of a fading memory's discount `θ` in doubles: `0 < θ < 1` ([`check_theta_of`]).
///
/// ```
/// use seqsmooth::discount::check_theta;
/// assert!(check_theta(0.9).is_ok() && check_theta(1.0).is_err() && check_theta(0.0).is_err());
/// ```
pub fn check_theta(theta: f64) -> Result<(), Error> {
    check_theta_of(&theta)
}

/// The range of a discount `θ` of any scalar (exact for the tables, Morrison (13.1.1)):
/// `0 < θ < 1`; the error holds `θ` rounded to a double.
///
/// ```
/// use seqsmooth::discount::check_theta_of;
/// use seqsmooth::scalar::parse_rational;
/// assert!(check_theta_of(&parse_rational("9/10").unwrap()).is_ok());
/// assert!(check_theta_of(&parse_rational("1").unwrap()).is_err());
/// assert!(check_theta_of(&0.0_f64).is_err());
/// ```
pub fn check_theta_of<T: crate::scalar::Scalar>(theta: &T) -> Result<(), Error> {
    if !(*theta > T::zero() && *theta < T::one()) {
        return Err(Error::ThetaOutOfRange {
            theta: theta.to_f64(),
        });
    }
    Ok(())
}

/// The range of the time `τ` a discount applies to: positive and finite.
///
/// ```
/// use seqsmooth::discount::check_tau;
/// assert!(check_tau(0.5).is_ok() && check_tau(0.0).is_err() && check_tau(f64::INFINITY).is_err());
/// ```
pub fn check_tau(tau: f64) -> Result<(), Error> {
    if !(tau.is_finite() && tau > 0.0) {
        return Err(Error::TauOutOfRange { tau });
    }
    Ok(())
}
