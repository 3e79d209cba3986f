//! The discrete-time linear model of the Kalman filter as its users write it with explicit
//! matrices (Morrison (15.4.10)-(15.4.14) with `Φ = F` and the driving noise `Q` of one step
//! given, not integrated; Kalman 1960):
//!
//! `x_k = F_k x_{k−1} + B_k u_k + w_k`, `w_k ~ N(0, Q_k)`; `z_k = H_k x_k + v_k`, `v_k ~ N(0, R_k)`,
//!
//! each matrix constant or given for one step. The filter is the crate's [`KalmanFilter`] on
//! [`DiscreteDynamics`] (`Φ = F`, the state carried to `F x + B u`), [`MatrixNoise`] (`Q`) and
//! a [`LinearObservation`] (`H`), its time the number of steps taken: the same prediction,
//! Joseph-form update (12.3.7), missing components and innovation statistics as for every other
//! model. [`LinearKalmanFilter`] holds the constant matrices, checks every matrix handed in
//! (shape, finite, and for `P`, `Q`, `R` symmetric positive semidefinite, [`check_covariance`])
//! before anything changes, and runs a batch ([`LinearKalmanFilter::update_many`]) with the
//! predicted and updated estimates of every step, which the Rauch–Tung–Striebel smoother
//! ([`LinearKalmanFilter::rts_smoother`], [`super::smoother::rts`]) takes without running the
//! measurements again.

mod lag;
pub use lag::LinearFixedLag;

use super::discrete_fixed;
use super::filter::{Innovation, KalmanFilter};
use super::noise::MatrixNoise;
pub use super::noise::{check_covariance, check_matrix};
use super::smoother::{rts, RtsStep};
use crate::error::{Error, Param};
use crate::model::dynamics::{Dynamics, Propagation};
use crate::model::measurement::{Measurement, NoiseCovariance};
use crate::model::observation::LinearObservation;
use nalgebra::{DMatrix, DVector};

/// `x ↦ F x + o` over one step (`o = B u`, or none), `Φ = F`: a discrete-time linear model.
/// Its times count steps: it carries a state from `t` to `t + 1` (and `t` to `t`, no step);
/// any other step is refused.
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::kalman::discrete::DiscreteDynamics;
/// use seqsmooth::model::dynamics::Dynamics;
/// let d = DiscreteDynamics::new(DMatrix::from_row_slice(2, 2, &[1.0, 0.5, 0.0, 1.0])).unwrap();
/// let p = d.propagate(&DVector::from_vec(vec![1.0, 2.0]), 3.0, 4.0).unwrap();
/// assert_eq!(p.state.as_slice(), &[2.0, 2.0]);
/// assert!(d.propagate(&DVector::zeros(2), 3.0, 5.0).is_err());
/// ```
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DiscreteDynamics {
    transition: DMatrix<f64>,
    offset: Option<DVector<f64>>,
}

impl DiscreteDynamics {
    /// `F`, square and finite ([`Param::TransitionMatrixF`] otherwise).
    pub fn new(transition: DMatrix<f64>) -> Result<Self, Error> {
        let n = transition.nrows();
        check_matrix(&transition, (n, n), Param::TransitionMatrixF)?;
        Ok(Self {
            transition,
            offset: None,
        })
    }

    /// `F`.
    pub fn transition(&self) -> &DMatrix<f64> {
        &self.transition
    }

    /// The step's `F` and offset `B u` (already checked by the caller: `n × n`, finite).
    fn set(&mut self, transition: &DMatrix<f64>, offset: Option<DVector<f64>>) {
        self.transition.copy_from(transition);
        self.offset = offset;
    }
}

impl Dynamics for DiscreteDynamics {
    fn dimension(&self) -> usize {
        self.transition.nrows()
    }

    fn is_linear(&self) -> bool {
        true
    }

