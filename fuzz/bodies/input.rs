//! Decoding a fuzz input's bytes into parameters: every byte string decodes to something
//! (missing bytes read as zero), so the fuzzer's mutations map to nearby parameters.

/// Numbers that sit on the edges the filters must survive: zero, the denormals, the limits of
/// `f64`, the scales the CLI meets (epoch seconds and nanoseconds), `±1`.
pub const SPECIAL: [f64; 24] = [
    0.0,
    1.0,
    0.5,
    0.1,
    0.9,
    0.99,
    1e-3,
    1e3,
    1.7e9,
    1.7e12,
    1.7e18,
    1e155,
    1e-155,
    1e-200,
    1e300,
    1e-300,
    1e308,
    f64::MAX,
    f64::MIN_POSITIVE,
    5e-324,
    // The largest subnormal.
    2.225073858507201e-308,
    f64::EPSILON,
    1.0 - f64::EPSILON / 2.0,
    9007199254740993.0,
];

/// A cursor over the fuzzer's bytes.
pub struct Input<'a> {
    data: &'a [u8],
    pos: usize,
}

impl<'a> Input<'a> {
    pub fn new(data: &'a [u8]) -> Self {
        Self { data, pos: 0 }
    }

    /// Whether every byte has been read.
    pub fn is_empty(&self) -> bool {
        self.pos >= self.data.len()
    }

    /// The bytes not read yet (all of them are consumed).
    pub fn rest(&mut self) -> &'a [u8] {
        let rest = &self.data[self.pos.min(self.data.len())..];
        self.pos = self.data.len();
        rest
    }

    /// The next `n` bytes (fewer at the end).
    pub fn take(&mut self, n: usize) -> &'a [u8] {
        let start = self.pos.min(self.data.len());
        let end = (start + n).min(self.data.len());
        self.pos = end;
        &self.data[start..end]
    }

    pub fn byte(&mut self) -> u8 {
        self.take(1).first().copied().unwrap_or(0)
    }

    pub fn u16(&mut self) -> u16 {
        u16::from(self.byte()) | u16::from(self.byte()) << 8
    }

    pub fn u64(&mut self) -> u64 {
        let mut b = [0u8; 8];
        let bytes = self.take(8);
        b[..bytes.len()].copy_from_slice(bytes);
        u64::from_le_bytes(b)
    }

    /// A number in `0..n` (`n <= 65536`).
    pub fn below(&mut self, n: usize) -> usize {
        if n <= 256 {
            usize::from(self.byte()) % n
        } else {
            usize::from(self.u16()) % n
        }
    }

    pub fn flag(&mut self) -> bool {
        self.byte() & 1 == 1
    }

    /// Any `f64`, NaN and infinities included (1 in 16 raw bits).
    pub fn any_number(&mut self) -> f64 {
        match self.byte() % 16 {
            0 => f64::from_bits(self.u64()),
            1 => f64::NAN,
            2 => f64::INFINITY,
            3 => f64::NEG_INFINITY,
            _ => self.number(),
        }
    }

    /// A finite `f64`: a small integer, a fraction, a [`SPECIAL`] value with its sign and a
    /// small factor, a mantissa times a power of ten anywhere in range, or raw finite bits.
    pub fn number(&mut self) -> f64 {
        let mode = self.byte();
        let sign = if mode & 0x80 != 0 { -1.0 } else { 1.0 };
        let x = match mode % 6 {
            0 => f64::from(self.byte() as i8),
            1 => f64::from(self.u16() as i16) / 64.0,
            2 => SPECIAL[self.below(SPECIAL.len())] * f64::from(1 + self.byte() % 4),
            3 => {
                let mantissa = f64::from(self.u16()) / 65536.0 + 1.0;
                let exp = i32::from(self.u16() % 633) - 324;
                mantissa * 10f64.powi(exp)
            }
            4 => {
                let x = f64::from_bits(self.u64());
                if x.is_finite() {
                    x
                } else {
                    0.0
                }
            }
            _ => SPECIAL[self.below(SPECIAL.len())],
        };
        let x = sign * x;
        if x.is_finite() {
            x
        } else {
            f64::MAX.copysign(x)
        }
    }

    /// A positive finite `f64` (the magnitude of [`number`](Self::number), `1` for zero).
    pub fn positive(&mut self) -> f64 {
        match self.number().abs() {
            0.0 => 1.0,
            x => x,
        }
    }

    /// `n` sample times: evenly spaced, jittered, each step its own, or arbitrary numbers
    /// (not increasing, not finite: for the errors).
    pub fn times(&mut self, n: usize) -> Vec<f64> {
        let mode = self.byte() % 8;
        let mut t = self.number();
        let step = self.positive();
        let mut times = Vec::with_capacity(n);
        for i in 0..n {
            times.push(t);
            t = match mode {
                0..=2 => t + step,
                3 => t + step * (1.0 + f64::from(self.byte() as i8) * 1e-3),
                4 | 5 => t + self.positive(),
                6 => self.any_number(),
                _ => times[0] + step * (i + 1) as f64,
            };
        }
        times
    }

    /// `n` sample values at `times`: a polynomial with a little noise, arbitrary finite
    /// numbers, or (rarely) any numbers.
    pub fn values(&mut self, times: &[f64]) -> Vec<f64> {
        let mode = self.byte() % 8;
        let coefficients: Vec<f64> = (0..3).map(|_| self.number()).collect();
        times
            .iter()
            .map(|&t| match mode {
                0..=3 => {
                    let dt = t - times[0];
                    let c = &coefficients;
                    c[0] + dt * (c[1] + dt * c[2]) + f64::from(self.byte() as i8) * 1e-3
                }
                4..=6 => self.number(),
                _ => self.any_number(),
            })
            .collect()
    }

    /// A short text: UTF-8 (lossy) of up to `max` bytes.
    pub fn text(&mut self, max: usize) -> String {
        let n = self.below(max + 1);
        String::from_utf8_lossy(self.take(n)).into_owned()
    }
}
