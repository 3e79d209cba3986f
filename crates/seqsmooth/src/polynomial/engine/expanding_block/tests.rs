//! Oracles: exact rational least squares (small runs), blocked Householder QR in a Legendre
//! basis (long runs), and the gain recursion itself, exact or in double-word arithmetic.
use super::super::testing::scaled_errors;
use super::*;
use crate::linalg::inverse_exact;
use crate::model::{for_each_shift_step, shift_scaled_compensated};
use crate::numeric::double_word::{two_prod, two_sum};
use crate::polynomial::expanding::gains::{expanding_gains, ExpandingGainSchedule};
use crate::polynomial::form::GainForm;
use crate::scalar::{rational_from_f64, Rational, Scalar};
use nalgebra::DMatrix;
use num_traits::Zero;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

fn max_err(e: &[f64]) -> f64 {
    e.iter().copied().fold(0.0, f64::max)
}

/// A trend of degree `deg` over the span `len` (every Taylor coefficient significant), a
/// sine and Gaussian-ish noise, as `f64` values.
fn data(len: usize, deg: usize, offset: f64, noise: f64, seed: u64) -> Vec<f64> {
    let mut r = StdRng::seed_from_u64(seed);
    let a: Vec<f64> = (0..=deg).map(|_| r.gen_range(0.5..1.5) * 10.0).collect();
    (0..len)
        .map(|u| {
            let x = u as f64 / len as f64 - 0.3;
            let trend = a.iter().rev().fold(0.0, |acc, c| acc * x + c);
            let e: f64 = (0..4).map(|_| r.gen::<f64>() - 0.5).sum();
            offset + trend + (20.0 * x).sin() + noise * e
        })
        .collect()
}

/// Exact least squares of degree `m` through `w` at `u = 0 … N−1`, as Taylor coefficients
/// about `u = N−1` (the normal equations in `x = u − (N−1)`, solved exactly).
fn exact_fit(m: usize, w: &[Rational]) -> Vec<Rational> {
    let k = m + 1;
    let last = w.len() as i64 - 1;
    let mut pw = vec![Rational::zero(); 2 * m + 1];
    let mut rhs = vec![Rational::zero(); k];
    for (u, wu) in w.iter().enumerate() {
        let x = Rational::from_i64(u as i64 - last);
        let mut p = Rational::from_i64(1);
        for r in 0..=2 * m {
            if r < k {
                rhs[r] += wu * &p;
            }
            pw[r] += &p;
            p *= &x;
        }
    }
    let g = DMatrix::from_fn(k, k, |i, j| pw[i + j].clone());
    let gi = inverse_exact(&g).expect("Gram matrix of ≥ m+1 points is regular");
    (0..k)
        .map(|i| (0..k).fold(Rational::zero(), |acc, j| acc + &gi[(i, j)] * &rhs[j]))
        .collect()
}

fn to_f64(v: &[Rational]) -> Vec<f64> {
    v.iter().map(|x| x.to_f64()).collect()
}

fn rat(x: f64) -> Rational {
    rational_from_f64(x).unwrap()
}

/// `p_old(u) = Σ_k z_k (u − (n−1))^k` for `u < n`, exactly.
fn pseudo_data(z: &[f64], n: usize) -> Vec<Rational> {
    let zr: Vec<Rational> = z.iter().map(|&v| rat(v)).collect();
    (0..n)
        .map(|u| {
            let x = Rational::from_i64(u as i64 - (n as i64 - 1));
            zr.iter()
                .rev()
                .fold(Rational::zero(), |acc, c| acc * &x + c)
        })
        .collect()
}

