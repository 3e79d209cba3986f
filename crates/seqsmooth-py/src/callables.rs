//! The user's own nonlinear model from Python: the library's [`Dynamics`], [`Observation`] and
//! [`ProcessNoise`] traits over Python callables — a state transition `f(x, t0, t1) -> x1`
//! and its optional Jacobian `F_jacobian(x, t0, t1) -> Φ`, an observation `h(x, t) -> z` and
//! its optional Jacobian `H_jacobian(x, t) -> M`, `Q` constant or `Q(t0, t1)` — with the
//! library's differencing rule (`model::nonlinear::differenced_jacobian`) for a Jacobian not
//! given and its angle rule (`model::observation::Angles`) for the residuals; and the class
//! `ExtendedKalmanFilter` over them (the library's `kalman::KalmanFilter`, its iterated update
//! and its Rauch–Tung–Striebel smoother). `UnscentedKalmanFilter` takes the same callables
//! ([`crate::unscented`]).
//!
//! Every call takes the GIL, hands the state as a fresh `float64` array and reads the result
//! back; an exception, a result of the wrong shape or with a NaN or infinity becomes the
//! library's typed error naming the callable (its keyword, `Param`) and the time, and the
//! filter refuses the update and stays as it was. Inside `update_many` the error also names
//! the measurement's index.

use crate::arrays::matrix;
use crate::errors::{raise, IntoPy, Kind};
use crate::fixed_lag::lagged;
use crate::kalman::{before, measurement, measurements, out_of_order, square, PyInnovation};
use crate::persist;
use nalgebra::{DMatrix, DVector};
use numpy::{PyArray1, PyArrayDyn, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use seqsmooth::error::Param;
use seqsmooth::kalman::filter::IterationLimits;
use seqsmooth::kalman::noise::{check_covariance, MatrixNoise, ProcessNoise};
use seqsmooth::kalman::saved_noise::SavedNoise;
use seqsmooth::kalman::{smoother, FixedLagSmoother, KalmanFilter};
use seqsmooth::model::dynamics::{Dynamics, Propagation};
use seqsmooth::model::measurement::Measurement;
use seqsmooth::model::nonlinear::{
    differenced_jacobian, differenced_jacobian_with, NonlinearDynamics,
};
use seqsmooth::model::observation::{Angles, Observation, Predicted};
use seqsmooth::persist::{DynamicsLeftOut, ObservationLeftOut};
use seqsmooth::Error;
use std::sync::{Arc, Mutex};

/// The first exception a model's callables raised since the last call of the filter, kept to
/// be the `__cause__` of the error that refuses the update.
#[derive(Clone, Debug, Default)]
pub(crate) struct Raised(Arc<Mutex<Option<PyErr>>>);

impl Raised {
    fn keep(&self, e: PyErr) {
        let mut slot = self.0.lock().unwrap_or_else(|p| p.into_inner());
        slot.get_or_insert(e);
    }

    fn take(&self) -> Option<PyErr> {
        self.0.lock().unwrap_or_else(|p| p.into_inner()).take()
    }

    /// `result` of one call of the filter as Python's: its error the library's, with the
    /// exception a callable raised (if any) as its cause; the slot emptied either way.
    pub(crate) fn py<T>(&self, result: Result<T, Error>) -> PyResult<T> {
        let kept = self.take();
        result.py().inspect_err(|err| {
            if let Some(cause) = kept {
                Python::attach(|py| err.set_cause(py, Some(cause)));
            }
        })
    }
}

/// A Python callable of the user's model, named in errors by its parameter.
#[derive(Clone)]
pub(crate) struct Callable {
    func: Arc<Py<PyAny>>,
    param: Param,
    raised: Raised,
}

impl std::fmt::Debug for Callable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Callable({})", self.param)
    }
}

impl Callable {
    /// `obj`, refused unless callable.
    fn new(obj: &Bound<'_, PyAny>, param: Param, keyword: &str, raised: &Raised) -> PyResult<Self> {
        if !obj.is_callable() {
            return Err(raise(
                Kind::InvalidType,
                format!("{keyword} must be callable"),
                None,
            ));
        }
        Ok(Self {
            func: Arc::new(obj.clone().unbind()),
            param,
            raised: raised.clone(),
        })
    }

    fn refuse(&self, at: String, reason: String) -> Error {
        Error::InvalidParameter {
            name: self.param,
            value: at,
            reason,
        }
    }

    /// The callable on `x` (if any) and the times, its result read as `rows × cols` in
    /// row-major order (`cols` `None`: a vector of `rows`, also `rows × 1` or a number for
    /// one row); `at` words the call's time in errors.
    fn call(
        &self,
        x: Option<&DVector<f64>>,
        times: &[f64],
        rows: usize,
        cols: Option<usize>,
        at: impl Fn() -> String,
    ) -> Result<Vec<f64>, Error> {
        Python::attach(|py| {
            let out = match (x, times) {
                (Some(x), [t]) => self
                    .func
                    .call1(py, (PyArray1::from_slice(py, x.as_slice()), *t)),
                (Some(x), [a, b]) => self
                    .func
                    .call1(py, (PyArray1::from_slice(py, x.as_slice()), *a, *b)),
                (_, [a, b]) => self.func.call1(py, (*a, *b)),
                _ => unreachable!("every call has a time or two"),
            };
            let out = out.map_err(|e| {
                let error = self.refuse(at(), format!("raised {e}"));
                self.raised.keep(e);
                error
            })?;
            read(out.bind(py), rows, cols).map_err(|reason| self.refuse(at(), reason))
        })
    }
}

