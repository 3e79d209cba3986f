//! Every fast path of the engine against the reference recursion
//! ([`predict_correct`]) run from the same state with the same gains, degrees 0 … 8.
use super::super::testing::scaled_errors;
use super::batch::{
    EXPANDING_BLOCK_MAX_DEGREE, PLAIN_KERNEL_MAX_DEGREE, STEADY_BLOCK, STEADY_BLOCK_MAX_DEGREE,
};
use super::*;

/// Smooth data with a trend of degree `m` and deterministic pseudo-noise.
fn data(n: usize, m: usize) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let x = k as f64 / n as f64;
            let trend = (0..=m).fold(0.0, |acc, j| acc * x + 1.0 + 0.5 * j as f64);
            trend + (7.0 * x).sin() + 0.3 * (((k * 7919) % 101) as f64 / 101.0 - 0.5)
        })
        .collect()
}

/// The worst scaled error ([`scaled_errors`]) with `S` the memory span.
fn scaled_error(z: &[f64], want: &[f64], span: f64) -> f64 {
    scaled_errors(z, want, span).into_iter().fold(0.0, f64::max)
}

/// The reference from the engine's state over `ts`, `ys` with the gains `h(i)`.
fn reference(e: &GainEngine, ts: &[f64], ys: &[f64], h: impl Fn(usize) -> Vec<f64>) -> Vec<f64> {
    let mut z: Vec<f64> = e.z.iter().zip(&e.z_lo).map(|(a, b)| a + b).collect();
    let mut t_last = e.t_last;
    for (i, (&t, &y)) in ts.iter().zip(ys).enumerate() {
        predict_correct(&mut z, (t - t_last) / e.unit, &h(i), y);
        t_last = t;
    }
    z
}

/// A fading engine fed sample by sample up to its switch; returns it and the samples used.
fn switched(m: usize, theta: f64, tau: f64, ts: &[f64], ys: &[f64]) -> (GainEngine, usize) {
    let fading = FadingGains::new(m, theta, DiscountMode::PerUpdate, SwitchRule::Position);
    let mut e = GainEngine::new(m, tau, Some(fading));
    let mut i = 0;
    while e.switched_at().is_none() {
        e.update(ts[i], ys[i]);
        i += 1;
    }
    (e, i)
}

/// The steady fading kernels (per sample, with and without outputs; block maps up to
/// degree 5) and the compensated update against the reference, within the bound of the
/// batch tests (1e-11).
#[test]
fn steady_fast_paths_match_the_reference() {
    for m in 0..=PLAIN_KERNEL_MAX_DEGREE {
        for &(theta, tau) in &[(0.9, 1.0), (0.95, 0.1)] {
            let n = 512 * (m + 1) * (m + 1) + 4 * STEADY_BLOCK + 1000;
            let ts: Vec<f64> = (0..n).map(|k| k as f64 * tau).collect();
            let ys = data(n, m);
            let (start, i) = switched(m, theta, tau, &ts, &ys);
            let (ts, ys) = (&ts[i..], &ys[i..]);
            let gains = start.k.clone();
            let span = 1.0 / (1.0 - theta);
            let want = reference(&start, ts, ys, |_| gains.clone());
            let mut out = vec![0.0; ts.len() * (m + 1)];
            for write in [false, true] {
                let mut e = start.clone();
                let done = match write {
                    false => {
                        unrolled_sizes!(m + 1, N => e.plain_run_n::<N, false>(ts, ys, &mut out, &[]), _ => 0)
                    }
                    true => {
                        unrolled_sizes!(m + 1, N => e.plain_run_n::<N, true>(ts, ys, &mut out, &[]), _ => 0)
                    }
                };
                assert_eq!(done, ts.len(), "m {m}: the kernel stopped early");
                let err = scaled_error(&e.z, &want, span);
                assert!(err <= 1e-11, "m {m} θ {theta} write {write}: {err:e}");
            }
            let mut e = start.clone();
            for (&t, &y) in ts.iter().zip(ys) {
                e.update(t, y);
            }
            let folded: Vec<f64> = e.z.iter().zip(&e.z_lo).map(|(a, b)| a + b).collect();
            let err = scaled_error(&folded, &want, span);
            assert!(err <= 1e-11, "m {m} θ {theta} compensated: {err:e}");
            if m <= STEADY_BLOCK_MAX_DEGREE {
                let mut e = start.clone();
                let done = unrolled_sizes!(m + 1, N => e.steady_block_run::<N>(ts, ys), _ => 0);
                assert!(
                    done >= ts.len() - STEADY_BLOCK,
                    "m {m}: {done} of {}",
                    ts.len()
                );
                let want = reference(&start, &ts[..done], &ys[..done], |_| gains.clone());
                let err = scaled_error(&e.z, &want, span);
                assert!(err <= 1e-11, "m {m} θ {theta} block: {err:e}");
            }
        }
    }
}

