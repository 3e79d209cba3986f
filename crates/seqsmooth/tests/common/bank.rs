//! Deterministic multi-channel data for the bank tests.

/// Deterministic data for channel `c` at step `n`: a slow sine of channel-dependent phase and
/// size, a trend, and a cheap pseudo-random term of unit size.
pub fn sample(c: usize, n: usize) -> f64 {
    let mut s = (c as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (n as u64).wrapping_mul(0xD1B5_4A32_D192_ED03);
    s ^= s >> 29;
    s = s.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    s ^= s >> 32;
    let noise = (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
    let t = n as f64;
    (1.0 + c as f64 % 5.0) * (0.01 * t + c as f64).sin() + 0.001 * t + noise
}
