//! The coordinated turn: a target turning at rate `ω` in the horizontal plane `x-y`, its
//! vertical velocity constant, the state `(x, y, z, ẋ, ẏ, ż)` (known `ω`) or
//! `(x, y, z, ẋ, ẏ, ż, ω)` (`ω` estimated), in the order of
//! [`PolynomialDynamics`](super::dynamics::PolynomialDynamics)'s constant velocity on three
//! axes.
//!
//! **The dynamics.** `ẍ = −ω ẏ`, `ÿ = ω ẋ`, `z̈ = 0`, `ω̇ = 0` (Bar-Shalom, Li and Kirubarajan,
//! *Estimation with Applications to Tracking and Navigation*, 2001, §11.7.1-11.7.2; Li and
//! Jilkov, "Survey of maneuvering target tracking, Part I", IEEE TAES 39(4), 2003, §V.A). Over a
//! step `ζ`, with `θ = ωζ`, `a = sin θ / ω = ζ S(θ)` and `b = (1 − cos θ)/ω = ζ C(θ)`:
//!
//! `x' = x + a ẋ − b ẏ`, `y' = y + b ẋ + a ẏ`, `z' = z + ζ ż`,
//! `ẋ' = cos θ ẋ − sin θ ẏ`, `ẏ' = sin θ ẋ + cos θ ẏ`, `ż' = ż`, `ω' = ω`,
//!
//! in closed form, forwards or backwards. For a known `ω` the model is linear, `dX/dt = A X`,
//! and this is `e^{Aζ}` exactly (Morrison §4.6). With `ω` a state the model is nonlinear; its
//! `Φ = ∂X(t + ζ)/∂X(t)` is analytic: the known-`ω` matrix with the column
//! `∂/∂ω`: `∂a/∂ω = ζ² S′(θ)`, `∂b/∂ω = ζ² C′(θ)`, `∂ẋ'/∂ω = −ζ ẏ'`, `∂ẏ'/∂ω = ζ ẋ'`.
//! `S(θ) = sin θ/θ`, `C(θ) = (1 − cos θ)/θ` and their derivatives are summed as their Taylor
//! series for `|θ| ≤ 1` (no cancellation; exact at `ω = 0`, where the model is constant
//! velocity) and in closed form beyond.
//!
//! **The driving noise** (Morrison ch. 15, (15.2.23)): white acceleration of spectral density
//! `q` on each axis, and for an estimated `ω` a random walk of `ω` of density `q_ω`. For a
//! known `ω` the integral is exact in closed form (the velocity noise turned with the
//! velocity; isotropic in `x-y`, so its covariance is turned into itself):
//!
//! `Q_pp = 2q (θ − sin θ)/ω³ I`, `Q_pv = q [[(1 − cos θ)/ω², (θ − sin θ)/ω²],
//! [−(θ − sin θ)/ω², (1 − cos θ)/ω²]]`, `Q_vv = q ζ I` in `x-y` (limits `q ζ³/3`,
//! `q ζ²/2`, 0 as `ω → 0`), constant velocity's `q [[ζ³/3, ζ²/2], [ζ²/2, ζ]]` in `z`;
//! equal to Van Loan's `Q(ζ)` of [`super::continuous`] to 1e-12 (tests/model_coordinated_turn.rs).
//! For an estimated `ω` the noise is taken independent of the turn, as Bar-Shalom, Li and
//! Kirubarajan's §11.7.2 does: the `ω = 0` form above (constant velocity's on each axis) and
//! `q_ω ζ` on `ω` (a step backwards uses `|ζ|`).

use super::dynamics::{check_propagation, finite_matrix, Dynamics, Propagation};
use crate::error::{Error, Param};
use nalgebra::{DMatrix, DVector};

/// Beyond this `|θ| = |ωζ|` the turn's functions are taken in closed form, within it by series.
const SERIES_LIMIT: f64 = 1.0;

/// The series' terms at most (`θ^40/41!` is far below a unit roundoff for `|θ| ≤ 1`).
const MAX_TERMS: usize = 20;