/// Against exact rational least squares: the kernel from the rounded old fit vs (a) the
/// exact combination of that same old fit with the new samples, (b) the exact fit of all
/// samples (which adds the rounding of the old state).
#[test]
fn expanding_block_matches_exact_least_squares() {
    let mut table = Vec::new();
    for m in 0..=MAX_BLOCK_DEGREE {
        let mut worst_a = 0.0f64;
        let mut worst_b = 0.0f64;
        for (ni, &big_n) in [m + 2, 13, 64, 300].iter().enumerate() {
            if big_n < m + 2 {
                continue;
            }
            let y = data(big_n, m, 3.0, 0.5, 100 * m as u64 + ni as u64);
            let yr: Vec<Rational> = y.iter().map(|&v| rat(v)).collect();
            let all = exact_fit(m, &yr);
            for n in [m + 1, m + 2, big_n / 2, big_n - 1] {
                if n < m + 1 || n >= big_n {
                    continue;
                }
                let mut z = to_f64(&exact_fit(m, &yr[..n]));
                let mut w = pseudo_data(&z, n);
                w.extend_from_slice(&yr[n..]);
                let want_a = to_f64(&exact_fit(m, &w));
                advance_even_fit(m, n as u64, &mut z, &y[n..]);
                let span = (big_n - 1) as f64;
                let ea = max_err(&scaled_errors(&z, &want_a, span));
                let eb = max_err(&scaled_errors(&z, &to_f64(&all), span));
                worst_a = worst_a.max(ea);
                worst_b = worst_b.max(eb);
                let tol = if m <= 2 {
                    1e-13
                } else if m <= 4 {
                    1e-12
                } else {
                    1e-9
                };
                assert!(ea < tol, "m {m} N {big_n} n {n}: {ea:e}");
            }
        }
        table.push((m, worst_a, worst_b));
    }
    for (m, a, b) in table {
        println!("exact N≤300 m {m}: vs same old state {a:.1e}, vs fit of all samples {b:.1e}");
    }
}

/// Legendre polynomials `P_0 … P_m` at `s`.
fn legendre(m: usize, s: f64, out: &mut [f64]) {
    out[0] = 1.0;
    if m >= 1 {
        out[1] = s;
    }
    for j in 1..m {
        let jf = j as f64;
        out[j + 1] = ((2.0 * jf + 1.0) * s * out[j] - jf * out[j - 1]) / (jf + 1.0);
    }
}

/// Least squares by Householder QR (nalgebra) in the Legendre basis of
/// `s = (2u + 1 − M)/M` over `u = 0 … M−1` with values `value(u)`, as Taylor coefficients
/// about `u = M−1` in step units. Tall-skinny QR: the triangular factors of 128-row chunks
/// are merged pairwise in a binary tree (a stack of levels), so that rounding grows with
/// the logarithm of the length rather than the length.
fn qr_fit(m: usize, big_m: usize, value: impl Fn(usize) -> f64) -> Vec<f64> {
    let k = m + 1;
    let chunk = 128;
    let mf = big_m as f64;
    let triangle = |a: DMatrix<f64>| -> DMatrix<f64> {
        let rr = a.qr().r();
        let mut r = DMatrix::<f64>::zeros(k + 1, k + 1);
        let rows = rr.nrows().min(k + 1);
        r.view_mut((0, 0), (rows, k + 1))
            .copy_from(&rr.view((0, 0), (rows, k + 1)));
        r
    };
    let merge = |a: &DMatrix<f64>, b: &DMatrix<f64>| -> DMatrix<f64> {
        let mut s = DMatrix::<f64>::zeros(2 * (k + 1), k + 1);
        s.view_mut((0, 0), (k + 1, k + 1)).copy_from(a);
        s.view_mut((k + 1, 0), (k + 1, k + 1)).copy_from(b);
        triangle(s)
    };
    let mut levels: Vec<Option<DMatrix<f64>>> = Vec::new();
    let mut p = vec![0.0; k];
    let mut u = 0;
    while u < big_m {
        let rows = chunk.min(big_m - u);
        let mut a = DMatrix::<f64>::zeros(rows.max(k + 1), k + 1);
        for i in 0..rows {
            let uu = u + i;
            legendre(m, (2.0 * uu as f64 + 1.0 - mf) / mf, &mut p);
            for j in 0..k {
                a[(i, j)] = p[j];
            }
            a[(i, k)] = value(uu);
        }
        let mut r = triangle(a);
        let mut level = 0;
        loop {
            if level == levels.len() {
                levels.push(None);
            }
            match levels[level].take() {
                Some(other) => {
                    r = merge(&other, &r);
                    level += 1;
                }
                None => {
                    levels[level] = Some(r);
                    break;
                }
            }
        }
        u += rows;
    }
    let r = levels
        .into_iter()
        .flatten()
        .reduce(|a, b| merge(&b, &a))
        .expect("at least one sample");
    // back substitution for the Legendre coefficients
    let mut c = vec![0.0; k];
    for i in (0..k).rev() {
        let mut v = r[(i, k)];
        for j in i + 1..k {
            v -= r[(i, j)] * c[j];
        }
        c[i] = v / r[(i, i)];
    }
    // Taylor coefficients of the P_j about s_new (Bonnet's recurrence on Taylor arrays)
    let x = (mf - 1.0) / mf;
    let mut t = vec![vec![0.0; k]; k];
    t[0][0] = 1.0;
    if k > 1 {
        t[1][0] = x;
        t[1][1] = 1.0;
    }
    for j in 1..k - 1 {
        let jf = j as f64;
        for d in 0..=j + 1 {
            let xs = x * t[j][d] + if d > 0 { t[j][d - 1] } else { 0.0 };
            t[j + 1][d] = ((2.0 * jf + 1.0) * xs - jf * t[j - 1][d]) / (jf + 1.0);
        }
    }
    let step = 2.0 / mf;
    (0..k)
        .map(|d| (d..k).map(|j| c[j] * t[j][d]).sum::<f64>() * step.powi(d as i32))
        .collect()
}

