//! The radar tracker's motion models: the built-in models a tracking engineer expects, by the
//! names every front end takes ([`MotionModel::from_name`]), each with its driving noise at the
//! level the innovation monitor chooses ([`super::adaptive`]).
//!
//! | name | state | dynamics | driving noise at level `ℓ` | start |
//! |---|---|---|---|---|
//! | `constant-velocity` | `(x, y, z, ẋ, ẏ, ż)` | [`PolynomialDynamics`] degree 1 | white acceleration `q 4^ℓ` (15.2.23) | the fit of degree 1 |
//! | `constant-acceleration` | and `(ẍ, ÿ, z̈)` | [`PolynomialDynamics`] degree 2 | white jerk `q 4^ℓ` | the fit of degree 2 |
//! | `singer` | as constant acceleration | [`ContinuousModel::singer`], `α` | Singer's, `σ_m² 4^ℓ` (Van Loan) | the fit of degree 2 |
//! | `coordinated-turn` | and `ω` | [`CoordinatedTurn::estimated`] | white acceleration `q 4^ℓ`, `ω`'s random walk `q_ω 4^ℓ` | the fit of degree 1, `ω = 0` with σ [`TURN_RATE_PRIOR_SIGMA`] |
//!
//! The adaptive driving noise's level 0 (no `q` given) is the tracking index 1 of the model's
//! highest derivative: `q₀ = σ_r² / T^(2m+1)` with `m` its degree (3 for constant velocity and
//! the turn, 5 for constant acceleration); for Singer `σ_m²₀ = α q₀ / 2`, whose long-step
//! limit `2σ_m²/α` is constant velocity's `q₀`. The first rows are fitted by Gauss–Newton (§8.5-8.7) with the
//! polynomial model of the start's degree; the turn rate starts at 0 (a straight leg).

use super::memory::Filter;
use super::TrackMethod;
use crate::error::{Error, Param};
use crate::estimate::gauss_newton::Correction;
use crate::kalman::noise::WhiteNoiseDerivative;
use crate::model::continuous::ContinuousModel;
use crate::model::coordinated_turn::CoordinatedTurn;
use crate::model::dynamics::{Dynamics, PolynomialDynamics, Propagation};
use nalgebra::{DMatrix, DVector};

/// Singer's manoeuvre rate `α` (per time unit) when none is given: a manoeuvre time constant
/// of 10 time units (Singer's "evasive manoeuvre" range, seconds).
pub const DEFAULT_MANOEUVRE_ALPHA: f64 = 0.1;

/// The coordinated turn's random-walk density `q_ω` of the turn rate when none is given
/// (rad² per time unit³): the rate's σ grows by 0.01 rad per time unit over one time unit.
pub const DEFAULT_TURN_RATE_NOISE: f64 = 1e-4;

/// The coordinated turn's prior σ of the turn rate at the start (rad per time unit, about
/// 5.7°/s in seconds; the start's fit gives no turn rate).
pub const TURN_RATE_PRIOR_SIGMA: f64 = 0.1;

/// A built-in motion model of the tracker (the module's table).
///
/// ```
/// use seqsmooth::track::MotionModel;
/// let m = MotionModel::from_name("coordinated-turn").unwrap();
/// assert_eq!((m.name(), m.dimension()), ("coordinated-turn", 7));
/// assert_eq!(MotionModel::default(), MotionModel::ConstantVelocity);
/// assert!(MotionModel::from_name("cv").is_none());
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum MotionModel {
    /// Nearly constant velocity, white acceleration of density `q` on each axis.
    #[default]
    ConstantVelocity,
    /// Nearly constant acceleration, white jerk of density `q` on each axis.
    ConstantAcceleration,
    /// Singer's exponentially correlated acceleration.
    Singer {
        /// `α > 0`, the reciprocal of the manoeuvre time constant.
        alpha: f64,
        /// `σ_m² ≥ 0`, the manoeuvre variance; `None`: adaptive.
        variance: Option<f64>,
    },
    /// The coordinated turn at an estimated rate.
    CoordinatedTurn {
        /// `q_ω ≥ 0`, the turn rate's random-walk density; `None`:
        /// [`DEFAULT_TURN_RATE_NOISE`] (times the adaptive level's scale).
        turn_rate_noise: Option<f64>,
    },
}

impl MotionModel {
    /// Every model's name, in the order of the module's table.
    pub const NAMES: [&'static str; 4] = [
        "constant-velocity",
        "constant-acceleration",
        "singer",
        "coordinated-turn",
    ];

