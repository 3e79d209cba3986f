//! The fixed-lag smoothers of the Kalman classes over a batch, `fixed_lag_smoother(t, z, R,
//! lag)`: the library's `kalman::fixed_lag::FixedLagSmoother` (the polynomial, extended and
//! continuous-model filters) or `kalman::unscented_fixed_lag::UnscentedFixedLagSmoother` (the
//! unscented filter) run over the measurements, each estimate written into the output arrays as
//! it is given; the smoother holds `lag + 1` measurements, whatever the batch's length.

use crate::arrays::matrix;
use nalgebra::{DMatrix, DVector};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use seqsmooth::kalman::{FixedLagSmoother, UnscentedFixedLagSmoother};
use seqsmooth::model::dynamics::Dynamics;
use seqsmooth::model::measurement::Measurement;
use seqsmooth::model::observation::Observation;
use seqsmooth::Error;

/// A smoothed estimate: the state and its covariance.
type Estimate = (DVector<f64>, DMatrix<f64>);

/// A fixed-lag smoother as the batch runs it: the estimate given by a push, and those given at
/// the end.
pub(crate) trait Lagging {
    fn push(&mut self, m: &Measurement) -> Result<Option<Estimate>, Error>;
    fn finish(self) -> Result<Vec<Estimate>, Error>;
}

impl<D: Dynamics + Clone, O: Observation + Clone> Lagging for FixedLagSmoother<D, O> {
    fn push(&mut self, m: &Measurement) -> Result<Option<Estimate>, Error> {
        Ok(FixedLagSmoother::push(self, m)?.map(|s| (s.state, s.covariance)))
    }
    fn finish(self) -> Result<Vec<Estimate>, Error> {
        let given = FixedLagSmoother::finish(self)?;
        Ok(given.into_iter().map(|s| (s.state, s.covariance)).collect())
    }
}

impl<D: Dynamics + Clone, O: Observation + Clone> Lagging for UnscentedFixedLagSmoother<D, O> {
    fn push(&mut self, m: &Measurement) -> Result<Option<Estimate>, Error> {
        Ok(UnscentedFixedLagSmoother::push(self, m)?.map(|s| (s.state, s.covariance)))
    }
    fn finish(self) -> Result<Vec<Estimate>, Error> {
        let given = UnscentedFixedLagSmoother::finish(self)?;
        Ok(given.into_iter().map(|s| (s.state, s.covariance)).collect())
    }
}

/// The smoothed estimates of a batch, `n` states each, filled in order.
pub(crate) struct Lagged {
    n: usize,
    count: usize,
    states: Vec<f64>,
    covariances: Vec<f64>,
}

impl Lagged {
    fn record(&mut self, (x, s): Estimate) {
        self.states.extend_from_slice(x.as_slice());
        // Symmetric: column-major is row-major.
        self.covariances.extend_from_slice(s.as_slice());
        self.count += 1;
    }

    /// `(states, covariances)`, `(N, n)` and `(N, n, n)`.
    pub(crate) fn into_tuple(self, py: Python<'_>) -> PyResult<Bound<'_, PyTuple>> {
        let states = matrix(py, self.states, self.count, self.n)?;
        let covariances = PyArray1::from_vec(py, self.covariances)
            .reshape([self.count, self.n, self.n])?
            .into_any();
        PyTuple::new(py, [states, covariances])
    }
}

/// Runs `smoother` (of `n` states, fresh) over `rows`: every measurement's estimate, in order.
/// An error names its measurement ([`Error::InBatch`]: the backward pass's already does; the
/// forward pass's is wrapped with the measurement pushed).
pub(crate) fn lagged<S: Lagging>(
    mut smoother: S,
    rows: &[Measurement],
    n: usize,
) -> Result<Lagged, Error> {
    let mut out = Lagged {
        n,
        count: 0,
        states: Vec::with_capacity(rows.len() * n),
        covariances: Vec::with_capacity(rows.len() * n * n),
    };
    for (index, m) in rows.iter().enumerate() {
        match smoother.push(m) {
            Ok(given) => given.into_iter().for_each(|g| out.record(g)),
            Err(e @ Error::InBatch { .. }) => return Err(e),
            Err(e) => {
                return Err(Error::InBatch {
                    index,
                    source: Box::new(e),
                })
            }
        }
    }
    smoother.finish()?.into_iter().for_each(|g| out.record(g));
    Ok(out)
}
