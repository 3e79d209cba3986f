//! The Kalman filter (Morrison ch. 12, with driving noise ch. 15), in its one-pass extended
//! form for nonlinear models (§12.5, (12.5.19)-(12.5.23)): any [`Dynamics`] and
//! [`Observation`], on any times.
//!
//! | step | | source |
//! |---|---|---|
//! | `X_{n,n−1} = X(t_n)` from `X_{n−1,n−1}`, with `Φ(t_n, t_{n−1})` | [`Dynamics::propagate_into`] | (12.2.15), (15.4.10) |
//! | `S_{n,n−1} = Φ S_{n−1,n−1} Φᵀ + Q(t_n, t_{n−1})` | [`ProcessNoise`] | (12.2.16), (15.4.11) |
//! | `ν = Y_n − G(X_{n,n−1})`, `V = M S_{n,n−1} Mᵀ + R_n` (present components) | [`Observation::predict_into`] | (12.2.17) |
//! | `H = S_{n,n−1} Mᵀ V⁻¹` (`V = L D Lᵀ`, square-root-free Cholesky) | | (12.2.17), (15.4.12) |
//! | `X_{n,n} = X_{n,n−1} + H ν` | | (12.2.19), (15.4.14) |
//! | `S_{n,n} = (I − H M) S_{n,n−1} (I − H M)ᵀ + H R Hᵀ` | Joseph form | (12.3.7) |
//!
//! The covariance update is Joseph's form (12.3.7), not (12.2.18): it is the covariance of the
//! estimate for the gain actually used, a sum of two positive semidefinite terms, so it stays
//! symmetric positive semidefinite where `(I − H M) S` loses it by cancellation (§12.4 item 5,
//! Ex. 12.16); as applied here (below) it costs `O(n² k)` more than (12.2.18) for `k`
//! components. A perfect observation (`R = 0`, Ex. 12.12, 12.13) is allowed while `V` stays
//! positive definite.
//!
//! Each update reports its innovation `ν`, its covariance `V`, the normalised innovation
//! squared `NIS = νᵀ V⁻¹ ν` (χ² with as many degrees of freedom as components when the model
//! holds, §14.8) and the Gaussian log-likelihood `−(NIS + ln det V + p ln 2π)/2`.
//!
//! The filter cannot start from zero information (§12.4 item 2): it needs a prior state and
//! covariance, e.g. from [`crate::estimate::gauss_newton`] on the first observations.
//!
//! ## The arithmetic
//!
//! One recursion serves every model and size; what makes it fast is where it works and in
//! which order it multiplies, not a second copy:
//!
//! - The filter keeps its work buffers ([`Dynamics::propagate_into`],
//!   [`ProcessNoise::covariance_into`] and [`Observation::predict_into`] fill them), writes each
//!   prediction and update there, and swaps them in only when every check has passed: nothing
//!   is allocated per update for the polynomial and radar models, and an update that fails
//!   leaves the filter as it was. [`KalmanFilter::update_stats`] reports the NIS and
//!   log-likelihood without building an [`Innovation`]'s vectors.
//! - `Φ S Φᵀ` is two products `X Φᵀ`, each an `axpy` of columns with `Φ`'s entries as the
//!   scalars, skipping its zeros (`Ψ ⊗ I`, (4.2.5), is mostly zeros: 9 of 36 entries are not for
//!   constant velocity on three axes); `S Mᵀ` and `X Mᵀ` skip the zeros of `M` likewise.
//!   Adding `0 · a` changes nothing for a finite `a`, so skipping them changes no result.
//! - Joseph's form applies `I − H M` from each side instead of forming it:
//!   `X = S − H (M S)`, then `X − (X Mᵀ) Hᵀ + H R Hᵀ`, `O(n² k)` for `k` components instead of
//!   `O(n³)`: the same products associated differently (for any gain, not only the optimal
//!   one).
//! - `V = L D Lᵀ` (the square-root-free Cholesky factorisation) gives the gain
//!   `H = (S Mᵀ) L⁻ᵀ D⁻¹ L⁻¹`, `NIS = Σ (L⁻¹ ν)_c² / D_c` and `ln det V = Σ ln D_c`, with no square
//!   root and fewer roundings than `L Lᵀ`.
//! - The polynomial model (`Dynamics::polynomial`: `n ≤ 9` states on `d ≤ 3` axes, with
//!   [`WhiteNoiseDerivative`](super::noise::WhiteNoiseDerivative) or no driving noise) is
//!   predicted at compile-time sizes, `Φ`'s zeros known to the compiler (`kalman::filter::fixed`),
//!   a constant `M` ([`Observation::linear_matrix`]) is read in place, and `R`'s identity and
//!   variances are checked at once: chosen without the caller asking, the same numbers bit for
//!   bit. With a constant `M` of at most 3 rows the whole update ([`KalmanFilter::update`],
//!   [`KalmanFilter::update_stats`]) is one function compiled for each `n` and `k`, on
//!   fixed-size arrays the compiler keeps in registers: the correction kernel's operations
//!   written out for them in its order (the one place the recursion is written twice, as the
//!   radar's update is; tested bit for bit against the general path), the estimate written to
//!   the filter once, what it needs of the models read when they change.
//! - The state dimension `n` and the present components `k` go through the crate's one size
//!   dispatch (`unrolled_sizes!`, [`crate::numeric`]): for `n ≤ 9` and `k ≤ 4` each kernel is
//!   compiled with them constants (its loops unrolled), other sizes take the same source with
//!   them variables. Measured in BENCHMARKS.md ("Kalman and extended Kalman filters against
//!   filterpy").

