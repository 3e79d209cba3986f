//! Driving noise (Morrison ch. 15): the covariance `Q(t_b, t_a)` of the state perturbation
//! accumulated over a step,
//!
//! `Q(t_b, t_a) = ∫_{t_a}^{t_b} Φ(t_b, l) D K Dᵀ Φ(t_b, l)ᵀ dl` (15.2.23),
//!
//! added to the predicted covariance (15.4.11). The book gives no closed form for a particular
//! model; for the polynomial model with white noise of power spectral density `q` on the
//! highest derivative of each axis (`D = e_m ⊗ I_d`, `K = q I_d`) the integral is exact in
//! closed form on any step `ζ = t_b − t_a`:
//!
//! `Q_ij = q |ζ|^(2m+1−i−j) / ((m−i)! (m−j)! (2m+1−i−j))` (per axis, derivatives `i, j ≤ m`),
//!
//! from `Φ(ζ) = Ψ(ζ)` (4.2.5): `[Ψ(s) e_m]_i = s^(m−i)/(m−i)!`. Degree 1 gives the familiar
//! constant-velocity `q [[ζ³/3, ζ²/2], [ζ²/2, ζ]]`. A step backwards uses `|ζ|`: the noise
//! accumulated over the interval either way.

use crate::calculus::factorial;
use crate::error::{Error, Param};
use crate::model::continuous::ContinuousModel;
use crate::model::coordinated_turn::CoordinatedTurn;
use crate::numeric::power::powi;
use crate::numeric::unrolled::{unrolled_sizes, Any, Fixed, Size, UNROLLED_MAX_SIZE};
use nalgebra::{DMatrix, DVector};

/// A driving-noise model: `Q` over a step.
pub trait ProcessNoise: std::fmt::Debug + Send + Sync {
    /// The state dimension.
    fn dimension(&self) -> usize;

    /// `Q(t_b, t_a)`, symmetric and positive semidefinite, `n × n`.
    fn covariance(&self, t_a: f64, t_b: f64) -> Result<DMatrix<f64>, Error>;

    /// [`ProcessNoise::covariance`] into the caller's `n × n` buffer (replaced if it is not
    /// `n × n`), allocating nothing where the model allows ([`WhiteNoiseDerivative`] does):
    /// what the Kalman filter calls at every prediction.
    ///
    /// ```
    /// use nalgebra::DMatrix;
    /// use seqsmooth::kalman::noise::{ProcessNoise, WhiteNoiseDerivative};
    /// let noise = WhiteNoiseDerivative::new(1, 1, 0.5).unwrap();
    /// let mut q = DMatrix::zeros(2, 2);
    /// noise.covariance_into(10.0, 12.0, &mut q).unwrap();
    /// assert_eq!(q, noise.covariance(10.0, 12.0).unwrap());
    /// ```
    fn covariance_into(&self, t_a: f64, t_b: f64, out: &mut DMatrix<f64>) -> Result<(), Error> {
        *out = self.covariance(t_a, t_b)?;
        Ok(())
    }

    /// The model's saved form ([`crate::persist`]), or `None` for a model of the caller's own
    /// type (a filter holding one cannot be saved).
    fn saved(&self) -> Option<super::saved_noise::SavedNoise> {
        None
    }

    /// Whether `Q(t_b, t_a)` depends only on the step `t_b − t_a` (the white-noise driving of
    /// the polynomial model, a continuous model's Van Loan `Q`): a bank computes it once for
    /// each step length in a row. `false` unless the model says so.
    fn is_time_invariant(&self) -> bool {
        false
    }

    /// The white noise on the polynomial model's highest derivative this is, when it is one
    /// ([`WhiteNoiseDerivative`], `Q` in closed form): the Kalman filter then fills `Q` with
    /// the sizes fixed at compile time (the same numbers). `None` unless the model says so.
    /// The filter reads it once when the noise is set, so the answer must not change over
    /// the model's life.
    ///
    /// ```
    /// use seqsmooth::kalman::noise::{ProcessNoise, WhiteNoiseDerivative};
    /// let q = WhiteNoiseDerivative::new(1, 1, 0.5).unwrap();
    /// assert_eq!(q.white_noise_derivative(), Some(q));
    /// ```
    fn white_noise_derivative(&self) -> Option<WhiteNoiseDerivative> {
        None
    }
}