    /// The model a front end names (one of [`Self::NAMES`]) at its defaults: Singer's
    /// [`DEFAULT_MANOEUVRE_ALPHA`] and an adaptive variance, the turn's
    /// [`DEFAULT_TURN_RATE_NOISE`] (`turn_rate_noise: None`); `None` for any other name.
    ///
    /// ```
    /// use seqsmooth::track::MotionModel;
    /// assert_eq!(MotionModel::from_name("singer"),
    ///     Some(MotionModel::Singer { alpha: 0.1, variance: None }));
    /// ```
    pub fn from_name(name: &str) -> Option<Self> {
        Some(match name {
            "constant-velocity" => MotionModel::ConstantVelocity,
            "constant-acceleration" => MotionModel::ConstantAcceleration,
            "singer" => MotionModel::Singer {
                alpha: DEFAULT_MANOEUVRE_ALPHA,
                variance: None,
            },
            "coordinated-turn" => MotionModel::CoordinatedTurn {
                turn_rate_noise: None,
            },
            _ => return None,
        })
    }

    /// [`Self::from_name`], a name not in [`Self::NAMES`] refused ([`Param::MotionModel`]).
    ///
    /// ```
    /// use seqsmooth::track::MotionModel;
    /// assert!(MotionModel::named("spiral").unwrap_err().to_string().contains("coordinated-turn"));
    /// ```
    pub fn named(name: &str) -> Result<Self, Error> {
        Self::from_name(name).ok_or_else(|| Error::InvalidParameter {
            name: Param::MotionModel,
            value: format!("'{name}'"),
            reason: format!("must be one of {}", Self::NAMES.join(", ")),
        })
    }

    /// The model with its parameters set where given: Singer's `alpha` and `variance`, the
    /// turn's `turn_rate_noise`; a parameter the model has not is refused, naming it.
    ///
    /// ```
    /// use seqsmooth::track::MotionModel;
    /// let m = MotionModel::named("singer").unwrap().with_parameters(Some(0.05), Some(4.0), None).unwrap();
    /// assert_eq!(m, MotionModel::Singer { alpha: 0.05, variance: Some(4.0) });
    /// assert!(MotionModel::ConstantVelocity.with_parameters(None, None, Some(1e-4)).is_err());
    /// ```
    pub fn with_parameters(
        self,
        alpha: Option<f64>,
        variance: Option<f64>,
        turn_rate_noise: Option<f64>,
    ) -> Result<Self, Error> {
        let refuse = |name: Param, value: f64| Error::InvalidParameter {
            name,
            value: value.to_string(),
            reason: format!("is not a parameter of the {} model", self.name()),
        };
        let model = match self {
            MotionModel::Singer {
                alpha: a,
                variance: v,
            } => {
                if let Some(q) = turn_rate_noise {
                    return Err(refuse(Param::TurnRateNoise, q));
                }
                MotionModel::Singer {
                    alpha: alpha.unwrap_or(a),
                    variance: variance.or(v),
                }
            }
            MotionModel::CoordinatedTurn { turn_rate_noise: q } => {
                if let Some(a) = alpha {
                    return Err(refuse(Param::ManoeuvreAlpha, a));
                }
                if let Some(v) = variance {
                    return Err(refuse(Param::ManoeuvreVariance, v));
                }
                MotionModel::CoordinatedTurn {
                    turn_rate_noise: turn_rate_noise.or(q),
                }
            }
            _ => {
                let given = [
                    (Param::ManoeuvreAlpha, alpha),
                    (Param::ManoeuvreVariance, variance),
                    (Param::TurnRateNoise, turn_rate_noise),
                ];
                if let Some((name, Some(v))) = given.into_iter().find(|(_, v)| v.is_some()) {
                    return Err(refuse(name, v));
                }
                self
            }
        };
        model.check()?;
        Ok(model)
    }

