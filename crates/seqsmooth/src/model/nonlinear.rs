//! Nonlinear dynamics `dX/dt = F(X, t)` and time-varying linear dynamics `dX/dt = A(t) X`
//! (Morrison §4.7, §8.4, §8.6): the trajectory through a state and its transition matrix from
//! the variational equations
//!
//! `dX/dt = F(X, t)`, `dΦ(t, t_a)/dt = A(X(t), t) Φ(t, t_a)`, `Φ(t_a, t_a) = I`,
//! `A = ∂F/∂X` ((8.6.3)-(8.6.7), (8.6.28)-(8.6.29)),
//!
//! integrated together, forwards or backwards, by the embedded Runge–Kutta pair of Dormand and
//! Prince of order 8(5,3) with step-size control (`ode_solvers::Dop853`, Hairer, Nørsett and
//! Wanner's DOP853). The error control covers `Φ` as well as `X`. Time is integrated from zero
//! (`ζ = t − t_a`), so that Unix-epoch times lose no digits to the step-size control; a
//! time-varying `F` is still handed the absolute time `t_a + ζ`, which near `t = 1.7e9` is
//! resolved to `ulp(t) ≈ 2.4e-7` only: an `F` that needs finer time should be written in time
//! from a nearer origin.
//!
//! The Jacobian's step rule assumes states of order one or more: for components much smaller
//! than one the differenced Jacobian's relative error grows as `(h/|x|)²` (2.7e-8 at
//! `|x| = 0.01`); give the analytic Jacobian, or scale the state.
//!
//! The Jacobian `∂F/∂X` is the caller's when given; otherwise central differences with the step
//! `h_j = ε^{1/3} max(|x_j|, 1)` (rounded so that `x_j ± h_j` are exact), whose error is
//! `O(ε^{2/3}) ≈ 4e-11` relative for a smooth `F` of unit scale.

use super::dynamics::{check_propagation, Dynamics, Propagation};
use crate::error::{Error, Param};
use nalgebra::{DMatrix, DVector};
use ode_solvers::{Dop853, OutputType, System};
use std::cell::Cell;
use std::rc::Rc;
use std::sync::Arc;

type Field = Arc<dyn Fn(f64, &DVector<f64>) -> DVector<f64> + Send + Sync>;
type Jacobian = Arc<dyn Fn(f64, &DVector<f64>) -> DMatrix<f64> + Send + Sync>;

/// `dX/dt = F(X, t)` with `n` states.
///
/// ```
/// use nalgebra::DVector;
/// use seqsmooth::model::dynamics::Dynamics;
/// use seqsmooth::model::nonlinear::NonlinearDynamics;
/// // Morrison Ex. 11.14: ẍ = −k ẋ², X = (x, ẋ); with k = 0.5 and ẋ(0) = 2, ẋ(t) = 2/(1 + t).
/// let k = 0.5;
/// let drag = NonlinearDynamics::new(2, move |_t, x: &DVector<f64>| DVector::from_vec(vec![x[1], -k * x[1] * x[1]]));
/// let p = drag.propagate(&DVector::from_vec(vec![0.0, 2.0]), 0.0, 1.0).unwrap();
/// assert!((p.state[1] - 1.0).abs() < 1e-9);
/// assert!((p.state[0] - 2.0 * 2.0_f64.ln()).abs() < 1e-9); // (1/k) ln(1 + k ẋ₀ t)
/// ```
#[derive(Clone)]
pub struct NonlinearDynamics {
    n: usize,
    field: Field,
    jacobian: Option<Jacobian>,
    relative_tolerance: f64,
    absolute_tolerance: f64,
    /// `F = A(t) X` ([`NonlinearDynamics::time_varying_linear`]): `Φ` is the same for every
    /// state.
    linear: bool,
}

