//! The dynamic model of a state (Morrison ch. 4, §8.6): one trait for every model, giving the
//! state at any time from the state at any other, forwards or backwards, with the transition
//! matrix `Φ(t_b, t_a; X) = ∂X(t_b)/∂X(t_a)` along that trajectory (4.7.x, (8.6.5)-(8.6.7)).
//!
//! | model | `Φ(t_b, t_a)` | source |
//! |---|---|---|
//! | [`PolynomialDynamics`] (degree `m`, `d` axes) | `Ψ(t_b − t_a) ⊗ I_d`, exact | (4.2.5), [`super::psi`] |
//! | [`super::linear::LinearDynamics`] `dX/dt = A X` | `e^{(t_b − t_a) A}` | (4.6.24)-(4.6.28) |
//! | [`super::continuous::ContinuousModel`] `dX/dt = A X + w` | `e^{(t_b − t_a) A}`, with the noise's `Q` | (15.2.23), Van Loan 1978 |
//! | [`super::nonlinear::NonlinearDynamics`] `dX/dt = F(X, t)` | variational equations `dΦ/dt = (∂F/∂X) Φ` | (4.7.x), (8.6.6) |
//!
//! For a linear model `Φ` does not depend on the state; for a nonlinear one it is the
//! linearisation about the trajectory through the given state (§8.6). A covariance is carried
//! to first order, `S_b = Φ S_a Φᵀ` ((6.6.x); exact for linear models).

use super::linear::LinearDynamics;
use super::transition::psi_term;
use crate::error::{Error, Param};
use crate::numeric::unrolled::{unrolled_sizes, Any, Fixed, Size};
use nalgebra::{DMatrix, DVector};

/// The state at `t_b` and the transition matrix `Φ(t_b, t_a)` that carried it there.
#[derive(Clone, Debug, PartialEq)]
pub struct Propagation {
    /// `X(t_b)`.
    pub state: DVector<f64>,
    /// `Φ(t_b, t_a) = ∂X(t_b)/∂X(t_a)`.
    pub transition: DMatrix<f64>,
}

/// A dynamic model: the state dimension and the propagation of a state from any time to any
/// other.
///
/// ```
/// use nalgebra::DVector;
/// use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
/// // A constant-velocity state (x, x') carried back 2 time units.
/// let p = PolynomialDynamics::new(1, 1).propagate(&DVector::from_vec(vec![5.0, 3.0]), 10.0, 8.0).unwrap();
/// assert_eq!(p.state.as_slice(), &[-1.0, 3.0]);
/// ```
pub trait Dynamics {
    /// The state dimension `n`.
    fn dimension(&self) -> usize;

    /// `X(t_b)` and `Φ(t_b, t_a)` from `X(t_a)`; `t_b < t_a` goes backwards.
    fn propagate(&self, state: &DVector<f64>, t_a: f64, t_b: f64) -> Result<Propagation, Error>;

    /// Whether `Φ(t_b, t_a)` is the same for every state (linear dynamics, `dX/dt = A(t) X`):
    /// the estimators then compute each observation's `Φ(t_k, t_c)` once, not at every
    /// iteration. `false` unless the model says so.
    ///
    /// ```
    /// use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
    /// assert!(PolynomialDynamics::new(1, 3).is_linear());
    /// ```
    fn is_linear(&self) -> bool {
        false
    }

    /// Whether `Φ(t_b, t_a)` depends only on the step `t_b − t_a` (a time-invariant linear
    /// model: the polynomial model, `dX/dt = A X` with a constant `A`): a bank computes it once
    /// for each step length in a row. `false` unless the model says so.
    ///
    /// ```
    /// use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
    /// assert!(PolynomialDynamics::new(1, 3).is_time_invariant());
    /// ```
    fn is_time_invariant(&self) -> bool {
        false
    }

    /// The polynomial model this is, when it is one ([`PolynomialDynamics`]: `Φ = Ψ(ζ) ⊗ I_d`,
    /// (4.2.5)): the Kalman filter then predicts with `Φ`'s structure and the sizes fixed at
    /// compile time (the same numbers). `None` unless the model says so. The filter reads
    /// it once when the model is set, so the answer must not change over the model's life.
    ///
    /// ```
    /// use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
    /// let cv = PolynomialDynamics::new(1, 3);
    /// assert_eq!(cv.polynomial(), Some(cv));
    /// ```
    fn polynomial(&self) -> Option<PolynomialDynamics> {
        None
    }