/// A result as `rows × cols` numbers (row-major), or why not.
fn read(out: &Bound<'_, PyAny>, rows: usize, cols: Option<usize>) -> Result<Vec<f64>, String> {
    let converted;
    let array = match out.cast::<PyArrayDyn<f64>>() {
        Ok(a) => a,
        Err(_) => {
            let np = out.py().import("numpy").map_err(|e| e.to_string())?;
            converted = np
                .call_method1("asarray", (out, "float64"))
                .map_err(|e| format!("returned {}, not an array of numbers ({e})", kind(out)))?;
            converted
                .cast::<PyArrayDyn<f64>>()
                .map_err(|e| e.to_string())?
        }
    };
    // A copy in logical (row-major) order, whatever the strides (no borrow to register).
    let owned = array.to_owned_array();
    let shape = owned.shape().to_vec();
    let want_cols = cols.unwrap_or(1);
    let fits = match (shape.as_slice(), cols) {
        ([r, c], _) => *r == rows && *c == want_cols,
        ([r], None) => *r == rows,
        ([], None) => rows == 1,
        _ => false,
    };
    if !fits {
        let want = match cols {
            Some(c) => format!("({rows}, {c})"),
            None => format!("({rows},)"),
        };
        return Err(format!("returned shape {shape:?}, not {want}"));
    }
    let flat: Vec<f64> = match owned.as_slice() {
        Some(s) => s.to_vec(),
        None => owned.iter().copied().collect(),
    };
    if let Some(i) = flat.iter().position(|v| !v.is_finite()) {
        let (r, c) = (i / want_cols, i % want_cols);
        let entry = if cols.is_some() {
            format!("({r}, {c})")
        } else {
            r.to_string()
        };
        return Err(format!("returned {} at entry {entry}", flat[i]));
    }
    Ok(flat)
}

/// The Python type's name of `obj`, for an error.
fn kind(obj: &Bound<'_, PyAny>) -> String {
    obj.get_type()
        .name()
        .map_or_else(|_| "an object".into(), |n| n.to_string())
}

/// `X(t1) = f(X(t0), t0, t1)`, `Φ` the caller's `F_jacobian` or the library's differences;
/// or, with `ode`, `f` is `dxdt(x, t)` and the library integrates `dX/dt` and its variational
/// equations for `Φ` ([`NonlinearDynamics`], Morrison §8.6).
#[derive(Clone, Debug)]
pub(crate) struct UserDynamics {
    n: usize,
    f: Callable,
    jacobian: Option<Callable>,
    ode: Option<Ode>,
}

/// `dX/dt = dxdt(X, t)` integrated by the library, and the refusal of the user's callable
/// that stopped the last integration (the integrator only sees a NaN).
#[derive(Clone, Debug)]
pub(crate) struct Ode {
    dynamics: NonlinearDynamics,
    refused: Arc<Mutex<Option<Error>>>,
}

impl Ode {
    /// `dxdt(x, t)` (`n` values) and its optional Jacobian `dxdt_jacobian(x, t)` (`n × n`; by
    /// default the library's central differences of `dxdt`).
    fn new(n: usize, dxdt: &Callable, jacobian: Option<&Callable>) -> Self {
        let refused: Arc<Mutex<Option<Error>>> = Arc::default();
        let keep = |slot: &Arc<Mutex<Option<Error>>>, e: Error| {
            slot.lock()
                .unwrap_or_else(|p| p.into_inner())
                .get_or_insert(e);
        };
        let (f, slot) = (dxdt.clone(), Arc::clone(&refused));
        let mut dynamics = NonlinearDynamics::new(n, move |t, x: &DVector<f64>| {
            match f.call(Some(x), &[t], n, None, || format!("at t = {t}")) {
                Ok(v) => DVector::from_vec(v),
                Err(e) => {
                    keep(&slot, e);
                    DVector::from_element(n, f64::NAN)
                }
            }
        });
        if let Some(j) = jacobian {
            let (j, slot) = (j.clone(), Arc::clone(&refused));
            dynamics = dynamics.with_jacobian(move |t, x: &DVector<f64>| {
                match j.call(Some(x), &[t], n, Some(n), || format!("at t = {t}")) {
                    Ok(v) => DMatrix::from_row_slice(n, n, &v),
                    Err(e) => {
                        keep(&slot, e);
                        DMatrix::from_element(n, n, f64::NAN)
                    }
                }
            });
        }
        Self { dynamics, refused }
    }

    /// `integrate` on the library's dynamics; its failure the user's callable's refusal where
    /// one stopped it.
    fn run<T>(
        &self,
        integrate: impl FnOnce(&NonlinearDynamics) -> Result<T, Error>,
    ) -> Result<T, Error> {
        let slot = || {
            self.refused
                .lock()
                .unwrap_or_else(|p| p.into_inner())
                .take()
        };
        slot();
        integrate(&self.dynamics).map_err(|e| slot().unwrap_or(e))
    }
}

impl UserDynamics {
    fn transition_state(
        &self,
        x: &DVector<f64>,
        t_a: f64,
        t_b: f64,
    ) -> Result<DVector<f64>, Error> {
        let at = || format!("over t = {t_a} to {t_b}");
        let v = self.f.call(Some(x), &[t_a, t_b], self.n, None, at)?;
        Ok(DVector::from_vec(v))
    }
}