/// The range of a driving noise's power spectral density `q` (ch. 15): finite and at least 0
/// (0: no driving noise). The one check of `q` ([`WhiteNoiseDerivative::new`], the radar
/// tracker, the command's `--q`, Python's `q`).
///
/// ```
/// use seqsmooth::kalman::noise::check_psd;
/// assert!(check_psd(0.0).is_ok() && check_psd(-1.0).is_err() && check_psd(f64::INFINITY).is_err());
/// ```
pub fn check_psd(q: f64) -> Result<(), Error> {
    if !(q.is_finite() && q >= 0.0) {
        return Err(Error::InvalidParameter {
            name: Param::Q,
            value: q.to_string(),
            reason: "must be a finite number at least 0".into(),
        });
    }
    Ok(())
}

/// White noise of power spectral density `q` on the highest derivative of a degree-`m`
/// polynomial model on `d` axes (the state order of
/// [`crate::model::dynamics::PolynomialDynamics`]): `q` in (value unit)² / (time unit)^(2m+1).
///
/// ```
/// use seqsmooth::kalman::noise::{ProcessNoise, WhiteNoiseDerivative};
/// // Constant velocity on one axis, q = 0.5, over ζ = 2: q [[ζ³/3, ζ²/2], [ζ²/2, ζ]].
/// let q = WhiteNoiseDerivative::new(1, 1, 0.5).unwrap().covariance(10.0, 12.0).unwrap();
/// assert_eq!((q[(0, 0)], q[(0, 1)], q[(1, 1)]), (0.5 * 8.0 / 3.0, 0.5 * 2.0, 0.5 * 2.0));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WhiteNoiseDerivative {
    degree: usize,
    axes: usize,
    psd: f64,
}

impl WhiteNoiseDerivative {
    /// Degree `m`, `axes ≥ 1`, spectral density `q ≥ 0` (finite; 0 is no driving noise).
    ///
    /// ```
    /// use seqsmooth::kalman::noise::WhiteNoiseDerivative;
    /// assert!(WhiteNoiseDerivative::new(2, 3, -1.0).is_err());
    /// assert!(WhiteNoiseDerivative::new(2, 0, 1.0).is_err());
    /// ```
    pub fn new(degree: usize, axes: usize, psd: f64) -> Result<Self, Error> {
        check_psd(psd)?;
        if axes == 0 {
            return Err(Error::InvalidParameter {
                name: Param::Axes,
                value: "0".into(),
                reason: "must be at least 1".into(),
            });
        }
        Ok(Self { degree, axes, psd })
    }

    /// The degree `m`, the axes `d` and the spectral density `q`.
    pub(crate) fn parts(&self) -> (usize, usize, f64) {
        (self.degree, self.axes, self.psd)
    }
}

impl ProcessNoise for WhiteNoiseDerivative {
    fn saved(&self) -> Option<super::saved_noise::SavedNoise> {
        Some(super::saved_noise::SavedNoise::WhiteNoiseDerivative(*self))
    }

    fn is_time_invariant(&self) -> bool {
        true
    }

    fn white_noise_derivative(&self) -> Option<WhiteNoiseDerivative> {
        Some(*self)
    }

    fn dimension(&self) -> usize {
        (self.degree + 1) * self.axes
    }

    fn covariance(&self, t_a: f64, t_b: f64) -> Result<DMatrix<f64>, Error> {
        let n = self.dimension();
        let mut q = DMatrix::zeros(n, n);
        self.covariance_into(t_a, t_b, &mut q)?;
        Ok(q)
    }

    /// The closed form on the upper triangle (`i ≤ j`), mirrored (the formula is symmetric in
    /// `i, j`), `ζ^p` by [`powi`] (the roundings of `f64::powi`); the rest of `out` zero.
    fn covariance_into(&self, t_a: f64, t_b: f64, out: &mut DMatrix<f64>) -> Result<(), Error> {
        for t in [t_a, t_b] {
            if !t.is_finite() {
                return Err(Error::NonFinite {
                    what: "time",
                    value: t,
                });
            }
        }
        let (m, d) = (self.degree, self.axes);
        let zeta = (t_b - t_a).abs();
        let n = (m + 1) * d;
        if out.shape() != (n, n) {
            *out = DMatrix::zeros(n, n);
        }
        let out = out.as_mut_slice();
        if d > 1 {
            out.fill(0.0);
        }
        let psd = self.psd;
        let finite = unrolled_sizes!(m + 1, M => fill(Fixed::<M>, d, psd, zeta, out),
            size => fill(Any(size), d, psd, zeta, out));
        if finite {
            return Ok(());
        }
        match out.iter().find(|v| !v.is_finite()) {
            Some(&value) => Err(Error::NonFinite {
                what: "driving-noise covariance entry",
                value,
            }),
            None => Ok(()),
        }
    }
}

