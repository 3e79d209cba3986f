//! Axis scales whose tick labels stay short and distinct at any magnitude.
//!
//! An axis over `1.7e18 … 1.7e18 + 1e9` (epoch nanoseconds) or `0 … 3e-9` (a small rate) has
//! no short decimal tick labels: they differ only in their last of nineteen digits, or all read
//! `0.00000000`. A [`Scale`] draws such an axis in tick units, `tick = (v − offset) / 10^e`:
//! the offset takes out the digits every value shares, the power of ten (a multiple of 3) the
//! magnitude, and the axis label says how to read the ticks back ([`Scale::note`]), as
//! `value = tick × 1e9 + 1.7e18` or, for a time axis measured from its first time `t₀`,
//! `t = t₀ + tick × 1e9` with `t₀` in full and, when `t₀` reads as a Unix time, its UTC date.

/// Values at least this many times the axis span get an offset (4 shared leading digits).
const OFFSET_RATIO: f64 = 1e4;
/// Tick magnitudes from this on are written with a power of ten.
const LARGE: f64 = 1e6;
/// Tick magnitudes below this are written with a power of ten.
const SMALL: f64 = 1e-2;

/// How an axis is drawn: `tick = (v − offset) / 10^exponent`.
#[derive(Clone, Debug, PartialEq)]
pub struct Scale {
    /// Subtracted from every value (0 for none).
    pub offset: f64,
    /// The power of ten the ticks are in (a multiple of 3; 0 for none).
    pub exponent: i32,
    /// Whether `offset` is the axis's first time `t₀` (a time axis) rather than a round number.
    pub origin: bool,
}

impl Scale {
    /// The identity: ticks are the values.
    pub const PLAIN: Scale = Scale {
        offset: 0.0,
        exponent: 0,
        origin: false,
    };

    /// The scale of an axis over `lo..hi`. With `origin = Some(t₀)` (a time axis) an offset
    /// is `t₀`, otherwise the round number nearest the middle, to the digit above the span's.
    ///
    /// ```
    /// use seqsmooth_cli::plot::ticks::Scale;
    /// let s = Scale::for_range(1.7e18, 1.7e18 + 1e9, None);
    /// assert_eq!((s.offset, s.exponent), (1.7e18, 9));
    /// assert_eq!(s.note("value"), "value = tick × 1e9 + 1.7e18");
    /// assert_eq!(Scale::for_range(-3.0, 250.0, None), Scale::PLAIN);
    /// ```
    pub fn for_range(lo: f64, hi: f64, origin: Option<f64>) -> Scale {
        let span = hi - lo;
        if !(lo.is_finite() && hi.is_finite() && span > 0.0 && span.is_finite()) {
            return Scale::PLAIN;
        }
        let far = lo.abs().max(hi.abs()) >= OFFSET_RATIO * span;
        let offset = match (far, origin) {
            (false, _) => 0.0,
            (true, Some(t0)) => t0,
            (true, None) => {
                let unit = 10f64.powi(span.log10().ceil() as i32 + 1);
                ((0.5 * lo + 0.5 * hi) / unit).round() * unit
            }
        };
        let reach = (lo - offset).abs().max((hi - offset).abs());
        let exponent = if (LARGE..f64::INFINITY).contains(&reach) || (reach > 0.0 && reach < SMALL)
        {
            3 * (reach.log10() / 3.0).floor() as i32
        } else {
            0
        };
        Scale {
            offset,
            exponent,
            origin: far && origin.is_some(),
        }
    }

    /// `v` in tick units.
    pub fn to_axis(&self, v: f64) -> f64 {
        (v - self.offset) / 10f64.powi(self.exponent)
    }

    /// How to read a tick back as the value `name`; empty for the identity.
    ///
    /// ```
    /// use seqsmooth_cli::plot::ticks::Scale;
    /// let s = Scale::for_range(0.0, 3e-9, None);
    /// assert_eq!(s.note("value"), "value = tick × 1e-9");
    /// assert!((s.to_axis(2e-9) - 2.0).abs() < 1e-12);
    /// ```
    pub fn note(&self, name: &str) -> String {
        let power = format!("1e{}", self.exponent);
        let times = if self.exponent == 0 {
            "tick".to_string()
        } else {
            format!("tick × {power}")
        };
        match (self.offset != 0.0, self.origin) {
            (false, _) if self.exponent == 0 => String::new(),
            (false, _) => format!("{name} = {times}"),
            (true, true) => {
                let t0 = crate::io::fmt_f64(self.offset);
                let date = unix_date(self.offset).map_or_else(String::new, |(unit, date)| {
                    format!(" (as Unix {unit}: {date})")
                });
                format!("{name} = t₀ + {times}, t₀ = {t0}{date}")
            }
            (true, false) => {
                let sign = if self.offset < 0.0 { '−' } else { '+' };
                format!("{name} = {times} {sign} {}", short(self.offset.abs()))
            }
        }
    }
}

/// Tick label text with the decimals the axis step needs (`-0` written `0`).
///
/// ```
/// use seqsmooth_cli::plot::ticks::tick;
/// assert_eq!(tick(0.25, 0.05), "0.25");
/// assert_eq!(tick(-0.0001, 0.5), "0.0");
/// ```
pub fn tick(v: f64, step: f64) -> String {
    let decimals = if step > 0.0 && step.is_finite() {
        (-(step.log10().floor()) as i32).clamp(0, 8) as usize
    } else {
        2
    };
    let s = format!("{v:.decimals$}");
    // "-0" and "-0.0" read as noise
    let unsigned = s.trim_start_matches('-');
    if unsigned.chars().all(|c| c == '0' || c == '.') {
        unsigned.to_string()
    } else {
        s
    }
}

/// A round offset, shortest: digits up to 8 characters, else with an exponent (`1.7e18`).
fn short(x: f64) -> String {
    let plain = crate::io::fmt_f64(x);
    if plain.len() <= 8 {
        plain
    } else {
        format!("{x:e}")
    }
}

/// `t` read as a Unix time in seconds, milliseconds, microseconds or nanoseconds — whichever
/// puts it between 1980 and 2100 — and its UTC date and time (to the second).
///
/// ```
/// use seqsmooth_cli::plot::ticks::unix_date;
/// let (unit, date) = unix_date(1.7e12).unwrap();
/// assert_eq!((unit, date.as_str()), ("ms", "2023-11-14 22:13:20 UTC"));
/// assert_eq!(unix_date(42.0), None);
/// ```
pub fn unix_date(t: f64) -> Option<(&'static str, String)> {
    // 1980-01-01 and 2100-01-01 in Unix seconds.
    const SPAN: (f64, f64) = (315_532_800.0, 4_102_444_800.0);
    let units = [("s", 1.0), ("ms", 1e3), ("µs", 1e6), ("ns", 1e9)];
    let (unit, secs) = units
        .into_iter()
        .map(|(u, per)| (u, t / per))
        .find(|(_, s)| (SPAN.0..SPAN.1).contains(s))?;
    let secs = secs.floor() as i64;
    let (days, rem) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    let (y, m, d) = civil_from_days(days);
    let (h, min, s) = (rem / 3600, rem / 60 % 60, rem % 60);
    Some((
        unit,
        format!("{y:04}-{m:02}-{d:02} {h:02}:{min:02}:{s:02} UTC"),
    ))
}

/// The proleptic Gregorian date of the day `z` days after 1970-01-01 (Hinnant's
/// `civil_from_days`).
fn civil_from_days(z: i64) -> (i64, i64, i64) {
    let z = z + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    (y, m, d)
}
