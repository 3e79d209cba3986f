//! The extended Kalman filter's update written out for the radar model: constant velocity on
//! three axes (`PolynomialDynamics::new(1, 3)`, `Φ = Ψ(ζ) ⊗ I₃`, (4.2.5)), white-acceleration
//! driving noise (`WhiteNoiseDerivative` of degree 1 on 3 axes, or none), range, azimuth and
//! elevation from one radar ((8.5.3)-(8.5.5)) with all three measured and `R` diagonal, no
//! fading memory; over a step or none. The filter takes it without being asked
//! (`KalmanFilter::update`, `update_stats`, `update_gated`); any other case, and any case this
//! path would refuse (a number that is not finite, `V` not positive definite, the target at
//! the site), goes to the general recursion, which gives the error.
//!
//! It is the general recursion's arithmetic (`kalman::correct`: `Φ S Φᵀ + Q` by `carry`, the
//! update by `correct_kernel`, `V = L D Lᵀ`, Joseph's form (12.3.7)), operation for operation
//! in the same order, with the sizes (6 states, 3 components) and the zeros of `Φ`, of
//! `M = [J 0]` and of the diagonal `R` fixed at compile time instead of tested or multiplied
//! at run time, on fixed-size arrays, and the model interfaces (`propagate_into`,
//! `covariance_into`, `predict_into`) and the measurement's general checks replaced by their
//! arithmetic (`psi_term`, the noise's `fill`, `Radar::look`). Its sums start at `−0` where the
//! general path's start at `0` (`−0 + a = a` exactly, which the compiler can drop; `0 + a`
//! differs from `a` only for `a = −0`), and it leaves out the products with a zero of `M` or
//! `R` that the general path adds or skips at run time: so its numbers are the general path's,
//! equal as numbers (`==`), a zero's sign aside. Tested update by update against the general
//! path (this module's tests on the work buffers, `tests/kalman_radar_fixed.rs` on the
//! filter's results).
//!
//! The filter's part (the models recognised, the measurement read once into a stack value)
//! is inlined where the filter updates and folds away for any other observation model; the
//! arithmetic ([`update`]) is one function kept out of line, so that the hot code is compact
//! and apart from the general path's. `Q` is the noise's own `fill` on one axis (its 2 × 2,
//! `Q₁ ⊗ I₃` read from it), from the spectral density the filter's plan holds, and `Φ`'s 36
//! entries are written one by one, the structural zeros as `0` (this model's `Ψ(ζ) ⊗ I₃`).

use super::super::correct::Work;
use super::{InnovationStats, KalmanFilter};
use crate::error::Error;
use crate::kalman::noise::fill;
use crate::linalg::dense::{ldl, log_det, symmetrize};
use crate::model::dynamics::Dynamics;
use crate::model::measurement::{Measurement, NoiseCovariance};
use crate::model::observation::Observation;
use crate::model::radar::{wrap, Radar};
use crate::model::transition::psi_term;
use crate::numeric::unrolled::Fixed;
use std::f64::consts::TAU;

/// States.
const N: usize = 6;
/// Components.
const K: usize = 3;

impl<D: Dynamics, O: Observation> KalmanFilter<D, O> {
    /// The prediction to the measurement's time and the correction into the work buffers, the
    /// filter unchanged: the time and the statistics, or `None` with no component present (the
    /// prediction then made the filter's). The radar model's fixed-size update where it applies
    /// ([`Self::correct_radar_fixed`], the same numbers), else `measure_and_predict` and `correct`.
    pub(super) fn predict_and_correct(
        &mut self,
        measurement: &Measurement,
        innovation: bool,
    ) -> Result<Option<(f64, InnovationStats)>, Error> {
        if let Some(stats) = self.correct_radar_fixed(measurement, innovation) {
            return Ok(Some((measurement.time, stats)));
        }
        let Some(t) = self.measure_and_predict(measurement)? else {
            return Ok(None);
        };
        Ok(Some((t, self.correct(t, false)?)))
    }