impl std::fmt::Debug for NonlinearDynamics {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NonlinearDynamics")
            .field("n", &self.n)
            .field("analytic_jacobian", &self.jacobian.is_some())
            .field("relative_tolerance", &self.relative_tolerance)
            .field("absolute_tolerance", &self.absolute_tolerance)
            .finish()
    }
}

impl NonlinearDynamics {
    /// `dX/dt = F(t, X)`, the Jacobian by central differences; tolerances 1e-10 relative and
    /// 1e-12 absolute per component.
    ///
    /// ```
    /// use nalgebra::DVector;
    /// use seqsmooth::model::dynamics::Dynamics;
    /// use seqsmooth::model::nonlinear::NonlinearDynamics;
    /// let growth = NonlinearDynamics::new(1, |_t, x: &DVector<f64>| x.clone());
    /// let p = growth.propagate(&DVector::from_vec(vec![1.0]), 0.0, 1.0).unwrap();
    /// assert!((p.transition[(0, 0)] - std::f64::consts::E).abs() < 1e-9);
    /// ```
    pub fn new<F>(n: usize, field: F) -> Self
    where
        F: Fn(f64, &DVector<f64>) -> DVector<f64> + Send + Sync + 'static,
    {
        Self {
            n,
            field: Arc::new(field),
            jacobian: None,
            relative_tolerance: 1e-10,
            absolute_tolerance: 1e-12,
            linear: false,
        }
    }

    /// `dX/dt = A(t) X`: `F = A(t) X`, `∂F/∂X = A(t)` exactly; linear
    /// ([`Dynamics::is_linear`]), so the Bayes filter and the estimators' cached `Φ` apply.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::model::dynamics::Dynamics;
    /// use seqsmooth::model::nonlinear::NonlinearDynamics;
    /// // ẋ = t x: Φ(t, 0) = e^{t²/2}.
    /// let d = NonlinearDynamics::time_varying_linear(1, |t| DMatrix::from_element(1, 1, t));
    /// let p = d.propagate(&DVector::from_vec(vec![1.0]), 0.0, 2.0).unwrap();
    /// assert!((p.transition[(0, 0)] / 2.0_f64.exp() - 1.0).abs() < 1e-9);
    /// assert!(d.is_linear());
    /// ```
    pub fn time_varying_linear<A>(n: usize, a: A) -> Self
    where
        A: Fn(f64) -> DMatrix<f64> + Send + Sync + 'static,
    {
        let a = Arc::new(a);
        let field_a = Arc::clone(&a);
        let mut d = Self::new(n, move |t, x: &DVector<f64>| {
            let m = field_a(t);
            if m.shape() == (x.len(), x.len()) {
                m * x
            } else {
                DVector::from_element(x.len(), f64::NAN)
            }
        });
        d.jacobian = Some(Arc::new(move |t, _x: &DVector<f64>| a(t)));
        d.linear = true;
        d
    }

    /// With the analytic Jacobian `∂F/∂X (t, X)` (an `n × n` matrix).
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::model::nonlinear::NonlinearDynamics;
    /// let d = NonlinearDynamics::new(1, |_t, x: &DVector<f64>| x.map(|v| v * v))
    ///     .with_jacobian(|_t, x: &DVector<f64>| DMatrix::from_element(1, 1, 2.0 * x[0]));
    /// assert!(d.has_jacobian());
    /// ```
    pub fn with_jacobian<J>(mut self, jacobian: J) -> Self
    where
        J: Fn(f64, &DVector<f64>) -> DMatrix<f64> + Send + Sync + 'static,
    {
        self.jacobian = Some(Arc::new(jacobian));
        self
    }

    /// Whether the Jacobian is the caller's (else central differences).
    ///
    /// ```
    /// use nalgebra::DVector;
    /// use seqsmooth::model::nonlinear::NonlinearDynamics;
    /// assert!(!NonlinearDynamics::new(1, |_t, x: &DVector<f64>| x.clone()).has_jacobian());
    /// ```
    pub fn has_jacobian(&self) -> bool {
        self.jacobian.is_some()
    }

