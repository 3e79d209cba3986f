//! The exact engine (recursive information filter) on irregular times: against batch least
//! squares by Householder QR and exact rational least squares, plain and discounted, and its
//! accuracy at high degree.

mod common;

use common::engine::*;
use common::*;
use seqsmooth::polynomial::MAX_DEGREE;
use seqsmooth::{DiscountMode, Engine, ExpandingMemory, PolynomialFilter};

#[test]
fn expanding_irregular_exact_engine_equals_batch_qr() {
    for m in 0..=8 {
        for (label, err) in expanding_irregular_errors(m) {
            assert!(err < TOL, "m={m} {label} {err:e}");
        }
    }
}

#[test]
fn expanding_irregular_exact_engine_equals_rational_least_squares() {
    // Exact rational normal equations: an oracle free of rounding.
    for m in 0..=4 {
        let times = random_times(25, 0.3, 41 + m as u64);
        let ys = noisy_polynomial(&times, m, 7.0, 0.5, 51 + m as u64);
        let mut f = ExpandingMemory::new(m, Engine::Exact).unwrap();
        let mut got = Vec::new();
        let mut want = Vec::new();
        for n in 0..times.len() {
            f.update(times[n], ys[n]).unwrap();
            if n >= m {
                got.push(f.estimate().unwrap().derivatives);
                want.push(exact_ls_derivatives(
                    &times[..=n],
                    &ys[..=n],
                    None,
                    m,
                    times[n],
                ));
            }
        }
        let fl = floors(&want);
        let err = got
            .iter()
            .zip(&want)
            .map(|(a, b)| rel_err(a, b, &fl))
            .fold(0.0, f64::max);
        assert!(err < TOL, "m={m} {err:e}");
    }
}

#[test]
fn fading_irregular_exact_engine_equals_discounted_batch_qr() {
    // Weights θ^((t_n - t_k)/τ) (and θ^(n-k) per update) from the first determinable sample.
    for m in 0..=8 {
        for mode in [DiscountMode::PerTime, DiscountMode::PerUpdate] {
            let err = fading_irregular_error(m, mode);
            assert!(err < TOL, "m={m} {mode:?} {err:e}");
        }
    }
}

#[test]
fn high_degree_exact_engine_accuracy_is_measured() {
    // Conditioning limit of the centred monomial square-root information form, documented in
    // the crate docs: measured against batch QR in the Legendre basis on 2000 irregular samples
    // (`cargo run --release -p seqsmooth --example accuracy_engines` prints it).
    // Bounds: 1e-9 to degree 12, 1e-6 to degree 16, 1e-3 to MAX_DEGREE.
    for m in [10, 12, 14, 16, 20, MAX_DEGREE] {
        let (expanding, fading) = high_degree_errors(m);
        let bound = if m <= 12 {
            1e-9
        } else if m <= 16 {
            1e-6
        } else {
            1e-3
        };
        assert!(
            expanding < bound && fading < bound,
            "m={m}: {expanding:e} {fading:e}"
        );
    }
}