    fn propagate(&self, state: &DVector<f64>, t_a: f64, t_b: f64) -> Result<Propagation, Error> {
        let n = self.dimension();
        let (mut x, mut phi) = (DVector::zeros(n), DMatrix::zeros(n, n));
        self.propagate_into(state, t_a, t_b, &mut x, &mut phi)?;
        Ok(Propagation {
            state: x,
            transition: phi,
        })
    }

    fn propagate_into(
        &self,
        state: &DVector<f64>,
        t_a: f64,
        t_b: f64,
        state_out: &mut DVector<f64>,
        transition_out: &mut DMatrix<f64>,
    ) -> Result<(), Error> {
        let n = self.dimension();
        crate::model::dynamics::check_propagation(n, state, t_a, t_b)?;
        if t_b == t_a {
            *state_out = state.clone();
            *transition_out = DMatrix::identity(n, n);
            return Ok(());
        }
        if t_b != t_a + 1.0 {
            return Err(Error::InvalidParameter {
                name: Param::Step,
                value: format!("from {t_a} to {t_b}"),
                reason: "a discrete-time model steps from t to t + 1".into(),
            });
        }
        if state_out.len() != n {
            *state_out = DVector::zeros(n);
        }
        self.transition.mul_to(state, state_out);
        if let Some(o) = &self.offset {
            *state_out += o;
        }
        if transition_out.shape() != (n, n) {
            *transition_out = DMatrix::zeros(n, n);
        }
        transition_out.copy_from(&self.transition);
        Ok(())
    }
}

/// The matrices of one step that differ from the filter's constant ones (each `None` takes
/// the constant): `F`, `Q`, `B` and `u` for the prediction, `H` and `R` for the update.
#[derive(Clone, Copy, Debug, Default)]
pub struct StepMatrices<'a> {
    /// `F_k`.
    pub f: Option<&'a DMatrix<f64>>,
    /// `Q_k`.
    pub q: Option<&'a DMatrix<f64>>,
    /// `B_k`.
    pub b: Option<&'a DMatrix<f64>>,
    /// `u_k` (needs a `B`).
    pub u: Option<&'a DVector<f64>>,
    /// `H_k`.
    pub h: Option<&'a DMatrix<f64>>,
    /// `R_k`.
    pub r: Option<&'a DMatrix<f64>>,
}

/// Every step of a batch: the predicted and the updated estimate, `(steps × n)` and
/// `(steps × n × n)` in row-major order (a covariance is symmetric, so each is also its own
/// column-major block), and each update's NIS (NaN where every component was missing).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Pass {
    /// `x_{k|k}`.
    pub states: Vec<f64>,
    /// `P_{k|k}`.
    pub covariances: Vec<f64>,
    /// `x_{k|k−1}`.
    pub predicted_states: Vec<f64>,
    /// `P_{k|k−1}`.
    pub predicted_covariances: Vec<f64>,
    /// `νᵀ V⁻¹ ν`.
    pub nis: Vec<f64>,
}

/// [`Pass`] in the caller's memory ([`LinearKalmanFilter::update_many_into`]): one row per
/// step, row-major as there; `nis` optional.
#[derive(Debug)]
pub struct PassInto<'a> {
    /// `x_{k|k}`, `steps × n`.
    pub states: &'a mut [f64],
    /// `P_{k|k}`, `steps × n × n`.
    pub covariances: &'a mut [f64],
    /// `x_{k|k−1}`, `steps × n`.
    pub predicted_states: &'a mut [f64],
    /// `P_{k|k−1}`, `steps × n × n`.
    pub predicted_covariances: &'a mut [f64],
    /// `νᵀ V⁻¹ ν`, `steps` (NaN where every component was missing), when wanted.
    pub nis: Option<&'a mut [f64]>,
}

/// One step's results as the batch loop hands them on (the filter's own memory).
pub(super) struct BatchStep<'a> {
    pub(super) predicted_state: &'a [f64],
    pub(super) predicted_covariance: &'a [f64],
    pub(super) state: &'a [f64],
    pub(super) covariance: &'a [f64],
    pub(super) nis: f64,
}

