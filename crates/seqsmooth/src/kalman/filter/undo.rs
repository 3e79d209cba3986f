//! Keeping a filter's estimate aside and putting it back: what a smoother's forward pass needs
//! to undo an update (Morrison ch. 12's estimate `X_{n,n}`, `S_{n,n}`, and ch. 14's fading `P`),
//! and the last prediction's transition `Φ` read in place.

use super::KalmanFilter;
use crate::model::dynamics::Dynamics;
use crate::model::observation::Observation;
use nalgebra::{DMatrix, DVector};

/// A filter's estimate kept aside ([`KalmanFilter::estimate_copy`]).
#[derive(Clone, Debug)]
pub struct EstimateCopy {
    state: DVector<f64>,
    covariance: DMatrix<f64>,
    time: f64,
    fading: Option<(DMatrix<f64>, f64)>,
}

impl<D: Dynamics, O: Observation> KalmanFilter<D, O> {
    /// A copy of the estimate (with a fading filter's `P` and last update), to put back by
    /// [`Self::restore_estimate`]: what undoing an update needs, without the work buffers.
    pub(crate) fn estimate_copy(&self) -> EstimateCopy {
        EstimateCopy {
            state: self.state.clone(),
            covariance: self.covariance.clone(),
            time: self.time,
            fading: self
                .fading
                .as_ref()
                .map(|f| (f.weight.clone(), f.last_update)),
        }
    }

    /// Puts back an estimate taken by [`Self::estimate_copy`] from this filter.
    pub(crate) fn restore_estimate(&mut self, copy: EstimateCopy) {
        (self.state, self.covariance, self.time) = (copy.state, copy.covariance, copy.time);
        if let (Some(f), Some((weight, last_update))) = (&mut self.fading, copy.fading) {
            (f.weight, f.last_update) = (weight, last_update);
        }
    }

    /// `Φ` of the last prediction that made a step (the work buffers'): right after an update
    /// to a later time by [`Self::update_stats_keeping_prediction`], the `Φ(t_n, t_{n−1})` of
    /// its prediction.
    pub(crate) fn last_transition(&self) -> &DMatrix<f64> {
        &self.work.phi
    }
}
