//! Decimal text to `f64`, fast, with exactly the result of `str::parse::<f64>`.
//!
//! [`parse_decimal`] reads the plain decimals of CSV files (`-0.125`, `3`, `1.5e-7`, up to 19
//! significant digits) and converts them with Clinger's fast path (one correctly rounded
//! operation on exact operands) or the Eisel–Lemire algorithm (Lemire, "Number parsing at a
//! gigabyte per second", 2021), as the standard library does; it gives up (`None`) on anything
//! else and wherever the standard library would go on to a slower method (an ambiguous
//! rounding, a subnormal, zero or infinite result, more digits), so the caller falls back to
//! `str::parse`, which then decides. The tests compare the two on many inputs.

use num_bigint::BigUint;
use num_traits::{One, ToPrimitive};
use std::sync::OnceLock;

/// The powers of ten that are exact in `f64`: `10^0 ..= 10^22`.
const EXACT_POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// The decimal exponents the power-of-five table covers (the standard library's range).
const MIN_POW5: i32 = -342;
const MAX_POW5: i32 = 308;

/// Appends the run of ASCII digits at `text[at..]` to `m`, wrapping past `u64` (which the
/// caller rules out by counting); returns the end of the run. One digit at a time: runs of
/// varying length would mispredict the branches of wider steps.
#[inline]
fn take_digits(text: &[u8], at: usize, m: &mut u64) -> usize {
    let mut end = at;
    while let Some(&b) = text.get(end) {
        let d = b.wrapping_sub(b'0');
        if d > 9 {
            break;
        }
        *m = m.wrapping_mul(10).wrapping_add(u64::from(d));
        end += 1;
    }
    end
}

/// A decimal `mantissa · 10^exponent` read from text.
struct Decimal {
    negative: bool,
    mantissa: u64,
    exponent: i32,
}

/// The exponent `[+-]digits` (1 to 4 digits) that is all of `text`.
fn read_exponent(text: &[u8]) -> Option<i32> {
    let (sign, digits) = match text.split_first() {
        Some((b'-', d)) => (-1, d),
        Some((b'+', d)) => (1, d),
        _ => (1, text),
    };
    if digits.is_empty() || digits.len() > 4 || !digits.iter().all(u8::is_ascii_digit) {
        return None;
    }
    Some(sign * digits.iter().fold(0, |e, &b| 10 * e + i32::from(b - b'0')))
}

/// Reads `[+-]digits[.digits][(e|E)[+-]digits]` with at most 19 significant digits and an
/// exponent of at most 4 digits; `None` for anything else.
fn read_decimal(text: &[u8]) -> Option<Decimal> {
    let negative = text.first() == Some(&b'-');
    let start = usize::from(negative || text.first() == Some(&b'+'));
    let zeros = |from: usize| text[from..].iter().take_while(|&&b| b == b'0').count();
    let mut mantissa = 0u64;
    let lead = zeros(start);
    let mut at = take_digits(text, start + lead, &mut mantissa);
    if at == start {
        return None;
    }
    let mut significant = at - start - lead;
    let mut exponent = 0i32;
    if text.get(at) == Some(&b'.') {
        at += 1;
        // Zeros right after the point are significant only after a nonzero whole part.
        let lead = if significant == 0 { zeros(at) } else { 0 };
        let end = take_digits(text, at + lead, &mut mantissa);
        if end == at {
            return None;
        }
        significant += end - at - lead;
        exponent = -i32::try_from(end - at).ok()?;
        at = end;
    }
    if significant > 19 {
        return None;
    }
    if at < text.len() {
        if text[at] | 0x20 != b'e' {
            return None;
        }
        exponent += read_exponent(&text[at + 1..])?;
    }
    Some(Decimal {
        negative,
        mantissa,
        exponent,
    })
}

/// The value of the decimal `text` — `[+-]digits[.digits][(e|E)[+-]digits]` — where it is
/// found fast and exactly; `None` where `str::parse` must decide (other forms, more than 19
/// significant digits, a result that is subnormal, zero from nonzero digits, or infinite, or a
/// rounding the fast methods cannot settle). Where it returns a value, it is the value
/// `str::parse::<f64>` gives.
pub fn parse_decimal(text: &[u8]) -> Option<f64> {
    let d = read_decimal(text)?;
    let magnitude = if d.mantissa == 0 {
        0.0
    } else if d.mantissa <= 1 << 53 && (-22..=22).contains(&d.exponent) {
        // Clinger: both operands exact, so the one rounding is the correct one.
        let m = d.mantissa as f64;
        let p = EXACT_POW10[d.exponent.unsigned_abs() as usize];
        if d.exponent < 0 {
            m / p
        } else {
            m * p
        }
    } else {
        eisel_lemire(d.mantissa, d.exponent)?
    };
    Some(if d.negative { -magnitude } else { magnitude })
}