pub(super) type Inner = KalmanFilter<DiscreteDynamics, LinearObservation>;

/// The Kalman filter on a discrete-time linear model with explicit matrices (the module's
/// model): `predict` then `update`, one step each, as filterpy's `KalmanFilter`.
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::kalman::discrete::{LinearKalmanFilter, StepMatrices};
/// // Constant velocity, dt = 1, position observed with R = 1.
/// let f = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 0.0, 1.0]);
/// let h = DMatrix::from_row_slice(1, 2, &[1.0, 0.0]);
/// let mut kf = LinearKalmanFilter::new(DVector::zeros(2), DMatrix::identity(2, 2) * 100.0,
///     f, h, DMatrix::zeros(2, 2), DMatrix::identity(1, 1)).unwrap();
/// for z in [1.0, 2.0, 3.0, 4.0] {
///     kf.predict(&StepMatrices::default()).unwrap();
///     kf.update(&[z], &StepMatrices::default()).unwrap();
/// }
/// assert!((kf.state()[1] - 1.0).abs() < 0.05);
/// ```
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct LinearKalmanFilter {
    filter: Inner,
    model: Constants,
}

/// The constant matrices of a [`LinearKalmanFilter`].
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
struct Constants {
    f: DMatrix<f64>,
    h: DMatrix<f64>,
    q: DMatrix<f64>,
    r: DMatrix<f64>,
    b: Option<DMatrix<f64>>,
}

impl LinearKalmanFilter {
    /// The prior `x0`, `P0` (symmetric positive semidefinite) and the constant `F` (`n × n`),
    /// `H` (`p × n`), `Q` (`n × n`) and `R` (`p × p`), `Q` and `R` symmetric positive
    /// semidefinite; every entry finite. Step 0.
    pub fn new(
        x0: DVector<f64>,
        p0: DMatrix<f64>,
        f: DMatrix<f64>,
        h: DMatrix<f64>,
        q: DMatrix<f64>,
        r: DMatrix<f64>,
    ) -> Result<Self, Error> {
        let n = x0.len();
        if n == 0 {
            return Err(Error::InvalidParameter {
                name: Param::State,
                value: "of length 0".into(),
                reason: "needs at least one state".into(),
            });
        }
        if let Some(&v) = x0.iter().find(|v| !v.is_finite()) {
            return Err(Error::InvalidParameter {
                name: Param::State,
                value: format!("holding {v}"),
                reason: "must be finite".into(),
            });
        }
        check_covariance(&p0, n, Param::PriorCovariance)?;
        check_matrix(&f, (n, n), Param::TransitionMatrixF)?;
        let p = h.nrows();
        check_matrix(&h, (p, n), Param::ObservationMatrixH)?;
        check_covariance(&q, n, Param::ProcessNoiseQ)?;
        check_covariance(&r, p, Param::MeasurementNoiseR)?;
        let filter = KalmanFilter::new(
            DiscreteDynamics::new(f.clone())?,
            LinearObservation::new(h.clone())?,
            x0,
            p0,
            0.0,
        )?
        .with_process_noise(MatrixNoise::new(q.clone())?)?;
        Ok(Self {
            filter,
            model: Constants {
                f,
                h,
                q,
                r,
                b: None,
            },
        })
    }

    /// With the constant control matrix `B` (`n × c`, finite): `predict` adds `B u`.
    pub fn with_control(mut self, b: DMatrix<f64>) -> Result<Self, Error> {
        check_matrix(&b, (self.dimension(), b.ncols()), Param::ControlMatrixB)?;
        self.model.b = Some(b);
        Ok(self)
    }

    /// The state dimension `n`.
    pub fn dimension(&self) -> usize {
        self.model.f.nrows()
    }

    /// The measurement's components `p`.
    pub fn components(&self) -> usize {
        self.model.h.nrows()
    }

    /// The estimate `x`.
    pub fn state(&self) -> &DVector<f64> {
        self.filter.state()
    }

    /// Its covariance `P`.
    pub fn covariance(&self) -> &DMatrix<f64> {
        self.filter.covariance()
    }

