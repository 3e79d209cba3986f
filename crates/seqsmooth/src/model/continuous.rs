//! Continuous linear models with white driving noise, `dX/dt = A X + w`, `E[w(t) w(s)ᵀ] =
//! Q_c δ(t − s)`, discretised exactly over each actual step `ζ` (Morrison ch. 15, (15.2.23)):
//!
//! `Φ(ζ) = e^{Aζ}`, `Q(ζ) = ∫₀^ζ e^{As} Q_c e^{Aᵀs} ds`.
//!
//! Both come from Van Loan's block exponential (C. F. Van Loan, "Computing integrals involving
//! the matrix exponential", IEEE TAC 23(3), 1978): for `M = [[−A, Q_c], [0, Aᵀ]]`,
//! `e^{Mζ} = [[e^{−Aζ}, G(ζ)], [0, e^{Aᵀζ}]]` with `Φ(ζ) = (e^{Aᵀζ})ᵀ` and `Q(ζ) = Φ(ζ) G(ζ)`. It
//! is evaluated by scaling and squaring, as Van Loan's §4 does: on `h = ζ/2^s` (`s` the least
//! with `h‖A‖₁ ≤ 1/2`) the block exponential's Taylor series gives, block by block,
//! `Φ(h) = Σ_k (Ah)^k/k!` and `Q(h) = Σ_k h^{k+1}/(k+1)! L^k(Q_c)` with `L(X) = AX + XAᵀ`
//! (each series summed until every entry has stopped changing; finite for a nilpotent `A`);
//! then each squaring of `e^{Mh}`, written on those blocks, is
//! `Q(2h) = Q(h) + Φ(h) Q(h) Φ(h)ᵀ`, `Φ(2h) = Φ(h)²`. No `e^{−Aζ}` is ever formed (for an `A`
//! with decaying modes it would grow as the step does, and `Φ G` would cancel), and every
//! squaring adds positive semi-definite terms: where `Φ(h)` and `Q(h)` have no negative entries
//! (the polynomial and Singer models) each entry keeps its relative accuracy (ACCURACY.md).
//!
//! The built-in models are constructors of [`ContinuousModel`]: [`ContinuousModel::polynomial`]
//! (white noise on the highest derivative, whose closed form is
//! [`crate::kalman::noise::WhiteNoiseDerivative`]), [`ContinuousModel::nearly_constant_velocity`],
//! [`ContinuousModel::nearly_constant_acceleration`] and [`ContinuousModel::singer`] (Singer
//! 1970). The state is ordered by derivative, then axis: `x_a^(k)` at `k·d + a` on `d` axes, as
//! [`super::dynamics::PolynomialDynamics`] orders it. The model is its own [`Dynamics`] and its
//! own driving noise ([`crate::kalman::noise::ProcessNoise`]) for a
//! [`crate::kalman::KalmanFilter`].

use super::dynamics::{Dynamics, Propagation};
use super::linear::LinearDynamics;
use crate::error::{Error, Param};
use nalgebra::{DMatrix, DVector};

/// Why a step is refused when its `Φ` or `Q` is not finite.
const BEYOND: &str =
    "e^(step A) or the noise over the step is beyond the double range (about 1.8e308)";

/// The largest `h‖A‖₁` whose Taylor series start the squarings.
const BASE_NORM: f64 = 0.5;

/// The most terms of a Taylor series on `h` (with `h‖A‖₁ ≤ 1/2` the `k`-th term is below
/// `2^−k/k!` of the first: far below rounding long before).
const MAX_TERMS: usize = 80;

/// `dX/dt = A X + w`, white noise `w` of spectral density matrix `Q_c`, discretised exactly on
/// any step.
///
/// ```
/// use nalgebra::DMatrix;
/// use seqsmooth::model::continuous::ContinuousModel;
/// // Nearly constant velocity on one axis, q = 0.5, over ζ = 2: q [[ζ³/3, ζ²/2], [ζ²/2, ζ]].
/// let m = ContinuousModel::nearly_constant_velocity(&[0.5]).unwrap();
/// let (phi, q) = m.discretise(2.0).unwrap();
/// assert_eq!(phi, DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 0.0, 1.0]));
/// assert!((q[(0, 0)] - 0.5 * 8.0 / 3.0).abs() < 1e-15 && (q[(1, 1)] - 1.0).abs() < 1e-15);
/// ```
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ContinuousModel {
    dynamics: LinearDynamics,
    qc: DMatrix<f64>,
    /// `‖A‖₁`, the largest column sum of `|A|`.
    norm: f64,
}