/// `5^q` to 128 bits as (high, low) words, the standard library's table entry: for `q >= 0`
/// truncated with the top bit set; for `q < 0` a reciprocal rounded up (`2^(z+127) / 5^-q + 1`
/// with `z` the bit length of `5^-q` down to `q = -27`, below that `2^(2z+128) / 5^-q + 1`
/// truncated to 128 bits). Computed on first use.
fn pow5_128(q: i32) -> (u64, u64) {
    const ENTRIES: usize = (MAX_POW5 - MIN_POW5 + 1) as usize;
    static TABLE: [OnceLock<(u64, u64)>; ENTRIES] = [const { OnceLock::new() }; ENTRIES];
    *TABLE[(q - MIN_POW5) as usize].get_or_init(|| {
        let p = BigUint::from(5u32).pow(q.unsigned_abs());
        let c = if q >= 0 {
            p
        } else {
            let z = p.bits();
            let shift = if q >= -27 { z + 127 } else { 2 * z + 128 };
            (BigUint::one() << shift) / p + 1u32
        };
        let bits = c.bits();
        let c = if bits >= 128 {
            c >> (bits - 128)
        } else {
            c << (128 - bits)
        };
        let lo = (&c & BigUint::from(u64::MAX)).to_u64().unwrap_or(0);
        let hi = (c >> 64u32).to_u64().unwrap_or(0);
        (hi, lo)
    })
}

/// `w · 5^q` approximated to 128 bits as (low, high) words, `w` normalized (top bit set): the
/// high word of `w` times the table's high word, refined with its low word when the bits that
/// decide the rounding are all ones.
fn product_approx(q: i32, w: u64) -> (u64, u64) {
    // The bits below the 55 that make the mantissa, its rounding bit and a possible leading 0.
    const MASK: u64 = u64::MAX >> 55;
    let (hi5, lo5) = pow5_128(q);
    let first = u128::from(w) * u128::from(hi5);
    let (mut lo, mut hi) = (first as u64, (first >> 64) as u64);
    if hi & MASK == MASK {
        let second_hi = ((u128::from(w) * u128::from(lo5)) >> 64) as u64;
        lo = lo.wrapping_add(second_hi);
        if second_hi > lo {
            hi += 1;
        }
    }
    (lo, hi)
}

