//! The exact engine (recursive information filter) on irregular times: against batch least
//! squares by Householder QR and exact rational least squares, plain and discounted, and its
//! accuracy at high degree.

mod common;

use common::engine::*;
use common::*;
use seqsmooth::polynomial::MAX_DEGREE;
use seqsmooth::{DiscountMode, Engine, ExpandingMemory, FadingMemory, PolynomialFilter};

#[test]
fn expanding_irregular_exact_engine_equals_batch_qr() {
    for m in 0..=8 {
        for (label, times) in [
            ("jittered", jittered_times(150, 0.1, 0.4, 11 + m as u64)),
            ("random", random_times(150, 0.1, 21 + m as u64)),
        ] {
            let ys = noisy_polynomial(&times, m, 15.0, 0.2, 31 + m as u64);
            let err = compare(
                Box::new(ExpandingMemory::new(m, Engine::Exact).unwrap()),
                &times,
                &ys,
                m,
                |_| true,
                |_| None,
            );
            eprintln!("expanding {label} m={m}: {err:.2e}");
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
        eprintln!("expanding rational m={m}: {err:.2e}");
        assert!(err < TOL, "m={m} {err:e}");
    }
}

fn discount_weights(times: &[f64], n: usize, theta: f64, tau: f64, mode: DiscountMode) -> Vec<f64> {
    (0..=n)
        .map(|k| match mode {
            DiscountMode::PerTime => theta.powf((times[n] - times[k]) / tau),
            DiscountMode::PerUpdate => theta.powi((n - k) as i32),
        })
        .collect()
}

#[test]
fn fading_irregular_exact_engine_equals_discounted_batch_qr() {
    // Weights θ^((t_n - t_k)/τ) (and θ^(n-k) per update) from the first determinable sample.
    for m in 0..=8 {
        for mode in [DiscountMode::PerTime, DiscountMode::PerUpdate] {
            let theta = 0.93;
            let tau = 0.1;
            let times = jittered_times(400, 0.1, 0.5, 61 + m as u64);
            let ys = noisy_polynomial(&times, m, 10.0, 0.2, 71 + m as u64);
            let f = FadingMemory::new(m, theta, tau, Engine::Exact)
                .unwrap()
                .with_discount_mode(mode)
                .unwrap();
            let err = compare(
                Box::new(f),
                &times,
                &ys,
                m,
                |n| n < 60 || n % 7 == 0,
                |n| Some(discount_weights(&times, n, theta, tau, mode)),
            );
            eprintln!("fading irregular {mode:?} m={m}: {err:.2e}");
            assert!(err < TOL, "m={m} {mode:?} {err:e}");
        }
    }
}

#[test]
fn high_degree_exact_engine_accuracy_is_measured() {
    // Conditioning limit of the centred monomial square-root information form, documented in
    // the crate docs: measured against batch QR in the Legendre basis on 2000 irregular samples.
    // Bounds: 1e-9 to degree 12, 1e-6 to degree 16, 1e-3 to MAX_DEGREE.
    for m in [10, 12, 14, 16, 20, MAX_DEGREE] {
        let times = jittered_times(2000, 0.01, 0.3, 111 + m as u64);
        let ys = noisy_polynomial(&times, m, 20.0, 1e-3, 121 + m as u64);
        let check = [m, m + 5, 100, 500, 1998];
        let expanding = compare(
            Box::new(ExpandingMemory::new(m, Engine::Exact).unwrap()),
            &times,
            &ys,
            m,
            |n| check.contains(&n),
            |_| None,
        );
        let theta = 0.99;
        let fading = compare(
            Box::new(FadingMemory::new(m, theta, 0.01, Engine::Exact).unwrap()),
            &times,
            &ys,
            m,
            |n| check.contains(&n),
            |n| {
                Some(discount_weights(
                    &times,
                    n,
                    theta,
                    0.01,
                    DiscountMode::PerTime,
                ))
            },
        );
        eprintln!("high degree m={m}: expanding {expanding:.2e}, fading {fading:.2e}");
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
