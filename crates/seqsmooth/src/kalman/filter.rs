//! The Kalman filter (Morrison ch. 12, with driving noise ch. 15), in its one-pass extended
//! form for nonlinear models (§12.5, (12.5.19)-(12.5.23)): any [`Dynamics`] and
//! [`Observation`], on any times.
//!
//! | step | | source |
//! |---|---|---|
//! | `X_{n,n−1} = X(t_n)` from `X_{n−1,n−1}`, with `Φ(t_n, t_{n−1})` | [`Dynamics::propagate_into`] | (12.2.15), (15.4.10) |
//! | `S_{n,n−1} = Φ S_{n−1,n−1} Φᵀ + Q(t_n, t_{n−1})` | [`ProcessNoise`] | (12.2.16), (15.4.11) |
//! | `ν = Y_n − G(X_{n,n−1})`, `V = M S_{n,n−1} Mᵀ + R_n` (present components) | [`Observation::predict_into`] | (12.2.17) |
//! | `H = S_{n,n−1} Mᵀ V⁻¹` (Cholesky of `V`) | | (12.2.17), (15.4.12) |
//! | `X_{n,n} = X_{n,n−1} + H ν` | | (12.2.19), (15.4.14) |
//! | `S_{n,n} = (I − H M) S_{n,n−1} (I − H M)ᵀ + H R Hᵀ` | Joseph form | (12.3.7) |
//!
//! The covariance update is Joseph's form (12.3.7), not (12.2.18): it is the covariance of the
//! estimate for the gain actually used, a sum of two positive semidefinite terms, so it stays
//! symmetric positive semidefinite where `(I − H M) S` loses it by cancellation (§12.4 item 5,
//! Ex. 12.16); it costs two more `n × n` products. A perfect observation (`R = 0`, Ex. 12.12,
//! 12.13) is allowed while `V` stays positive definite.
//!
//! Each update reports its innovation `ν`, its covariance `V`, the normalised innovation
//! squared `NIS = νᵀ V⁻¹ ν` (χ² with as many degrees of freedom as components when the model
//! holds, §14.8) and the Gaussian log-likelihood `−(NIS + ln det V + p ln 2π)/2`.
//!
//! The filter cannot start from zero information (§12.4 item 2): it needs a prior state and
//! covariance, e.g. from [`crate::estimate::gauss_newton`] on the first observations.

use super::noise::ProcessNoise;
use crate::error::Error;
use crate::estimate::batch::NoiseCovariance;
use crate::estimate::gauss_newton::Measurement;
use crate::model::dynamics::Dynamics;
use crate::model::observation::Observation;
use nalgebra::{Cholesky, DMatrix, DVector};
use std::f64::consts::TAU;
use std::sync::Arc;

/// What one update saw: the innovation and its statistics.
#[derive(Clone, Debug, PartialEq)]
pub struct Innovation {
    /// The components used (the present ones), in the observation's order.
    pub components: Vec<usize>,
    /// `ν = Y − G(X_{n,n−1})` on those components (an angle's wrapped).
    pub innovation: DVector<f64>,
    /// `V = M S_{n,n−1} Mᵀ + R`.
    pub covariance: DMatrix<f64>,
    /// The gain `H = S_{n,n−1} Mᵀ V⁻¹`, states × components.
    pub gain: DMatrix<f64>,
    /// `νᵀ V⁻¹ ν`.
    pub nis: f64,
    /// `−(NIS + ln det V + p ln 2π)/2`.
    pub log_likelihood: f64,
}

