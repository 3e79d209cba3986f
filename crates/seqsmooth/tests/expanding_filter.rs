//! The expanding-memory filter (`seqsmooth::ExpandingMemory`; Morrison (1969) ch. 9): both
//! engines against batch least squares by Householder QR in a Legendre basis
//! (`estimate::PolynomialFit`, a different algorithm from the recursive engines), degrees 0-8,
//! to 1e-9 relative, and over long runs.

mod common;

use common::engine::*;
use seqsmooth::Engine;

#[test]
fn expanding_even_both_engines_equal_batch_qr_degrees_0_to_8() {
    // Morrison §9.6: the gain recursion is exact least squares from n = m whatever its initial
    // state; the exact engine is least squares by construction.
    for m in 0..=8 {
        let (exact, gain) = expanding_even_errors(m);
        assert!(exact < TOL, "m={m} exact {exact:e}");
        assert!(gain < TOL, "m={m} gain {gain:e}");
    }
}

#[test]
fn expanding_even_long_run_stays_exact() {
    // 10^5 samples: both engines against batch QR at checkpoints (stability, Morrison §9.5).
    for m in [1, 2, 4, 8] {
        for engine in [Engine::Exact, Engine::Gain] {
            let err = expanding_long_run_error(m, engine);
            assert!(err < TOL, "m={m} {engine:?} {err:e}");
        }
    }
}