    /// [`Dynamics::propagate`] into the caller's buffers (`state_out` of length `n`,
    /// `transition_out` `n × n`, replaced if they are not), allocating nothing where the model
    /// allows ([`PolynomialDynamics`] does): what the estimators call at every observation time.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
    /// let (mut x, mut phi) = (DVector::zeros(2), DMatrix::zeros(2, 2));
    /// PolynomialDynamics::new(1, 1)
    ///     .propagate_into(&DVector::from_vec(vec![5.0, 3.0]), 10.0, 8.0, &mut x, &mut phi)
    ///     .unwrap();
    /// assert_eq!((x[0], phi[(0, 1)]), (-1.0, -2.0));
    /// ```
    fn propagate_into(
        &self,
        state: &DVector<f64>,
        t_a: f64,
        t_b: f64,
        state_out: &mut DVector<f64>,
        transition_out: &mut DMatrix<f64>,
    ) -> Result<(), Error> {
        let p = self.propagate(state, t_a, t_b)?;
        *state_out = p.state;
        *transition_out = p.transition;
        Ok(())
    }

    /// `X(t_b)` alone, without `Φ`: what the unscented filter evaluates at each sigma point
    /// (Wan and van der Merwe (18)). By default [`Dynamics::propagate`]'s state; a model whose
    /// `Φ` costs more than `X` (variational equations) may give `X` alone.
    ///
    /// ```
    /// use nalgebra::DVector;
    /// use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
    /// let x = PolynomialDynamics::new(1, 1).propagate_state(&DVector::from_vec(vec![5.0, 3.0]), 10.0, 8.0).unwrap();
    /// assert_eq!(x.as_slice(), &[-1.0, 3.0]);
    /// ```
    fn propagate_state(
        &self,
        state: &DVector<f64>,
        t_a: f64,
        t_b: f64,
    ) -> Result<DVector<f64>, Error> {
        Ok(self.propagate(state, t_a, t_b)?.state)
    }

    /// `X(t_b)` and, to first order, its covariance `Φ S Φᵀ` from `X(t_a)` with covariance `S`.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
    /// let (x, s) = PolynomialDynamics::new(1, 1)
    ///     .propagate_covariance(&DVector::from_vec(vec![0.0, 1.0]), &DMatrix::identity(2, 2), 0.0, 1.0)
    ///     .unwrap();
    /// assert_eq!(x[0], 1.0);
    /// assert_eq!(s, DMatrix::from_row_slice(2, 2, &[2.0, 1.0, 1.0, 1.0]));
    /// ```
    fn propagate_covariance(
        &self,
        state: &DVector<f64>,
        covariance: &DMatrix<f64>,
        t_a: f64,
        t_b: f64,
    ) -> Result<(DVector<f64>, DMatrix<f64>), Error> {
        let n = self.dimension();
        if covariance.shape() != (n, n) {
            return Err(Error::InvalidParameter {
                name: Param::Covariance,
                value: format!("{}x{}", covariance.nrows(), covariance.ncols()),
                reason: format!("must be {n}x{n}, the state dimension"),
            });
        }
        if let Some(v) = covariance.iter().find(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "covariance entry",
                value: *v,
            });
        }
        let p = self.propagate(state, t_a, t_b)?;
        let s = &p.transition * covariance * p.transition.transpose();
        let s = (&s + s.transpose()) * 0.5;
        finite_matrix(&s, "propagated covariance")?;
        Ok((p.state, s))
    }
}

/// Refuses a state of the wrong length or with a non-finite entry, and non-finite times.
pub(crate) fn check_propagation(
    n: usize,
    state: &DVector<f64>,
    t_a: f64,
    t_b: f64,
) -> Result<(), Error> {
    if state.len() != n {
        return Err(Error::InvalidParameter {
            name: Param::State,
            value: format!("of length {}", state.len()),
            reason: format!("must have the model's dimension {n}"),
        });
    }
    if let Some(v) = state.as_slice().iter().find(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            what: "state entry",
            value: *v,
        });
    }
    for t in [t_a, t_b] {
        if !t.is_finite() {
            return Err(Error::NonFinite {
                what: "time",
                value: t,
            });
        }
    }
    Ok(())
}