/// `p_old(u)` in `f64` (Horner in `u − (n−1)`).
fn eval_old(z: &[f64], n: usize, u: usize) -> f64 {
    let x = u as f64 - (n as f64 - 1.0);
    z.iter().rev().fold(0.0, |acc, c| acc * x + c)
}

fn long_run_errors(m: usize, big_n: usize, splits: &[usize], seed: u64) -> f64 {
    let y = data(big_n, m, 3.0, 1.0, seed);
    let mut worst = 0.0f64;
    for &n in splits {
        let z0 = qr_fit(m, n, |u| y[u]);
        let want = qr_fit(m, big_n, |u| if u < n { eval_old(&z0, n, u) } else { y[u] });
        let mut z = z0.clone();
        advance_even_fit(m, n as u64, &mut z, &y[n..]);
        let e = scaled_errors(&z, &want, (big_n - 1) as f64);
        worst = worst.max(max_err(&e));
    }
    worst
}

/// Against blocked QR over 10⁶ samples, with old runs of a few, a third and most samples.
#[test]
fn expanding_block_matches_qr_on_long_runs() {
    let big_n = 1_000_000;
    for m in 0..=MAX_BLOCK_DEGREE {
        let splits = [m + 1, 333_333, 999_000, big_n - 7, big_n - 1];
        let e = long_run_errors(m, big_n, &splits, 7 + m as u64);
        println!("QR N=1e6 m {m}: {e:.1e}");
        let tol = match m {
            0..=2 => 1e-13,
            3..=4 => 1e-12,
            _ => 1e-9,
        };
        assert!(e < tol, "m {m}: {e:e}");
    }
}

/// The same at 10⁷ samples (slow: run with `--ignored`).
#[test]
#[ignore]
fn expanding_block_matches_qr_on_ten_million() {
    for m in 0..=MAX_BLOCK_DEGREE {
        let e = long_run_errors(m, 10_000_000, &[m + 1, 4_000_000], 11 + m as u64);
        println!("QR N=1e7 m {m}: {e:.1e}");
    }
}

/// The gain recursion `z ← Φ(1) z; e = y − z₀; z_k += h_k(n) e` in exact rationals.
fn exact_recursion(m: usize, n0: usize, z: &[f64], ys: &[f64]) -> Vec<f64> {
    let k = m + 1;
    let mut zr: Vec<Rational> = z.iter().map(|&v| rat(v)).collect();
    for (i, &y) in ys.iter().enumerate() {
        for_each_shift_step(k, |b| {
            let t = zr[b + 1].clone();
            zr[b] += t;
        });
        let e = rat(y) - &zr[0];
        let h = expanding_gains::<Rational>(m, (n0 + i) as u64, GainForm::Current);
        for (zk, hk) in zr.iter_mut().zip(&h) {
            *zk += hk * &e;
        }
    }
    to_f64(&zr)
}

