//! Observation models (Morrison §8.2, §8.6): what a sensor sees of the state,
//! `Y = G(X, t) + N`, with the observation matrix `M = ∂G/∂X` ((8.6.8)-(8.6.13)); for a linear
//! model `G = M X` (8.2.2).
//!
//! | model | `G(X, t)` | `M` |
//! |---|---|---|
//! | [`LinearObservation`] | `M X` | the given `M` |
//! | [`NonlinearObservation`] | the caller's `G` | the caller's, or central differences |
//! | [`super::radar::Radar`] | range, azimuth, elevation (and range rate) from a site | analytic |
//!
//! A residual `Y − G` is taken by [`Observation::residual`], where an angle is wrapped.

use super::nonlinear::central_differences;
use super::radar::wrap;
use crate::error::{Error, Param};
use nalgebra::{DMatrix, DVector};
use std::sync::Arc;

/// `G(X, t)` and `M = ∂G/∂X` at one state.
#[derive(Clone, Debug, PartialEq)]
pub struct Predicted {
    /// `G(X, t)`, one number per component.
    pub value: DVector<f64>,
    /// `M`, components × states.
    pub jacobian: DMatrix<f64>,
}

/// An observation model of `components` numbers from a state of `state_dimension`.
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::model::observation::{LinearObservation, Observation};
/// let m = LinearObservation::new(DMatrix::from_row_slice(1, 2, &[1.0, 0.0])).unwrap();
/// let p = m.predict(&DVector::from_vec(vec![3.0, 4.0]), 0.0).unwrap();
/// assert_eq!(p.value[0], 3.0);
/// ```
pub trait Observation {
    /// The numbers in one observation.
    fn components(&self) -> usize;

    /// The state dimension.
    fn state_dimension(&self) -> usize;

    /// `G(X, t)` and `M(X, t)`.
    fn predict(&self, state: &DVector<f64>, t: f64) -> Result<Predicted, Error>;

    /// Whether `G(X, t) = M(t) X` exactly (no linearisation error): the Bayes filter then
    /// folds in the measured values as they are. `false` unless the model says so.
    ///
    /// ```
    /// use seqsmooth::model::observation::{LinearObservation, Observation};
    /// assert!(LinearObservation::value_of(2).is_linear());
    /// ```
    fn is_linear(&self) -> bool {
        false
    }

    /// [`Observation::predict`] into the caller's buffers (`value` of length `components`,
    /// `jacobian` `components × states`, replaced if they are not), allocating nothing where
    /// the model allows ([`super::radar::Radar`] does): what the estimators call at every
    /// observation.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::model::observation::{LinearObservation, Observation};
    /// let m = LinearObservation::value_of(2);
    /// let (mut g, mut j) = (DVector::zeros(1), DMatrix::zeros(1, 2));
    /// m.predict_into(&DVector::from_vec(vec![3.0, 4.0]), 0.0, &mut g, &mut j).unwrap();
    /// assert_eq!((g[0], j[(0, 0)], j[(0, 1)]), (3.0, 1.0, 0.0));
    /// ```
    fn predict_into(
        &self,
        state: &DVector<f64>,
        t: f64,
        value: &mut DVector<f64>,
        jacobian: &mut DMatrix<f64>,
    ) -> Result<(), Error> {
        let p = self.predict(state, t)?;
        *value = p.value;
        *jacobian = p.jacobian;
        Ok(())
    }

    /// `G(X, t)` alone, without `M`: what the unscented filter evaluates at each sigma point
    /// (Wan and van der Merwe (22)). By default [`Observation::predict`]'s value; a model whose
    /// `M` costs more than `G` (differenced) gives `G` alone.
    ///
    /// ```
    /// use nalgebra::DVector;
    /// use seqsmooth::model::observation::{LinearObservation, Observation};
    /// let m = LinearObservation::value_of(2);
    /// assert_eq!(m.value(&DVector::from_vec(vec![3.0, 4.0]), 0.0).unwrap()[0], 3.0);
    /// ```
    fn value(&self, state: &DVector<f64>, t: f64) -> Result<DVector<f64>, Error> {
        Ok(self.predict(state, t)?.value)
    }

    /// The residual of component `component`, `measured − predicted` (an angle's wrapped to
    /// `(−π, π]`).
    fn residual(&self, component: usize, measured: f64, predicted: f64) -> f64 {
        let _ = component;
        measured - predicted
    }

    /// The constant `M` of `G(X) = M X` when this is a [`LinearObservation`] (residuals
    /// `measured − predicted`): the Kalman filter then reads `M` in place rather than through
    /// [`Observation::predict_into`] (the same numbers). `None` unless the model says so.
    ///
    /// ```
    /// use seqsmooth::model::observation::{LinearObservation, Observation};
    /// let m = LinearObservation::value_of(2);
    /// assert_eq!(m.linear_matrix(), Some(m.matrix()));
    /// ```
    fn linear_matrix(&self) -> Option<&DMatrix<f64>> {
        None
    }

