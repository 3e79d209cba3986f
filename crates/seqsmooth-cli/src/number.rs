//! Number text: round-trip formatting of `f64` and the parsers of the numeric arguments.
//!
//! The argument parsers return `Err(message)`; clap prints it as
//! `error: invalid value 'V' for '--name <X>': message` and exits with code 2.

use num_traits::{One, Zero};
use seqsmooth::polynomial::MAX_DEGREE;
use seqsmooth::scalar::{parse_rational, Rational};

/// The shortest text that parses back to exactly `x`.
///
/// Plain decimal (`{}`) for `0` and `1e-5 <= |x| < 1e16`, otherwise scientific (`{:e}`, e.g.
/// `1e-300`, `2.5e20`): both of Rust's formats print the shortest round-trip digits, the
/// plain one only avoids an exponent, which would take hundreds of digits far from 1.
/// Non-finite values print as `NaN`, `inf`, `-inf` (they never occur in valid output).
pub fn fmt_f64(x: f64) -> String {
    let mut out = Vec::with_capacity(24);
    write_f64(&mut out, x);
    // Only ASCII digits, signs, '.', 'e', "NaN" and "inf" are written.
    String::from_utf8(out).unwrap_or_default()
}

/// Appends [`fmt_f64`]`(x)` to `out` without allocating (beyond `out`'s growth): the digits
/// of [`crate::shortest`], the same as Rust's `{}` and `{:e}`.
#[inline]
pub fn write_f64(out: &mut Vec<u8>, x: f64) {
    let a = x.abs();
    if x == 0.0 || !x.is_finite() {
        write_special(out, x);
    } else {
        crate::shortest::write(out, x, !(1e-5..1e16).contains(&a));
    }
}

/// Appends "0", "-0", "NaN", "inf" or "-inf".
#[cold]
fn write_special(out: &mut Vec<u8>, x: f64) {
    out.extend_from_slice(x.to_string().as_bytes());
}

/// The rational `r` as `p/q` in lowest terms, or `p` alone when `q = 1`.
pub fn fmt_rational(r: &Rational) -> String {
    r.to_string()
}

/// A discount factor θ as given on the command line: exact, and rounded to `f64`.
#[derive(Clone, Debug)]
pub struct Theta {
    /// The text as given (used in messages).
    pub text: String,
    /// θ exactly (`0.9` is `9/10`).
    pub exact: Rational,
    /// θ rounded to the nearest `f64`.
    pub value: f64,
}

impl Theta {
    /// θ as an `f64` strictly inside `(0, 1)`, for the computations that run in `f64`.
    pub fn value_f64(&self) -> Result<f64, String> {
        if self.value > 0.0 && self.value < 1.0 {
            Ok(self.value)
        } else {
            Err(format!(
                "theta {} is out of range: it rounds to {} in double precision, and the filters \
                 need 0 < theta < 1 after rounding (--exact tables accept it)",
                self.text, self.value
            ))
        }
    }
}

/// Parses `--theta`: `0.9`, `9/10` or `9e-1`, strictly between 0 and 1.
pub fn parse_theta(s: &str) -> Result<Theta, String> {
    let text = s.trim();
    let exact = parse_rational(text)
        .ok_or_else(|| format!("theta '{text}' is not a number (write it as 0.9 or 9/10)"))?;
    if !(exact > Rational::zero() && exact < Rational::one()) {
        return Err(format!(
            "theta {text} is out of range: it must lie strictly between 0 and 1"
        ));
    }
    let value = seqsmooth::scalar::ratio_to_f64(&exact);
    Ok(Theta {
        text: text.to_string(),
        exact,
        value,
    })
}

/// Parses `--degree`: a whole number from 0 to [`MAX_DEGREE`].
pub fn parse_degree(s: &str) -> Result<usize, String> {
    let text = s.trim();
    let range = format!("it must be a whole number from 0 to {MAX_DEGREE}");
    match text.parse::<i128>() {
        Ok(d) if (0..=MAX_DEGREE as i128).contains(&d) => Ok(d as usize),
        Ok(d) if d > MAX_DEGREE as i128 => Err(format!(
            "degree {text} is out of range: the largest supported degree is {MAX_DEGREE}"
        )),
        _ => Err(format!("degree {text} is out of range: {range}")),
    }
}

/// Parses `--n`: the 0-based index of the newest sample, a whole number from 0 to `i64::MAX`.
pub fn parse_index(s: &str) -> Result<u64, String> {
    let text = s.trim();
    match text.parse::<i128>() {
        Ok(n) if (0..=i64::MAX as i128).contains(&n) => Ok(n as u64),
        _ => Err(format!(
            "n {text} is out of range: it must be a whole number from 0 to {}",
            i64::MAX
        )),
    }
}

fn parse_f64(name: &str, s: &str) -> Result<f64, String> {
    let text = s.trim();
    text.parse::<f64>()
        .map_err(|_| format!("{name} '{text}' is not a number"))
}

/// Parses `--tau`: a positive finite number.
pub fn parse_tau(s: &str) -> Result<f64, String> {
    let v = parse_f64("tau", s)?;
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(format!(
            "tau {} is out of range: it must be a positive finite number",
            s.trim()
        ))
    }
}

/// Parses `--sigma`: a positive finite number.
pub fn parse_sigma(s: &str) -> Result<f64, String> {
    let v = parse_f64("sigma", s)?;
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(format!(
            "sigma {} is out of range: it must be a positive finite number",
            s.trim()
        ))
    }
}

/// Parses `--lead`: any finite number (negative = retrodiction).
pub fn parse_lead(s: &str) -> Result<f64, String> {
    let v = parse_f64("lead", s)?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!(
            "lead {} is out of range: it must be a finite number",
            s.trim()
        ))
    }
}

