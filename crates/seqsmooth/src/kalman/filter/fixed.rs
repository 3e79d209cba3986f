//! The Kalman filter's prediction and whole update on the polynomial model at compile-time
//! sizes, taken without the user asking: for [`PolynomialDynamics`](crate::model::dynamics::PolynomialDynamics)
//! (`Φ(ζ) = Ψ(ζ) ⊗ I_d`, (4.2.5)) of `n = (m + 1) d ≤ 9` states on `d ≤ 3` axes, with
//! [`WhiteNoiseDerivative`](crate::kalman::noise::WhiteNoiseDerivative)'s `Q(ζ)` ((15.2.23) in
//! closed form) or no driving noise, the prediction
//!
//! `X_{n,n−1} = Φ X_{n−1,n−1}` (12.2.15), `S_{n,n−1} = Φ S Φᵀ + Q` (12.2.16), (15.4.11)
//!
//! is one function compiled for each `(n, d)`: `Φ`'s entries `ζ^k/k!` are made once
//! ([`psi_term`](crate::model::transition::psi_term), the model's one formula) and `Φ`'s structural zeros are known to the
//! compiler, so that `Φ S Φᵀ` ([`carry_with`](crate::kalman::correct::carry_with), the generic path's kernel) has only the
//! products that are not zero, and `Q` is the noise model's own [`fill`](crate::kalman::noise::fill) with the degree a
//! constant. There are no calls through the model interfaces, no checks of what the filter
//! already holds (a finite state of the model's size), and no general loops over the axes.
//!
//! With a constant `M` ([`Observation::linear_matrix`]) of at most 3 rows, `R` the identity
//! or variances, at least one component present and no fading memory, the whole update
//! ((12.2.15)-(12.2.19), Joseph's form (12.3.7)) is one function compiled for each `n` and
//! each count `k` of present components ([`update`]; a fading filter takes the prediction
//! above and the generic correction): the measurement read once, the prediction, `G = M X_{n,n−1}`
//! and `ν`, and the correction, all on arrays of its own (`[[f64; N]; N]`) that the compiler
//! keeps in registers where it can, the estimate written to the filter once, without a swap;
//! what the path needs of the models (the polynomial model's degree and axes, the driving
//! noise's spectral density) is read once when they change ([`Plan`]), not through the model
//! interfaces (a virtual call for the noise) at each step. Whether every number is finite is
//! one sum of the results, not a test of each. `M = [I_p 0]` (`LinearObservation::value_of`,
//! or a position seen on each axis) with every component present is known when the models
//! are ([`Observed`]), and the update is compiled for it too: `G`, `S Mᵀ`, `M S Mᵀ` and
//! `X Mᵀ` are then entries and columns read in place, the products with `M`'s zeros and ones
//! left out (the generic path skips the zeros; `a · 1 = a`).
//!
//! Every number is the generic path's (`Dynamics::propagate_into`, `ProcessNoise::covariance_into`,
//! [`carry`](super::super::correct::carry), `Observation::predict_into`,
//! [`correct_kernel`](super::super::correct::correct_kernel)) **bit for bit**: each sum adds
//! the same terms in the same order (a skipped term is `0 · a` for a finite `a`, which adds
//! nothing to a sum; a sum started at `−0` rather than `+0` differs at most in a zero's sign,
//! and each result is made `+0` where it is `−0`: [`update`]'s doc; a state entry that
//! underflows to zero may be `−0` on the generic path and `+0` here, the only difference), tested on seeded random
//! models of every size in range, `M` random or of unit rows (`tests/kalman_fixed_path.rs`).
//! Anything not finite, or `V` not positive definite, stops this path before the filter
//! changes; the generic path then takes the step and gives its own error.

mod predict;

use super::super::correct::Work;
use super::{InnovationStats, KalmanFilter};
use crate::linalg::dense::{ldl, log_det};
use crate::model::dynamics::Dynamics;
use crate::model::measurement::{Measurement, NoiseCovariance};
use crate::model::observation::Observation;
use crate::numeric::unrolled::{unrolled_sizes, UNROLLED_MAX_SIZE};
use nalgebra::{DMatrix, DVector};
use predict::{predict, predict_exact};
use std::f64::consts::TAU;