    /// The model as a [`Radar`](super::radar::Radar), if it is one: the Kalman filter then
    /// takes its fixed-size radar update (the same numbers), without being asked. `None`
    /// unless the model says so.
    ///
    /// ```
    /// use seqsmooth::model::observation::{LinearObservation, Observation};
    /// use seqsmooth::model::radar::Radar;
    /// assert!(Radar::new([0.0; 3], 6).unwrap().as_radar().is_some());
    /// assert!(LinearObservation::value_of(2).as_radar().is_none());
    /// ```
    fn as_radar(&self) -> Option<&super::radar::Radar> {
        None
    }
}

impl<O: Observation + ?Sized> Observation for &O {
    fn components(&self) -> usize {
        (**self).components()
    }
    fn state_dimension(&self) -> usize {
        (**self).state_dimension()
    }
    fn predict(&self, state: &DVector<f64>, t: f64) -> Result<Predicted, Error> {
        (**self).predict(state, t)
    }
    fn is_linear(&self) -> bool {
        (**self).is_linear()
    }
    fn predict_into(
        &self,
        state: &DVector<f64>,
        t: f64,
        value: &mut DVector<f64>,
        jacobian: &mut DMatrix<f64>,
    ) -> Result<(), Error> {
        (**self).predict_into(state, t, value, jacobian)
    }
    fn value(&self, state: &DVector<f64>, t: f64) -> Result<DVector<f64>, Error> {
        (**self).value(state, t)
    }
    fn residual(&self, component: usize, measured: f64, predicted: f64) -> f64 {
        (**self).residual(component, measured, predicted)
    }
    fn linear_matrix(&self) -> Option<&DMatrix<f64>> {
        (**self).linear_matrix()
    }
    fn as_radar(&self) -> Option<&super::radar::Radar> {
        (**self).as_radar()
    }
}

/// Refuses a state of the wrong length or with a non-finite entry.
pub(crate) fn check_state(n: usize, state: &DVector<f64>) -> Result<(), Error> {
    if state.len() != n {
        return Err(Error::InvalidParameter {
            name: Param::State,
            value: format!("of length {}", state.len()),
            reason: format!("the observation model needs {n} states"),
        });
    }
    match state.as_slice().iter().find(|v| !v.is_finite()) {
        Some(&value) => Err(Error::NonFinite {
            what: "state entry",
            value,
        }),
        None => Ok(()),
    }
}

/// Which of an observation's components are angles: their residuals `measured − predicted`
/// are wrapped to `(−π, π]` ([`wrap`], as [`super::radar::Radar`]'s azimuth), so that a
/// measured 179° against a predicted −179° is a residual of −2°, not 358°. What a model of
/// the caller's own ([`Observation::residual`]) gives for its angle components.
///
/// ```
/// use seqsmooth::model::observation::Angles;
/// let a = Angles::new(2, &[1]).unwrap();
/// assert_eq!(a.residual(0, 3.0, 1.0), 2.0);
/// assert!((a.residual(1, 3.1, -3.1) - (6.2 - std::f64::consts::TAU)).abs() < 1e-15);
/// assert!(Angles::new(2, &[2]).is_err()); // no component 2
/// ```
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Angles {
    is_angle: Vec<bool>,
}

impl Angles {
    /// The components `indices` (each below `components`, none twice) of a `components`-long
    /// observation are angles, in radians.
    pub fn new(components: usize, indices: &[usize]) -> Result<Self, Error> {
        let mut is_angle = vec![false; components];
        for &i in indices {
            if i >= components || is_angle[i] {
                return Err(Error::InvalidParameter {
                    name: Param::AngleComponents,
                    value: format!("{indices:?}"),
                    reason: format!(
                        "each must be a distinct component below {components}, the observation's count"
                    ),
                });
            }
            is_angle[i] = true;
        }
        Ok(Self { is_angle })
    }

    /// The observation's components (angles or not).
    ///
    /// ```
    /// use seqsmooth::model::observation::Angles;
    /// assert_eq!(Angles::new(3, &[1]).unwrap().components(), 3);
    /// ```
    pub fn components(&self) -> usize {
        self.is_angle.len()
    }

    /// The components that are angles, in order.
    ///
    /// ```
    /// use seqsmooth::model::observation::Angles;
    /// assert_eq!(Angles::new(3, &[2, 0]).unwrap().indices(), vec![0, 2]);
    /// ```
    pub fn indices(&self) -> Vec<usize> {
        (0..self.is_angle.len())
            .filter(|&c| self.is_angle[c])
            .collect()
    }

