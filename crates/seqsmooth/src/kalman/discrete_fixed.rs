//! The fixed-size batch of [`LinearKalmanFilter`](super::discrete::LinearKalmanFilter) with
//! constant matrices: the same recursion as the generic [`KalmanFilter`](super::KalmanFilter)
//! (Morrison (12.2.15)-(12.2.19) with `Φ = F`, driving noise (15.4.11), Joseph's covariance
//! (12.3.7)) for `n ≤ 9` states and `p ≤ 3` observed components, with `n` and each step's
//! present components `k` compile-time constants, and without the generic filter's per-step
//! work that does not depend on the step:
//!
//! - `F`, `Q`, `H` and `R` are read in place (the generic filter copies `Φ = F`, `Q` and `M = H`
//!   into its work buffers at each step), and `Mᵀ` and `R` of the present components are built
//!   again only when the pattern of missing components changes (at most `2^p` patterns);
//! - `R`'s checks (finite, symmetric, non-negative variances) are made once per batch, not per
//!   step; the measurement is read in place (no [`Measurement`](crate::model::measurement::Measurement)
//!   is filled).
//!
//! The arithmetic is the generic filter's own kernels ([`carry`] for `F S Fᵀ + Q`,
//! [`correct_kernel`] for the update) on the same buffers, and `F x`, `H x` in the generic
//! order (each sum over the columns in order, as `nalgebra`'s `gemv` and
//! [`LinearObservation`](crate::model::observation::LinearObservation) form them), so every
//! number is the generic path's **bit for bit** (tested on seeded random models of every size
//! in range, missing components included: `tests/kalman_discrete.rs`). Anything the generic
//! path would refuse or flag — an infinite measurement value, a step with its own matrices, a
//! non-finite result, an innovation covariance that is not positive definite — stops this
//! kernel before the step changes anything; the generic path then takes that step and the rest
//! (giving its own error, or going on), so errors are the generic path's too.

use super::correct::{carry, correct_kernel, Work};
use super::discrete::{BatchStep, Inner, StepMatrices};
use crate::linalg::dense::all_finite;
use crate::numeric::unrolled::{unrolled_sizes, Fixed};
use nalgebra::{DMatrix, DVector};
use std::f64::consts::TAU;

/// The constant matrices of a batch: `F` (`n × n`), `Q` (`n × n`), `H` (`p × n`), `R`
/// (`p × p`), all checked when the filter was built (column-major, as `nalgebra` holds them).
pub(super) struct ConstantModel<'a> {
    f: &'a DMatrix<f64>,
    q: &'a DMatrix<f64>,
    h: &'a DMatrix<f64>,
    r: &'a DMatrix<f64>,
}

impl<'a> ConstantModel<'a> {
    /// `F`, `Q`, `H`, `R`.
    pub(super) fn new(
        f: &'a DMatrix<f64>,
        q: &'a DMatrix<f64>,
        h: &'a DMatrix<f64>,
        r: &'a DMatrix<f64>,
    ) -> Self {
        Self { f, q, h, r }
    }
}

impl StepMatrices<'_> {
    /// Whether the step takes every constant matrix (no `F`, `Q`, `B`, `u`, `H`, `R` of its own).
    pub(super) fn is_constant(&self) -> bool {
        [self.f, self.q, self.b, self.h, self.r]
            .iter()
            .all(Option::is_none)
            && self.u.is_none()
    }
}

/// The largest state dimension and observed components the fixed-size path takes.
pub(super) const MAX_STATES: usize = 9;
/// See [`MAX_STATES`].
pub(super) const MAX_COMPONENTS: usize = 3;

/// Whether `model` is in the fixed-size path's range (`n ≤ 9`, `1 ≤ p ≤ 3`, `R`'s variances
/// non-negative: what the generic filter checks at each step; `R` is finite and symmetric from
/// the filter's own checks).
pub(super) fn fits(model: &ConstantModel<'_>) -> bool {
    let (p, n) = model.h.shape();
    (1..=MAX_STATES).contains(&n)
        && (1..=MAX_COMPONENTS).contains(&p)
        && model.r.diagonal().iter().all(|&v| v >= 0.0)
}

/// [`run_constant`] on `filter`'s estimate (its time advanced by the steps taken) over the
/// rows of `zs` from row `from` on, `step(k)` and `emit` with each row's index in `zs`; the
/// steps taken. Nothing is set up when row `from` has matrices of its own.
pub(super) fn run_from<'a>(
    model: &ConstantModel<'_>,
    filter: &mut Inner,
    zs: &[f64],
    from: usize,
    step: &impl Fn(usize) -> StepMatrices<'a>,
    emit: &mut impl FnMut(usize, BatchStep<'_>),
) -> usize {
    let p = model.h.nrows();
    if p == 0 || zs.len() < (from + 1) * p || !step(from).is_constant() {
        return 0;
    }
    let (x, cov, time) = filter.estimate_mut();
    let constant = |k| step(from + k).is_constant();
    let mut shifted = |k, s: BatchStep<'_>| emit(from + k, s);
    let taken = run_constant(model, x, cov, &zs[from * p..], constant, &mut shifted);
    *time += taken as f64;
    taken
}

