//! The Bayes filter (Morrison ch. 10) in square-root information form, for linear dynamics:
//! the same recursion ([`crate::recursive::InformationFilter`], Gentleman's rotations of
//! [`crate::recursive::TriangularFactor`]) that the exact polynomial engine runs, here over any
//! [`Dynamics`] with `Φ` independent of the state and any [`Observation`].
//!
//! | step | information form | source |
//! |---|---|---|
//! | predict to `t_n` | `x(t_{n−1}) = Φ(t_{n−1}, t_n) x(t_n)`: `R ← R Φ(t_{n−1}, t_n)` | (10.2.40)-(10.2.41), §11.3 (11.3.3) |
//! | update | each whitened row of `M` folded into `R` (`(S_{n,n})⁻¹ = (S_{n,n−1})⁻¹ + Mᵀ R⁻¹ M`) | (10.2.42)-(10.2.44), (11.3.4) |
//! | estimate, covariance | `X = R⁻¹ d`, `S = R⁻¹ R⁻ᵀ` | (10.2.33)-(10.2.34) |
//!
//! Unlike the Kalman filter it can start from zero information (`(S_{1,0})⁻¹ = 0`, (10.3.1)-
//! (10.3.5)); the estimate exists once the observations determine it.
//!
//! With fading memory ([`BayesFilter::with_fading`], the fading-memory Bayes filter of
//! (14.4.26)-(14.4.32)) the information so far is multiplied by `θ^((t_n − t_(n−1))/τ)` or `θ`
//! before each update, so the estimate minimises the discounted criterion (14.2.10) or
//! (14.2.12); [`BayesFilter::covariance`] is then the estimate's true covariance `S*`
//! (14.3.11)-(14.3.13), and [`BayesFilter::information_covariance`] the recursion's own `P`. A nonlinear
//! observation is linearised about the current estimate (it must exist). A perfect observation
//! (zero variance) cannot be weighed in this form and is refused (§12.4 item 4: the Bayes
//! filter fails visibly).
//!
//! With driving noise ([`BayesFilter::with_process_noise`], ch. 15) each prediction adds
//! `Q(t_n, t_{n−1})` to the covariance the information stands for ((15.4.11), in the
//! square-root information form of [`InformationFilter::diffuse`]): the estimator is then the
//! Kalman filter's with the same `Q` (the Bayes and Kalman forms of one estimator, §12.2),
//! and unlike it may start from no information. Driving noise and fading memory are not
//! combined here (the true covariance (14.3.11) assumes none).

use crate::discount::Discount;
use crate::error::{Error, Param};
use crate::kalman::noise::{check_estimate, ProcessNoise};
use crate::model::dynamics::Dynamics;
use crate::model::measurement::Measurement;
use crate::model::measurement::NoiseCovariance;
use crate::model::observation::Observation;
use crate::recursive::InformationFilter;
use nalgebra::{Cholesky, DMatrix, DVector};
use std::sync::Arc;

/// The largest variance inflation at which [`BayesFilter`] reports an estimate. Rounding costs
/// the estimate and covariance about `0.1-1 ε` times the inflation of their σ (measured: 0.12
/// at degree 8 on the polynomial model, 1.1 on Ex. 14.9a's faded direction), so at most
/// `≈ 2e-5 σ` here; a degree-8 polynomial state at the end of its memory has about 1e8.
pub const MAX_VARIANCE_INFLATION: f64 = 1e11;

