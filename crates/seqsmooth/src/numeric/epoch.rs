//! Timestamps as seconds since the Unix epoch (1970-01-01T00:00:00Z), the one time axis every
//! front end reads dates onto: integer ticks of any unit (Parquet and Arrow timestamps and
//! dates, numpy `datetime64`), and ISO-8601 / RFC 3339 text (CSV cells).
//!
//! The rule: a timestamp is the **nearest double to its exact number of seconds** (what parsing
//! that number written out in decimal gives), Unix time (no leap seconds, the proleptic
//! Gregorian calendar). A time written without an offset is UTC. Seconds at 1.7e9 are resolved
//! to about 2.4e-7 s (a double's spacing there): finer ticks are rounded to it.

use crate::error::{Error, Param};

/// Seconds in a day.
const DAY: i64 = 86_400;

/// `ticks · num / den` seconds as the nearest double to the exact value, for `den` a power of
/// ten (`1` for whole units: minutes `num = 60`, days `num = 86_400`; milliseconds `den =
/// 1_000`): one correctly rounded division where both operands are exact doubles, else through
/// the decimal text (correctly rounded by `str::parse`).
///
/// Errors: `den` not a positive power of ten, `num` not positive, or the product beyond `i128`.
///
/// ```
/// use seqsmooth::numeric::epoch::seconds_from_ticks;
/// assert_eq!(seconds_from_ticks(1_709_294_400_123, 1, 1_000).unwrap(), 1_709_294_400.123);
/// assert_eq!(seconds_from_ticks(19_783, 86_400, 1).unwrap(), 1_709_251_200.0); // 2024-03-01
/// // nanoseconds beyond 2^53: still the double nearest to the decimal
/// assert_eq!(seconds_from_ticks(1_709_294_400_123_456_789, 1, 1_000_000_000).unwrap(),
///            "1709294400.123456789".parse::<f64>().unwrap());
/// assert!(seconds_from_ticks(1, 1, 3).is_err());
/// ```
pub fn seconds_from_ticks(ticks: i64, num: i64, den: i64) -> Result<f64, Error> {
    let unit = || Error::InvalidParameter {
        name: Param::TimeUnit,
        value: format!("{num}/{den} s"),
        reason: "a tick must be a positive whole number of seconds over a power of ten".into(),
    };
    if num <= 0 || den <= 0 || 10i64.pow(den.ilog10()) != den {
        return Err(unit());
    }
    let exact = i128::from(ticks)
        .checked_mul(i128::from(num))
        .ok_or_else(unit)?;
    Ok(decimal_seconds(exact, den))
}

/// `scaled / den` (`den` a power of ten) as the nearest double.
fn decimal_seconds(scaled: i128, den: i64) -> f64 {
    const EXACT: u128 = 1 << 53;
    if den == 1 {
        // Rounded to nearest once (integer to float casts round to nearest, ties to even).
        return scaled as f64;
    }
    if scaled.unsigned_abs() <= EXACT && (den as u128) <= EXACT {
        return scaled as f64 / den as f64;
    }
    // Whole seconds plus the fraction, kept when it is provably the nearest double (almost
    // always); the decimal text decides the rest.
    let d = i128::from(den);
    let x = scaled.div_euclid(d) as f64 + scaled.rem_euclid(d) as f64 / den as f64;
    if is_nearest(x, scaled, d) {
        return x;
    }
    let digits = den.ilog10() as usize;
    let sign = if scaled < 0 { "-" } else { "" };
    let den = den.unsigned_abs() as u128;
    let (whole, frac) = (scaled.unsigned_abs() / den, scaled.unsigned_abs() % den);
    format!("{sign}{whole}.{frac:0digits$}")
        .parse()
        .unwrap_or(scaled as f64 / den as f64)
}

