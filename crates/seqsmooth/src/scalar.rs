//! The number types the exact foundations are generic over.
//!
//! Every formula in [`crate::calculus`], [`crate::basis`], [`crate::model`] and the gain and
//! variance-reduction generators of [`crate::polynomial`] is written once, generic over
//! [`Scalar`], and instantiated twice: with [`Rational`] (arbitrary-precision exact rationals, the
//! oracle and the generator of printed tables) and with `f64` (what the filters run on).

use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{One, Signed, ToPrimitive, Zero};
use std::fmt::Debug;
use std::ops::Neg;

/// Exact arbitrary-precision rational number.
pub type Rational = BigRational;

/// A field the exact formulas can be evaluated in: `f64` or [`Rational`].
pub trait Scalar:
    num_traits::Num + Neg<Output = Self> + Clone + PartialOrd + Debug + Send + Sync + 'static
{
    /// The integer `v` in this field.
    fn from_i64(v: i64) -> Self;
    /// The ratio `num / den` in this field (`den != 0`).
    fn ratio(num: i64, den: i64) -> Self {
        Self::from_i64(num) / Self::from_i64(den)
    }
    /// Nearest `f64`.
    fn to_f64(&self) -> f64;
    /// The exact rational `r` in this field (rounded to nearest for `f64`).
    fn from_rational(r: &Rational) -> Self;
    /// Absolute value.
    fn abs_val(&self) -> Self;
    /// Whether the number is one (every exact rational is; an `f64` not NaN or ±∞).
    fn is_number(&self) -> bool {
        true
    }
    /// `self^k` for a non-negative integer power (`0^0 = 1`).
    fn powi_u(&self, k: usize) -> Self {
        let mut acc = Self::one();
        for _ in 0..k {
            acc = acc * self.clone();
        }
        acc
    }
}

impl Scalar for f64 {
    fn is_number(&self) -> bool {
        self.is_finite()
    }
    fn from_i64(v: i64) -> Self {
        v as f64
    }
    fn to_f64(&self) -> f64 {
        *self
    }
    fn from_rational(r: &Rational) -> Self {
        ratio_to_f64(r)
    }
    fn abs_val(&self) -> Self {
        self.abs()
    }
    fn powi_u(&self, k: usize) -> Self {
        match i32::try_from(k) {
            Ok(k) => self.powi(k),
            Err(_) => self.powf(k as f64),
        }
    }
}

impl Scalar for BigRational {
    fn from_i64(v: i64) -> Self {
        BigRational::from_integer(BigInt::from(v))
    }
    fn to_f64(&self) -> f64 {
        ratio_to_f64(self)
    }
    fn from_rational(r: &Rational) -> Self {
        r.clone()
    }
    fn abs_val(&self) -> Self {
        self.abs()
    }
}

/// Nearest `f64` to an exact rational (num-rational's correctly rounded conversion).
pub fn ratio_to_f64(r: &BigRational) -> f64 {
    ToPrimitive::to_f64(r).unwrap_or(f64::NAN)
}

/// The largest decimal exponent [`parse_rational`] takes (`1e-400` … `1e400`): beyond it the
/// exact value has hundreds of digits and more, and every operation on it is slower (a
/// `1e7161213` took minutes), while no parameter it parses is meaningful there (every double
/// is inside it).
pub const MAX_DECIMAL_EXPONENT: i32 = 400;

/// Whether the decimal exponent written in `text` (after an `e` or `E`), if any, is within
/// [`MAX_DECIMAL_EXPONENT`] in magnitude: the one rule of every front end that reads a
/// number exactly (beyond it the exact value would take unbounded time to expand, while every
/// double, subnormals included, is written with an exponent inside it).
///
/// ```
/// use seqsmooth::scalar::decimal_exponent_in_range;
/// assert!(decimal_exponent_in_range("0.9") && decimal_exponent_in_range("1e-400"));
/// assert!(!decimal_exponent_in_range("1e-401") && !decimal_exponent_in_range("5e6999999"));
/// ```
pub fn decimal_exponent_in_range(text: &str) -> bool {
    match text.trim().split_once(['e', 'E']) {
        Some((_, e)) => !e
            .parse::<i64>()
            .is_ok_and(|e| e.unsigned_abs() > MAX_DECIMAL_EXPONENT as u64),
        None => true,
    }
}

/// Parses a rational written as `p/q`, an integer, or a finite decimal such as `0.95`, with a
/// decimal exponent of at most [`MAX_DECIMAL_EXPONENT`] in magnitude (after the digits).
///
/// ```
/// use seqsmooth::scalar::parse_rational;
/// assert_eq!(parse_rational("9/10").unwrap().to_string(), "9/10");
/// assert_eq!(parse_rational("0.95").unwrap().to_string(), "19/20");
/// assert_eq!(parse_rational("95e-2").unwrap().to_string(), "19/20");
/// assert!(parse_rational("x").is_none());
/// assert!(parse_rational("1e400").is_some() && parse_rational("1e-400").is_some());
/// assert!(parse_rational("1e401").is_none() && parse_rational("5e6999999").is_none());
/// ```
pub fn parse_rational(text: &str) -> Option<BigRational> {
    let s = text.trim();
    if let Some((p, q)) = s.split_once('/') {
        let p: BigInt = p.trim().parse().ok()?;
        let q: BigInt = q.trim().parse().ok()?;
        if q.is_zero() {
            return None;
        }
        return Some(BigRational::new(p, q));
    }
    let (neg, body) = match s.strip_prefix('-') {
        Some(b) => (true, b),
        None => (false, s.strip_prefix('+').unwrap_or(s)),
    };
    let (mant, exp) = match body.split_once(['e', 'E']) {
        Some((m, e)) => (m, e.parse::<i32>().ok()?),
        None => (body, 0),
    };
    let (int_part, frac_part) = mant.split_once('.').unwrap_or((mant, ""));
    if int_part.is_empty() && frac_part.is_empty() {
        return None;
    }
    if !int_part.chars().all(|c| c.is_ascii_digit())
        || !frac_part.chars().all(|c| c.is_ascii_digit())
    {
        return None;
    }
    let digits = format!("{int_part}{frac_part}");
    let mut num: BigInt = if digits.is_empty() {
        BigInt::zero()
    } else {
        digits.parse().ok()?
    };
    let scale = exp.checked_sub(i32::try_from(frac_part.len()).ok()?)?;
    if exp.unsigned_abs() > MAX_DECIMAL_EXPONENT as u32
        || scale.unsigned_abs() > MAX_DECIMAL_EXPONENT as u32 + 400
    {
        return None;
    }
    let mut den = BigInt::one();
    let ten = BigInt::from(10);
    if scale >= 0 {
        num *= num_traits::pow(ten, scale as usize);
    } else {
        den = num_traits::pow(ten, (-scale) as usize);
    }
    if neg {
        num = -num;
    }
    Some(BigRational::new(num, den))
}

/// The exact rational equal to a finite `f64` (every finite double is a dyadic rational).
pub fn rational_from_f64(x: f64) -> Option<BigRational> {
    BigRational::from_float(x)
}
