//! The batch σ path (`PolynomialFilter::update_many_sigma_into`): each row's derivatives and
//! 1σ equal those of `update` + `try_estimate_at` on the same samples (the covariance of the
//! Joseph recursion, Morrison (12.2.x), kept without a matrix per sample; its steady state held
//! by the plain kernels), for every engine, even and irregular steps and gaps; and its refusals.

mod common;

use seqsmooth::FixedEngine;
use seqsmooth::{Engine, Error, ExpandingMemory, FadingMemory, FixedMemory, PolynomialFilter};

/// Times with even stretches, jitter and a gap (the steady covariance is left and re-found).
fn samples(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut t = 1.7e9;
    let (mut ts, mut ys) = (Vec::new(), Vec::new());
    for k in 0..n {
        ts.push(t);
        ys.push(3.0 + 0.2 * (t - 1.7e9) + ((k * 7919) % 13) as f64 * 0.1);
        t += match k {
            k if (900..910).contains(&k) => 0.25 + 0.01 * (k % 3) as f64,
            1500 => 7.0,
            _ => 0.25,
        };
    }
    (ts, ys)
}

fn filters() -> Vec<(&'static str, Box<dyn PolynomialFilter>)> {
    let mut out: Vec<(&'static str, Box<dyn PolynomialFilter>)> = Vec::new();
    for m in [0, 1, 2, 4] {
        for engine in [Engine::Gain, Engine::Exact] {
            out.push((
                "fading",
                Box::new(
                    FadingMemory::new(m, 0.9, 0.25, engine)
                        .unwrap()
                        .with_noise_sigma(0.3)
                        .unwrap(),
                ),
            ));
            out.push((
                "expanding",
                Box::new(
                    ExpandingMemory::new(m, engine)
                        .unwrap()
                        .with_noise_sigma(0.3)
                        .unwrap(),
                ),
            ));
        }
        out.push((
            "fixed",
            Box::new(
                FixedMemory::new(m, 31, FixedEngine::Adaptive)
                    .unwrap()
                    .with_noise_sigma(0.3)
                    .unwrap(),
            ),
        ));
    }
    out
}

/// Row by row against `update` + `try_estimate_at`: derivatives and 1σ to 1e-9 relative (the
/// kernels and the per-sample recursion round differently; the covariance's steady state is
/// kept to 4ε per update), NaN rows exactly where there is no estimate.
#[test]
fn batch_sigma_equals_per_sample_estimates() {
    let (t, y) = samples(3000);
    for ((name, mut batch), (_, mut single)) in filters().into_iter().zip(filters()) {
        let w = batch.degree() + 1;
        let mut rows = vec![0.0; t.len() * 2 * w];
        // Two calls: the state carries over.
        let half = 1200 * 2 * w;
        batch
            .update_many_sigma_into(&t[..1200], &y[..1200], &mut rows[..half])
            .unwrap();
        batch
            .update_many_sigma_into(&t[1200..], &y[1200..], &mut rows[half..])
            .unwrap();
        for (i, row) in rows.chunks_exact(2 * w).enumerate() {
            single.update(t[i], y[i]).unwrap();
            match single.try_estimate_at(t[i]) {
                Err(Error::TooFewSamples { .. }) => {
                    assert!(row.iter().all(|v| v.is_nan()), "{name} m {} row {i}", w - 1);
                }
                Ok(s) => {
                    let sd = s.std_devs().unwrap();
                    for k in 0..w {
                        let (d, want) = (row[k], s.derivatives[k]);
                        let scale = want.abs().max(sd[k]);
                        assert!(
                            (d - want).abs() <= 1e-9 * scale,
                            "{name} m {} row {i} d{k}: {d} vs {want}",
                            w - 1
                        );
                        assert!(
                            (row[w + k] - sd[k]).abs() <= 1e-9 * sd[k],
                            "{name} m {} row {i} s{k}: {} vs {}",
                            w - 1,
                            row[w + k],
                            sd[k]
                        );
                    }
                }
                Err(e) => panic!("{name}: {e}"),
            }
        }
    }
}

/// Without a noise σ the first determined sample is the error, the samples up to it taken; a
/// bad sample is named by its index; rows of the wrong length are refused.
#[test]
fn batch_sigma_refusals() {
    let mut f = FadingMemory::new(2, 0.9, 1.0, Engine::Gain).unwrap();
    let t: Vec<f64> = (0..10).map(f64::from).collect();
    let mut rows = vec![0.0; 10 * 6];
    let e = f.update_many_sigma_into(&t, &t, &mut rows).unwrap_err();
    assert!(matches!(e, Error::InBatch { index: 2, .. }), "{e}");
    assert!(e.to_string().contains("sigma"), "{e}");
    assert_eq!(f.samples(), 3);
    let mut f = ExpandingMemory::new(1, Engine::Exact)
        .unwrap()
        .with_noise_sigma(1.0)
        .unwrap();
    let y = [1.0, 2.0, f64::NAN, 4.0];
    let mut rows = vec![0.0; 4 * 4];
    let e = f
        .update_many_sigma_into(&t[..4], &y, &mut rows)
        .unwrap_err();
    assert!(matches!(e, Error::InBatch { index: 2, .. }), "{e}");
    assert!(f
        .update_many_sigma_into(&t[..4], &y, &mut rows[..15])
        .is_err());
}

/// Legendre polynomials `P_0 … P_m` at `x` (Bonnet's recursion).
fn legendre(m: usize, x: f64) -> Vec<f64> {
    let mut p = vec![1.0; m + 1];
    if m >= 1 {
        p[1] = x;
    }
    for j in 1..m {
        p[j + 1] = ((2 * j + 1) as f64 * x * p[j] - j as f64 * p[j - 1]) / (j + 1) as f64;
    }
    p
}

/// The 1σ of the derivatives at `times[n]` of the weighted least-squares polynomial of degree
/// `m` through samples `0..=n` with weights `w` and noise σ, by a direct QR solve in the
/// Legendre basis on `[times[0], times[n]]` (an algorithm independent of the filters'): with
/// `√W A = QR`, the coefficients `c = R⁻¹ Qᵀ √W y` have covariance `σ² R⁻¹ Qᵀ W Q R⁻ᵀ` (the
/// sandwich; `σ² (RᵀR)⁻¹` for unit weights), and the derivatives are `G c` with
/// `G_dj = P_j^(d)(1) (2/L)^d`, `P_j^(d)(1) = (j+d)!/(2^d d! (j-d)!)`.
fn qr_std_devs(times: &[f64], w: &[f64], n: usize, m: usize, sigma: f64) -> Vec<f64> {
    qr_std_devs_on(times, w, n, m, sigma, times[0])
}

/// [`qr_std_devs`] with the Legendre basis on `[t0, times[n]]` (rows before `t0`, of small
/// weight, lie outside `[-1, 1]`).
fn qr_std_devs_on(times: &[f64], w: &[f64], n: usize, m: usize, sigma: f64, t0: f64) -> Vec<f64> {
    use nalgebra::DMatrix;
    let p = m + 1;
    let len = times[n] - t0;
    let a = DMatrix::from_fn(n + 1, p, |k, j| {
        w[k].sqrt() * legendre(m, 2.0 * (times[k] - t0) / len - 1.0)[j]
    });
    let (q, r) = a.qr().unpack();
    let r_inv = r.try_inverse().expect("determined");
    let wq = DMatrix::from_fn(n + 1, p, |k, j| w[k] * q[(k, j)]);
    let cov_c = &r_inv * (q.transpose() * wq) * r_inv.transpose() * (sigma * sigma);
    let factorial = |k: usize| (1..=k).map(|i| i as f64).product::<f64>();
    let g = DMatrix::from_fn(p, p, |d, j| {
        if d > j {
            0.0
        } else {
            factorial(j + d) / (2f64.powi(d as i32) * factorial(d) * factorial(j - d))
                * (2.0 / len).powi(d as i32)
        }
    });
    (&g * cov_c * g.transpose())
        .diagonal()
        .iter()
        .map(|v| v.sqrt())
        .collect()
}

/// The exact engine's 1σ on the batch σ path against the direct QR covariance
/// ([`qr_std_devs`]) at its first determined rows and at random rows, degrees 0 to 10 (the
/// sizes with unrolled kernels and beyond), expanding and fading memory per time and per
/// update, on Poisson times (gaps of 0.001 to several mean steps): every σ to 1e-8 relative.
#[test]
fn exact_engine_sigma_equals_direct_qr_covariance() {
    use rand::Rng;
    use seqsmooth::DiscountMode;
    let (theta, tau, sigma) = (0.93, 0.1, 0.3);
    let mut worst = 0.0f64;
    for m in 0..=10 {
        let times = common::random_times(300, 0.1, 7 + m as u64);
        let ys: Vec<f64> = times.iter().map(|t| (3.0 * t).sin() + 0.1 * t).collect();
        let mut r = common::rng(17 + m as u64);
        let mut check: Vec<usize> = (m..m + 3).collect();
        check.extend((0..8).map(|_| r.gen_range(m + 3..times.len())));
        for mode in [
            None,
            Some(DiscountMode::PerTime),
            Some(DiscountMode::PerUpdate),
        ] {
            let mut f: Box<dyn PolynomialFilter> = match mode {
                None => Box::new(
                    ExpandingMemory::new(m, Engine::Exact)
                        .unwrap()
                        .with_noise_sigma(sigma)
                        .unwrap(),
                ),
                Some(mode) => Box::new(
                    FadingMemory::new(m, theta, tau, Engine::Exact)
                        .unwrap()
                        .with_discount_mode(mode)
                        .unwrap()
                        .with_noise_sigma(sigma)
                        .unwrap(),
                ),
            };
            let w = m + 1;
            let mut rows = vec![0.0; times.len() * 2 * w];
            f.update_many_sigma_into(&times, &ys, &mut rows).unwrap();
            for &n in &check {
                let weights: Vec<f64> = (0..=n)
                    .map(|k| match mode {
                        None => 1.0,
                        Some(DiscountMode::PerTime) => theta.powf((times[n] - times[k]) / tau),
                        Some(DiscountMode::PerUpdate) => theta.powi((n - k) as i32),
                    })
                    .collect();
                let want = qr_std_devs(&times, &weights, n, m, sigma);
                let got = &rows[n * 2 * w + w..(n + 1) * 2 * w];
                for (k, (g, s)) in got.iter().zip(&want).enumerate() {
                    let err = (g - s).abs() / s;
                    worst = worst.max(err);
                    assert!(err < 1e-8, "m {m} {mode:?} row {n} s{k}: {g} vs {s}");
                }
            }
        }
    }
    eprintln!("largest relative difference {worst:.1e}");
}

/// The same on long irregular runs (10⁵ Poisson times, gaps of 0.001 to several mean steps),
/// degrees 4 to 8, at the last rows: the fading filters have re-centred their basis some
/// thousand times by then and the expanding one has 10⁵ rows of information. The oracle
/// drops the rows whose weight is below 10⁻²⁵ of the newest's and puts its Legendre basis on
/// the stretch where the weights exceed 10⁻³ (the memory, not the whole run, so that the
/// oracle's own basis is well conditioned). Every σ to 1e-8 relative to degree 7 and 1e-6
/// at degree 8 (measured there: up to 2e-7, with memories of about
/// 14 samples for 9 coefficients; which side rounds more is not resolved here).
#[test]
fn exact_engine_sigma_on_long_irregular_runs() {
    use seqsmooth::DiscountMode;
    let (theta, tau, sigma) = (0.93, 0.1, 0.3);
    let times = common::random_times(100_000, 0.1, 41);
    let ys: Vec<f64> = times.iter().map(|t| (0.3 * t).sin() + 1e-3 * t).collect();
    let mut worst = 0.0f64;
    for m in 4..=8 {
        for mode in [
            None,
            Some(DiscountMode::PerTime),
            Some(DiscountMode::PerUpdate),
        ] {
            let mut f: Box<dyn PolynomialFilter> = match mode {
                None => Box::new(
                    ExpandingMemory::new(m, Engine::Exact)
                        .unwrap()
                        .with_noise_sigma(sigma)
                        .unwrap(),
                ),
                Some(mode) => Box::new(
                    FadingMemory::new(m, theta, tau, Engine::Exact)
                        .unwrap()
                        .with_discount_mode(mode)
                        .unwrap()
                        .with_noise_sigma(sigma)
                        .unwrap(),
                ),
            };
            let w = m + 1;
            let tol = if m < 8 { 1e-8 } else { 1e-6 };
            let mut rows = vec![0.0; times.len() * 2 * w];
            f.update_many_sigma_into(&times, &ys, &mut rows).unwrap();
            let last = times.len() - 1;
            for n in [last - 777, last - 1, last] {
                let weights: Vec<f64> = (0..=n)
                    .map(|k| match mode {
                        None => 1.0,
                        Some(DiscountMode::PerTime) => theta.powf((times[n] - times[k]) / tau),
                        Some(DiscountMode::PerUpdate) => theta.powi((n - k) as i32),
                    })
                    .collect();
                let start = weights.iter().position(|&v| v >= 1e-25).unwrap();
                let from = weights.iter().position(|&v| v >= 1e-3).unwrap();
                let want = qr_std_devs_on(
                    &times[start..],
                    &weights[start..],
                    n - start,
                    m,
                    sigma,
                    times[from],
                );
                let got = &rows[n * 2 * w + w..(n + 1) * 2 * w];
                for (k, (g, s)) in got.iter().zip(&want).enumerate() {
                    let err = (g - s).abs() / s;
                    worst = worst.max(err);
                    assert!(err < tol, "m {m} {mode:?} row {n} s{k}: {g} vs {s}");
                }
            }
        }
    }
    eprintln!("largest relative difference {worst:.1e}");
}

/// One batch call against the same samples in uneven pieces (1, 7, 333 samples, the rest):
/// the σ rows are the same to the bit at degrees 0-8, fading and expanding exact engines
/// (each row's 1σ comes from the state after its sample alone, whichever kernel — fused or
/// not — the processor runs; a piece boundary changes nothing).
#[test]
fn exact_engine_sigma_rows_do_not_depend_on_the_batches() {
    let (ts, ys) = samples(2000);
    for m in 0..=8 {
        let make = |fading: bool| -> Box<dyn PolynomialFilter> {
            match fading {
                true => Box::new(
                    FadingMemory::new(m, 0.9, 0.25, Engine::Exact)
                        .unwrap()
                        .with_noise_sigma(0.3)
                        .unwrap(),
                ),
                false => Box::new(
                    ExpandingMemory::new(m, Engine::Exact)
                        .unwrap()
                        .with_noise_sigma(0.3)
                        .unwrap(),
                ),
            }
        };
        for fading in [true, false] {
            let w = 2 * (m + 1);
            let mut whole = vec![0.0; ts.len() * w];
            // The first rows (not yet determined) are errors by the row rule: start past them.
            let skip = m + 1;
            let mut f = make(fading);
            f.update_many(&ts[..skip], &ys[..skip]).unwrap();
            f.update_many_sigma_into(&ts[skip..], &ys[skip..], &mut whole[skip * w..])
                .unwrap();
            let mut g = make(fading);
            g.update_many(&ts[..skip], &ys[..skip]).unwrap();
            let mut pieces = vec![0.0; ts.len() * w];
            let mut start = skip;
            for len in [1, 7, 333, usize::MAX] {
                let end = start.saturating_add(len).min(ts.len());
                g.update_many_sigma_into(
                    &ts[start..end],
                    &ys[start..end],
                    &mut pieces[start * w..end * w],
                )
                .unwrap();
                start = end;
            }
            assert_eq!(start, ts.len());
            for (i, (a, b)) in whole.iter().zip(&pieces).enumerate() {
                assert_eq!(a.to_bits(), b.to_bits(), "m {m} fading {fading} cell {i}");
            }
            assert!(whole[skip * w..].iter().all(|v| v.is_finite()));
        }
    }
}