    /// The integrator's relative and absolute tolerances (each positive and finite).
    ///
    /// ```
    /// use nalgebra::DVector;
    /// use seqsmooth::model::nonlinear::NonlinearDynamics;
    /// let d = NonlinearDynamics::new(1, |_t, x: &DVector<f64>| x.clone());
    /// assert!(d.clone().with_tolerances(1e-8, 1e-9).is_ok());
    /// assert!(d.with_tolerances(0.0, 1e-9).is_err());
    /// ```
    pub fn with_tolerances(mut self, relative: f64, absolute: f64) -> Result<Self, Error> {
        for (name, v) in [
            (Param::RelativeTolerance, relative),
            (Param::AbsoluteTolerance, absolute),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::InvalidParameter {
                    name,
                    value: v.to_string(),
                    reason: "must be positive and finite".into(),
                });
            }
        }
        self.relative_tolerance = relative;
        self.absolute_tolerance = absolute;
        Ok(self)
    }

    /// `F(t, X)`, refused unless it has `n` finite entries.
    fn field_at(&self, t: f64, x: &DVector<f64>) -> Option<DVector<f64>> {
        let f = (self.field)(t, x);
        (f.len() == self.n && f.iter().all(|v| v.is_finite())).then_some(f)
    }

    /// `∂F/∂X (t, X)`: the caller's, or central differences.
    pub(crate) fn jacobian_at(&self, t: f64, x: &DVector<f64>) -> Option<DMatrix<f64>> {
        let n = self.n;
        if let Some(j) = &self.jacobian {
            let j = j(t, x);
            return (j.shape() == (n, n) && j.iter().all(|v| v.is_finite())).then_some(j);
        }
        central_differences(n, x, |probe| self.field_at(t, probe))
    }
}

/// `∂f/∂x` of an `rows`-valued `f` by central differences, `h_j = ε^{1/3} max(|x_j|, 1)`
/// rounded so that `x_j ± h_j` are exact; `None` when `f` gives `None` anywhere.
pub(crate) fn central_differences(
    rows: usize,
    x: &DVector<f64>,
    f: impl Fn(&DVector<f64>) -> Option<DVector<f64>>,
) -> Option<DMatrix<f64>> {
    differenced_jacobian(rows, x, |probe| f(probe).ok_or(())).ok()
}

/// The library's differencing rule for a Jacobian `∂f/∂x` (`rows × n`) that the caller does
/// not give: central differences `(f(x + h_j e_j) − f(x − h_j e_j)) / 2h_j` with the step
/// `h_j = ε^{1/3} max(|x_j|, 1)` rounded so that `x_j ± h_j` are exact (error `O(ε^{2/3})`
/// relative for a smooth `f` of unit scale; Morrison §8.6's `M` and `Φ` when no closed form
/// is at hand). `f`'s first error is returned as it is; a value that has not `rows` entries
/// makes its column NaN (never a panic), for the caller's finiteness check to refuse.
///
/// ```
/// use nalgebra::DVector;
/// use seqsmooth::model::nonlinear::differenced_jacobian;
/// let x = DVector::from_vec(vec![2.0, 3.0]);
/// let j = differenced_jacobian(1, &x, |p| Ok::<_, ()>(DVector::from_vec(vec![p[0] * p[1]]))).unwrap();
/// assert!((j[(0, 0)] - 3.0).abs() < 1e-9 && (j[(0, 1)] - 2.0).abs() < 1e-9);
/// ```
pub fn differenced_jacobian<E>(
    rows: usize,
    x: &DVector<f64>,
    f: impl FnMut(&DVector<f64>) -> Result<DVector<f64>, E>,
) -> Result<DMatrix<f64>, E> {
    differenced_jacobian_with(rows, x, f, |_, up, down| up - down)
}

