//! A restored Kalman filter's checks ([`crate::persist`]): the invariants its saved state must
//! hold before it is handed out.

use super::{KalmanFilter, Work};
use crate::model::dynamics::Dynamics;
use crate::model::observation::Observation;

impl<D: Dynamics, O: Observation> KalmanFilter<D, O> {
    /// The dynamic and observation models (a restored filter's checks).
    pub(crate) fn models(&self) -> (&D, &O) {
        (&self.dynamics, &self.observation)
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
