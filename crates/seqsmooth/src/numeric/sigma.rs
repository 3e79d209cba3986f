//! A variance read as a standard deviation: [`std_dev`], the one rule of every reported 1σ
//! (the polynomial engines' and fixed-memory filters' rows, the Kalman bank's rows, every
//! `std_devs`).

/// The 1σ of a variance `v`: `√v`, with a rounding below zero read as zero, and a NaN kept.
///
/// - `v > 0` (and `+∞`): `√v`, bit for bit `v.sqrt()`;
/// - `v < 0` (a covariance's diagonal a rounding below zero), `-0.0` and `+0.0`: `+0.0`;
/// - NaN: NaN, so that the finiteness check of the row that reports it refuses it.
///
/// `v.max(0.0).sqrt()`, the rule it replaces, read a NaN variance as σ = 0 (`f64::max`
/// returns the other operand when one is NaN), which then passed every such check. The test
/// is one comparison and one select, so a loop of them still goes into vector operations.
///
/// ```
/// use seqsmooth::numeric::sigma::std_dev;
/// assert_eq!(std_dev(4.0), 2.0);
/// assert_eq!(std_dev(-1e-18).to_bits(), 0.0f64.to_bits());
/// assert!(std_dev(f64::NAN).is_nan());
/// ```
#[inline(always)]
pub fn std_dev(v: f64) -> f64 {
    // `v <= 0` is false for a NaN, which therefore goes to the square root (and stays NaN).
    (if v <= 0.0 { 0.0 } else { v }).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each case of the rule, bit for bit.
    #[test]
    fn each_case() {
        let bits = |v: f64| std_dev(v).to_bits();
        // Positive and finite: the square root, bit for bit.
        for v in [
            4.0,
            2.0,
            1e-300,
            f64::MIN_POSITIVE,
            5e-324,
            1.0 / 3.0,
            f64::MAX,
        ] {
            assert_eq!(bits(v), v.sqrt().to_bits(), "{v}");
        }
        // Negative rounding, and both zeros: +0.0 (not -0.0).
        for v in [-1e-18, -5e-324, -1.0, f64::NEG_INFINITY, -0.0, 0.0] {
            assert_eq!(bits(v), 0.0f64.to_bits(), "{v}");
        }
        // NaN stays NaN (the rule it replaces gave 0 here), of either sign.
        assert!(std_dev(f64::NAN).is_nan());
        assert!(std_dev(-f64::NAN).is_nan());
        // +∞ stays +∞.
        assert_eq!(std_dev(f64::INFINITY), f64::INFINITY);
    }

    /// On a slice, as the batch kernels use it: the same results as one at a time.
    #[test]
    fn over_a_slice() {
        let v = [9.0, -0.0, f64::NAN, -3.0, f64::INFINITY, 0.25];
        let s: Vec<f64> = v.iter().map(|&v| std_dev(v)).collect();
        assert_eq!(&s[..2], &[3.0, 0.0]);
        assert_eq!(s[1].to_bits(), 0);
        assert!(s[2].is_nan());
        assert_eq!(s[3].to_bits(), 0);
        assert_eq!(&s[4..], &[f64::INFINITY, 0.5]);
    }
}
