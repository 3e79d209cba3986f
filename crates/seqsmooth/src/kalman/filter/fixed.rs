//! The Kalman filter's prediction and whole update on the polynomial model at compile-time
//! sizes, taken without the user asking: for [`PolynomialDynamics`](crate::model::dynamics::PolynomialDynamics)
//! (`Φ(ζ) = Ψ(ζ) ⊗ I_d`, (4.2.5)) of `n = (m + 1) d ≤ 9` states on `d ≤ 3` axes, with
//! [`WhiteNoiseDerivative`](crate::kalman::noise::WhiteNoiseDerivative)'s `Q(ζ)` ((15.2.23) in
//! closed form) or no driving noise, the prediction
//!
//! `X_{n,n−1} = Φ X_{n−1,n−1}` (12.2.15), `S_{n,n−1} = Φ S Φᵀ + Q` (12.2.16), (15.4.11)
//!
//! is one function compiled for each `(n, d)`: `Φ`'s entries `ζ^k/k!` are made once
//! ([`psi_term`], the model's one formula) and `Φ`'s structural zeros are known to the
//! compiler, so that `Φ S Φᵀ` ([`carry_with`], the generic path's kernel) has only the
//! products that are not zero, and `Q` is the noise model's own [`fill`] with the degree a
//! constant. There are no calls through the model interfaces, no checks of what the filter
//! already holds (a finite state of the model's size), and no general loops over the axes.
//!
//! With a constant `M` ([`Observation::linear_matrix`]) of at most 3 rows, `R` the identity
//! or variances, at least one component present and no fading memory, the whole update
//! ((12.2.15)-(12.2.19), Joseph's form (12.3.7)) is one function compiled for each `n`
//! ([`update`]; a fading filter takes the prediction above and the generic correction): the measurement
//! read once, the prediction, `G = M X_{n,n−1}` and `ν`, and the generic path's correction
//! ([`correct_in`]) with the present components `k` a constant, all on arrays of its own that
//! the compiler keeps in registers, the results written to the filter's buffers once; no
//! `DMatrix` is read or written inside the arithmetic, and the checks are those the generic
//! path makes, once each.
//!
//! Every number is the generic path's (`Dynamics::propagate_into`, `ProcessNoise::covariance_into`,
//! [`carry`](super::super::correct::carry), `Observation::predict_into`,
//! [`correct_kernel`](super::super::correct::correct_kernel)) **bit for bit**: each sum adds
//! the same terms in the same order (a skipped term is `0 · a` for a finite `a`, which adds
//! nothing to a sum that started at `+0`), tested on seeded random models of every size in
//! range (`tests/kalman_fixed_path.rs`). Anything not finite, or `V` not positive definite,
//! stops this path before the filter changes; the generic path then takes the step and gives
//! its own error.

use super::super::correct::{carry_with, correct_in, Buffers, Work};
use super::{InnovationStats, KalmanFilter};
use crate::kalman::noise::fill;
use crate::linalg::dense::all_finite;
use crate::model::dynamics::Dynamics;
use crate::model::measurement::{Measurement, NoiseCovariance};
use crate::model::observation::{linear_value, Observation};
use crate::model::transition::psi_term;
use crate::numeric::unrolled::{unrolled_sizes, Fixed, Quotient, UNROLLED_MAX_SIZE};
use nalgebra::DMatrix;
use std::f64::consts::TAU;

/// The most axes with the path compiled for them.
const MAX_AXES: usize = 3;
/// The most components of a constant `M` the whole update takes at fixed size.
const MAX_COMPONENTS: usize = 3;