/// The most axes with the path compiled for them.
const MAX_AXES: usize = 3;
/// The most components of a constant `M` the whole update takes at fixed size.
const MAX_COMPONENTS: usize = 3;

/// The fixed-size path's reading of the filter's models (what [`KalmanFilter::update_fixed`]
/// and [`KalmanFilter::predict_fixed`] need of them each step): made when first needed after
/// the dynamics or the driving noise change, so that a step makes no call through the model
/// interfaces (the driving noise's is a virtual call). Not saved: a restored filter makes it
/// again.
#[derive(Clone, Copy, Debug, Default)]
pub(super) enum Plan {
    /// Not made since the models last changed.
    #[default]
    Unknown,
    /// Not a model of the path: the generic recursion.
    Generic,
    /// The polynomial model of `degree` on `axes` axes, with `WhiteNoiseDerivative`'s spectral
    /// density `psd` of the same degree and axes or no driving noise (`None`), observed as
    /// `observed` says.
    Polynomial {
        degree: usize,
        axes: usize,
        psd: Option<f64>,
        observed: Observed,
    },
}

/// What the whole update at fixed size needs of the observation model (part of the [`Plan`]):
/// the rows `p` of its constant `M` ([`Observation::linear_matrix`]) when it has `n` columns,
/// at most [`MAX_COMPONENTS`] rows and as many as the model's components (`0`: the update
/// is not taken at fixed size), and whether `M = [I_p 0]` (each row `a` the state's
/// component `a`: `LinearObservation::value_of`, a position seen on each axis).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Observed {
    components: usize,
    unit: bool,
}

impl<D: Dynamics, O: Observation> KalmanFilter<D, O> {
    /// The degree, axes and driving noise's spectral density (`None`: no driving noise) of a
    /// polynomial model in the path's range, the filter's state of its size; `None` otherwise
    /// (the [`Plan`], made if it is not).
    pub(super) fn fixed_model(&mut self) -> Option<(usize, usize, Option<f64>)> {
        if matches!(self.plan, Plan::Unknown) {
            self.plan = self.make_plan();
        }
        match self.plan {
            Plan::Polynomial {
                degree, axes, psd, ..
            } => Some((degree, axes, psd)),
            _ => None,
        }
    }

    /// The [`Plan`] of the filter's models.
    fn make_plan(&self) -> Plan {
        let Some(model) = self.dynamics.polynomial() else {
            return Plan::Generic;
        };
        let (m, d) = (model.degree(), model.axes());
        let psd = match &self.noise {
            None => None,
            Some(noise) => match noise.white_noise_derivative().map(|q| q.parts()) {
                Some((degree, axes, psd)) if degree == m && axes == d => Some(psd),
                _ => return Plan::Generic,
            },
        };
        let n = (m + 1) * d;
        let observed = match self.observation.linear_matrix() {
            Some(model)
                if model.ncols() == n
                    && model.nrows() <= MAX_COMPONENTS
                    && model.nrows() == self.observation.components() =>
            {
                // Exactly `1` and `+0` (by their bits: a `−0` entry gives `−0·x` terms whose
                // sign the pattern's update would not reproduce).
                let unit = |(l, a): (usize, usize)| {
                    model[(a, l)].to_bits() == if a == l { 1.0f64 } else { 0.0 }.to_bits()
                };
                Observed {
                    components: model.nrows(),
                    unit: model.nrows() <= n
                        && (0..n)
                            .flat_map(|l| (0..model.nrows()).map(move |a| (l, a)))
                            .all(unit),
                }
            }
            _ => Observed::default(),
        };
        if n <= UNROLLED_MAX_SIZE && d <= MAX_AXES && self.state.len() == n {
            Plan::Polynomial {
                degree: m,
                axes: d,
                psd,
                observed,
            }
        } else {
            Plan::Generic
        }
    }

