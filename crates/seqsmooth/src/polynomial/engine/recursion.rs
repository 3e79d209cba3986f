//! The steady gain recursion of Morrison Tables 9.1 and 13.1 (expanding and fading memory),
//! one sample, any degree, plain `f64`: the reference every fast path is tested against.
//!
//! `Z ← Φ(ζ) Z` (predict, the Taylor shift of [`crate::model::taylor`]), `ε = y − z₀`,
//! `Z ← Z + H ε` (correct), with `Z` Morrison's scaled state and `H` the gains for the step
//! (Reyneke et al. §6: `h_k/ζ̄^k` for the typical step `ζ̄`).
//!
//! The fast paths: the gain engine's plain kernels (`expanding_run_n` is this function on a
//! fixed-size array; `steady_run_n` regroups it so the chain between samples is one
//! multiplication deep), the banks' structure-of-arrays kernel (this function per channel,
//! the same operations in the same order), and the block maps (the fading recursion unrolled
//! over a block, the expanding one as a least-squares update), which are different algorithms
//! for the same result. The compensated single-sample update (`GainEngine::update`) is this
//! recursion in double words.

use crate::model::for_each_shift_step;

/// One step of the recursion: `Z ← Φ(ζ) Z`, `ε = y − z₀`, `Z ← Z + H ε`; returns `ε`.
#[inline(always)]
pub(crate) fn predict_correct(z: &mut [f64], zeta: f64, h: &[f64], y: f64) -> f64 {
    for_each_shift_step(z.len(), |k| z[k] += zeta * z[k + 1]);
    let e = y - z[0];
    for (zk, hk) in z.iter_mut().zip(h) {
        *zk += hk * e;
    }
    e
}