impl<D: Dynamics, O: Observation> KalmanFilter<D, O> {
    /// The degree, axes and driving noise's spectral density (`None`: no driving noise) of a
    /// polynomial model in the path's range, the filter's state of its size; `None` otherwise.
    fn fixed_model(&self) -> Option<(usize, usize, Option<f64>)> {
        let model = self.dynamics.polynomial()?;
        let (m, d) = (model.degree(), model.axes());
        let psd = match &self.noise {
            None => None,
            Some(noise) => match noise.white_noise_derivative().map(|q| q.parts()) {
                Some((degree, axes, psd)) if degree == m && axes == d => Some(psd),
                _ => return None,
            },
        };
        let n = (m + 1) * d;
        (n <= UNROLLED_MAX_SIZE && d <= MAX_AXES && self.state.len() == n).then_some((m, d, psd))
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
    /// compiled for each state size (the module's doc), into the work buffers as the generic
    /// path leaves them (the prediction `X_{n,n−1}`, `S_{n,n−1}`, `Φ`; with `innovation` what
    /// an [`Innovation`](super::Innovation) reads; the updated estimate), the filter unchanged:
    /// the statistics, or `None` for the generic path (a model out of range, a constant `M`
    /// of more than [`MAX_COMPONENTS`] rows, no component present, `R` other than the
    /// identity or variances, or anything the generic path would refuse).
    pub(super) fn update_fixed(
        &mut self,
        m: &Measurement,
        innovation: bool,
    ) -> Option<InnovationStats> {
        if self.fading.is_some() {
            return None;
        }
        let (degree, axes, psd) = self.fixed_model()?;
        let n = (degree + 1) * axes;
        let model = self.observation.linear_matrix()?;
        let p = model.nrows();
        let t = m.time;
        if model.ncols() != n || p > MAX_COMPONENTS || m.values.len() != p || !t.is_finite() {
            return None;
        }
        // The measurement as `measure` reads it: the present components, their values and
        // variances.
        let mut seen = Seen {
            model,
            present: [0; MAX_COMPONENTS],
            values: [0.0; MAX_COMPONENTS],
            variances: [1.0; MAX_COMPONENTS],
            k: 0,
        };
        for (c, v) in m.values.iter().enumerate() {
            if let Some(v) = *v {
                if !v.is_finite() {
                    return None;
                }
                (seen.present[seen.k], seen.values[seen.k]) = (c, v);
                seen.k += 1;
            }
        }
        match &m.noise {
            NoiseCovariance::Identity => {}
            NoiseCovariance::Variances(v)
                if v.len() == p && v.iter().all(|v| (0.0..f64::INFINITY).contains(v)) =>
            {
                for c in 0..seen.k {
                    seen.variances[c] = v[seen.present[c]];
                }
            }
            _ => return None,
        }
        if seen.k == 0 {
            return None;
        }
        let step = (t != self.time).then_some(t - self.time);
        let from = (self.state.as_slice(), self.covariance.as_slice());
        let observation = &self.observation;
        let residual = |a: usize, y: f64, g: f64| observation.residual(a, y, g);
        let w = &mut self.work;
        let (nis, log_det) = unrolled_sizes!(n, N =>
            update::<N>(axes, (step, psd), from, (&seen, residual), w, innovation),
            _ => None)?;
        let log_likelihood = -0.5 * (nis + log_det + seen.k as f64 * TAU.ln());
        (nis.is_finite() && log_likelihood.is_finite()).then_some(InnovationStats {
            components: seen.k,
            nis,
            log_likelihood,
        })
    }
}

/// A measurement as the fixed-size update reads it: the constant `M` (`p × n`), the `k`
/// present components, their values and their variances (`R`'s diagonal on them).
struct Seen<'a> {
    model: &'a DMatrix<f64>,
    present: [usize; MAX_COMPONENTS],
    values: [f64; MAX_COMPONENTS],
    variances: [f64; MAX_COMPONENTS],
    k: usize,
}

/// The largest `n × n` the path holds.
const SQUARE: usize = UNROLLED_MAX_SIZE * UNROLLED_MAX_SIZE;
/// The largest `n × k` the path holds.
const TALL: usize = UNROLLED_MAX_SIZE * MAX_COMPONENTS;

