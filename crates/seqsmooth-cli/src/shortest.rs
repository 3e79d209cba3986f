//! The shortest round-trip decimal digits of a double, fast: the Ryū algorithm (Adams, "Ryū:
//! fast float-to-string conversion", PLDI 2018), written from the paper.
//!
//! For a finite, nonzero `x` it finds the decimal `d·10^e` with the fewest digits that lies in
//! the interval of reals rounding to `x` (its ends included when `x`'s mantissa is even, as
//! round-half-even parsing does), and of those the nearest to `x` (the upper one of two equally
//! near) — the same digits as Rust's own `{}` and `{:e}` (Grisu with a Dragon4 fallback), which
//! the tests check against. Multiplying by 5^±q is done with 125-bit approximations of the
//! powers, each computed on first use from exact big integers.
//!
//! Numbers are formatted by the million, so the hot path avoids branches whose outcome varies
//! from number to number (how many digits are dropped, the sign, a point inside the digits or
//! `0.` before them): a mispredicted branch costs more than the work it would skip.

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

/// `floor(m · mul / 2^j)` for a 125-bit `mul` and `j >= 64` (the tests' reference for
/// [`mul_shift_all`]).
#[cfg(test)]
fn mul_shift(m: u64, mul: Split, j: i32) -> u64 {
    let low = (m as u128 * mul.0 as u128) >> 64;
    let high = m as u128 * mul.1 as u128;
    ((low + high) >> (j - 64) as u32) as u64
}