    /// The prediction to `t` (not the filter's time) into the work buffers on the fixed-size
    /// path (the module's doc): `X_{n,n−1}`, `Φ`, `Q`, `S_{n,n−1}` and the fading `P`; `false`
    /// when the model is not in its range or a number is not finite (nothing of the filter
    /// changed: the generic path takes the step).
    pub(super) fn predict_fixed(&mut self, t: f64) -> bool {
        let Some((m, d, psd)) = self.fixed_model() else {
            return false;
        };
        let n = (m + 1) * d;
        let zeta = t - self.time;
        let fading = self.fading.as_ref().map(|f| f.weight.as_slice());
        let from = (self.state.as_slice(), self.covariance.as_slice(), fading);
        let w = &mut self.work;
        unrolled_sizes!(n, N => match d {
                1 => predict::<N, 1>(zeta, psd, from, w),
                2 => N.is_multiple_of(2) && predict::<N, 2>(zeta, psd, from, w),
                _ => N.is_multiple_of(3) && predict::<N, 3>(zeta, psd, from, w),
            },
            _ => false)
    }

    /// The whole update on the fixed-size path, prediction and correction in one function
    /// compiled for each state size and count of present components (the module's doc): the
    /// filter's new estimate and time, and in the work buffers what the caller reads of what
    /// the generic path leaves there (with `prediction` the prediction `X_{n,n−1}`,
    /// `S_{n,n−1}` and `Φ`; with `innovation` what an [`Innovation`](super::Innovation)
    /// reads); the statistics. `None`, the filter unchanged,
    /// for the generic path: a model out of range, a constant `M` of more than
    /// [`MAX_COMPONENTS`] rows, no component present, `R` other than the identity or
    /// variances, fading memory, or anything the generic path would refuse.
    pub(super) fn update_fixed(
        &mut self,
        m: &Measurement,
        innovation: bool,
        prediction: bool,
    ) -> Option<InnovationStats> {
        if self.fading.is_some() {
            return None;
        }
        if matches!(self.plan, Plan::Unknown) {
            self.plan = self.make_plan();
        }
        let Plan::Polynomial {
            degree,
            axes,
            psd,
            observed: Observed {
                components: p,
                unit,
            },
        } = self.plan
        else {
            return None;
        };
        let n = (degree + 1) * axes;
        let t = m.time;
        if p == 0 || m.values.len() != p || !t.is_finite() {
            return None;
        }
        // The plan has checked `M`'s shape against the model's components and `n`.
        let model = self.observation.linear_matrix()?;
        // A user's model whose `M` changed shape since the plan was made takes the general
        // path, which checks it, rather than indexing past it.
        if model.len() != p * n {
            return None;
        }
        let seen = match p {
            1 => read::<1>(m, model),
            2 => read::<2>(m, model),
            _ => read::<3>(m, model),
        }?;
        // `M = [I_p 0]` with every component present: row `c` of `M` is component `c`.
        let unit = unit && seen.k == p;
        let step = (t != self.time).then_some(t - self.time);
        let estimate = (&mut self.state, &mut self.covariance);
        let observation = &self.observation;
        let residual = |a: usize, y: f64, g: f64| observation.residual(a, y, g);
        let w = &mut self.work;
        let how = (step, psd);
        let keep = (innovation, prediction);
        let stats = unrolled_sizes!(n, N => match (seen.k, unit) {
                (0, _) => None,
                (1, false) => update::<N, 1, false>(axes, how, estimate, (&seen, residual), w, keep),
                (1, true) => update::<N, 1, true>(axes, how, estimate, (&seen, residual), w, keep),
                (2, false) => update::<N, 2, false>(axes, how, estimate, (&seen, residual), w, keep),
                (2, true) => update::<N, 2, true>(axes, how, estimate, (&seen, residual), w, keep),
                (_, false) => update::<N, 3, false>(axes, how, estimate, (&seen, residual), w, keep),
                (_, true) => update::<N, 3, true>(axes, how, estimate, (&seen, residual), w, keep),
            },
            _ => None)?;
        self.time = t;
        Some(stats)
    }
}