/// The entries of [`WhiteNoiseDerivative`]'s `Q` for `size = m + 1` (a constant through the
/// size dispatch for the common degrees, so that each `ζ^p` is multiplied out and each
/// denominator folded: the same operations) on `d` axes into the zeroed `out`; whether all are
/// finite. Derivatives `i ≤ j` are counted from the highest, `u = m − i ≥ v = m − j`, so
/// `p = 2m + 1 − i − j = u + v + 1`; each entry is written at `(i, j)` and `(j, i)` of each axis.
#[inline(always)]
pub(crate) fn fill<S: Size>(size: S, d: usize, psd: f64, zeta: f64, out: &mut [f64]) -> bool {
    let (size, mut finite) = (size.get(), true);
    let n = size * d;
    // k! for k < size as a running product (the operations of `factorial`, in its order), in a
    // table when `size` is one the dispatch unrolls.
    let mut table = [1.0; UNROLLED_MAX_SIZE];
    let tabled = size <= UNROLLED_MAX_SIZE;
    for k in 2..if tabled { size } else { 0 } {
        table[k] = table[k - 1] * k as f64;
    }
    let fact = |k: usize| {
        if tabled {
            table[k]
        } else {
            factorial::<f64>(k)
        }
    };
    for u in 0..size {
        for v in 0..u + 1 {
            let p = u + v + 1;
            let q = psd * powi(zeta, p as u32) / (fact(u) * fact(v) * p as f64);
            finite &= q.is_finite();
            let (i, j) = ((size - 1 - u) * d, (size - 1 - v) * d);
            for a in 0..d {
                out[(i + a) + (j + a) * n] = q;
                out[(j + a) + (i + a) * n] = q;
            }
        }
    }
    finite
}

/// A continuous model's driving noise over the step, `Q(|t_b − t_a|)`
/// ([`ContinuousModel::noise_covariance`]: Van Loan's `∫₀^ζ e^{As} Q_c e^{Aᵀs} ds`). A step
/// backwards uses `Q(|ζ|)`, the convention of [`WhiteNoiseDerivative`]: the uncertainty added
/// grows with the span whichever way it is crossed. It is a convention, not the backward
/// model's own noise `Φ(−ζ) Q(ζ) Φ(−ζ)ᵀ`, which differs (for constant velocity its
/// position–velocity term is `−qζ²/2`; for the Singer model its acceleration variance is
/// `σ_m² (e^{2α|ζ|} − 1)`). The model is also the filter's
/// [`Dynamics`](crate::model::dynamics::Dynamics).
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::kalman::noise::{ProcessNoise, WhiteNoiseDerivative};
/// use seqsmooth::kalman::KalmanFilter;
/// use seqsmooth::model::continuous::ContinuousModel;
/// use seqsmooth::model::observation::LinearObservation;
/// let model = ContinuousModel::singer(1, 0.2, 9.0).unwrap();
/// let q = model.covariance(1.0, 1.5).unwrap();
/// assert!((q[(2, 2)] - 9.0 * (1.0 - (-0.2_f64).exp())).abs() < 1e-14); // σ_m² (1 − e^{−2αζ})
/// // The model as a Kalman filter's dynamics and driving noise.
/// let mut f = KalmanFilter::new(model.clone(), LinearObservation::value_of(3),
///     DVector::zeros(3), DMatrix::zeros(3, 3), 0.0).unwrap()
///     .with_process_noise(model).unwrap();
/// f.predict(0.5).unwrap();
/// assert!((f.covariance() - q).amax() < 1e-15);
/// ```
impl ProcessNoise for ContinuousModel {
    fn saved(&self) -> Option<super::saved_noise::SavedNoise> {
        Some(super::saved_noise::SavedNoise::Continuous(self.clone()))
    }

    fn is_time_invariant(&self) -> bool {
        true
    }

    fn dimension(&self) -> usize {
        crate::model::dynamics::Dynamics::dimension(self)
    }

    fn covariance(&self, t_a: f64, t_b: f64) -> Result<DMatrix<f64>, Error> {
        self.noise_covariance(step_between(t_a, t_b)?)
    }
}

