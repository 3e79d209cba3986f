//! The unscented Kalman filter (Julier and Uhlmann 1997; Wan and van der Merwe 2000, "The
//! unscented Kalman filter for nonlinear estimation", Algorithm 3.1 with additive noise) over
//! any [`Dynamics`] and [`Observation`], on any times, with the scaled sigma points of
//! [`super::sigma_points`]:
//!
//! | step | | Wan and van der Merwe 2000 |
//! |---|---|---|
//! | `𝒳 = x ± √((n + λ) S)`, each point carried to `t_n` by the dynamics: `𝒴_i` | [`Dynamics::propagate_state`] | (15), (18) |
//! | `x̄ = Σ W^(m) 𝒴_i`, `S̄ = Σ W^(c) (𝒴_i − x̄)(𝒴_i − x̄)ᵀ + Q(t_n, t_{n−1})` | [`ProcessNoise`] | (19)-(20) |
//! | `𝒵 = x̄ ± √((n + λ) S̄)` (points redrawn about the prediction), `𝒢_i = G(𝒵_i, t_n)` | [`Observation::value`] | (21)-(22), redrawn as their footnote |
//! | `ŷ = Σ W^(m) 𝒢_i`, `V = Σ W^(c) (𝒢_i − ŷ)(𝒢_i − ŷ)ᵀ + R`, `C_xy = Σ W^(c) (𝒵_i − x̄)(𝒢_i − ŷ)ᵀ` | present components only | (23), (25)-(26) |
//! | `H = C_xy V⁻¹`, `x = x̄ + H (Y − ŷ)`, `S = S̄ − H V Hᵀ` | `V` by its Cholesky factor | (27)-(29) |
//!
//! Residuals `𝒢_i − ŷ` and `Y − ŷ` are the observation's ([`Observation::residual`]: a radar's
//! azimuth is wrapped), and `ŷ` is taken about the central point (see
//! [`super::sigma_points::Weights::mean_of`]), so an angle near `±π` averages correctly. The
//! points are redrawn from `(x̄, S̄)` before the observation, as filterpy's
//! `UnscentedKalmanFilter` does, so that `Q` is seen by the observation's points.
//!
//! Each update reports an [`Innovation`] as the Kalman filter's: `ν = Y − ŷ`, `V`, the gain
//! `H`, `NIS = νᵀ V⁻¹ ν` (χ² with as many degrees of freedom as components present when the
//! model holds, Morrison §14.8) and the log-likelihood. A missing component (`None` in the
//! [`Measurement`]) drops its row of `G` and its row and column of `R`; with none present the
//! update is the prediction alone.
//!
//! Each prediction also keeps the cross-covariance `D = Σ W^(c) (𝒳_i − x)(𝒴_i − x̄)ᵀ` of the
//! state before and after the step, what the unscented RTS smoother needs
//! ([`super::unscented_smoother`], Särkkä 2008 (10)).
//!
//! Refused, the filter unchanged: a covariance whose Cholesky factorisation fails (not
//! positive definite: no sigma points), an innovation covariance `V` that is not positive
//! definite, and any output that is not finite.

use super::correct::noise_entries;
use super::filter::{Innovation, KalmanFilter};
use super::noise::ProcessNoise;
use super::sigma_points::{SigmaPoints, Weights};
use crate::error::{Error, Param};
use crate::model::dynamics::Dynamics;
use crate::model::measurement::Measurement;
use crate::model::observation::Observation;
use nalgebra::{Cholesky, DMatrix, DVector};
use std::f64::consts::TAU;
use std::sync::Arc;

/// One prediction of the filter: the prior at `time` from the estimate at `from`, and the
/// cross-covariance of the two states.
#[derive(Clone, Debug, PartialEq)]
pub struct Prediction {
    /// The time predicted from (the estimate's before the step).
    pub from: f64,
    /// The time predicted to.
    pub time: f64,
    /// `x̄`, the predicted state.
    pub state: DVector<f64>,
    /// `S̄`, its covariance (with `Q` of the step).
    pub covariance: DMatrix<f64>,
    /// `D = Cov(x(from), x̄(time))`, states × states (the covariance before the step when the
    /// step is zero).
    pub cross: DMatrix<f64>,
}