/// A measurement as the fixed-size update reads it: the constant `M` (`p × n`), the `k`
/// present components, their values and their variances (`R`'s diagonal on them).
struct Seen<'a> {
    model: Option<&'a DMatrix<f64>>,
    present: [usize; MAX_COMPONENTS],
    values: [f64; MAX_COMPONENTS],
    variances: [f64; MAX_COMPONENTS],
    k: usize,
}

/// The measurement `m` of `P` components as `measure` reads it, with the model's `M` (`model`):
/// the present components, their values and variances; `None` (for the generic
/// path) unless it has `P` values, `R` is the identity or `P` variances, every variance is
/// finite and not negative (as `measure` checks the whole `R`) and every present value
/// finite. Every check at once, `P` a constant (the loops unrolled, no bounds tests).
#[inline(always)]
fn read<'a, const P: usize>(m: &Measurement, model: &'a DMatrix<f64>) -> Option<Seen<'a>> {
    let values: &[Option<f64>; P] = m.values.as_slice().try_into().ok()?;
    let variances: [f64; P] = match &m.noise {
        NoiseCovariance::Identity => [1.0; P],
        NoiseCovariance::Variances(v) => *<&[f64; P]>::try_from(v.as_slice()).ok()?,
        NoiseCovariance::Full(_) => return None,
    };
    let mut seen = Seen {
        model: Some(model),
        present: [0; MAX_COMPONENTS],
        values: [0.0; MAX_COMPONENTS],
        variances: [1.0; MAX_COMPONENTS],
        k: 0,
    };
    // Finite by one sum (an infinity or NaN makes it so; a finite sum that overflows only
    // sends the step to the generic path, which reads the same numbers), not negative by a
    // comparison each: float arithmetic, no tests of each number's class.
    let (mut sum, mut negative) = (0.0, false);
    for c in 0..P.min(MAX_COMPONENTS) {
        let variance = variances[c];
        sum += variance;
        negative |= variance < 0.0;
        if let Some(v) = values[c] {
            sum += v;
            let k = seen.k.min(c);
            (seen.present[k], seen.values[k], seen.variances[k]) = (c, v, variance);
            seen.k = k + 1;
        }
    }
    (sum.is_finite() && !negative).then_some(seen)
}

/// `N × N`, column-major: `m[j][i]` is the entry `(i, j)`.
type Square<const N: usize> = [[f64; N]; N];

