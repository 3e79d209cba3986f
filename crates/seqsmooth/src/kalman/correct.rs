//! The Kalman filter's arithmetic on its preallocated buffers ([`Work`]): the prediction's
//! covariance `Φ S Φᵀ + Q` ((12.2.16), (15.4.11)) and one correction ((12.2.17)-(12.2.19),
//! Joseph's form (12.3.7); fading memory (14.4.34)-(14.4.40)), on column-major slices with the
//! sizes the caller dispatches as constants (`unrolled_sizes!`), over the dense kernels of
//! [`crate::linalg::dense`].

use crate::error::{Error, Param};
use crate::linalg::dense::{
    all_finite, combine, ldl, log_det, symmetrize, times_transpose, transpose,
};
use crate::model::measurement::NoiseCovariance;
use crate::numeric::unrolled::Size;
use nalgebra::{DMatrix, DVector};

use super::filter::Innovation;
use super::filter::InnovationStats;

/// `R`'s entry `(i, j)` as a function, once its shape is checked against `p` components.
pub(super) fn noise_entries(
    p: usize,
    noise: &NoiseCovariance,
) -> Result<impl Fn(usize, usize) -> f64 + '_, Error> {
    match noise {
        NoiseCovariance::Identity => {}
        NoiseCovariance::Variances(v) if v.len() == p => {}
        NoiseCovariance::Full(r) if r.shape() == (p, p) => {}
        other => {
            return Err(Error::InvalidParameter {
                name: Param::MeasurementNoise,
                value: format!("{other:?}"),
                reason: format!("needs {p} components"),
            })
        }
    }
    Ok(move |i: usize, j: usize| match noise {
        NoiseCovariance::Identity => f64::from(u8::from(i == j)),
        NoiseCovariance::Variances(v) => {
            if i == j {
                v[i]
            } else {
                0.0
            }
        }
        NoiseCovariance::Full(r) => r[(i, j)],
    })
}

/// The filter's preallocated buffers: every update and prediction works in these, so that
/// the hot path allocates nothing, and writes its results here before they become the
/// filter's (an update that fails leaves the filter as it was). Matrices are column-major;
/// `n` states, `p` observation components, `k ≤ p` present in the update.
#[derive(Clone, Debug)]
pub(super) struct Work {
    /// The prediction: `X_{n,n−1}`, `Φ(t_n, t_{n−1})`, `Q`, `S_{n,n−1}` and the fading `P`.
    pub(super) x: DVector<f64>,
    pub(super) phi: DMatrix<f64>,
    pub(super) q: DMatrix<f64>,
    pub(super) s: DMatrix<f64>,
    pub(super) p: DMatrix<f64>,
    /// `n × n` scratch (`S Φᵀ`, then `(I − H M) S`).
    pub(super) square: Vec<f64>,
    /// The measurement: the present components, their values, `R` on them (`k × k`).
    pub(super) present: Vec<usize>,
    pub(super) values: Vec<f64>,
    pub(super) r: Vec<f64>,
    /// `f R` for the fading `P` (`k × k`).
    pub(super) rf: Vec<f64>,
    /// The linearisation point of an iterated update, and `G` and `M` (all components) there.
    pub(super) about: DVector<f64>,
    pub(super) g: DVector<f64>,
    pub(super) m_all: DMatrix<f64>,
    /// `Mᵀ` of the present rows, `P Mᵀ`, `S Mᵀ`, the gain `H`, `(I − H M) S Mᵀ` (`n × k`).
    pub(super) mt: Vec<f64>,
    pub(super) u: Vec<f64>,
    pub(super) sm: Vec<f64>,
    pub(super) h: Vec<f64>,
    pub(super) y: Vec<f64>,
    /// `H R` (`n × k`), and a column (`n`).
    pub(super) hr: Vec<f64>,
    pub(super) column: Vec<f64>,
    /// `ν`, and `L⁻¹ ν` (`k`).
    pub(super) nu: Vec<f64>,
    pub(super) z: Vec<f64>,
    /// `V_P = M P Mᵀ + f R` and its `L D Lᵀ` factors; `V = M S Mᵀ + R` and its (`k × k`).
    pub(super) vp: Vec<f64>,
    pub(super) lp: Vec<f64>,
    pub(super) v: Vec<f64>,
    pub(super) lv: Vec<f64>,
    /// The update's results: `X_{n,n}`, `S_{n,n}`, the fading `P`.
    pub(super) x_out: DVector<f64>,
    pub(super) s_out: DMatrix<f64>,
    pub(super) p_out: DMatrix<f64>,
}