/// The coordinated turn (the module's model), with its driving noise.
///
/// ```
/// use nalgebra::DVector;
/// use seqsmooth::model::coordinated_turn::CoordinatedTurn;
/// use seqsmooth::model::dynamics::Dynamics;
/// // A quarter turn at 0.1 rad/s: velocity (100, 0) turns to (0, 100) in π/(2 · 0.1) s.
/// let turn = CoordinatedTurn::estimated(1.0, 1e-6).unwrap();
/// let x = DVector::from_vec(vec![0.0, 0.0, 0.0, 100.0, 0.0, 0.0, 0.1]);
/// let p = turn.propagate(&x, 0.0, std::f64::consts::PI / 0.2).unwrap();
/// assert!((p.state[0] - 1000.0).abs() < 1e-9 && (p.state[1] - 1000.0).abs() < 1e-9);
/// assert!(p.state[3].abs() < 1e-12 && (p.state[4] - 100.0).abs() < 1e-12);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CoordinatedTurn {
    /// `Some(ω)`: known; `None`: the seventh state.
    rate: Option<f64>,
    /// `q`, the white acceleration's spectral density on each axis.
    q: f64,
    /// `q_ω`, the turn rate's random walk density (0 for a known rate).
    q_rate: f64,
}

/// `S(θ) = sin θ/θ`, `C(θ) = (1 − cos θ)/θ` and their derivatives `S′`, `C′`.
#[derive(Clone, Copy, Debug)]
struct TurnFunctions {
    sin: f64,
    cos: f64,
    s: f64,
    c: f64,
    ds: f64,
    dc: f64,
}

impl TurnFunctions {
    fn at(theta: f64) -> Self {
        let (sin, cos) = theta.sin_cos();
        if theta.abs() > SERIES_LIMIT {
            let t2 = theta * theta;
            return Self {
                sin,
                cos,
                s: sin / theta,
                c: (1.0 - cos) / theta,
                ds: (theta * cos - sin) / t2,
                dc: (theta * sin - (1.0 - cos)) / t2,
            };
        }
        // S = Σ (−1)^k θ^{2k}/(2k+1)!, C = Σ (−1)^k θ^{2k+1}/(2k+2)!,
        // S′ = Σ_{k≥1} (−1)^k 2k θ^{2k−1}/(2k+1)!, C′ = Σ (−1)^k (2k+1) θ^{2k}/(2k+2)!.
        let t2 = theta * theta;
        // term = (−1)^k θ^{2k}/(2k+1)!, next = (−1)^k θ^{2k}/(2k+2)!.
        let (mut s, mut c, mut ds, mut dc) = (0.0, 0.0, 0.0, 0.0);
        let mut term = 1.0;
        for k in 0..MAX_TERMS {
            let kf = k as f64;
            let next = term / (2.0 * kf + 2.0);
            let (s1, c1) = (s + term, c + next * theta);
            let ds1 = if k > 0 && theta != 0.0 {
                ds + 2.0 * kf * term / theta
            } else {
                ds
            };
            let dc1 = dc + (2.0 * kf + 1.0) * next;
            let same = s1 == s && c1 == c && ds1 == ds && dc1 == dc;
            (s, c, ds, dc) = (s1, c1, ds1, dc1);
            if same {
                break;
            }
            term = -next * t2 / (2.0 * kf + 3.0);
        }
        Self {
            sin,
            cos,
            s,
            c,
            ds,
            dc,
        }
    }
}

impl CoordinatedTurn {
    /// The turn at the known rate `omega` (rad per time unit, positive anticlockwise from +x
    /// to +y; finite), six states, white acceleration of density `q ≥ 0` on each axis.
    ///
    /// ```
    /// use seqsmooth::model::coordinated_turn::CoordinatedTurn;
    /// use seqsmooth::model::dynamics::Dynamics;
    /// let turn = CoordinatedTurn::known(0.05, 1.0).unwrap();
    /// assert_eq!((turn.dimension(), turn.turn_rate(), turn.is_linear()), (6, Some(0.05), true));
    /// assert!(CoordinatedTurn::known(f64::NAN, 1.0).is_err());
    /// ```
    pub fn known(omega: f64, q: f64) -> Result<Self, Error> {
        if !omega.is_finite() {
            return Err(Error::InvalidParameter {
                name: Param::TurnRate,
                value: omega.to_string(),
                reason: "must be finite".into(),
            });
        }
        Self::checked(Some(omega), q, 0.0)
    }