/// The step `|t_b − t_a|` a driving noise accumulates over, both times finite.
fn step_between(t_a: f64, t_b: f64) -> Result<f64, Error> {
    match [t_a, t_b].into_iter().find(|t| !t.is_finite()) {
        Some(value) => Err(Error::NonFinite {
            what: "time",
            value,
        }),
        None => Ok((t_b - t_a).abs()),
    }
}
/// The coordinated turn's driving noise ([`crate::model::coordinated_turn`]): white
/// acceleration on each axis (turned with the velocity for a known rate) and a random walk of
/// an estimated rate, `Q` over `|t_b − t_a|` in closed form. The model is also the filter's
/// [`Dynamics`](crate::model::dynamics::Dynamics).
///
/// ```
/// use seqsmooth::kalman::noise::ProcessNoise;
/// use seqsmooth::model::coordinated_turn::CoordinatedTurn;
/// let turn = CoordinatedTurn::estimated(2.0, 0.25).unwrap();
/// let q = turn.covariance(10.0, 13.0).unwrap();
/// assert_eq!((q[(3, 3)], q[(6, 6)]), (6.0, 0.75)); // q ζ, q_ω ζ
/// ```
impl ProcessNoise for CoordinatedTurn {
    fn saved(&self) -> Option<super::saved_noise::SavedNoise> {
        Some(super::saved_noise::SavedNoise::CoordinatedTurn(*self))
    }

    fn dimension(&self) -> usize {
        crate::model::dynamics::Dynamics::dimension(self)
    }

    fn covariance(&self, t_a: f64, t_b: f64) -> Result<DMatrix<f64>, Error> {
        self.noise_covariance(step_between(t_a, t_b)?)
    }
}

/// A given `Q` over each step, the same whatever the step's length: the process noise of a
/// discrete-time model ([`super::discrete`]), symmetric positive semidefinite and finite.
///
/// ```
/// use nalgebra::DMatrix;
/// use seqsmooth::kalman::noise::{MatrixNoise, ProcessNoise};
/// let q = DMatrix::from_row_slice(2, 2, &[0.25, 0.5, 0.5, 1.0]);
/// assert_eq!(MatrixNoise::new(q.clone()).unwrap().covariance(0.0, 1.0).unwrap(), q);
/// assert!(MatrixNoise::new(DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, -1.0])).is_err());
/// ```
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MatrixNoise {
    q: DMatrix<f64>,
}

impl MatrixNoise {
    /// `Q`, checked by [`check_covariance`] ([`Param::ProcessNoiseQ`]).
    pub fn new(q: DMatrix<f64>) -> Result<Self, Error> {
        check_covariance(&q, q.nrows(), Param::ProcessNoiseQ)?;
        Ok(Self { q })
    }

    /// `Q` already checked by the caller.
    pub(crate) fn unchecked(q: DMatrix<f64>) -> Self {
        Self { q }
    }
}

impl ProcessNoise for MatrixNoise {
    fn saved(&self) -> Option<super::saved_noise::SavedNoise> {
        Some(super::saved_noise::SavedNoise::Matrix(self.clone()))
    }

    fn dimension(&self) -> usize {
        self.q.nrows()
    }

    fn covariance(&self, _t_a: f64, _t_b: f64) -> Result<DMatrix<f64>, Error> {
        Ok(self.q.clone())
    }

    fn covariance_into(&self, _t_a: f64, _t_b: f64, out: &mut DMatrix<f64>) -> Result<(), Error> {
        if out.shape() != self.q.shape() {
            *out = self.q.clone();
        } else {
            out.copy_from(&self.q);
        }
        Ok(())
    }
}

/// Refuses a matrix that is not `shape` or holds a number that is not finite, naming it.
///
/// ```
/// use nalgebra::DMatrix;
/// use seqsmooth::error::Param;
/// use seqsmooth::kalman::noise::check_matrix;
/// assert!(check_matrix(&DMatrix::zeros(2, 3), (2, 2), Param::TransitionMatrixF).is_err());
/// ```
pub fn check_matrix(m: &DMatrix<f64>, shape: (usize, usize), name: Param) -> Result<(), Error> {
    if m.shape() != shape || m.is_empty() {
        return Err(Error::InvalidParameter {
            name,
            value: format!("of shape {}x{}", m.nrows(), m.ncols()),
            reason: format!("must be {}x{}", shape.0, shape.1),
        });
    }
    if let Some(&v) = m.iter().find(|v| !v.is_finite()) {
        return Err(Error::InvalidParameter {
            name,
            value: format!("holding {v}"),
            reason: "must be finite".into(),
        });
    }
    Ok(())
}

