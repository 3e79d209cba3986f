//! Double-word arithmetic: a value carried as an unevaluated sum `hi + lo` of two `f64`
//! (`|lo| ≤ ulp(hi)/2` when normalised), built on the error-free transformations
//! [`two_sum`] (Knuth, TAOCP vol. 2 §4.2.2) and [`two_prod`] (Dekker 1971, with Veltkamp's
//! splitting). The compensated Taylor shift, the gain engine's compensated state and the fading
//! block map are written with these, and only these.
//!
//! ## FMA policy
//!
//! No fused multiply-add anywhere: the product error `a·b − fl(a·b)` comes from Dekker's
//! product, which needs only `+`, `−` and `×`, so the operations and hence the results are
//! the same on every target whatever its features (the baseline x86-64 target has no FMA
//! instruction and would call a software `fma`). For finite operands with `|a|, |b| < 2⁹⁹⁶`
//! whose product neither overflows nor underflows, Dekker's product is exact, so it equals the
//! correctly rounded `a.mul_add(b, −p)` bit for bit.

/// A double word `hi + lo`.
pub(crate) type DoubleWord = (f64, f64);

/// Error-free sum: `a + b = s + e` exactly, `s = fl(a + b)` (Knuth's TwoSum, six operations,
/// no branch).
///
/// ```
/// use seqsmooth::numeric::double_word::two_sum;
/// let (s, e) = two_sum(1.0, 1e-20);
/// assert_eq!((s, e), (1.0, 1e-20));
/// ```
#[inline(always)]
pub fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    (s, e)
}

/// Error-free product: `a·b = p + e` exactly, `p = fl(a·b)` (Dekker's product with Veltkamp's
/// splitting by `2²⁷ + 1`; no FMA, see the [module docs](self)).
///
/// ```
/// use seqsmooth::numeric::double_word::two_prod;
/// let a = 1.0 + f64::EPSILON;
/// let (p, e) = two_prod(a, a); // (1 + ε)² = 1 + 2ε + ε²
/// assert_eq!((p, e), (1.0 + 2.0 * f64::EPSILON, f64::EPSILON * f64::EPSILON));
/// ```
#[inline(always)]
pub fn two_prod(a: f64, b: f64) -> (f64, f64) {
    const SPLIT: f64 = 134_217_729.0; // 2^27 + 1
    let split = |x: f64| {
        let c = SPLIT * x;
        let hi = c - (c - x);
        (hi, x - hi)
    };
    let p = a * b;
    let ((ah, al), (bh, bl)) = (split(a), split(b));
    (p, ((ah * bh - p) + ah * bl + al * bh) + al * bl)
}

/// `x + y` for double words, normalised: `two_sum` of the high words, the low words added to
/// its error, renormalised.
#[inline]
pub(crate) fn add(x: DoubleWord, y: DoubleWord) -> DoubleWord {
    let (s, e) = two_sum(x.0, y.0);
    two_sum(s, e + x.1 + y.1)
}

/// `x − y` for double words (as [`add`] of `−y`).
#[inline]
pub(crate) fn sub(x: DoubleWord, y: DoubleWord) -> DoubleWord {
    add(x, (-y.0, -y.1))
}

/// `x·b` for a double word `x` and an `f64` `b`, normalised.
#[inline]
pub(crate) fn mul_f64(x: DoubleWord, b: f64) -> DoubleWord {
    let (p, e) = two_prod(x.0, b);
    two_sum(p, e + x.1 * b)
}

/// `x·y` for double words, normalised (the exact product of the high words plus the cross
/// terms; relative error a few units of 2⁻¹⁰⁶).
#[inline]
pub(crate) fn mul(x: DoubleWord, y: DoubleWord) -> DoubleWord {
    let (p, e) = two_prod(x.0, y.0);
    two_sum(p, e + (x.0 * y.1 + x.1 * y.0))
}

/// `x/y` for double words, normalised: the quotient of the high words, corrected once by the
/// double-word remainder `x − q·y` (relative error a few units of 2⁻¹⁰⁶).
#[inline]
pub(crate) fn div(x: DoubleWord, y: DoubleWord) -> DoubleWord {
    let q = x.0 / y.0;
    let r = sub(x, mul((q, 0.0), y));
    two_sum(q, r.0 / y.0)
}

/// `b·x` for an `f64` `b` and a double word `x`, not renormalised (`lo` may exceed
/// `ulp(hi)/2` by a rounding of `lo`).
#[inline]
pub(crate) fn scale(b: f64, x: DoubleWord) -> DoubleWord {
    let (p, e) = two_prod(b, x.0);
    (p, e + b * x.1)
}

/// `Σ aᵢ bᵢ` in double-word arithmetic (exact products, TwoSum accumulation).
pub(crate) fn dot(a: &[DoubleWord], b: &[DoubleWord]) -> DoubleWord {
    let (mut hi, mut lo) = (0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        let (p, e) = two_prod(x.0, y.0);
        let pe = e + (x.0 * y.1 + x.1 * y.0);
        let (s, se) = two_sum(hi, p);
        let (s, l) = two_sum(s, se + lo + pe);
        hi = s;
        lo = l;
    }
    (hi, lo)
}

/// `a + b` for double-word vectors.
pub(crate) fn add_vectors(a: &[DoubleWord], b: &[DoubleWord]) -> Vec<DoubleWord> {
    a.iter().zip(b).map(|(x, y)| add(*x, *y)).collect()
}

