//! Integer powers inline: [`powi`], square-and-multiply, the algorithm of the runtime routine
//! (`__powidf2`) that `f64::powi` calls for an exponent not known at compile time, so the same
//! roundings (checked bit for bit below) without the call: what the Kalman filter's driving
//! noise evaluates a few times per prediction.

/// `x^p` by square-and-multiply: the bits of `p` from the lowest, multiplying the result by
/// `x^(2^b)` for each set bit `b`; `x^0 = 1`.
///
/// ```
/// use seqsmooth::numeric::power::powi;
/// assert_eq!(powi(2.0, 10), 1024.0);
/// assert_eq!(powi(1.5, 0), 1.0);
/// assert_eq!(powi(0.1, 7), 0.1f64.powi(7));
/// ```
#[inline(always)]
pub fn powi(x: f64, p: u32) -> f64 {
    let (mut base, mut p, mut acc) = (x, p, 1.0);
    loop {
        if p & 1 != 0 {
            acc *= base;
        }
        p >>= 1;
        if p == 0 {
            return acc;
        }
        base *= base;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bit for bit `f64::powi` on awkward bases and every exponent to 40.
    #[test]
    fn equals_std_powi() {
        for x in [
            0.1,
            1.0 / 3.0,
            std::f64::consts::E,
            1e-3,
            123.456,
            -0.7,
            1e10,
        ] {
            for p in 0..=40u32 {
                assert_eq!(powi(x, p).to_bits(), x.powi(p as i32).to_bits(), "{x}^{p}");
            }
        }
    }
}