    /// `√diag(P)`.
    pub fn std_devs(&self) -> Vec<f64> {
        self.filter.std_devs()
    }

    /// The steps taken (predictions).
    pub fn steps(&self) -> usize {
        self.filter.time() as usize
    }

    /// The constant `F`, `H`, `Q`, `R` and `B`.
    pub fn matrices(&self) -> (&DMatrix<f64>, &DMatrix<f64>, &DMatrix<f64>, &DMatrix<f64>) {
        (&self.model.f, &self.model.h, &self.model.q, &self.model.r)
    }

    /// The constant `B`, if any.
    pub fn control(&self) -> Option<&DMatrix<f64>> {
        self.model.b.as_ref()
    }

    /// Replaces the estimate `x`, `P` ([`KalmanFilter::set_estimate`]'s checks: `x` finite,
    /// `P` a finite symmetric positive semidefinite covariance). On an error the filter is
    /// unchanged.
    pub fn set_estimate(&mut self, x: DVector<f64>, p: DMatrix<f64>) -> Result<(), Error> {
        let time = self.filter.time();
        self.filter.set_estimate(x, p, time)
    }

    /// Replaces the constant `F`, `H`, `Q`, `R` or `B` (each `None` kept), all checked first.
    pub fn set_matrices(&mut self, step: &StepMatrices<'_>) -> Result<(), Error> {
        self.check(step, false)?;
        if let Some(f) = step.f {
            self.model.f.copy_from(f);
            self.filter.dynamics_mut().set(f, None);
        }
        if let Some(h) = step.h {
            self.model.h.copy_from(h);
            self.filter
                .set_observation(LinearObservation::new(h.clone())?)?;
        }
        if let Some(q) = step.q {
            self.model.q.copy_from(q);
            self.filter
                .set_process_noise(MatrixNoise::new(q.clone())?)?;
        }
        if let Some(r) = step.r {
            self.model.r.copy_from(r);
        }
        if let Some(b) = step.b {
            self.model.b = Some(b.clone());
        }
        Ok(())
    }

    /// Checks `step`'s matrices against the model's shapes (`u` too when `with_u`).
    fn check(&self, step: &StepMatrices<'_>, with_u: bool) -> Result<(), Error> {
        let (n, p) = (self.dimension(), self.components());
        if let Some(f) = step.f {
            check_matrix(f, (n, n), Param::TransitionMatrixF)?;
        }
        if let Some(q) = step.q {
            check_covariance(q, n, Param::ProcessNoiseQ)?;
        }
        if let Some(h) = step.h {
            check_matrix(h, (p, n), Param::ObservationMatrixH)?;
        }
        if let Some(r) = step.r {
            check_covariance(r, p, Param::MeasurementNoiseR)?;
        }
        if let Some(b) = step.b {
            check_matrix(b, (n, b.ncols()), Param::ControlMatrixB)?;
        }
        if with_u {
            if let Some(u) = step.u {
                let Some(b) = step.b.or(self.model.b.as_ref()) else {
                    return Err(Error::InvalidParameter {
                        name: Param::ControlInputU,
                        value: format!("{:?}", u.as_slice()),
                        reason: "needs a control matrix B".into(),
                    });
                };
                if u.len() != b.ncols() || u.iter().any(|v| !v.is_finite()) {
                    return Err(Error::InvalidParameter {
                        name: Param::ControlInputU,
                        value: format!("{:?}", u.as_slice()),
                        reason: format!("must be {} finite numbers (B's columns)", b.ncols()),
                    });
                }
            }
        }
        Ok(())
    }

    /// The prediction `x ← F x + B u`, `P ← F P Fᵀ + Q` with `step`'s `F`, `Q`, `B`, `u` where
    /// given. On an error the filter is unchanged.
    pub fn predict(&mut self, step: &StepMatrices<'_>) -> Result<(), Error> {
        self.check(step, true)?;
        predict_on(&mut self.filter, &self.model, step, |f, t| f.predict(t))
    }