    /// Whether component `c` is an angle.
    ///
    /// ```
    /// use seqsmooth::model::observation::Angles;
    /// assert!(Angles::new(3, &[0, 2]).unwrap().is_angle(2));
    /// ```
    pub fn is_angle(&self, c: usize) -> bool {
        self.is_angle.get(c).copied().unwrap_or(false)
    }

    /// `measured − predicted`, wrapped to `(−π, π]` for an angle component.
    pub fn residual(&self, component: usize, measured: f64, predicted: f64) -> f64 {
        if self.is_angle(component) {
            wrap(measured - predicted)
        } else {
            measured - predicted
        }
    }
}

/// `Y = M X + N` with a constant `M` (8.2.2).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LinearObservation {
    m: DMatrix<f64>,
}

impl LinearObservation {
    /// `M`: components × states, finite, not empty.
    ///
    /// ```
    /// use nalgebra::DMatrix;
    /// use seqsmooth::model::observation::LinearObservation;
    /// assert!(LinearObservation::new(DMatrix::from_row_slice(1, 1, &[f64::NAN])).is_err());
    /// ```
    pub fn new(m: DMatrix<f64>) -> Result<Self, Error> {
        if m.is_empty() {
            return Err(Error::InvalidParameter {
                name: Param::ObservationMatrixM,
                value: format!("{}x{}", m.nrows(), m.ncols()),
                reason: "must not be empty".into(),
            });
        }
        if let Some(&value) = m.iter().find(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "observation matrix entry",
                value,
            });
        }
        Ok(Self { m })
    }

    /// The first component of a polynomial state: `M = (1, 0, …, 0)` (8.3.5).
    ///
    /// ```
    /// use seqsmooth::model::observation::{LinearObservation, Observation};
    /// assert_eq!(LinearObservation::value_of(3).state_dimension(), 3);
    /// ```
    pub fn value_of(states: usize) -> Self {
        let mut m = DMatrix::zeros(1, states.max(1));
        m[(0, 0)] = 1.0;
        Self { m }
    }

    /// `M`.
    ///
    /// ```
    /// use seqsmooth::model::observation::LinearObservation;
    /// assert_eq!(LinearObservation::value_of(2).matrix()[(0, 0)], 1.0);
    /// ```
    pub fn matrix(&self) -> &DMatrix<f64> {
        &self.m
    }
}

/// `M X` into `value` (`p`), each row's sum over the columns in order: [`LinearObservation`]'s
/// prediction, and the Kalman filter's where it reads `M` in place.
#[inline]
pub(crate) fn linear_value(m: &DMatrix<f64>, x: &[f64], value: &mut [f64]) {
    let (p, n) = m.shape();
    let m = m.as_slice();
    for (r, v) in value[..p].iter_mut().enumerate() {
        *v = (0..n).map(|c| m[r + c * p] * x[c]).sum();
    }
}

impl Observation for LinearObservation {
    fn linear_matrix(&self) -> Option<&DMatrix<f64>> {
        Some(&self.m)
    }
    fn is_linear(&self) -> bool {
        true
    }
    fn components(&self) -> usize {
        self.m.nrows()
    }
    fn state_dimension(&self) -> usize {
        self.m.ncols()
    }
    fn predict(&self, state: &DVector<f64>, _t: f64) -> Result<Predicted, Error> {
        check_state(self.m.ncols(), state)?;
        let value = &self.m * state;
        match value.iter().find(|v| !v.is_finite()) {
            Some(&v) => Err(Error::NonFinite {
                what: "predicted observation",
                value: v,
            }),
            None => Ok(Predicted {
                value,
                jacobian: self.m.clone(),
            }),
        }
    }

    /// `M X` and `M` into the caller's buffers, allocating nothing when they have the right
    /// shapes.
    fn predict_into(
        &self,
        state: &DVector<f64>,
        _t: f64,
        value: &mut DVector<f64>,
        jacobian: &mut DMatrix<f64>,
    ) -> Result<(), Error> {
        let (p, n) = self.m.shape();
        check_state(n, state)?;
        if value.len() != p {
            *value = DVector::zeros(p);
        }
        linear_value(&self.m, state.as_slice(), value.as_mut_slice());
        if let Some(&v) = value.iter().find(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "predicted observation",
                value: v,
            });
        }
        if jacobian.shape() == self.m.shape() {
            jacobian.as_mut_slice().copy_from_slice(self.m.as_slice());
        } else {
            *jacobian = self.m.clone();
        }
        Ok(())
    }
}

type Map = Arc<dyn Fn(f64, &DVector<f64>) -> DVector<f64> + Send + Sync>;
type MapJacobian = Arc<dyn Fn(f64, &DVector<f64>) -> DMatrix<f64> + Send + Sync>;