/// The same recursion in double-word arithmetic (`f64` gains, accurate to a few ulps).
fn compensated_recursion(m: usize, n0: usize, z: &[f64], ys: &[f64]) -> Vec<f64> {
    let k = m + 1;
    let mut hi = z.to_vec();
    let mut lo = vec![0.0; k];
    let sched = ExpandingGainSchedule::new(m);
    let mut h = vec![0.0; k];
    for (i, &y) in ys.iter().enumerate() {
        shift_scaled_compensated(&mut hi, &mut lo, 1.0);
        let (e, ee) = two_sum(y, -hi[0]);
        let (e, ee) = two_sum(e, ee - lo[0]);
        sched.gains((n0 + i) as u64, &mut h);
        for j in 0..k {
            let (p, pe) = two_prod(h[j], e);
            let pe = pe + h[j] * ee;
            let (s, se) = two_sum(hi[j], p);
            let (s, t) = two_sum(s, lo[j] + se + pe);
            hi[j] = s;
            lo[j] = t;
        }
    }
    hi.iter().zip(&lo).map(|(a, b)| a + b).collect()
}

/// Against the gain recursion: exactly over 200 samples, in double-word arithmetic over
/// 10⁵, from the same state; and one call against many calls of uneven lengths.
#[test]
fn expanding_block_matches_gain_recursion() {
    for m in 0..=4 {
        let tol = if m <= 2 { 1e-13 } else { 1e-12 };
        // exact, 200 samples
        let y = data(200, m, -2.0, 0.3, 40 + m as u64);
        let yr: Vec<Rational> = y.iter().map(|&v| rat(v)).collect();
        let n0 = m + 1;
        let z0 = to_f64(&exact_fit(m, &yr[..n0]));
        let want = exact_recursion(m, n0, &z0, &y[n0..]);
        let mut z = z0.clone();
        advance_even_fit(m, n0 as u64, &mut z, &y[n0..]);
        let e1 = max_err(&scaled_errors(&z, &want, 199.0));
        // double-word, 10⁵ samples, from the rounded exact fit of the first 1000
        let big = 100_000;
        let y = data(big, m, 5.0, 1.0, 50 + m as u64);
        let yr: Vec<Rational> = y[..1000].iter().map(|&v| rat(v)).collect();
        let z0 = to_f64(&exact_fit(m, &yr));
        let want = compensated_recursion(m, 1000, &z0, &y[1000..]);
        let mut z = z0.clone();
        advance_even_fit(m, 1000, &mut z, &y[1000..]);
        let e2 = max_err(&scaled_errors(&z, &want, (big - 1) as f64));
        // many calls of uneven lengths (1 … 1500) against one call
        let mut zs = z0.clone();
        let (mut at, mut len) = (1000, 1);
        while at < big {
            let end = (at + len).min(big);
            advance_even_fit(m, at as u64, &mut zs, &y[at..end]);
            at = end;
            len = (len * 7 + 3) % 1501 + 1;
        }
        let e3 = max_err(&scaled_errors(&zs, &z, (big - 1) as f64));
        println!(
            "recursion m {m}: exact N=200 {e1:.1e}, double-word N=1e5 {e2:.1e}, pieces vs one call {e3:.1e}"
        );
        assert!(
            e1 < tol && e2 < tol && e3 < 10.0 * tol,
            "m {m}: {e1:e} {e2:e} {e3:e}"
        );
    }
}

/// Both forms against QR over 2·10⁵ samples, for runs from 1 % to 100 times the old
/// samples: the chosen form is accurate throughout; the residual form degrades once the
/// run outgrows the old samples (it extrapolates the old fit over the run).
#[test]
fn expanding_block_forms_across_run_lengths() {
    let big_n = 200_000;
    for m in 0..=MAX_BLOCK_DEGREE {
        let y = data(big_n, m, 3.0, 1.0, 99 + m as u64);
        let mut line = format!("forms m {m} (L/n: chosen direct residual):");
        for ratio in [0.01, 0.1, 0.2, 0.3, 1.0, 3.0, 10.0, 100.0] {
            let n = ((big_n as f64) / (1.0 + ratio)) as usize;
            let z0 = qr_fit(m, n, |u| y[u]);
            let want = qr_fit(m, big_n, |u| if u < n { eval_old(&z0, n, u) } else { y[u] });
            let run = |form: Option<Form>| {
                let mut z = z0.clone();
                match form {
                    None => advance_even_fit(m, n as u64, &mut z, &y[n..]),
                    Some(f) => advance_even_fit_in(m, n as u64, &mut z, &y[n..], f),
                }
                max_err(&scaled_errors(&z, &want, (big_n - 1) as f64))
            };
            let (e, ed, er) = (
                run(None),
                run(Some(Form::Direct)),
                run(Some(Form::Residual)),
            );
            line += &format!(" {ratio}: {e:.0e} {ed:.0e} {er:.0e};");
            let tol = match m {
                0..=2 => 1e-13,
                3..=4 => 1e-12,
                _ => 1e-10,
            };
            assert!(e < tol, "m {m} L/n {ratio}: {e:e}");
        }
        println!("{line}");
    }
}

