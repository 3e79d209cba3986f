//! A filter saved with its models left out: a front end's own dynamic and observation models
//! (Python callables) have no saved form, so a filter over them is saved over these data-less
//! stand-ins ([`KalmanFilter::with_models`](crate::kalman::KalmanFilter::with_models)) — the
//! state, covariance, time and the library's driving noise inside the checksum, the models'
//! dimensions and angle components with them — and restored over the front end's models
//! again, rebuilt from what it keeps beside the bytes. A stand-in cannot be run: every use is
//! refused.

use super::SavedModel;
use crate::error::{Error, Param};
use crate::model::dynamics::{Dynamics, Propagation};
use crate::model::observation::{Angles, Observation, Predicted};
use nalgebra::DVector;
use serde::{Deserialize, Serialize};

/// The largest state or observation a stand-in takes (a decoded count is checked against it).
const MOST: usize = 1 << 12;

/// The refusal of running a stand-in.
fn left_out(what: &str) -> Error {
    Error::InvalidParameter {
        name: Param::ObservationModel,
        value: format!("the {what} left out of a saved filter"),
        reason: "restore the filter over its own models (with_models) before running it".into(),
    }
}

/// The dynamic model of `states` states, left out of a saved filter.
///
/// ```
/// use nalgebra::DVector;
/// use seqsmooth::model::dynamics::Dynamics;
/// use seqsmooth::persist::DynamicsLeftOut;
/// let d = DynamicsLeftOut::new(2);
/// assert_eq!(d.dimension(), 2);
/// assert!(d.propagate(&DVector::zeros(2), 0.0, 1.0).is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct DynamicsLeftOut {
    states: usize,
}

impl DynamicsLeftOut {
    /// The stand-in of a dynamic model of `states` states.
    pub fn new(states: usize) -> Self {
        Self { states }
    }
}

impl Dynamics for DynamicsLeftOut {
    fn dimension(&self) -> usize {
        self.states
    }

    fn propagate(&self, _: &DVector<f64>, _: f64, _: f64) -> Result<Propagation, Error> {
        Err(left_out("dynamic model"))
    }
}

impl SavedModel for DynamicsLeftOut {
    const MODEL: &'static str = "DynamicsLeftOut";

    fn check_model(&self) -> Result<(), String> {
        if self.states == 0 || self.states > MOST {
            return Err(format!("dynamics of {} states", self.states));
        }
        Ok(())
    }
}

/// The observation model of `states` states, left out of a saved filter: its components and
/// which are angles ([`Angles`]: a residual is wrapped, so the stand-in's
/// [`Observation::residual`] is the model's).
///
/// ```
/// use nalgebra::DVector;
/// use seqsmooth::model::observation::{Angles, Observation};
/// use seqsmooth::persist::ObservationLeftOut;
/// let o = ObservationLeftOut::new(4, Angles::new(2, &[1]).unwrap());
/// assert_eq!((o.components(), o.state_dimension()), (2, 4));
/// assert_eq!(o.angles().indices(), vec![1]);
/// assert!(o.predict(&DVector::zeros(4), 0.0).is_err());
/// ```
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ObservationLeftOut {
    states: usize,
    angles: Angles,
}

impl ObservationLeftOut {
    /// The stand-in of an observation of `states` states and `angles.components()`
    /// components, `angles` its angle components.
    pub fn new(states: usize, angles: Angles) -> Self {
        Self { states, angles }
    }

    /// Its components' angles.
    pub fn angles(&self) -> &Angles {
        &self.angles
    }
}

impl Observation for ObservationLeftOut {
    fn components(&self) -> usize {
        self.angles.components()
    }

    fn state_dimension(&self) -> usize {
        self.states
    }

    fn predict(&self, _: &DVector<f64>, _: f64) -> Result<Predicted, Error> {
        Err(left_out("observation model"))
    }

    fn residual(&self, component: usize, measured: f64, predicted: f64) -> f64 {
        self.angles.residual(component, measured, predicted)
    }
}

impl SavedModel for ObservationLeftOut {
    const MODEL: &'static str = "ObservationLeftOut";

    fn check_model(&self) -> Result<(), String> {
        let p = self.angles.components();
        if p == 0 || p > MOST || self.states == 0 || self.states > MOST {
            return Err(format!(
                "observation of {p} components of {} states",
                self.states
            ));
        }
        Ok(())
    }
}