pub(crate) fn finite_matrix(m: &DMatrix<f64>, what: &'static str) -> Result<(), Error> {
    match m.as_slice().iter().find(|v| !v.is_finite()) {
        Some(&value) => Err(Error::NonFinite { what, value }),
        None => Ok(()),
    }
}

/// The polynomial model of degree `m` on `d` axes: each axis a degree-`m` polynomial in time, the
/// state ordered by derivative, then axis, in unscaled derivatives:
/// `(x₁, …, x_d, x₁′, …, x_d′, …, x₁^(m), …, x_d^(m))`, so that `d = 3`, `m = 1` is the 3-D
/// constant-velocity state `(x, y, z, vx, vy, vz)`. `Φ(t_b, t_a) = Ψ(t_b − t_a) ⊗ I_d`
/// (4.2.5), the one polynomial transition the crate has ([`super::psi`]).
///
/// ```
/// use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
/// let cv = PolynomialDynamics::new(1, 3);
/// assert_eq!(cv.dimension(), 6);
/// let phi = cv.transition(2.0);
/// assert_eq!((phi[(0, 3)], phi[(2, 5)], phi[(0, 4)]), (2.0, 2.0, 0.0));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct PolynomialDynamics {
    degree: usize,
    axes: usize,
}

impl PolynomialDynamics {
    /// Degree `m` on `axes` axes (at least one).
    ///
    /// ```
    /// use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
    /// assert_eq!(PolynomialDynamics::new(2, 1).dimension(), 3);
    /// ```
    pub fn new(degree: usize, axes: usize) -> Self {
        Self {
            degree,
            axes: axes.max(1),
        }
    }

    /// The degree `m`.
    ///
    /// ```
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// assert_eq!(PolynomialDynamics::new(4, 2).degree(), 4);
    /// ```
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// The number of axes `d`.
    ///
    /// ```
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// assert_eq!(PolynomialDynamics::new(4, 2).axes(), 2);
    /// ```
    pub fn axes(&self) -> usize {
        self.axes
    }

    /// `Φ(ζ) = Ψ(ζ) ⊗ I_d`: `[Φ]_{i d + a, j d + a} = ζ^(j−i)/(j−i)!` for `j ≥ i`.
    ///
    /// ```
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// assert_eq!(PolynomialDynamics::new(2, 1).transition(2.0)[(0, 2)], 2.0); // ζ²/2!
    /// ```
    pub fn transition(&self, zeta: f64) -> DMatrix<f64> {
        let n = (self.degree + 1) * self.axes;
        let mut out = DMatrix::zeros(n, n);
        self.transition_into(zeta, &mut out);
        out
    }

    /// `Φ(ζ) = Ψ(ζ) ⊗ I_d` written into `out` (resized to `n × n` if it is not).
    fn transition_into(&self, zeta: f64, out: &mut DMatrix<f64>) {
        let n = self.dimension();
        if out.shape() != (n, n) {
            *out = DMatrix::zeros(n, n);
        }
        let out = out.as_mut_slice();
        out.fill(0.0);
        self.for_each_entry(zeta, |r, c, term| out[r + c * n] = term);
    }

    /// Calls `entry(r, c, ζ^k/k!)` for every entry of `Φ(ζ)` that is not structurally zero,
    /// `[Φ]_{i d + a, (i + k) d + a}`, by `k` ascending (so each row's columns ascending), each
    /// `ζ^k/k!` from [`psi_term`] once. The size `m + 1` goes through the crate's size dispatch:
    /// for the common degrees `k` is then a constant in each `ζ^k/k!` (its power multiplied
    /// out, the factorial folded; the same operations).
    fn for_each_entry(&self, zeta: f64, entry: impl FnMut(usize, usize, f64)) {
        let d = self.axes;
        unrolled_sizes!(self.degree + 1, M => entries(Fixed::<M>, d, zeta, entry),
            m => entries(Any(m), d, zeta, entry));
    }
}