/// The Bayes filter on `D` (linear) and `O`.
///
/// ```
/// use nalgebra::DVector;
/// use seqsmooth::model::measurement::NoiseCovariance;
/// use seqsmooth::model::measurement::Measurement;
/// use seqsmooth::kalman::BayesFilter;
/// use seqsmooth::model::dynamics::PolynomialDynamics;
/// use seqsmooth::model::observation::LinearObservation;
/// // From no information: a line through two points is determined by them.
/// let mut f = BayesFilter::new(PolynomialDynamics::new(1, 1), LinearObservation::value_of(2), 0.0).unwrap();
/// for (t, y) in [(0.0, 1.0), (2.0, 5.0)] {
///     f.update(&Measurement { time: t, values: vec![Some(y)], noise: NoiseCovariance::Identity }).unwrap();
/// }
/// let x = f.estimate().unwrap();
/// assert!((x[0] - 5.0).abs() < 1e-14 && (x[1] - 2.0).abs() < 1e-14);
/// ```
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct BayesFilter<D: Dynamics, O: Observation> {
    dynamics: D,
    observation: O,
    info: InformationFilter,
    time: f64,
    /// The discount and the time of the last update (from which a discount per time counts).
    fading: Option<(Discount, f64)>,
    /// Whether there is information to discount (a prior or an update).
    informed: bool,
    /// The driving noise added at each prediction (ch. 15), if any.
    #[serde(with = "crate::kalman::saved_noise::field")]
    noise: Option<Arc<dyn ProcessNoise>>,
}

impl<D: Dynamics, O: Observation> BayesFilter<D, O> {
    /// A filter at `time` with no information (`(S_{1,0})⁻¹ = 0`, (10.3.5)). The dynamics must
    /// be linear ([`Dynamics::is_linear`]).
    ///
    /// ```
    /// use seqsmooth::kalman::BayesFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let f = BayesFilter::new(PolynomialDynamics::new(1, 1), LinearObservation::value_of(2), 0.0).unwrap();
    /// assert!(f.estimate().is_none());
    /// ```
    pub fn new(dynamics: D, observation: O, time: f64) -> Result<Self, Error> {
        let n = dynamics.dimension();
        if !dynamics.is_linear() {
            return Err(Error::InvalidParameter {
                name: Param::Dynamics,
                value: "a nonlinear model".into(),
                reason: "the Bayes filter here needs Φ independent of the state (linear \
                         dynamics); use the extended Kalman filter"
                    .into(),
            });
        }
        if observation.state_dimension() != n {
            return Err(Error::InvalidParameter {
                name: Param::ObservationModel,
                value: format!("for {} states", observation.state_dimension()),
                reason: format!("the dynamics have {n} states"),
            });
        }
        if !time.is_finite() {
            return Err(Error::NonFinite {
                what: "time",
                value: time,
            });
        }
        Ok(Self {
            dynamics,
            observation,
            info: InformationFilter::new(n),
            time,
            fading: None,
            informed: false,
            noise: None,
        })
    }

