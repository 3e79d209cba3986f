//! The shared vocabulary of the expanding- and fading-memory filters: which [`Engine`] a filter
//! runs on, how fading memory discounts ([`DiscountMode`]), the largest degree, and the checks of
//! their parameters.

use crate::error::Error;

/// The largest degree the filters accept. The exact engine's accuracy against an independent
/// batch QR fit is measured in the tests up to this degree.
pub const MAX_DEGREE: usize = 24;

/// Which computation a filter uses (see the [module docs](self)).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Engine {
    /// Recursive least squares, exact on any timestamps.
    #[default]
    Exact,
    /// Fixed-gain recursion, exact on evenly spaced samples.
    Gain,
}

/// How a fading-memory filter discounts old samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum DiscountMode {
    /// By `θ` per `τ` of elapsed time: weight `θ^((t_n - t_k)/τ)` (`θ_eff = θ^ζ` per update).
    #[default]
    PerTime,
    /// By `θ` per sample whatever the spacing: weight `θ^(n-k)`.
    PerUpdate,
}

pub(crate) fn check_degree(m: usize) -> Result<(), Error> {
    if m > MAX_DEGREE {
        return Err(Error::DegreeOutOfRange {
            degree: m,
            max: MAX_DEGREE,
        });
    }
    Ok(())
}

pub(crate) fn check_tau(tau: f64) -> Result<(), Error> {
    if !(tau.is_finite() && tau > 0.0) {
        return Err(Error::TauOutOfRange { tau });
    }
    Ok(())
}

pub(crate) fn check_theta(theta: f64) -> Result<(), Error> {
    if !(theta > 0.0 && theta < 1.0) {
        return Err(Error::ThetaOutOfRange { theta });
    }
    Ok(())
}

/// Settings are fixed once a filter has taken its first sample: an error naming `what` to set
/// before the first update when `started`.
pub(crate) fn check_not_started(started: bool, what: &str) -> Result<(), Error> {
    if started {
        return Err(Error::InvalidParameter {
            name: "configuration",
            value: "change after the first sample".into(),
            reason: format!("set {what} before the first update"),
        });
    }
    Ok(())
}