    /// The update with `z` (`p` values; NaN a missing component, none present a no-op) and
    /// `step`'s `H`, `R` where given: Joseph's form (12.3.7). Returns the innovation (`None`
    /// when every component is missing). On an error the filter is unchanged.
    pub fn update(
        &mut self,
        z: &[f64],
        step: &StepMatrices<'_>,
    ) -> Result<Option<Innovation>, Error> {
        self.check(step, false)?;
        let m = self.measurement(z, step.r)?;
        update_on(&mut self.filter, &self.model, step, |f| f.update(&m))
    }

    /// One measurement of `z` at the filter's time with `r` or the constant `R`.
    fn measurement(&self, z: &[f64], r: Option<&DMatrix<f64>>) -> Result<Measurement, Error> {
        let mut m = Measurement {
            time: 0.0,
            values: Vec::new(),
            noise: NoiseCovariance::Identity,
        };
        self.fill_measurement(z, r, &mut m)?;
        Ok(m)
    }

    /// [`Self::measurement`] into `m`, reusing its buffers (a batch's hot path).
    fn fill_measurement(
        &self,
        z: &[f64],
        r: Option<&DMatrix<f64>>,
        m: &mut Measurement,
    ) -> Result<(), Error> {
        let p = self.components();
        if z.len() != p {
            return Err(Error::InvalidParameter {
                name: Param::Measurement,
                value: format!("of {} values", z.len()),
                reason: format!("the observation H has {p} components"),
            });
        }
        if let Some(&v) = z.iter().find(|v| v.is_infinite()) {
            return Err(Error::NonFinite {
                what: "measurement value",
                value: v,
            });
        }
        m.time = self.filter.time();
        m.values.clear();
        m.values
            .extend(z.iter().map(|&v| (!v.is_nan()).then_some(v)));
        let r = r.unwrap_or(&self.model.r);
        match &mut m.noise {
            NoiseCovariance::Full(held) if held.shape() == r.shape() => held.copy_from(r),
            noise => *noise = NoiseCovariance::Full(r.clone()),
        }
        Ok(())
    }

