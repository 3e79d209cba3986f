//! The shortest round-trip decimal digits of a double, fast: the Ryū algorithm (Adams, "Ryū:
//! fast float-to-string conversion", PLDI 2018), written from the paper.
//!
//! For a finite, nonzero `x` it finds the decimal `d·10^e` with the fewest digits that lies in
//! the interval of reals rounding to `x` (its ends included when `x`'s mantissa is even, as
//! round-half-even parsing does), and of those the nearest to `x` (the upper one of two equally
//! near) — the same digits as Rust's own `{}` and `{:e}` (Grisu with a Dragon4 fallback), which
//! the tests check against. Multiplying by
//! 5^±q is done with 125-bit approximations of the powers, each computed on first use from exact
//! big integers.

use num_bigint::BigUint;
use num_traits::{One, ToPrimitive};
use std::sync::OnceLock;

const MANTISSA_BITS: u32 = 52;
const EXPONENT_BIAS: i32 = 1023;
/// Bits of the powers of 5 and of their inverses.
const POW5_BITCOUNT: i32 = 125;
const POW5_INV_BITCOUNT: i32 = 125;
/// Table sizes: 5^-q for q < 342 (binary exponents e2 ≥ 0), 5^i for i < 326 (e2 < 0).
const POW5_INV_TABLE: usize = 342;
const POW5_TABLE: usize = 326;

/// `ceil(log2(5^e))` for `e` in `0..=3528` (1 for `e = 0`).
fn pow5bits(e: i32) -> i32 {
    (((e as u32) * 1_217_359) >> 19) as i32 + 1
}

/// `floor(log10(2^e))` for `e` in `0..=1650`.
fn log10_pow2(e: i32) -> u32 {
    ((e as u32) * 78_913) >> 18
}

/// `floor(log10(5^e))` for `e` in `0..=2620`.
fn log10_pow5(e: i32) -> u32 {
    ((e as u32) * 732_923) >> 20
}

/// A 128-bit table entry as (low, high) words.
type Split = (u64, u64);

fn split(v: &BigUint) -> Split {
    let mask = BigUint::from(u64::MAX);
    let lo = (v & &mask).to_u64().unwrap_or(0);
    let hi = (v >> 64u32).to_u64().unwrap_or(0);
    (lo, hi)
}

/// `floor(2^(pow5bits(q) - 1 + 125) / 5^q) + 1`, computed on first use (one big-integer
/// division; an input's numbers need only a few).
fn pow5_inv(q: usize) -> Split {
    static TABLE: [OnceLock<Split>; POW5_INV_TABLE] = [const { OnceLock::new() }; POW5_INV_TABLE];
    *TABLE[q].get_or_init(|| {
        let shift = (pow5bits(q as i32) - 1 + POW5_INV_BITCOUNT) as u32;
        split(&((BigUint::one() << shift) / BigUint::from(5u32).pow(q as u32) + 1u32))
    })
}

/// `floor(5^i / 2^(pow5bits(i) - 125))`, computed on first use.
fn pow5(i: usize) -> Split {
    static TABLE: [OnceLock<Split>; POW5_TABLE] = [const { OnceLock::new() }; POW5_TABLE];
    *TABLE[i].get_or_init(|| {
        let bits = pow5bits(i as i32) - POW5_BITCOUNT;
        let p = BigUint::from(5u32).pow(i as u32);
        split(&if bits >= 0 {
            p >> bits as u32
        } else {
            p << (-bits) as u32
        })
    })
}

/// `floor(m · mul / 2^j)` for a 125-bit `mul` and `j >= 64`.
#[inline]
fn mul_shift(m: u64, mul: Split, j: i32) -> u64 {
    let low = (m as u128 * mul.0 as u128) >> 64;
    let high = m as u128 * mul.1 as u128;
    ((low + high) >> (j - 64) as u32) as u64
}

/// The exponent of 5 in `v > 0`.
fn pow5_factor(mut v: u64) -> u32 {
    let mut count = 0;
    while v % 5 == 0 {
        v /= 5;
        count += 1;
    }
    count
}

fn multiple_of_pow5(v: u64, p: u32) -> bool {
    pow5_factor(v) >= p
}