/// Parses `--window`: the number of samples in the window (Morrison's `L+1`), a whole number
/// from 1 to `i64::MAX`. Whether it suits the degree is checked by the command.
pub fn parse_window(s: &str) -> Result<usize, String> {
    let text = s.trim();
    match text.parse::<i128>() {
        Ok(w) if (1..=i64::MAX as i128).contains(&w) && w <= usize::MAX as i128 => Ok(w as usize),
        _ => Err(format!(
            "window {text} is out of range: it must be a whole number of samples from 1 to {}",
            i64::MAX
        )),
    }
}

/// A lead in sampling intervals as given on the command line (`seqsmooth vrf --kind fixed`):
/// exact, and rounded to `f64`.
#[derive(Clone, Debug)]
pub struct LeadSteps {
    /// The lead exactly (`-2.5` is `-5/2`).
    pub exact: Rational,
    /// The lead rounded to the nearest `f64`.
    pub value: f64,
}

impl Default for LeadSteps {
    fn default() -> Self {
        Self {
            exact: Rational::zero(),
            value: 0.0,
        }
    }
}

/// Parses `--lead` of `seqsmooth vrf`: `0`, `1`, `-2.5`, `-5/2` or `25e-1`, in samples, exactly;
/// finite in double precision.
pub fn parse_lead_steps(s: &str) -> Result<LeadSteps, String> {
    let text = s.trim();
    let not_a_number = || format!("lead '{text}' is not a number (write it as -2.5 or -5/2)");
    let out_of_range = || {
        format!("lead {text} is out of range: it must be a finite number of samples (|H| < 1e300)")
    };
    // An exponent this large would take unbounded time to expand exactly.
    if let Some((_, e)) = text.split_once(['e', 'E']) {
        if e.parse::<i64>().is_ok_and(|e| e.unsigned_abs() > 400) {
            return Err(format!(
                "lead {text} is out of range: write it with an exponent from -400 to 400"
            ));
        }
    }
    let exact = parse_rational(text).ok_or_else(not_a_number)?;
    let value = seqsmooth::scalar::ratio_to_f64(&exact);
    if !(value.is_finite() && value.abs() < 1e300) {
        return Err(out_of_range());
    }
    Ok(LeadSteps { exact, value })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(x: f64) {
        let s = fmt_f64(x);
        let back: f64 = s.parse().unwrap();
        assert_eq!(back.to_bits(), x.to_bits(), "{x:?} printed as {s}");
        assert!(s.len() <= 24, "{x:?} printed as {s} ({} chars)", s.len());
    }

    #[test]
    fn round_trip_special_values() {
        for x in [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.1,
            0.1 + 0.2,
            1e-5,
            9.999999999999999e-6,
            1e16,
            9999999999999998.0,
            1e-300,
            -1e-300,
            5e-324,
            f64::MIN_POSITIVE,
            f64::MAX,
            f64::MIN,
            f64::EPSILON,
            123456.789,
            2.5e20,
        ] {
            check(x);
        }
        assert_eq!(fmt_f64(1e-300), "1e-300");
        assert_eq!(fmt_f64(2.5e20), "2.5e20");
        assert_eq!(fmt_f64(0.1), "0.1");
        assert_eq!(fmt_f64(4.6), "4.6");
        assert_eq!(fmt_f64(3.0), "3");
    }

    #[test]
    fn round_trip_many_bit_patterns() {
        // xorshift64 over all exponents: every finite double must survive.
        let mut state = 0x9E37_79B9_7F4A_7C15_u64;
        for _ in 0..200_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let x = f64::from_bits(state);
            if x.is_finite() {
                check(x);
            }
        }
    }

    #[test]
    fn theta_forms() {
        assert_eq!(parse_theta("9/10").unwrap().exact.to_string(), "9/10");
        assert_eq!(parse_theta("0.9").unwrap().exact.to_string(), "9/10");
        assert_eq!(parse_theta("0.9").unwrap().value, 0.9);
        assert!(parse_theta("1").is_err());
        assert!(parse_theta("0").is_err());
        assert!(parse_theta("nan").is_err());
        let near_one = parse_theta("0.99999999999999999999").unwrap();
        assert!(near_one.value_f64().is_err());
    }

    #[test]
    fn degree_range() {
        assert_eq!(parse_degree("0"), Ok(0));
        assert_eq!(parse_degree("24"), Ok(24));
        assert!(parse_degree("25").unwrap_err().contains("degree 25"));
        assert!(parse_degree("-1").unwrap_err().contains("degree -1"));
        assert!(parse_degree("x").is_err());
    }

    #[test]
    fn window_range() {
        assert_eq!(parse_window("1"), Ok(1));
        assert_eq!(parse_window(" 11 "), Ok(11));
        assert!(parse_window("0")
            .unwrap_err()
            .contains("window 0 is out of range"));
        assert!(parse_window("-3").unwrap_err().contains("window -3"));
        assert!(parse_window("2.5").is_err());
    }

    #[test]
    fn lead_steps_forms() {
        assert_eq!(parse_lead_steps("-5/2").unwrap().exact.to_string(), "-5/2");
        assert_eq!(parse_lead_steps("-2.5").unwrap().exact.to_string(), "-5/2");
        assert_eq!(parse_lead_steps("25e-1").unwrap().value, 2.5);
        assert_eq!(parse_lead_steps("0").unwrap().value, 0.0);
        assert!(parse_lead_steps("x")
            .unwrap_err()
            .contains("lead 'x' is not a number"));
        assert!(parse_lead_steps("1e999")
            .unwrap_err()
            .contains("out of range"));
        assert!(parse_lead_steps("1e-99999999")
            .unwrap_err()
            .contains("out of range"));
        assert!(parse_lead_steps("inf").is_err());
    }
}