impl Dynamics for UserDynamics {
    fn dimension(&self) -> usize {
        self.n
    }

    fn propagate(&self, state: &DVector<f64>, t_a: f64, t_b: f64) -> Result<Propagation, Error> {
        if let Some(ode) = &self.ode {
            return ode.run(|d| d.propagate(state, t_a, t_b));
        }
        let n = self.n;
        let new_state = self.transition_state(state, t_a, t_b)?;
        let transition = match &self.jacobian {
            Some(j) => {
                let at = || format!("over t = {t_a} to {t_b}");
                DMatrix::from_row_slice(n, n, &j.call(Some(state), &[t_a, t_b], n, Some(n), at)?)
            }
            None => differenced_jacobian(n, state, |x| self.transition_state(x, t_a, t_b))?,
        };
        Ok(Propagation {
            state: new_state,
            transition,
        })
    }

    fn propagate_state(
        &self,
        state: &DVector<f64>,
        t_a: f64,
        t_b: f64,
    ) -> Result<DVector<f64>, Error> {
        match &self.ode {
            // The trajectory alone: no variational equations for a state the caller carries.
            Some(ode) => ode.run(|d| d.propagate_state(state, t_a, t_b)),
            None => self.transition_state(state, t_a, t_b),
        }
    }
}

/// `z = h(X, t)`, `M` the caller's `H_jacobian` or the library's differences; the `angles`
/// components' residuals wrapped.
#[derive(Clone, Debug)]
pub(crate) struct UserObservation {
    n: usize,
    p: usize,
    h: Callable,
    jacobian: Option<Callable>,
    angles: Angles,
}

impl Observation for UserObservation {
    fn components(&self) -> usize {
        self.p
    }

    fn state_dimension(&self) -> usize {
        self.n
    }

    fn predict(&self, state: &DVector<f64>, t: f64) -> Result<Predicted, Error> {
        let value = self.value(state, t)?;
        let jacobian = match &self.jacobian {
            Some(j) => {
                let at = || format!("at t = {t}");
                let m = j.call(Some(state), &[t], self.p, Some(self.n), at)?;
                DMatrix::from_row_slice(self.p, self.n, &m)
            }
            // An angle's differences wrapped: a probe across ±π changes it little.
            None => differenced_jacobian_with(
                self.p,
                state,
                |x| self.value(x, t),
                |c, up, down| self.angles.residual(c, up, down),
            )?,
        };
        Ok(Predicted { value, jacobian })
    }

    fn value(&self, state: &DVector<f64>, t: f64) -> Result<DVector<f64>, Error> {
        let v = self
            .h
            .call(Some(state), &[t], self.p, None, || format!("at t = {t}"))?;
        Ok(DVector::from_vec(v))
    }

    fn residual(&self, component: usize, measured: f64, predicted: f64) -> f64 {
        self.angles.residual(component, measured, predicted)
    }
}

/// `Q` over a step: one matrix for every step, or the caller's `Q(t0, t1)`, checked at every
/// call (`n × n`, finite, symmetric, non-negative variances).
#[derive(Clone, Debug)]
pub(crate) enum UserNoise {
    /// The library's constant `Q`, which has a saved form.
    Constant(MatrixNoise),
    Callable(Callable, usize),
}

/// Why `q` is not a driving-noise covariance by the library's rule
/// ([`check_covariance`]: symmetric, positive semidefinite), or `None`.
fn not_covariance(q: &DMatrix<f64>) -> Option<String> {
    match check_covariance(q, q.nrows(), Param::ProcessNoiseQ) {
        Ok(()) => None,
        Err(Error::InvalidParameter { value, reason, .. }) => Some(format!("{value}: {reason}")),
        Err(e) => Some(e.to_string()),
    }
}

impl ProcessNoise for UserNoise {
    fn dimension(&self) -> usize {
        match self {
            UserNoise::Constant(q) => q.dimension(),
            UserNoise::Callable(_, n) => *n,
        }
    }

    /// A constant `Q`'s saved form (the library's); a callable has none (it is pickled
    /// beside the filter's bytes).
    fn saved(&self) -> Option<SavedNoise> {
        match self {
            UserNoise::Constant(q) => q.saved(),
            UserNoise::Callable(..) => None,
        }
    }

    fn covariance(&self, t_a: f64, t_b: f64) -> Result<DMatrix<f64>, Error> {
        match self {
            UserNoise::Constant(q) => q.covariance(t_a, t_b),
            UserNoise::Callable(c, n) => {
                let at = || format!("over t = {t_a} to {t_b}");
                let q =
                    DMatrix::from_row_slice(*n, *n, &c.call(None, &[t_a, t_b], *n, Some(*n), at)?);
                match not_covariance(&q) {
                    Some(reason) => Err(c.refuse(at(), format!("returned a matrix {reason}"))),
                    None => Ok(q),
                }
            }
        }
    }
}

/// The user's dynamics as given: `f(x, t0, t1)` with its optional `F_jacobian`, or
/// `dxdt(x, t)` with its optional `dxdt_jacobian(x, t)`.
#[derive(Clone, Copy, Default)]
pub(crate) struct Transition<'a, 'py> {
    pub(crate) f: Option<&'a Bound<'py, PyAny>>,
    pub(crate) f_jacobian: Option<&'a Bound<'py, PyAny>>,
    pub(crate) dxdt: Option<&'a Bound<'py, PyAny>>,
    pub(crate) dxdt_jacobian: Option<&'a Bound<'py, PyAny>>,
}