    /// The prediction to the measurement's time and the update, when the model is the radar
    /// case of this module, into the work buffers (the prediction `x`, `s`, `Φ`; the present
    /// components and values, `ν`, `V` and the gain that an `Innovation` reads; the updated
    /// state and covariance), the filter unchanged: the statistics, or `None` for the general
    /// path (another model, or anything the general path would refuse or treat otherwise).
    /// The model's checks here (folded away for any other observation model), the arithmetic
    /// in [`update`], compiled once, apart from the general path.
    #[inline]
    pub(super) fn correct_radar_fixed(
        &mut self,
        m: &Measurement,
        innovation: bool,
    ) -> Option<InnovationStats> {
        self.observation.as_radar()?;
        if self.fading.is_some() {
            return None;
        }
        // The models read once when they change (the fixed-size path's plan: the polynomial
        // model's degree and axes, the driving noise's spectral density when it is
        // `WhiteNoiseDerivative` of the same degree and axes), not through the interfaces (a
        // virtual call for the noise) at each update.
        let (1, 3, psd) = self.fixed_model()? else {
            return None;
        };
        let radar = self.observation.as_radar()?;
        if radar.has_range_rate() {
            return None;
        }
        let t = m.time;
        let [Some(y0), Some(y1), Some(y2)] = *m.values.as_slice() else {
            return None;
        };
        let r = match &m.noise {
            NoiseCovariance::Identity => [1.0; K],
            NoiseCovariance::Variances(v) if v.len() == K => [v[0], v[1], v[2]],
            _ => return None,
        };
        let x: &[f64; N] = self.state.as_slice().try_into().ok()?;
        let s: &[f64; N * N] = self.covariance.as_slice().try_into().ok()?;
        let read = Read {
            zeta: (t != self.time).then_some(t - self.time),
            t,
            psd,
            y: [y0, y1, y2],
            r,
        };
        update(radar, read, (x, s), &mut self.work, innovation)
    }
}

/// What [`update`] reads besides the filter's estimate: the step (`None` at the filter's own
/// time), the measurement's time, the driving noise's spectral density (`None`: none), the
/// three measured values and `R`'s variances.
#[derive(Clone, Copy)]
struct Read {
    zeta: Option<f64>,
    t: f64,
    psd: Option<f64>,
    y: [f64; K],
    r: [f64; K],
}

