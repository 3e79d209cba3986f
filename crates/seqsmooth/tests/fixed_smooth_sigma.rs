//! Whole-series smoothing as a stream and with its 1σ (`CentredSmoother`,
//! `smooth_with_sigma_into`; Morrison §7.4-7.5): the stream gives the batch's rows bit for bit
//! in any chunking; the 1σ against a direct QR solve of each window (the covariance
//! `σ² (AᵀA)⁻¹` of its fit, and the residuals' σ); and Monte Carlo coverage, with the known
//! noise (normal) and the estimated one (Student-t with `W − m − 1` degrees of freedom).

use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use seqsmooth::polynomial::fixed::{
    smooth, smooth_into, smooth_with_sigma_into, CentredSmoother, SmoothSigma,
};
use seqsmooth::{Error, Param};
use statrs::distribution::{ContinuousCDF, StudentsT};

/// Evenly spaced, irregular, and even with one irregular stretch (windows of both engines).
fn series(kind: usize, n: usize, seed: u64) -> (Vec<f64>, Vec<f64>) {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let mut t: f64 = 1.7e9;
    let (mut ts, mut ys) = (Vec::new(), Vec::new());
    for k in 0..n {
        ts.push(t);
        ys.push((1e-1 * (t - 1.7e9)).sin() * 3.0 + rng.gen_range(-0.5..0.5));
        t += match kind {
            0 => 0.25,
            1 => 0.1 + 0.3 * rng.gen::<f64>(),
            _ if (n / 3..n / 3 + 7).contains(&k) => 0.13 + 0.01 * k as f64,
            _ => 0.25,
        };
    }
    (ts, ys)
}

/// Rows of a stream fed `(t, y)` one at a time: derivatives and 1σ, in order of index.
fn streamed(t: &[f64], y: &[f64], m: usize, w: usize, sigma: SmoothSigma) -> (Vec<f64>, Vec<f64>) {
    let mut s = CentredSmoother::new(m, w, sigma).unwrap();
    let (mut d, mut sd, mut next) = (Vec::new(), Vec::new(), 0);
    let mut take = |r: seqsmooth::polynomial::fixed::SmoothedRow<'_>| -> Result<(), Error> {
        assert_eq!(r.index, next, "rows in order");
        next += 1;
        d.extend_from_slice(r.derivatives);
        sd.extend_from_slice(r.std_devs.unwrap_or(&[]));
        Ok(())
    };
    for (&t, &y) in t.iter().zip(y) {
        s.push(t, y, &mut take).unwrap();
    }
    s.finish(&mut take).unwrap();
    (d, sd)
}

/// The stream and the batch functions are one engine: the same numbers bit for bit, with and
/// without σ, on every kind of spacing, odd and even windows, degrees 0 to 5.
#[test]
fn stream_equals_batch_bit_for_bit() {
    for kind in 0..3 {
        let (t, y) = series(kind, 300, 7 + kind as u64);
        for (m, w) in [(0, 1), (1, 4), (2, 21), (3, 12), (5, 41), (2, 300)] {
            let p = m + 1;
            let mut plain = vec![0.0; 300 * p];
            smooth_into(&t, &y, m, w, &mut plain).unwrap();
            let (d, none) = streamed(&t, &y, m, w, SmoothSigma::Off);
            assert!(none.is_empty());
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&d), bits(&plain), "kind {kind} m {m} w {w}");
            let rows = smooth(&t, &y, m, w).unwrap().concat();
            assert_eq!(bits(&rows), bits(&plain));
            for sigma in [Some(0.3), None] {
                if sigma.is_none() && w <= p {
                    continue;
                }
                let (mut d2, mut s2) = (vec![0.0; 300 * p], vec![0.0; 300 * p]);
                smooth_with_sigma_into(&t, &y, m, w, sigma, &mut d2, &mut s2).unwrap();
                let mode = sigma.map_or(SmoothSigma::Estimated, SmoothSigma::Given);
                let (d3, s3) = streamed(&t, &y, m, w, mode);
                assert_eq!(bits(&d2), bits(&plain));
                assert_eq!(bits(&d3), bits(&plain));
                assert_eq!(bits(&s3), bits(&s2), "kind {kind} m {m} w {w} {sigma:?}");
                assert!(s2.iter().all(|v| v.is_finite() && *v >= 0.0));
            }
        }
    }
}