/// The unscented Kalman filter on `D` and `O`, with optional driving noise.
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::kalman::noise::WhiteNoiseDerivative;
/// use seqsmooth::kalman::UnscentedKalmanFilter;
/// use seqsmooth::model::dynamics::PolynomialDynamics;
/// use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
/// use seqsmooth::model::observation::LinearObservation;
/// // Morrison Ex. 12.1b: S_{n,n−1} = [[1, 1], [1, 2]], M = (1, 0), R = 1 gives (1/2)[[1, 1], [1, 3]]
/// // (a linear model: the unscented filter is the Kalman filter).
/// let mut f = UnscentedKalmanFilter::new(
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
/// assert!((i.nis - 0.5).abs() < 1e-15);
/// ```
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct UnscentedKalmanFilter<D: Dynamics, O: Observation> {
    dynamics: D,
    observation: O,
    #[serde(with = "crate::kalman::saved_noise::field")]
    noise: Option<Arc<dyn ProcessNoise>>,
    points: SigmaPoints,
    weights: Weights,
    state: DVector<f64>,
    covariance: DMatrix<f64>,
    time: f64,
}

impl<D: Dynamics, O: Observation> UnscentedKalmanFilter<D, O> {
    /// A filter at `time` with the prior `state` and `covariance` (symmetric, positive
    /// definite, finite), the default sigma points ([`SigmaPoints::default`]: `α = 1`, `β = 2`,
    /// `κ = 0`), without driving noise.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::UnscentedKalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let bad = UnscentedKalmanFilter::new(PolynomialDynamics::new(1, 1), LinearObservation::value_of(2),
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
        // The Kalman filter's checks of the prior (shapes, finite, symmetric), on borrowed
        // models; then positive definiteness, which the sigma points need.
        KalmanFilter::new(
            &dynamics,
            &observation,
            state.clone(),
            covariance.clone(),
            time,
        )?;
        check_positive_definite(&covariance, Param::PriorCovariance)?;
        let n = state.len();
        let points = SigmaPoints::default();
        let weights = points.weights(n)?;
        Ok(Self {
            dynamics,
            observation,
            noise: None,
            points,
            weights,
            state,
            covariance,
            time,
        })
    }

    /// With the sigma points `points` (their weights for this state dimension checked).
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::sigma_points::SigmaPoints;
    /// use seqsmooth::kalman::UnscentedKalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let f = UnscentedKalmanFilter::new(PolynomialDynamics::new(1, 1), LinearObservation::value_of(2),
    ///     DVector::zeros(2), DMatrix::identity(2, 2), 0.0).unwrap();
    /// assert!(f.clone().with_sigma_points(SigmaPoints::new(0.5, 2.0, 0.0).unwrap()).is_ok());
    /// assert!(f.with_sigma_points(SigmaPoints::new(1.0, 2.0, -2.0).unwrap()).is_err()); // n + κ = 0
    /// ```
    pub fn with_sigma_points(mut self, points: SigmaPoints) -> Result<Self, Error> {
        self.weights = points.weights(self.state.len())?;
        self.points = points;
        Ok(self)
    }

    /// With driving noise `Q` (Morrison ch. 15) of the model's dimension.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::noise::WhiteNoiseDerivative;
    /// use seqsmooth::kalman::UnscentedKalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let mut f = UnscentedKalmanFilter::new(PolynomialDynamics::new(1, 1), LinearObservation::value_of(2),
    ///     DVector::zeros(2), DMatrix::identity(2, 2), 0.0).unwrap()
    ///     .with_process_noise(WhiteNoiseDerivative::new(1, 1, 3.0).unwrap()).unwrap();
    /// f.predict(1.0).unwrap();
    /// assert!((f.covariance()[(1, 1)] - 4.0).abs() < 1e-14); // 1 + q ζ
    /// ```
    pub fn with_process_noise<P: ProcessNoise + 'static>(
        mut self,
        noise: P,
    ) -> Result<Self, Error> {
        let n = self.state.len();
        super::noise::check_noise_dimension(&noise, n)?;
        self.noise = Some(Arc::new(noise));
        Ok(self)
    }

    /// The sigma points' parameters.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::UnscentedKalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let f = UnscentedKalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
    ///     DVector::from_vec(vec![4.0]), DMatrix::from_element(1, 1, 2.0), 1.5).unwrap();
    /// assert_eq!(f.sigma_points().alpha(), 1.0); // the default
    /// ```
    pub fn sigma_points(&self) -> SigmaPoints {
        self.points
    }

    /// The current estimate `x`.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::UnscentedKalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let f = UnscentedKalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
    ///     DVector::from_vec(vec![4.0]), DMatrix::from_element(1, 1, 2.0), 1.5).unwrap();
    /// assert_eq!(f.state()[0], 4.0);
    /// ```
    pub fn state(&self) -> &DVector<f64> {
        &self.state
    }

    /// The covariance `S` of [`Self::state`].
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::UnscentedKalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let f = UnscentedKalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
    ///     DVector::from_vec(vec![4.0]), DMatrix::from_element(1, 1, 2.0), 1.5).unwrap();
    /// assert_eq!(f.covariance()[(0, 0)], 2.0);
    /// ```
    pub fn covariance(&self) -> &DMatrix<f64> {
        &self.covariance
    }

    /// The 1σ of each state component, `√diag(S)`.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::UnscentedKalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let f = UnscentedKalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
    ///     DVector::zeros(1), DMatrix::from_element(1, 1, 4.0), 0.0).unwrap();
    /// assert_eq!(f.std_devs(), vec![2.0]);
    /// ```
    pub fn std_devs(&self) -> Vec<f64> {
        crate::linalg::std_devs(&self.covariance)
    }

    /// The time the estimate refers to.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::UnscentedKalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let f = UnscentedKalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
    ///     DVector::from_vec(vec![4.0]), DMatrix::from_element(1, 1, 2.0), 1.5).unwrap();
    /// assert_eq!(f.time(), 1.5);
    /// ```
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Replaces the estimate: `state` and `covariance` at `time`, checked by
    /// [`check_estimate`](super::noise::check_estimate) and positive definite (the sigma
    /// points are drawn from its Cholesky factor), the time finite. On an error the filter is
    /// unchanged.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::UnscentedKalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let mut f = UnscentedKalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
    ///     DVector::zeros(1), DMatrix::identity(1, 1), 0.0).unwrap();
    /// f.set_estimate(DVector::from_vec(vec![2.0]), DMatrix::from_element(1, 1, 4.0), 1.0).unwrap();
    /// assert_eq!((f.state()[0], f.std_devs()[0], f.time()), (2.0, 2.0, 1.0));
    /// // Singular: no sigma points; refused, the filter unchanged.
    /// assert!(f.set_estimate(DVector::zeros(1), DMatrix::zeros(1, 1), 1.0).is_err());
    /// assert_eq!(f.state()[0], 2.0);
    /// ```
    pub fn set_estimate(
        &mut self,
        state: DVector<f64>,
        covariance: DMatrix<f64>,
        time: f64,
    ) -> Result<(), Error> {
        super::noise::check_estimate_at(&state, &covariance, self.state.len(), time)?;
        check_positive_definite(&covariance, Param::StateCovarianceP)?;
        (self.state, self.covariance, self.time) = (state, covariance, time);
        Ok(())
    }

    /// Carries the estimate to `t` (forwards or backwards) through the sigma points
    /// (Wan and van der Merwe (18)-(20)). On an error the filter is unchanged.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::UnscentedKalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let mut f = UnscentedKalmanFilter::new(PolynomialDynamics::new(1, 1), LinearObservation::value_of(2),
    ///     DVector::from_vec(vec![0.0, 1.0]), DMatrix::identity(2, 2), 0.0).unwrap();
    /// f.predict(2.0).unwrap();
    /// assert!((f.state()[0] - 2.0).abs() < 1e-15);
    /// assert!((f.covariance()[(0, 0)] - 5.0).abs() < 1e-14); // 1 + ζ²
    /// ```
    pub fn predict(&mut self, t: f64) -> Result<(), Error> {
        let p = self.prediction(t)?;
        self.commit(p.time, p.state, p.covariance);
        Ok(())
    }

    /// Predicts to the measurement's time and updates with its present components
    /// (Wan and van der Merwe (21)-(29)); `Ok(None)` when no component is present (the
    /// prediction alone). On an error the filter is unchanged.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::UnscentedKalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
    /// use seqsmooth::model::observation::LinearObservation;
    /// let mut f = UnscentedKalmanFilter::new(PolynomialDynamics::new(1, 1), LinearObservation::value_of(2),
    ///     DVector::from_vec(vec![0.0, 1.0]), DMatrix::identity(2, 2), 0.0).unwrap();
    /// let missing = Measurement { time: 1.0, values: vec![None], noise: NoiseCovariance::Identity };
    /// assert!(f.update(&missing).unwrap().is_none());
    /// let z = Measurement { time: 2.0, values: vec![Some(2.5)], noise: NoiseCovariance::Identity };
    /// let i = f.update(&z).unwrap().unwrap();
    /// assert!((i.innovation[0] - 0.5).abs() < 1e-14);
    /// ```
    pub fn update(&mut self, measurement: &Measurement) -> Result<Option<Innovation>, Error> {
        Ok(self.step(measurement)?.1)
    }

    /// [`Self::update`], also returning the step's [`Prediction`]: what the smoother stores.
    /// On an error the filter is unchanged.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::UnscentedKalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
    /// use seqsmooth::model::observation::LinearObservation;
    /// let mut f = UnscentedKalmanFilter::new(PolynomialDynamics::new(1, 1), LinearObservation::value_of(2),
    ///     DVector::from_vec(vec![0.0, 1.0]), DMatrix::identity(2, 2), 0.0).unwrap();
    /// let m = Measurement { time: 1.0, values: vec![None], noise: NoiseCovariance::Identity };
    /// let (p, innovation) = f.step(&m).unwrap();
    /// assert!(innovation.is_none() && (p.from, p.time) == (0.0, 1.0));
    /// // D = Cov(x(0), x̄(1)) = S Φᵀ for a linear model: Φᵀ = [[1, 0], [1, 1]] here.
    /// assert!((p.cross[(0, 1)] - 0.0).abs() < 1e-15 && (p.cross[(0, 0)] - 1.0).abs() < 1e-15);
    /// ```
    pub fn step(
        &mut self,
        measurement: &Measurement,
    ) -> Result<(Prediction, Option<Innovation>), Error> {
        let p_all = self.observation.components();
        let (present, values) = measurement.present(p_all)?;
        let r = measurement_noise(p_all, measurement, &present)?;
        let prediction = self.prediction(measurement.time)?;
        if present.is_empty() {
            self.commit(
                prediction.time,
                prediction.state.clone(),
                prediction.covariance.clone(),
            );
            return Ok((prediction, None));
        }
        let (state, covariance, innovation) = self.correction(&prediction, &present, &values, r)?;
        self.commit(prediction.time, state, covariance);
        Ok((prediction, Some(innovation)))
    }

    fn commit(&mut self, time: f64, state: DVector<f64>, covariance: DMatrix<f64>) {
        self.state = state;
        self.covariance = covariance;
        self.time = time;
    }

    /// The prediction to `t` and the cross-covariance of the step, the filter unchanged.
    fn prediction(&self, t: f64) -> Result<Prediction, Error> {
        if !t.is_finite() {
            return Err(Error::NonFinite {
                what: "time",
                value: t,
            });
        }
        let (x, s) = (&self.state, &self.covariance);
        if t == self.time {
            return Ok(Prediction {
                from: self.time,
                time: t,
                state: x.clone(),
                covariance: s.clone(),
                cross: s.clone(),
            });
        }
        let w = &self.weights;
        let n = x.len();
        let points = w.points(x, s, Param::Covariance, self.time)?;
        let mut carried = DMatrix::zeros(n, 2 * n + 1);
        for i in 0..2 * n + 1 {
            let point = points.column(i).into_owned();
            let out = self.dynamics.propagate_state(&point, self.time, t)?;
            if out.len() != n {
                return Err(Error::InvalidParameter {
                    name: Param::Dynamics,
                    value: format!("a state of length {}", out.len()),
                    reason: format!("the dynamics have {n} states"),
                });
            }
            carried.column_mut(i).copy_from(&out);
        }
        let plain = |_: usize, a: f64, b: f64| a - b;
        let state = w.mean_of(&carried, plain);
        let after = w.deviations(&carried, &state, plain);
        let before = w.deviations(&points, x, plain);
        let mut covariance = w.covariance_of(&after, &after);
        if let Some(noise) = &self.noise {
            covariance += noise.covariance(self.time, t)?;
        }
        let cross = w.covariance_of(&before, &after);
        finite(state.as_slice(), "predicted state entry")?;
        finite(covariance.as_slice(), "predicted covariance")?;
        finite(cross.as_slice(), "predicted cross-covariance")?;
        positive_definite(&covariance, Param::PredictedCovariance, t, w)?;
        Ok(Prediction {
            from: self.time,
            time: t,
            state,
            covariance,
            cross,
        })
    }

    /// The update of `prediction` with the present components `present` measured as
    /// `values`, with `R` on them: the new state, covariance and the innovation.
    fn correction(
        &self,
        prediction: &Prediction,
        present: &[usize],
        values: &[f64],
        r: DMatrix<f64>,
    ) -> Result<(DVector<f64>, DMatrix<f64>, Innovation), Error> {
        let (w, t) = (&self.weights, prediction.time);
        let (x, s) = (&prediction.state, &prediction.covariance);
        let n = x.len();
        let k = present.len();
        let points = w.points(x, s, Param::PredictedCovariance, t)?;
        let mut seen = DMatrix::zeros(k, 2 * n + 1);
        for i in 0..2 * n + 1 {
            let g = self.observation.value(&points.column(i).into_owned(), t)?;
            if g.len() != self.observation.components() {
                return Err(Error::InvalidParameter {
                    name: Param::ObservationModel,
                    value: format!("{} values", g.len()),
                    reason: format!("the observation has {}", self.observation.components()),
                });
            }
            for (c, &a) in present.iter().enumerate() {
                seen[(c, i)] = g[a];
            }
        }
        let obs = &self.observation;
        let residual = |c: usize, a: f64, b: f64| obs.residual(present[c], a, b);
        let expected = w.mean_of(&seen, residual);
        let spread = w.deviations(&seen, &expected, residual);
        let v = w.covariance_of(&spread, &spread) + r;
        let states = w.deviations(&points, x, |_, a, b| a - b);
        let cross = w.covariance_of(&states, &spread);
        finite(v.as_slice(), "innovation covariance")?;
        let Some(factor) = Cholesky::new(v.clone()) else {
            return Err(Error::InvalidParameter {
                name: Param::InnovationCovariance,
                value: format!("at t = {t}"),
                reason: "is not positive definite".into(),
            });
        };
        let innovation = DVector::from_fn(k, |c, _| residual(c, values[c], expected[c]));
        // H = C_xy V⁻¹ = (V⁻¹ C_xyᵀ)ᵀ.
        let gain = factor.solve(&cross.transpose()).transpose();
        let state = x + &gain * &innovation;
        let mut covariance = s - &gain * (&v * gain.transpose());
        covariance = (&covariance + covariance.transpose()) * 0.5;
        let nis = innovation.dot(&factor.solve(&innovation));
        let log_det: f64 = factor
            .l_dirty()
            .diagonal()
            .iter()
            .map(|d| d.ln())
            .sum::<f64>()
            * 2.0;
        let log_likelihood = -0.5 * (nis + log_det + k as f64 * TAU.ln());
        finite(state.as_slice(), "updated state entry")?;
        finite(covariance.as_slice(), "updated covariance")?;
        positive_definite(&covariance, Param::Covariance, t, w)?;
        if !(nis.is_finite() && log_likelihood.is_finite()) {
            return Err(Error::EstimateOutOfRange {
                what: "normalised innovation squared".into(),
            });
        }
        let report = Innovation {
            components: present.to_vec(),
            innovation,
            covariance: v,
            gain,
            nis,
            log_likelihood,
        };
        Ok((state, covariance, report))
    }
}