/// The radar case's update (the module's doc) from the estimate `x`, `s` into the work
/// buffers: the statistics, or `None` for the general path. Kept out of line so that the
/// filter's hot code is this function alone, compact, with the general path elsewhere.
#[inline(never)]
fn update(
    radar: &Radar,
    m: Read,
    (x, s): (&[f64; N], &[f64; N * N]),
    w: &mut Work,
    innovation: bool,
) -> Option<InnovationStats> {
    let Read { zeta, t, psd, y, r } = m;
    // Every check at once (no early exit: one branch): the inputs finite (their sum: an
    // infinity or NaN makes it so; a finite sum that overflows only sends the step to the
    // general path), the variances not negative.
    let inputs = (t + y[0]) + (y[1] + y[2]) + ((r[0] + r[1]) + r[2]);
    if !(inputs.is_finite() & (r[0] >= 0.0) & (r[1] >= 0.0) & (r[2] >= 0.0)) {
        return None;
    }
    let xp: &mut [f64; N] = w.x.as_mut_slice().try_into().ok()?;
    let sp: &mut [f64; N * N] = w.s.as_mut_slice().try_into().ok()?;
    let x_out: &mut [f64; N] = w.x_out.as_mut_slice().try_into().ok()?;
    let s_out: &mut [f64; N * N] = w.s_out.as_mut_slice().try_into().ok()?;
    let phi: &mut [f64; N * N] = w.phi.as_mut_slice().try_into().ok()?;

    // The prediction, into the work buffers (none at the filter's own time: the estimate
    // as it is, as `predict_work`).
    match zeta {
        None => {
            *xp = *x;
            *sp = *s;
        }
        Some(zeta) => {
            predict(x, s, zeta, psd, xp, sp)?;
            let (t0, t1) = (psi_term(0, &zeta), psi_term(1, &zeta));
            // `Φ` into the work buffer as the general path leaves it (the smoothers read it:
            // `last_transition`): `[[I, ζ I], [0, I]]` by `psi_term`, (4.2.5). Written whole,
            // entry by entry (no separate fill): the buffer may hold another model's `Φ` of
            // the same size (`with_models` keeps the work buffers).
            for c in 0..N {
                for r in 0..N {
                    phi[r + c * N] = if r == c {
                        t0
                    } else if c == r + 3 {
                        t1
                    } else {
                        0.0
                    };
                }
            }
        }
    }
    // The radar's prediction and its Jacobian J (M = [J 0]; J₁₂ = 0).
    let look = radar.look([xp[0], xp[1], xp[2]])?;
    let (g, jm) = (look.value, look.jacobian);
    let nu = [y[0] - g[0], wrap(y[1] - g[1]), y[2] - g[2]];

    // `correct_kernel` without fading (P = S, f = 1): U = S Mᵀ, V = M U + R = L D Lᵀ.
    let mut u = [0.0; N * K];
    times_mt(sp, &jm, &mut u);
    let mut v = [0.0; K * K];
    for b in 0..K {
        for a in 0..K {
            let mut msm = -0.0;
            for l in 0..3 {
                if a != 1 || l != 2 {
                    msm += jm[a][l] * u[l + b * N];
                }
            }
            v[a + b * K] = if a == b { msm + r[a] } else { msm + 0.0 };
        }
    }
    symmetrize(K, &mut v);
    let mut lv = [0.0; K * K];
    if !ldl(K, &v, &mut lv) {
        return None;
    }
    // H = U L⁻ᵀ D⁻¹ L⁻¹: forwards, the pivots, backwards.
    let mut h = u;
    for c in 0..K {
        for d in 0..c {
            let l = lv[c + d * K];
            for i in 0..N {
                h[i + c * N] -= l * h[i + d * N];
            }
        }
    }
    for c in 0..K {
        let pivot = lv[c + c * K];
        for i in 0..N {
            h[i + c * N] /= pivot;
        }
    }
    for c in (0..K).rev() {
        for d in c + 1..K {
            let l = lv[d + c * K];
            for i in 0..N {
                h[i + c * N] -= l * h[i + d * N];
            }
        }
    }
    // NIS = Σ z_c² / D_c, z = L⁻¹ ν.
    let (mut nis, mut z) = (0.0, [0.0; K]);
    for c in 0..K {
        let mut acc = nu[c];
        for d in 0..c {
            acc -= lv[c + d * K] * z[d];
        }
        z[c] = acc;
        nis += acc * acc / lv[c + c * K];
    }
    for i in 0..N {
        let mut acc = -0.0;
        for c in 0..K {
            acc += h[i + c * N] * nu[c];
        }
        x_out[i] = acc + xp[i];
    }
    // Joseph's form: X = S − H (M S), Y = X Mᵀ, out = (X − Y Hᵀ) + (H R) Hᵀ, with
    // H R = H diag(R).
    let mut xm = [0.0; N * N];
    for j in 0..N {
        for i in 0..N {
            let mut acc = -0.0;
            for c in 0..K {
                acc += h[i + c * N] * u[j + c * N];
            }
            xm[i + j * N] = sp[i + j * N] - acc;
        }
    }
    let mut ym = [0.0; N * K];
    times_mt(&xm, &jm, &mut ym);
    let mut hr = [0.0; N * K];
    for d in 0..K {
        for i in 0..N {
            hr[i + d * N] = h[i + d * N] * r[d];
        }
    }
    for j in 0..N {
        for i in 0..N {
            let (mut yh, mut rh) = (-0.0, -0.0);
            for c in 0..K {
                yh += ym[i + c * N] * h[j + c * N];
            }
            for d in 0..K {
                rh += hr[i + d * N] * h[j + d * N];
            }
            s_out[i + j * N] = (xm[i + j * N] - yh) + rh;
        }
    }
    symmetrize(N, s_out);
    let log_likelihood = -0.5 * (nis + log_det(K, &lv) + K as f64 * TAU.ln());
    // Whether every number is finite, by one sum (module's doc): the results, and `G` and
    // `J`, from which they are made (the prediction's `Φ`, `Q`, `X` and `S` reach the
    // results' entries by sums and differences, so a number not finite there is not finite
    // here).
    let [j0, j1, j2] = jm;
    let sums = [
        sums(x_out),
        sums(s_out),
        sums(&g),
        sums(&j0),
        sums(&j1),
        sums(&j2),
    ];
    let mut total = [0.0; 4];
    for part in &sums {
        for (total, part) in total.iter_mut().zip(part) {
            *total += part;
        }
    }
    let finite = ((total[0] + total[1]) + (total[2] + total[3])).is_finite();
    if !(finite && nis.is_finite() && log_likelihood.is_finite()) {
        return None;
    }

    // What an `Innovation` reads, as the general path leaves it.
    if innovation {
        w.present.clear();
        w.present.extend_from_slice(&[0, 1, 2]);
        w.values.clear();
        w.values.extend_from_slice(&y);
        w.nu[..K].copy_from_slice(&nu);
        w.v[..K * K].copy_from_slice(&v);
        w.h[..N * K].copy_from_slice(&h);
    }
    Some(InnovationStats {
        components: K,
        nis,
        log_likelihood,
    })
}

