//! The [`Persist`] impls of the library's filters: each type's name and the invariants of a
//! decoded value (each checked by the type's own `check_saved`, next to its fields).

use super::Persist;
use crate::estimate::sliding::{Fitter, RowNoise};
use crate::kalman::bayes::BayesFilter;
use crate::kalman::discrete::{DiscreteDynamics, LinearFixedLag, LinearKalmanFilter};
use crate::kalman::filter::{IterationLimits, KalmanFilter};
use crate::kalman::fixed_lag::FixedLagSmoother;
use crate::kalman::unscented::UnscentedKalmanFilter;
use crate::model::continuous::ContinuousModel;
use crate::model::dynamics::{Dynamics, PolynomialDynamics};
use crate::model::measurement::NoiseCovariance;
use crate::model::observation::{LinearObservation, Observation};
use crate::model::radar::Radar;
use crate::paml::{OnlineSmoother, SmootherGains};
use crate::polynomial::automatic::AutomaticFilter;
use crate::polynomial::bank::{ExpandingBank, FadingBank};
use crate::polynomial::merge::Information;
use crate::polynomial::spec::{AnyFilter, FilterKind, Inner};
use crate::polynomial::PolynomialFilter;
use crate::track::RadarTracker;
use crate::{ExpandingMemory, FadingMemory, FixedMemory};
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::ops::Deref;

/// A dynamic or observation model a saved Kalman filter holds: its name in the envelope and
/// the invariants of its data. A front end's own model (Python callables) implements it with
/// no data of its own and is supplied again on restoring.
pub trait SavedModel {
    /// The model's name.
    const MODEL: &'static str;

    /// Why the model's data cannot be used, or nothing.
    fn check_model(&self) -> Result<(), String> {
        Ok(())
    }
}

impl SavedModel for PolynomialDynamics {
    const MODEL: &'static str = "PolynomialDynamics";

    fn check_model(&self) -> Result<(), String> {
        let n = self.dimension();
        if n == 0 || n > 1 << 12 {
            return Err(format!("motion model of {n} states"));
        }
        Ok(())
    }
}

impl SavedModel for LinearObservation {
    const MODEL: &'static str = "LinearObservation";

    fn check_model(&self) -> Result<(), String> {
        let m = self.matrix();
        crate::linalg::invariant::matrix(m, m.nrows(), m.ncols(), "observation matrix")
    }
}

impl SavedModel for DiscreteDynamics {
    const MODEL: &'static str = "DiscreteDynamics";

    fn check_model(&self) -> Result<(), String> {
        let f = self.transition();
        crate::linalg::invariant::matrix(f, f.nrows(), f.nrows(), "transition matrix")
    }
}

impl SavedModel for ContinuousModel {
    const MODEL: &'static str = "ContinuousModel";

    /// The model built again from its `A` and `Q_c` by [`ContinuousModel::new`] (all its
    /// checks) must be the saved one, its `‖A‖₁` included.
    fn check_model(&self) -> Result<(), String> {
        let again = ContinuousModel::new(
            self.dynamics().matrix().clone(),
            self.spectral_density().clone(),
        )
        .map_err(|e| format!("continuous model: {e}"))?;
        if again != *self {
            return Err("continuous model does not match its A and Qc".into());
        }
        Ok(())
    }
}

impl SavedModel for Radar {
    const MODEL: &'static str = "Radar";
}

/// The models' own checks, and that the observation is of the dynamics' states.
fn models<D: SavedModel + Dynamics, O: SavedModel + Observation>(
    (d, o): (&D, &O),
) -> Result<(), String> {
    d.check_model()?;
    o.check_model()?;
    if o.components() == 0 {
        return Err("observation of no components".into());
    }
    if o.state_dimension() != d.dimension() {
        return Err(format!(
            "observation of {} states, dynamics of {}",
            o.state_dimension(),
            d.dimension()
        ));
    }
    Ok(())
}

/// [`Persist`] for a filter generic over its models: the name with the models', the checks
/// after the models'.
macro_rules! persist_over_models {
    ($ty:ident, $name:literal, |$f:ident| $check:expr) => {
        impl<D, O> Persist for $ty<D, O>
        where
            D: Dynamics + SavedModel + Serialize + DeserializeOwned,
            O: Observation + SavedModel + Serialize + DeserializeOwned,
        {
            fn name() -> String {
                format!(concat!($name, "<{}, {}>"), D::MODEL, O::MODEL)
            }

            fn check(&mut self) -> Result<(), String> {
                let $f = self;
                $check
            }
        }
    };
}

