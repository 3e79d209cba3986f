//! The lanes' straight path for the common step ([`super::Lanes`]): every lane holding a
//! series whose next row has every component present and finite, at a later time, with a step
//! length whose `Φ` and `Q` the lane has — the kernels of [`super::super::kernel`] (Morrison
//! (12.2.15)-(12.2.19), Joseph's covariance (12.3.7)) on the same inputs as
//! `Lanes::advance`, without its per-lane choices, the checks one sum per lane.

// The loops index by position on purpose: entry by entry, lane by lane (the innermost, over
// the lanes, vectorises).
#![allow(clippy::needless_range_loop)]

use super::super::kernel;
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
                let sigma: [[f64; L]; N] =
                    std::array::from_fn(|i| std::array::from_fn(|e| std_dev(self.s[i][i][e])));
                for e in 0..L {
                    let r = rows[e] - base;
                    let state = &mut out.state[r * N..(r + 1) * N];
                    let to = &mut out.sigma[r * N..(r + 1) * N];
                    for i in 0..N {
                        state[i] = self.x[i][e];
                        to[i] = sigma[i][e];
                    }
                    out.nis[r] = up.nis[e];
                }
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