/// Runs the rows of `zs` (`p` values each, NaN missing) from the estimate `state`, `covariance`
/// while `constant(k)` holds (step `k` takes the constant matrices), each step's results handed
/// to `emit`, the estimate advanced in place; returns the steps taken. It stops before the
/// first step it does not take (see the module's doc): the estimate is then that of the step
/// before. Zero when the model is out of range ([`fits`]).
pub(super) fn run_constant(
    model: &ConstantModel<'_>,
    state: &mut DVector<f64>,
    covariance: &mut DMatrix<f64>,
    zs: &[f64],
    constant: impl Fn(usize) -> bool,
    emit: &mut impl FnMut(usize, BatchStep<'_>),
) -> usize {
    if !fits(model) {
        return 0;
    }
    let n = model.f.nrows();
    unrolled_sizes!(n, N => run::<N>(model, state, covariance, zs, &constant, emit),
        _ => 0)
}

/// [`run_constant`] for `N` states.
fn run<const N: usize>(
    model: &ConstantModel<'_>,
    state: &mut DVector<f64>,
    covariance: &mut DMatrix<f64>,
    zs: &[f64],
    constant: &impl Fn(usize) -> bool,
    emit: &mut impl FnMut(usize, BatchStep<'_>),
) -> usize {
    let p = model.h.nrows();
    let (f, q) = (&model.f.as_slice()[..N * N], &model.q.as_slice()[..N * N]);
    let (h, r) = (model.h.as_slice(), model.r.as_slice());
    let mut w = Work::new(N, p);
    let mut g = [0.0; MAX_COMPONENTS];
    // The pattern of present components whose Mᵀ and R are in `w` (none yet).
    let mut pattern = usize::MAX;
    for (k, z) in zs.chunks_exact(p).enumerate() {
        if !constant(k) || z.iter().any(|v| v.is_infinite()) {
            return k;
        }
        // X_{n,n−1} = F X (each entry F_i0 x_0 + F_i1 x_1 + …, in order) and F S Fᵀ + Q.
        let (x, xp) = (state.as_slice(), w.x.as_mut_slice());
        for i in 0..N {
            xp[i] = f[i] * x[0];
        }
        for j in 1..N {
            for i in 0..N {
                xp[i] += f[i + j * N] * x[j];
            }
        }
        let carried = carry(
            Fixed::<N>,
            f,
            covariance.as_slice(),
            Some(q),
            &mut w.square,
            w.s.as_mut_slice(),
        );
        if !carried || !all_finite(w.x.as_slice()) {
            return k;
        }
        // H X for every component (the generic filter refuses a non-finite one, present or not).
        let xp = w.x.as_slice();
        for (a, g) in g[..p].iter_mut().enumerate() {
            *g = (0..N).map(|l| h[a + l * p] * xp[l]).sum();
        }
        if !all_finite(&g[..p]) {
            return k;
        }
        let present = z
            .iter()
            .enumerate()
            .fold(0, |m, (c, v)| m | (usize::from(!v.is_nan()) << c));
        if present != pattern {
            select(present, p, N, h, r, &mut w);
            pattern = present;
        }
        let kc = w.present.len();
        if kc == 0 {
            // The prediction alone, the step's estimate both predicted and updated.
            std::mem::swap(state, &mut w.x);
            std::mem::swap(covariance, &mut w.s);
            emit(
                k,
                BatchStep {
                    predicted_state: state.as_slice(),
                    predicted_covariance: covariance.as_slice(),
                    state: state.as_slice(),
                    covariance: covariance.as_slice(),
                    nis: f64::NAN,
                },
            );
            continue;
        }
        for (c, &a) in w.present.iter().enumerate() {
            w.nu[c] = z[a] - g[a];
        }
        let corrected = match kc {
            1 => correct_kernel(Fixed::<N>, Fixed::<1>, 1.0, false, &mut w),
            2 => correct_kernel(Fixed::<N>, Fixed::<2>, 1.0, false, &mut w),
            _ => correct_kernel(Fixed::<N>, Fixed::<3>, 1.0, false, &mut w),
        };
        let Ok((nis, log_det, finite_out)) = corrected else {
            return k;
        };
        let log_likelihood = -0.5 * (nis + log_det + kc as f64 * TAU.ln());
        if !(finite_out && nis.is_finite() && log_likelihood.is_finite()) {
            return k;
        }
        std::mem::swap(state, &mut w.x_out);
        std::mem::swap(covariance, &mut w.s_out);
        emit(
            k,
            BatchStep {
                predicted_state: w.x.as_slice(),
                predicted_covariance: w.s.as_slice(),
                state: state.as_slice(),
                covariance: covariance.as_slice(),
                nis,
            },
        );
    }
    zs.len() / p
}

/// The present components of `present` (a bit per component), `Mᵀ` of their rows of `H`
/// (`n × k`) and `R` on them (`k × k`) into `w`, as the generic filter's measurement and
/// correction lay them out.
fn select(present: usize, p: usize, n: usize, h: &[f64], r: &[f64], w: &mut Work) {
    w.present.clear();
    w.present
        .extend((0..p).filter(|&c| present & (1 << c) != 0));
    let k = w.present.len();
    for (c, &a) in w.present.iter().enumerate() {
        for (l, mt) in w.mt[c * n..(c + 1) * n].iter_mut().enumerate() {
            *mt = h[a + l * p];
        }
    }
    for (j, &b) in w.present.iter().enumerate() {
        for (i, &a) in w.present.iter().enumerate() {
            w.r[i + j * k] = r[a + b * p];
        }
    }
}
