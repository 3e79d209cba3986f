//! The fixed-size path's prediction of the polynomial model ([`super`]'s doc):
//! `X_{n,n−1} = Φ X_{n−1,n−1}` (12.2.15) and `S_{n,n−1} = Φ S Φᵀ + Q` (12.2.16), (15.4.11), with
//! `Φ = Ψ(ζ) ⊗ I_d` (4.2.5) made from its terms `ζ^k/k!` and its structural zeros known at
//! compile time, the generic path's numbers bit for bit.

use super::Square;
use crate::kalman::correct::{carry_with, Work};
use crate::kalman::noise::fill;
use crate::linalg::dense::all_finite;
use crate::model::transition::psi_term;
use crate::numeric::unrolled::{Fixed, Quotient, UNROLLED_MAX_SIZE};

/// Whether `Φ`'s entry `(r, c)` on `A` axes is one of `Ψ ⊗ I`'s terms `ζ^k/k!` (4.2.5): `c ≥ r`
/// on the same axis (every other entry is a structural zero).
#[inline(always)]
const fn on<const A: usize>(r: usize, c: usize) -> bool {
    c >= r && (c - r).is_multiple_of(A)
}

/// The prediction of `N` states on `A` axes over the step `zeta` in place of `(xp, sp)`, `Φ`
/// into `phi` (when the caller reads it): [`predict_in`]'s numbers (the generic path's
/// [`carry`](crate::kalman::correct::carry)), operation for operation on this function's
/// arrays, `Φ`'s structural zeros left out at compile time, its other entries multiplied
/// whatever their value, and the sums from `−0`: each entry of `S_{n,n−1}` the generic path's
/// or a zero of the other sign, which [`update`](super::update) makes `+0` where it writes the
/// prediction out (its doc: a zero's sign reaches only zeros, and every result is made `+0`
/// where it is `−0`; not here, where the add would lengthen the chain from one covariance to
/// the next). Whether `Φ`, `Q` and the prediction are finite is left to
/// [`update`](super::update)'s check.
#[allow(clippy::needless_range_loop)]
#[inline(always)]
pub(super) fn predict_exact<const N: usize, const A: usize>(
    zeta: f64,
    psd: Option<f64>,
    xp: &mut [f64; N],
    sp: &mut Square<N>,
    phi: Option<&mut [f64]>,
) {
    let size = N / A;
    let mut psi = [0.0; N];
    for (k, psi) in psi[..size].iter_mut().enumerate() {
        *psi = psi_term(k, &zeta);
    }
    let x = *xp;
    if let Some(phi) = phi {
        write_transition::<N, A>(&psi, phi);
    }
    transition_times::<N, A>(&psi, &x, xp);
    // T = S Φᵀ (`t[i]` its column i), then Φ S Φᵀ = Tᵀ Φᵀ: its column j is Σ_l Tᵀ[:, l] Φ(j, l).
    let s = *sp;
    let mut t = [[-0.0; N]; N];
    for i in 0..N {
        for l in 0..N {
            if on::<A>(i, l) {
                let scale = psi[(l - i) / A];
                for r in 0..N {
                    t[i][r] += s[l][r] * scale;
                }
            }
        }
    }
    let mut out = [[-0.0; N]; N];
    for j in 0..N {
        for l in 0..N {
            if on::<A>(j, l) {
                let scale = psi[(l - j) / A];
                for r in 0..N {
                    out[j][r] += t[r][l] * scale;
                }
            }
        }
    }
    match psd {
        // (out + Q) symmetrized, in one pass.
        Some(psd) => {
            let mut q = [[0.0; N]; N];
            fill(Quotient::<N, A>, A, psd, zeta.abs(), q.as_flattened_mut());
            for j in 0..N {
                out[j][j] += q[j][j];
                for i in j + 1..N {
                    let v = ((out[j][i] + q[j][i]) + (out[i][j] + q[i][j])) * 0.5;
                    out[j][i] = v;
                    out[i][j] = v;
                }
            }
        }
        None => {
            for j in 0..N {
                for i in j + 1..N {
                    let v = (out[j][i] + out[i][j]) * 0.5;
                    out[j][i] = v;
                    out[i][j] = v;
                }
            }
        }
    }
    *sp = out;
}

/// [`KalmanFilter::predict_fixed`](super::super::KalmanFilter::predict_fixed) for `N` states on `A` axes over the step `zeta`: from the
/// estimate `(x, s)` and the fading `P`, into `w`; whether every number is finite.
#[inline(never)]
pub(super) fn predict<const N: usize, const A: usize>(
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
    let xp = &mut xp[..N];
    write_transition::<N, A>(&psi, phi);
    transition_times::<N, A>(&psi, &x[..N], xp);
    let entry = |r: usize, c: usize| phi_entry::<A>(&psi, r, c);
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

/// `[Φ]_{r c}` from `psi[k] = ζ^k/k!` ([`write_transition`]).
#[inline(always)]
fn phi_entry<const A: usize>(psi: &[f64], r: usize, c: usize) -> f64 {
    if on::<A>(r, c) {
        psi[(c - r) / A]
    } else {
        0.0
    }
}

/// `Φ` into `phi` (`[Φ]_{i A + a, (i + k) A + a} = ζ^k/k!`: row r, column c, when c ≥ r on the
/// same axis, (4.2.5); `psi[k] = ζ^k/k!`).
#[inline(always)]
fn write_transition<const N: usize, const A: usize>(psi: &[f64], phi: &mut [f64]) {
    let phi = &mut phi[..N * N];
    for c in 0..N {
        for r in 0..N {
            phi[r + c * N] = phi_entry::<A>(psi, r, c);
        }
    }
}

/// `Φ x` into `xp` (`psi[k] = ζ^k/k!`, [`write_transition`]'s `Φ`), each row's sum from its
/// diagonal term over the columns ascending (the model's order; its structural zeros add
/// nothing).
#[inline(always)]
fn transition_times<const N: usize, const A: usize>(psi: &[f64], x: &[f64], xp: &mut [f64]) {
    let size = N / A;
    for r in 0..N {
        let mut acc = psi[0] * x[r];
        for k in 1..size {
            if r + k * A < N {
                acc += psi[k] * x[r + k * A];
            }
        }
        xp[r] = acc;
    }
}