    /// With the prior `state` and its `covariance` (symmetric positive definite).
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::BayesFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let f = BayesFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1), 0.0)
    ///     .unwrap()
    ///     .with_prior(&DVector::from_vec(vec![3.0]), &DMatrix::from_element(1, 1, 4.0))
    ///     .unwrap();
    /// assert!((f.estimate().unwrap()[0] - 3.0).abs() < 1e-15);
    /// assert!((f.covariance().unwrap()[(0, 0)] - 4.0).abs() < 1e-14);
    /// ```
    pub fn with_prior(
        mut self,
        state: &DVector<f64>,
        covariance: &DMatrix<f64>,
    ) -> Result<Self, Error> {
        let n = self.dynamics.dimension();
        if state.len() != n || covariance.shape() != (n, n) {
            return Err(Error::InvalidParameter {
                name: Param::Prior,
                value: format!(
                    "state of length {}, covariance {}x{}",
                    state.len(),
                    covariance.nrows(),
                    covariance.ncols()
                ),
                reason: format!("the model has {n} states"),
            });
        }
        if let Some(&value) = state
            .iter()
            .chain(covariance.iter())
            .find(|v| !v.is_finite())
        {
            return Err(Error::NonFinite {
                what: "prior entry",
                value,
            });
        }
        if (covariance - covariance.transpose()).abs().max() > 1e-12 * covariance.abs().max() {
            return Err(not_positive_definite(Param::PriorCovariance, covariance));
        }
        self.inform(state, covariance, Param::PriorCovariance)?;
        Ok(self)
    }

    /// Replaces the information by that of the estimate `state` with `covariance` at the
    /// current time, as a prior ((10.3.8): `(S_{n,n})⁻¹` from it, the information before
    /// forgotten), checked by [`check_estimate`] and positive definite (the information form
    /// needs `S⁻¹`); with fading memory the discount counts from now (§14.5). On an error the
    /// filter is unchanged.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::BayesFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let mut f = BayesFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1), 0.0).unwrap();
    /// f.set_estimate(&DVector::from_vec(vec![3.0]), &DMatrix::from_element(1, 1, 4.0)).unwrap();
    /// assert!((f.std_devs().unwrap()[0] - 2.0).abs() < 1e-15);
    /// // Singular: no information form; refused, the filter unchanged.
    /// assert!(f.set_estimate(&DVector::zeros(1), &DMatrix::zeros(1, 1)).is_err());
    /// assert!((f.estimate().unwrap()[0] - 3.0).abs() < 1e-15);
    /// ```
    pub fn set_estimate(
        &mut self,
        state: &DVector<f64>,
        covariance: &DMatrix<f64>,
    ) -> Result<(), Error> {
        check_estimate(state, covariance, self.dynamics.dimension())?;
        self.inform(state, covariance, Param::StateCovarianceP)?;
        if let Some((_, last)) = &mut self.fading {
            *last = self.time;
        }
        Ok(())
    }

    /// The information of `state` with `covariance` (finite, symmetric) as the filter's:
    /// `S⁻¹ = L⁻ᵀ L⁻¹` (`S = L Lᵀ`), its factor `R = L_Jᵀ` with `J = L_J L_Jᵀ`; a covariance
    /// that is not positive definite is refused naming `name`, the filter unchanged.
    fn inform(
        &mut self,
        state: &DVector<f64>,
        covariance: &DMatrix<f64>,
        name: Param,
    ) -> Result<(), Error> {
        let refuse = || not_positive_definite(name, covariance);
        let l = Cholesky::new(covariance.clone()).ok_or_else(refuse)?;
        let information = l.inverse();
        let information = (&information + information.transpose()) * 0.5;
        let r = Cholesky::new(information)
            .ok_or_else(refuse)?
            .l()
            .transpose();
        let info = InformationFilter::with_prior(state, &r);
        self.info = match self.fading {
            Some(_) => info.with_true_covariance(),
            None => info,
        };
        self.informed = true;
        Ok(())
    }

    /// With driving noise (ch. 15): `Q(t_n, t_{n−1})` ([`ProcessNoise`]) added at each
    /// prediction, (15.4.11) in information form ([`InformationFilter::diffuse`]). Refused
    /// with fading memory, and for other than the dynamics' states.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::noise::WhiteNoiseDerivative;
    /// use seqsmooth::kalman::BayesFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let mut f = BayesFilter::new(PolynomialDynamics::new(1, 1), LinearObservation::value_of(2), 0.0)
    ///     .unwrap()
    ///     .with_prior(&DVector::zeros(2), &DMatrix::identity(2, 2))
    ///     .unwrap()
    ///     .with_process_noise(WhiteNoiseDerivative::new(1, 1, 3.0).unwrap())
    ///     .unwrap();
    /// f.predict(1.0).unwrap();
    /// // Φ S Φᵀ + Q: [[2, 1], [1, 1]] + 3 [[1/3, 1/2], [1/2, 1]].
    /// let want = DMatrix::from_row_slice(2, 2, &[3.0, 2.5, 2.5, 4.0]);
    /// assert!((f.covariance().unwrap() - want).amax() < 1e-14);
    /// ```
    pub fn with_process_noise<P: ProcessNoise + 'static>(
        mut self,
        noise: P,
    ) -> Result<Self, Error> {
        let n = self.dynamics.dimension();
        super::noise::check_noise_dimension(&noise, n)?;
        if self.fading.is_some() {
            return Err(noise_with_fading());
        }
        self.noise = Some(Arc::new(noise));
        Ok(self)
    }

    /// The fading-memory Bayes filter (14.4.26)-(14.4.32): before each update the information
    /// so far is multiplied by the discount over the step ([`Discount`]: `θ^(Δt/τ)` for `θ`
    /// per span `τ` of time, `Δt` since the last update, or `θ` per update);
    /// [`Self::covariance`] becomes the true covariance. `0 < θ < 1`: without fading memory the
    /// filter is the plain one.
    ///
    /// ```
    /// use seqsmooth::model::measurement::NoiseCovariance;
    /// use seqsmooth::model::measurement::Measurement;
    /// use seqsmooth::kalman::{BayesFilter, Discount};
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// // A constant with θ = 1/2: the fading-memory polynomial filter of degree 0, whose
    /// // variance tends to (1 − θ)/(1 + θ) = 1/3 (Table 13.2).
    /// let mut f = BayesFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1), 0.0)
    ///     .unwrap()
    ///     .with_fading(Discount::PerUpdate { theta: 0.5 })
    ///     .unwrap();
    /// for k in 0..60 {
    ///     f.update(&Measurement { time: k as f64, values: vec![Some(1.0)], noise: NoiseCovariance::Identity }).unwrap();
    /// }
    /// assert!((f.covariance().unwrap()[(0, 0)] - 1.0 / 3.0).abs() < 1e-12);
    /// assert!((f.information_covariance().unwrap()[(0, 0)] - 0.5).abs() < 1e-12); // 1 − θ
    /// ```
    pub fn with_fading(mut self, discount: Discount) -> Result<Self, Error> {
        if self.noise.is_some() {
            return Err(noise_with_fading());
        }
        self.fading = Some((discount.checked()?, self.time));
        self.info = self.info.with_true_covariance();
        Ok(self)
    }

    /// The estimate at [`Self::time`], once the information determines it (to working
    /// accuracy: see [`MAX_VARIANCE_INFLATION`]).
    ///
    /// ```
    /// use nalgebra::DVector;
    /// use seqsmooth::model::measurement::NoiseCovariance;
    /// use seqsmooth::model::measurement::Measurement;
    /// use seqsmooth::kalman::BayesFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let mut f = BayesFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1), 0.0).unwrap();
    /// f.update(&Measurement { time: 1.0, values: vec![Some(2.0)], noise: NoiseCovariance::Variances(vec![4.0]) }).unwrap();
    /// assert_eq!(f.estimate().unwrap()[0], 2.0);
    /// ```
    pub fn estimate(&self) -> Option<DVector<f64>> {
        self.determined().then(|| self.info.solve()).flatten()
    }

    /// Its covariance, once determined: `(RᵀR)⁻¹`, or with fading memory the true covariance
    /// `S* = P (Σ w_k² M_kᵀ R_k⁻¹ M_k) P` (14.3.11)-(14.3.13).
    ///
    /// ```
    /// use nalgebra::DVector;
    /// use seqsmooth::model::measurement::NoiseCovariance;
    /// use seqsmooth::model::measurement::Measurement;
    /// use seqsmooth::kalman::BayesFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let mut f = BayesFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1), 0.0).unwrap();
    /// f.update(&Measurement { time: 1.0, values: vec![Some(2.0)], noise: NoiseCovariance::Variances(vec![4.0]) }).unwrap();
    /// assert!((f.covariance().unwrap()[(0, 0)] - 4.0).abs() < 1e-14);
    /// ```
    pub fn covariance(&self) -> Option<DMatrix<f64>> {
        self.determined().then(|| self.info.covariance()).flatten()
    }

    /// The 1σ of each state component, `√diag(S)` of [`Self::covariance`], once determined.
    pub fn std_devs(&self) -> Option<Vec<f64>> {
        self.covariance().map(|s| crate::linalg::std_devs(&s))
    }

    /// The recursion's own matrix `P = (RᵀR)⁻¹` (14.3.13), the inverse of the discounted
    /// information: the covariance itself without fading memory.
    ///
    /// ```
    /// use seqsmooth::model::measurement::NoiseCovariance;
    /// use seqsmooth::model::measurement::Measurement;
    /// use seqsmooth::kalman::{BayesFilter, Discount};
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let mut f = BayesFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1), 0.0)
    ///     .unwrap()
    ///     .with_fading(Discount::PerTime { theta: 0.25, tau: 1.0 })
    ///     .unwrap();
    /// for t in [0.0, 1.0] {
    ///     f.update(&Measurement { time: t, values: vec![Some(t)], noise: NoiseCovariance::Identity }).unwrap();
    /// }
    /// // information 1/4 + 1: P = 4/5; S* = (1/16 + 1)·P² = 17/25.
    /// assert!((f.information_covariance().unwrap()[(0, 0)] - 0.8).abs() < 1e-15);
    /// assert!((f.covariance().unwrap()[(0, 0)] - 0.68).abs() < 1e-15);
    /// ```
    pub fn information_covariance(&self) -> Option<DMatrix<f64>> {
        self.determined()
            .then(|| self.info.information_covariance())
            .flatten()
    }

    /// Whether the information determines the state to working accuracy: every pivot non-zero
    /// and the largest variance inflation ([`InformationFilter::variance_inflation`]) at most
    /// [`MAX_VARIANCE_INFLATION`]. Beyond it some direction has next to no information (under
    /// fading memory, one the observations never see: its information fades as `θ^n`), and
    /// the estimate and covariance would carry rounding errors of up to `ε` times the
    /// inflation of their σ, so they are refused instead.
    fn determined(&self) -> bool {
        self.info
            .variance_inflation()
            .is_some_and(|v| v <= MAX_VARIANCE_INFLATION)
    }

    /// The time the information refers to.
    ///
    /// ```
    /// use nalgebra::DVector;
    /// use seqsmooth::model::measurement::NoiseCovariance;
    /// use seqsmooth::model::measurement::Measurement;
    /// use seqsmooth::kalman::BayesFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let mut f = BayesFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1), 0.0).unwrap();
    /// f.update(&Measurement { time: 1.0, values: vec![Some(2.0)], noise: NoiseCovariance::Variances(vec![4.0]) }).unwrap();
    /// assert_eq!(f.time(), 1.0);
    /// ```
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Carries the information to `t`: `R ← R Φ(t_old, t)` (10.2.40)-(10.2.41).
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::BayesFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let mut f = BayesFilter::new(PolynomialDynamics::new(1, 1), LinearObservation::value_of(2), 0.0)
    ///     .unwrap()
    ///     .with_prior(&DVector::from_vec(vec![1.0, 2.0]), &DMatrix::identity(2, 2))
    ///     .unwrap();
    /// f.predict(1.0).unwrap();
    /// assert!((f.estimate().unwrap()[0] - 3.0).abs() < 1e-14);
    /// assert!((f.covariance().unwrap()[(0, 0)] - 2.0).abs() < 1e-14); // Φ S Φᵀ
    /// ```
    pub fn predict(&mut self, t: f64) -> Result<(), Error> {
        if !t.is_finite() {
            return Err(Error::NonFinite {
                what: "time",
                value: t,
            });
        }
        if t == self.time {
            return Ok(());
        }
        let n = self.dynamics.dimension();
        let (mut x, mut back) = (DVector::zeros(n), DMatrix::zeros(n, n));
        // Φ(t_old, t) does not depend on the state (linear dynamics).
        self.dynamics
            .propagate_into(&DVector::zeros(n), t, self.time, &mut x, &mut back)?;
        // The noise's square root `G` (`Q = G Gᵀ`), before anything changes.
        let root = match &self.noise {
            Some(noise) => Some(noise_root(&noise.covariance(self.time, t)?)?),
            None => None,
        };
        self.info.change_variables(&back);
        if let Some(g) = root {
            self.info.diffuse(&g);
        }
        self.time = t;
        Ok(())
    }

    /// Predicts to the measurement's time and folds in its present components, whitened by
    /// `R` ((10.2.42)-(10.2.44)). On an error the filter is unchanged.
    ///
    /// ```
    /// use nalgebra::DVector;
    /// use seqsmooth::model::measurement::NoiseCovariance;
    /// use seqsmooth::model::measurement::Measurement;
    /// use seqsmooth::kalman::BayesFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let mut f = BayesFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1), 0.0).unwrap();
    /// f.update(&Measurement { time: 1.0, values: vec![Some(2.0)], noise: NoiseCovariance::Variances(vec![4.0]) }).unwrap();
    /// assert!(f.update(&Measurement { time: 2.0, values: vec![Some(1.0)], noise: NoiseCovariance::Variances(vec![0.0]) }).is_err());
    /// assert_eq!(f.time(), 1.0);
    /// ```
    pub fn update(&mut self, measurement: &Measurement) -> Result<(), Error> {
        let p = self.observation.components();
        let (present, values) = measurement.present(p)?;
        let whitener = whitener(p, &measurement.noise, &present)?;
        let saved = (self.info.clone(), self.time, self.fading);
        self.predict(measurement.time)?;
        if present.is_empty() {
            return Ok(());
        }
        let result = self
            .fade()
            .and_then(|()| self.fold(&present, &values, &whitener))
            .and_then(|()| self.check_finite());
        match result {
            Ok(()) => self.informed = true,
            Err(_) => (self.info, self.time, self.fading) = saved,
        }
        result
    }

    /// Refuses an update after which the estimate or its covariance leaves the double range.
    fn check_finite(&self) -> Result<(), Error> {
        let (Some(x), Some(c)) = (self.estimate(), self.covariance()) else {
            return Ok(());
        };
        match x.iter().chain(c.iter()).find(|v| !v.is_finite()) {
            Some(&value) => Err(Error::NonFinite {
                what: "estimate or covariance entry after the update",
                value,
            }),
            None => Ok(()),
        }
    }

    /// Multiplies the information so far by the discount over the step since the last update
    /// ((14.4.26)-(14.4.27)).
    fn fade(&mut self) -> Result<(), Error> {
        if let Some((discount, last)) = &mut self.fading {
            if !self.informed {
                // Nothing to discount: the memory starts here, whatever the time origin.
                *last = self.time;
                return Ok(());
            }
            let f = discount.factor_over(self.time - *last)?;
            self.info.fade(1.0 / f.sqrt());
            *last = self.time;
        }
        Ok(())
    }

    /// Folds the present components' whitened rows into the information.
    fn fold(
        &mut self,
        present: &[usize],
        values: &[f64],
        whitener: &DMatrix<f64>,
    ) -> Result<(), Error> {
        let n = self.dynamics.dimension();
        let p = self.observation.components();
        let linear = self.observation.is_linear();
        let about = if linear {
            DVector::zeros(n)
        } else {
            self.estimate().ok_or_else(|| Error::InvalidParameter {
                name: Param::ObservationModel,
                value: "nonlinear".into(),
                reason: "the Bayes filter linearises it about its estimate, which the \
                         information so far does not determine: give a prior"
                    .into(),
            })?
        };
        let (mut g, mut m_all) = (DVector::zeros(p), DMatrix::zeros(p, n));
        self.observation
            .predict_into(&about, self.time, &mut g, &mut m_all)?;
        let k = present.len();
        let m = DMatrix::from_fn(k, n, |i, j| m_all[(present[i], j)]);
        // y' = y (linear), or the residual about x̄ plus M x̄ (linearised).
        let y = if linear {
            DVector::from_column_slice(values)
        } else {
            let mx = &m * &about;
            DVector::from_fn(k, |i, _| {
                self.observation
                    .residual(present[i], values[i], g[present[i]])
                    + mx[i]
            })
        };
        let (wm, wy) = (whitener * m, whitener * y);
        if let Some(&value) = wm.iter().chain(wy.iter()).find(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "whitened observation",
                value,
            });
        }
        let mut row = vec![0.0; n];
        for i in 0..k {
            for (j, v) in row.iter_mut().enumerate() {
                *v = wm[(i, j)];
            }
            self.info.observe(&row, wy[i], 1.0);
        }
        Ok(())
    }
}