/// `R` on the present components, after the checks of the Kalman filter: the shape, finite
/// entries, symmetric, non-negative variances.
fn measurement_noise(p: usize, m: &Measurement, present: &[usize]) -> Result<DMatrix<f64>, Error> {
    let entry = noise_entries(p, &m.noise)?;
    let full = DMatrix::from_fn(p, p, &entry);
    if let Some(&value) = full.iter().find(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            what: "measurement noise entry",
            value,
        });
    }
    let asymmetry = (&full - full.transpose()).amax();
    if asymmetry > 1e-12 * full.amax() || full.diagonal().iter().any(|&v| v < 0.0) {
        return Err(Error::InvalidParameter {
            name: Param::MeasurementNoise,
            value: format!("{full:?}"),
            reason: "must be symmetric with non-negative variances".into(),
        });
    }
    Ok(full.select_rows(present).select_columns(present))
}

/// Refuses a covariance `s` (named `name`, at time `t`) without a Cholesky factor: a negative
/// central weight `W₀ᶜ` can make the weighted sum of outer products indefinite (Julier
/// (2002) §III), and the next sigma points need the factor, so the filter keeps its last
/// estimate rather than one whose σ would be read as zero.
fn positive_definite(s: &DMatrix<f64>, name: Param, t: f64, w: &Weights) -> Result<(), Error> {
    if Cholesky::new(s.clone()).is_some() {
        return Ok(());
    }
    let w0c = w.covariance[0];
    let why = if w0c < 0.0 {
        format!(
            "is not positive definite; the central covariance weight W0c = {w0c} is negative \
             (choose alpha, beta and kappa with W0c >= 0, e.g. the defaults 1, 2, 0)"
        )
    } else {
        "is not positive definite".into()
    };
    Err(Error::InvalidParameter {
        name,
        value: format!("at t = {t}"),
        reason: why,
    })
}