/// The direct fit of one window: derivatives at `t0`, their covariance per unit variance
/// `(k! j!) [(AᵀA)⁻¹]_kj / h^(k+j)` (`A` the powers of `(t − t0)/h`, by nalgebra's QR), and
/// the residual sum of squares.
fn direct(t: &[f64], y: &[f64], m: usize, t0: f64) -> (Vec<f64>, Vec<f64>, f64) {
    let h = (t[t.len() - 1] - t[0]).max(1e-300) / 2.0;
    let a = DMatrix::from_fn(t.len(), m + 1, |i, k| ((t[i] - t0) / h).powi(k as i32));
    let qr = a.clone().qr();
    let (q, r) = (qr.q(), qr.r());
    let c = r
        .solve_upper_triangular(&(q.transpose() * DVector::from_column_slice(y)))
        .unwrap();
    let rinv = r
        .solve_upper_triangular(&DMatrix::identity(m + 1, m + 1))
        .unwrap();
    let cov = &rinv * rinv.transpose();
    let fact = |k: usize| (1..=k).map(|v| v as f64).product::<f64>();
    let d = (0..=m).map(|k| c[k] * fact(k) / h.powi(k as i32)).collect();
    let v = (0..=m)
        .map(|k| cov[(k, k)] * (fact(k) / h.powi(k as i32)).powi(2))
        .collect();
    let rss = (&a * &c - DVector::from_column_slice(y)).norm_squared();
    (d, v, rss)
}

/// Each row's 1σ is σ·√(VRF) of its window's fit, and the estimated σ the residuals' RMS over
/// `W − m − 1` degrees of freedom, against nalgebra's QR of the window (even windows: the
/// sliding moments; irregular ones: the library's own QR), to 1e-9 relative.
#[test]
fn sigma_equals_direct_qr_of_the_window() {
    for kind in 0..3 {
        let (t, y) = series(kind, 120, 40 + kind as u64);
        let t: Vec<f64> = t.iter().map(|v| v - 1.7e9).collect();
        for (m, w) in [(0, 3), (1, 7), (2, 21), (3, 16)] {
            let p = m + 1;
            let n = t.len();
            let (mut d, mut s) = (vec![0.0; n * p], vec![0.0; n * p]);
            let (mut dg, mut sg) = (vec![0.0; n * p], vec![0.0; n * p]);
            smooth_with_sigma_into(&t, &y, m, w, None, &mut d, &mut s).unwrap();
            smooth_with_sigma_into(&t, &y, m, w, Some(0.7), &mut dg, &mut sg).unwrap();
            for row in 0..n {
                let start = row.saturating_sub((w - 1) / 2).min(n - w);
                let (wt, wy) = (&t[start..start + w], &y[start..start + w]);
                let (dd, vrf, rss) = direct(wt, wy, m, t[row]);
                let s_hat = (rss / (w - p) as f64).sqrt();
                for k in 0..p {
                    let scale = dd[k].abs().max(vrf[k].sqrt() * 10.0);
                    assert!(
                        (d[row * p + k] - dd[k]).abs() <= 1e-9 * scale,
                        "kind {kind} m {m} w {w} row {row} d{k}: {} vs {}",
                        d[row * p + k],
                        dd[k]
                    );
                    let want_g = 0.7 * vrf[k].sqrt();
                    let want_e = s_hat * vrf[k].sqrt();
                    let got_g = sg[row * p + k];
                    let got_e = s[row * p + k];
                    assert!(
                        (got_g - want_g).abs() <= 1e-9 * want_g,
                        "kind {kind} m {m} w {w} row {row} s{k} given: {got_g} vs {want_g}"
                    );
                    assert!(
                        (got_e - want_e).abs() <= 1e-8 * want_e,
                        "kind {kind} m {m} w {w} row {row} s{k} estimated: {got_e} vs {want_e}"
                    );
                }
            }
        }
    }
}