/// Whether `x` is the double nearest to `scaled / d` (strictly: a tie answers `false`), by
/// exact integer arithmetic on `x = M·2^E`: `|scaled/d − x|` below half the gap to each
/// neighbour. `false` also where the integers would overflow.
fn is_nearest(x: f64, scaled: i128, d: i128) -> bool {
    if x == 0.0 || !x.is_finite() || (x < 0.0) != (scaled < 0) {
        return false;
    }
    let bits = x.abs().to_bits();
    let exp = (bits >> 52) as i32;
    if exp == 0 {
        return false;
    }
    let m = i128::from((bits & ((1 << 52) - 1)) | (1 << 52));
    let e = exp - 1075;
    let a = scaled.abs();
    // Everything times d·2^-E (E < 0) or d (E ≥ 0): the value, x, and the gap above x.
    let (value, at, gap) = if e < 0 {
        let k = (-e) as u32;
        if k >= 100 {
            return false;
        }
        match (a.checked_mul(1 << k), m.checked_mul(d)) {
            (Some(v), Some(x)) => (v, x, d),
            _ => return false,
        }
    } else {
        let scale = match 1i128.checked_shl(e as u32) {
            Some(s) if e < 100 => s,
            _ => return false,
        };
        match (
            m.checked_mul(d).and_then(|v| v.checked_mul(scale)),
            d.checked_mul(scale),
        ) {
            (Some(x), Some(g)) => (a, x, g),
            _ => return false,
        }
    };
    let diff = value - at;
    if diff >= 0 {
        2 * diff < gap
    } else if m == 1 << 52 {
        // Below a power of two the gap is half as wide.
        4 * -diff < gap
    } else {
        2 * -diff < gap
    }
}