/// The shortest nearest decimal of a finite, nonzero, positive double given by its raw
/// mantissa and exponent fields: `(digits, exponent)` with the value `digits · 10^exponent`.
fn decimal(ieee_mantissa: u64, ieee_exponent: u32) -> (u64, i32) {
    let (e2, m2) = if ieee_exponent == 0 {
        (1 - EXPONENT_BIAS - MANTISSA_BITS as i32 - 2, ieee_mantissa)
    } else {
        (
            ieee_exponent as i32 - EXPONENT_BIAS - MANTISSA_BITS as i32 - 2,
            (1u64 << MANTISSA_BITS) | ieee_mantissa,
        )
    };
    let accept_bounds = m2 & 1 == 0;
    // The value is mv·2^e2 with mv = 4·m2; its rounding interval is (mm, mp)·2^e2.
    let mv = 4 * m2;
    let mm_shift = u64::from(ieee_mantissa != 0 || ieee_exponent <= 1);
    let (mut vr, mut vp, mut vm, e10);
    // Whether the interval's lower end is a decimal with the digits removed so far (then,
    // when it is in the interval, removing its trailing zeros gives a shorter decimal).
    let mut vm_trailing_zeros = false;
    if e2 >= 0 {
        let q = log10_pow2(e2) - u32::from(e2 > 3);
        e10 = q as i32;
        let k = POW5_INV_BITCOUNT + pow5bits(q as i32) - 1;
        let i = -e2 + q as i32 + k;
        let mul = pow5_inv(q as usize);
        vr = mul_shift(mv, mul, i);
        vp = mul_shift(mv + 2, mul, i);
        vm = mul_shift(mv - 1 - mm_shift, mul, i);
        // Only for q <= 21 can the exact quotients be integers; at most one of mv - 1 -
        // mm_shift, mv, mv + 2 is a multiple of 5.
        if q <= 21 && mv % 5 != 0 {
            if accept_bounds {
                vm_trailing_zeros = multiple_of_pow5(mv - 1 - mm_shift, q);
            } else {
                // The upper end is excluded: step below it when it is exact.
                vp -= u64::from(multiple_of_pow5(mv + 2, q));
            }
        }
    } else {
        let q = log10_pow5(-e2) - u32::from(-e2 > 1);
        e10 = q as i32 + e2;
        let i = -e2 - q as i32;
        let k = pow5bits(i) - POW5_BITCOUNT;
        let j = q as i32 - k;
        let mul = pow5(i as usize);
        vr = mul_shift(mv, mul, j);
        vp = mul_shift(mv + 2, mul, j);
        vm = mul_shift(mv - 1 - mm_shift, mul, j);
        if q <= 1 {
            // mv has at least q trailing zero bits, so the quotients are exact.
            if accept_bounds {
                vm_trailing_zeros = mm_shift == 1;
            } else {
                vp -= 1;
            }
        }
    }
    // Remove digits while the interval still holds a shorter decimal.
    let mut removed = 0i32;
    let output = if vm_trailing_zeros {
        let mut last_removed = 0u64;
        while vp / 10 > vm / 10 {
            vm_trailing_zeros &= vm % 10 == 0;
            last_removed = vr % 10;
            vr /= 10;
            vp /= 10;
            vm /= 10;
            removed += 1;
        }
        if vm_trailing_zeros {
            while vm % 10 == 0 {
                last_removed = vr % 10;
                vr /= 10;
                vm /= 10;
                removed += 1;
            }
        }
        // Exactly halfway between two shortest decimals, Rust's formatting (and so this)
        // takes the upper one: no round-half-even correction.
        vr + u64::from((vr == vm && (!accept_bounds || !vm_trailing_zeros)) || last_removed >= 5)
    } else {
        let mut round_up = false;
        while vp / 10 > vm / 10 {
            round_up = vr % 10 >= 5;
            vr /= 10;
            vp /= 10;
            vm /= 10;
            removed += 1;
        }
        vr + u64::from(vr == vm || round_up)
    };
    (output, e10 + removed)
}

/// "00", "01", …, "99".
const PAIRS: [u8; 200] = {
    let mut t = [0u8; 200];
    let mut i = 0;
    while i < 100 {
        t[2 * i] = b'0' + (i / 10) as u8;
        t[2 * i + 1] = b'0' + (i % 10) as u8;
        i += 1;
    }
    t
};

/// Writes the decimal digits of `d` at the end of `buf`; returns where they start. Four
/// digits per division on the long path, so the chain of dependent divisions stays short.
fn decimal_digits(mut d: u64, buf: &mut [u8; 20]) -> usize {
    let pair = |k: u32| &PAIRS[2 * k as usize..2 * k as usize + 2];
    let mut i = buf.len();
    while d >= 10_000 {
        let r = (d % 10_000) as u32;
        d /= 10_000;
        buf[i - 4..i - 2].copy_from_slice(pair(r / 100));
        buf[i - 2..i].copy_from_slice(pair(r % 100));
        i -= 4;
    }
    let mut d = d as u32;
    while d >= 100 {
        buf[i - 2..i].copy_from_slice(pair(d % 100));
        d /= 100;
        i -= 2;
    }
    if d >= 10 {
        buf[i - 2..i].copy_from_slice(pair(d));
        i - 2
    } else {
        buf[i - 1] = b'0' + d as u8;
        i - 1
    }
}