    /// `predict` and `update` for each row of `zs` (`steps × p`, row-major; NaN missing) with
    /// `step(k)`'s matrices, into `pass` (cleared first): the predicted and updated estimates of
    /// every step. On an error ([`Error::InBatch`] naming the step) the steps before it are
    /// taken and given in `pass`. Steps with the constant matrices at `n ≤ 9` states and
    /// `p ≤ 3` components run a fixed-size kernel, without being asked: the same numbers as the
    /// generic filter, bit for bit.
    pub fn update_many<'a>(
        &mut self,
        zs: &[f64],
        step: impl Fn(usize) -> StepMatrices<'a>,
        pass: &mut Pass,
    ) -> Result<(), Error> {
        let (n, p) = (self.dimension(), self.components());
        let rows = zs.len() / p;
        *pass = Pass::default();
        for v in [&mut pass.states, &mut pass.predicted_states] {
            v.reserve(rows * n);
        }
        for v in [&mut pass.covariances, &mut pass.predicted_covariances] {
            v.reserve(rows * n * n);
        }
        pass.nis.reserve(rows);
        self.run_batch(zs, step, |_, step| {
            pass.predicted_states
                .extend_from_slice(step.predicted_state);
            pass.predicted_covariances
                .extend_from_slice(step.predicted_covariance);
            pass.states.extend_from_slice(step.state);
            pass.covariances.extend_from_slice(step.covariance);
            pass.nis.push(step.nis);
        })
    }

    /// [`Self::update_many`] into the caller's memory, for `N` rows of `zs`: row `k` of
    /// `out.states` (`N × n`), `out.covariances` (`N × n × n`), `out.predicted_states`,
    /// `out.predicted_covariances` and `out.nis` (`N`, where given) is step `k`'s, written in
    /// place (no buffer of the whole batch is allocated: a front end hands in its own arrays,
    /// e.g. numpy's, whose pages the system may map in large blocks). The same numbers as
    /// [`Self::update_many`], bit for bit. On an error ([`Error::InBatch`] naming the step)
    /// the steps before it are taken and written; slices of the wrong length are refused
    /// before any step.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::discrete::{LinearKalmanFilter, PassInto, StepMatrices};
    /// let f = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 0.0, 1.0]);
    /// let h = DMatrix::from_row_slice(1, 2, &[1.0, 0.0]);
    /// let mut kf = LinearKalmanFilter::new(DVector::zeros(2), DMatrix::identity(2, 2) * 100.0,
    ///     f, h, DMatrix::zeros(2, 2), DMatrix::identity(1, 1)).unwrap();
    /// let zs = [1.0, 2.0, 3.0, 4.0];
    /// let (mut x, mut p, mut xp, mut pp) = ([0.0; 8], [0.0; 16], [0.0; 8], [0.0; 16]);
    /// let out = PassInto { states: &mut x, covariances: &mut p, predicted_states: &mut xp,
    ///     predicted_covariances: &mut pp, nis: None };
    /// kf.update_many_into(&zs, |_| StepMatrices::default(), out).unwrap();
    /// assert!((x[7] - 1.0).abs() < 0.05); // the velocity after the fourth step
    /// ```
    pub fn update_many_into<'a>(
        &mut self,
        zs: &[f64],
        step: impl Fn(usize) -> StepMatrices<'a>,
        out: PassInto<'_>,
    ) -> Result<(), Error> {
        let (n, p) = (self.dimension(), self.components());
        let rows = zs.len() / p;
        let PassInto {
            states,
            covariances,
            predicted_states,
            predicted_covariances,
            mut nis,
        } = out;
        let fits = [states.len(), predicted_states.len()] == [rows * n; 2]
            && [covariances.len(), predicted_covariances.len()] == [rows * n * n; 2]
            && nis.as_ref().is_none_or(|v| v.len() == rows);
        if !fits {
            return Err(Error::InvalidParameter {
                name: Param::MatrixLength,
                value: format!(
                    "{} and {} state, {} and {} covariance entries for {rows} steps",
                    states.len(),
                    predicted_states.len(),
                    covariances.len(),
                    predicted_covariances.len()
                ),
                reason: format!("need {rows} x {n} states and {rows} x {n} x {n} covariances"),
            });
        }
        let (mut x, mut c) = (
            states.chunks_exact_mut(n),
            covariances.chunks_exact_mut(n * n),
        );
        let mut xp = predicted_states.chunks_exact_mut(n);
        let mut cp = predicted_covariances.chunks_exact_mut(n * n);
        self.run_batch(zs, step, |k, step| {
            let rows = (x.next(), c.next(), xp.next(), cp.next());
            let (Some(x), Some(c), Some(xp), Some(cp)) = rows else {
                unreachable!("the lengths were checked against the rows")
            };
            xp.copy_from_slice(step.predicted_state);
            cp.copy_from_slice(step.predicted_covariance);
            x.copy_from_slice(step.state);
            c.copy_from_slice(step.covariance);
            if let Some(nis) = nis.as_deref_mut() {
                nis[k] = step.nis;
            }
        })
    }

    /// The one loop of [`Self::update_many`] and [`Self::update_many_into`]: each row's
    /// prediction and update, its results handed to `emit` with the row's index. Runs of steps
    /// with the constant matrices at `n ≤ 9`, `p ≤ 3` go to the fixed-size kernel
    /// (`discrete_fixed`, the same numbers bit for bit); the generic filter takes the others.
    fn run_batch<'a>(
        &mut self,
        zs: &[f64],
        step: impl Fn(usize) -> StepMatrices<'a>,
        mut emit: impl FnMut(usize, BatchStep<'_>),
    ) -> Result<(), Error> {
        let p = self.components();
        let mut m = Measurement {
            time: 0.0,
            values: Vec::with_capacity(p),
            noise: NoiseCovariance::Identity,
        };
        let (rows, mut k) = (zs.len() / p, 0);
        while k < rows {
            let c = &self.model;
            let model = discrete_fixed::ConstantModel::new(&c.f, &c.q, &c.h, &c.r);
            k += discrete_fixed::run_from(&model, &mut self.filter, zs, k, &step, &mut emit);
            let Some(z) = zs.get(k * p..(k + 1) * p) else {
                break;
            };
            let s = step(k);
            let in_batch = |e: Error| Error::InBatch {
                index: k,
                source: Box::new(e),
            };
            self.check(&s, true).map_err(in_batch)?;
            self.fill_measurement(z, s.r, &mut m).map_err(in_batch)?;
            m.time += 1.0;
            // The prediction and the update in one call: both or neither.
            apply_prediction(&mut self.filter, &self.model, &s);
            let stats = apply_update(&mut self.filter, &self.model, &s)
                .and_then(|()| self.filter.update_stats_keeping_prediction(&m));
            restore(&mut self.filter, &self.model, &s);
            let nis = stats.map_err(in_batch)?.map(|s| s.nis);
            let (xp, pp) = match nis {
                Some(_) => self.filter.last_prediction(),
                None => (self.filter.state(), self.filter.covariance()),
            };
            emit(
                k,
                BatchStep {
                    predicted_state: xp.as_slice(),
                    predicted_covariance: pp.as_slice(),
                    state: self.filter.state().as_slice(),
                    covariance: self.filter.covariance().as_slice(),
                    nis: nis.unwrap_or(f64::NAN),
                },
            );
            k += 1;
        }
        Ok(())
    }

    /// The Rauch–Tung–Striebel smoother ([`rts`]) over a forward pass's updated estimates
    /// `states` (`N × n`) and `covariances` (`N × n × n`), row-major, with `step(k)`'s `F`,
    /// `Q`, `B`, `u` for the prediction into step `k` (as in [`Self::update_many`]): each
    /// prediction `x_{k+1|k}`, `P_{k+1|k}` is the filter's own ([`KalmanFilter::predict`] from
    /// `x_{k|k}`, `P_{k|k}`), so on [`Self::update_many`]'s output it is that pass's,
    /// bit for bit; no measurement is read again. One [`RtsStep`] per step; an error names its
    /// step ([`Error::InBatch`]).
    pub fn rts_smoother<'a>(
        &self,
        states: &[f64],
        covariances: &[f64],
        step: impl Fn(usize) -> StepMatrices<'a>,
    ) -> Result<Vec<RtsStep>, Error> {
        let n = self.dimension();
        let count = states.len() / n;
        if states.len() != count * n || covariances.len() != count * n * n {
            return Err(Error::InvalidParameter {
                name: Param::MatrixLength,
                value: format!(
                    "{} states, {} covariance entries",
                    states.len(),
                    covariances.len()
                ),
                reason: format!("need N x {n} states and N x {n} x {n} covariances"),
            });
        }
        let filtered: Vec<(DVector<f64>, DMatrix<f64>)> = (0..count)
            .map(|k| {
                let x = DVector::from_column_slice(&states[k * n..(k + 1) * n]);
                let p = DMatrix::from_row_slice(n, n, &covariances[k * n * n..(k + 1) * n * n]);
                (x, p)
            })
            .collect();
        let in_batch = |index: usize| {
            move |e: Error| Error::InBatch {
                index,
                source: Box::new(e),
            }
        };
        let mut predictions = Vec::with_capacity(count.saturating_sub(1));
        for k in 1..count {
            let s = step(k);
            self.check(&s, true).map_err(in_batch(k))?;
            let (x0, p0) = &filtered[k - 1];
            let mut filter = self.filter.clone();
            // Checked there (check_estimate: P named, the step its index).
            filter
                .set_estimate(x0.clone(), p0.clone(), 0.0)
                .map_err(in_batch(k - 1))?;
            let phi = predict_on(&mut filter, &self.model, &s, |f, t| {
                f.predict_with_transition(t)
            })
            .map_err(in_batch(k))?;
            predictions.push((phi, filter.state().clone(), filter.covariance().clone()));
        }
        rts(&filtered, &predictions)
    }
}

