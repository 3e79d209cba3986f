//! The Kalman filter's iterated update (Morrison §12.5, (12.5.10)-(12.5.17)): the observation
//! relinearised about each new estimate until the correction is within its own σ.

use super::{Innovation, KalmanFilter};
use crate::error::{Error, Param};
use crate::model::dynamics::Dynamics;
use crate::model::measurement::Measurement;
use crate::model::observation::Observation;
use nalgebra::Cholesky;

impl<D: Dynamics, O: Observation> KalmanFilter<D, O> {
    /// The iterated update of §12.5 ((12.5.10)-(12.5.17), Morrison's Kalman filter with
    /// iterative differential correction): predicts to the measurement's time, then relinearises
    /// the observation about the updated estimate,
    /// `X_{r+1} = X_{n,n−1} + H(X_r) [Y − G(X_r) − M(X_r)(X_{n,n−1} − X_r)]`, from
    /// `X_0 = X_{n,n−1}`, until the change `|X_{r+1} − X_r|` is at most `tolerance` of its own σ
    /// (in the metric of `S_{n,n−1}`), at most `max_iterations` times ([`Error::NotConverged`]
    /// otherwise). The covariance and the reported innovation are those of the last
    /// linearisation. For a linear observation it is [`Self::update`] (two passes, the second a
    /// check). On an error the filter is unchanged.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::model::measurement::NoiseCovariance;
    /// use seqsmooth::model::measurement::Measurement;
    /// use seqsmooth::kalman::KalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::NonlinearObservation;
    /// // Morrison Ex. 11.1 / T11-1: range sqrt(9 + x²), prior x = 4, a² = 1, s² = 0.01, ρ = 5.2.
    /// let range = NonlinearObservation::new(1, 1, |_t, x: &DVector<f64>| DVector::from_vec(vec![(9.0 + x[0] * x[0]).sqrt()]));
    /// let mut f = KalmanFilter::new(PolynomialDynamics::new(0, 1), range,
    ///     DVector::from_vec(vec![4.0]), DMatrix::identity(1, 1), 0.0).unwrap();
    /// let m = Measurement { time: 0.0, values: vec![Some(5.2)], noise: NoiseCovariance::Variances(vec![0.01]) };
    /// f.update_iterated(&m, 1e-9, 20).unwrap();
    /// assert!((f.state()[0] - 4.243697780575).abs() < 1e-9);
    /// ```
    pub fn update_iterated(
        &mut self,
        measurement: &Measurement,
        tolerance: f64,
        max_iterations: usize,
    ) -> Result<Option<Innovation>, Error> {
        check_iteration_limits(tolerance, max_iterations)?;
        let Some(t) = self.measure_and_predict(measurement)? else {
            return Ok(None);
        };
        let prior = self.work.s.clone();
        let metric = Cholesky::new(prior.clone());
        self.work.about.copy_from(&self.work.x);
        let mut correction = f64::INFINITY;
        for _ in 0..max_iterations {
            let stats = self.correct(t, true)?;
            let change = &self.work.x_out - &self.work.about;
            correction = match &metric {
                Some(c) => change.dot(&c.solve(&change)).sqrt(),
                None => change.amax() / prior.diagonal().amax().sqrt().max(f64::MIN_POSITIVE),
            };
            self.work.about.copy_from(&self.work.x_out);
            if correction <= tolerance {
                let innovation = self.work.innovation(stats);
                self.commit_correction(t);
                return Ok(Some(innovation));
            }
        }
        Err(Error::NotConverged {
            iterations: max_iterations,
            correction,
            tolerance,
            chi_squared: f64::NAN,
        })
    }
}

/// The range of the iterated update's limits ([`KalmanFilter::update_iterated`]): a positive
/// finite `tolerance` (in the correction's own σ) and at least one iteration.
///
/// ```
/// use seqsmooth::kalman::filter::check_iteration_limits;
/// assert!(check_iteration_limits(1e-9, 1).is_ok());
/// assert!(check_iteration_limits(0.0, 5).is_err() && check_iteration_limits(1e-9, 0).is_err());
/// ```
pub fn check_iteration_limits(tolerance: f64, max_iterations: usize) -> Result<(), Error> {
    if !(tolerance.is_finite() && tolerance > 0.0) || max_iterations == 0 {
        return Err(Error::InvalidParameter {
            name: Param::IterationLimits,
            value: format!("tolerance {tolerance}, {max_iterations} iterations"),
            reason: "the tolerance must be positive and finite, the iterations at least 1".into(),
        });
    }
    Ok(())
}

/// The iterated update's limits a front end holds beside its filter (Morrison §12.5): at most
/// `iterations` relinearisations, until the correction is at most `tolerance` of its σ; saved
/// inside the filter's checksum ([`crate::persist::Beside`]) and checked on restoring by
/// [`check_iteration_limits`].
///
/// ```
/// use seqsmooth::kalman::filter::IterationLimits;
/// let limits = IterationLimits::new(1e-9, 5)?;
/// assert_eq!((limits.tolerance(), limits.iterations()), (1e-9, 5));
/// assert!(IterationLimits::new(f64::NAN, 5).is_err());
/// # Ok::<(), seqsmooth::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct IterationLimits {
    tolerance: f64,
    iterations: usize,
}

impl IterationLimits {
    /// The limits, in [`check_iteration_limits`]'s range.
    pub fn new(tolerance: f64, iterations: usize) -> Result<Self, Error> {
        check_iteration_limits(tolerance, iterations)?;
        Ok(Self {
            tolerance,
            iterations,
        })
    }

    /// The convergence test, in the correction's own σ.
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// The most iterations (1: the extended filter's single update).
    pub fn iterations(&self) -> usize {
        self.iterations
    }

    /// Why the limits are out of range, or nothing (a restored value's check).
    pub fn check(&self) -> Result<(), Error> {
        check_iteration_limits(self.tolerance, self.iterations)
    }
}