/// Monte Carlo: on a quadratic truth (no bias at degree 2) with Gaussian noise, the fraction of
/// rows whose error is within 1σ, 2σ and 3σ is the normal probability with the given σ and the
/// Student-t one (18 degrees of freedom) with the estimated σ, within 4.5 binomial standard
/// deviations. Rows are taken from non-overlapping windows (independent errors): 600 series
/// × 9 rows × 3 derivatives, even and irregular times.
#[test]
fn coverage_monte_carlo() {
    let (m, w, n) = (2, 21, 200);
    let normal = statrs::distribution::Normal::new(0.0, 1.0).unwrap();
    let student = StudentsT::new(0.0, 1.0, (w - m - 1) as f64).unwrap();
    let noise = Normal::new(0.0, 0.5).unwrap();
    for irregular in [false, true] {
        // [given, estimated] × k = 1, 2, 3: rows within kσ.
        let mut within = [[0usize; 3]; 2];
        let mut total = 0usize;
        for run in 0..600u64 {
            let mut rng = rand::rngs::StdRng::seed_from_u64(1000 + run);
            let mut t = vec![0.0];
            for _ in 1..n {
                let step = if irregular {
                    0.05 + 0.1 * rng.gen::<f64>()
                } else {
                    0.1
                };
                t.push(t[t.len() - 1] + step);
            }
            let truth = |t: f64| [3.0 - 2.0 * t + 0.4 * t * t, -2.0 + 0.8 * t, 0.8];
            let y: Vec<f64> = t
                .iter()
                .map(|&t| truth(t)[0] + noise.sample(&mut rng))
                .collect();
            let p = m + 1;
            let (mut d, mut sg, mut se) = (vec![0.0; n * p], vec![0.0; n * p], vec![0.0; n * p]);
            smooth_with_sigma_into(&t, &y, m, w, Some(0.5), &mut d, &mut sg).unwrap();
            smooth_with_sigma_into(&t, &y, m, w, None, &mut d, &mut se).unwrap();
            for row in (w / 2..n - w / 2).step_by(w) {
                let want = truth(t[row]);
                for k in 0..p {
                    let err = (d[row * p + k] - want[k]).abs();
                    for (j, s) in [&sg, &se].iter().enumerate() {
                        for (c, kk) in [1.0, 2.0, 3.0].iter().enumerate() {
                            within[j][c] += usize::from(err <= kk * s[row * p + k]);
                        }
                    }
                    total += 1;
                }
            }
        }
        for (j, name) in ["given", "estimated"].iter().enumerate() {
            for (c, k) in [1.0f64, 2.0, 3.0].iter().enumerate() {
                let p = if j == 0 {
                    normal.cdf(*k) - normal.cdf(-k)
                } else {
                    student.cdf(*k) - student.cdf(-k)
                };
                let got = within[j][c] as f64 / total as f64;
                let sd = (p * (1.0 - p) / total as f64).sqrt();
                assert!(
                    (got - p).abs() <= 4.5 * sd,
                    "irregular {irregular}, {name} sigma, {k} sigma: {got:.4} of {total} vs {p:.4}"
                );
            }
        }
    }
}

/// The refusals: a σ that is not positive, an estimated σ with no residual degrees of freedom,
/// a stream that ends before its first window, and a bad sample (with nothing taken).
#[test]
fn refusals() {
    assert!(CentredSmoother::new(2, 5, SmoothSigma::Given(0.0)).is_err());
    assert!(CentredSmoother::new(2, 5, SmoothSigma::Given(f64::NAN)).is_err());
    let e = CentredSmoother::new(2, 3, SmoothSigma::Estimated).unwrap_err();
    assert!(e.to_string().contains("at least 4"), "{e}");
    let mut s = CentredSmoother::new(1, 5, SmoothSigma::Off).unwrap();
    let mut none = |_: seqsmooth::polynomial::fixed::SmoothedRow<'_>| -> Result<(), Error> {
        panic!("no row before the window is full")
    };
    s.push(0.0, 1.0, &mut none).unwrap();
    assert!(s.push(0.0, 1.0, &mut none).is_err());
    assert!(s.push(1.0, f64::NAN, &mut none).is_err());
    assert_eq!(s.samples(), 1);
    assert!(matches!(
        s.finish(|_| Ok::<(), Error>(())),
        Err(Error::TooFewSamplesFor {
            param: Param::Window,
            needed: 5,
            got: 1
        })
    ));
    let (mut d, mut sd) = (vec![0.0; 6], vec![0.0; 6]);
    let t = [0.0, 1.0, 2.0];
    assert!(
        smooth_with_sigma_into(&t, &[1.0, 2.0, 4.0], 1, 3, None, &mut d, &mut sd[..5]).is_err()
    );
    assert!(smooth_with_sigma_into(&t, &[1.0, 2.0, 4.0], 1, 2, None, &mut d, &mut sd).is_err());
}
