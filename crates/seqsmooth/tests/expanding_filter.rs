//! The expanding-memory filter (`seqsmooth::ExpandingMemory`; Morrison (1969) ch. 9): both
//! engines against batch least squares by Householder QR in a Legendre basis
//! (`estimate::PolynomialFit`, a different algorithm from the recursive engines), degrees 0-8,
//! to 1e-9 relative, and over long runs.

mod common;

use common::engine::*;
use common::*;
use seqsmooth::{Engine, ExpandingMemory};

#[test]
fn expanding_even_both_engines_equal_batch_qr_degrees_0_to_8() {
    // Morrison §9.6: the gain recursion is exact least squares from n = m whatever its initial
    // state; the exact engine is least squares by construction.
    for m in 0..=8 {
        let times = even_times(200, 5.0, 0.25);
        let ys = noisy_polynomial(&times, m, 50.0, 0.3, 100 + m as u64);
        let exact = compare(
            Box::new(ExpandingMemory::new(m, Engine::Exact).unwrap()),
            &times,
            &ys,
            m,
            |_| true,
            |_| None,
        );
        let gain = compare(
            Box::new(ExpandingMemory::new(m, Engine::Gain).unwrap()),
            &times,
            &ys,
            m,
            |_| true,
            |_| None,
        );
        eprintln!("expanding even m={m}: exact {exact:.2e}, gain {gain:.2e}");
        assert!(exact < TOL, "m={m} exact {exact:e}");
        assert!(gain < TOL, "m={m} gain {gain:e}");
    }
}

#[test]
fn expanding_even_long_run_stays_exact() {
    // 10^5 samples: both engines against batch QR at checkpoints (stability, Morrison §9.5).
    let n = 100_001;
    for m in [1, 2, 4, 8] {
        let times = even_times(n, 0.0, 1e-3);
        let ys = noisy_polynomial(&times, m, 100.0, 0.1, 7 + m as u64);
        let checkpoints = [999usize, 9_999, 99_999];
        for engine in [Engine::Exact, Engine::Gain] {
            let err = compare(
                Box::new(ExpandingMemory::new(m, engine).unwrap()),
                &times,
                &ys,
                m,
                |k| checkpoints.contains(&k),
                |_| None,
            );
            eprintln!("expanding long m={m} {engine:?}: {err:.2e}");
            assert!(err < TOL, "m={m} {engine:?} {err:e}");
        }
    }
}