/// Days from 1970-01-01 to the proleptic Gregorian date `year-month-day` (negative before),
/// for `month` 1–12 (any `day`, counted on from the month's first): Hinnant's `days_from_civil`.
///
/// ```
/// use seqsmooth::numeric::epoch::days_from_civil;
/// assert_eq!(days_from_civil(1970, 1, 1), 0);
/// assert_eq!(days_from_civil(2024, 3, 1), 19_783);
/// assert_eq!(days_from_civil(1969, 12, 31), -1);
/// assert_eq!(days_from_civil(2000, 2, 29) + 1, days_from_civil(2000, 3, 1));
/// ```
pub fn days_from_civil(year: i64, month: u32, day: u32) -> i64 {
    let y = if month <= 2 { year - 1 } else { year };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let m = i64::from(month);
    let doy = (153 * (if m > 2 { m - 3 } else { m + 9 }) + 2) / 5 + i64::from(day) - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

/// Days in `month` (1–12) of `year` (proleptic Gregorian).
fn days_in_month(year: i64, month: u32) -> u32 {
    match month {
        2 if year % 4 == 0 && (year % 100 != 0 || year % 400 == 0) => 29,
        2 => 28,
        4 | 6 | 9 | 11 => 30,
        _ => 31,
    }
}

/// Whether `text` starts like an ISO-8601 date (`YYYY-`): a cheap test that no decimal number
/// passes, so that a reader can try [`parse_iso8601`] only where a number failed and a date
/// was meant.
///
/// ```
/// use seqsmooth::numeric::epoch::looks_like_date;
/// assert!(looks_like_date(b"2024-03-01"));
/// assert!(!looks_like_date(b"1e-5") && !looks_like_date(b"-1234.5"));
/// ```
pub fn looks_like_date(text: &[u8]) -> bool {
    text.len() >= 5 && text[..4].iter().all(u8::is_ascii_digit) && text[4] == b'-'
}

/// The ISO-8601 time `text` as seconds since the Unix epoch (the rule of the
/// [module](self)): the RFC 3339 form `YYYY-MM-DDTHH:MM:SS[.fraction](Z|±HH:MM)`, and its
/// everyday relatives — `T` or a space (either case) between date and time; seconds optional
/// (`HH:MM`); any number of fraction digits (those beyond the 18th, below an attosecond, are
/// dropped); an offset as `±HH:MM`, `±HHMM` or `±HH`; a date alone (`YYYY-MM-DD`, its midnight).
/// A time without an offset is **UTC**. Leap seconds (`:60`) have no Unix time and are refused.
///
/// Errors: [`Error::InvalidParameter`] naming the text and what is wrong with it.
///
/// ```
/// use seqsmooth::numeric::epoch::parse_iso8601;
/// assert_eq!(parse_iso8601("2024-03-01T12:00:00Z").unwrap(), 1_709_294_400.0);
/// assert_eq!(parse_iso8601("2024-03-01T12:00:00.25Z").unwrap(), 1_709_294_400.25);
/// assert_eq!(parse_iso8601("2024-03-01T14:00:00+02:00").unwrap(), 1_709_294_400.0);
/// assert_eq!(parse_iso8601("2024-03-01 12:00").unwrap(), 1_709_294_400.0); // naive: UTC
/// assert_eq!(parse_iso8601("2024-03-01").unwrap(), 1_709_251_200.0);
/// assert!(parse_iso8601("2024-02-30").is_err());
/// ```
pub fn parse_iso8601(text: &str) -> Result<f64, Error> {
    let bad = |reason: &str| Error::InvalidParameter {
        name: Param::Time,
        value: text.to_string(),
        reason: format!(
            "{reason}; an ISO-8601 time is YYYY-MM-DD[THH:MM[:SS[.fff]]][Z|+HH:MM] (UTC without \
             an offset)"
        ),
    };
    let mut p = Cursor(text.as_bytes());
    let year = p.digits(4).ok_or_else(|| bad("the year is not 4 digits"))?;
    let month = p
        .sep(b'-')
        .and_then(|_| p.digits(2))
        .ok_or_else(|| bad("the month is not 2 digits after '-'"))?;
    let day = p
        .sep(b'-')
        .and_then(|_| p.digits(2))
        .ok_or_else(|| bad("the day is not 2 digits after '-'"))?;
    let (year, month, day) = (year as i64, month as u32, day as u32);
    if !(1..=12).contains(&month) {
        return Err(bad(&format!("month {month:02} is not 01 to 12")));
    }
    if day < 1 || day > days_in_month(year, month) {
        return Err(bad(&format!("day {day:02} is not in {year:04}-{month:02}")));
    }
    let mut seconds = days_from_civil(year, month, day) * DAY;
    let (mut frac, mut frac_digits) = (0i128, 0u32);
    if !p.0.is_empty() {
        if !matches!(p.0[0], b'T' | b't' | b' ') {
            return Err(bad("the date is not followed by 'T' and a time"));
        }
        p.0 = &p.0[1..];
        let hour = p.digits(2).ok_or_else(|| bad("the hour is not 2 digits"))?;
        let minute = p
            .sep(b':')
            .and_then(|_| p.digits(2))
            .ok_or_else(|| bad("the minute is not 2 digits after ':'"))?;
        let second = if p.sep(b':').is_some() {
            p.digits(2)
                .ok_or_else(|| bad("the second is not 2 digits after ':'"))?
        } else {
            0
        };
        if hour > 23 || minute > 59 {
            return Err(bad(&format!("{hour:02}:{minute:02} is not a time of day")));
        }
        if second == 60 {
            return Err(bad("a leap second (:60) has no Unix time"));
        }
        if second > 59 {
            return Err(bad(&format!("second {second:02} is not 00 to 59")));
        }
        if matches!(p.0.first(), Some(b'.' | b',')) {
            p.0 = &p.0[1..];
            let n = p.0.iter().take_while(|b| b.is_ascii_digit()).count();
            if n == 0 {
                return Err(bad("no digits after the decimal point"));
            }
            for &b in &p.0[..n.min(18)] {
                frac = 10 * frac + i128::from(b - b'0');
            }
            frac_digits = n.min(18) as u32;
            p.0 = &p.0[n..];
        }
        seconds += (hour * 3600 + minute * 60 + second) as i64;
        match p.0.first() {
            None => {}
            Some(b'Z' | b'z') if p.0.len() == 1 => p.0 = &[],
            Some(&sign @ (b'+' | b'-')) => {
                p.0 = &p.0[1..];
                let oh = p
                    .digits(2)
                    .ok_or_else(|| bad("the offset's hours are not 2 digits"))?;
                let om = if p.0.is_empty() {
                    0
                } else {
                    let _ = p.sep(b':');
                    p.digits(2)
                        .ok_or_else(|| bad("the offset's minutes are not 2 digits"))?
                };
                if oh > 23 || om > 59 {
                    return Err(bad(&format!("the offset {oh:02}:{om:02} is out of range")));
                }
                let offset = (oh * 3600 + om * 60) as i64;
                // Local time = UTC + offset.
                seconds -= if sign == b'+' { offset } else { -offset };
            }
            Some(_) => return Err(bad("unexpected text after the time")),
        }
        if !p.0.is_empty() {
            return Err(bad("unexpected text after the offset"));
        }
    }
    let den = 10i64.pow(frac_digits);
    Ok(decimal_seconds(
        i128::from(seconds) * den as i128 + frac,
        den,
    ))
}

/// The unread rest of a text.
struct Cursor<'a>(&'a [u8]);

impl Cursor<'_> {
    /// Exactly `n` ASCII digits as a number.
    fn digits(&mut self, n: usize) -> Option<u64> {
        let d = self.0.get(..n)?;
        if !d.iter().all(u8::is_ascii_digit) {
            return None;
        }
        self.0 = &self.0[n..];
        Some(d.iter().fold(0, |acc, &b| 10 * acc + u64::from(b - b'0')))
    }

    /// The byte `c`.
    fn sep(&mut self, c: u8) -> Option<()> {
        (self.0.first() == Some(&c)).then(|| self.0 = &self.0[1..])
    }
}