/// The Eisel–Lemire conversion of `w · 10^q` (`w` nonzero): the correctly rounded normal
/// `f64`, or `None` where the standard library goes on to its exact slow path or the result
/// is subnormal, zero or infinite.
fn eisel_lemire(w: u64, q: i32) -> Option<f64> {
    if !(MIN_POW5..=MAX_POW5).contains(&q) {
        return None;
    }
    let lz = w.leading_zeros();
    let w = w << lz;
    let (lo, hi) = product_approx(q, w);
    if lo == u64::MAX && !(-27..=55).contains(&q) {
        return None;
    }
    let upper = (hi >> 63) as i32;
    let shift = upper + 64 - 52 - 3;
    let mut mantissa = hi >> shift;
    // floor(q · log2(10)) + 63 + the normalization, with the exponent bias 1023.
    let mut power2 = ((q.wrapping_mul(152_170 + 65_536)) >> 16) + 63 + upper - lz as i32 + 1023;
    if power2 <= 0 {
        return None;
    }
    // Exactly halfway with an even result below: round down, not up.
    if lo <= 1 && (-4..=23).contains(&q) && mantissa & 3 == 1 && (mantissa << shift) == hi {
        mantissa &= !1;
    }
    mantissa += mantissa & 1;
    mantissa >>= 1;
    if mantissa >= 2 << 52 {
        mantissa = 1 << 52;
        power2 += 1;
    }
    mantissa &= !(1 << 52);
    if power2 >= 0x7FF {
        return None;
    }
    Some(f64::from_bits(mantissa | (power2 as u64) << 52))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `parse_decimal` agrees with `str::parse` wherever it answers.
    fn agrees(text: &str) -> bool {
        let fast = parse_decimal(text.as_bytes());
        if let Some(v) = fast {
            let want: f64 = text.parse().unwrap_or_else(|_| panic!("{text:?} parsed"));
            assert_eq!(v.to_bits(), want.to_bits(), "{text:?}");
        }
        fast.is_some()
    }

    #[test]
    fn table_matches_the_standard_library_entries() {
        // Entries of the standard library's (and fast_float's) table.
        assert_eq!(
            pow5_128(-342),
            (0xeef4_53d6_923b_d65a, 0x113f_aa29_06a1_3b3f)
        );
        assert_eq!(
            pow5_128(-71),
            (0x8d59_0723_948a_535f, 0x579c_487e_5a38_ad0e)
        );
        assert_eq!(
            pow5_128(-27),
            (0x9e74_d1b7_91e0_7e48, 0x775e_a264_cf55_347e)
        );
        assert_eq!(pow5_128(-1), (0xcccc_cccc_cccc_cccc, 0xcccc_cccc_cccc_cccd));
        assert_eq!(pow5_128(0), (0x8000_0000_0000_0000, 0));
        assert_eq!(pow5_128(55), (0xd0cf_4b50_cfe2_0765, 0xfff4_b4e3_f741_cf6d));
        assert_eq!(
            pow5_128(308),
            (0x8e67_9c2f_5e44_ff8f, 0x570f_09ea_a7ea_7648)
        );
    }

    #[test]
    fn digit_runs_at_every_offset_and_length() {
        let text = b"1234567890123456789.25e7x098765";
        for len in 0..=text.len() {
            let t = &text[..len];
            for at in 0..=len {
                let mut m = 7u64;
                let end = take_digits(t, at, &mut m);
                let run = t[at..].iter().take_while(|b| b.is_ascii_digit()).count();
                assert_eq!(end, at + run, "{len} {at}");
                let want = t[at..at + run].iter().fold(7u64, |m, &b| {
                    m.wrapping_mul(10).wrapping_add(u64::from(b - b'0'))
                });
                assert_eq!(m, want, "{len} {at}");
            }
        }
    }

    #[test]
    fn forms() {
        for (text, want) in [
            ("0", Some(0.0)),
            ("-0", Some(-0.0)),
            ("0.0", Some(0.0)),
            ("-0.000", Some(-0.0)),
            ("0.001", Some(0.001)),
            ("+1.5", Some(1.5)),
            ("1e3", Some(1000.0)),
            ("1E-3", Some(0.001)),
            ("2.5e+2", Some(250.0)),
            ("000123.4500", Some(123.45)),
            ("0.24200448786793888", Some(0.24200448786793888)),
            ("-601879894391618e-15", Some(-0.601879894391618)),
            ("1.", None),
            (".5", None),
            ("", None),
            ("-", None),
            ("1e", None),
            ("1e+", None),
            ("1e99999", None),
            ("inf", None),
            ("NaN", None),
            ("1,5", None),
            (" 1", None),
            ("1.2.3", None),
            ("1\0", None),
            ("1e5\0", None),
            ("0.000000000000000000000000000001", Some(1e-30)),
            ("0.0000000000000000000000000000012", Some(1.2e-30)),
            ("12345678901234567890", None),
            ("1e400", None),
            ("5e-324", None),
        ] {
            let got = parse_decimal(text.as_bytes());
            assert_eq!(got.map(f64::to_bits), want.map(f64::to_bits), "{text:?}");
            agrees(text);
        }
    }

    #[test]
    fn random_decimals_agree_with_std() {
        let mut state = 0x2545_F491_4F6C_DD1D_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut answered = 0;
        for k in 0..400_000 {
            let r = next();
            let text = match k % 4 {
                // Shortest round-trip text of random doubles, plain and scientific.
                0 => format!("{}", f64::from_bits(r)),
                1 => format!("{:e}", f64::from_bits(r)),
                // Random digit strings of up to 20 digits at random exponents.
                2 => {
                    let digits = r % 10u64.pow((next() % 20) as u32 + 1);
                    format!("{digits}e{}", (next() % 700) as i64 - 350)
                }
                // Random decimals with a point, near halfway cases included.
                _ => {
                    let digits = next() % 10u64.pow(19);
                    let s = format!("{digits:019}");
                    let point = (r % 20) as usize;
                    format!("{}.{}", &s[..point.max(1)], &s[point.max(1)..])
                }
            };
            if text.contains("inf") || text.contains("NaN") {
                continue;
            }
            answered += usize::from(agrees(&text));
        }
        assert!(answered > 250_000, "{answered}");
    }

    #[test]
    fn halfway_and_boundary_cases_agree_with_std() {
        // Exact midpoints between neighbouring doubles (ties, rounded to even) and their
        // neighbours: (2k + 1) · 2^(j-1) for a 53-bit k is an integer midpoint for j >= 1,
        // and (2k + 1) · 5^j · 10^-j a fractional one.
        let mut state = 0x9E37_79B9_7F4A_7C15_u64;
        let mut tested = 0;
        for _ in 0..20_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let k = (1u128 << 52) | u128::from(state >> 12);
            let odd = 2 * k + 1;
            let mut cases = Vec::new();
            for j in 0..12 {
                cases.push((odd << j, 0));
            }
            for j in 1..4u32 {
                cases.push((odd * 5u128.pow(j), -(j as i32)));
            }
            for (m, e) in cases {
                for m in [m - 1, m, m + 1] {
                    let digits = m.to_string();
                    if digits.len() <= 19 {
                        tested += usize::from(agrees(&format!("{digits}e{e}")));
                    }
                }
            }
        }
        assert!(tested > 100_000, "{tested}");
        for text in [
            "9007199254740993",
            "9007199254740995",
            "9007199254740994.5",
            "1.7976931348623157e308",
            "1.7976931348623159e308",
            "2.2250738585072011e-308",
            "2.2250738585072014e-308",
            "4.9406564584124654e-324",
        ] {
            agrees(text);
        }
    }
}