/// A Kalman filter on `D` and `O`, with optional driving noise.
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::estimate::batch::NoiseCovariance;
/// use seqsmooth::estimate::gauss_newton::Measurement;
/// use seqsmooth::kalman::KalmanFilter;
/// use seqsmooth::model::dynamics::PolynomialDynamics;
/// use seqsmooth::model::observation::LinearObservation;
/// // Morrison Ex. 12.1b: S_{n,n−1} = [[1, 1], [1, 2]], M = (1, 0), R = 1 gives (1/2)[[1, 1], [1, 3]].
/// let mut f = KalmanFilter::new(
///     PolynomialDynamics::new(1, 1),
///     LinearObservation::value_of(2),
///     DVector::zeros(2),
///     DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 1.0, 2.0]),
///     0.0,
/// )
/// .unwrap();
/// let m = Measurement { time: 0.0, values: vec![Some(1.0)], noise: NoiseCovariance::Variances(vec![1.0]) };
/// let i = f.update(&m).unwrap().unwrap();
/// let want = DMatrix::from_row_slice(2, 2, &[0.5, 0.5, 0.5, 1.5]);
/// assert!((f.covariance() - want).amax() < 1e-15);
/// assert!((i.nis - 0.5).abs() < 1e-15); // ν² / V = 1 / 2
/// ```
#[derive(Clone, Debug)]
pub struct KalmanFilter<D: Dynamics, O: Observation> {
    dynamics: D,
    observation: O,
    noise: Option<Arc<dyn ProcessNoise>>,
    fading: Option<Fading>,
    state: DVector<f64>,
    covariance: DMatrix<f64>,
    time: f64,
}

/// How old observations are discounted (Morrison ch. 14): by time, `β^(t_n − t_k)`
/// (14.2.10), or by count, `θ^(n−k)` (14.2.12). `β = 1` or `θ = 1` is the plain filter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Discount {
    /// `0 < β ≤ 1` per unit of time.
    PerTime(f64),
    /// `0 < θ ≤ 1` per update.
    PerUpdate(f64),
}

/// The fading filter's own matrix `P` (14.3.13), not the covariance when the discount is
/// below 1, and the time of the last update (from which `β` counts).
#[derive(Clone, Debug)]
struct Fading {
    discount: Discount,
    weight: DMatrix<f64>,
    last_update: f64,
}

impl Fading {
    /// `β^(t − t_last)` or `θ`, in `(0, 1]`.
    fn factor(&self, t: f64) -> Result<f64, Error> {
        let f = match self.discount {
            Discount::PerTime(beta) => beta.powf((t - self.last_update).abs()),
            Discount::PerUpdate(theta) => theta,
        };
        if f > 0.0 && f.is_normal() {
            Ok(f)
        } else {
            Err(Error::InvalidParameter {
                name: "discount over the step",
                value: format!("{f:e} over {} since the last update", t - self.last_update),
                reason: "underflows: the memory holds nothing; raise beta or update more often"
                    .into(),
            })
        }
    }
}