    /// The model's name (its entry of [`Self::NAMES`]).
    pub fn name(self) -> &'static str {
        Self::NAMES[match self {
            MotionModel::ConstantVelocity => 0,
            MotionModel::ConstantAcceleration => 1,
            MotionModel::Singer { .. } => 2,
            MotionModel::CoordinatedTurn { .. } => 3,
        }]
    }

    /// The state dimension: 6, 9, 9 or 7.
    pub fn dimension(self) -> usize {
        match self {
            MotionModel::ConstantVelocity => 6,
            MotionModel::ConstantAcceleration | MotionModel::Singer { .. } => 9,
            MotionModel::CoordinatedTurn { .. } => 7,
        }
    }

    /// The parameters' ranges: Singer's `α` finite and above 0, `σ_m²` finite and at least 0,
    /// the turn's `q_ω` finite and at least 0.
    ///
    /// ```
    /// use seqsmooth::track::MotionModel;
    /// assert!(MotionModel::Singer { alpha: 0.0, variance: None }.check().is_err());
    /// assert!(MotionModel::CoordinatedTurn { turn_rate_noise: Some(1e-4) }.check().is_ok());
    /// assert!(MotionModel::CoordinatedTurn { turn_rate_noise: Some(-1.0) }.check().is_err());
    /// ```
    pub fn check(self) -> Result<(), Error> {
        self.dynamics().map(|_| ())
    }

    /// Refuses the model where `method` cannot use it: the window method fits constant
    /// velocity only; a `q` does not apply to Singer (its driving noise is its variance); the
    /// fading method has no driving noise, so neither a Singer variance nor a turn rate noise.
    ///
    /// ```
    /// use seqsmooth::track::{MotionModel, TrackMethod};
    /// let singer = MotionModel::named("singer").unwrap();
    /// assert!(singer.check_method(TrackMethod::Kalman { q: None }).is_ok());
    /// assert!(singer.check_method(TrackMethod::Kalman { q: Some(1.0) }).is_err());
    /// assert!(singer.check_method(TrackMethod::Window { window: 8 }).is_err());
    /// ```
    pub fn check_method(self, method: TrackMethod) -> Result<(), Error> {
        let refuse = |name: Param, value: String, reason: &str| Error::InvalidParameter {
            name,
            value,
            reason: reason.into(),
        };
        match (method, self) {
            (TrackMethod::Window { .. }, MotionModel::ConstantVelocity) => {}
            (TrackMethod::Window { .. }, _) => {
                return Err(refuse(
                    Param::MotionModel,
                    self.name().into(),
                    "the window method fits the constant-velocity model only (use the \
                     kalman, smooth or fading method)",
                ))
            }
            (
                TrackMethod::Kalman { q: Some(q) } | TrackMethod::Smooth { q: Some(q), .. },
                MotionModel::Singer { .. },
            ) => {
                return Err(refuse(
                    Param::Q,
                    q.to_string(),
                    "does not apply to the singer model: its driving noise is the manoeuvre \
                     variance",
                ))
            }
            (
                TrackMethod::Fading(_),
                MotionModel::Singer {
                    variance: Some(v), ..
                },
            ) => {
                return Err(refuse(
                    Param::ManoeuvreVariance,
                    v.to_string(),
                    "does not apply to the fading method, which has no driving noise",
                ))
            }
            (
                TrackMethod::Fading(_),
                MotionModel::CoordinatedTurn {
                    turn_rate_noise: Some(v),
                },
            ) => {
                return Err(refuse(
                    Param::TurnRateNoise,
                    v.to_string(),
                    "does not apply to the fading method, which has no driving noise",
                ))
            }
            _ => {}
        }
        Ok(())
    }

    /// The degree of the polynomial model of the start's fit: 2 where the state holds the
    /// acceleration, else 1.
    pub(crate) fn start_degree(self) -> usize {
        match self {
            MotionModel::ConstantAcceleration | MotionModel::Singer { .. } => 2,
            _ => 1,
        }
    }

    /// The degree `m` of the derivative the driving noise enters (the adaptive `q₀`'s power
    /// `2m + 1`).
    pub(crate) fn noise_degree(self) -> i32 {
        match self {
            MotionModel::ConstantAcceleration => 2,
            _ => 1,
        }
    }

    /// The level-0 driving noise of the adaptive memory from constant velocity's `q₀` at
    /// the model's own `q₀_m` (`q₀_m = σ_r²/T^(2m+1)`): Singer's `σ_m²₀ = α q₀ / 2`.
    pub(crate) fn adaptive_base(self, q0: f64, q0_cv: f64) -> f64 {
        match self {
            MotionModel::Singer { alpha, .. } => alpha * q0_cv / 2.0,
            _ => q0,
        }
    }

    /// The dynamics (checked).
    pub(crate) fn dynamics(self) -> Result<TrackDynamics, Error> {
        Ok(match self {
            MotionModel::ConstantVelocity => {
                TrackDynamics::Polynomial(PolynomialDynamics::new(1, 3))
            }
            MotionModel::ConstantAcceleration => {
                TrackDynamics::Polynomial(PolynomialDynamics::new(2, 3))
            }
            MotionModel::Singer { alpha, variance } => TrackDynamics::Continuous(
                ContinuousModel::singer(3, alpha, variance.unwrap_or(0.0))?,
            ),
            MotionModel::CoordinatedTurn { turn_rate_noise } => {
                let q = turn_rate_noise.unwrap_or(DEFAULT_TURN_RATE_NOISE);
                TrackDynamics::Turn(CoordinatedTurn::estimated(0.0, q)?)
            }
        })
    }

    /// Sets `f`'s driving noise: `noise` (`q`, or Singer's `σ_m²`) and the turn's `q_ω`, both
    /// times `scale`.
    pub(crate) fn set_noise(self, f: &mut Filter, noise: f64, scale: f64) -> Result<(), Error> {
        let level = noise * scale;
        match self {
            MotionModel::ConstantVelocity => {
                f.set_process_noise(WhiteNoiseDerivative::new(1, 3, level)?)
            }
            MotionModel::ConstantAcceleration => {
                f.set_process_noise(WhiteNoiseDerivative::new(2, 3, level)?)
            }
            MotionModel::Singer { alpha, .. } => {
                f.set_process_noise(ContinuousModel::singer(3, alpha, level)?)
            }
            MotionModel::CoordinatedTurn { turn_rate_noise } => {
                let q = turn_rate_noise.unwrap_or(DEFAULT_TURN_RATE_NOISE);
                f.set_process_noise(CoordinatedTurn::estimated(level, q * scale)?)
            }
        }
    }

    /// The start's fit as the model's state: the coordinated turn's rate appended, 0 with
    /// variance [`TURN_RATE_PRIOR_SIGMA`]²; the others as fitted.
    pub(crate) fn extend(self, c: &mut Correction) {
        if let MotionModel::CoordinatedTurn { .. } = self {
            let n = c.state.len();
            let mut state = DVector::zeros(n + 1);
            state.rows_mut(0, n).copy_from(&c.state);
            let mut covariance = DMatrix::zeros(n + 1, n + 1);
            covariance.view_mut((0, 0), (n, n)).copy_from(&c.covariance);
            covariance[(n, n)] = TURN_RATE_PRIOR_SIGMA * TURN_RATE_PRIOR_SIGMA;
            c.state = state;
            c.covariance = covariance;
        }
    }
}