use super::correct::{carry, correct_kernel, finite, Work};
use super::noise::ProcessNoise;
use crate::discount::Discount;
use crate::error::{Error, Param};
use crate::linalg::dense::all_finite;
use crate::model::dynamics::Dynamics;
use crate::model::measurement::Measurement;
use crate::model::observation::{linear_value, Observation};
use crate::numeric::unrolled::{unrolled_sizes, Any, Fixed};
use nalgebra::{DMatrix, DVector};
use std::f64::consts::TAU;
use std::sync::Arc;

mod fixed;
mod innovation;
mod iterated;
mod measure;
mod radar;
mod saved;
mod undo;
pub use innovation::{Innovation, InnovationStats};
pub use iterated::{check_iteration_limits, IterationLimits};
pub(crate) use saved::same_shape;

use fixed::Plan;

/// A Kalman filter on `D` and `O`, with optional driving noise.
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::model::measurement::NoiseCovariance;
/// use seqsmooth::model::measurement::Measurement;
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
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct KalmanFilter<D: Dynamics, O: Observation> {
    dynamics: D,
    observation: O,
    #[serde(with = "crate::kalman::saved_noise::field")]
    noise: Option<Arc<dyn ProcessNoise>>,
    fading: Option<Fading>,
    state: DVector<f64>,
    covariance: DMatrix<f64>,
    time: f64,
    /// Scratch: not saved; made anew on restoring ([`crate::persist`]).
    #[serde(skip)]
    work: Work,
    /// What the fixed-size path needs of the models, made when first needed after they
    /// change: not saved.
    #[serde(skip)]
    plan: Plan,
}

/// The fading filter's own matrix `P` (14.3.13), not the covariance when the discount is
/// below 1, and the time of the last update (from which a discount per time counts).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
struct Fading {
    discount: Discount,
    weight: DMatrix<f64>,
    last_update: f64,
}