/// Refuses a covariance that is not `n × n`, finite, symmetric (to `10⁻¹²` of its largest
/// entry) and positive semidefinite (no eigenvalue below `−10⁻¹²` of the largest in size, the
/// symmetric eigendecomposition's rounding), naming it.
///
/// ```
/// use nalgebra::DMatrix;
/// use seqsmooth::error::Param;
/// use seqsmooth::kalman::noise::check_covariance;
/// let indefinite = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
/// assert!(check_covariance(&indefinite, 2, Param::ProcessNoiseQ).is_err());
/// assert!(check_covariance(&DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 1.0, 1.0]), 2, Param::ProcessNoiseQ).is_ok());
/// ```
pub fn check_covariance(m: &DMatrix<f64>, n: usize, name: Param) -> Result<(), Error> {
    check_matrix(m, (n, n), name)?;
    let largest = m.amax();
    let skew = m - m.transpose();
    if skew.amax() > 1e-12 * largest {
        let (i, j) = skew.iamax_full();
        return Err(Error::InvalidParameter {
            name,
            value: format!(
                "with [{i}, {j}] = {} and [{j}, {i}] = {}",
                m[(i, j)],
                m[(j, i)]
            ),
            reason: "must be symmetric".into(),
        });
    }
    let eigen = nalgebra::SymmetricEigen::new((m + m.transpose()) * 0.5).eigenvalues;
    let scale = eigen.amax();
    let least = eigen.min();
    if least < -1e-12 * scale {
        return Err(Error::InvalidParameter {
            name,
            value: format!("with an eigenvalue {least:e}"),
            reason: "must be positive semidefinite".into(),
        });
    }
    Ok(())
}

/// Refuses an estimate to set in a filter of `n` states: `state` not `n` finite numbers
/// ([`Param::State`]), or `covariance` not a covariance as [`check_covariance`] has it
/// ([`Param::StateCovarianceP`]). The one check of every Kalman-family filter's
/// `set_estimate`.
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::error::{Error, Param};
/// use seqsmooth::kalman::noise::check_estimate;
/// let x = DVector::from_vec(vec![1.0, 2.0]);
/// assert!(check_estimate(&x, &DMatrix::identity(2, 2), 2).is_ok());
/// let e = check_estimate(&x, &DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]), 2);
/// assert!(matches!(e, Err(Error::InvalidParameter { name: Param::StateCovarianceP, .. })));
/// let e = check_estimate(&DVector::from_vec(vec![f64::NAN, 0.0]), &DMatrix::identity(2, 2), 2);
/// assert!(matches!(e, Err(Error::InvalidParameter { name: Param::State, .. })));
/// ```
pub fn check_estimate(
    state: &DVector<f64>,
    covariance: &DMatrix<f64>,
    n: usize,
) -> Result<(), Error> {
    if state.len() != n || state.iter().any(|v| !v.is_finite()) {
        return Err(Error::InvalidParameter {
            name: Param::State,
            value: format!("{:?}", state.as_slice()),
            reason: format!("must be {n} finite numbers"),
        });
    }
    check_covariance(covariance, n, Param::StateCovarianceP)
}

/// [`check_estimate`] and a finite `time`: what a filter's `set_estimate(state, covariance,
/// time)` checks.
pub(crate) fn check_estimate_at(
    state: &DVector<f64>,
    covariance: &DMatrix<f64>,
    n: usize,
    time: f64,
) -> Result<(), Error> {
    check_estimate(state, covariance, n)?;
    if !time.is_finite() {
        return Err(Error::NonFinite {
            what: "time",
            value: time,
        });
    }
    Ok(())
}

/// Refuses a driving noise of other than the dynamics' `n` states, naming it.
pub(crate) fn check_noise_dimension(noise: &dyn ProcessNoise, n: usize) -> Result<(), Error> {
    if noise.dimension() != n {
        return Err(Error::InvalidParameter {
            name: Param::ProcessNoise,
            value: format!("for {} states", noise.dimension()),
            reason: format!("the dynamics have {n} states"),
        });
    }
    Ok(())
}
