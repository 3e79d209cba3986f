//! The automatic filter's review (`polynomial::automatic`, step 6; `automatic/review.rs`): each
//! sample's final outlier decision by its deleted residual against the fit through its
//! neighbours.
//!
//! - The verdict against an independent computation: a flat line with one offset sample, the
//!   gate off, so that the review alone decides; the fit's VRF at the sample by a direct QR
//!   least-squares solve (nalgebra) on the neighbours' times. An offset just inside
//!   `k σ √(1 + v_p)` is kept, one just outside rejected.
//! - Every sample decided exactly once, in order, at degrees 0 to 12 and with the review off;
//!   after `finish` the filter's own counts agree with the final decisions (so a decision that
//!   went back left the state consistent with it).
//! - In a sharp turn, outliers the gate passed (its prediction too uncertain) are rejected
//!   finally, and samples it rejected are taken.

use nalgebra::{DMatrix, DVector};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use seqsmooth::polynomial::automatic::{final_outliers, AutoOutput, AutomaticFilter};

/// The VRF at `t` of the least-squares line through `times` (unit noise), by QR.
fn line_vrf_at(times: &[f64], t: f64) -> f64 {
    let c = times.iter().sum::<f64>() / times.len() as f64;
    let a = DMatrix::from_fn(
        times.len(),
        2,
        |i, j| if j == 0 { 1.0 } else { times[i] - c },
    );
    let r = a.qr().r();
    // v = ‖R⁻ᵀ x‖², x = (1, t − c)
    let z = r
        .transpose()
        .solve_lower_triangular(&DVector::from_vec(vec![1.0, t - c]))
        .unwrap();
    z.norm_squared()
}

/// Runs the samples, finishes, and returns the outputs and the final decisions.
fn run(f: &mut AutomaticFilter, t: &[f64], y: &[f64]) -> (Vec<AutoOutput>, Vec<bool>) {
    let outs: Vec<AutoOutput> = t
        .iter()
        .zip(y)
        .map(|(&t, &y)| f.update(t, y).unwrap())
        .collect();
    let tail = f.finish();
    let reported: usize = outs.iter().map(|o| o.decided.len()).sum();
    assert_eq!(reported + tail.len(), t.len(), "one decision per sample");
    let flags = final_outliers(&outs, &tail);
    (outs, flags)
}

#[test]
fn deleted_residual_matches_a_direct_solve() {
    // Degree 0: the review fits lines through L = 4 accepted samples on each side.
    let sigma = 0.5;
    let mut r = StdRng::seed_from_u64(7);
    let t: Vec<f64> = (0..40)
        .scan(0.0, |t, _| {
            *t += 0.6 + 0.8 * r.gen::<f64>();
            Some(*t)
        })
        .collect();
    let at = 20;
    let around: Vec<f64> = t[at - 4..at]
        .iter()
        .chain(&t[at + 1..at + 5])
        .copied()
        .collect();
    let v = line_vrf_at(&around, t[at]);
    assert!(v > 0.1 && v < 0.3, "v = {v}");
    let limit = 3.0 * sigma * (1.0 + v).sqrt();
    for (offset, rejected) in [(limit * 0.999, false), (limit * 1.001, true)] {
        let mut f = AutomaticFilter::new(0, 0.9, 1.0)
            .unwrap()
            .with_noise_sigma(sigma)
            .unwrap()
            .with_gate_max_vrf(1e-300) // the gate never on: the review alone decides
            .unwrap();
        let y: Vec<f64> = (0..t.len())
            .map(|i| 5.0 + if i == at { offset } else { 0.0 })
            .collect();
        let (outs, flags) = run(&mut f, &t, &y);
        assert!(outs.iter().all(|o| o.gate.is_none() && !o.outlier));
        assert_eq!(flags[at], rejected, "offset {offset} against {limit}");
        assert_eq!(flags.iter().filter(|&&r| r).count(), usize::from(rejected));
        assert_eq!(f.rejected(), u64::from(rejected));
    }
}

