//! The lanes' straight path for the common step ([`super::Lanes`]): every lane holding a
//! series whose next row has every component present and finite, at a later time, with a step
//! length whose `Φ` and `Q` the lane has — the kernels of [`super::super::kernel`] (Morrison
//! (12.2.15)-(12.2.19), Joseph's covariance (12.3.7)) on the same inputs as
//! `Lanes::advance`, without its per-lane choices, the checks one sum per lane.

// The loops index by position on purpose: entry by entry, lane by lane (the innermost, over
// the lanes, vectorises).
#![allow(clippy::needless_range_loop)]

use super::super::kernel::{self, Column, Square};
use super::super::{Panel, RowsMut};
use super::{Lanes, Step};
use crate::model::dynamics::Dynamics;
use crate::numeric::sigma::std_dev;

impl<D: Dynamics, const N: usize, const K: usize, const L: usize> Lanes<'_, D, N, K, L> {
    /// The step of every lane when each is steady — it holds a series whose next row has
    /// every component present and finite, a later finite time, and a step length whose `Φ`
    /// and `Q` the lane has (a time-invariant model) — and no check would stop its numbers:
    /// [`Self::advance`]'s arithmetic for such lanes, operation for operation, without its
    /// per-lane choices (into `out` the rows, or into `keep` the step); `true` when taken.
    /// Otherwise nothing changes and `false` ([`Self::advance`] takes the step).
    // `v − v` on purpose: 0 for a finite `v`, NaN for an infinite or NaN one.
    #[allow(clippy::eq_op)]
    #[inline(always)]
    pub(super) fn steady(
        &mut self,
        panel: &Panel<'_>,
        out: &mut RowsMut<'_>,
        base: usize,
        keep: Option<&mut Step<N, L>>,
    ) -> bool {
        if !self.one.invariant {
            return false;
        }
        let mut rows = [0; L];
        let mut t = [0.0; L];
        let mut z = [[0.0; L]; K];
        for e in 0..L {
            let Some(held) = self.held[e] else {
                return false;
            };
            rows[e] = held.row;
            t[e] = panel.times[held.row];
            for c in 0..K {
                z[c][e] = panel.values[held.row * K + c];
            }
        }
        // `v − v` is 0 for a finite `v`, NaN otherwise: one sum per lane, NaN when any
        // entry is not finite.
        let mut bad = [0.0; L];
        for c in 0..K {
            for e in 0..L {
                bad[e] += z[c][e] - z[c][e];
            }
        }
        let mut steady = true;
        for e in 0..L {
            steady &= (bad[e] == 0.0)
                & (t[e] - t[e] == 0.0)
                & (t[e] > self.time[e])
                & (t[e] - self.time[e] == self.step[e]);
        }
        if !steady {
            return false;
        }
        let noise = self.bank.noise.as_ref();
        let xp = kernel::propagate(&self.phi, &self.x);
        let sp = kernel::carry(&self.phi, &self.s, noise.map(|_| &self.q));
        let g = kernel::observe(&self.mt, &xp);
        let mut nu = [[0.0; L]; K];
        for c in 0..K {
            for e in 0..L {
                nu[c][e] = z[c][e] - g[c][e];
            }
        }
        let up = kernel::correct(&self.mt, &self.r, &xp, &sp, &nu);
        // The checks of `advance`: every entry finite, `V` positive definite, the NIS
        // below 1e300.
        let mut bad = [0.0; L];
        for i in 0..N {
            for e in 0..L {
                bad[e] += (xp[i][e] - xp[i][e]) + (up.x[i][e] - up.x[i][e]);
            }
            for j in 0..N {
                for e in 0..L {
                    bad[e] += (sp[j][i][e] - sp[j][i][e]) + (up.s[j][i][e] - up.s[j][i][e]);
                }
            }
        }
        for c in 0..K {
            for e in 0..L {
                bad[e] += (g[c][e] - g[c][e]) + (up.lv[c][c][e] - up.lv[c][c][e]);
            }
        }
        let mut fine = true;
        for e in 0..L {
            fine &= (bad[e] == 0.0) & up.positive[e] & (up.nis[e] < 1e300);
        }
        if !fine {
            return false;
        }
        (self.x, self.s, self.time) = (up.x, up.s, t);
        match keep {
            Some(keep) => {
                (keep.phi, keep.xp, keep.sp, keep.x, keep.s) = (self.phi, xp, sp, up.x, up.s);
                keep.nis = up.nis.map(Some);
            }
            None => {
                let r = rows.map(|row| row - base);
                // SAFETY: the lanes run only where the processor has AVX2 (`Lanes::filter`
                // and `Lanes::smooth` check it before any step), the one feature it enables.
                unsafe { put_rows(out, r, &self.x, &self.s, &up.nis) };
            }
        }
        for held in self.held.iter_mut() {
            let h = held.as_mut().expect("every lane holds");
            h.row += 1;
            if h.row == h.end {
                *held = None;
            }
        }
        true
    }
}