/// The refusal of a covariance the information form cannot hold.
fn not_positive_definite(name: Param, covariance: &DMatrix<f64>) -> Error {
    Error::InvalidParameter {
        name,
        value: format!("{covariance:?}"),
        reason: "must be symmetric positive definite (the Bayes filter holds its inverse)".into(),
    }
}

/// The refusal of driving noise with fading memory in the Bayes filter.
fn noise_with_fading() -> Error {
    Error::InvalidParameter {
        name: Param::ProcessNoise,
        value: "with fading memory".into(),
        reason: "the Bayes filter's true covariance under fading memory (14.3.11) assumes no \
                 driving noise: use one or the other (the Kalman filter takes both)"
            .into(),
    }
}

/// A square root `G` of the driving noise's `Q` (`Q = G Gᵀ`): its Cholesky factor, or for a
/// singular `Q` the symmetric eigendecomposition's `V √Λ` (negative rounding clipped to 0);
/// refused unless finite.
fn noise_root(q: &DMatrix<f64>) -> Result<DMatrix<f64>, Error> {
    if let Some(&value) = q.iter().find(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            what: "driving-noise covariance Q",
            value,
        });
    }
    if let Some(c) = Cholesky::new(q.clone()) {
        return Ok(c.l());
    }
    let e = nalgebra::SymmetricEigen::new((q + q.transpose()) * 0.5);
    let roots = e.eigenvalues.map(|v| v.max(0.0).sqrt());
    Ok(e.eigenvectors * DMatrix::from_diagonal(&roots))
}