/// Sets `filter`'s dynamics and noise to `step`'s (the model's constants where not given),
/// with the offset `B u` (checked before).
fn apply_prediction(filter: &mut Inner, model: &Constants, step: &StepMatrices<'_>) {
    let offset = step
        .u
        .map(|u| step.b.or(model.b.as_ref()).expect("checked: u has a B") * u);
    let f = step.f.unwrap_or(&model.f);
    if step.f.is_some() || offset.is_some() {
        filter.dynamics_mut().set(f, offset);
    }
    if let Some(q) = step.q {
        filter
            .set_process_noise(MatrixNoise::unchecked(q.clone()))
            .expect("checked: n x n");
    }
}

/// Sets `filter`'s observation to `step`'s `H` where given.
fn apply_update(
    filter: &mut Inner,
    _model: &Constants,
    step: &StepMatrices<'_>,
) -> Result<(), Error> {
    if let Some(h) = step.h {
        filter.set_observation(LinearObservation::new(h.clone())?)?;
    }
    Ok(())
}

/// Puts the model's constant `F` (no offset), `Q` and `H` back on `filter` where `step`
/// changed them.
fn restore(filter: &mut Inner, model: &Constants, step: &StepMatrices<'_>) {
    if step.f.is_some() || step.u.is_some() {
        filter.dynamics_mut().set(&model.f, None);
    }
    if step.q.is_some() {
        filter
            .set_process_noise(MatrixNoise::unchecked(model.q.clone()))
            .expect("checked: n x n");
    }
    if step.h.is_some() {
        filter
            .set_observation(LinearObservation::new(model.h.clone()).expect("checked: finite"))
            .expect("checked: p x n");
    }
}