/// The lanes' rows `r` of `out` from their estimates `(x, s)` and NIS: the state, σ (each
/// [`std_dev`] of the diagonal, `sqrt(max(v, +0))` with a NaN kept, four lanes an instruction:
/// the same numbers) and the NIS. With two states (the constant-velocity model) each row's
/// state and σ are one 16-byte store, the lanes' columns transposed into rows two lanes an
/// instruction; otherwise entry by entry.
///
/// # Safety
///
/// The processor has AVX2 (the lanes' [`super::available`]). Inlined into the lanes' AVX2
/// functions (`Lanes::filter_avx2`, `Lanes::smooth_avx2`), as is `steady`.
#[inline(always)]
unsafe fn put_rows<const N: usize, const L: usize>(
    out: &mut RowsMut<'_>,
    r: [usize; L],
    x: &Column<N, L>,
    s: &Square<N, L>,
    nis: &[f64; L],
) {
    use std::arch::x86_64::{
        __m256d, _mm256_andnot_pd, _mm256_castpd256_pd128, _mm256_cmp_pd, _mm256_extractf128_pd,
        _mm256_loadu_pd, _mm256_setzero_pd, _mm256_sqrt_pd, _mm256_storeu_pd, _mm256_unpackhi_pd,
        _mm256_unpacklo_pd, _mm_storeu_pd, _CMP_LE_OQ,
    };
    if L != 4 {
        for e in 0..L {
            let (state, sigma) = (
                &mut out.state[r[e] * N..][..N],
                &mut out.sigma[r[e] * N..][..N],
            );
            for i in 0..N {
                state[i] = x[i][e];
                sigma[i] = std_dev(s[i][i][e]);
            }
            out.nis[r[e]] = nis[e];
        }
        return;
    }
    // SAFETY: `L == 4`, four `f64` in each lane array; AVX2 is the caller's.
    let load = |v: &[f64; L]| unsafe { _mm256_loadu_pd(v.as_ptr()) };
    // `std_dev` in four lanes: `v ≤ 0` (false for a NaN) to +0, then the square root.
    // SAFETY: AVX2 is the caller's.
    let sigma = |i: usize| -> __m256d {
        unsafe {
            let v = load(&s[i][i]);
            let nonpositive = _mm256_cmp_pd::<_CMP_LE_OQ>(v, _mm256_setzero_pd());
            _mm256_sqrt_pd(_mm256_andnot_pd(nonpositive, v))
        }
    };
    if N == 2 {
        // Lane e's row (a[e], b[e]): lanes 0 and 2 in the interleave of the low halves of
        // each 128 bits, lanes 1 and 3 in that of the high halves.
        // SAFETY: AVX2 is the caller's.
        let rows = |a: __m256d, b: __m256d| unsafe {
            let (low, high) = (_mm256_unpacklo_pd(a, b), _mm256_unpackhi_pd(a, b));
            [
                _mm256_castpd256_pd128(low),
                _mm256_castpd256_pd128(high),
                _mm256_extractf128_pd::<1>(low),
                _mm256_extractf128_pd::<1>(high),
            ]
        };
        let state = rows(load(&x[0]), load(&x[1]));
        let sd = rows(sigma(0), sigma(1));
        // One bounds check for the four rows: the last of them in each buffer.
        let top = r.iter().fold(0, |top, &row| top.max(row));
        // `..=top` first: it checks `top < len`, so `(top + 1) * 2` below cannot wrap.
        let to_nis = &mut out.nis[..=top];
        let (to_state, to_sigma) = (
            &mut out.state[..(top + 1) * 2],
            &mut out.sigma[..(top + 1) * 2],
        );
        for e in 0..L {
            // SAFETY: `r[e] ≤ top`, so row `r[e]`'s two `f64` (the 16 bytes stored) and its
            // NIS are inside the slices just checked; AVX2 is the caller's.
            unsafe {
                _mm_storeu_pd(to_state.as_mut_ptr().add(r[e] * 2), state[e]);
                _mm_storeu_pd(to_sigma.as_mut_ptr().add(r[e] * 2), sd[e]);
                *to_nis.as_mut_ptr().add(r[e]) = nis[e];
            }
        }
        return;
    }
    let mut sd = [[0.0; L]; N];
    for i in 0..N {
        // SAFETY: `sd[i]` is four `f64` (`L == 4`); AVX2 is the caller's.
        unsafe { _mm256_storeu_pd(sd[i].as_mut_ptr(), sigma(i)) };
    }
    for e in 0..L {
        let (state, to) = (
            &mut out.state[r[e] * N..][..N],
            &mut out.sigma[r[e] * N..][..N],
        );
        for i in 0..N {
            state[i] = x[i][e];
            to[i] = sd[i][e];
        }
        out.nis[r[e]] = nis[e];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `put_rows` writes what the entry-by-entry rows would, bit for bit: the state, σ by
    /// [`std_dev`] (a negative or −0 variance to +0, a NaN kept, +∞ to +∞) and the NIS, each
    /// lane into its own row, for two states (the transposing store) and three.
    fn same_as_entry_by_entry<const N: usize>() {
        if !super::super::available() {
            return;
        }
        let diagonal = [
            4.0,
            -1e-18,
            f64::NAN,
            2.0,
            -0.0,
            f64::INFINITY,
            1e-300,
            -3.0,
        ];
        let mut x = [[0.0; 4]; N];
        let mut s = [[[0.5; 4]; N]; N];
        for i in 0..N {
            for e in 0..4 {
                x[i][e] = (10 * i + e) as f64 - 7.5;
                s[i][i][e] = diagonal[(i * 4 + e) % diagonal.len()];
            }
        }
        let nis = [1.5, 0.25, 3.0, 1e-3];
        let r = [5, 0, 3, 1];
        let (mut state, mut sigma, mut out_nis) =
            (vec![9.0; 6 * N], vec![9.0; 6 * N], vec![9.0; 6]);
        let mut out = RowsMut {
            state: &mut state,
            sigma: &mut sigma,
            nis: &mut out_nis,
        };
        // SAFETY: the processor has AVX2 (checked above).
        unsafe { put_rows(&mut out, r, &x, &s, &nis) };
        for e in 0..4 {
            for i in 0..N {
                assert_eq!(state[r[e] * N + i].to_bits(), x[i][e].to_bits());
                assert_eq!(sigma[r[e] * N + i].to_bits(), std_dev(s[i][i][e]).to_bits());
            }
            assert_eq!(out_nis[r[e]].to_bits(), nis[e].to_bits());
        }
        // The rows no lane holds are untouched.
        for row in [2, 4] {
            assert!(state[row * N..(row + 1) * N].iter().all(|&v| v == 9.0));
            assert!(sigma[row * N..(row + 1) * N].iter().all(|&v| v == 9.0));
            assert_eq!(out_nis[row], 9.0);
        }
    }

    #[test]
    fn rows_of_two_states() {
        same_as_entry_by_entry::<2>();
    }

    #[test]
    fn rows_of_three_states() {
        same_as_entry_by_entry::<3>();
    }
}