/// `L⁻¹` for the present components' `R = L Lᵀ` (positive definite: the information form
/// needs `R⁻¹`).
fn whitener(p: usize, noise: &NoiseCovariance, present: &[usize]) -> Result<DMatrix<f64>, Error> {
    let k = present.len();
    let r = match noise {
        NoiseCovariance::Identity => DMatrix::identity(k, k),
        NoiseCovariance::Variances(v) if v.len() == p => {
            DMatrix::from_fn(k, k, |i, j| if i == j { v[present[i]] } else { 0.0 })
        }
        NoiseCovariance::Full(r) if r.shape() == (p, p) => {
            DMatrix::from_fn(k, k, |i, j| r[(present[i], present[j])])
        }
        other => {
            return Err(Error::InvalidParameter {
                name: Param::MeasurementNoise,
                value: format!("{other:?}"),
                reason: format!("needs {p} components"),
            })
        }
    };
    let refuse = || Error::InvalidParameter {
        name: Param::MeasurementNoise,
        value: format!("{r:?}"),
        reason: "must be finite, symmetric and positive definite (the Bayes filter weighs by \
                 R⁻¹; a perfect observation needs the Kalman filter)"
            .into(),
    };
    if r.iter().any(|v| !v.is_finite()) || (&r - r.transpose()).abs().max() > 1e-12 * r.abs().max()
    {
        return Err(refuse());
    }
    if k == 0 {
        return Ok(DMatrix::zeros(0, 0));
    }
    let l = Cholesky::new(r.clone()).ok_or_else(refuse)?.l();
    l.solve_lower_triangular(&DMatrix::identity(k, k))
        .ok_or_else(refuse)
}

impl<D: Dynamics, O: Observation> BayesFilter<D, O> {
    /// The dynamic and observation models.
    ///
    /// ```
    /// use seqsmooth::kalman::bayes::BayesFilter;
    /// use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
    /// use seqsmooth::model::observation::{LinearObservation, Observation};
    /// let m = LinearObservation::new(nalgebra::DMatrix::from_row_slice(1, 2, &[1.0, 0.0])).unwrap();
    /// let f = BayesFilter::new(PolynomialDynamics::new(1, 1), m, 0.0).unwrap();
    /// assert_eq!((f.models().0.dimension(), f.models().1.components()), (2, 1));
    /// ```
    pub fn models(&self) -> (&D, &O) {
        (&self.dynamics, &self.observation)
    }

    /// A restored filter's invariants ([`crate::persist`]): the information of the model's
    /// dimension, the time finite.
    pub(crate) fn check_saved(&self) -> Result<(), String> {
        self.info.check_saved()?;
        if self.info.dim() != self.dynamics.dimension() || !self.time.is_finite() {
            return Err(
                "information is not of the model's dimension, or the time not finite".into(),
            );
        }
        Ok(())
    }
}