/// Samples on a polynomial of degree `m` continue the old fit exactly: the result is the
/// old polynomial re-expanded about the new newest sample, `z' = Φ(L) z`, for old runs up to
/// 10¹² samples.
#[test]
fn expanding_block_reproduces_polynomials() {
    let mut worst = [0.0f64; MAX_BLOCK_DEGREE + 1];
    let mut worst_direct = [0.0f64; MAX_BLOCK_DEGREE + 1];
    for m in 0..=MAX_BLOCK_DEGREE {
        for n in [m as u64 + 1, 1000, 1_000_000_000, 1_000_000_000_000] {
            for len in [1usize, 700, 5000] {
                let span = (n + len as u64 - 1) as f64;
                // O(1) variation over the span in every degree
                let z0: Vec<f64> = (0..=m)
                    .map(|k| (1.0 + 0.1 * k as f64) * if k % 2 == 0 { 1.0 } else { -1.0 })
                    .enumerate()
                    .map(|(k, c)| c / span.powi(k as i32))
                    .collect();
                let zr: Vec<Rational> = z0.iter().map(|&v| rat(v)).collect();
                let at = |u: i64| -> Rational {
                    let x = Rational::from_i64(u);
                    zr.iter()
                        .rev()
                        .fold(Rational::zero(), |acc, c| acc * &x + c)
                };
                // y at u = n … n+L−1, i.e. offsets 1 … L from the old newest
                let ys: Vec<f64> = (1..=len as i64).map(|d| at(d).to_f64()).collect();
                // Φ(L) z exactly
                let lr = Rational::from_i64(len as i64);
                let want: Vec<f64> = (0..=m)
                    .map(|j| {
                        (j..=m)
                            .fold(Rational::zero(), |acc, k| {
                                let c = crate::calculus::choose::<Rational>(k, j);
                                let mut p = Rational::from_i64(1);
                                for _ in j..k {
                                    p *= &lr;
                                }
                                acc + &zr[k] * c * p
                            })
                            .to_f64()
                    })
                    .collect();
                let mut z = z0.clone();
                advance_even_fit(m, n, &mut z, &ys);
                let e = max_err(&scaled_errors(&z, &want, span));
                let mut z = z0.clone();
                advance_even_fit_in(m, n, &mut z, &ys, Form::Direct);
                let e2 = max_err(&scaled_errors(&z, &want, span));
                worst[m] = worst[m].max(e);
                worst_direct[m] = worst_direct[m].max(e2);
                let tol = match m {
                    0..=2 => 1e-13,
                    3..=4 => 1e-12,
                    _ => 1e-10,
                };
                assert!(e < tol, "m {m} n {n} L {len}: {e:e}");
            }
        }
    }
    for m in 0..=MAX_BLOCK_DEGREE {
        println!(
            "polynomial data m {m}: {:.1e} (direct form throughout: {:.1e})",
            worst[m], worst_direct[m]
        );
    }
}

/// The running mean (m = 0) is the plain mean, also from one old sample.
#[test]
fn expanding_block_degree_zero_is_the_running_mean() {
    let y: Vec<f64> = (0..10_007)
        .map(|i| ((i * 37) % 101) as f64 - 50.0)
        .collect();
    let mut z = [y[0]];
    advance_even_fit(0, 1, &mut z, &y[1..]);
    let mean = y.iter().sum::<f64>() / y.len() as f64;
    assert!((z[0] - mean).abs() <= 1e-15 * 50.0, "{} vs {mean}", z[0]);
    let mut z = [4.0];
    advance_even_fit(0, 3, &mut z, &[]);
    assert_eq!(z, [4.0]);
}