/// Empty buffers, to be made anew for the filter's dimensions (a restored filter's scratch).
impl Default for Work {
    fn default() -> Self {
        Self::new(0, 0)
    }
}

impl Work {
    pub(super) fn new(n: usize, p: usize) -> Self {
        let vector = |len: usize| vec![0.0; len];
        Self {
            x: DVector::zeros(n),
            phi: DMatrix::zeros(n, n),
            q: DMatrix::zeros(n, n),
            s: DMatrix::zeros(n, n),
            p: DMatrix::zeros(n, n),
            square: vector(n * n),
            present: Vec::with_capacity(p),
            values: Vec::with_capacity(p),
            r: vector(p * p),
            rf: vector(p * p),
            about: DVector::zeros(n),
            g: DVector::zeros(p),
            m_all: DMatrix::zeros(p, n),
            mt: vector(n * p),
            u: vector(n * p),
            sm: vector(n * p),
            h: vector(n * p),
            y: vector(n * p),
            hr: vector(n * p),
            column: vector(n),
            nu: vector(p),
            z: vector(p),
            vp: vector(p * p),
            lp: vector(p * p),
            v: vector(p * p),
            lv: vector(p * p),
            x_out: DVector::zeros(n),
            s_out: DMatrix::zeros(n, n),
            p_out: DMatrix::zeros(n, n),
        }
    }

    /// The last correction's [`Innovation`], from the buffers.
    pub(super) fn innovation(&self, stats: InnovationStats) -> Innovation {
        let (n, k) = (self.x.len(), stats.components);
        Innovation {
            components: self.present.clone(),
            innovation: DVector::from_column_slice(&self.nu[..k]),
            covariance: DMatrix::from_column_slice(k, k, &self.v[..k * k]),
            gain: DMatrix::from_column_slice(n, k, &self.h[..n * k]),
            nis: stats.nis,
            log_likelihood: stats.log_likelihood,
        }
    }
}

/// `out = Φ S Φᵀ + Q`, symmetrized ((12.2.16), (15.4.11)): `A = S Φᵀ = (Φ S)ᵀ` (`S`
/// symmetric), transposed in place, then `(Φ S) Φᵀ`, both products by [`times_transpose`]
/// (the zeros of `Φ` skipped); `a` is `n × n` scratch. Whether every entry is finite.
pub(super) fn carry<S: Size>(
    n: S,
    phi: &[f64],
    s: &[f64],
    q: Option<&[f64]>,
    a: &mut [f64],
    out: &mut [f64],
) -> bool {
    let nn = n.get() * n.get();
    let phi = &phi[..nn];
    carry_with(n, |i, l| phi[i + l * n.get()], s, q, a, out)
}

/// [`carry`] with `Φ`'s entry `(i, l)` from `phi(i, l)`: where the entries are known zeros
/// (the polynomial model's `Ψ(ζ) ⊗ I_d`, (4.2.5)) and the sizes constants, their terms are
/// dropped at compile time rather than skipped at run time; the same numbers.
#[inline(always)]
pub(super) fn carry_with<S: Size>(
    n: S,
    phi: impl Fn(usize, usize) -> f64 + Copy,
    s: &[f64],
    q: Option<&[f64]>,
    a: &mut [f64],
    out: &mut [f64],
) -> bool {
    let n = n.get();
    let out = &mut out[..n * n];
    times_transpose(n, s, n, phi, a);
    transpose(n, a);
    times_transpose(n, a, n, phi, out);
    match q {
        // (out + Q) symmetrized, in one pass.
        Some(q) => {
            let q = &q[..n * n];
            for j in 0..n {
                out[j + j * n] += q[j + j * n];
                for i in j + 1..n {
                    let (lower, upper) = (i + j * n, j + i * n);
                    let v = ((out[lower] + q[lower]) + (out[upper] + q[upper])) * 0.5;
                    out[lower] = v;
                    out[upper] = v;
                }
            }
        }
        None => symmetrize(n, out),
    }
    all_finite(out)
}