/// The user's model from the keywords of `ExtendedKalmanFilter` and `UnscentedKalmanFilter`:
/// `n` states, the observation's components counted by one call of `h(x0, t0)`.
#[allow(non_snake_case, clippy::too_many_arguments)]
pub(crate) fn user_model(
    x0: &DVector<f64>,
    t0: f64,
    transition: Transition<'_, '_>,
    h: &Bound<'_, PyAny>,
    H_jacobian: Option<&Bound<'_, PyAny>>,
    Q: Option<&Bound<'_, PyAny>>,
    angles: Option<Vec<usize>>,
) -> PyResult<UserModel> {
    let angles = |h: &Callable| {
        let p = components_at(h, x0, t0)?;
        Angles::new(p, &angles.unwrap_or_default()).py()
    };
    model_of(x0.len(), transition, h, H_jacobian, Q, angles)
}

/// The components `h` gives at the prior (at least 1).
fn components_at(h: &Callable, x0: &DVector<f64>, t0: f64) -> PyResult<usize> {
    let first = Python::attach(|py| {
        h.func
            .call1(py, (PyArray1::from_slice(py, x0.as_slice()), t0))
            .and_then(|v| {
                let np = py.import("numpy")?;
                np.call_method1("size", (v,))?.extract::<usize>()
            })
    })
    .map_err(|e| {
        raise(
            Kind::Parameter,
            format!("h at the prior (t0 = {t0}) gave no array of numbers: {e}"),
            None,
        )
    })?;
    if first == 0 {
        return Err(raise(
            Kind::Parameter,
            "h at the prior gave no values: the observation needs at least one component",
            None,
        ));
    }
    Ok(first)
}

/// The user's model of `n` states, its observation's components and angles given by
/// `angles` (called once `h` is taken).
#[allow(non_snake_case)]
fn model_of(
    n: usize,
    transition: Transition<'_, '_>,
    h: &Bound<'_, PyAny>,
    H_jacobian: Option<&Bound<'_, PyAny>>,
    Q: Option<&Bound<'_, PyAny>>,
    angles: impl FnOnce(&Callable) -> PyResult<Angles>,
) -> PyResult<UserModel> {
    let raised = Raised::default();
    let optional = |obj: Option<&Bound<'_, PyAny>>, param, keyword| {
        obj.filter(|o| !o.is_none())
            .map(|o| Callable::new(o, param, keyword, &raised))
            .transpose()
    };
    let given = |o: Option<&Bound<'_, PyAny>>| o.is_some_and(|o| !o.is_none());
    let dynamics = match (given(transition.f), given(transition.dxdt)) {
        (true, false) => UserDynamics {
            n,
            f: Callable::new(
                transition.f.expect("given"),
                Param::TransitionFunction,
                "f",
                &raised,
            )?,
            jacobian: optional(
                transition.f_jacobian,
                Param::TransitionJacobian,
                "F_jacobian",
            )?,
            ode: None,
        },
        (false, true) if !given(transition.f_jacobian) => {
            let f = Callable::new(
                transition.dxdt.expect("given"),
                Param::DerivativeFunction,
                "dxdt",
                &raised,
            )?;
            let jacobian = optional(
                transition.dxdt_jacobian,
                Param::DerivativeJacobian,
                "dxdt_jacobian",
            )?;
            let ode = Ode::new(n, &f, jacobian.as_ref());
            UserDynamics {
                n,
                f,
                jacobian,
                ode: Some(ode),
            }
        }
        _ => {
            return Err(raise(
                Kind::Parameter,
                "the dynamics are f (with F_jacobian) or dxdt (with dxdt_jacobian): give one",
                None,
            ))
        }
    };
    let h = Callable::new(h, Param::ObservationFunction, "h", &raised)?;
    let angles = angles(&h)?;
    let observation = UserObservation {
        n,
        p: angles.components(),
        h,
        jacobian: optional(H_jacobian, Param::ObservationJacobian, "H_jacobian")?,
        angles,
    };
    let noise = match Q.filter(|q| !q.is_none()) {
        None => None,
        Some(q) if q.is_callable() => Some(UserNoise::Callable(
            Callable::new(q, Param::ProcessNoiseFunction, "Q", &raised)?,
            n,
        )),
        Some(q) => {
            let q = crate::kalman::square_from(q, n, "Q")?;
            check_covariance(&q, n, Param::ProcessNoiseQ).py()?;
            Some(UserNoise::Constant(MatrixNoise::new(q).py()?))
        }
    };
    Ok(UserModel {
        dynamics,
        observation,
        noise,
        raised,
    })
}

