//! The fixed-lag smoother on the discrete-time linear model ([`FixedLagSmoother`]): each
//! step's estimate from the `lag` steps after it, in memory bounded by the lag, as a batch
//! over a filter's copy ([`LinearKalmanFilter::fixed_lag`]) or a measurement at a time
//! ([`LinearFixedLag`]).

use super::{
    apply_prediction, apply_update, restore, DiscreteDynamics, LinearKalmanFilter, StepMatrices,
};
use crate::error::Error;
use crate::kalman::fixed_lag::FixedLagSmoother;
use crate::kalman::smoother::Smoothed;
use crate::model::observation::LinearObservation;

impl LinearKalmanFilter {
    /// The fixed-lag smoother ([`FixedLagSmoother`], lag `lag` measurements) from this
    /// filter's estimate over the rows of `zs` with `step(k)`'s matrices: each step's
    /// estimate from the `lag` steps after it (the last `lag` from all), in memory bounded by
    /// the lag; the filter itself is not changed. An error names its step.
    pub fn fixed_lag<'a>(
        &self,
        zs: &[f64],
        lag: usize,
        step: impl Fn(usize) -> StepMatrices<'a>,
        mut out: impl FnMut(usize, Smoothed),
    ) -> Result<(), Error> {
        let p = self.components();
        let mut smoother = LinearFixedLag::new(self, lag);
        let mut given = 0;
        for (k, z) in zs.chunks_exact(p).enumerate() {
            let in_batch = |e: Error| match e {
                Error::InBatch { .. } => e,
                e => Error::InBatch {
                    index: k,
                    source: Box::new(e),
                },
            };
            if let Some(smoothed) = smoother.push(z, &step(k)).map_err(in_batch)? {
                out(given, smoothed);
                given += 1;
            }
        }
        for smoothed in smoother.finish()? {
            out(given, smoothed);
            given += 1;
        }
        Ok(())
    }
}

/// The fixed-lag smoother ([`FixedLagSmoother`]) on a [`LinearKalmanFilter`]'s model, a
/// measurement at a time: each step's estimate from the `lag` steps after it, given once they
/// are in, in memory bounded by the lag (`lag + 1` steps' estimates and backward maps).
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::kalman::discrete::{LinearFixedLag, LinearKalmanFilter, StepMatrices};
/// let kf = LinearKalmanFilter::new(DVector::zeros(1), DMatrix::identity(1, 1) * 1e12,
///     DMatrix::identity(1, 1), DMatrix::identity(1, 1), DMatrix::zeros(1, 1),
///     DMatrix::identity(1, 1)).unwrap();
/// let mut s = LinearFixedLag::new(&kf, 1);
/// assert!(s.push(&[1.0], &StepMatrices::default()).unwrap().is_none());
/// let first = s.push(&[3.0], &StepMatrices::default()).unwrap().unwrap();
/// assert!((first.state[0] - 2.0).abs() < 1e-9); // a constant: the mean of both
/// assert_eq!(s.finish().unwrap().len(), 1);
/// ```
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct LinearFixedLag {
    smoother: FixedLagSmoother<DiscreteDynamics, LinearObservation>,
    model: LinearKalmanFilter,
}

impl LinearFixedLag {
    /// A smoother of lag `lag` measurements starting from `filter`'s estimate and model.
    pub fn new(filter: &LinearKalmanFilter, lag: usize) -> Self {
        Self {
            smoother: FixedLagSmoother::new(filter.filter.clone(), lag),
            model: filter.clone(),
        }
    }

    /// The lag, in measurements.
    pub fn lag(&self) -> usize {
        self.smoother.lag()
    }

    /// The measurements pushed.
    pub fn pushed(&self) -> usize {
        self.smoother.pushed()
    }

    /// One step: the prediction and the update with `z` (NaN a missing component) and
    /// `step`'s matrices, and the smoothed estimate of the step `lag` before, if there is
    /// one. On an error the smoother is unchanged.
    pub fn push(&mut self, z: &[f64], step: &StepMatrices<'_>) -> Result<Option<Smoothed>, Error> {
        let model = &self.model;
        model.check(step, true)?;
        let mut m = model.measurement(z, step.r)?;
        m.time = self.smoother.filter().time() + 1.0;
        let filter = self.smoother.filter_mut();
        apply_prediction(filter, &model.model, step);
        let pushed = apply_update(filter, &model.model, step).and_then(|()| self.smoother.push(&m));
        restore(self.smoother.filter_mut(), &model.model, step);
        pushed
    }

    /// The steps held, each smoothed by every step pushed, in order.
    pub fn finish(self) -> Result<Vec<Smoothed>, Error> {
        self.smoother.finish()
    }
}

impl LinearFixedLag {
    /// The state's dimension `n`.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::discrete::{LinearFixedLag, LinearKalmanFilter};
    /// let i = DMatrix::identity(2, 2);
    /// let h = DMatrix::from_row_slice(1, 2, &[1.0, 0.0]);
    /// let r = DMatrix::identity(1, 1);
    /// let f = LinearKalmanFilter::new(DVector::zeros(2), i.clone(), i.clone(), h, i, r).unwrap();
    /// assert_eq!(LinearFixedLag::new(&f, 3).dimension(), 2);
    /// ```
    pub fn dimension(&self) -> usize {
        self.model.dimension()
    }

    /// A restored smoother's invariants ([`crate::persist`]): its model's and its own.
    pub(crate) fn check_saved(&mut self) -> Result<(), String> {
        self.model.check_saved()?;
        if self.smoother.filter().state().len() != self.model.dimension() {
            return Err("smoother's and model's dimensions differ".into());
        }
        self.smoother.check_saved()
    }
}