/// [`PolynomialDynamics::for_each_entry`] for `size = m + 1` on `d` axes.
#[inline(always)]
fn entries<S: Size>(size: S, d: usize, zeta: f64, mut entry: impl FnMut(usize, usize, f64)) {
    let size = size.get();
    for k in 0..size {
        let term = psi_term(k, &zeta);
        for i in 0..size - k {
            for a in 0..d {
                entry(i * d + a, (i + k) * d + a, term);
            }
        }
    }
}

impl Dynamics for PolynomialDynamics {
    fn dimension(&self) -> usize {
        (self.degree + 1) * self.axes
    }

    fn is_linear(&self) -> bool {
        true
    }

    fn is_time_invariant(&self) -> bool {
        true
    }

    fn polynomial(&self) -> Option<PolynomialDynamics> {
        Some(*self)
    }

    fn propagate(&self, state: &DVector<f64>, t_a: f64, t_b: f64) -> Result<Propagation, Error> {
        let n = self.dimension();
        let mut p = Propagation {
            state: DVector::zeros(n),
            transition: DMatrix::zeros(n, n),
        };
        self.propagate_into(state, t_a, t_b, &mut p.state, &mut p.transition)?;
        Ok(p)
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
        check_propagation(n, state, t_a, t_b)?;
        if transition_out.shape() != (n, n) {
            *transition_out = DMatrix::zeros(n, n);
        }
        if state_out.len() != n {
            *state_out = DVector::zeros(n);
        }
        // Φ's entries, and X(t_b) = Φ X(t_a) over them (each row's columns ascending; the
        // structural zeros would add nothing), in one pass.
        let (phi, x, out) = (
            transition_out.as_mut_slice(),
            state.as_slice(),
            state_out.as_mut_slice(),
        );
        phi.fill(0.0);
        let mut finite = true;
        // Each row's diagonal entry (k = 0) comes first: it starts the row's sum.
        self.for_each_entry(t_b - t_a, |r, c, term| {
            phi[r + c * n] = term;
            if r == c {
                out[r] = term * x[c];
            } else {
                out[r] += term * x[c];
            }
            finite &= term.is_finite();
        });
        if !finite {
            finite_matrix(transition_out, "transition matrix entry")?;
        }
        if let Some(v) = state_out.as_slice().iter().find(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "propagated state entry",
                value: *v,
            });
        }
        Ok(())
    }
}

impl Dynamics for LinearDynamics {
    fn dimension(&self) -> usize {
        LinearDynamics::dimension(self)
    }

    fn is_linear(&self) -> bool {
        true
    }

    fn is_time_invariant(&self) -> bool {
        true
    }

    fn propagate(&self, state: &DVector<f64>, t_a: f64, t_b: f64) -> Result<Propagation, Error> {
        check_propagation(LinearDynamics::dimension(self), state, t_a, t_b)?;
        let transition = self.transition(t_b - t_a)?;
        let state = &transition * state;
        if let Some(v) = state.iter().find(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "propagated state entry",
                value: *v,
            });
        }
        Ok(Propagation { state, transition })
    }
}

impl<D: Dynamics + ?Sized> Dynamics for &D {
    fn dimension(&self) -> usize {
        (**self).dimension()
    }

    fn is_linear(&self) -> bool {
        (**self).is_linear()
    }

    fn is_time_invariant(&self) -> bool {
        (**self).is_time_invariant()
    }

    fn polynomial(&self) -> Option<PolynomialDynamics> {
        (**self).polynomial()
    }

    fn propagate(&self, state: &DVector<f64>, t_a: f64, t_b: f64) -> Result<Propagation, Error> {
        (**self).propagate(state, t_a, t_b)
    }

    fn propagate_into(
        &self,
        state: &DVector<f64>,
        t_a: f64,
        t_b: f64,
        state_out: &mut DVector<f64>,
        transition_out: &mut DMatrix<f64>,
    ) -> Result<(), Error> {
        (**self).propagate_into(state, t_a, t_b, state_out, transition_out)
    }

    fn propagate_state(
        &self,
        state: &DVector<f64>,
        t_a: f64,
        t_b: f64,
    ) -> Result<DVector<f64>, Error> {
        (**self).propagate_state(state, t_a, t_b)
    }
}
