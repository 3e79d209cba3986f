//! A restored Kalman filter's checks ([`crate::persist`]): the invariants its saved state must
//! hold before it is handed out.

use super::{KalmanFilter, Work};
use crate::error::{Error, Param};
use crate::kalman::noise::ProcessNoise;
use crate::model::dynamics::Dynamics;
use crate::model::observation::Observation;
use std::sync::Arc;

/// Whether `(dynamics, observation)` can stand in for `(d, o)`: the same states and
/// components, else the error naming the observation model.
pub(crate) fn same_shape(
    (d, o): (&impl Dynamics, &impl Observation),
    dynamics: &impl Dynamics,
    observation: &impl Observation,
) -> Result<(), Error> {
    let (n, p) = (d.dimension(), o.components());
    let (n2, p2) = (dynamics.dimension(), observation.components());
    if n2 != n || p2 != p || observation.state_dimension() != n {
        return Err(Error::InvalidParameter {
            name: Param::ObservationModel,
            value: format!("{n2} states, {p2} components"),
            reason: format!("the filter's models have {n} states, {p} components"),
        });
    }
    Ok(())
}

impl<D: Dynamics, O: Observation> KalmanFilter<D, O> {
    /// The dynamic and observation models.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::KalmanFilter;
    /// use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
    /// use seqsmooth::model::observation::{LinearObservation, Observation};
    /// let f = KalmanFilter::new(PolynomialDynamics::new(1, 1), LinearObservation::value_of(2),
    ///     DVector::zeros(2), DMatrix::identity(2, 2), 0.0).unwrap();
    /// assert_eq!((f.models().0.dimension(), f.models().1.components()), (2, 1));
    /// ```
    pub fn models(&self) -> (&D, &O) {
        (&self.dynamics, &self.observation)
    }

    /// The filter over the models `dynamics` and `observation` in place of its own (the same
    /// states and components, else refused), its estimate, time, driving noise and fading
    /// memory kept: how a filter over a front end's own models (Python callables, which have
    /// no saved form) is saved over the data-less
    /// [`DynamicsLeftOut`](crate::persist::DynamicsLeftOut) and
    /// [`ObservationLeftOut`](crate::persist::ObservationLeftOut), and restored over its own
    /// models again ([`crate::persist`]).
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::KalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::{Angles, LinearObservation};
    /// use seqsmooth::persist::{from_bytes, to_bytes, DynamicsLeftOut, ObservationLeftOut};
    /// let (d, o) = (PolynomialDynamics::new(1, 1), LinearObservation::value_of(2));
    /// let f = KalmanFilter::new(d, o.clone(), DVector::zeros(2), DMatrix::identity(2, 2), 0.0)?;
    /// let bare = f.clone().with_models(DynamicsLeftOut::new(2), ObservationLeftOut::new(2, Angles::new(1, &[])?))?;
    /// let back: KalmanFilter<DynamicsLeftOut, ObservationLeftOut> = from_bytes(&to_bytes(&bare)?)?;
    /// let g = back.with_models(d, o)?;
    /// assert_eq!(g.covariance(), f.covariance());
    /// assert!(g.with_models(PolynomialDynamics::new(2, 1), LinearObservation::value_of(3)).is_err());
    /// # Ok::<(), seqsmooth::Error>(())
    /// ```
    pub fn with_models<D2: Dynamics, O2: Observation>(
        self,
        dynamics: D2,
        observation: O2,
    ) -> Result<KalmanFilter<D2, O2>, Error> {
        same_shape(self.models(), &dynamics, &observation)?;
        Ok(KalmanFilter {
            dynamics,
            observation,
            noise: self.noise,
            fading: self.fading,
            state: self.state,
            covariance: self.covariance,
            time: self.time,
            work: self.work,
            plan: super::Plan::Unknown,
        })
    }

    /// The driving-noise model taken out (the filter has none after): a model of the
    /// caller's own, which has no saved form, is taken out before saving and set again on
    /// restoring ([`Self::set_process_noise`]).
    pub fn take_process_noise(&mut self) -> Option<Arc<dyn ProcessNoise>> {
        self.plan = super::Plan::Unknown;
        self.noise.take()
    }

    /// A restored filter's invariants ([`crate::persist`]): the state of the model's
    /// dimension, finite; the covariance (and the fading weight) symmetric, positive
    /// semi-definite; the time finite; the noise model of the same dimension. The work
    /// buffers are made anew.
    pub(crate) fn check_saved(&mut self) -> Result<(), String> {
        use crate::linalg::invariant::{covariance, vector};
        let n = self.dynamics.dimension();
        vector(&self.state, n, "state")?;
        covariance(&self.covariance, n, "covariance")?;
        if !self.time.is_finite() {
            return Err(format!("time {} is not finite", self.time));
        }
        if let Some(noise) = &self.noise {
            if noise.dimension() != n {
                return Err(format!(
                    "noise model is {}-dimensional, {n} expected",
                    noise.dimension()
                ));
            }
        }
        if let Some(f) = &self.fading {
            covariance(&f.weight, n, "fading weight")?;
        }
        self.work = Work::new(n, self.observation.components());
        Ok(())
    }
}