/// The prediction over a step `zeta ≠ 0` of the filter's state `x` and covariance `s` into
/// `xp`, `sp`: `X(t)` as `PolynomialDynamics::propagate_into` (`Φ`'s terms `(1, ζ)` by
/// `psi_term`, each row's diagonal term first), `Q` as `WhiteNoiseDerivative::covariance_into`,
/// `Φ S Φᵀ + Q` as `carry` (`A = S Φᵀ`, `Aᵀ`, `Aᵀ Φᵀ`; `(out + Q)` symmetrized); `None` where
/// the noise's `Q` is not finite (other numbers are left to [`update`]'s test of the results).
#[inline(always)]
fn predict(
    x: &[f64; N],
    s: &[f64; N * N],
    zeta: f64,
    psd: Option<f64>,
    xp: &mut [f64; N],
    sp: &mut [f64; N * N],
) -> Option<()> {
    let (t0, t1) = (psi_term(0, &zeta), psi_term(1, &zeta));
    for r in 0..N {
        xp[r] = t0 * x[r];
    }
    for a in 0..3 {
        xp[a] += t1 * x[a + 3];
    }
    // Q = Q₁ ⊗ I₃ with Q₁ the noise's own 2 × 2 (`fill` on one axis: each entry's formula
    // does not depend on the axes); its zeros are added as `+ 0` where the general path adds
    // them, so that a zero's sign stays the general path's too.
    let mut q1 = [0.0; 4];
    if let Some(psd) = psd {
        if !fill(Fixed::<2>, 1, psd, zeta.abs(), &mut q1) {
            return None;
        }
    }
    let q = |i: usize, j: usize| {
        if i % 3 == j % 3 {
            q1[i / 3 + (j / 3) * 2]
        } else {
            0.0
        }
    };
    // A = S Φᵀ written transposed ((Aᵀ)_{ir} = A_{ri}), then Aᵀ Φᵀ.
    let mut at = [0.0; N * N];
    times_phi_t(s, t0, t1, |r, i| i + r * N, &mut at);
    times_phi_t(&at, t0, t1, |r, i| r + i * N, sp);
    match psd {
        Some(_) => {
            for j in 0..N {
                sp[j + j * N] += q(j, j);
                for i in j + 1..N {
                    let (lower, upper) = (i + j * N, j + i * N);
                    let v = ((sp[lower] + q(i, j)) + (sp[upper] + q(j, i))) * 0.5;
                    sp[lower] = v;
                    sp[upper] = v;
                }
            }
        }
        None => symmetrize(N, sp),
    }
    // Whether `Φ`, `X` and `S` are finite is left to [`update`]'s one test of the results.
    Some(())
}

/// The numbers of `a` summed in four running sums, to test whether every number is finite
/// by one test of their total (an infinity or NaN makes it infinite or NaN; a finite total
/// that overflows says "not finite", which only sends the step to the general path).
#[allow(clippy::needless_range_loop)]
#[inline(always)]
fn sums<const L: usize>(a: &[f64; L]) -> [f64; 4] {
    let mut sums = [0.0; 4];
    for i in 0..L {
        sums[i % 4] += a[i];
    }
    sums
}

/// `(B Φᵀ)_{ri} = B_{ri} ζ⁰ + B_{r,i+3} ζ` (`Φ = [[I, ζ I], [0, I]]`, terms `t0`, `t1`) into
/// `out` at `at(r, i)`, each sum from `−0` in the general kernel's order.
#[inline(always)]
fn times_phi_t(
    b: &[f64; N * N],
    t0: f64,
    t1: f64,
    at: impl Fn(usize, usize) -> usize,
    out: &mut [f64; N * N],
) {
    for i in 0..N {
        for r in 0..N {
            let mut acc = -0.0;
            acc += b[r + i * N] * t0;
            if i < 3 {
                acc += b[r + (i + 3) * N] * t1;
            }
            out[at(r, i)] = acc;
        }
    }
}