/// The caller's callables of a model, pickled beside the library's bytes:
/// `(f, F_jacobian, dxdt, dxdt_jacobian, h, H_jacobian, Q)`, `None` where not given (`Q`
/// only a callable: a constant `Q` is in the library's bytes).
pub(crate) fn callables_of<'py>(
    py: Python<'py>,
    dynamics: &UserDynamics,
    observation: &UserObservation,
    q: Option<&Callable>,
) -> PyResult<Bound<'py, PyTuple>> {
    let obj = |c: Option<&Callable>| match c {
        Some(c) => c.func.clone_ref(py).into_bound(py),
        None => py.None().into_bound(py),
    };
    let (f, jacobian) = (Some(&dynamics.f), dynamics.jacobian.as_ref());
    let (f, f_jacobian, dxdt, dxdt_jacobian) = match dynamics.ode {
        None => (obj(f), obj(jacobian), obj(None), obj(None)),
        Some(_) => (obj(None), obj(None), obj(f), obj(jacobian)),
    };
    let (h, h_jacobian) = (
        obj(Some(&observation.h)),
        obj(observation.jacobian.as_ref()),
    );
    PyTuple::new(
        py,
        [f, f_jacobian, dxdt, dxdt_jacobian, h, h_jacobian, obj(q)],
    )
}

/// The library's stand-ins a filter over the caller's model is saved over: its states, its
/// observation's components and angles.
pub(crate) fn stand_ins(
    dynamics: &UserDynamics,
    observation: &UserObservation,
) -> (DynamicsLeftOut, ObservationLeftOut) {
    let n = dynamics.n;
    (
        DynamicsLeftOut::new(n),
        ObservationLeftOut::new(n, observation.angles.clone()),
    )
}

/// The caller's model again from the callables pickled beside the library's bytes
/// ([`callables_of`]) and the stand-ins restored from them (states, components, angles);
/// anything amiss a `DamagedStateError`.
pub(crate) fn model_again(
    callables: &Bound<'_, PyAny>,
    dynamics: &DynamicsLeftOut,
    observation: &ObservationLeftOut,
) -> PyResult<UserModel> {
    let items = persist::items(callables, 7)?;
    let given = (0..7)
        .map(|i| Ok(items.get_item(i)?).map(|v| (!v.is_none()).then_some(v)))
        .collect::<PyResult<Vec<_>>>()?;
    let [f, f_jacobian, dxdt, dxdt_jacobian, h, h_jacobian, q] = &given[..] else {
        unreachable!("seven items")
    };
    let Some(h) = h else {
        return Err(persist::damaged("the observation h is missing"));
    };
    if q.as_ref().is_some_and(|q| !q.is_callable()) {
        return Err(persist::damaged(
            "the driving noise Q beside the bytes is not callable",
        ));
    }
    let transition = Transition {
        f: f.as_ref(),
        f_jacobian: f_jacobian.as_ref(),
        dxdt: dxdt.as_ref(),
        dxdt_jacobian: dxdt_jacobian.as_ref(),
    };
    let angles = |_: &Callable| Ok(observation.angles().clone());
    model_of(
        dynamics.dimension(),
        transition,
        h,
        h_jacobian.as_ref(),
        q.as_ref(),
        angles,
    )
    .map_err(|e| persist::damaged(format!("the model's callables: {e}")))
}

/// The user's model: its dynamics, observation, driving noise and the slot its callables
/// keep their first exception in.
pub(crate) struct UserModel {
    pub(crate) dynamics: UserDynamics,
    pub(crate) observation: UserObservation,
    pub(crate) noise: Option<UserNoise>,
    pub(crate) raised: Raised,
}

impl UserModel {
    /// The driving noise `Q` if it is the caller's callable (pickled beside the filter's
    /// bytes; a constant `Q` is in them).
    pub(crate) fn q_callable(&self) -> Option<Callable> {
        match &self.noise {
            Some(UserNoise::Callable(c, _)) => Some(c.clone()),
            _ => None,
        }
    }
}

type Extended = KalmanFilter<UserDynamics, UserObservation>;

/// The extended Kalman filter (Morrison §12.5; with driving noise ch. 15) over the caller's
/// own model, given as Python callables; with ``iterations > 1`` the iterated extended Kalman
/// filter (Morrison §12.5, (12.5.10)-(12.5.17)).
///
/// Parameters
/// ----------
/// x0, P0 : array_like
///     The prior state (``n`` values) and its covariance (a number: that variance on every
///     state; a vector: the diagonal; or ``n × n``) at time ``t0``.
/// f : callable
///     ``f(x, t0, t1) -> x1``: the state at ``t1`` from the state ``x`` at ``t0`` (a step
///     forwards or backwards). Or ``dxdt`` instead.
/// h : callable
///     ``h(x, t) -> z``: the observation of the state ``x`` at ``t``, ``p`` values (counted by
///     one call ``h(x0, t0)``).
/// Q : array_like or callable, optional
///     The driving-noise covariance added over each step: one ``n × n`` matrix (or a number or
///     diagonal) for every step, or ``Q(t0, t1) -> n × n``. Default none.
/// t0 : float
///     The prior's time.
/// F_jacobian : callable, optional
///     ``F_jacobian(x, t0, t1) -> Φ`` (``n × n``), ``∂f/∂x``; default central differences
///     (step ``ε^(1/3) max(|x_j|, 1)``).
/// H_jacobian : callable, optional
///     ``H_jacobian(x, t) -> M`` (``p × n``), ``∂h/∂x``; default central differences.
/// angles : sequence of int, optional
///     The components of ``z`` that are angles in radians: their residuals are wrapped to
///     (−π, π].
/// dxdt : callable, optional (keyword only)
///     Instead of ``f``: ``dxdt(x, t) -> dx/dt`` (``n`` values) of ``dX/dt = F(X, t)``; the
///     library integrates it with its variational equations ``dΦ/dt = (∂F/∂X) Φ`` (Morrison
///     §8.6) over each step, forwards or backwards, by the Dormand–Prince 8(5,3) pair
///     (DOP853) with step-size control on ``X`` and ``Φ`` to 1e-10 relative, 1e-12 absolute
///     per component.
/// dxdt_jacobian : callable, optional (keyword only)
///     ``dxdt_jacobian(x, t) -> ∂F/∂X`` (``n × n``); default central differences of ``dxdt``
///     (step ``ε^(1/3) max(|x_j|, 1)``).
/// iterations : int
///     1 (default): the extended filter; more: the iterated update, relinearised about each
///     new estimate until the change is at most ``tolerance`` of its σ, at most
///     ``iterations`` times (``NotDeterminedError`` otherwise).
/// tolerance : float
///     The iterated update's convergence test (default 1e-9).
///
/// A callable that raises, returns the wrong shape, a NaN or an infinity is refused with a
/// ``ParameterError`` naming it (``f``, ``dxdt``, ``h``, ``F_jacobian``, ``dxdt_jacobian``,
/// ``H_jacobian``, ``Q``), the
/// time and, in ``update_many``, the measurement's index (``.index``), a raised exception as
/// its ``__cause__``; the filter is left as it was.
#[pyclass(name = "ExtendedKalmanFilter", module = "seqsmooth")]
#[derive(Clone)]
pub struct PyExtendedKalmanFilter {
    filter: Extended,
    raised: Raised,
    /// The driving noise `Q` if it is the caller's callable.
    q: Option<Callable>,
    /// The observation's components `p`.
    components: usize,
    iterations: usize,
    tolerance: f64,
}