impl Fading {
    /// `θ^((t − t_last)/τ)` or `θ`, in `(0, 1)` ([`Discount`]'s factor over the step).
    fn factor(&self, t: f64) -> Result<f64, Error> {
        self.discount.factor_over(t - self.last_update)
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
        let bad = |name: Param, value: String, reason: String| Error::InvalidParameter {
            name,
            value,
            reason,
        };
        if observation.state_dimension() != n {
            return Err(bad(
                Param::ObservationModel,
                format!("for {} states", observation.state_dimension()),
                format!("the dynamics have {n} states"),
            ));
        }
        check_prior(n, &state, &covariance, time)?;
        let work = Work::new(n, observation.components());
        Ok(Self {
            dynamics,
            observation,
            noise: None,
            fading: None,
            state,
            covariance,
            time,
            work,
            plan: Plan::Unknown,
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
        self.set_process_noise(noise)?;
        Ok(self)
    }

    /// The generalized fading-memory filter of ch. 14 ((14.4.34)-(14.4.40)): the gain from
    /// the recursion's own matrix `P`, `H = P Mᵀ (f R + M P Mᵀ)⁻¹`, `P ← (1/f)(I − H M) P` (in
    /// Joseph's form), with `f = θ^((t_n − t_{n−1})/τ)` (time since the previous update;
    /// Morrison's `β^(t_n − t_{n−1})` with `β = θ^(1/τ)`) or `θ` per update ([`Discount`]);
    /// the covariance reported, [`Self::covariance`], is the true one of the estimate
    /// ((14.4.31)-(14.4.32), (14.3.19)), and the innovation statistics use it (§14.8). `P`
    /// starts as the current covariance, counted from the current time (start without fading
    /// and switch, §14.5). `0 < θ < 1`, `τ > 0`: without fading memory, the plain filter.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::model::measurement::NoiseCovariance;
    /// use seqsmooth::model::measurement::Measurement;
    /// use seqsmooth::kalman::{Discount, KalmanFilter};
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// // Degree 0, θ = 0.5, vague prior: the gain settles at 1 − θ = 0.5 (Table 13.1).
    /// let mut f = KalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
    ///     DVector::zeros(1), DMatrix::from_element(1, 1, 1e9), 0.0).unwrap()
    ///     .with_fading(Discount::PerUpdate { theta: 0.5 }).unwrap();
    /// let mut gain = 0.0;
    /// for k in 1..60 {
    ///     let m = Measurement { time: k as f64, values: vec![Some(1.0)], noise: NoiseCovariance::Identity };
    ///     gain = f.update(&m).unwrap().unwrap().gain[(0, 0)];
    /// }
    /// assert!((gain - 0.5).abs() < 1e-12);
    /// assert!((f.covariance()[(0, 0)] - 1.0 / 3.0).abs() < 1e-12); // (1 − θ)/(1 + θ)
    /// ```
    pub fn with_fading(mut self, discount: Discount) -> Result<Self, Error> {
        self.set_fading(discount)?;
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

    /// The 1σ of each state component, `√diag(S)` (as `PolynomialState::std_devs`).
    pub fn std_devs(&self) -> Vec<f64> {
        crate::linalg::std_devs(&self.covariance)
    }

    /// Replaces the estimate: `state` and `covariance` at `time`, checked by
    /// [`check_estimate`](super::noise::check_estimate) (`n` finite numbers; a finite,
    /// symmetric, positive semidefinite `n × n` covariance), the time finite (a fading
    /// filter's own matrix `P` restarts at the covariance, §14.5). On an error the filter is
    /// unchanged.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::KalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let mut f = KalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
    ///     DVector::zeros(1), DMatrix::identity(1, 1), 0.0).unwrap();
    /// f.set_estimate(DVector::from_vec(vec![2.0]), DMatrix::identity(1, 1) * 4.0, 1.0).unwrap();
    /// assert_eq!((f.state()[0], f.std_devs()[0], f.time()), (2.0, 2.0, 1.0));
    /// assert!(f.set_estimate(DVector::zeros(2), DMatrix::identity(2, 2), 1.0).is_err());
    /// // Not positive semidefinite: refused, the filter unchanged.
    /// assert!(f.set_estimate(DVector::zeros(1), DMatrix::from_element(1, 1, -1.0), 1.0).is_err());
    /// assert_eq!(f.std_devs()[0], 2.0);
    /// ```
    pub fn set_estimate(
        &mut self,
        state: DVector<f64>,
        covariance: DMatrix<f64>,
        time: f64,
    ) -> Result<(), Error> {
        super::noise::check_estimate_at(&state, &covariance, self.state.len(), time)?;
        if let Some(f) = &mut self.fading {
            f.weight.copy_from(&covariance);
            f.last_update = time;
        }
        (self.state, self.covariance, self.time) = (state, covariance, time);
        Ok(())
    }

    /// The observation model.
    pub fn observation(&self) -> &O {
        &self.observation
    }

    /// Replaces the observation model by one of the same state dimension and components
    /// (a time-varying `H`). On an error the filter is unchanged.
    pub fn set_observation(&mut self, observation: O) -> Result<(), Error> {
        let (n, p) = (self.state.len(), self.observation.components());
        if observation.state_dimension() != n || observation.components() != p {
            return Err(Error::InvalidParameter {
                name: Param::ObservationModel,
                value: format!(
                    "of {} components for {} states",
                    observation.components(),
                    observation.state_dimension()
                ),
                reason: format!("the filter's has {p} components for {n} states"),
            });
        }
        self.observation = observation;
        self.plan = Plan::Unknown;
        Ok(())
    }

    /// The prediction `X_{n,n−1}`, `S_{n,n−1}` that the last update corrected (valid right
    /// after an update that made its correction by [`Self::update_stats_keeping_prediction`]).
    pub(crate) fn last_prediction(&self) -> (&DVector<f64>, &DMatrix<f64>) {
        (&self.work.x, &self.work.s)
    }

    /// The estimate and its time, for a batch kernel of the same arithmetic to advance in
    /// place (`kalman::discrete_fixed`): it keeps the filter's invariants.
    pub(crate) fn estimate_mut(&mut self) -> (&mut DVector<f64>, &mut DMatrix<f64>, &mut f64) {
        (&mut self.state, &mut self.covariance, &mut self.time)
    }

    /// The dynamics, to change a step's matrices in place (the caller keeps its dimension).
    pub(crate) fn dynamics_mut(&mut self) -> &mut D {
        self.plan = Plan::Unknown;
        &mut self.dynamics
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
    /// use seqsmooth::model::measurement::NoiseCovariance;
    /// use seqsmooth::model::measurement::Measurement;
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
        self.predict_work(t)?;
        self.commit_prediction(t);
        Ok(())
    }

    /// [`Self::predict`], returning `Φ(t, t_before)` (the identity for no step): what the
    /// smoother needs.
    pub(crate) fn predict_with_transition(&mut self, t: f64) -> Result<DMatrix<f64>, Error> {
        let n = self.state.len();
        if t == self.time {
            return Ok(DMatrix::identity(n, n));
        }
        self.predict(t)?;
        Ok(self.work.phi.clone())
    }

    /// Predicts to the measurement's time and updates with its present components
    /// ((12.2.17)-(12.2.19), Joseph's covariance (12.3.7)); `Ok(None)` when no component is
    /// present (the prediction alone). On an error the filter is unchanged.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::model::measurement::NoiseCovariance;
    /// use seqsmooth::model::measurement::Measurement;
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
        self.update_with(measurement, true, false, Work::innovation)
    }

    /// [`Self::update`] reporting only the innovation's statistics ([`InnovationStats`]): the
    /// same update, the same state and covariance afterwards, without the vectors and
    /// matrices of an [`Innovation`], so that it allocates nothing (for
    /// [`PolynomialDynamics`](crate::model::dynamics::PolynomialDynamics),
    /// [`LinearObservation`](crate::model::observation::LinearObservation),
    /// [`Radar`](crate::model::radar::Radar) and
    /// [`WhiteNoiseDerivative`](super::noise::WhiteNoiseDerivative)): the filter's fast path.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::model::measurement::NoiseCovariance;
    /// use seqsmooth::model::measurement::Measurement;
    /// use seqsmooth::kalman::KalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let f = KalmanFilter::new(PolynomialDynamics::new(1, 1), LinearObservation::value_of(2),
    ///     DVector::from_vec(vec![0.0, 1.0]), DMatrix::identity(2, 2), 0.0).unwrap();
    /// let z = Measurement { time: 2.0, values: vec![Some(2.5)], noise: NoiseCovariance::Identity };
    /// let (mut a, mut b) = (f.clone(), f);
    /// let stats = a.update_stats(&z).unwrap().unwrap();
    /// let full = b.update(&z).unwrap().unwrap();
    /// assert_eq!((stats.components, stats.nis, stats.log_likelihood), (1, full.nis, full.log_likelihood));
    /// assert_eq!((a.state(), a.covariance()), (b.state(), b.covariance()));
    /// ```
    pub fn update_stats(
        &mut self,
        measurement: &Measurement,
    ) -> Result<Option<InnovationStats>, Error> {
        self.update_with(measurement, false, false, |_, stats| stats)
    }

    /// [`Self::update_stats`] leaving in the work buffers the prediction it corrected and its
    /// `Φ` ([`Self::last_prediction`], [`Self::last_transition`]), for the smoothers and
    /// batch kernels that read them; [`Self::update_stats`] on the fixed-size path does not
    /// write them (a filter alone never reads them).
    pub(crate) fn update_stats_keeping_prediction(
        &mut self,
        measurement: &Measurement,
    ) -> Result<Option<InnovationStats>, Error> {
        self.update_with(measurement, false, true, |_, stats| stats)
    }

    /// [`Self::update_stats`] with a gate (Morrison §14.8): the update is made only where
    /// `accept` accepts its statistics; otherwise the filter takes the prediction to the
    /// measurement's time and leaves the measurement unused. Returns the statistics and
    /// whether they were accepted (`None` when no component is present: the prediction).
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::model::measurement::NoiseCovariance;
    /// use seqsmooth::model::measurement::Measurement;
    /// use seqsmooth::kalman::KalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let mut f = KalmanFilter::new(PolynomialDynamics::new(1, 1), LinearObservation::value_of(2),
    ///     DVector::from_vec(vec![0.0, 1.0]), DMatrix::identity(2, 2), 0.0).unwrap();
    /// let far = Measurement { time: 1.0, values: vec![Some(50.0)], noise: NoiseCovariance::Identity };
    /// let (stats, used) = f.update_gated(&far, |s| s.nis < 16.0).unwrap().unwrap();
    /// assert!(!used && stats.nis > 16.0);
    /// assert_eq!((f.time(), f.state()[0]), (1.0, 1.0)); // the prediction only
    /// ```
    pub fn update_gated(
        &mut self,
        measurement: &Measurement,
        accept: impl FnOnce(&InnovationStats) -> bool,
    ) -> Result<Option<(InnovationStats, bool)>, Error> {
        let Some((t, stats)) = self.predict_and_correct(measurement, false)? else {
            return Ok(None);
        };
        let used = accept(&stats);
        if used {
            self.commit_correction(t);
        } else {
            self.commit_prediction(t);
        }
        Ok(Some((stats, used)))
    }

    /// Replaces the driving noise from the next prediction on (ch. 15): what an adaptive
    /// filter changes between updates.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::noise::WhiteNoiseDerivative;
    /// use seqsmooth::kalman::KalmanFilter;
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let mut f = KalmanFilter::new(PolynomialDynamics::new(1, 1), LinearObservation::value_of(2),
    ///     DVector::zeros(2), DMatrix::zeros(2, 2), 0.0).unwrap();
    /// f.set_process_noise(WhiteNoiseDerivative::new(1, 1, 3.0).unwrap()).unwrap();
    /// f.predict(1.0).unwrap();
    /// assert_eq!(f.covariance()[(1, 1)], 3.0);
    /// ```
    pub fn set_process_noise<P: ProcessNoise + 'static>(&mut self, noise: P) -> Result<(), Error> {
        let n = self.dynamics.dimension();
        super::noise::check_noise_dimension(&noise, n)?;
        self.noise = Some(Arc::new(noise));
        self.plan = Plan::Unknown;
        Ok(())
    }

    /// Switches to fading memory with `discount` from now on, as [`Self::with_fading`] (its
    /// `P` restarted at the current covariance, §14.5).
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::{Discount, KalmanFilter};
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::observation::LinearObservation;
    /// let mut f = KalmanFilter::new(PolynomialDynamics::new(0, 1), LinearObservation::value_of(1),
    ///     DVector::zeros(1), DMatrix::identity(1, 1), 0.0).unwrap();
    /// assert!(f.set_fading(Discount::PerUpdate { theta: 0.5 }).is_ok());
    /// assert!(f.set_fading(Discount::PerUpdate { theta: 1.5 }).is_err());
    /// ```
    pub fn set_fading(&mut self, discount: Discount) -> Result<(), Error> {
        let discount = discount.checked()?;
        self.fading = Some(Fading {
            discount,
            weight: self.covariance.clone(),
            last_update: self.time,
        });
        Ok(())
    }

    /// The one update behind [`Self::update`] and [`Self::update_stats`]: `report` reads what
    /// the caller wants from the work buffers once the update has succeeded (with
    /// `innovation`, what an [`Innovation`] reads). The whole update at fixed size where the
    /// model allows ([`Self::update_fixed`], the same numbers; the prediction and `Φ` left in
    /// the work buffers only with `prediction`), else prediction and correction (which leave
    /// them there).
    fn update_with<T>(
        &mut self,
        measurement: &Measurement,
        innovation: bool,
        prediction: bool,
        report: impl FnOnce(&Work, InnovationStats) -> T,
    ) -> Result<Option<T>, Error> {
        // The fixed-size path has made its update the filter's.
        if let Some(stats) = self.update_fixed(measurement, innovation, prediction) {
            return Ok(Some(report(&self.work, stats)));
        }
        let Some((t, stats)) = self.predict_and_correct(measurement, innovation)? else {
            return Ok(None);
        };
        let out = report(&self.work, stats);
        self.commit_correction(t);
        Ok(Some(out))
    }

    /// The start of every update: the measurement read ([`Self::measure`]) and the prediction
    /// to its time ([`Self::predict_work`]); with no component present the prediction is made
    /// the filter's and `None` returned, else the time to correct at.
    fn measure_and_predict(&mut self, measurement: &Measurement) -> Result<Option<f64>, Error> {
        let k = self.measure(measurement)?;
        let t = measurement.time;
        self.predict_work(t)?;
        if k == 0 {
            self.commit_prediction(t);
            return Ok(None);
        }
        Ok(Some(t))
    }

    /// The prediction to `t` into the work buffers (`X_{n,n−1}`, `S_{n,n−1}` and the fading
    /// `P`), the filter unchanged: `Φ` and the propagated state from the dynamics, `Q` from the
    /// driving noise, `Φ S Φᵀ + Q` by [`carry`]. No step (`t` the current time) copies.
    fn predict_work(&mut self, t: f64) -> Result<(), Error> {
        if !t.is_finite() {
            return Err(Error::NonFinite {
                what: "time",
                value: t,
            });
        }
        let w = &mut self.work;
        if t == self.time {
            w.x.copy_from(&self.state);
            w.s.copy_from(&self.covariance);
            if let Some(f) = &self.fading {
                w.p.copy_from(&f.weight);
            }
            return Ok(());
        }
        if self.predict_fixed(t) {
            return Ok(());
        }
        let w = &mut self.work;
        self.dynamics
            .propagate_into(&self.state, self.time, t, &mut w.x, &mut w.phi)?;
        let q = match &self.noise {
            Some(noise) => {
                noise.covariance_into(self.time, t, &mut w.q)?;
                Some(w.q.as_slice())
            }
            None => None,
        };
        let n = self.state.len();
        let phi = w.phi.as_slice();
        let mut carry_into = |from: &DMatrix<f64>, to: &mut DMatrix<f64>, what| {
            let (from, to) = (from.as_slice(), to.as_mut_slice());
            let finite_out = unrolled_sizes!(n, N => carry(Fixed::<N>, phi, from, q, &mut w.square, to),
                n => carry(Any(n), phi, from, q, &mut w.square, to));
            if finite_out {
                Ok(())
            } else {
                finite(to, what)
            }
        };
        carry_into(&self.covariance, &mut w.s, "predicted covariance")?;
        if let Some(f) = &self.fading {
            carry_into(&f.weight, &mut w.p, "predicted fading-memory matrix P")?;
        }
        Ok(())
    }

    /// Makes the predicted state, covariance and `P` in the work buffers the filter's, at `t`.
    fn commit_prediction(&mut self, t: f64) {
        std::mem::swap(&mut self.state, &mut self.work.x);
        std::mem::swap(&mut self.covariance, &mut self.work.s);
        if let Some(f) = &mut self.fading {
            std::mem::swap(&mut f.weight, &mut self.work.p);
        }
        self.time = t;
    }

    /// Makes the corrected state, covariance and `P` in the work buffers the filter's, at `t`.
    fn commit_correction(&mut self, t: f64) {
        std::mem::swap(&mut self.state, &mut self.work.x_out);
        std::mem::swap(&mut self.covariance, &mut self.work.s_out);
        if let Some(f) = &mut self.fading {
            std::mem::swap(&mut f.weight, &mut self.work.p_out);
            f.last_update = t;
        }
        self.time = t;
    }

    /// The update of the predicted state in the work buffers with the measured components
    /// (after [`Self::measure`] and [`Self::predict_work`]), into the work buffers' outputs,
    /// the filter unchanged: the observation linearised about the prediction, or with
    /// `iterated` about `work.about` ((12.5.17): the innovation
    /// `Y − G(about) − M(about)(X_{n,n−1} − about)`, `M` at `about`); then [`correct_kernel`].
    fn correct(&mut self, t: f64, iterated: bool) -> Result<InnovationStats, Error> {
        let (n, p) = (self.state.len(), self.observation.components());
        let w = &mut self.work;
        let about = if iterated { &w.about } else { &w.x };
        // A constant M is read in place (G = M X from the finite prediction, as the model's
        // `predict_into` makes it); anything else, or a G that is not finite, through the model.
        let linear = match self.observation.linear_matrix() {
            Some(m) if !iterated && m.shape() == (p, n) => {
                linear_value(m, about.as_slice(), w.g.as_mut_slice());
                all_finite(&w.g.as_slice()[..p]).then_some(m)
            }
            _ => None,
        };
        let m_all = match linear {
            Some(m) => m.as_slice(),
            None => {
                self.observation
                    .predict_into(about, t, &mut w.g, &mut w.m_all)?;
                w.m_all.as_slice()
            }
        };
        let k = w.present.len();
        for (c, (&a, &y)) in w.present.iter().zip(&w.values).enumerate() {
            for (l, mt) in w.mt[c * n..(c + 1) * n].iter_mut().enumerate() {
                *mt = m_all[a + l * p];
            }
            let mut nu = self.observation.residual(a, y, w.g[a]);
            if iterated {
                let mut offset = 0.0;
                for (l, mt) in w.mt[c * n..(c + 1) * n].iter().enumerate() {
                    offset += mt * (w.x[l] - w.about[l]);
                }
                nu -= offset;
            }
            w.nu[c] = nu;
        }
        // The gain from P and f R (fading, ch. 14), or from S and R (f = 1, P = S).
        let f = match &self.fading {
            Some(fading) => fading.factor(t)?,
            None => 1.0,
        };
        let fading = self.fading.is_some();
        let (nis, log_det, finite_out) = unrolled_sizes!(n, N => match k {
                1 => correct_kernel(Fixed::<N>, Fixed::<1>, f, fading, w),
                2 => correct_kernel(Fixed::<N>, Fixed::<2>, f, fading, w),
                3 => correct_kernel(Fixed::<N>, Fixed::<3>, f, fading, w),
                4 => correct_kernel(Fixed::<N>, Fixed::<4>, f, fading, w),
                k => correct_kernel(Fixed::<N>, Any(k), f, fading, w),
            },
            n => correct_kernel(Any(n), Any(k), f, fading, w))?;
        let log_likelihood = -0.5 * (nis + log_det + k as f64 * TAU.ln());
        if !finite_out {
            finite(w.s_out.as_slice(), "updated covariance")?;
            if fading {
                finite(w.p_out.as_slice(), "updated fading-memory matrix P")?;
            }
            finite(w.x_out.as_slice(), "updated state entry")?;
        }
        if !(nis.is_finite() && log_likelihood.is_finite()) {
            return Err(Error::EstimateOutOfRange {
                what: "normalised innovation squared".into(),
            });
        }
        Ok(InnovationStats {
            components: k,
            nis,
            log_likelihood,
        })
    }
}

/// Refuses a prior of other than `n` states, with a number that is not finite, or with a
/// covariance that is not symmetric positive semidefinite ([`check_covariance`](super::noise::check_covariance)).
fn check_prior(
    n: usize,
    state: &DVector<f64>,
    covariance: &DMatrix<f64>,
    time: f64,
) -> Result<(), Error> {
    let bad = |name: Param, value: String, reason: String| Error::InvalidParameter {
        name,
        value,
        reason,
    };
    if state.len() != n || covariance.shape() != (n, n) {
        return Err(bad(
            Param::Prior,
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
    // Symmetric positive semidefinite: the library's one rule of a covariance, as
    // `set_estimate`'s.
    super::noise::check_covariance(covariance, n, Param::PriorCovariance)
}