persist_over_models!(KalmanFilter, "KalmanFilter", |f| {
    models(f.models())?;
    f.check_saved()
});
persist_over_models!(BayesFilter, "BayesFilter", |f| {
    models(f.models())?;
    f.check_saved()
});
persist_over_models!(UnscentedKalmanFilter, "UnscentedKalmanFilter", |f| {
    models(f.models())?;
    f.check_saved()
});
persist_over_models!(FixedLagSmoother, "FixedLagSmoother", |f| {
    models(f.models())?;
    f.check_saved()
});

/// [`Persist`] for a type of its own name whose checks are its `check_saved`.
macro_rules! persist_plain {
    ($($ty:ty => $name:literal),* $(,)?) => {$(
        impl Persist for $ty {
            fn name() -> String {
                $name.into()
            }

            fn check(&mut self) -> Result<(), String> {
                self.check_saved()
            }
        }
    )*};
}

persist_plain!(
    ExpandingMemory => "ExpandingMemory",
    FadingMemory => "FadingMemory",
    FixedMemory => "FixedMemory",
    AutomaticFilter => "AutomaticFilter",
    FadingBank => "FadingBank",
    ExpandingBank => "ExpandingBank",
    LinearKalmanFilter => "LinearKalmanFilter",
    LinearFixedLag => "LinearFixedLag",
    RadarTracker => "RadarTracker",
    Information => "Information",
    Fitter => "SlidingFit",
);

impl<G> Persist for OnlineSmoother<G>
where
    G: Deref<Target = SmootherGains> + Serialize + DeserializeOwned,
{
    fn name() -> String {
        "OnlineSmoother".into()
    }

    fn check(&mut self) -> Result<(), String> {
        self.check_saved()
    }
}

impl Persist for AnyFilter {
    fn name() -> String {
        "AnyFilter".into()
    }

    fn check(&mut self) -> Result<(), String> {
        let kind = match &self.inner {
            Inner::Expanding(f) => f.check_saved().map(|_| FilterKind::Expanding),
            Inner::Fading(f) => f.check_saved().map(|_| FilterKind::Fading),
            Inner::Fixed(f, w) => f.check_saved().and_then(|_| {
                if f.window() == *w {
                    Ok(FilterKind::Fixed)
                } else {
                    Err(format!("window {w} is not the filter's {}", f.window()))
                }
            }),
            Inner::Automatic(f) => f.check_saved().map(|_| FilterKind::Automatic),
        }?;
        if kind != self.kind() || self.rows < self.samples() {
            return Err("kind or row count does not match the filter".into());
        }
        Ok(())
    }
}

/// What a front end holds beside a saved filter (its constant measurement noise, an update's
/// limits), saved inside the filter's checksum so that a damaged one is refused like the
/// filter: its name in the envelope and the checks of a decoded value.
pub trait Beside: Serialize + DeserializeOwned {
    /// The name written after the filter's.
    fn name() -> String;

    /// Why the decoded value cannot be used, or nothing.
    fn check_beside(&self) -> Result<(), String>;
}

/// A filter with what a front end holds beside it: the filter's checks, then its
/// companion's.
impl<T: Persist, B: Beside> Persist for (T, B) {
    fn name() -> String {
        format!("({}, {})", T::name(), B::name())
    }

    fn check(&mut self) -> Result<(), String> {
        self.0.check()?;
        self.1.check_beside()
    }
}

/// The constant measurement noise `R`: finite, symmetric positive semidefinite (the
/// constructors' rule, [`check_covariance`](crate::kalman::noise::check_covariance)).
impl Beside for NoiseCovariance {
    fn name() -> String {
        "NoiseCovariance".into()
    }

    fn check_beside(&self) -> Result<(), String> {
        let invalid = |e: crate::Error| format!("measurement noise R: {e}");
        match self {
            NoiseCovariance::Identity => Ok(()),
            NoiseCovariance::Variances(v) => {
                let m = nalgebra::DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(v));
                crate::kalman::noise::check_covariance(&m, v.len(), crate::Param::MeasurementNoiseR)
                    .map_err(invalid)
            }
            NoiseCovariance::Full(m) => crate::kalman::noise::check_covariance(
                m,
                m.nrows(),
                crate::Param::MeasurementNoiseR,
            )
            .map_err(invalid),
        }
    }
}

/// The iterated update's limits, in [`check_iteration_limits`](crate::kalman::filter::check_iteration_limits)'s range.
impl Beside for IterationLimits {
    fn name() -> String {
        "IterationLimits".into()
    }

    fn check_beside(&self) -> Result<(), String> {
        self.check().map_err(|e| format!("iteration limits: {e}"))
    }
}

/// A sliding fit's row noise, its σ usable ([`RowNoise::check`]).
impl Beside for RowNoise {
    fn name() -> String {
        "RowNoise".into()
    }

    fn check_beside(&self) -> Result<(), String> {
        self.check()
    }
}
