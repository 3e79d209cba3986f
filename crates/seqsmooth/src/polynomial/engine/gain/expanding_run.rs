//! The gain engine's expanding memory on runs of even steps: whole blocks folded in as one
//! least-squares update ([`super::super::expanding_block`], Morrison §9.4).

use super::batch::STEADY_BLOCK;
use super::*;

impl GainEngine {
    /// Expanding memory on a run of whole blocks of [`STEADY_BLOCK`] even steps: on an even
    /// grid the filter's state is the least-squares polynomial through every sample so far
    /// (Morrison §9.4), so the run is folded in as one least-squares update
    /// ([`super::super::expanding_block::advance_even_fit`]) instead of a recursion per sample. The
    /// grid is the run's own: from the first sample to the run's last at their mean step (the
    /// old state moved onto it first, by the rounding of the timestamps); within it, the samples'
    /// own times differ from the grid by their rounding, which the per-sample recursion follows
    /// and this does not (measured in tests/batch.rs). Returns how many samples it took.
    pub(super) fn expanding_block_run(&mut self, ts: &[f64], ys: &[f64]) -> usize {
        if self.n <= self.m as u64 || ts.is_empty() {
            return 0;
        }
        if self.m == 0 {
            // Degree 0 is the running mean, whatever the steps.
            let mut z = [self.z[0] + self.z_lo[0]];
            super::super::expanding_block::advance_even_fit(0, self.n, &mut z, ys);
            self.end_plain_run(&z, ts[ts.len() - 1], ts.len());
            return ts.len();
        }
        // The mean step so far (the one the recursion's gains are scaled for).
        let step = (self.t_last - self.t_first) / ((self.n - 1) as f64 * self.unit);
        let mut prev = self.t_last;
        let mut take = 0;
        for tb in ts.chunks_exact(STEADY_BLOCK) {
            if !StepCheck::new(step, self.unit).all_agree(tb, prev, 1.0 / self.unit) {
                break;
            }
            take += STEADY_BLOCK;
            prev = tb[STEADY_BLOCK - 1];
        }
        if take == 0 {
            return 0;
        }
        let (tau, m, n) = (self.unit, self.m, self.n);
        let t_end = ts[take - 1];
        // The grid from the first sample to the run's last, in units of its step.
        let grid = (t_end - self.t_first) / ((n + take as u64 - 1) as f64 * tau);
        // The old state onto the grid's sample n−1 (a rounding-sized move), then in grid units.
        let mut z = [0.0; MAX_DEGREE + 1];
        let z = &mut z[..=m];
        for (zk, (hi, lo)) in z.iter_mut().zip(self.z.iter().zip(&self.z_lo)) {
            *zk = hi + lo;
        }
        let moved = (self.t_first - self.t_last) / tau + (n - 1) as f64 * grid;
        shift_scaled(z, moved);
        let mut power = 1.0;
        for zk in z.iter_mut() {
            *zk *= power;
            power *= grid;
        }
        super::super::expanding_block::advance_even_fit(m, n, z, &ys[..take]);
        let mut power = 1.0;
        for zk in z.iter_mut() {
            *zk /= power;
            power *= grid;
        }
        self.z.copy_from_slice(z);
        self.z_lo.iter_mut().for_each(|v| *v = 0.0);
        self.t_last = t_end;
        self.n += take as u64;
        self.step_mean = grid;
        take
    }
}
