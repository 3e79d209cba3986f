//! Exact merges (`polynomial::merge::Information`): one series of 10⁶ samples cut into 10
//! partitions at random rows, each reduced to its information, merged pairwise, against the
//! single passes: the same reduction over all the samples in one call, the exact least-squares
//! solution (the normal equations of the same Legendre rows summed exactly in integers and
//! solved in rationals: the oracle), the batch least-squares fit (`PolynomialFit`, Householder
//! QR of all the samples at once), the exact expanding-memory filter run sample by sample and
//! the Bayes filter (expanding memory with a prior, Morrison ch. 10).
//!
//! Two measures of "relative", both recorded (ACCURACY.md):
//! - **derivatives**: the derivative vector at a time in the span's units, `max_k |Δd_k| h^k`
//!   over `max_k |d_k| h^k`, `h` the half span (each derivative times the time it acts over);
//!   at the ends of the span this amplifies a coefficient's error by up to `P_m^(m)(1) h^m`
//!   (`2·10⁶` at degree 8: Markov's inequality), the conditioning of the question asked;
//! - **curve**: the fitted polynomial's values over the span, `max_t |Δp(t)| / max_t |p(t)|`
//!   on 201 times spread over `[start, end]`.

use nalgebra::DMatrix;
use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::ToPrimitive;
use seqsmooth::basis::legendre;
use seqsmooth::estimate::PolynomialFit;
use seqsmooth::polynomial::merge::Information;
use seqsmooth::polynomial::prior::Prior;
use seqsmooth::{Engine, ExpandingMemory, PolynomialFilter};

const N: usize = 1_000_000;

/// xorshift64*.
struct Rng(u64);

impl Rng {
    fn uniform(&mut self) -> f64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        (x.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// 10⁶ samples at irregular times over about 10⁶ s of a smooth curve with unit noise.
fn series(seed: u64) -> (Vec<f64>, Vec<f64>) {
    let mut rng = Rng(seed);
    let mut t = Vec::with_capacity(N);
    let mut now = 1000.0;
    for _ in 0..N {
        now += 0.5 + rng.uniform();
        t.push(now);
    }
    let span = now;
    let y = t
        .iter()
        .map(|&t| {
            let u = t / span;
            5.0 + 3.0 * u - 2.0 * u * u + (6.0 * u).sin() + (rng.uniform() - 0.5) * 3.0
        })
        .collect();
    (t, y)
}

/// Cuts `0..N` at 9 random rows: 10 partitions.
fn cuts(seed: u64) -> Vec<usize> {
    let mut rng = Rng(seed ^ 0xabcd);
    let mut c: Vec<usize> = (0..9)
        .map(|_| (rng.uniform() * N as f64) as usize)
        .collect();
    c.extend([0, N]);
    c.sort_unstable();
    c
}

/// The partitions' informations merged (in a tree, pairwise, as a cluster would).
fn merged(t: &[f64], y: &[f64], empty: &Information, cuts: &[usize]) -> Information {
    let mut parts: Vec<Information> = cuts
        .windows(2)
        .map(|w| {
            let mut info = empty.clone();
            info.reduce(&t[w[0]..w[1]], &y[w[0]..w[1]]).unwrap();
            info
        })
        .collect();
    while parts.len() > 1 {
        let mut next = Vec::new();
        for pair in parts.chunks(2) {
            let mut a = pair[0].clone();
            if let Some(b) = pair.get(1) {
                a.merge(b).unwrap();
            }
            next.push(a);
        }
        parts = next;
    }
    parts.pop().unwrap()
}

/// `max_k |a_k − b_k| h^k / max_k |b_k| h^k`.
fn relative(a: &[f64], b: &[f64], h: f64) -> f64 {
    let mut num: f64 = 0.0;
    let mut den: f64 = 0.0;
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        let s = h.powi(k as i32);
        num = num.max((x - y).abs() * s);
        den = den.max(y.abs() * s);
    }
    num / den
}

/// `x = m·2^e` exactly (`m` an integer of at most 53 bits).
fn decompose(x: f64) -> (i128, i32) {
    let bits = x.to_bits();
    let sign = if bits >> 63 == 1 { -1 } else { 1 };
    let exp = ((bits >> 52) & 0x7ff) as i32;
    let frac = (bits & ((1u64 << 52) - 1)) as i128;
    if exp == 0 {
        (sign * frac, -1074)
    } else {
        (sign * (frac | 1 << 52), exp - 1075)
    }
}

/// An exact sum of products of doubles: the products' integer mantissas (106 bits) summed in
/// one 128-bit bin per binary exponent (room for 2²⁰ products a bin).
struct ExactSum {
    bins: Vec<i128>,
}

const OFFSET: i32 = 2200;

impl ExactSum {
    fn new() -> Self {
        Self {
            bins: vec![0; 2 * OFFSET as usize + 200],
        }
    }

