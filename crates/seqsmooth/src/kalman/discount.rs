//! The generalized fading memory's discount over a step (Morrison ch. 14), shared by the
//! fading Bayes and fading Kalman filters: `β^(t_n − t_(n−1))` per unit of time (14.2.10) or
//! `θ` per update (14.2.12).

use super::filter::Discount;
use crate::error::{Error, Param};

impl Discount {
    /// Refuses a discount outside `(0, 1]`.
    pub(crate) fn checked(self) -> Result<Self, Error> {
        let (name, value) = match self {
            Discount::PerTime(b) => (Param::Beta, b),
            Discount::PerUpdate(t) => (Param::Theta, t),
        };
        if value > 0.0 && value <= 1.0 {
            Ok(self)
        } else {
            Err(Error::InvalidParameter {
                name,
                value: value.to_string(),
                reason: "the discount must lie in (0, 1]".into(),
            })
        }
    }

    /// The factor `f ∈ (0, 1]` the information so far is multiplied by at an update `elapsed`
    /// after the previous one: `β^|elapsed|` or `θ`. Refused when it underflows.
    pub(crate) fn factor_over(self, elapsed: f64) -> Result<f64, Error> {
        let f = match self {
            Discount::PerTime(beta) => beta.powf(elapsed.abs()),
            Discount::PerUpdate(theta) => theta,
        };
        if f > 0.0 && f.is_normal() {
            Ok(f)
        } else {
            Err(Error::InvalidParameter {
                name: Param::DiscountOverStep,
                value: format!("{f:e} over {elapsed} since the last update"),
                reason: "underflows: the memory holds nothing; raise beta or update more often"
                    .into(),
            })
        }
    }
}