/// `v = M sm + f R` (`k × k`), symmetrized: `sm = S Mᵀ` (`n × k`) and `mt = Mᵀ`.
#[inline(always)]
fn innovation_covariance(
    (n, k): (usize, usize),
    mt: &[f64],
    sm: &[f64],
    r: &[f64],
    f: f64,
    v: &mut [f64],
) {
    for b in 0..k {
        let sm = &sm[b * n..(b + 1) * n];
        for a in 0..k {
            let mt = &mt[a * n..(a + 1) * n];
            let mut msm = 0.0;
            for l in 0..n {
                msm += mt[l] * sm[l];
            }
            v[a + b * k] = msm + r[a + b * k] * f;
        }
    }
    symmetrize(k, v);
}

/// Joseph's form (12.3.7) `out = (I − H M) S (I − H M)ᵀ + H R Hᵀ`, symmetrized, with
/// `I − H M` applied from each side rather than formed: `X = S − H (M S)` (`M S = (S Mᵀ)ᵀ`
/// for the symmetric `S`, `sm = S Mᵀ`), then `X (I − H M)ᵀ = X − (X Mᵀ) Hᵀ`: the same
/// products associated differently, `O(n² k)` for `k` components instead of `O(n³)`; and
/// `(H R) Hᵀ`. `x` (`n × n`), `y` and `hr` (`n × k`) and `column` (`n`) are scratch.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn joseph(
    (n, k): (usize, usize),
    s: &[f64],
    h: &[f64],
    sm: &[f64],
    mt: &[f64],
    r: &[f64],
    (x, y, hr, column): (&mut [f64], &mut [f64], &mut [f64], &mut [f64]),
    out: &mut [f64],
) {
    let (s, x, out) = (&s[..n * n], &mut x[..n * n], &mut out[..n * n]);
    let (h, sm, column) = (&h[..n * k], &sm[..n * k], &mut column[..n]);
    for j in 0..n {
        combine(n, k, h, |c| sm[j + c * n], column);
        for i in 0..n {
            x[i + j * n] = s[i + j * n] - column[i];
        }
    }
    times_transpose(n, x, k, |c, l| mt[l + c * n], y);
    for d in 0..k {
        combine(n, k, h, |c| r[c + d * k], &mut hr[d * n..(d + 1) * n]);
    }
    for j in 0..n {
        let out = &mut out[j * n..(j + 1) * n];
        combine(n, k, y, |c| h[j + c * n], out);
        combine(n, k, hr, |d| h[j + d * n], column);
        for i in 0..n {
            out[i] = (x[i + j * n] - out[i]) + column[i];
        }
    }
    symmetrize(n, out);
}

/// The buffers of one correction ([`correct_in`]) as column-major slices: its inputs (the
/// prediction `X_{n,n−1}`, `S_{n,n−1}`, the fading `P` (`S` without fading), `Mᵀ` of the
/// present rows, `R` on them, `ν`), its scratch and its outputs. The filter's are its
/// [`Work`]'s ([`correct_kernel`]); a fixed-size caller passes arrays of its own, which the
/// compiler can keep in registers (slices of distinct arrays cannot overlap, where the
/// buffers behind a `Work` could for all it knows).
pub(super) struct Buffers<'a> {
    pub(super) x: &'a [f64],
    pub(super) s: &'a [f64],
    pub(super) p: &'a [f64],
    pub(super) mt: &'a [f64],
    pub(super) r: &'a [f64],
    pub(super) nu: &'a [f64],
    /// `n × k`: `P Mᵀ`, the gain `H`, `S Mᵀ` (fading only), `(I − H M) S Mᵀ`, `H R`.
    pub(super) u: &'a mut [f64],
    pub(super) h: &'a mut [f64],
    pub(super) sm: &'a mut [f64],
    pub(super) y: &'a mut [f64],
    pub(super) hr: &'a mut [f64],
    /// `k × k`: `V_P` and its factors (fading only), `V` and its factors, `f R`.
    pub(super) vp: &'a mut [f64],
    pub(super) lp: &'a mut [f64],
    pub(super) v: &'a mut [f64],
    pub(super) lv: &'a mut [f64],
    pub(super) rf: &'a mut [f64],
    /// `L⁻¹ ν` (`k`), a column (`n`) and an `n × n` square.
    pub(super) z: &'a mut [f64],
    pub(super) column: &'a mut [f64],
    pub(super) square: &'a mut [f64],
    /// `X_{n,n}`, `S_{n,n}` and the fading `P`'s update.
    pub(super) x_out: &'a mut [f64],
    pub(super) s_out: &'a mut [f64],
    pub(super) p_out: &'a mut [f64],
}