/// `out = A Mᵀ` (`N × K`) for `M = [J 0]` (`J` by rows, `J₁₂ = 0`): column `c` is
/// `Σ_l A_{·l} J_{cl}` over the `J_{cl}` not structurally zero, `l` ascending, as
/// `times_transpose`.
#[inline(always)]
fn times_mt(a: &[f64; N * N], jm: &[[f64; 3]; 3], out: &mut [f64; N * K]) {
    for c in 0..K {
        for r in 0..N {
            let mut acc = -0.0;
            for l in 0..3 {
                if c != 1 || l != 2 {
                    acc += a[r + l * N] * jm[c][l];
                }
            }
            out[r + c * N] = acc;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kalman::noise::WhiteNoiseDerivative;
    use crate::model::dynamics::PolynomialDynamics;
    use crate::model::radar::Radar;
    use nalgebra::{DMatrix, DVector};
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    /// A random radar filter: a site, a target 5-80 km away moving at up to 300 m/s, a
    /// positive definite prior, white acceleration `q` or none.
    fn filter(rng: &mut StdRng) -> KalmanFilter<PolynomialDynamics, Radar> {
        let site = [0.0; 3].map(|_| rng.gen_range(-1e3..1e3));
        let mut state = DVector::zeros(6);
        for a in 0..3 {
            state[a] = site[a] + rng.gen_range(5e3..8e4) * if rng.gen() { 1.0 } else { -1.0 };
            state[a + 3] = rng.gen_range(-300.0..300.0);
        }
        let g = DMatrix::from_fn(6, 6, |_, _| rng.gen_range(-1.0..1.0));
        let scale = DMatrix::from_diagonal(&DVector::from_vec(vec![
            100.0, 100.0, 100.0, 10.0, 10.0, 10.0,
        ]));
        let covariance = &scale * (&g * g.transpose() + DMatrix::identity(6, 6)) * &scale;
        let covariance = (&covariance + covariance.transpose()) * 0.5;
        let dynamics = PolynomialDynamics::new(1, 3);
        let radar = Radar::of_polynomial(site, &dynamics).unwrap();
        let f = KalmanFilter::new(dynamics, radar, state, covariance, 0.0).unwrap();
        if rng.gen_bool(0.8) {
            let q = rng.gen_range(0.0..5.0);
            f.with_process_noise(WhiteNoiseDerivative::new(1, 3, q).unwrap())
                .unwrap()
        } else {
            f
        }
    }

    /// The fast path taken, and its work buffers and statistics equal (`==`) to the general
    /// path's (`measure_and_predict`, `correct`) on 200 random filters of 40 updates each,
    /// at irregular steps forwards and backwards, with `R` by variances or the identity.
    #[test]
    fn the_general_paths_numbers() {
        let mut rng = StdRng::seed_from_u64(20_261_207);
        let mut taken = 0;
        for _ in 0..200 {
            let mut f = filter(&mut rng);
            let mut t = 0.0;
            for _ in 0..40 {
                t += rng.gen_range(0.05..3.0) * if rng.gen_bool(0.1) { -1.0 } else { 1.0 };
                let truth = f.state().clone();
                let look = f
                    .observation()
                    .look([truth[0], truth[1], truth[2]])
                    .unwrap();
                let noise = if rng.gen_bool(0.2) {
                    NoiseCovariance::Identity
                } else {
                    NoiseCovariance::Variances(vec![
                        rng.gen_range(1.0..400.0),
                        rng.gen_range(1e-7..1e-5),
                        rng.gen_range(1e-7..1e-5),
                    ])
                };
                let m = Measurement {
                    time: t,
                    values: vec![
                        Some(look.value[0] + rng.gen_range(-30.0..30.0)),
                        Some(wrap(look.value[1] + rng.gen_range(-0.01..0.01))),
                        Some(look.value[2] + rng.gen_range(-0.01..0.01)),
                    ],
                    noise,
                };
                let (mut fast, mut general) = (f.clone(), f.clone());
                let a = fast
                    .correct_radar_fixed(&m, true)
                    .expect("the fixed-size path");
                let t_general = general.measure_and_predict(&m).unwrap().unwrap();
                let b = general.correct(t_general, false).unwrap();
                assert_eq!(
                    (a.components, a.nis, a.log_likelihood),
                    (b.components, b.nis, b.log_likelihood)
                );
                let (wa, wb) = (&fast.work, &general.work);
                assert_eq!(wa.x, wb.x);
                assert_eq!(wa.s, wb.s);
                assert_eq!(wa.phi, wb.phi);
                assert_eq!(wa.x_out, wb.x_out);
                assert_eq!(wa.s_out, wb.s_out);
                assert_eq!(wa.present, wb.present);
                assert_eq!(wa.values, wb.values);
                assert_eq!(wa.nu[..3], wb.nu[..3]);
                assert_eq!(wa.v[..9], wb.v[..9]);
                assert_eq!(wa.h[..18], wb.h[..18]);
                taken += 1;
                f.update_stats(&m).unwrap();
                assert_eq!(f.state(), &wa.x_out);
            }
        }
        assert_eq!(taken, 200 * 40);
    }

    /// `Φ` written whole even where the work buffer held another model's transition of the
    /// same size (`with_models` keeps the work buffers): equal to the general path's.
    #[test]
    fn the_whole_transition_over_a_stale_buffer() {
        let mut rng = StdRng::seed_from_u64(11);
        let mut f = filter(&mut rng);
        f.work.phi.fill(0.25);
        let look = f
            .observation()
            .look([f.state()[0], f.state()[1], f.state()[2]])
            .unwrap();
        let m = Measurement {
            time: 1.5,
            values: look.value.iter().map(|&v| Some(v)).collect(),
            noise: NoiseCovariance::Identity,
        };
        let (mut fast, mut general) = (f.clone(), f);
        fast.correct_radar_fixed(&m, true)
            .expect("the fixed-size path");
        let t_general = general.measure_and_predict(&m).unwrap().unwrap();
        general.correct(t_general, false).unwrap();
        assert_eq!(fast.work.phi, general.work.phi);
    }

    /// Not taken where the general path must decide: a missing component, a full `R`, fading
    /// memory, a target at the site.
    #[test]
    fn the_general_path_otherwise() {
        let mut rng = StdRng::seed_from_u64(7);
        let f = filter(&mut rng);
        let m = |values: Vec<Option<f64>>, noise| Measurement {
            time: 1.0,
            values,
            noise,
        };
        let all = vec![Some(1e4), Some(0.5), Some(0.1)];
        let variances = NoiseCovariance::Variances(vec![100.0, 1e-6, 1e-6]);
        assert!(f
            .clone()
            .correct_radar_fixed(&m(all.clone(), variances.clone()), true)
            .is_some());
        let missing = vec![Some(1e4), None, Some(0.1)];
        assert!(f
            .clone()
            .correct_radar_fixed(&m(missing, variances.clone()), true)
            .is_none());
        let full = NoiseCovariance::Full(DMatrix::identity(3, 3));
        assert!(f
            .clone()
            .correct_radar_fixed(&m(all.clone(), full), true)
            .is_none());
        let fading = f
            .clone()
            .with_fading(crate::discount::Discount::PerUpdate { theta: 0.9 })
            .unwrap();
        assert!(fading
            .clone()
            .correct_radar_fixed(&m(all.clone(), variances.clone()), true)
            .is_none());
        // At the filter's own time it is taken too (no prediction), with the general numbers.
        let mut now = m(all.clone(), variances.clone());
        now.time = 0.0;
        let (mut fast, mut general) = (f.clone(), f.clone());
        let a = fast
            .correct_radar_fixed(&now, true)
            .expect("taken with no step");
        let t = general.measure_and_predict(&now).unwrap().unwrap();
        assert_eq!(a, general.correct(t, false).unwrap());
        assert_eq!(fast.work.s_out, general.work.s_out);
        let site = f.observation().site();
        let mut at_site = f.clone();
        at_site
            .set_estimate(
                DVector::from_vec(vec![site[0], site[1], site[2], 0.0, 0.0, 0.0]),
                f.covariance().clone(),
                0.0,
            )
            .unwrap();
        assert!(at_site
            .correct_radar_fixed(&m(all, variances.clone()), true)
            .is_none());
        // The general path gives the error.
        let mut at_site_general = at_site.clone();
        assert!(at_site_general
            .update_stats(&m(vec![Some(1e4), Some(0.5), Some(0.1)], variances))
            .is_err());
    }
}
