//! Data shared by the benches.

/// Deterministic data: a slow sine plus a cheap pseudo-random term.
pub fn data(len: usize) -> Vec<f64> {
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    (0..len)
        .map(|n| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let noise = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            10.0 * (n as f64 * 1e-3).sin() + noise
        })
        .collect()
}