#[pymethods]
impl PyExtendedKalmanFilter {
    #[new]
    #[allow(non_snake_case, clippy::too_many_arguments)]
    #[pyo3(signature = (x0, P0, f = None, h = None, Q = None, t0 = 0.0, F_jacobian = None, H_jacobian = None, angles = None, iterations = 1, tolerance = 1e-9, *, dxdt = None, dxdt_jacobian = None))]
    fn new(
        x0: &Bound<'_, PyAny>,
        P0: &Bound<'_, PyAny>,
        f: Option<&Bound<'_, PyAny>>,
        h: Option<&Bound<'_, PyAny>>,
        Q: Option<&Bound<'_, PyAny>>,
        t0: f64,
        F_jacobian: Option<&Bound<'_, PyAny>>,
        H_jacobian: Option<&Bound<'_, PyAny>>,
        angles: Option<Vec<usize>>,
        iterations: usize,
        tolerance: f64,
        dxdt: Option<&Bound<'_, PyAny>>,
        dxdt_jacobian: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        // The library's range of the iterated update's limits.
        IterationLimits::new(tolerance, iterations).py()?;
        let Some(h) = h.filter(|h| !h.is_none()) else {
            return Err(raise(Kind::Parameter, "h is required", None));
        };
        let x = DVector::from_column_slice(crate::arrays::series(x0, "x0")?.as_slice());
        let p0 = crate::kalman::square_from(P0, x.len(), "P0")?;
        let transition = Transition {
            f,
            f_jacobian: F_jacobian,
            dxdt,
            dxdt_jacobian,
        };
        let model = user_model(&x, t0, transition, h, H_jacobian, Q, angles)?;
        let (components, q) = (model.observation.components(), model.q_callable());
        let mut filter = KalmanFilter::new(model.dynamics, model.observation, x, p0, t0).py()?;
        if let Some(q) = model.noise {
            filter = filter.with_process_noise(q).py()?;
        }
        Ok(Self {
            filter,
            raised: model.raised,
            q,
            components,
            iterations,
            tolerance,
        })
    }