    fn add_product(&mut self, a: f64, b: f64) {
        let ((ma, ea), (mb, eb)) = (decompose(a), decompose(b));
        if ma != 0 && mb != 0 {
            self.bins[(ea + eb + OFFSET) as usize] += ma * mb;
        }
    }

    fn value(&self) -> BigRational {
        let mut num = BigInt::from(0);
        for (i, &b) in self.bins.iter().enumerate() {
            if b != 0 {
                num += BigInt::from(b) << i;
            }
        }
        BigRational::new(num, BigInt::from(1) << OFFSET as usize)
    }
}

/// The least-squares Legendre coefficients of the rows `crate::basis::legendre::values` gives
/// (the rows of `PolynomialFit` and `Information`, as rounded doubles), exactly: the normal
/// equations' sums exact, solved by Gaussian elimination in rationals, rounded once.
fn exact_coefficients(
    t: &[f64],
    y: &[f64],
    m: usize,
    (start, end): (f64, f64),
    extra: &[(Vec<f64>, f64)],
) -> Vec<f64> {
    let (centre, half) = (0.5 * (start + end), 0.5 * (end - start));
    let p = m + 1;
    let mut sums: Vec<ExactSum> = (0..p * (p + 1)).map(|_| ExactSum::new()).collect();
    for (&t, &y) in t.iter().zip(y) {
        let v = legendre::values(m, (t - centre) / half);
        for i in 0..p {
            for j in 0..p {
                sums[i * (p + 1) + j].add_product(v[i], v[j]);
            }
            sums[i * (p + 1) + p].add_product(v[i], y);
        }
    }
    for (v, y) in extra {
        for i in 0..p {
            for j in 0..p {
                sums[i * (p + 1) + j].add_product(v[i], v[j]);
            }
            sums[i * (p + 1) + p].add_product(v[i], *y);
        }
    }
    let mut a: Vec<Vec<BigRational>> = (0..p)
        .map(|i| (0..=p).map(|j| sums[i * (p + 1) + j].value()).collect())
        .collect();
    for k in 0..p {
        let (top, bottom) = a.split_at_mut(k + 1);
        let pivot = &top[k];
        for row in bottom.iter_mut() {
            let f = &row[k] / &pivot[k];
            for (x, y) in row[k..].iter_mut().zip(&pivot[k..]) {
                *x -= &f * y;
            }
        }
    }
    let mut c = vec![BigRational::from_integer(BigInt::from(0)); p];
    for i in (0..p).rev() {
        let mut s = a[i][p].clone();
        for j in i + 1..p {
            s -= &a[i][j] * &c[j];
        }
        c[i] = s / &a[i][i];
    }
    c.iter().map(|c| c.to_f64().unwrap()).collect()
}

/// The derivatives at `t` times `h^k` of the Legendre coefficients `c` on `[start, end]`.
fn scaled_from_coefficients(c: &[f64], (start, end): (f64, f64), t: f64) -> Vec<f64> {
    let (centre, half) = (0.5 * (start + end), 0.5 * (end - start));
    let m = c.len() - 1;
    let table = legendre::taylor_table(m, m, (t - centre) / half);
    let mut factorial = 1.0;
    (0..=m)
        .map(|k| {
            if k > 0 {
                factorial *= k as f64;
            }
            factorial * (0..=m).map(|j| table[(k, j)] * c[j]).sum::<f64>()
        })
        .collect()
}

/// `d_k h^k`.
fn scaled(d: &[f64], h: f64) -> Vec<f64> {
    d.iter()
        .enumerate()
        .map(|(k, d)| d * h.powi(k as i32))
        .collect()
}

/// The curve measure between two polynomials given by their values at 201 times of the span.
fn curve_relative(a: impl Fn(f64) -> f64, b: impl Fn(f64) -> f64, (s, e): (f64, f64)) -> f64 {
    let (mut num, mut den): (f64, f64) = (0.0, 0.0);
    for i in 0..=200 {
        let t = s + (e - s) * f64::from(i) / 200.0;
        let (x, y) = (a(t), b(t));
        num = num.max((x - y).abs());
        den = den.max(y.abs());
    }
    num / den
}

/// `Σ c_j P_j(u(t))`.
fn legendre_value(c: &[f64], (start, end): (f64, f64), t: f64) -> f64 {
    let (centre, half) = (0.5 * (start + end), 0.5 * (end - start));
    let v = legendre::values(c.len() - 1, (t - centre) / half);
    v.iter().zip(c).map(|(a, b)| a * b).sum()
}

#[test]
fn partitions_merge_to_the_exact_least_squares_fit_at_degrees_0_to_8() {
    let (t, y) = series(1);
    let span = (t[0], t[N - 1]);
    let (start, end) = span;
    let h = 0.5 * (end - start);
    for m in 0..=8 {
        let empty = Information::new(m, start, end, None).unwrap();
        let info = merged(&t, &y, &empty, &cuts(m as u64));
        assert_eq!(info.samples(), N as u64);
        let exact = exact_coefficients(&t, &y, m, span, &[]);
        let single = PolynomialFit::new(&t, &y, None, m).unwrap();
        let mut one = empty.clone();
        one.reduce(&t, &y).unwrap();
        let (mut worst_one, mut worst_exact, mut worst_qr, mut qr_exact) =
            (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for at in [start, 0.5 * (start + end), end] {
            let a = scaled(&info.estimate(at).unwrap().derivatives, h);
            let b = scaled(&single.derivatives_at(at), h);
            let c = scaled(&one.estimate(at).unwrap().derivatives, h);
            let x = scaled_from_coefficients(&exact, span, at);
            worst_one = worst_one.max(relative(&a, &c, 1.0));
            worst_exact = worst_exact.max(relative(&a, &x, 1.0));
            worst_qr = worst_qr.max(relative(&a, &b, 1.0));
            qr_exact = qr_exact.max(relative(&b, &x, 1.0));
        }
        let fit = info.fit().unwrap();
        let curve_exact = curve_relative(
            |t| fit.value_and_vrf_at(t).0,
            |t| legendre_value(&exact, span, t),
            span,
        );
        let curve_qr = curve_relative(
            |t| fit.value_and_vrf_at(t).0,
            |t| single.value_and_vrf_at(t).0,
            span,
        );
        let curve_qr_exact = curve_relative(
            |t| single.value_and_vrf_at(t).0,
            |t| legendre_value(&exact, span, t),
            span,
        );
        eprintln!(
            "degree {m}: derivatives: merged vs one pass {worst_one:.1e}, vs exact \
             {worst_exact:.1e}, vs QR {worst_qr:.1e}, QR vs exact {qr_exact:.1e}; curve: merged \
             vs exact {curve_exact:.1e}, vs QR {curve_qr:.1e}, QR vs exact {curve_qr_exact:.1e}"
        );
        // The merge is the single pass and the exact fit, in both measures, at every degree.
        assert!(
            worst_one < 1e-14,
            "degree {m}: merged vs one pass {worst_one:e}"
        );
        assert!(
            worst_exact < 1e-12,
            "degree {m}: merged vs exact {worst_exact:e}"
        );
        assert!(
            curve_exact < 1e-14,
            "degree {m}: curve vs exact {curve_exact:e}"
        );
        // Householder QR holds the curve to 1e-12; its derivatives at the ends of the span
        // are off the exact fit by its own rounding (measured: ACCURACY.md).
        assert!(curve_qr < 1e-12, "degree {m}: curve vs QR {curve_qr:e}");
        let qr_tol = [1e-12, 1e-12, 1e-12, 1e-12, 1e-12, 1e-12, 1e-11, 1e-11, 1e-9][m];
        assert!(worst_qr < qr_tol, "degree {m}: merged vs QR {worst_qr:e}");
        let rel_rss =
            (info.fit().unwrap().residual_sq() - single.residual_sq()).abs() / single.residual_sq();
        assert!(rel_rss < 1e-12, "degree {m}: residual {rel_rss:e}");
    }
}

#[test]
fn partitions_merge_to_expanding_memory_and_the_bayes_filter() {
    let (t, y) = series(2);
    let span = (t[0], t[N - 1]);
    let (start, end) = span;
    let h = 0.5 * (end - start);
    for m in [0, 1, 2, 4, 6, 8] {
        // Expanding memory, sample by sample: its estimate at the last sample.
        let mut f = ExpandingMemory::new(m, Engine::Exact).unwrap();
        f.update_many(&t, &y).unwrap();
        let want = f.estimate().unwrap().derivatives;
        let empty = Information::new(m, start, end, None).unwrap();
        let info = merged(&t, &y, &empty, &cuts(10 + m as u64));
        let got = info.estimate(end).unwrap();
        let exact = scaled_from_coefficients(&exact_coefficients(&t, &y, m, span, &[]), span, end);
        let r = relative(&got.derivatives, &want, h);
        let r_exact = relative(&scaled(&want, h), &exact, 1.0);
        let fit = info.fit().unwrap();
        let curve = curve_relative(
            |t| fit.value_and_vrf_at(t).0,
            |t| f.estimate_at(t).unwrap().derivatives[0],
            span,
        );
        eprintln!(
            "expanding memory, degree {m}: derivatives: merged vs filter {r:.1e}, filter vs \
             exact {r_exact:.1e}; curve: merged vs filter {curve:.1e}"
        );
        // The filter's own rounding at the end of the span (measured 2.5e-12 at degree 6,
        // 4.8e-11 at 8: "filter vs exact"); the merge is the exact fit (the test above).
        assert!(
            r < [1e-12, 1e-12, 1e-12, 1e-12, 1e-12, 1e-11, 1e-11, 1e-10, 1e-10][m],
            "expanding, degree {m}: {r:e}"
        );
        let merged_exact = relative(&scaled(&got.derivatives, h), &exact, 1.0);
        assert!(
            merged_exact < 1e-14,
            "expanding, degree {m}: vs exact {merged_exact:e}"
        );
        assert!(curve < 1e-12, "expanding, degree {m}: curve {curve:e}");
        // The Bayes filter: a prior on the derivatives at a time before the first sample.
        let sigma = 1.5;
        let state: Vec<f64> = (0..=m).map(|k| [5.0, 3e-6, -1e-12][k.min(2)]).collect();
        let cov = DMatrix::from_fn(m + 1, m + 1, |i, j| {
            if i == j {
                4.0 / 1e6f64.powi(2 * i as i32)
            } else {
                0.0
            }
        });
        let prior = Prior::new(start - 10.0, state, cov).unwrap();
        let mut f = ExpandingMemory::new(m, Engine::Exact)
            .unwrap()
            .with_noise_sigma(sigma)
            .unwrap()
            .with_prior(&prior)
            .unwrap();
        f.update_many(&t, &y).unwrap();
        let want = f.estimate().unwrap();
        let mut empty = Information::new(m, start, end, Some(sigma)).unwrap();
        let mut with_prior = empty.clone();
        with_prior.add_prior(&prior).unwrap();
        let mut one = with_prior.clone();
        one.reduce(&t, &y).unwrap();
        let mut info = merged(&t, &y, &empty, &cuts(20 + m as u64));
        info.merge(&with_prior).unwrap();
        assert!(empty.merge(&with_prior).is_ok() && info.merge(&with_prior).is_err());
        let got = info.estimate(end).unwrap();
        // The oracle: the prior's rows written here, `(σ/σ_k) d_k(t₀)` of the coefficients
        // (`d_k = k! Σ_j T_kj c_j / h^k`, the diagonal prior's whitening), summed exactly.
        let table = legendre::taylor_table(m, m, (prior.time - 0.5 * (start + end)) / h);
        let mut factorial = 1.0;
        let rows: Vec<(Vec<f64>, f64)> = (0..=m)
            .map(|k| {
                if k > 0 {
                    factorial *= k as f64;
                }
                let w = sigma / (2.0 / 1e6f64.powi(k as i32));
                let scale = w * factorial / h.powi(k as i32);
                (
                    (0..=m).map(|j| scale * table[(k, j)]).collect(),
                    w * prior.state[k],
                )
            })
            .collect();
        let exact = exact_coefficients(&t, &y, m, span, &rows);
        let x = scaled_from_coefficients(&exact, span, end);
        let r_exact = relative(&scaled(&got.derivatives, h), &x, 1.0);
        let r_filter_exact = relative(&scaled(&want.derivatives, h), &x, 1.0);
        let curve_exact = curve_relative(
            |t| info.fit().unwrap().value_and_vrf_at(t).0,
            |t| legendre_value(&exact, span, t),
            span,
        );
        let curve_filter_exact = curve_relative(
            |t| f.estimate_at(t).unwrap().derivatives[0],
            |t| legendre_value(&exact, span, t),
            span,
        );
        eprintln!(
            "Bayes, degree {m}: vs the exact fit: merged: derivatives {r_exact:.1e}, curve \
             {curve_exact:.1e}; filter: derivatives {r_filter_exact:.1e}, curve \
             {curve_filter_exact:.1e}"
        );
        let r = relative(&got.derivatives, &want.derivatives, h);
        let r_one = relative(&got.derivatives, &one.estimate(end).unwrap().derivatives, h);
        let fit = info.fit().unwrap();
        let curve = curve_relative(
            |t| fit.value_and_vrf_at(t).0,
            |t| f.estimate_at(t).unwrap().derivatives[0],
            span,
        );
        eprintln!(
            "Bayes, degree {m}: derivatives: merged vs filter {r:.1e}, vs one pass \
             {r_one:.1e}; curve: merged vs filter {curve:.1e}"
        );
        // The merge is the one pass and the exact fit with the prior, in both measures.
        assert!(r_one < 1e-14, "Bayes, degree {m}: vs one pass {r_one:e}");
        assert!(r_exact < 1e-14, "Bayes, degree {m}: vs exact {r_exact:e}");
        assert!(
            curve_exact < 1e-14,
            "Bayes, degree {m}: curve vs exact {curve_exact:e}"
        );
        // The filter is off the exact fit by its own rounding (1.2e-12 and 1.6e-12 at
        // degree 8 measured): the merge is within that of it.
        assert!(
            r < if m <= 6 { 1e-12 } else { 1e-11 },
            "Bayes, degree {m}: {r:e}"
        );
        assert!(
            curve < if m <= 6 { 1e-12 } else { 1e-11 },
            "Bayes, degree {m}: curve {curve:e}"
        );
        let (a, b) = (got.covariance.unwrap(), want.covariance.unwrap());
        let r0 = ((a[(0, 0)] - b[(0, 0)]) / b[(0, 0)]).abs();
        assert!(
            r0 < 1e-9,
            "Bayes, degree {m}: variance of d0 relative {r0:e}"
        );
    }
}

#[test]
fn informations_of_other_shapes_do_not_merge_and_round_trip_bit_for_bit() {
    let mut a = Information::new(2, 0.0, 10.0, None).unwrap();
    let b = Information::new(2, 0.0, 11.0, None).unwrap();
    assert!(a.merge(&b).is_err());
    assert!(Information::new(2, 1.0, 0.0, None).is_err());
    assert!(a.estimate(1.0).is_err()); // nothing in yet
    a.reduce(&[0.0, 1.0, 2.0, 3.0], &[1.0, 2.0, 5.0, 10.0])
        .unwrap();
    assert!(a.reduce(&[4.0], &[f64::NAN]).is_err());
    // Its square leaves the double range: refused naming the sample, nothing added.
    assert!(matches!(
        a.reduce(&[4.0, 5.0], &[1.0, 1e200]),
        Err(seqsmooth::Error::InBatch { index: 1, .. })
    ));
    assert_eq!(a.samples(), 4);
    // Many samples at two distinct times do not determine a parabola.
    let mut two = Information::new(2, 0.0, 10.0, None).unwrap();
    let t: Vec<f64> = (0..1000)
        .map(|k| if k % 2 == 0 { 1.0 } else { 7.0 })
        .collect();
    two.reduce(&t, &vec![3.0; 1000]).unwrap();
    assert!(matches!(
        two.estimate(5.0),
        Err(seqsmooth::Error::NotDetermined { samples: 1000, .. })
    ));
    let mut one = Information::new(2, 0.0, 10.0, None).unwrap();
    one.reduce(&[1.0, 2.0], &[3.0, 3.0]).unwrap();
    assert!(matches!(
        one.estimate(5.0),
        Err(seqsmooth::Error::TooFewSamples { needed: 3, got: 2 })
    ));
    two.reduce(&[4.0], &[3.0]).unwrap();
    let d = two.estimate(5.0).unwrap().derivatives;
    assert!((d[0] - 3.0).abs() < 1e-14 && d[1].abs() < 1e-14 && d[2].abs() < 1e-14);
    assert_eq!(a.samples(), 4);
    let bytes = seqsmooth::persist::to_bytes(&a).unwrap();
    let back: Information = seqsmooth::persist::from_bytes(&bytes).unwrap();
    assert_eq!(back.estimate(2.5).unwrap(), a.estimate(2.5).unwrap());
}