/// `A v` for a double-word `n × n` matrix `A` (row-major) and vector `v`.
pub(crate) fn mat_vec(a: &[DoubleWord], v: &[DoubleWord]) -> Vec<DoubleWord> {
    a.chunks_exact(v.len()).map(|row| dot(row, v)).collect()
}

/// `A B` for double-word `n × n` matrices (row-major).
pub(crate) fn mat_mul(a: &[DoubleWord], b: &[DoubleWord], n: usize) -> Vec<DoubleWord> {
    let mut col = vec![(0.0, 0.0); n];
    let mut c = vec![(0.0, 0.0); n * n];
    for j in 0..n {
        for (k, ck) in col.iter_mut().enumerate() {
            *ck = b[k * n + j];
        }
        for (i, row) in a.chunks_exact(n).enumerate() {
            c[i * n + j] = dot(row, &col);
        }
    }
    c
}

/// `√x` for a double word `x > 0`, normalised: the `f64` root corrected once by the
/// double-word remainder `x − s²` (Newton's step; relative error a few units of 2⁻¹⁰⁶).
#[inline]
pub(crate) fn sqrt(x: DoubleWord) -> DoubleWord {
    let s = x.0.sqrt();
    let (p, e) = two_prod(s, s);
    two_sum(s, ((x.0 - p) - e + x.1) / (2.0 * s))
}

/// The double word rounded to the nearest `f64`, `hi + lo`.
#[inline]
pub(crate) fn round(x: &DoubleWord) -> f64 {
    x.0 + x.1
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scalar::{rational_from_f64, Rational, Scalar};

    fn exact(x: f64) -> Rational {
        rational_from_f64(x).unwrap()
    }

    /// Oracle: exact rationals. TwoSum and Dekker's product are error-free, and Dekker's
    /// product error equals the FMA's (the policy the module documents).
    #[test]
    fn error_free_transformations_are_exact() {
        let mut x = 0.123_456_789_f64;
        for i in 0..2000 {
            x = (x * 3.987_654_3).fract() + 1e-3;
            let a = x * 10f64.powi(i % 30 - 15);
            let b = (1.0 - x) * 10f64.powi((i * 7) % 30 - 15) * if i % 3 == 0 { -1.0 } else { 1.0 };
            let (s, e) = two_sum(a, b);
            assert_eq!(exact(s) + exact(e), exact(a) + exact(b));
            let (p, e) = two_prod(a, b);
            assert_eq!(exact(p) + exact(e), exact(a) * exact(b));
            assert_eq!(e, a.mul_add(b, -p));
        }
    }

    /// Double-word dot products and matrix products against exact rationals: relative error
    /// of order 2⁻¹⁰⁴ for positive terms.
    #[test]
    fn double_word_dot_is_twice_as_accurate() {
        let a: Vec<DoubleWord> = (1..=9).map(|i| (1.0 / i as f64, 0.0)).collect();
        let b: Vec<DoubleWord> = (1..=9).map(|i| ((i as f64).sqrt(), 0.0)).collect();
        let want = a.iter().zip(&b).fold(Rational::from_i64(0), |acc, (x, y)| {
            acc + exact(x.0) * exact(y.0)
        });
        let got = dot(&a, &b);
        let err = ((exact(got.0) + exact(got.1)) - want.clone())
            .to_f64()
            .abs();
        assert!(err <= 1e-30 * want.to_f64(), "{err:e}");
        let c = mat_mul(&a, &b, 3);
        let want00 = (0..3).fold(Rational::from_i64(0), |acc, k| {
            acc + exact(a[k].0) * exact(b[3 * k].0)
        });
        let err = ((exact(c[0].0) + exact(c[0].1)) - want00.clone())
            .to_f64()
            .abs();
        assert!(err <= 1e-30 * want00.to_f64(), "{err:e}");
        assert_eq!(mat_vec(&a[..4], &b[..2]).len(), 2);
        let s = add_vectors(&a, &b);
        assert_eq!(s[0], add(a[0], b[0]));
        assert_eq!(sub(a[1], a[1]), (0.0, 0.0));
        let m = mul_f64((1.0 / 3.0, 0.0), 3.0);
        assert_eq!(round(&m), 1.0);
        assert_eq!(scale(2.0, (1.0, 1e-20)), (2.0, 2e-20));
    }

    /// Double-word products and quotients against exact rationals: relative error below
    /// 2⁻¹⁰⁴ on operands spread over many magnitudes and both signs.
    #[test]
    fn double_word_mul_and_div_are_twice_as_accurate() {
        let dw = |x: f64| {
            let hi = x * (1.0 + 1.0 / 3.0);
            (hi, hi * 1e-17)
        };
        let value = |x: DoubleWord| exact(x.0) + exact(x.1);
        let mut v = 0.377_f64;
        for i in 0..500 {
            v = (v * 7.31).fract() + 1e-3;
            let a = dw(v * 10f64.powi(i % 40 - 20));
            let b = dw(-(1.5 - v) * 10f64.powi((i * 13) % 40 - 20));
            let want = value(a) * value(b);
            let err = (value(mul(a, b)) - want.clone()).to_f64().abs();
            assert!(err <= 2f64.powi(-104) * want.to_f64().abs(), "{i}: {err:e}");
            let want = value(a) / value(b);
            let err = (value(div(a, b)) - want.clone()).to_f64().abs();
            assert!(err <= 2f64.powi(-104) * want.to_f64().abs(), "{i}: {err:e}");
        }
    }
}