/// The expanding-memory kernels (per sample for every degree; the least-squares blocks up
/// to degree 4) against the reference with the gains `h_k(n)` of Table 9.1 (unit steps, so
/// no step scaling), within the bound of the batch tests (1e-12).
#[test]
fn expanding_fast_paths_match_the_reference() {
    for m in 0..=PLAIN_KERNEL_MAX_DEGREE {
        let n = 20 * STEADY_BLOCK + 37;
        let ts: Vec<f64> = (0..n).map(|k| k as f64).collect();
        let ys = data(n, m);
        let mut start = GainEngine::new(m, 1.0, None);
        for i in 0..=m {
            start.update(ts[i], ys[i]);
        }
        let (ts, ys) = (&ts[m + 1..], &ys[m + 1..]);
        let schedule = ExpandingGainSchedule::new(m);
        let gains = |i: usize| {
            let mut h = vec![0.0; m + 1];
            schedule.gains((m + 1 + i) as u64, &mut h);
            h
        };
        let want = reference(&start, ts, ys, gains);
        let span = n as f64;
        let mut e = start.clone();
        let done =
            unrolled_sizes!(m + 1, N => e.plain_run_n::<N, false>(ts, ys, &mut [], &[]), _ => 0);
        assert_eq!(done, ts.len());
        let err = scaled_error(&e.z, &want, span);
        assert!(err <= 1e-12, "m {m} per sample: {err:e}");
        if m <= EXPANDING_BLOCK_MAX_DEGREE {
            let mut e = start.clone();
            let done = e.expanding_block_run(ts, ys);
            assert!(done >= ts.len() - STEADY_BLOCK, "m {m}: {done}");
            let want = reference(&start, &ts[..done], &ys[..done], gains);
            let err = scaled_error(&e.z, &want, span);
            assert!(err <= 1e-12, "m {m} block: {err:e}");
        }
    }
}

/// The start from Lagrange's form in double words against the interpolating polynomial in
/// exact rationals (Newton's divided differences, expanded about the newest time), state and
/// covariance, degrees 0 … 12, on irregular times far from the origin and a τ that is not a
/// power of two.
#[test]
fn start_equals_the_exact_interpolating_polynomial() {
    use crate::calculus::Polynomial;
    use crate::scalar::Rational;
    let exact = |x: f64| rational_from_f64(x).unwrap();
    for m in 0..=12 {
        let tau = 0.37;
        let ts: Vec<f64> = (0..=m)
            .map(|i| 1.7e9 + 0.01 * i as f64 + 0.003 * ((i * i) % 7) as f64)
            .collect();
        let ys: Vec<f64> = (0..=m).map(|i| 1e4 + (i as f64 * 1.3).sin()).collect();
        let mut e = GainEngine::new(m, tau, None);
        e.track_covariance(1.0);
        for (&t, &y) in ts.iter().zip(&ys) {
            e.update(t, y);
        }
        let u: Vec<Rational> = ts
            .iter()
            .map(|&t| (exact(t) - exact(ts[m])) / exact(tau))
            .collect();
        let interpolate = |v: &[Rational]| -> Vec<Rational> {
            let mut c = v.to_vec();
            for j in 1..=m {
                for i in (j..=m).rev() {
                    c[i] = (c[i].clone() - c[i - 1].clone()) / (u[i].clone() - u[i - j].clone());
                }
            }
            let mut p = Polynomial::constant(c[m].clone());
            for j in (0..m).rev() {
                p = p.mul(&Polynomial::new(vec![-u[j].clone(), Rational::from_i64(1)]));
                p = p.add(&Polynomial::constant(c[j].clone()));
            }
            let mut coeffs = p.coeffs;
            coeffs.resize(m + 1, Rational::from_i64(0));
            coeffs
        };
        let want = interpolate(&ys.iter().map(|&y| exact(y)).collect::<Vec<_>>());
        // Column i of L: the interpolating polynomial of the i-th unit vector.
        let l: Vec<Vec<f64>> = (0..=m)
            .map(|i| {
                let unit: Vec<Rational> = (0..=m)
                    .map(|j| Rational::from_i64(i64::from(i == j)))
                    .collect();
                interpolate(&unit).iter().map(|c| c.to_f64()).collect()
            })
            .collect();
        let scale: f64 = ys.iter().map(|y| y.abs()).sum();
        let (_, p) = e.cov.as_ref().unwrap();
        for k in 0..=m {
            // The weights' relative error is a few 2⁻¹⁰⁶, so the sum's is that times Σ|L y|.
            let largest = l.iter().map(|col| col[k].abs()).fold(0.0, f64::max);
            let got = exact(e.z[k]) + exact(e.z_lo[k]);
            let err = (got - want[k].clone()).to_f64().abs();
            assert!(err <= 1e-28 * largest * scale, "m={m} k={k}: {err:e}");
            // The covariance P = L Lᵀ, its diagonal.
            let var: f64 = l.iter().map(|col| col[k] * col[k]).sum();
            let rel = (p[(k, k)] - var).abs() / var;
            assert!(rel <= 1e-13, "m={m} P_{k}{k}: {rel:e}");
        }
    }
}