/// `Y = G(X, t) + N` with the caller's `G` (and `M = ∂G/∂X` if given, else central
/// differences with the step rule of [`super::nonlinear`]).
///
/// ```
/// use nalgebra::DVector;
/// use seqsmooth::model::observation::{NonlinearObservation, Observation};
/// // Morrison Ex. 11.1: the range sqrt(d² + x²) of a body at x from a sensor at distance d = 3.
/// let range = NonlinearObservation::new(1, 1, |_t, x: &DVector<f64>| DVector::from_vec(vec![(9.0 + x[0] * x[0]).sqrt()]));
/// let p = range.predict(&DVector::from_vec(vec![4.0]), 0.0).unwrap();
/// assert_eq!(p.value[0], 5.0);
/// assert!((p.jacobian[(0, 0)] - 0.8).abs() < 1e-9); // m(x) = x/sqrt(d² + x²)
/// ```
#[derive(Clone)]
pub struct NonlinearObservation {
    components: usize,
    states: usize,
    map: Map,
    jacobian: Option<MapJacobian>,
}

impl std::fmt::Debug for NonlinearObservation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NonlinearObservation")
            .field("components", &self.components)
            .field("states", &self.states)
            .field("analytic_jacobian", &self.jacobian.is_some())
            .finish()
    }
}

impl NonlinearObservation {
    /// `components` numbers `G(t, X)` from `states` states.
    ///
    /// ```
    /// use nalgebra::DVector;
    /// use seqsmooth::model::observation::{NonlinearObservation, Observation};
    /// let g = NonlinearObservation::new(2, 1, |_t, x: &DVector<f64>| DVector::from_vec(vec![x[0], x[0] * x[0]]));
    /// assert_eq!(g.components(), 2);
    /// ```
    pub fn new<G>(components: usize, states: usize, map: G) -> Self
    where
        G: Fn(f64, &DVector<f64>) -> DVector<f64> + Send + Sync + 'static,
    {
        Self {
            components,
            states,
            map: Arc::new(map),
            jacobian: None,
        }
    }

    /// With the analytic `M = ∂G/∂X` (components × states).
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::model::observation::{NonlinearObservation, Observation};
    /// let g = NonlinearObservation::new(1, 1, |_t, x: &DVector<f64>| x.map(f64::sin))
    ///     .with_jacobian(|_t, x: &DVector<f64>| DMatrix::from_element(1, 1, x[0].cos()));
    /// assert_eq!(g.predict(&DVector::from_vec(vec![0.0]), 0.0).unwrap().jacobian[(0, 0)], 1.0);
    /// ```
    pub fn with_jacobian<J>(mut self, jacobian: J) -> Self
    where
        J: Fn(f64, &DVector<f64>) -> DMatrix<f64> + Send + Sync + 'static,
    {
        self.jacobian = Some(Arc::new(jacobian));
        self
    }

    fn value_at(&self, t: f64, x: &DVector<f64>) -> Option<DVector<f64>> {
        let g = (self.map)(t, x);
        (g.len() == self.components && g.iter().all(|v| v.is_finite())).then_some(g)
    }
}

impl Observation for NonlinearObservation {
    fn components(&self) -> usize {
        self.components
    }
    fn state_dimension(&self) -> usize {
        self.states
    }
    /// `G(X, t)` without differencing `M` (`2n` evaluations fewer).
    fn value(&self, state: &DVector<f64>, t: f64) -> Result<DVector<f64>, Error> {
        check_state(self.states, state)?;
        self.value_at(t, state)
            .ok_or_else(|| Error::InvalidParameter {
                name: Param::ObservationModel,
                value: format!("at t = {t}"),
                reason: format!(
                    "G(X, t) has a non-finite entry or is not {} long",
                    self.components
                ),
            })
    }
    fn predict(&self, state: &DVector<f64>, t: f64) -> Result<Predicted, Error> {
        check_state(self.states, state)?;
        let refuse = || Error::InvalidParameter {
            name: Param::ObservationModel,
            value: format!("at t = {t}"),
            reason: format!(
                "G(X, t) or its Jacobian has a non-finite entry or is not {} x {}",
                self.components, self.states
            ),
        };
        let value = self.value_at(t, state).ok_or_else(refuse)?;
        let jacobian = match &self.jacobian {
            Some(j) => Some(j(t, state)).filter(|j| {
                j.shape() == (self.components, self.states) && j.iter().all(|v| v.is_finite())
            }),
            None => central_differences(self.components, state, |x| self.value_at(t, x)),
        }
        .ok_or_else(refuse)?;
        Ok(Predicted { value, jacobian })
    }
}