/// `mul_shift` of `4m`, `4m + 2` and `4m - 1 - mm_shift` (the value and the ends of its
/// rounding interval) from one product `m · mul`, exact to the bit: 2 multiplications instead
/// of 6. `m < 2^54`, so `4m · mul` and the ends fit in a (128 + 64)-bit number.
#[inline]
fn mul_shift_all(m: u64, mul: Split, j: i32, mm_shift: u64) -> (u64, u64, u64) {
    let low = u128::from(m) * u128::from(mul.0);
    let high = u128::from(m) * u128::from(mul.1) + (low >> 64);
    // 4m · mul as high · 2^64 + low.
    let high = (high << 2) | u128::from(low as u64 >> 62);
    let low = (low as u64) << 2;
    let shift = (j - 64) as u32;
    let mul = (u128::from(mul.1) << 64) | u128::from(mul.0);
    // Plus 2 · mul, minus (1 + mm_shift) · mul (both below 2^127).
    let up = mul << 1;
    let carry = low.overflowing_add(up as u64).1;
    let up_high = high + (up >> 64) + u128::from(carry);
    let down = mul * u128::from(1 + mm_shift);
    let borrow = low.overflowing_sub(down as u64).1;
    let down_high = high - (down >> 64) - u128::from(borrow);
    (
        (high >> shift) as u64,
        (up_high >> shift) as u64,
        (down_high >> shift) as u64,
    )
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
        (vr, vp, vm) = mul_shift_all(m2, mul, i, mm_shift);
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
        (vr, vp, vm) = mul_shift_all(m2, mul, j, mm_shift);
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
        // Two digits at once, then one: most numbers lose two or three. Selected without
        // branches, which the varying counts would mispredict.
        let mut round_up = false;
        for (step, half) in [(100, 50), (10, 5)] {
            let (p, m, r) = (vp / step, vm / step, vr / step);
            let take = p > m;
            round_up = if take {
                vr - r * step >= half
            } else {
                round_up
            };
            vr = if take { r } else { vr };
            vp = if take { p } else { vp };
            vm = if take { m } else { vm };
            removed += if take { step.ilog10() as i32 } else { 0 };
        }
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

/// `10^k` for `k` in `0..=17`.
const POW10: [u64; 18] = {
    let mut t = [1u64; 18];
    let mut k = 1;
    while k < 18 {
        t[k] = t[k - 1] * 10;
        k += 1;
    }
    t
};

/// The number of decimal digits of `d` (`0 < d < 10^17`).
#[inline]
fn digit_count(d: u64) -> usize {
    // floor(log10(2) · bit length) is the count or one less.
    let t = (((64 - d.leading_zeros()) * 1233) >> 12) as usize;
    t + usize::from(d >= POW10[t])
}

/// The 8 decimal digits of `x < 10^8` as ASCII, the first digit in the lowest byte: the
/// halves, quarters and digits split in parallel lanes of one word.
#[inline]
fn eight_digits(x: u32) -> u64 {
    let x = u64::from(x);
    let hi = x / 10_000;
    // Lanes of 32 bits: the first four digits, then the last four.
    let quads = hi | ((x - hi * 10_000) << 32);
    // Lanes of 16 bits: pairs of digits (a quad / 100 is (quad · 10486) >> 20 below 10^4).
    let top = ((quads * 10_486) >> 20) & 0x0000_007F_0000_007F;
    let pairs = top | ((quads - top * 100) << 16);
    // Lanes of 8 bits: digits (a pair / 10 is (pair · 103) >> 10 below 100).
    let tens = ((pairs * 103) >> 10) & 0x000F_000F_000F_000F;
    (tens | ((pairs - tens * 10) << 8)) | 0x3030_3030_3030_3030
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

/// The 8 decimal digits of `x < 10^8` into `out`, two at a time from [`PAIRS`].
#[inline]
fn eight_digits_by_pairs(x: u32, out: &mut [u8]) {
    let (high, low) = (x / 10_000, x % 10_000);
    for (k, pair) in [high / 100, high % 100, low / 100, low % 100]
        .into_iter()
        .enumerate()
    {
        let p = 2 * pair as usize;
        out[2 * k..2 * k + 2].copy_from_slice(&PAIRS[p..p + 2]);
    }
}

/// The 17 decimal digits of `d < 10^17`, zero-padded on the left, at the start of `buf`. The
/// two 8-digit halves are converted in different ways: the same way twice, they would be
/// vectorized into slower SSE code.
#[inline]
fn seventeen_digits(d: u64, buf: &mut [u8; DIGITS_BUF]) {
    let high = d / 100_000_000;
    let low = (d - high * 100_000_000) as u32;
    let top = high / 100_000_000;
    let middle = (high - top * 100_000_000) as u32;
    buf[0] = b'0' + top as u8;
    eight_digits_by_pairs(middle, &mut buf[1..9]);
    buf[9..17].copy_from_slice(&eight_digits(low).to_le_bytes());
}

/// The digits buffer: 17 digits and room for fixed-size copies past them.
const DIGITS_BUF: usize = 40;
/// The text buffer: every number's text is shorter than [`TEXT`] bytes.
const TEXT: usize = 32;

/// Copies the fixed-size `N` bytes of `from` at `src` to `to` at `dst`.
#[inline]
fn copy<const N: usize>(to: &mut [u8], dst: usize, from: &[u8], src: usize) {
    to[dst..dst + N].copy_from_slice(&from[src..src + N]);
}

/// Appends the plain text of `digits` with the point after `point` of them, when that needs
/// more than 4 zeros after the point or more than 16 digits before it (never for the command's
/// numbers, which are written in scientific notation there).
fn write_long(out: &mut Vec<u8>, negative: bool, digits: &[u8], point: i32) {
    if negative {
        out.push(b'-');
    }
    if point > 0 {
        out.extend_from_slice(digits);
        out.resize(out.len() + point as usize - digits.len(), b'0');
    } else {
        out.extend_from_slice(b"0.");
        out.resize(out.len() + point.unsigned_abs() as usize, b'0');
        out.extend_from_slice(digits);
    }
}

/// Appends `x` (finite, nonzero) as Rust's `{}` (`scientific = false`: plain decimal, no
/// exponent) or `{:e}` (`scientific = true`: `d[.ddd]e[-]x`) would. The text is laid out in a
/// buffer prefilled with `0` by fixed-size copies and appended in one piece; plain text with
/// more than 4 zeros after the point or 16 digits before it (which the command writes in
/// scientific notation) is appended piece by piece.
pub fn write(out: &mut Vec<u8>, x: f64, scientific: bool) {
    let bits = x.to_bits();
    let (d, exp) = decimal(
        bits & ((1u64 << MANTISSA_BITS) - 1),
        ((bits >> MANTISSA_BITS) & 0x7ff) as u32,
    );
    let mut digits = [b'0'; DIGITS_BUF];
    seventeen_digits(d, &mut digits);
    let n = digit_count(d);
    let first = 17 - n;
    let mut text = [b'0'; TEXT + 24];
    let at = usize::from(x.is_sign_negative());
    // Without a branch: the signs of numbers vary unpredictably.
    text[0] = [b'0', b'-'][at];
    // Where the point goes, counted in digits from the first: 0 or less is "0.000ddd".
    let point = n as i32 + exp;
    if !scientific && !(-4..=16).contains(&point) {
        return write_long(out, at == 1, &digits[first..17], point);
    }
    let len = if scientific {
        text[at] = digits[first];
        text[at + 1] = b'.';
        copy::<16>(&mut text, at + 2, &digits, first + 1);
        let mut end = if n > 1 { at + n + 1 } else { at + 1 };
        text[end] = b'e';
        end += 1;
        let e = point - 1;
        if e < 0 {
            text[end] = b'-';
            end += 1;
        }
        let e = e.unsigned_abs();
        let width = 1 + usize::from(e >= 10) + usize::from(e >= 100);
        let mut rest = e;
        for k in (0..width).rev() {
            text[end + k] = b'0' + (rest % 10) as u8;
            rest /= 10;
        }
        end + width
    } else if exp >= 0 {
        // Digits, then zeros (the digits buffer's padding).
        copy::<16>(&mut text, at, &digits, first);
        at + point as usize
    } else {
        // "ddd.ddd" (point > 0) or "0.000ddd" (point <= 0) by the same three writes at
        // computed places, without a branch (the two alternate with the numbers' sizes): the
        // whole part (digits, or the zeros past them), the point, the fraction after its
        // leading zeros.
        let whole = point.max(0) as usize;
        let zeros = (-point).max(0) as usize;
        let before = whole.max(1);
        copy::<16>(&mut text, at, &digits, if whole > 0 { first } else { 17 });
        text[at + before] = b'.';
        copy::<17>(&mut text, at + before + 1 + zeros, &digits, first + whole);
        at + before + 1 + zeros + n - whole
    };
    let start = out.len();
    out.extend_from_slice(&text[..TEXT]);
    out.truncate(start + len);
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
        let mut more = vec![
            99_999_999_999_999_999,
            10u64.pow(16),
            12_345_678_901_234_567,
        ];
        more.extend((1..17).flat_map(|k| [10u64.pow(k) - 1, 10u64.pow(k), 10u64.pow(k) + 1]));
        for d in (1..100_000u64).chain(more) {
            let mut buf = [0u8; DIGITS_BUF];
            seventeen_digits(d, &mut buf);
            assert_eq!(std::str::from_utf8(&buf[..17]).unwrap(), format!("{d:017}"));
            assert_eq!(digit_count(d), d.to_string().len(), "{d}");
        }
        for x in [0, 1, 9, 10, 99, 1234, 9999, 10_000, 12_345_678, 99_999_999] {
            assert_eq!(eight_digits(x).to_le_bytes(), *format!("{x:08}").as_bytes());
        }
    }

    #[test]
    fn one_product_gives_the_three_shifts() {
        let mut state = 0x2545_F491_4F6C_DD1D_u64;
        for q in 0..POW5_TABLE {
            for _ in 0..200 {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                let m = (state >> 10) | 1 << 53;
                let m = if state % 7 == 0 {
                    m & ((1 << 53) - 1) | 1
                } else {
                    m
                };
                let mm_shift = state >> 63;
                for (mul, j) in [(pow5(q), 64 + (state % 60) as i32), (pow5_inv(q), 120)] {
                    let want = (
                        mul_shift(4 * m, mul, j),
                        mul_shift(4 * m + 2, mul, j),
                        mul_shift(4 * m - 1 - mm_shift, mul, j),
                    );
                    assert_eq!(mul_shift_all(m, mul, j, mm_shift), want, "{m} {q} {j}");
                }
            }
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