/// [`KalmanFilter::update_fixed`] for `N` states on `axes` axes: the prediction over `step`
/// ([`predict_in`]; `None`: no step, the estimate as it is), `G = M X_{n,n−1}`
/// ([`linear_value`], the generic path's), `ν` by the model's `residual`, `Mᵀ` and `R` of the
/// present components, and [`correct_in`] with `k` a constant, all on arrays of this function
/// (which the compiler keeps in registers), the results then written to `w` once: `NIS` and
/// `ln det V`, or `None` where a number is not finite or `V` not positive definite.
#[inline(never)]
fn update<const N: usize>(
    axes: usize,
    (step, psd): (Option<f64>, Option<f64>),
    (x, s): (&[f64], &[f64]),
    (seen, residual): (&Seen<'_>, impl Fn(usize, f64, f64) -> f64),
    w: &mut Work,
    innovation: bool,
) -> Option<(f64, f64)> {
    let (mut xp, mut sp) = ([0.0; UNROLLED_MAX_SIZE], [0.0; SQUARE]);
    let (xp, sp) = (&mut xp[..N], &mut sp[..N * N]);
    let (mut q, mut square) = ([0.0; SQUARE], [0.0; SQUARE]);
    match step {
        Some(zeta) => {
            let from = (x, s, None);
            let (phi, q, square) = (&mut w.phi.as_mut_slice()[..N * N], &mut q, &mut square);
            let into: (&mut [f64], &mut [f64], &mut [f64]) = (&mut *xp, &mut *sp, &mut []);
            let predicted = match axes {
                1 => predict_in::<N, 1>(zeta, psd, from, phi, q, square, into),
                2 => {
                    N.is_multiple_of(2) && predict_in::<N, 2>(zeta, psd, from, phi, q, square, into)
                }
                _ => {
                    N.is_multiple_of(3) && predict_in::<N, 3>(zeta, psd, from, phi, q, square, into)
                }
            };
            if !predicted {
                return None;
            }
        }
        None => {
            xp.copy_from_slice(&x[..N]);
            sp.copy_from_slice(&s[..N * N]);
        }
    }
    let (p, k) = (seen.model.nrows(), seen.k);
    let mut g = [0.0; MAX_COMPONENTS];
    linear_value(seen.model, xp, &mut g);
    if !all_finite(&g[..p]) {
        return None;
    }
    let model = &seen.model.as_slice()[..p * N];
    let (mut mt, mut nu, mut r) = ([0.0; TALL], [0.0; MAX_COMPONENTS], [0.0; 9]);
    for c in 0..k {
        let a = seen.present[c];
        for l in 0..N {
            mt[l + c * N] = model[a + l * p];
        }
        nu[c] = residual(a, seen.values[c], g[a]);
        r[c + c * k] = seen.variances[c];
    }
    let (mut u, mut h, mut y, mut hr) = ([0.0; TALL], [0.0; TALL], [0.0; TALL], [0.0; TALL]);
    let (mut v, mut lv) = ([0.0; 9], [0.0; 9]);
    let (mut z, mut column) = ([0.0; MAX_COMPONENTS], [0.0; UNROLLED_MAX_SIZE]);
    let (mut x_out, mut s_out) = ([0.0; UNROLLED_MAX_SIZE], [0.0; SQUARE]);
    let (xp, sp): (&[f64], &[f64]) = (xp, sp);
    let buffers = Buffers {
        x: xp,
        s: sp,
        p: sp,
        mt: &mt,
        r: &r,
        nu: &nu,
        u: &mut u,
        h: &mut h,
        sm: &mut [],
        y: &mut y,
        hr: &mut hr,
        vp: &mut [],
        lp: &mut [],
        v: &mut v,
        lv: &mut lv,
        rf: &mut [],
        z: &mut z,
        column: &mut column,
        square: &mut square,
        x_out: &mut x_out,
        s_out: &mut s_out,
        p_out: &mut [],
    };
    let corrected = match k {
        1 => correct_in(Fixed::<N>, Fixed::<1>, 1.0, false, buffers),
        2 => correct_in(Fixed::<N>, Fixed::<2>, 1.0, false, buffers),
        _ => correct_in(Fixed::<N>, Fixed::<3>, 1.0, false, buffers),
    };
    let (nis, log_det, finite_out) = corrected.ok()?;
    if !finite_out {
        return None;
    }
    // The results, once: the prediction (which the smoothers read), the update, and what an
    // `Innovation` reads.
    w.x.as_mut_slice()[..N].copy_from_slice(xp);
    w.s.as_mut_slice()[..N * N].copy_from_slice(sp);
    w.x_out.as_mut_slice()[..N].copy_from_slice(&x_out[..N]);
    w.s_out.as_mut_slice()[..N * N].copy_from_slice(&s_out[..N * N]);
    if innovation {
        w.present.clear();
        w.present.extend_from_slice(&seen.present[..k]);
        w.nu[..k].copy_from_slice(&nu[..k]);
        w.v[..k * k].copy_from_slice(&v[..k * k]);
        w.h[..N * k].copy_from_slice(&h[..N * k]);
    }
    Some((nis, log_det))
}

/// [`KalmanFilter::predict_fixed`] for `N` states on `A` axes over the step `zeta`: from the
/// estimate `(x, s)` and the fading `P`, into `w`; whether every number is finite.
#[inline(never)]
fn predict<const N: usize, const A: usize>(
    zeta: f64,
    psd: Option<f64>,
    from: (&[f64], &[f64], Option<&[f64]>),
    w: &mut Work,
) -> bool {
    let into = (
        &mut w.x.as_mut_slice()[..N],
        &mut w.s.as_mut_slice()[..N * N],
        &mut w.p.as_mut_slice()[..N * N],
    );
    let (phi, q) = (w.phi.as_mut_slice(), w.q.as_mut_slice());
    predict_in::<N, A>(zeta, psd, from, phi, q, &mut w.square, into)
}

/// The prediction of `N` states on `A` axes over the step `zeta`, from the estimate `(x, s)`
/// and the fading `P` into `Φ`, `Q` and `(X_{n,n−1}, S_{n,n−1}, P)`, `square` its scratch
/// (`N × N`); whether every number is finite.
#[inline(always)]
fn predict_in<const N: usize, const A: usize>(
    zeta: f64,
    psd: Option<f64>,
    (x, s, fading): (&[f64], &[f64], Option<&[f64]>),
    phi: &mut [f64],
    q: &mut [f64],
    square: &mut [f64],
    (xp, sp, pp): (&mut [f64], &mut [f64], &mut [f64]),
) -> bool {
    // ζ^k/k! for k ≤ m (the model's `for_each_entry`: `psi_term`, k a constant).
    let size = N / A;
    let mut psi = [0.0; UNROLLED_MAX_SIZE];
    for (k, psi) in psi[..size].iter_mut().enumerate() {
        *psi = psi_term(k, &zeta);
    }
    if !all_finite(&psi[..size]) {
        return false;
    }
    // [Φ]_{i A + a, (i + k) A + a} = ζ^k/k!: row r, column c, when c ≥ r on the same axis.
    let entry = |r: usize, c: usize| {
        if c >= r && (c - r).is_multiple_of(A) {
            psi[(c - r) / A]
        } else {
            0.0
        }
    };
    let phi = &mut phi[..N * N];
    for c in 0..N {
        for r in 0..N {
            phi[r + c * N] = entry(r, c);
        }
    }
    // X = Φ X, each row's sum from its diagonal term over the columns ascending (the
    // model's order; its structural zeros add nothing).
    let (x, xp) = (&x[..N], &mut xp[..N]);
    for r in 0..N {
        let mut acc = psi[0] * x[r];
        for k in 1..size {
            if r + k * A < N {
                acc += psi[k] * x[r + k * A];
            }
        }
        xp[r] = acc;
    }
    if !all_finite(xp) {
        return false;
    }
    let q = match psd {
        Some(psd) => {
            let q = &mut q[..N * N];
            if A > 1 {
                q.fill(0.0);
            }
            if !fill(Quotient::<N, A>, A, psd, zeta.abs(), q) {
                return false;
            }
            Some(&*q)
        }
        None => None,
    };
    if !carry_with(Fixed::<N>, entry, s, q, square, sp) {
        return false;
    }
    match fading {
        Some(p) => carry_with(Fixed::<N>, entry, p, q, square, pp),
        None => true,
    }
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
    /// The whole update at fixed size is taken for every polynomial model in range with a
    /// constant `M` of 1-3 rows, with and without driving noise, over a step (forwards or
    /// backwards) or none, and not with 4 rows, a full `R`, no component present, fading
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
                        f.update_fixed(&row(0.7, variances), false).is_some(),
                        taken,
                        "{what}"
                    );
                    let q = WhiteNoiseDerivative::new(degree, axes, 0.3).unwrap();
                    f.set_process_noise(q).unwrap();
                    assert_eq!(
                        f.update_fixed(&row(-1.3, NoiseCovariance::Identity), true)
                            .is_some(),
                        taken,
                        "{what}"
                    );
                    assert_eq!(
                        f.update_fixed(&row(0.0, NoiseCovariance::Identity), true)
                            .is_some(),
                        taken,
                        "{what}: no step"
                    );
                    let full = NoiseCovariance::Full(DMatrix::identity(p, p));
                    assert!(
                        f.update_fixed(&row(0.7, full), false).is_none(),
                        "{what}: full R"
                    );
                    let none = Measurement {
                        time: 0.7,
                        values: vec![None; p],
                        noise: NoiseCovariance::Identity,
                    };
                    assert!(
                        f.update_fixed(&none, false).is_none(),
                        "{what}: nothing present"
                    );
                    f.set_fading(Discount::PerUpdate { theta: 0.9 }).unwrap();
                    assert!(
                        f.update_fixed(&row(0.7, NoiseCovariance::Identity), false)
                            .is_none(),
                        "{what}: fading"
                    );
                }
            }
        }
    }
}