    /// ``pickle`` support (``copy.copy`` and ``copy.deepcopy`` too): the filter's state in
    /// the library's saved form over its stand-in models (``iterations`` and ``tolerance``
    /// inside the checksum), the callables ``f``/``dxdt``, ``h``, the Jacobians and a
    /// callable ``Q`` beside it, pickled by Python (a module-level function pickles; a lambda
    /// or a local function raises pickle's own error). Restored bit for bit; a copy is a deep
    /// copy of the state that shares the callables.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let me = slf.borrow();
        let (d, o) = me.filter.models();
        let callables = callables_of(py, d, o, me.q.as_ref())?;
        let (dynamics, observation) = stand_ins(d, o);
        let mut filter = me.filter.clone();
        if me.q.is_some() {
            filter.take_process_noise();
        }
        let filter = filter.with_models(dynamics, observation).py()?;
        let limits = IterationLimits::new(me.tolerance, me.iterations).py()?;
        let bytes = persist::save(py, &(filter, limits))?;
        let state = PyTuple::new(py, [bytes, callables.into_any()])?;
        persist::reduce(slf.as_any(), state.into_any())
    }

    /// The filter ``__reduce__`` saved (a ``DamagedStateError`` if ``state`` is damaged or
    /// another class's).
    #[staticmethod]
    fn _from_state(state: &Bound<'_, PyAny>) -> PyResult<Self> {
        let items = persist::items(state, 2)?;
        let (mut bare, limits): (
            KalmanFilter<DynamicsLeftOut, ObservationLeftOut>,
            IterationLimits,
        ) = persist::load(&items.get_item(0)?)?;
        let (d, o) = bare.models();
        let model = model_again(&items.get_item(1)?, d, o)?;
        let (components, q) = (model.observation.components(), model.q_callable());
        if q.is_some() && bare.take_process_noise().is_some() {
            return Err(persist::damaged(
                "the driving noise is both in the bytes and beside them",
            ));
        }
        let mut filter = bare.with_models(model.dynamics, model.observation).py()?;
        if let Some(noise) = model.noise {
            filter.set_process_noise(noise).py()?;
        }
        Ok(Self {
            filter,
            raised: model.raised,
            q,
            components,
            iterations: limits.iterations(),
            tolerance: limits.tolerance(),
        })
    }

    /// The current estimate ``X``; settable (``n`` finite numbers, checked by the library;
    /// on an error the filter is unchanged).
    #[getter]
    fn state<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.filter.state().as_slice())
    }

    #[setter]
    fn set_state(&mut self, x: &Bound<'_, PyAny>) -> PyResult<()> {
        let (p, t) = (self.filter.covariance().clone(), self.filter.time());
        self.filter
            .set_estimate(crate::kalman::state_from(x)?, p, t)
            .py()
    }

    /// The covariance of ``X``'s errors; settable (finite, symmetric, positive
    /// semidefinite, checked by the library: a ``ParameterError`` naming ``P`` otherwise,
    /// the filter unchanged).
    #[getter]
    fn covariance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        square(py, self.filter.covariance())
    }

    #[setter]
    fn set_covariance(&mut self, p: &Bound<'_, PyAny>) -> PyResult<()> {
        let (x, t) = (self.filter.state().clone(), self.filter.time());
        let p = crate::kalman::covariance_from(p, x.len())?;
        self.filter.set_estimate(x, p, t).py()
    }

    /// The 1σ of each state component, the square roots of ``covariance``'s diagonal.
    #[getter]
    fn std_devs<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.filter.std_devs())
    }

    /// The time the estimate is valid at.
    #[getter]
    fn time(&self) -> f64 {
        self.filter.time()
    }

    /// Carries the estimate to time ``t`` by ``f`` and its covariance by ``Φ S Φᵀ + Q`` (no
    /// measurement). On an error the filter is unchanged.
    fn predict(&mut self, t: f64) -> PyResult<()> {
        let result = self.filter.predict(t);
        self.raised.py(result)
    }

    /// Predicts to ``t`` and updates with ``z`` (a number, or one value per component; NaN for
    /// a missing one) of noise ``R`` (a variance for every component, the variances, or the
    /// covariance). Returns the :class:`Innovation`, or ``None`` when every component is
    /// missing (a prediction only). On an error the filter is unchanged.
    #[allow(non_snake_case)]
    #[pyo3(signature = (t, z, R))]
    fn update(
        &mut self,
        t: f64,
        z: &Bound<'_, PyAny>,
        R: &Bound<'_, PyAny>,
    ) -> PyResult<Option<PyInnovation>> {
        let m = measurement(t, z, R, self.filter_components(), self.filter.time())?;
        let result = self.step(&m);
        let innovation = self.raised.py(result)?;
        Ok(innovation.map(|inner| PyInnovation { inner }))
    }

    /// Runs the measurements ``(t[i], z[i])`` (``z`` of shape ``(n,)`` or ``(n, p)``, NaN for
    /// a missing component) with noise ``R`` on every one. Returns ``(states, covariances,
    /// nis)``: ``(n, dim)``, ``(n, dim, dim)`` and ``(n,)`` (NaN where nothing was measured).
    /// On an error (``.index`` names the measurement) the measurements before it are taken.
    #[allow(non_snake_case)]
    #[pyo3(signature = (t, z, R))]
    fn update_many<'py>(
        &mut self,
        py: Python<'py>,
        t: &Bound<'py, PyAny>,
        z: &Bound<'py, PyAny>,
        R: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let mut rows = measurements(t, z, R, self.filter_components())?;
        let disorder = out_of_order(self.filter.time(), &rows);
        if let Some((k, _, _)) = disorder {
            rows.truncate(k);
        }
        let n = self.filter.state().len();
        let mut run = Run::new(rows.len(), n);
        // The GIL is kept: every step calls Python.
        let outcome = rows.iter().enumerate().try_for_each(|(i, m)| {
            let innovation = self.step(m).map_err(|e| Error::InBatch {
                index: i,
                source: Box::new(e),
            })?;
            let nis = innovation.map(|s| s.nis);
            run.record(i, self.filter.state(), self.filter.covariance(), nis);
            Ok::<(), Error>(())
        });
        self.raised.py(outcome)?;
        if let Some((k, t, previous)) = disorder {
            return Err(before(t, previous, Some(k)));
        }
        run.into_tuple(py)
    }

    /// The Rauch–Tung–Striebel smoother over the measurements, from this filter's current
    /// state (the filter itself is not changed): the extended filter forwards (one
    /// linearisation per measurement; with ``iterations > 1`` the iterated update, as
    /// ``update``), then the backward pass with each step's ``Φ`` along the
    /// forward trajectory. Returns ``(states, covariances)``, ``(n, dim)`` and
    /// ``(n, dim, dim)``.
    #[allow(non_snake_case)]
    #[pyo3(signature = (t, z, R))]
    fn smooth<'py>(
        &self,
        py: Python<'py>,
        t: &Bound<'py, PyAny>,
        z: &Bound<'py, PyAny>,
        R: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let rows = measurements(t, z, R, self.filter_components())?;
        if let Some((k, t, previous)) = out_of_order(self.filter.time(), &rows) {
            return Err(before(t, previous, Some(k)));
        }
        // The forward pass iterated as the filter's own updates are (§12.5).
        let forward = smoother::Smoother::new(self.filter.clone());
        let forward = match self.iterations {
            1 => Ok(forward),
            most => forward.with_iterated_update(self.tolerance, most),
        };
        let smoothed = self.raised.py(forward.and_then(|s| s.smooth(&rows)))?;
        stacked(py, smoothed.iter().map(|s| (&s.state, &s.covariance)))
    }

    /// The fixed-lag smoother over the measurements (as ``smooth`` takes them), from this
    /// filter's current state (the filter itself is not changed), its forward pass iterated as
    /// ``smooth``'s: each measurement's estimate from the ``lag`` measurements after it (the
    /// last ``lag`` from all of them; a ``lag`` of at least their number gives ``smooth``'s),
    /// by the library's ``FixedLagSmoother``, which holds ``lag + 1`` measurements however
    /// many there are. Returns ``(states, covariances)``, ``(N, dim)``
    /// and ``(N, dim, dim)``; an error's ``.index`` names the measurement.
    #[allow(non_snake_case)]
    #[pyo3(signature = (t, z, R, lag))]
    fn fixed_lag_smoother<'py>(
        &self,
        py: Python<'py>,
        t: &Bound<'py, PyAny>,
        z: &Bound<'py, PyAny>,
        R: &Bound<'py, PyAny>,
        lag: usize,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let rows = measurements(t, z, R, self.filter_components())?;
        if let Some((k, t, previous)) = out_of_order(self.filter.time(), &rows) {
            return Err(before(t, previous, Some(k)));
        }
        let forward = FixedLagSmoother::new(self.filter.clone(), lag);
        let forward = match self.iterations {
            1 => Ok(forward),
            most => forward.with_iterated_update(self.tolerance, most),
        };
        let n = self.filter.state().len();
        let out = forward.and_then(|s| lagged(s, &rows, n));
        self.raised.py(out)?.into_tuple(py)
    }

    fn __repr__(&self) -> String {
        format!(
            "ExtendedKalmanFilter(states={}, components={}, time={:?}, iterations={})",
            self.filter.state().len(),
            self.filter_components(),
            self.filter.time(),
            self.iterations
        )
    }
}