/// [`correct_in`] on the filter's work buffers.
pub(super) fn correct_kernel<S: Size, C: Size>(
    n: S,
    k: C,
    f: f64,
    fading: bool,
    w: &mut Work,
) -> Result<(f64, f64, bool), Error> {
    let s = w.s.as_slice();
    correct_in(
        n,
        k,
        f,
        fading,
        Buffers {
            x: w.x.as_slice(),
            s,
            p: if fading { w.p.as_slice() } else { s },
            mt: &w.mt,
            r: &w.r,
            nu: &w.nu,
            u: &mut w.u,
            h: &mut w.h,
            sm: &mut w.sm,
            y: &mut w.y,
            hr: &mut w.hr,
            vp: &mut w.vp,
            lp: &mut w.lp,
            v: &mut w.v,
            lv: &mut w.lv,
            rf: &mut w.rf,
            z: &mut w.z,
            column: &mut w.column,
            square: &mut w.square,
            x_out: w.x_out.as_mut_slice(),
            s_out: w.s_out.as_mut_slice(),
            p_out: w.p_out.as_mut_slice(),
        },
    )
}

/// The numbers of one correction ((12.2.17)-(12.2.19), (12.3.7); fading (14.4.34)-(14.4.40)),
/// from the prediction, `Mᵀ`, `ν` and `R` in `b` into its outputs; `NIS`, `ln det V`
/// and whether the outputs are all finite.
/// With `f` the discount over the step (1 without fading, when `P = S`):
///
/// `U = P Mᵀ`, `V_P = M U + f R = L_P D_P L_Pᵀ` ([`ldl`]), `H = U V_P⁻¹` (two unit
/// triangular solves and the pivots), `V = M S Mᵀ + R = L D Lᵀ` (`V_P` without fading, and
/// then `S Mᵀ = U`), `NIS = Σ z_c² / D_c` with `z = L⁻¹ ν`, `ln det V = Σ ln D_c`,
/// `X = X_{n,n−1} + H ν`, `S` by [`joseph`] with `R`, and the fading `P` by [`joseph`] with
/// `f R`, divided by `f`. Without fading `V` and its factors are made in `v`, `lv` (`vp`,
/// `lp` and `sm` untouched).
#[inline(always)]
pub(super) fn correct_in<S: Size, C: Size>(
    n: S,
    k: C,
    f: f64,
    fading: bool,
    b: Buffers<'_>,
) -> Result<(f64, f64, bool), Error> {
    let (n, k) = (n.get(), k.get());
    let (nn, nk, kk) = (n * n, n * k, k * k);
    let s = &b.s[..nn];
    let p = &b.p[..nn];
    let (mt, u, h) = (&b.mt[..nk], &mut b.u[..nk], &mut b.h[..nk]);
    let r = &b.r[..kk];
    let (v, lv) = (&mut b.v[..kk], &mut b.lv[..kk]);
    times_transpose(n, p, k, |c, l| mt[l + c * n], u);
    let not_pd = |v: &[f64]| Error::InvalidParameter {
        name: Param::InnovationCovariance,
        value: format!("{:?}", DMatrix::from_column_slice(k, k, v)),
        reason: "is not positive definite: the observation adds nothing the filter can weigh \
                 (a perfect observation of a component already known exactly)"
            .into(),
    };
    // V_P = M U + f R and its factors: V's own without fading (P = S, f = 1).
    let (vp, lp) = if fading {
        (&mut b.vp[..kk], &mut b.lp[..kk])
    } else {
        (&mut *v, &mut *lv)
    };
    innovation_covariance((n, k), mt, u, r, f, vp);
    if !ldl(k, vp, lp) {
        return Err(not_pd(vp));
    }
    // H = U V_P⁻¹ = U L⁻ᵀ D⁻¹ L⁻¹, a column at a time: G Lᵀ = U (columns forwards), each
    // column divided by its pivot, then H L = G (backwards).
    h.copy_from_slice(u);
    for c in 0..k {
        let (done, rest) = h.split_at_mut(c * n);
        let column = &mut rest[..n];
        for d in 0..c {
            let (l, hd) = (lp[c + d * k], &done[d * n..(d + 1) * n]);
            for i in 0..n {
                column[i] -= l * hd[i];
            }
        }
    }
    for c in 0..k {
        let pivot = lp[c + c * k];
        for o in &mut h[c * n..(c + 1) * n] {
            *o /= pivot;
        }
    }
    for c in (0..k).rev() {
        let (head, later) = h.split_at_mut((c + 1) * n);
        let column = &mut head[c * n..];
        for d in c + 1..k {
            let (l, hd) = (lp[d + c * k], &later[(d - c - 1) * n..(d - c) * n]);
            for i in 0..n {
                column[i] -= l * hd[i];
            }
        }
    }
    // The innovation's true covariance M S Mᵀ + R (§14.8): V_P itself without fading.
    let sm: &[f64] = if fading {
        let sm = &mut b.sm[..nk];
        times_transpose(n, s, k, |c, l| mt[l + c * n], sm);
        innovation_covariance((n, k), mt, sm, r, 1.0, v);
        if !ldl(k, v, lv) {
            return Err(not_pd(v));
        }
        sm
    } else {
        u
    };
    let (nu, z) = (&b.nu[..k], &mut b.z[..k]);
    // NIS = νᵀ V⁻¹ ν = Σ z_c² / D_c, z = L⁻¹ ν.
    let mut nis = 0.0;
    for c in 0..k {
        let mut acc = nu[c];
        for d in 0..c {
            acc -= lv[c + d * k] * z[d];
        }
        z[c] = acc;
        nis += acc * acc / lv[c + c * k];
    }
    let (x, x_out) = (&b.x[..n], &mut b.x_out[..n]);
    combine(n, k, h, |c| nu[c], x_out);
    for i in 0..n {
        x_out[i] += x[i];
    }
    let s_out = &mut b.s_out[..nn];
    let scratch = (&mut *b.square, &mut *b.y, &mut *b.hr, &mut *b.column);
    joseph((n, k), s, h, sm, mt, r, scratch, s_out);
    let mut finite_out = all_finite(x_out) & all_finite(s_out);
    if fading {
        let rf = &mut b.rf[..kk];
        for (rf, r) in rf.iter_mut().zip(r) {
            *rf = r * f;
        }
        let scratch = (&mut *b.square, &mut *b.y, &mut *b.hr, &mut *b.column);
        let out = &mut b.p_out[..nn];
        joseph((n, k), p, h, u, mt, rf, scratch, out);
        for v in out.iter_mut() {
            *v /= f;
        }
        finite_out &= all_finite(out);
    }
    Ok((nis, log_det(k, lv), finite_out))
}

/// A non-finite entry of `m`, named `what`, as an error.
pub(super) fn finite(m: &[f64], what: &'static str) -> Result<(), Error> {
    if !m.iter().fold(false, |bad, v| bad | !v.is_finite()) {
        return Ok(());
    }
    match m.iter().find(|v| !v.is_finite()) {
        Some(&value) => Err(Error::NonFinite { what, value }),
        None => Ok(()),
    }
}