fn finite(values: &[f64], what: &'static str) -> Result<(), Error> {
    match values.iter().find(|v| !v.is_finite()) {
        Some(&value) => Err(Error::NonFinite { what, value }),
        None => Ok(()),
    }
}

/// Refuses a covariance without a Cholesky factor (not positive definite), naming it: the
/// unscented filter draws its sigma points from that factor.
fn check_positive_definite(covariance: &DMatrix<f64>, name: Param) -> Result<(), Error> {
    if Cholesky::new(covariance.clone()).is_none() {
        return Err(Error::InvalidParameter {
            name,
            value: format!("{covariance:?}"),
            reason: "must be positive definite (the unscented filter draws its sigma points \
                     from its Cholesky factor)"
                .into(),
        });
    }
    Ok(())
}

impl<D: Dynamics, O: Observation> UnscentedKalmanFilter<D, O> {
    /// The dynamic and observation models.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::UnscentedKalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::{LinearObservation, Observation};
    /// let m = LinearObservation::new(DMatrix::from_row_slice(1, 2, &[1.0, 0.0])).unwrap();
    /// let (x, p) = (DVector::zeros(2), DMatrix::identity(2, 2));
    /// let f = UnscentedKalmanFilter::new(PolynomialDynamics::new(1, 1), m, x, p, 0.0).unwrap();
    /// assert_eq!(f.models().1.components(), 1);
    /// ```
    pub fn models(&self) -> (&D, &O) {
        (&self.dynamics, &self.observation)
    }