impl<D: Dynamics, O: Observation> KalmanFilter<D, O> {
    /// A filter at `time` with the prior `state` and `covariance` (symmetric, positive
    /// semidefinite, finite), without driving noise.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::KalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let bad = KalmanFilter::new(PolynomialDynamics::new(1, 1), LinearObservation::value_of(2),
    ///     DVector::zeros(2), DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 0.0, 1.0]), 0.0);
    /// assert!(bad.is_err()); // not symmetric
    /// ```
    pub fn new(
        dynamics: D,
        observation: O,
        state: DVector<f64>,
        covariance: DMatrix<f64>,
        time: f64,
    ) -> Result<Self, Error> {
        let n = dynamics.dimension();
        let bad = |name: &'static str, value: String, reason: String| Error::InvalidParameter {
            name,
            value,
            reason,
        };
        if observation.state_dimension() != n {
            return Err(bad(
                "observation model",
                format!("for {} states", observation.state_dimension()),
                format!("the dynamics have {n} states"),
            ));
        }
        if state.len() != n || covariance.shape() != (n, n) {
            return Err(bad(
                "prior",
                format!(
                    "state of length {}, covariance {}x{}",
                    state.len(),
                    covariance.nrows(),
                    covariance.ncols()
                ),
                format!("the model has {n} states"),
            ));
        }
        if let Some(&value) = state
            .iter()
            .chain(covariance.iter())
            .chain([&time])
            .find(|v| !v.is_finite())
        {
            return Err(Error::NonFinite {
                what: "prior state, covariance or time",
                value,
            });
        }
        if (&covariance - covariance.transpose()).abs().max() > 1e-12 * covariance.abs().max()
            || covariance.diagonal().iter().any(|&v| v < 0.0)
        {
            return Err(bad(
                "prior covariance",
                format!("{covariance:?}"),
                "must be symmetric with a non-negative diagonal".into(),
            ));
        }
        Ok(Self {
            dynamics,
            observation,
            noise: None,
            fading: None,
            state,
            covariance,
            time,
        })
    }

    /// With driving noise `Q` (ch. 15) of the model's dimension.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::noise::WhiteNoiseDerivative;
    /// use seqsmooth::kalman::KalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let mut f = KalmanFilter::new(PolynomialDynamics::new(1, 1), LinearObservation::value_of(2),
    ///     DVector::zeros(2), DMatrix::zeros(2, 2), 0.0)
    ///     .unwrap()
    ///     .with_process_noise(WhiteNoiseDerivative::new(1, 1, 3.0).unwrap())
    ///     .unwrap();
    /// f.predict(1.0).unwrap();
    /// assert_eq!(f.covariance()[(1, 1)], 3.0); // q ζ
    /// ```
    pub fn with_process_noise<P: ProcessNoise + 'static>(
        mut self,
        noise: P,
    ) -> Result<Self, Error> {
        let n = self.dynamics.dimension();
        if noise.dimension() != n {
            return Err(Error::InvalidParameter {
                name: "process noise",
                value: format!("for {} states", noise.dimension()),
                reason: format!("the dynamics have {n} states"),
            });
        }
        self.noise = Some(Arc::new(noise));
        Ok(self)
    }

    /// The generalized fading-memory filter of ch. 14 ((14.4.34)-(14.4.40)): the gain from
    /// the recursion's own matrix `P`, `H = P Mᵀ (f R + M P Mᵀ)⁻¹`, `P ← (1/f)(I − H M) P` (in
    /// Joseph's form), with `f = β^(t_n − t_{n−1})` (time since the previous update) or `θ`;
    /// the covariance reported, [`Self::covariance`], is the true one of the estimate
    /// ((14.4.31)-(14.4.32), (14.3.19)), and the innovation statistics use it (§14.8). `P`
    /// starts as the current covariance, counted from the current time (start at `β = 1` and
    /// switch, §14.5). The discount must lie in `(0, 1]`.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::estimate::batch::NoiseCovariance;
    /// use seqsmooth::estimate::gauss_newton::Measurement;
    /// use seqsmooth::kalman::{Discount, KalmanFilter};
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// // Degree 0, θ = 0.5, vague prior: the gain settles at 1 − θ = 0.5 (Table 13.1).
    /// let mut f = KalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
    ///     DVector::zeros(1), DMatrix::from_element(1, 1, 1e9), 0.0).unwrap()
    ///     .with_fading(Discount::PerUpdate(0.5)).unwrap();
    /// let mut gain = 0.0;
    /// for k in 1..60 {
    ///     let m = Measurement { time: k as f64, values: vec![Some(1.0)], noise: NoiseCovariance::Identity };
    ///     gain = f.update(&m).unwrap().unwrap().gain[(0, 0)];
    /// }
    /// assert!((gain - 0.5).abs() < 1e-12);
    /// assert!((f.covariance()[(0, 0)] - 1.0 / 3.0).abs() < 1e-12); // (1 − θ)/(1 + θ)
    /// ```
    pub fn with_fading(mut self, discount: Discount) -> Result<Self, Error> {
        let (name, value) = match discount {
            Discount::PerTime(b) => ("beta", b),
            Discount::PerUpdate(t) => ("theta", t),
        };
        if !(value > 0.0 && value <= 1.0) {
            return Err(Error::InvalidParameter {
                name,
                value: value.to_string(),
                reason: "the discount must lie in (0, 1]".into(),
            });
        }
        self.fading = Some(Fading {
            discount,
            weight: self.covariance.clone(),
            last_update: self.time,
        });
        Ok(self)
    }

    /// The current estimate `X`.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::KalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let f = KalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
    ///     DVector::from_vec(vec![4.0]), DMatrix::identity(1, 1), 0.0).unwrap();
    /// assert_eq!(f.state()[0], 4.0);
    /// ```
    pub fn state(&self) -> &DVector<f64> {
        &self.state
    }

    /// The covariance `S` of [`Self::state`].
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::KalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let f = KalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
    ///     DVector::zeros(1), DMatrix::identity(1, 1), 0.0).unwrap();
    /// assert_eq!(f.covariance()[(0, 0)], 1.0);
    /// ```
    pub fn covariance(&self) -> &DMatrix<f64> {
        &self.covariance
    }

    /// The time the estimate refers to.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::KalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let mut f = KalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
    ///     DVector::zeros(1), DMatrix::identity(1, 1), 0.0).unwrap();
    /// f.predict(2.5).unwrap();
    /// assert_eq!(f.time(), 2.5);
    /// ```
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Carries the estimate to `t` (forwards or backwards): (12.2.15)-(12.2.16), (15.4.10)-(15.4.11).
    /// On an error the filter is unchanged.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::estimate::batch::NoiseCovariance;
    /// use seqsmooth::estimate::gauss_newton::Measurement;
    /// use seqsmooth::kalman::KalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let mut f = KalmanFilter::new(PolynomialDynamics::new(1, 1), LinearObservation::value_of(2),
    ///     DVector::from_vec(vec![0.0, 1.0]), DMatrix::identity(2, 2), 0.0).unwrap();
    /// f.predict(2.0).unwrap();
    /// assert_eq!(f.state()[0], 2.0);
    /// assert_eq!(f.covariance()[(0, 0)], 5.0); // 1 + ζ²
    /// ```
    pub fn predict(&mut self, t: f64) -> Result<(), Error> {
        self.predict_with_transition(t).map(|_| ())
    }

    /// [`Self::predict`], returning `Φ(t, t_before)` (the identity for no step): what the
    /// smoother needs.
    pub(crate) fn predict_with_transition(&mut self, t: f64) -> Result<DMatrix<f64>, Error> {
        if !t.is_finite() {
            return Err(Error::NonFinite {
                what: "time",
                value: t,
            });
        }
        let n = self.state.len();
        if t == self.time {
            return Ok(DMatrix::identity(n, n));
        }
        let (mut x, mut phi) = (DVector::zeros(n), DMatrix::zeros(n, n));
        self.dynamics
            .propagate_into(&self.state, self.time, t, &mut x, &mut phi)?;
        let q = match &self.noise {
            Some(q) => Some(q.covariance(self.time, t)?),
            None => None,
        };
        let carry = |s: &DMatrix<f64>| {
            let mut s = &phi * s * phi.transpose();
            if let Some(q) = &q {
                s += q;
            }
            symmetric(s)
        };
        let s = carry(&self.covariance);
        finite(&s, "predicted covariance")?;
        let weight = match &self.fading {
            Some(f) => {
                let w = carry(&f.weight);
                finite(&w, "predicted fading-memory matrix P")?;
                Some(w)
            }
            None => None,
        };
        self.state = x;
        self.covariance = s;
        self.time = t;
        if let (Some(f), Some(w)) = (&mut self.fading, weight) {
            f.weight = w;
        }
        Ok(phi)
    }

    /// Predicts to the measurement's time and updates with its present components
    /// ((12.2.17)-(12.2.19), Joseph's covariance (12.3.7)); `Ok(None)` when no component is
    /// present (the prediction alone). On an error the filter is unchanged.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::estimate::batch::NoiseCovariance;
    /// use seqsmooth::estimate::gauss_newton::Measurement;
    /// use seqsmooth::kalman::KalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let mut f = KalmanFilter::new(PolynomialDynamics::new(1, 1), LinearObservation::value_of(2),
    ///     DVector::from_vec(vec![0.0, 1.0]), DMatrix::identity(2, 2), 0.0).unwrap();
    /// let missing = Measurement { time: 1.0, values: vec![None], noise: NoiseCovariance::Identity };
    /// assert!(f.update(&missing).unwrap().is_none());
    /// let z = Measurement { time: 2.0, values: vec![Some(2.5)], noise: NoiseCovariance::Identity };
    /// let i = f.update(&z).unwrap().unwrap();
    /// assert_eq!(i.innovation[0], 0.5);
    /// ```
    pub fn update(&mut self, measurement: &Measurement) -> Result<Option<Innovation>, Error> {
        let p = self.observation.components();
        let (present, values, r) = present_components(p, measurement)?;
        self.transaction(|f| {
            f.predict(measurement.time)?;
            if present.is_empty() {
                return Ok(None);
            }
            f.correct(&present, &values, &r).map(Some)
        })
    }

    /// Runs `step`, restoring the filter as it was if `step` fails.
    fn transaction<T>(
        &mut self,
        step: impl FnOnce(&mut Self) -> Result<T, Error>,
    ) -> Result<T, Error> {
        let saved = (
            self.state.clone(),
            self.covariance.clone(),
            self.time,
            self.fading.clone(),
        );
        let out = step(self);
        if out.is_err() {
            (self.state, self.covariance, self.time, self.fading) = saved;
        }
        out
    }

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
    /// use seqsmooth::estimate::batch::NoiseCovariance;
    /// use seqsmooth::estimate::gauss_newton::Measurement;
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
        if !(tolerance.is_finite() && tolerance > 0.0) || max_iterations == 0 {
            return Err(Error::InvalidParameter {
                name: "iteration limits",
                value: format!("tolerance {tolerance}, {max_iterations} iterations"),
                reason: "the tolerance must be positive and finite, the iterations at least 1"
                    .into(),
            });
        }
        let p = self.observation.components();
        let (present, values, r) = present_components(p, measurement)?;
        self.transaction(|f| {
            f.predict(measurement.time)?;
            if present.is_empty() {
                return Ok(None);
            }
            let (predicted, prior, fading) =
                (f.state.clone(), f.covariance.clone(), f.fading.clone());
            let metric = Cholesky::new(prior.clone());
            let mut about = predicted.clone();
            let mut correction = f64::INFINITY;
            for _ in 0..max_iterations {
                (f.state, f.covariance, f.fading) =
                    (predicted.clone(), prior.clone(), fading.clone());
                let innovation = f.correct_about(&present, &values, &r, &about)?;
                let change = &f.state - &about;
                correction = match &metric {
                    Some(c) => change.dot(&c.solve(&change)).sqrt(),
                    None => change.amax() / prior.diagonal().amax().sqrt().max(f64::MIN_POSITIVE),
                };
                about = f.state.clone();
                if correction <= tolerance {
                    return Ok(Some(innovation));
                }
            }
            Err(Error::NotConverged {
                iterations: max_iterations,
                correction,
                tolerance,
                chi_squared: f64::NAN,
            })
        })
    }

    /// The update at the current (predicted) state.
    fn correct(
        &mut self,
        present: &[usize],
        values: &[f64],
        r: &DMatrix<f64>,
    ) -> Result<Innovation, Error> {
        let about = self.state.clone();
        self.correct_about(present, values, r, &about)
    }

    /// The update of the predicted state linearised about `about` (12.5.17): the innovation
    /// `Y − G(about) − M(about)(X_{n,n−1} − about)`, `M` at `about`.
    fn correct_about(
        &mut self,
        present: &[usize],
        values: &[f64],
        r: &DMatrix<f64>,
        about: &DVector<f64>,
    ) -> Result<Innovation, Error> {
        let n = self.state.len();
        let p = self.observation.components();
        let (mut g, mut m_all) = (DVector::zeros(p), DMatrix::zeros(p, n));
        self.observation
            .predict_into(about, self.time, &mut g, &mut m_all)?;
        let k = present.len();
        let m = DMatrix::from_fn(k, n, |i, j| m_all[(present[i], j)]);
        let offset = &m * (&self.state - about);
        let nu = DVector::from_fn(k, |i, _| {
            self.observation
                .residual(present[i], values[i], g[present[i]])
                - offset[i]
        });
        // The gain from P and f R (fading, ch. 14), or from S and R (f = 1, P = S).
        let f = match &self.fading {
            Some(fading) => fading.factor(self.time)?,
            None => 1.0,
        };
        let weight = self.fading.as_ref().map_or(&self.covariance, |x| &x.weight);
        let pm = weight * m.transpose(); // P Mᵀ, n × k
        let not_pd = |v: &DMatrix<f64>| Error::InvalidParameter {
            name: "innovation covariance M S Mᵀ + R",
            value: format!("{v:?}"),
            reason: "is not positive definite: the observation adds nothing the filter can \
                     weigh (a perfect observation of a component already known exactly)"
                .into(),
        };
        let vp = symmetric(&m * &pm + r * f);
        let chol_p = Cholesky::new(vp.clone()).ok_or_else(|| not_pd(&vp))?;
        // H = P Mᵀ V_P⁻¹: solve V_P Hᵀ = M P.
        let gain = chol_p.solve(&pm.transpose()).transpose();
        // The innovation's true covariance M S Mᵀ + R (§14.8): V_P itself without fading.
        let (v, chol) = if self.fading.is_some() {
            let v = symmetric(&m * &self.covariance * m.transpose() + r);
            let c = Cholesky::new(v.clone()).ok_or_else(|| not_pd(&v))?;
            (v, c)
        } else {
            (vp, chol_p)
        };
        let nis = nu.dot(&chol.solve(&nu));
        let log_det = 2.0
            * chol
                .l_dirty()
                .diagonal()
                .iter()
                .map(|d| d.ln())
                .sum::<f64>();
        let log_likelihood = -0.5 * (nis + log_det + k as f64 * TAU.ln());
        let x = &self.state + &gain * &nu;
        let a = DMatrix::identity(n, n) - &gain * &m;
        let joseph = |s: &DMatrix<f64>, r: &DMatrix<f64>| {
            symmetric(&a * s * a.transpose() + &gain * r * gain.transpose())
        };
        let s = joseph(&self.covariance, r);
        finite(&s, "updated covariance")?;
        let weight = match &self.fading {
            Some(_) => {
                let w = joseph(weight, &(r * f)) / f;
                finite(&w, "updated fading-memory matrix P")?;
                Some(w)
            }
            None => None,
        };
        if let Some(&value) = x.iter().find(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "updated state entry",
                value,
            });
        }
        if !(nis.is_finite() && log_likelihood.is_finite()) {
            return Err(Error::EstimateOutOfRange {
                what: "normalised innovation squared".into(),
            });
        }
        self.state = x;
        self.covariance = s;
        if let (Some(fading), Some(w)) = (&mut self.fading, weight) {
            fading.weight = w;
            fading.last_update = self.time;
        }
        Ok(Innovation {
            components: present.to_vec(),
            innovation: nu,
            covariance: v,
            gain,
            nis,
            log_likelihood,
        })
    }
}