impl ContinuousModel {
    /// The model of `A` (square, finite) and `Q_c` (`n × n` like `A`, finite, symmetric to
    /// 1e-12 of its largest entry, positive semi-definite to the same; kept symmetrised).
    ///
    /// ```
    /// use nalgebra::DMatrix;
    /// use seqsmooth::model::continuous::ContinuousModel;
    /// use seqsmooth::{Error, Param};
    /// let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 0.0]);
    /// let not_psd = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
    /// let e = ContinuousModel::new(a, not_psd).unwrap_err();
    /// assert!(matches!(e, Error::InvalidParameter { name: Param::SpectralDensity, .. }));
    /// ```
    pub fn new(a: DMatrix<f64>, qc: DMatrix<f64>) -> Result<Self, Error> {
        let dynamics = LinearDynamics::new(a)?;
        let n = dynamics.dimension();
        let qc = checked_spectral_density(qc, n)?;
        let norm = (0..n)
            .map(|j| dynamics.matrix().column(j).iter().map(|v| v.abs()).sum())
            .fold(0.0, f64::max);
        if !norm.is_finite() {
            // Finite entries whose column sum overflows: no step could be scaled into the
            // series' range (ζ would halve to zero and give Q = 0).
            return Err(Error::InvalidParameter {
                name: Param::DynamicsMatrixA,
                value: format!("a column sum of |A| of {norm}"),
                reason: "must be finite (rescale the time unit)".into(),
            });
        }
        Ok(Self { dynamics, qc, norm })
    }

    /// The polynomial model of degree `m` on `psd.len()` axes: `x_a^(m+1) = w_a`, white noise
    /// of spectral density `psd[a]` (finite, at least 0; (value unit)² / (time unit)^(2m+1)) on
    /// each axis' highest derivative, the axes independent. Its `Q(ζ)` is Morrison (15.2.23)'s
    /// closed form, [`crate::kalman::noise::WhiteNoiseDerivative`] (equal to 1e-12:
    /// tests/model_continuous.rs).
    ///
    /// ```
    /// use seqsmooth::model::continuous::ContinuousModel;
    /// let m = ContinuousModel::polynomial(0, &[2.0]).unwrap(); // a random walk
    /// assert_eq!(m.noise_covariance(3.0).unwrap()[(0, 0)], 6.0); // q ζ
    /// assert!(ContinuousModel::polynomial(1, &[]).is_err()); // no axes
    /// ```
    pub fn polynomial(degree: usize, psd: &[f64]) -> Result<Self, Error> {
        let d = psd.len();
        if d == 0 {
            return Err(Error::InvalidParameter {
                name: Param::Axes,
                value: "0".into(),
                reason: "must be at least 1 (one spectral density per axis)".into(),
            });
        }
        if let Some(&q) = psd.iter().find(|q| !(q.is_finite() && **q >= 0.0)) {
            return Err(Error::InvalidParameter {
                name: Param::DrivingNoiseQ,
                value: q.to_string(),
                reason: "must be finite and at least 0".into(),
            });
        }
        let n = states(degree.saturating_add(1), d)?;
        let mut a = DMatrix::zeros(n, n);
        let mut qc = DMatrix::zeros(n, n);
        for (axis, &q) in psd.iter().enumerate() {
            for k in 0..degree {
                a[(k * d + axis, (k + 1) * d + axis)] = 1.0;
            }
            qc[(degree * d + axis, degree * d + axis)] = q;
        }
        Self::new(a, qc)
    }

    /// Nearly constant velocity on `psd.len()` axes: [`polynomial`](Self::polynomial) of
    /// degree 1, white acceleration of spectral density `psd[a]` on axis `a`; the state
    /// `(x_0 … x_{d−1}, x'_0 … x'_{d−1})`.
    ///
    /// ```
    /// use seqsmooth::model::continuous::ContinuousModel;
    /// let m = ContinuousModel::nearly_constant_velocity(&[1.0, 4.0]).unwrap();
    /// let q = m.noise_covariance(1.0).unwrap();
    /// assert_eq!((q[(3, 3)], q[(1, 3)], q[(0, 1)]), (4.0, 2.0, 0.0)); // q ζ, q ζ²/2, axes apart
    /// ```
    pub fn nearly_constant_velocity(psd: &[f64]) -> Result<Self, Error> {
        Self::polynomial(1, psd)
    }