impl PyExtendedKalmanFilter {
    fn filter_components(&self) -> usize {
        self.components
    }

    /// One update, iterated when asked.
    fn step(&mut self, m: &Measurement) -> Result<Option<seqsmooth::kalman::Innovation>, Error> {
        if self.iterations > 1 {
            self.filter
                .update_iterated(m, self.tolerance, self.iterations)
        } else {
            self.filter.update(m)
        }
    }
}

/// Smoothed states and covariances as `(states, covariances)`, `(count, n)` and
/// `(count, n, n)`.
pub(crate) fn stacked<'py, 'a>(
    py: Python<'py>,
    rows: impl ExactSizeIterator<Item = (&'a DVector<f64>, &'a DMatrix<f64>)>,
) -> PyResult<Bound<'py, PyTuple>> {
    let count = rows.len();
    let (mut states, mut covariances, mut n) = (Vec::new(), Vec::new(), 0);
    for (x, s) in rows {
        n = x.len();
        states.extend_from_slice(x.as_slice());
        covariances.extend_from_slice(s.as_slice());
    }
    let states = matrix(py, states, count, n)?;
    let covariances = PyArray1::from_vec(py, covariances)
        .reshape([count, n, n])?
        .into_any();
    PyTuple::new(py, [states, covariances])
}

/// `update_many`'s outputs, filled a measurement at a time: `(states, covariances, nis)`,
/// `(count, n)`, `(count, n, n)` and `(count,)` (NaN where nothing was measured).
pub(crate) struct Run {
    n: usize,
    states: Vec<f64>,
    covariances: Vec<f64>,
    nis: Vec<f64>,
}

impl Run {
    pub(crate) fn new(count: usize, n: usize) -> Self {
        Self {
            n,
            states: vec![0.0; count * n],
            covariances: vec![0.0; count * n * n],
            nis: vec![f64::NAN; count],
        }
    }

    /// Measurement `i`'s row: the filter's state and covariance after it, and its NIS.
    pub(crate) fn record(
        &mut self,
        i: usize,
        state: &DVector<f64>,
        covariance: &DMatrix<f64>,
        nis: Option<f64>,
    ) {
        let n = self.n;
        if let Some(v) = nis {
            self.nis[i] = v;
        }
        self.states[i * n..(i + 1) * n].copy_from_slice(state.as_slice());
        // Symmetric: column-major is row-major.
        self.covariances[i * n * n..(i + 1) * n * n].copy_from_slice(covariance.as_slice());
    }

    pub(crate) fn into_tuple(self, py: Python<'_>) -> PyResult<Bound<'_, PyTuple>> {
        let (count, n) = (self.nis.len(), self.n);
        let states = matrix(py, self.states, count, n)?;
        let covariances = PyArray1::from_vec(py, self.covariances)
            .reshape([count, n, n])?
            .into_any();
        let nis = PyArray1::from_vec(py, self.nis).into_any();
        PyTuple::new(py, [states, covariances, nis])
    }
}