/// `run` (a prediction to the next step) with `step`'s prediction matrices on `filter`, the
/// constants put back after.
fn predict_on<T>(
    filter: &mut Inner,
    model: &Constants,
    step: &StepMatrices<'_>,
    run: impl FnOnce(&mut Inner, f64) -> Result<T, Error>,
) -> Result<T, Error> {
    let changed = step.f.is_some() || step.q.is_some() || step.u.is_some();
    if changed {
        apply_prediction(filter, model, step);
    }
    let t = filter.time() + 1.0;
    let out = run(filter, t);
    if changed {
        restore(filter, model, step);
    }
    out
}

/// `run` (an update) with `step`'s `H` on `filter`, the constant put back after.
fn update_on<T>(
    filter: &mut Inner,
    model: &Constants,
    step: &StepMatrices<'_>,
    run: impl FnOnce(&mut Inner) -> Result<T, Error>,
) -> Result<T, Error> {
    if step.h.is_none() {
        return run(filter);
    }
    let out = apply_update(filter, model, step).and_then(|()| run(filter));
    restore(filter, model, step);
    out
}

impl LinearKalmanFilter {
    /// A restored filter's invariants ([`crate::persist`]): `F`, `H`, `Q`, `R`, `B` of the
    /// state's and the observation's dimensions, finite, `Q` and `R` covariances; the filter's.
    pub(crate) fn check_saved(&mut self) -> Result<(), String> {
        use crate::linalg::invariant::{covariance, matrix};
        let n = self.filter.state().len();
        let c = &self.model;
        let p = c.h.nrows();
        matrix(&c.f, n, n, "F")?;
        matrix(&c.h, p, n, "H")?;
        covariance(&c.q, n, "Q")?;
        covariance(&c.r, p, "R")?;
        if let Some(b) = &c.b {
            matrix(b, n, b.ncols(), "B")?;
        }
        matrix(self.filter.dynamics_mut().transition(), n, n, "F")?;
        let o = self.filter.observation().matrix();
        matrix(o, p, n, "H")?;
        self.filter.check_saved()
    }
}