    /// The filter over the models `dynamics` and `observation` in place of its own (the same
    /// states and components, else refused), its estimate, time, sigma points and driving
    /// noise kept, as [`KalmanFilter::with_models`]: how a filter over a front end's own
    /// models is saved and restored ([`crate::persist`]).
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::UnscentedKalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::{Angles, LinearObservation};
    /// use seqsmooth::persist::{DynamicsLeftOut, ObservationLeftOut};
    /// let (d, o) = (PolynomialDynamics::new(1, 1), LinearObservation::value_of(2));
    /// let f = UnscentedKalmanFilter::new(d, o.clone(), DVector::zeros(2), DMatrix::identity(2, 2), 0.0)?;
    /// let bare = f.with_models(DynamicsLeftOut::new(2), ObservationLeftOut::new(2, Angles::new(1, &[])?))?;
    /// assert_eq!(bare.with_models(d, o)?.state().len(), 2);
    /// # Ok::<(), seqsmooth::Error>(())
    /// ```
    pub fn with_models<D2: Dynamics, O2: Observation>(
        self,
        dynamics: D2,
        observation: O2,
    ) -> Result<UnscentedKalmanFilter<D2, O2>, Error> {
        super::filter::same_shape(self.models(), &dynamics, &observation)?;
        Ok(UnscentedKalmanFilter {
            dynamics,
            observation,
            noise: self.noise,
            points: self.points,
            weights: self.weights,
            state: self.state,
            covariance: self.covariance,
            time: self.time,
        })
    }

    /// The driving-noise model taken out (the filter has none after), as
    /// [`KalmanFilter::take_process_noise`].
    pub fn take_process_noise(&mut self) -> Option<Arc<dyn ProcessNoise>> {
        self.noise.take()
    }

    /// A restored filter's invariants ([`crate::persist`]): state and covariance of the
    /// model's dimension, the sigma points' weights for it, the time finite.
    pub(crate) fn check_saved(&self) -> Result<(), String> {
        let n = self.dynamics.dimension();
        crate::linalg::invariant::vector(&self.state, n, "state")?;
        crate::linalg::invariant::covariance(&self.covariance, n, "covariance")?;
        let w = &self.weights;
        if w.n != n || w.mean.len() != 2 * n + 1 || w.covariance.len() != 2 * n + 1 {
            return Err(format!("sigma-point weights are not for {n} states"));
        }
        if !self.time.is_finite() {
            return Err(format!("time {} is not finite", self.time));
        }
        if self.noise.as_ref().is_some_and(|q| q.dimension() != n) {
            return Err(format!("noise model is not {n}-dimensional"));
        }
        Ok(())
    }
}