/// A measurement's present components, their values, and their `R`.
type Present = (Vec<usize>, Vec<f64>, DMatrix<f64>);

/// The present components of a measurement, their values and their `R` (symmetric, finite,
/// non-negative diagonal: a perfect observation is allowed).
fn present_components(p: usize, m: &Measurement) -> Result<Present, Error> {
    let (present, values) = m.present(p)?;
    let full = match &m.noise {
        NoiseCovariance::Identity => DMatrix::identity(p, p),
        NoiseCovariance::Variances(v) if v.len() == p => {
            DMatrix::from_diagonal(&DVector::from_column_slice(v))
        }
        NoiseCovariance::Full(r) if r.shape() == (p, p) => r.clone(),
        other => {
            return Err(Error::InvalidParameter {
                name: "measurement noise",
                value: format!("{other:?}"),
                reason: format!("needs {p} components"),
            })
        }
    };
    if let Some(&value) = full.iter().find(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            what: "measurement noise entry",
            value,
        });
    }
    if (&full - full.transpose()).abs().max() > 1e-12 * full.abs().max()
        || full.diagonal().iter().any(|&v| v < 0.0)
    {
        return Err(Error::InvalidParameter {
            name: "measurement noise",
            value: format!("{full:?}"),
            reason: "must be symmetric with non-negative variances".into(),
        });
    }
    let r = DMatrix::from_fn(present.len(), present.len(), |i, j| {
        full[(present[i], present[j])]
    });
    Ok((present, values, r))
}

/// `(a + aᵀ)/2`.
fn symmetric(a: DMatrix<f64>) -> DMatrix<f64> {
    (&a + a.transpose()) * 0.5
}

fn finite(m: &DMatrix<f64>, what: &'static str) -> Result<(), Error> {
    match m.iter().find(|v| !v.is_finite()) {
        Some(&value) => Err(Error::NonFinite { what, value }),
        None => Ok(()),
    }
}