    /// Nearly constant acceleration on `psd.len()` axes: [`polynomial`](Self::polynomial) of
    /// degree 2, white jerk of spectral density `psd[a]` on axis `a`.
    ///
    /// ```
    /// use seqsmooth::model::continuous::ContinuousModel;
    /// let m = ContinuousModel::nearly_constant_acceleration(&[3.0]).unwrap();
    /// let q = m.noise_covariance(2.0).unwrap();
    /// assert!((q[(0, 0)] - 3.0 * 32.0 / 20.0).abs() < 1e-14); // q ζ⁵/20
    /// ```
    pub fn nearly_constant_acceleration(psd: &[f64]) -> Result<Self, Error> {
        Self::polynomial(2, psd)
    }

    /// The Singer model (R. A. Singer, "Estimating optimal tracking filter performance for
    /// manned maneuvering targets", IEEE TAES 6(4), 1970) on `axes` axes: position, velocity
    /// and an acceleration correlated as `σ_m² e^{−α|τ|}`, `da/dt = −α a + w` with `w` of
    /// spectral density `2ασ_m²`. `α > 0` is the reciprocal of the manoeuvre time constant,
    /// `σ_m² ≥ 0` the manoeuvre variance (both finite). Long steps tend to the nearly
    /// constant velocity model with `q = 2σ_m²/α`; short ones to nearly constant acceleration.
    ///
    /// ```
    /// use seqsmooth::model::continuous::ContinuousModel;
    /// let m = ContinuousModel::singer(1, 0.5, 4.0).unwrap();
    /// let phi = m.transition(2.0).unwrap();
    /// assert!((phi[(2, 2)] - (-1.0_f64).exp()).abs() < 1e-15); // e^{−αζ}
    /// // The acceleration's variance tends to σ_m² from zero: σ_m² (1 − e^{−2αζ}).
    /// let q = m.noise_covariance(2.0).unwrap();
    /// assert!((q[(2, 2)] - 4.0 * (1.0 - (-2.0_f64).exp())).abs() < 1e-14);
    /// assert!(ContinuousModel::singer(1, 0.0, 4.0).is_err());
    /// assert!(ContinuousModel::singer(usize::MAX / 2, 0.5, 4.0).is_err()); // beyond memory
    /// ```
    pub fn singer(axes: usize, alpha: f64, variance: f64) -> Result<Self, Error> {
        if axes == 0 {
            return Err(Error::InvalidParameter {
                name: Param::Axes,
                value: "0".into(),
                reason: "must be at least 1".into(),
            });
        }
        if !(alpha.is_finite() && alpha > 0.0) {
            return Err(Error::InvalidParameter {
                name: Param::ManoeuvreAlpha,
                value: alpha.to_string(),
                reason: "must be finite and greater than 0 (the reciprocal of the manoeuvre \
                         time constant)"
                    .into(),
            });
        }
        if !(variance.is_finite() && variance >= 0.0) {
            return Err(Error::InvalidParameter {
                name: Param::ManoeuvreVariance,
                value: variance.to_string(),
                reason: "must be finite and at least 0".into(),
            });
        }
        let d = axes;
        let n = states(3, d)?;
        let mut a = DMatrix::zeros(n, n);
        let mut qc = DMatrix::zeros(n, n);
        for axis in 0..d {
            a[(axis, d + axis)] = 1.0;
            a[(d + axis, 2 * d + axis)] = 1.0;
            a[(2 * d + axis, 2 * d + axis)] = -alpha;
            qc[(2 * d + axis, 2 * d + axis)] = 2.0 * alpha * variance;
        }
        Self::new(a, qc)
    }

    /// The dynamics `dX/dt = A X`.
    ///
    /// ```
    /// use seqsmooth::model::continuous::ContinuousModel;
    /// let m = ContinuousModel::nearly_constant_velocity(&[1.0]).unwrap();
    /// assert!(m.dynamics().is_nilpotent());
    /// ```
    pub fn dynamics(&self) -> &LinearDynamics {
        &self.dynamics
    }