/// The tracker's dynamics: one of the built-in models' (a [`Dynamics`] by dispatch).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub(crate) enum TrackDynamics {
    Polynomial(PolynomialDynamics),
    Continuous(ContinuousModel),
    Turn(CoordinatedTurn),
}

impl Dynamics for TrackDynamics {
    fn dimension(&self) -> usize {
        match self {
            TrackDynamics::Polynomial(d) => d.dimension(),
            TrackDynamics::Continuous(d) => Dynamics::dimension(d),
            TrackDynamics::Turn(d) => Dynamics::dimension(d),
        }
    }

    fn is_linear(&self) -> bool {
        match self {
            TrackDynamics::Polynomial(d) => d.is_linear(),
            TrackDynamics::Continuous(d) => d.is_linear(),
            TrackDynamics::Turn(d) => d.is_linear(),
        }
    }

    fn polynomial(&self) -> Option<PolynomialDynamics> {
        match self {
            TrackDynamics::Polynomial(d) => Some(*d),
            _ => None,
        }
    }

    fn propagate(&self, state: &DVector<f64>, t_a: f64, t_b: f64) -> Result<Propagation, Error> {
        match self {
            TrackDynamics::Polynomial(d) => d.propagate(state, t_a, t_b),
            TrackDynamics::Continuous(d) => d.propagate(state, t_a, t_b),
            TrackDynamics::Turn(d) => d.propagate(state, t_a, t_b),
        }
    }

    fn propagate_into(
        &self,
        state: &DVector<f64>,
        t_a: f64,
        t_b: f64,
        state_out: &mut DVector<f64>,
        transition_out: &mut DMatrix<f64>,
    ) -> Result<(), Error> {
        match self {
            TrackDynamics::Polynomial(d) => {
                d.propagate_into(state, t_a, t_b, state_out, transition_out)
            }
            TrackDynamics::Continuous(d) => {
                d.propagate_into(state, t_a, t_b, state_out, transition_out)
            }
            TrackDynamics::Turn(d) => d.propagate_into(state, t_a, t_b, state_out, transition_out),
        }
    }
}
