//! The Kalman filter's prediction on the polynomial model at compile-time sizes, taken
//! without the user asking: for [`PolynomialDynamics`] (`Φ(ζ) = Ψ(ζ) ⊗ I_d`, (4.2.5)) of
//! `n = (m + 1) d ≤ 9` states on `d ≤ 3` axes, with [`WhiteNoiseDerivative`]'s `Q(ζ)`
//! ((15.2.23) in closed form) or no driving noise, the prediction
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
//! Every number is the generic path's (`Dynamics::propagate_into`, `ProcessNoise::covariance_into`,
//! [`carry`](super::super::correct::carry)) **bit for bit**: each sum adds the same terms in
//! the same order (a skipped term is `0 · a` for a finite `a`, which adds nothing to a sum that
//! started at `+0`), tested on seeded random models of every size in range
//! (`tests/kalman_fixed_path.rs`). Anything not finite stops this path before the filter
//! changes; the generic path then takes the step and gives its own error.

use super::super::correct::{carry_with, Work};
use super::KalmanFilter;
use crate::kalman::noise::fill;
use crate::linalg::dense::all_finite;
use crate::model::dynamics::Dynamics;
use crate::model::observation::Observation;
use crate::model::transition::psi_term;
use crate::numeric::unrolled::{unrolled_sizes, Fixed, Quotient, UNROLLED_MAX_SIZE};
use nalgebra::{DMatrix, DVector};

/// The most axes with the path compiled for them.
const MAX_AXES: usize = 3;

impl<D: Dynamics, O: Observation> KalmanFilter<D, O> {
    /// The prediction to `t` (not the filter's time) into the work buffers on the fixed-size
    /// path (the module's doc): `X_{n,n−1}`, `Φ`, `Q`, `S_{n,n−1}` and the fading `P`; `false`
    /// when the model is not in its range or a number is not finite (nothing of the filter
    /// changed: the generic path takes the step).
    pub(super) fn predict_fixed(&mut self, t: f64) -> bool {
        let Some(model) = self.dynamics.polynomial() else {
            return false;
        };
        let (m, d) = (model.degree(), model.axes());
        let psd = match &self.noise {
            None => None,
            Some(noise) => match noise.white_noise_derivative().map(|q| q.parts()) {
                Some((degree, axes, psd)) if degree == m && axes == d => Some(psd),
                _ => return false,
            },
        };
        let n = (m + 1) * d;
        if n > UNROLLED_MAX_SIZE || d > MAX_AXES || self.state.len() != n {
            return false;
        }
        let zeta = t - self.time;
        let fading = self.fading.as_ref().map(|f| &f.weight);
        let from = (&self.state, &self.covariance, fading);
        let w = &mut self.work;
        unrolled_sizes!(n, N => match d {
                1 => predict::<N, 1>(zeta, psd, from, w),
                2 => N.is_multiple_of(2) && predict::<N, 2>(zeta, psd, from, w),
                _ => N.is_multiple_of(3) && predict::<N, 3>(zeta, psd, from, w),
            },
            _ => false)
    }
}

/// [`KalmanFilter::predict_fixed`] for `N` states on `A` axes over the step `zeta`: from the
/// estimate `(x, s)` and the fading `P`, into `w`; whether every number is finite.
#[inline(never)]
fn predict<const N: usize, const A: usize>(
    zeta: f64,
    psd: Option<f64>,
    (x, s, fading): (&DVector<f64>, &DMatrix<f64>, Option<&DMatrix<f64>>),
    w: &mut Work,
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
    let phi = &mut w.phi.as_mut_slice()[..N * N];
    for c in 0..N {
        for r in 0..N {
            phi[r + c * N] = entry(r, c);
        }
    }
    // X = Φ X, each row's sum from its diagonal term over the columns ascending (the
    // model's order; its structural zeros add nothing).
    let (x, xp) = (&x.as_slice()[..N], &mut w.x.as_mut_slice()[..N]);
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
            let q = &mut w.q.as_mut_slice()[..N * N];
            if A > 1 {
                q.fill(0.0);
            }
            if !fill(Quotient::<N, A>, A, psd, zeta.abs(), q) {
                return false;
            }
            Some(&w.q.as_slice()[..N * N])
        }
        None => None,
    };
    let square = &mut w.square[..];
    if !carry_with(
        Fixed::<N>,
        entry,
        s.as_slice(),
        q,
        square,
        w.s.as_mut_slice(),
    ) {
        return false;
    }
    match fading {
        Some(p) => carry_with(
            Fixed::<N>,
            entry,
            p.as_slice(),
            q,
            square,
            w.p.as_mut_slice(),
        ),
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
}