    /// `Q_c`, the white noise's spectral density matrix (symmetrised).
    ///
    /// ```
    /// use seqsmooth::model::continuous::ContinuousModel;
    /// let m = ContinuousModel::nearly_constant_velocity(&[2.0]).unwrap();
    /// assert_eq!(m.spectral_density()[(1, 1)], 2.0);
    /// ```
    pub fn spectral_density(&self) -> &DMatrix<f64> {
        &self.qc
    }

    /// `Φ(ζ) = e^{Aζ}` for a step `ζ ≥ 0`: [`LinearDynamics::transition`] (the exact finite
    /// series for a nilpotent `A`, else nalgebra's scaling and squaring with a Padé
    /// approximant); the [`Dynamics`] propagation goes backwards too.
    ///
    /// ```
    /// use seqsmooth::model::continuous::ContinuousModel;
    /// let m = ContinuousModel::nearly_constant_acceleration(&[1.0]).unwrap();
    /// assert_eq!(m.transition(4.0).unwrap()[(0, 2)], 8.0); // ζ²/2
    /// assert!(m.transition(-1.0).is_err());
    /// ```
    pub fn transition(&self, zeta: f64) -> Result<DMatrix<f64>, Error> {
        if !(zeta.is_finite() && zeta >= 0.0) {
            return Err(Error::InvalidParameter {
                name: Param::Step,
                value: zeta.to_string(),
                reason: "must be finite and at least 0".into(),
            });
        }
        self.dynamics.transition(zeta)
    }

    /// `Q(ζ) = ∫₀^ζ e^{As} Q_c e^{Aᵀs} ds` for a step `ζ ≥ 0`: symmetric, positive
    /// semi-definite.
    ///
    /// ```
    /// use seqsmooth::model::continuous::ContinuousModel;
    /// let m = ContinuousModel::nearly_constant_velocity(&[3.0]).unwrap();
    /// let q = m.noise_covariance(1.0).unwrap();
    /// assert!((q[(0, 0)] - 1.0).abs() < 1e-15 && (q[(0, 1)] - 1.5).abs() < 1e-15);
    /// ```
    pub fn noise_covariance(&self, zeta: f64) -> Result<DMatrix<f64>, Error> {
        self.discretise(zeta).map(|(_, q)| q)
    }

    /// `(Φ(ζ), Q(ζ))` over a step `ζ ≥ 0` (finite): [`transition`](Self::transition) and
    /// Van Loan's block exponential by scaling and squaring (the module's method). Refused when `ζ` is negative or not finite, or a
    /// number of the result is beyond the double range.
    ///
    /// ```
    /// use seqsmooth::model::continuous::ContinuousModel;
    /// use seqsmooth::{Error, Param};
    /// let m = ContinuousModel::singer(2, 0.1, 1.0).unwrap();
    /// let (phi, q) = m.discretise(0.0).unwrap();
    /// assert!(phi.is_identity(0.0) && q.iter().all(|&v| v == 0.0));
    /// let e = m.discretise(f64::NAN).unwrap_err();
    /// assert!(matches!(e, Error::InvalidParameter { name: Param::Step, .. }));
    /// ```
    pub fn discretise(&self, zeta: f64) -> Result<(DMatrix<f64>, DMatrix<f64>), Error> {
        let refuse = |reason: &str| Error::InvalidParameter {
            name: Param::Step,
            value: zeta.to_string(),
            reason: reason.into(),
        };
        if !(zeta.is_finite() && zeta >= 0.0) {
            return Err(refuse("must be finite and at least 0"));
        }
        // ζ = 2^s h with h‖A‖₁ ≤ 1/2 (halving is exact).
        let (mut h, mut squarings) = (zeta, 0);
        while h * self.norm > BASE_NORM {
            h *= 0.5;
            squarings += 1;
        }
        if h > 0.0 && h < f64::MIN_POSITIVE {
            // A subnormal h: its halvings were not exact and its series would lose digits.
            return Err(refuse(BEYOND));
        }
        let (mut phi_h, mut q) = self.taylor(h);
        for _ in 0..squarings {
            q += &phi_h * &q * phi_h.transpose();
            phi_h = &phi_h * &phi_h;
        }
        let q = (&q + q.transpose()) * 0.5;
        let phi = self.dynamics.transition(zeta).map_err(|_| refuse(BEYOND))?;
        if phi.iter().chain(q.iter()).all(|v| v.is_finite()) {
            Ok((phi, q))
        } else {
            Err(refuse(BEYOND))
        }
    }