/// [`KalmanFilter::update_fixed`] for `N` states on `axes` axes with `K` components present:
/// the prediction over `step` ([`predict_exact`]; `None`: no step, the estimate as it is),
/// `G = M X_{n,n−1}` (each row's sum over the columns in order, as
/// [`linear_value`](crate::model::observation::linear_value)), `ν` by the model's `residual`,
/// and the correction ((12.2.17)-(12.2.19), Joseph's form (12.3.7)), all on arrays of this
/// function; only when every number is finite and `V` positive definite, the results are
/// written once: the estimate into `estimate`, and into `w` what the caller reads (`keep`):
/// what an `Innovation` reads, and the prediction with its `Φ` (`Φ` written as it is made).
/// The statistics, or `None` (nothing written but `Φ`, which the generic path writes again).
///
/// The correction is [`correct_in`](super::super::correct::correct_in)'s with no fading,
/// operation for operation: each sum over the same terms in the same order, with two
/// differences that change no result. The generic path skips the products with a zero of `M`
/// or `Φ` (and adds those with `R`'s zeros off the diagonal); for a finite `a`, `0 · a` is
/// `±0`, which adds nothing to a sum. And its sums start at `+0` where these start at `−0`
/// (which the compiler drops: `−0 + a = a`): an intermediate zero's sign can then differ,
/// and a zero's sign changes only the sign of a zero it reaches through `+`, `−`, `·` and
/// `/` by a pivot (`0 + a = a` for `a ≠ 0`), so each result is the generic path's or a zero
/// of the other sign; the generic path's results are never `−0` (a sum from `+0` is not; barring
/// a result that underflows to zero), and
/// each result here is made `+0` where it is `−0` (`a + 0`) before it is written. For the
/// covariance that `a + 0` is on `(H R) Hᵀ`, off the chain from one covariance to the next
/// (`S_{n,n−1}`'s is where the prediction is written out, [`predict_exact`]): then
/// `(X' − Y Hᵀ) + (H R) Hᵀ` is never `−0` (an add is `−0` only when both terms are), nor is
/// the sum of two such entries, and each entry is the generic path's (whose `(H R) Hᵀ`, from
/// `+0`, is never `−0` either), its symmetrized `(a + b) / 2` too, an underflow to zero
/// included.
///
/// `U = S Mᵀ`, `V = M U + R` symmetrized, `V = L D Lᵀ` ([`ldl`]), `H = U L⁻ᵀ D⁻¹ L⁻¹`,
/// `NIS = Σ z_c² / D_c` (`z = L⁻¹ ν`), `X = H ν + X_{n,n−1}`, and Joseph's
/// `X' = S − H (M S)`, `Y = X' Mᵀ`, `S = (X' − Y Hᵀ) + (H R) Hᵀ` symmetrized. Whether every
/// number is finite is one sum of the results (an infinity or NaN makes the sum infinite or
/// NaN; a finite sum that overflows only sends the step to the generic path): a non-finite
/// `Φ`, `Q` or entry of the prediction reaches the same entry of the update
/// (`X_{n,n−1} + …`, `S_{n,n−1} − …`), so the update's sum covers them. The log-likelihood
/// `−(NIS + ln det V + K ln 2π)/2` is finite when the NIS is below `10³⁰⁰` and each pivot
/// finite (then `|ln D_c| ≤ 745`): tested before the results are written, the logarithm
/// taken after them, so that no number is held across its call.
// The loops index by position on purpose: each sum in the kernel's order, over arrays whose
// sizes are constants (the loops unroll).
#[allow(clippy::needless_range_loop)]
#[inline(never)]
fn update<const N: usize, const K: usize, const UNIT: bool>(
    axes: usize,
    (step, psd): (Option<f64>, Option<f64>),
    (state, covariance): (&mut DVector<f64>, &mut DMatrix<f64>),
    (seen, residual): (&Seen<'_>, impl Fn(usize, f64, f64) -> f64),
    w: &mut Work,
    (innovation, prediction): (bool, bool),
) -> Option<InnovationStats> {
    if UNIT && K > N {
        // `M = [I_K 0]` has at least as many columns as rows (never called so).
        return None;
    }
    let (x, s) = (&state.as_slice()[..N], &covariance.as_slice()[..N * N]);
    let mut xp: [f64; N] = std::array::from_fn(|i| x[i]);
    let mut sp: Square<N> = std::array::from_fn(|j| std::array::from_fn(|i| s[i + j * N]));
    if let Some(zeta) = step {
        let phi = prediction.then(|| &mut w.phi.as_mut_slice()[..N * N]);
        match axes {
            1 => predict_exact::<N, 1>(zeta, psd, &mut xp, &mut sp, phi),
            2 if N.is_multiple_of(2) => predict_exact::<N, 2>(zeta, psd, &mut xp, &mut sp, phi),
            3 if N.is_multiple_of(3) => predict_exact::<N, 3>(zeta, psd, &mut xp, &mut sp, phi),
            _ => return None,
        }
    }
    // G = M X_{n,n−1}, every row (the generic path checks them all), each from −0 as
    // `Iterator::sum`.
    let model = seen.model.map_or(&[][..], |m| m.as_slice());
    let p = model.len() / N;
    let mut check = 0.0;
    let mut g = [0.0; MAX_COMPONENTS];
    if UNIT {
        // M = [I_K 0] (K = p, every component present): G_a = x_a, summed as the general
        // path does (from −0, with the `0·x_l` terms: they set the sign of a zero and carry a
        // NaN), so the innovation is its bits too.
        for a in 0..K {
            let mut acc = -0.0;
            for (l, x) in xp.iter().enumerate() {
                acc += if l == a { *x } else { 0.0 * x };
            }
            g[a] = acc;
            check += acc;
        }
    } else {
        for (a, g) in g.iter_mut().enumerate().take(p) {
            let mut acc = -0.0;
            for l in 0..N {
                acc += model[a + l * p] * xp[l];
            }
            *g = acc;
            check += acc;
        }
    }
    // Mᵀ (`mt[c]` row `present[c]` of `M`), `ν` and `R`'s diagonal on the present components.
    let mut mt = [[0.0; N]; K];
    let (mut nu, mut rd) = ([0.0; K], [0.0; K]);
    for c in 0..K {
        let a = if UNIT { c } else { seen.present[c] };
        for l in 0..N {
            mt[c][l] = if UNIT {
                if l == c {
                    1.0
                } else {
                    0.0
                }
            } else {
                model[a + l * p]
            };
        }
        nu[c] = residual(a, seen.values[c], g[a]);
        rd[c] = seen.variances[c];
    }
    // U = S Mᵀ.
    let u = times_mt::<N, K, UNIT>(&sp, &mt);
    // V = M U + R, symmetrized, and V = L D Lᵀ.
    let mut v = [[0.0; K]; K];
    for b in 0..K {
        for a in 0..K {
            let mut msm = -0.0;
            for l in 0..N {
                if !UNIT || l == a {
                    msm += mt[a][l] * u[b][l];
                }
            }
            v[b][a] = if a == b { msm + rd[a] } else { msm };
        }
    }
    for j in 0..K {
        for i in j + 1..K {
            let value = (v[j][i] + v[i][j]) * 0.5;
            v[j][i] = value;
            v[i][j] = value;
        }
    }
    let mut lv = [[0.0; K]; K];
    if !ldl(K, v.as_flattened(), lv.as_flattened_mut()) {
        return None;
    }
    // H = U L⁻ᵀ D⁻¹ L⁻¹: forwards, each column by its pivot, backwards.
    let mut h = u;
    for c in 0..K {
        for d in 0..c {
            let l = lv[d][c];
            for i in 0..N {
                h[c][i] -= l * h[d][i];
            }
        }
    }
    for c in 0..K {
        let pivot = lv[c][c];
        for i in 0..N {
            h[c][i] /= pivot;
        }
    }
    for c in (0..K).rev() {
        for d in c + 1..K {
            let l = lv[c][d];
            for i in 0..N {
                h[c][i] -= l * h[d][i];
            }
        }
    }
    // NIS = Σ z_c² / D_c, z = L⁻¹ ν.
    let (mut nis, mut z) = (0.0, [0.0; K]);
    for c in 0..K {
        let mut acc = nu[c];
        for d in 0..c {
            acc -= lv[d][c] * z[d];
        }
        z[c] = acc;
        nis += acc * acc / lv[c][c];
    }
    let mut x_out = [0.0; N];
    for i in 0..N {
        let mut acc = -0.0;
        for c in 0..K {
            acc += h[c][i] * nu[c];
        }
        x_out[i] = (acc + xp[i]) + 0.0;
        check += x_out[i];
    }
    // Joseph's form: X' = S − H (M S), Y = X' Mᵀ, H R, then (X' − Y Hᵀ) + (H R) Hᵀ.
    let mut xs = sp;
    for j in 0..N {
        for i in 0..N {
            let mut acc = -0.0;
            for c in 0..K {
                acc += h[c][i] * u[c][j];
            }
            xs[j][i] = sp[j][i] - acc;
        }
    }
    let y = times_mt::<N, K, UNIT>(&xs, &mt);
    let mut hr = [[0.0; N]; K];
    for d in 0..K {
        for i in 0..N {
            hr[d][i] = h[d][i] * rd[d];
        }
    }
    let mut s_out = [[0.0; N]; N];
    for j in 0..N {
        for i in 0..N {
            let (mut yh, mut hrh) = (-0.0, -0.0);
            for c in 0..K {
                yh += y[c][i] * h[c][j];
            }
            for d in 0..K {
                hrh += hr[d][i] * h[d][j];
            }
            // `+ 0` here (never `−0` after it), not on the result: off the chain.
            s_out[j][i] = (xs[j][i] - yh) + (hrh + 0.0);
        }
    }
    for j in 0..N {
        check += s_out[j][j];
        for i in j + 1..N {
            let value = (s_out[j][i] + s_out[i][j]) * 0.5;
            s_out[j][i] = value;
            s_out[i][j] = value;
            check += value;
        }
    }
    // The log-likelihood is finite when the NIS is below 10³⁰⁰ and each pivot finite (each
    // `ln D_c` of a positive finite pivot is within ±745): checked before the results are
    // written, the logarithm taken after (no values held across its call).
    let pivots_finite = (0..K).all(|c| lv[c][c] < f64::INFINITY);
    if !(check.is_finite() && nis < 1e300 && pivots_finite) {
        return None;
    }
    // The results, once: the estimate, the prediction (which the smoothers read), and what an
    // `Innovation` reads.
    state.as_mut_slice()[..N].copy_from_slice(&x_out);
    covariance.as_mut_slice()[..N * N].copy_from_slice(s_out.as_flattened());
    if prediction {
        w.x.as_mut_slice()[..N].copy_from_slice(&xp);
        // `S_{n,n−1}` made `+0` where it is `−0` here, off the chain ([`predict_exact`]);
        // with no step it is the covariance as it was, copied unchanged (as the generic
        // path's `predict_work` copies it).
        let zero = if step.is_some() { 0.0 } else { -0.0 };
        for (to, s) in w.s.as_mut_slice()[..N * N]
            .iter_mut()
            .zip(sp.as_flattened())
        {
            *to = s + zero;
        }
    }
    if innovation {
        w.present.clear();
        w.present.extend_from_slice(&seen.present[..K]);
        w.nu[..K].copy_from_slice(&nu);
        for (to, v) in w.v[..K * K].iter_mut().zip(v.as_flattened()) {
            *to = v + 0.0;
        }
        for (to, h) in w.h[..N * K].iter_mut().zip(h.as_flattened()) {
            *to = h + 0.0;
        }
    }
    let log_likelihood = -0.5 * (nis + log_det(K, lv.as_flattened()) + K as f64 * TAU.ln());
    Some(InnovationStats {
        components: K,
        nis,
        log_likelihood,
    })
}

/// `A Mᵀ` from `M`'s rows: `out[c][r] = Σ_l a[l][r] · mt[c][l]`, each sum from `−0` over `l`
/// ascending (the order of the generic path's product, [`update`]'s doc on `−0`). With
/// `UNIT` (`M = [I_K 0]`) only the term `l = c`, `a[c][r] · 1` (the generic path skips `M`'s
/// zeros; `−0 + a · 1 = a`): column `c` of `A`.
#[inline(always)]
fn times_mt<const N: usize, const K: usize, const UNIT: bool>(
    a: &[[f64; N]; N],
    mt: &[[f64; N]; K],
) -> [[f64; N]; K] {
    if UNIT {
        return std::array::from_fn(|c| a[c]);
    }
    let mut out = [[-0.0; N]; K];
    for c in 0..K {
        for l in 0..N {
            for r in 0..N {
                out[c][r] += a[l][r] * mt[c][l];
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::discount::Discount;
    use crate::kalman::noise::WhiteNoiseDerivative;
    use crate::model::dynamics::PolynomialDynamics;
    use crate::model::observation::LinearObservation;
    use nalgebra::DVector;

    /// The path is taken (not silently left to the generic one) for every polynomial model
    /// in range, with and without driving noise and fading, and not outside the range or
    /// with a noise of another model: the equality tests of `tests/kalman_fixed_path.rs`
    /// could not tell.
    #[test]
    fn taken_in_range_and_only_there() {
        for axes in 1..=4 {
            for degree in 0..=8 {
                let n = (degree + 1) * axes;
                let mut f = KalmanFilter::new(
                    PolynomialDynamics::new(degree, axes),
                    LinearObservation::value_of(n),
                    DVector::from_element(n, 0.5),
                    DMatrix::identity(n, n),
                    0.0,
                )
                .unwrap();
                let in_range = n <= UNROLLED_MAX_SIZE && axes <= MAX_AXES;
                assert_eq!(f.predict_fixed(0.7), in_range, "m = {degree}, d = {axes}");
                let q = WhiteNoiseDerivative::new(degree, axes, 0.3).unwrap();
                f.set_process_noise(q).unwrap();
                f.set_fading(Discount::PerUpdate { theta: 0.9 }).unwrap();
                assert_eq!(f.predict_fixed(-1.3), in_range, "m = {degree}, d = {axes}");
                // The same state count from another degree and axes: not this model's `Q`.
                if axes == 1 && degree % 2 == 1 {
                    let other = WhiteNoiseDerivative::new((degree - 1) / 2, 2, 0.3).unwrap();
                    f.set_process_noise(other).unwrap();
                    assert!(!f.predict_fixed(0.7), "m = {degree}: a noise on 2 axes");
                }
            }
        }
    }
    /// The whole update at fixed size is taken (and made the filter's) for every polynomial
    /// model in range with a constant `M` of 1-3 rows, with and without driving noise, over a
    /// step (forwards or backwards) or none, and not with 4 rows, a full `R`, no component present, fading
    /// memory, or out of range (where
    /// `tests/kalman_fixed_path.rs`'s equalities could not tell a silent fallback).
    #[test]
    fn whole_update_taken_in_range_and_only_there() {
        use crate::model::measurement::{Measurement, NoiseCovariance};
        for axes in 1..=4 {
            for degree in 0..=8 {
                let n = (degree + 1) * axes;
                let in_range = n <= UNROLLED_MAX_SIZE && axes <= MAX_AXES;
                for p in 1..=4 {
                    let m = DMatrix::from_fn(p, n, |r, c| if r == c % p { 1.0 } else { 0.5 });
                    let mut f = KalmanFilter::new(
                        PolynomialDynamics::new(degree, axes),
                        LinearObservation::new(m).unwrap(),
                        DVector::from_element(n, 0.5),
                        DMatrix::identity(n, n),
                        0.0,
                    )
                    .unwrap();
                    let row = |time: f64, noise: NoiseCovariance| Measurement {
                        time,
                        values: (0..p).map(|c| (c != 1).then_some(0.3)).collect(),
                        noise,
                    };
                    let taken = in_range && p <= MAX_COMPONENTS;
                    let what = format!("m = {degree}, d = {axes}, p = {p}");
                    let variances = NoiseCovariance::Variances(vec![0.25; p]);
                    assert_eq!(
                        f.update_fixed(&row(0.7, variances), false, true).is_some(),
                        taken,
                        "{what}"
                    );
                    let q = WhiteNoiseDerivative::new(degree, axes, 0.3).unwrap();
                    f.set_process_noise(q).unwrap();
                    assert_eq!(
                        f.update_fixed(&row(-1.3, NoiseCovariance::Identity), true, true)
                            .is_some(),
                        taken,
                        "{what}"
                    );
                    // The path commits its update: the filter is now at −1.3.
                    assert_eq!(f.time(), if taken { -1.3 } else { 0.0 }, "{what}");
                    let now = f.time();
                    assert_eq!(
                        f.update_fixed(&row(now, NoiseCovariance::Identity), true, true)
                            .is_some(),
                        taken,
                        "{what}: no step"
                    );
                    let full = NoiseCovariance::Full(DMatrix::identity(p, p));
                    assert!(
                        f.update_fixed(&row(0.7, full), false, true).is_none(),
                        "{what}: full R"
                    );
                    let none = Measurement {
                        time: 0.7,
                        values: vec![None; p],
                        noise: NoiseCovariance::Identity,
                    };
                    assert!(
                        f.update_fixed(&none, false, true).is_none(),
                        "{what}: nothing present"
                    );
                    f.set_fading(Discount::PerUpdate { theta: 0.9 }).unwrap();
                    assert!(
                        f.update_fixed(&row(0.7, NoiseCovariance::Identity), false, true)
                            .is_none(),
                        "{what}: fading"
                    );
                }
            }
        }
    }
}