    /// The turn at an estimated rate (the seventh state), white acceleration of density
    /// `q ≥ 0` on each axis and a random walk of the rate of density `q_rate ≥ 0`
    /// (rad² per time³).
    ///
    /// ```
    /// use seqsmooth::model::coordinated_turn::CoordinatedTurn;
    /// use seqsmooth::model::dynamics::Dynamics;
    /// let turn = CoordinatedTurn::estimated(0.5, 1e-6).unwrap();
    /// assert_eq!((turn.dimension(), turn.turn_rate(), turn.is_linear()), (7, None, false));
    /// assert!(CoordinatedTurn::estimated(0.5, -1.0).is_err());
    /// ```
    pub fn estimated(q: f64, q_rate: f64) -> Result<Self, Error> {
        Self::checked(None, q, q_rate)
    }

    fn checked(rate: Option<f64>, q: f64, q_rate: f64) -> Result<Self, Error> {
        for (name, v) in [(Param::Q, q), (Param::TurnRateNoise, q_rate)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::InvalidParameter {
                    name,
                    value: v.to_string(),
                    reason: "must be a finite number at least 0".into(),
                });
            }
        }
        Ok(Self { rate, q, q_rate })
    }

    /// The known turn rate, or `None` where it is the seventh state.
    pub fn turn_rate(&self) -> Option<f64> {
        self.rate
    }

    /// `q`, the white acceleration's spectral density on each axis.
    pub fn acceleration_density(&self) -> f64 {
        self.q
    }

    /// `q_ω`, the turn rate's random-walk density (0 for a known rate).
    pub fn turn_rate_density(&self) -> f64 {
        self.q_rate
    }

    /// The known-rate model's `A` (`dX/dt = A X`, six states): the oracle's matrix for
    /// [`super::linear`] and [`super::continuous`]. `None` for an estimated rate.
    ///
    /// ```
    /// use seqsmooth::model::coordinated_turn::CoordinatedTurn;
    /// let a = CoordinatedTurn::known(0.2, 1.0).unwrap().matrix().unwrap();
    /// assert_eq!((a[(0, 3)], a[(3, 4)], a[(4, 3)]), (1.0, -0.2, 0.2));
    /// ```
    pub fn matrix(&self) -> Option<DMatrix<f64>> {
        let w = self.rate?;
        let mut a = DMatrix::zeros(6, 6);
        for k in 0..3 {
            a[(k, k + 3)] = 1.0;
        }
        a[(3, 4)] = -w;
        a[(4, 3)] = w;
        Some(a)
    }

    /// `Φ(ζ)` at the state `x` (the rate from `x[6]` unless known) and `X(t + ζ)`.
    fn step(&self, x: &DVector<f64>, zeta: f64) -> (DVector<f64>, DMatrix<f64>) {
        let n = self.dimension();
        let w = self.rate.unwrap_or_else(|| x[6]);
        let f = TurnFunctions::at(w * zeta);
        let (a, b) = (zeta * f.s, zeta * f.c);
        let (vx, vy) = (x[3], x[4]);
        let mut phi = DMatrix::identity(n, n);
        phi[(0, 3)] = a;
        phi[(0, 4)] = -b;
        phi[(1, 3)] = b;
        phi[(1, 4)] = a;
        phi[(2, 5)] = zeta;
        phi[(3, 3)] = f.cos;
        phi[(3, 4)] = -f.sin;
        phi[(4, 3)] = f.sin;
        phi[(4, 4)] = f.cos;
        let mut out = x.clone();
        out[0] = x[0] + a * vx - b * vy;
        out[1] = x[1] + b * vx + a * vy;
        out[2] = x[2] + zeta * x[5];
        out[3] = f.cos * vx - f.sin * vy;
        out[4] = f.sin * vx + f.cos * vy;
        if self.rate.is_none() {
            let (da, db) = (zeta * zeta * f.ds, zeta * zeta * f.dc);
            phi[(0, 6)] = vx * da - vy * db;
            phi[(1, 6)] = vx * db + vy * da;
            phi[(3, 6)] = -zeta * out[4];
            phi[(4, 6)] = zeta * out[3];
        }
        (out, phi)
    }

    /// `Q(ζ)`, the driving noise accumulated over a step `|ζ|` (the module's closed form):
    /// symmetric, positive semidefinite.
    ///
    /// ```
    /// use seqsmooth::model::coordinated_turn::CoordinatedTurn;
    /// // At ω = 0, constant velocity's q ζ³/3, q ζ²/2, q ζ on each axis.
    /// let q = CoordinatedTurn::known(0.0, 3.0).unwrap().noise_covariance(2.0).unwrap();
    /// assert_eq!((q[(0, 0)], q[(0, 3)], q[(3, 3)], q[(1, 3)]), (8.0, 6.0, 6.0, 0.0));
    /// let q = CoordinatedTurn::estimated(3.0, 0.5).unwrap().noise_covariance(-2.0).unwrap();
    /// assert_eq!((q[(2, 2)], q[(6, 6)]), (8.0, 1.0));
    /// ```
    pub fn noise_covariance(&self, zeta: f64) -> Result<DMatrix<f64>, Error> {
        if !zeta.is_finite() {
            return Err(Error::InvalidParameter {
                name: Param::Step,
                value: zeta.to_string(),
                reason: "must be finite".into(),
            });
        }
        let zeta = zeta.abs();
        let n = self.dimension();
        let q = self.q;
        let w = self.rate.unwrap_or(0.0);
        // With θ = ωζ: (θ − sin θ)/ω³ = ζ³ (1 − S)/θ², (1 − cos θ)/ω² = ζ² C/θ,
        // (θ − sin θ)/ω² = ζ² (1 − S)/θ; their series for |θ| ≤ 1.
        let theta = w * zeta;
        let (one_minus_s_2, c_1, one_minus_s_1) = if theta.abs() > SERIES_LIMIT {
            let f = TurnFunctions::at(theta);
            let t2 = theta * theta;
            ((1.0 - f.s) / t2, f.c / theta, (1.0 - f.s) / theta)
        } else {
            // (1 − S)/θ² = Σ_{k≥0} (−1)^k θ^{2k}/(2k+3)!, C/θ = Σ (−1)^k θ^{2k}/(2k+2)!.
            let t2 = theta * theta;
            let (mut u, mut v) = (0.0, 0.0);
            let (mut tu, mut tv) = (1.0 / 6.0, 0.5);
            for k in 0..MAX_TERMS {
                let kf = k as f64;
                let (u1, v1) = (u + tu, v + tv);
                if u1 == u && v1 == v {
                    break;
                }
                (u, v) = (u1, v1);
                tu *= -t2 / ((2.0 * kf + 4.0) * (2.0 * kf + 5.0));
                tv *= -t2 / ((2.0 * kf + 3.0) * (2.0 * kf + 4.0));
            }
            (u, v, u * theta)
        };
        let z2 = zeta * zeta;
        let mut out = DMatrix::zeros(n, n);
        let pp = 2.0 * q * z2 * zeta * one_minus_s_2;
        let pv = q * z2 * c_1;
        let cross = q * z2 * one_minus_s_1;
        out[(0, 0)] = pp;
        out[(1, 1)] = pp;
        out[(0, 3)] = pv;
        out[(1, 4)] = pv;
        out[(0, 4)] = cross;
        out[(1, 3)] = -cross;
        out[(3, 3)] = q * zeta;
        out[(4, 4)] = q * zeta;
        out[(2, 2)] = q * z2 * zeta / 3.0;
        out[(2, 5)] = q * z2 / 2.0;
        out[(5, 5)] = q * zeta;
        for (i, j) in [(0, 3), (1, 4), (0, 4), (1, 3), (2, 5)] {
            out[(j, i)] = out[(i, j)];
        }
        if n == 7 {
            out[(6, 6)] = self.q_rate * zeta;
        }
        finite_matrix(&out, "driving-noise covariance entry")?;
        Ok(out)
    }
}

impl Dynamics for CoordinatedTurn {
    fn dimension(&self) -> usize {
        if self.rate.is_some() {
            6
        } else {
            7
        }
    }

    fn is_linear(&self) -> bool {
        self.rate.is_some()
    }

    fn propagate(&self, state: &DVector<f64>, t_a: f64, t_b: f64) -> Result<Propagation, Error> {
        check_propagation(self.dimension(), state, t_a, t_b)?;
        let (state, transition) = self.step(state, t_b - t_a);
        finite_matrix(&transition, "transition matrix entry")?;
        if let Some(&value) = state.iter().find(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "propagated state entry",
                value,
            });
        }
        Ok(Propagation { state, transition })
    }
}