/// A polynomial-ish track with irregular steps, Gaussian noise and 3% outliers of 6-12σ.
fn noisy_track(seed: u64, n: usize, degree: usize) -> (Vec<f64>, Vec<f64>) {
    let mut r = StdRng::seed_from_u64(seed);
    let noise = Normal::new(0.0, 1.0).unwrap();
    let mut t = 0.0;
    let (mut ts, mut ys) = (Vec::new(), Vec::new());
    for _ in 0..n {
        t += 0.5 + r.gen::<f64>();
        let x = t / n as f64;
        let trend: f64 =
            (0..=degree).map(|k| 100.0 * x.powi(k as i32)).sum::<f64>() + 20.0 * (6.0 * x).sin();
        let out = if r.gen::<f64>() < 0.03 {
            r.gen_range(6.0..12.0) * if r.gen::<bool>() { 1.0 } else { -1.0 }
        } else {
            0.0
        };
        ts.push(t);
        ys.push(trend + noise.sample(&mut r) + out);
    }
    (ts, ys)
}

#[test]
fn every_sample_is_decided_once_and_the_counts_agree() {
    for (degree, n) in [
        (0, 1500),
        (1, 1500),
        (2, 2000),
        (5, 1500),
        (8, 2000),
        (12, 600),
    ] {
        for review in [None, Some(0)] {
            let (t, y) = noisy_track(degree as u64, n, degree);
            let mut f = AutomaticFilter::new(degree, 0.95, 1.0).unwrap();
            if let Some(l) = review {
                f = f.with_review_window(l).unwrap();
            }
            let (outs, flags) = run(&mut f, &t, &y);
            let rejected = flags.iter().filter(|&&r| r).count() as u64;
            assert_eq!(f.samples() + f.rejected(), n as u64, "degree {degree}");
            assert_eq!(f.rejected(), rejected, "degree {degree} review {review:?}");
            assert!(outs.iter().all(|o| o.decided.len() <= 64));
            if review.is_none() {
                // The review decides within L = m + 4 accepted samples (plus the rejected
                // ones among them): nothing waits long, except that the start-up decisions
                // wait for the noise estimate's first 40 samples.
                let waiting: Vec<usize> = outs
                    .iter()
                    .scan(0usize, |waiting, o| {
                        *waiting = *waiting + 1 - o.decided.len();
                        Some(*waiting)
                    })
                    .collect();
                let after_start = waiting[60..].iter().max().unwrap();
                let start = waiting.iter().max().unwrap();
                assert!(
                    *after_start <= 2 * (degree + 4) + 1,
                    "degree {degree}: {after_start}"
                );
                assert!(*start <= 41 + 2 * (degree + 4), "degree {degree}: {start}");
            }
        }
    }
}

#[test]
fn in_a_sharp_turn_the_review_rejects_what_the_gate_passed() {
    // A 3°/s turn (x = A sin(ωt), A = 1 km, ω = 2π/120 s) sampled at 1 s ± 40%, σ = 10 m, 2%
    // outliers of 5-10σ: where the filter uses its shortest memory the gate is off.
    let (mut passed, mut caught, mut taken_back) = (0, 0, 0);
    for seed in 0..20 {
        let mut r = StdRng::seed_from_u64(seed);
        let noise = Normal::new(0.0, 10.0).unwrap();
        let (mut t, mut ts, mut ys, mut bad) = (0.0, Vec::new(), Vec::new(), Vec::new());
        for _ in 0..600 {
            t += 1.0 + 0.4 * (2.0 * r.gen::<f64>() - 1.0);
            let truth = 1000.0 * (std::f64::consts::TAU * t / 120.0).sin() + 50.0 * t;
            let outlier = r.gen::<f64>() < 0.02;
            let size = r.gen_range(50.0..100.0) * if r.gen::<bool>() { 1.0 } else { -1.0 };
            ts.push(t);
            ys.push(truth + noise.sample(&mut r) + if outlier { size } else { 0.0 });
            bad.push(outlier);
        }
        let mut f = AutomaticFilter::new(2, 0.95, 1.0).unwrap();
        let (outs, flags) = run(&mut f, &ts, &ys);
        for ((o, &rejected), &outlier) in outs.iter().zip(&flags).zip(&bad) {
            if outlier && !o.outlier {
                passed += 1;
                caught += usize::from(rejected);
            }
            taken_back += usize::from(o.outlier && !rejected && !outlier);
        }
    }
    println!("gate passed {passed} outliers, the review rejected {caught}; took {taken_back} good samples the gate rejected");
    assert!(
        passed > 50,
        "the scenario has outliers the gate passes: {passed}"
    );
    assert!(
        caught as f64 >= 0.85 * passed as f64,
        "{caught} of {passed}"
    );
    assert!(taken_back > 0);
}