    /// `Φ(h)` and `Q(h)` by their Taylor series (the blocks of `e^{Mh}`), each summed until no
    /// entry changes: the start of the squarings.
    fn taylor(&self, h: f64) -> (DMatrix<f64>, DMatrix<f64>) {
        let a = self.dynamics.matrix();
        let n = a.nrows();
        let mut phi = DMatrix::identity(n, n);
        let mut term = DMatrix::identity(n, n);
        for k in 1..MAX_TERMS {
            term = &term * a * (h / k as f64);
            if !adds_to(&mut phi, &term) {
                break;
            }
        }
        let mut q = &self.qc * h;
        let mut term = q.clone();
        for k in 1..MAX_TERMS {
            term = (a * &term + &term * a.transpose()) * (h / (k + 1) as f64);
            if !adds_to(&mut q, &term) {
                break;
            }
        }
        (phi, q)
    }
}

/// The states of a built-in model, `per_axis · axes`, refused ([`Param::Axes`]) where an
/// `n × n` matrix's bytes would pass the largest allocation (`isize::MAX`).
fn states(per_axis: usize, axes: usize) -> Result<usize, Error> {
    let bytes = |n: usize| n.checked_mul(n)?.checked_mul(std::mem::size_of::<f64>());
    per_axis
        .checked_mul(axes)
        .filter(|&n| bytes(n).is_some_and(|b| b <= isize::MAX as usize))
        .ok_or_else(|| Error::InvalidParameter {
            name: Param::Axes,
            value: axes.to_string(),
            reason: "too many: the model's matrices must fit in memory".into(),
        })
}

/// `sum += term`; whether any entry of `sum` changed.
fn adds_to(sum: &mut DMatrix<f64>, term: &DMatrix<f64>) -> bool {
    let mut changed = false;
    for (s, &t) in sum.iter_mut().zip(term.iter()) {
        let next = *s + t;
        changed |= next != *s;
        *s = next;
    }
    changed
}

/// `Q_c` checked (`n × n`, finite, symmetric and positive semi-definite to 1e-12 of its
/// largest entry) and symmetrised.
fn checked_spectral_density(qc: DMatrix<f64>, n: usize) -> Result<DMatrix<f64>, Error> {
    let bad = |value: String, reason: String| Error::InvalidParameter {
        name: Param::SpectralDensity,
        value,
        reason,
    };
    if qc.shape() != (n, n) {
        return Err(bad(
            format!("{}x{}", qc.nrows(), qc.ncols()),
            format!("must be {n}x{n}, the shape of A"),
        ));
    }
    if let Some((k, v)) = qc.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(bad(
            format!("entry [{}, {}] = {v}", k % n, k / n),
            "must be finite".into(),
        ));
    }
    let scale = qc.amax();
    let tolerance = 1e-12 * scale;
    if let Some((k, _)) = (qc.clone() - qc.transpose())
        .iter()
        .enumerate()
        .find(|(_, v)| v.abs() > tolerance)
    {
        let (i, j) = (k % n, k / n);
        return Err(bad(
            format!(
                "entries [{i}, {j}] = {} and [{j}, {i}] = {}",
                qc[(i, j)],
                qc[(j, i)]
            ),
            "must be symmetric".into(),
        ));
    }
    let qc = (&qc + qc.transpose()) * 0.5;
    let least = qc.clone().symmetric_eigenvalues().min();
    if least < -tolerance {
        return Err(bad(
            format!("with eigenvalue {least}"),
            "must be positive semi-definite".into(),
        ));
    }
    Ok(qc)
}

impl Dynamics for ContinuousModel {
    fn dimension(&self) -> usize {
        self.dynamics.dimension()
    }

    fn is_linear(&self) -> bool {
        true
    }

    fn is_time_invariant(&self) -> bool {
        true
    }

    /// [`LinearDynamics`]'s propagation by `e^{Aζ}` ([`ContinuousModel::transition`]).
    fn propagate(&self, state: &DVector<f64>, t_a: f64, t_b: f64) -> Result<Propagation, Error> {
        self.dynamics.propagate(state, t_a, t_b)
    }
}