/// [`differenced_jacobian`] with the difference of row `r`'s two values given by
/// `difference(r, up, down)`: for an angle, the wrapped one
/// ([`super::observation::Angles::residual`]), so that a probe across the branch cut at ±π
/// gives the angle's small change, not `±2π` over the step.
///
/// ```
/// use nalgebra::DVector;
/// use seqsmooth::model::nonlinear::differenced_jacobian_with;
/// use seqsmooth::model::observation::Angles;
/// // The bearing atan2(y, x) at (−1, 0), on the cut: ∂/∂y = x / (x² + y²) = −1.
/// let bearing = |p: &DVector<f64>| Ok::<_, ()>(DVector::from_vec(vec![p[1].atan2(p[0])]));
/// let angles = Angles::new(1, &[0]).unwrap();
/// let x = DVector::from_vec(vec![-1.0, 0.0]);
/// let j = differenced_jacobian_with(1, &x, bearing, |c, a, b| angles.residual(c, a, b)).unwrap();
/// assert!((j[(0, 1)] + 1.0).abs() < 1e-9);
/// ```
pub fn differenced_jacobian_with<E>(
    rows: usize,
    x: &DVector<f64>,
    mut f: impl FnMut(&DVector<f64>) -> Result<DVector<f64>, E>,
    difference: impl Fn(usize, f64, f64) -> f64,
) -> Result<DMatrix<f64>, E> {
    let step = f64::EPSILON.cbrt();
    let mut out = DMatrix::zeros(rows, x.len());
    let mut probe = x.clone();
    for c in 0..x.len() {
        let xc = x[c];
        let h = (xc + step * xc.abs().max(1.0)) - xc;
        probe[c] = xc + h;
        let up = f(&probe)?;
        probe[c] = xc - h;
        let down = f(&probe)?;
        probe[c] = xc;
        if up.len() == rows && down.len() == rows {
            for r in 0..rows {
                out[(r, c)] = difference(r, up[r], down[r]) / (2.0 * h);
            }
        } else {
            out.column_mut(c).fill(f64::NAN);
        }
    }
    Ok(out)
}

/// The state, `Φ` (by columns) and the time offset `ζ` side by side (`n + n² + 1` numbers) for
/// the integrator. `F` is given the time carried in the last component, not the integrator's
/// stage time: ode_solvers 0.6.2's DOP853 evaluates its twelfth stage at `c₁₂ = 0` instead of 1
/// (its `a` coefficients are right), which corrupts every `F` that depends on `t`; the carried
/// `ζ` (`dζ/dζ = 1`, integrated exactly) has each stage's true time.
/// Without `transition`, the state and `ζ` only (`n + 1` numbers): the trajectory alone, for a
/// caller that needs no `Φ` ([`Dynamics::propagate_state`]: the unscented filter's sigma
/// points), without the `n` (or `2n` differenced) extra evaluations of `F` per stage.
struct Variational<'a> {
    model: &'a NonlinearDynamics,
    t_a: f64,
    transition: bool,
    failed: Rc<Cell<Option<f64>>>,
}

impl System<f64, DVector<f64>> for Variational<'_> {
    fn system(&self, _zeta: f64, y: &DVector<f64>, dy: &mut DVector<f64>) {
        let n = self.model.n;
        let m = if self.transition { n * n } else { 0 };
        let t = self.t_a + y[n + m];
        let x = y.rows(0, n).into_owned();
        let fail = |dy: &mut DVector<f64>| {
            self.failed.set(Some(t));
            dy.fill(0.0);
        };
        let Some(f) = self.model.field_at(t, &x) else {
            return fail(dy);
        };
        dy.rows_mut(0, n).copy_from(&f);
        if self.transition {
            let Some(a) = self.model.jacobian_at(t, &x) else {
                return fail(dy);
            };
            let phi = DMatrix::from_column_slice(n, n, &y.as_slice()[n..n + m]);
            let dphi = a * phi;
            dy.rows_mut(n, m).copy_from_slice(dphi.as_slice());
        }
        dy[n + m] = 1.0;
    }

    fn solout(&mut self, _x: f64, _y: &DVector<f64>, _dy: &DVector<f64>) -> bool {
        self.failed.get().is_some()
    }
}