/// Appends `x` (finite, nonzero) as Rust's `{}` (`scientific = false`: plain decimal, no
/// exponent) or `{:e}` (`scientific = true`: `d[.ddd]e[-]x`) would.
pub fn write(out: &mut Vec<u8>, x: f64, scientific: bool) {
    let bits = x.to_bits();
    let (digits, exp) = decimal(
        bits & ((1u64 << MANTISSA_BITS) - 1),
        ((bits >> MANTISSA_BITS) & 0x7ff) as u32,
    );
    if x.is_sign_negative() {
        out.push(b'-');
    }
    let mut buf = [0u8; 20];
    let start = decimal_digits(digits, &mut buf);
    let text = &buf[start..];
    let n = text.len() as i32;
    if scientific {
        out.push(text[0]);
        if n > 1 {
            out.push(b'.');
            out.extend_from_slice(&text[1..]);
        }
        out.push(b'e');
        let e = exp + n - 1;
        if e < 0 {
            out.push(b'-');
        }
        let e = e.unsigned_abs();
        if e >= 100 {
            out.push(b'0' + (e / 100) as u8);
        }
        if e >= 10 {
            out.push(b'0' + (e / 10 % 10) as u8);
        }
        out.push(b'0' + (e % 10) as u8);
    } else if exp >= 0 {
        out.extend_from_slice(text);
        out.resize(out.len() + exp as usize, b'0');
    } else {
        let point = n + exp;
        if point > 0 {
            out.extend_from_slice(&text[..point as usize]);
            out.push(b'.');
            out.extend_from_slice(&text[point as usize..]);
        } else {
            out.extend_from_slice(b"0.");
            out.resize(out.len() + (-point) as usize, b'0');
            out.extend_from_slice(text);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rust's own formatting is the oracle.
    fn check(x: f64) {
        for sci in [false, true] {
            let mut out = Vec::new();
            write(&mut out, x, sci);
            let want = if sci {
                format!("{x:e}")
            } else {
                format!("{x}")
            };
            assert_eq!(String::from_utf8(out).unwrap(), want, "{:#x}", x.to_bits());
        }
    }

    #[test]
    fn digits_of_integers() {
        for d in (0..100_000u64).chain([u64::MAX, 10u64.pow(19), 99_999_999_999_999_999]) {
            let mut buf = [0u8; 20];
            let start = decimal_digits(d, &mut buf);
            assert_eq!(std::str::from_utf8(&buf[start..]).unwrap(), d.to_string());
        }
    }

    #[test]
    fn tables_start_right() {
        assert_eq!(pow5_inv(0), (1, 1 << 61));
        assert_eq!(pow5(0), (0, 1 << 60));
        assert_eq!(pow5(1), (0, 1 << 60 | 1 << 58));
        // 2^127 / 5 = 0x1999…9 (a 125-bit number), rounded up.
        assert_eq!(pow5_inv(1), (0x9999_9999_9999_999A, 0x1999_9999_9999_9999));
    }

    #[test]
    fn special_and_boundary_values() {
        let mut xs = vec![
            1.0,
            0.1,
            0.3,
            0.1 + 0.2,
            1e-5,
            9.999999999999999e-6,
            1e16,
            9999999999999998.0,
            1e-300,
            5e-324,
            1e-323,
            f64::MIN_POSITIVE,
            f64::MAX,
            f64::EPSILON,
            123456.789,
            2.5e20,
            1e23,
            5e-310,
            9007199254740993.0,
            0.5,
            0.25,
            2.0f64.powi(-1074),
        ];
        for e in -1074..=1023 {
            let p = 2.0f64.powi(e);
            xs.extend([
                p,
                p * 1.5,
                p * (1.0 + f64::EPSILON),
                p * (2.0 - f64::EPSILON),
            ]);
        }
        for e in -325..=308 {
            let p: f64 = format!("1e{e}").parse().unwrap();
            xs.extend([
                p,
                f64::from_bits(p.to_bits() + 1),
                f64::from_bits(p.to_bits() - 1),
            ]);
        }
        for k in 1..100_000u64 {
            xs.push(k as f64);
            xs.push(k as f64 / 1000.0);
            xs.push(k as f64 * 1e10);
        }
        for x in xs {
            if x.is_finite() && x != 0.0 {
                check(x);
                check(-x);
            }
        }
    }

    #[test]
    fn random_bit_patterns() {
        let mut state = 0x2545_F491_4F6C_DD1D_u64;
        for _ in 0..2_000_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let x = f64::from_bits(state);
            if x.is_finite() && x != 0.0 {
                check(x);
            }
        }
    }

    #[test]
    fn random_short_decimals() {
        // Values written with few digits: ties and trailing-zero paths of the digit removal.
        let mut state = 0x9E37_79B9_7F4A_7C15_u64;
        for _ in 0..300_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let digits = state % 100_000_000;
            let e = (state >> 40) % 600;
            let x: f64 = format!("{digits}e{}", e as i64 - 300).parse().unwrap();
            if x.is_finite() && x != 0.0 {
                check(x);
            }
        }
    }
}