impl Dynamics for NonlinearDynamics {
    fn dimension(&self) -> usize {
        self.n
    }

    fn is_linear(&self) -> bool {
        self.linear
    }

    fn propagate(&self, state: &DVector<f64>, t_a: f64, t_b: f64) -> Result<Propagation, Error> {
        let (state, transition) = self.integrate(state, t_a, t_b, true)?;
        Ok(Propagation {
            state,
            transition: transition.expect("integrated with the transition"),
        })
    }

    /// The trajectory alone (no variational equations): `X(t_b)` within the same tolerances.
    fn propagate_state(
        &self,
        state: &DVector<f64>,
        t_a: f64,
        t_b: f64,
    ) -> Result<DVector<f64>, Error> {
        Ok(self.integrate(state, t_a, t_b, false)?.0)
    }
}

impl NonlinearDynamics {
    /// `X(t_b)` from `X(t_a)` and, with `transition`, `Φ(t_b, t_a)` from the variational
    /// equations integrated alongside (the error control covering both).
    fn integrate(
        &self,
        state: &DVector<f64>,
        t_a: f64,
        t_b: f64,
        transition: bool,
    ) -> Result<(DVector<f64>, Option<DMatrix<f64>>), Error> {
        let n = self.n;
        check_propagation(n, state, t_a, t_b)?;
        let m = if transition { n * n } else { 0 };
        let span = t_b - t_a;
        if span == 0.0 {
            if self.field_at(t_a, state).is_none() {
                return Err(non_finite_field(t_a));
            }
            return Ok((state.clone(), transition.then(|| DMatrix::identity(n, n))));
        }
        let mut y0 = DVector::zeros(n + m + 1);
        y0.rows_mut(0, n).copy_from(state);
        if transition {
            for k in 0..n {
                y0[n + k * n + k] = 1.0;
            }
        }
        let failed = Rc::new(Cell::new(None));
        let system = Variational {
            model: self,
            t_a,
            transition,
            failed: Rc::clone(&failed),
        };
        let mut solver = Dop853::from_param(
            system,
            0.0,
            span,
            span,
            y0,
            self.relative_tolerance,
            self.absolute_tolerance,
            0.9,
            0.0,
            0.333,
            6.0,
            span,
            0.0,
            100_000,
            1000,
            OutputType::Sparse,
        );
        let outcome = solver.integrate();
        if let Some(t) = failed.get() {
            return Err(non_finite_field(t));
        }
        let last = solver.y_out().last().cloned();
        let reached = solver.x_out().last().copied().unwrap_or(0.0);
        if let Err(e) = outcome {
            return Err(Error::InvalidParameter {
                name: Param::Dynamics,
                value: format!("integrated from t = {t_a} to t = {t_b}"),
                reason: format!("the integrator failed: {e}"),
            });
        }
        let y = match last {
            Some(y)
                if (reached - span).abs() <= 1e-9 * span.abs()
                    && y.iter().all(|v| v.is_finite()) =>
            {
                y
            }
            _ => return Err(non_finite_field(t_a + reached)),
        };
        Ok((
            y.rows(0, n).into_owned(),
            transition.then(|| DMatrix::from_column_slice(n, n, &y.as_slice()[n..n + m])),
        ))
    }
}

fn non_finite_field(t: f64) -> Error {
    Error::InvalidParameter {
        name: Param::Dynamics,
        value: format!("at t = {t}"),
        reason: "F(X, t) or its Jacobian has a non-finite entry or the wrong size there".into(),
    }
}
