//! Banks of many independent polynomial filters sharing one configuration, for evenly spaced
//! samples (Reyneke et al.: 10 000 filters integrating an image sensor): [`FadingBank`] and
//! [`ExpandingBank`], fed one time step of all channels at a time ([`FadingBank::update`]) or a
//! `(time × K)` matrix ([`FadingBank::update_rows`]). Channels with their own timestamps go in
//! a [`StreamBank`] (any [`PolynomialFilter`](super::PolynomialFilter) per channel, batches per channel, channels in
//! parallel).
//!
//! Every channel runs the gain recursion of Morrison Table 9.1 / 13.1 on its own data:
//!
//! `Z ← Φ(1) Z` (predict), `ε = y − z₀`, `Z ← Z + H ε` (correct),
//!
//! with `Z` Morrison's scaled state (`z_k = τ^k x^(k)/k!`, unit step) and the gains `H`
//! shared by all channels: the expanding-memory gains `h_k(n)`
//! ([`ExpandingGainSchedule`], Table 9.1) for the sample index `n`, and for a
//! [`FadingBank`] from the switch index `n₀ = SwitchRule::Position.switch_index(m, θ)` on the
//! constant fading gains ([`fading_gains`], Table 13.1) — the fading gain filter is not
//! self-starting (Morrison §13.8). Since all channels share `n`, the gains are scalars per step.
//!
//! ## Layout and vectorisation
//!
//! The state is structure-of-arrays: one contiguous `Vec<f64>` of length `K` per derivative
//! order. An update walks the channels in blocks of [`BLOCK`] (so the block's `m+2` rows stay in
//! L1 and each row is read and written once from memory per step); inside a block every
//! operation is a loop over equal-length slices (`zip`, no indexing), which LLVM vectorises:
//! the release assembly (`cargo rustc --release -p seqsmooth -- --emit asm`) of the block kernel
//! contains packed `addpd`/`mulpd`/`subpd` on `xmm` registers (SSE2, the default x86-64
//! target), with scalar code only for the remainders (throughput: see BENCHMARKS.md). No
//! fused multiply-add is used, so results do not depend on the target features
//! ([`crate::numeric::double_word`]). The `_par` updates split the channels into blocks of
//! [`PAR_CHUNK`] over rayon; every channel sees exactly the same operations, so they equal the
//! serial updates bit for bit.
//!
//! ## Numerics
//!
//! The bank runs in plain `f64` from a zero state (the expanding-memory recursion reaches the
//! interpolating polynomial at `n = m` from any initial state, Morrison §9.6), unlike the
//! single-stream gain engine, which starts exactly and carries a compensated state. Its
//! agreement with the single-stream `FadingMemory` and `ExpandingMemory` gain engines is
//! asserted in `tests/bank.rs`, printed by `cargo run --release -p seqsmooth --example accuracy_bank` (ACCURACY.md).

use super::expanding::gains::ExpandingGainSchedule;
use super::fading::gains::fading_gains;
use super::fading::switch::SwitchRule;
use super::form::GainForm;
use super::options::{check_engine_degree, check_tau, check_theta, Engine};
use crate::error::{Error, Param};
use crate::model::{derivative_scale, for_each_shift_step};
use rayon::prelude::*;

/// Channels per inner block of an update: the block's rows (`m+1` state rows, input, residual)
/// stay in L1 cache.
pub const BLOCK: usize = 256;

/// Channels per rayon task in the parallel updates (a multiple of [`BLOCK`]).
pub const PAR_CHUNK: usize = 64 * BLOCK;

/// The channels' states of a bank, structure-of-arrays, and the shared sample count and gain
/// schedule.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
struct BankState {
    m: usize,
    tau: f64,
    channels: usize,
    n: u64,
    /// `z[k][c]`: scaled derivative `k` of channel `c`.
    z: Vec<Vec<f64>>,
    schedule: ExpandingGainSchedule,
    gains: Vec<f64>,
}

impl BankState {
    fn new(m: usize, tau: f64, channels: usize) -> Result<Self, Error> {
        check_engine_degree(m, Engine::Gain)?;
        check_tau(tau)?;
        if channels == 0 {
            return Err(Error::InvalidParameter {
                name: Param::Channels,
                value: "0".into(),
                reason: "a bank needs at least one channel".into(),
            });
        }
        Ok(Self {
            m,
            tau,
            channels,
            n: 0,
            z: vec![vec![0.0; channels]; m + 1],
            schedule: ExpandingGainSchedule::new(m),
            gains: vec![0.0; m + 1],
        })
    }

    /// Checks the input; on error the state is untouched.
    fn check(&self, y: &[f64]) -> Result<(), Error> {
        if y.len() != self.channels {
            return Err(Error::InvalidParameter {
                name: Param::InputLength,
                value: y.len().to_string(),
                reason: format!("the bank has {} channels", self.channels),
            });
        }
        if let Some((c, v)) = y.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(Error::InvalidParameter {
                name: Param::InputValue,
                value: v.to_string(),
                reason: format!("channel {c}: samples must be finite"),
            });
        }
        Ok(())
    }

    fn update(
        &mut self,
        y: &[f64],
        fading: Option<(u64, &[f64])>,
        parallel: bool,
    ) -> Result<(), Error> {
        self.check(y)?;
        match fading {
            Some((n0, h)) if self.n >= n0 => self.gains.copy_from_slice(h),
            _ => self.schedule.gains(self.n, &mut self.gains),
        }
        let h = &self.gains;
        if parallel {
            let groups = self.channels.div_ceil(PAR_CHUNK);
            let mut rows: Vec<Vec<&mut [f64]>> = (0..groups)
                .map(|_| Vec::with_capacity(self.m + 1))
                .collect();
            for row in self.z.iter_mut() {
                for (g, chunk) in rows.iter_mut().zip(row.chunks_mut(PAR_CHUNK)) {
                    g.push(chunk);
                }
            }
            rows.into_par_iter()
                .zip(y.par_chunks(PAR_CHUNK))
                .for_each(|(mut z, y)| kernel(&mut z, y, h));
        } else {
            let mut z: Vec<&mut [f64]> = self.z.iter_mut().map(|r| r.as_mut_slice()).collect();
            kernel(&mut z, y, h);
        }
        self.n += 1;
        Ok(())
    }

    fn derivatives_scale(&self) -> Vec<f64> {
        derivative_scale(self.tau).take(self.m + 1).collect()
    }

    fn estimate(&self, channel: usize) -> Option<Vec<f64>> {
        if self.n <= self.m as u64 || channel >= self.channels {
            return None;
        }
        Some(
            self.derivatives_scale()
                .iter()
                .zip(&self.z)
                .map(|(s, row)| s * row[channel])
                .collect(),
        )
    }

    fn derivative_into(&self, k: usize, out: &mut [f64]) -> Result<(), Error> {
        if k > self.m {
            return Err(Error::InvalidParameter {
                name: Param::DerivativeOrder,
                value: k.to_string(),
                reason: format!("must be at most the degree {}", self.m),
            });
        }
        if out.len() != self.channels {
            return Err(Error::InvalidParameter {
                name: Param::OutputLength,
                value: out.len().to_string(),
                reason: format!("the bank has {} channels", self.channels),
            });
        }
        if self.n <= self.m as u64 {
            return Err(Error::TooFewSamples {
                needed: self.m + 1,
                got: self.n as usize,
            });
        }
        let s = self.derivatives_scale()[k];
        for (o, z) in out.iter_mut().zip(&self.z[k]) {
            *o = s * z;
        }
        Ok(())
    }
}

/// One step of the recursion for a set of channels: `z[k]` are equal-length rows, `y` the
/// inputs, `h` the gains. Elementwise over channels, block by block.
fn kernel(z: &mut [&mut [f64]], y: &[f64], h: &[f64]) {
    let m = z.len() - 1;
    let len = y.len();
    let mut e = [0.0f64; BLOCK];
    let mut start = 0;
    while start < len {
        let end = (start + BLOCK).min(len);
        let e = &mut e[..end - start];
        // Predict Z ← Φ(1) Z: the Taylor shift by one step, row by row.
        for_each_shift_step(m + 1, |j| {
            let (lo, hi) = z.split_at_mut(j + 1);
            for (a, b) in lo[j][start..end].iter_mut().zip(&hi[0][start..end]) {
                *a += *b;
            }
        });
        // ε = y − z₀.
        for ((e, y), z0) in e.iter_mut().zip(&y[start..end]).zip(&z[0][start..end]) {
            *e = y - z0;
        }
        // Z ← Z + H ε.
        for (row, &hk) in z.iter_mut().zip(h) {
            for (a, e) in row[start..end].iter_mut().zip(e.iter()) {
                *a += hk * e;
            }
        }
        start = end;
    }
}

macro_rules! bank_accessors {
    ($ty:ident, $new:literal) => {
        impl $ty {
            /// Degree `m`.
            pub fn degree(&self) -> usize {
                self.core.m
            }

            /// Number of channels `K`.
            pub fn channels(&self) -> usize {
                self.core.channels
            }

            /// Number of time steps processed.
            pub fn samples(&self) -> u64 {
                self.core.n
            }

            /// The sampling interval `τ`.
            pub fn tau(&self) -> f64 {
                self.core.tau
            }

            /// Channel `channel`'s current estimate as unscaled derivatives `X = D(τ) Z`,
            /// `x^(k) = k! z_k / τ^k` (Morrison (4.2.9)); `None` before `m+1` samples or for a
            /// channel out of range.
            pub fn estimate(&self, channel: usize) -> Option<Vec<f64>> {
                self.core.estimate(channel)
            }

            /// Writes derivative `k` (unscaled) of every channel into `out` (`out.len() == K`).
            pub fn derivative_into(&self, k: usize, out: &mut [f64]) -> Result<(), Error> {
                self.core.derivative_into(k, out)
            }

            /// The scaled state row `z_k` of all channels (`z_k = τ^k x^(k)/k!`).
            pub fn scaled_row(&self, k: usize) -> Option<&[f64]> {
                self.core.z.get(k).map(|r| r.as_slice())
            }

            /// Several time steps at once from a `(time × K)` matrix in row-major order
            /// (`matrix.len()` a multiple of `K`; row `i` is time step `i`), each row as
            /// [`update`](Self::update) (serial) would. On a bad row the rows before it are
            /// processed and the error is [`Error::InBatch`] with the row's index.
            ///
            /// ```
            #[doc = concat!("use seqsmooth::polynomial::bank::", stringify!($ty), ";")]
            #[doc = concat!("let mut bank = ", $new, "?;")]
            /// // two channels, three time steps: y = t and y = 10 - 2t
            /// bank.update_rows(&[0.0, 10.0, 1.0, 8.0, 2.0, 6.0])?;
            /// let x = bank.estimate(1).unwrap();
            /// assert!((x[0] - 6.0).abs() < 1e-12 && (x[1] + 2.0).abs() < 1e-12);
            /// assert!(bank.update_rows(&[1.0, 2.0, 3.0]).is_err()); // not whole rows
            /// # Ok::<(), seqsmooth::Error>(())
            /// ```
            pub fn update_rows(&mut self, matrix: &[f64]) -> Result<(), Error> {
                self.rows(matrix, false)
            }

            /// [`update_rows`](Self::update_rows) with each row as
            /// [`update_par`](Self::update_par): bit-for-bit equal to the serial form.
            ///
            /// ```
            #[doc = concat!("use seqsmooth::polynomial::bank::", stringify!($ty), ";")]
            #[doc = concat!("let mut a = ", $new, "?;")]
            /// let mut b = a.clone();
            /// let m = [0.0, 10.0, 1.0, 8.0, 2.0, 6.0];
            /// a.update_rows(&m)?;
            /// b.update_rows_par(&m)?;
            /// assert_eq!(a.scaled_row(1), b.scaled_row(1));
            /// # Ok::<(), seqsmooth::Error>(())
            /// ```
            pub fn update_rows_par(&mut self, matrix: &[f64]) -> Result<(), Error> {
                self.rows(matrix, true)
            }

            fn rows(&mut self, matrix: &[f64], parallel: bool) -> Result<(), Error> {
                let k = self.core.channels;
                if matrix.len() % k != 0 {
                    return Err(Error::InvalidParameter {
                        name: Param::MatrixLength,
                        value: matrix.len().to_string(),
                        reason: format!("not a whole number of rows of {k} channels"),
                    });
                }
                for (index, row) in matrix.chunks_exact(k).enumerate() {
                    self.step(row, parallel).map_err(|e| Error::InBatch {
                        index,
                        source: Box::new(e),
                    })?;
                }
                Ok(())
            }
        }
    };
}

/// `K` independent fading-memory polynomial filters of degree `m`, discount `θ` per sample, on
/// evenly spaced samples with step `τ` (Morrison Table 13.1, started by the expanding-memory
/// gains of Table 9.1 until `n₀ = SwitchRule::Position.switch_index(m, θ)`, §13.8). See the
/// [module docs](self).
///
/// ```
/// use seqsmooth::polynomial::bank::FadingBank;
/// let mut bank = FadingBank::new(1, 0.9, 0.5, 3).unwrap();
/// for n in 0..200 {
///     let t = 0.5 * n as f64;
///     bank.update(&[1.0 + t, 2.0 * t, -t]).unwrap();
/// }
/// let x = bank.estimate(1).unwrap(); // channel 1: y = 2t
/// assert!((x[0] - 199.0).abs() < 1e-9 && (x[1] - 2.0).abs() < 1e-9);
/// let mut slopes = vec![0.0; 3];
/// bank.derivative_into(1, &mut slopes).unwrap();
/// assert!((slopes[2] + 1.0).abs() < 1e-9);
/// ```
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct FadingBank {
    core: BankState,
    theta: f64,
    switch_at: u64,
    fading: Vec<f64>,
}

impl FadingBank {
    /// A bank of `channels` filters of degree `m`, discount `θ ∈ (0,1)` per step `τ > 0`.
    pub fn new(m: usize, theta: f64, tau: f64, channels: usize) -> Result<Self, Error> {
        check_theta(theta)?;
        let core = BankState::new(m, tau, channels)?;
        Ok(Self {
            core,
            theta,
            switch_at: SwitchRule::Position.switch_index(m, theta)?,
            fading: fading_gains(m, theta, GainForm::Current),
        })
    }

    /// `θ`.
    pub fn theta(&self) -> f64 {
        self.theta
    }

    /// The 0-based sample index from which the constant fading gains are used.
    pub fn switch_index(&self) -> u64 {
        self.switch_at
    }

    /// One time step of every channel: `y[c]` is channel `c`'s sample. A wrong length or a
    /// non-finite value is an [`Error`] naming it, and leaves the bank unchanged.
    ///
    /// ```
    /// use seqsmooth::polynomial::bank::FadingBank;
    /// let mut bank = FadingBank::new(0, 0.5, 1.0, 2).unwrap();
    /// assert!(bank.update(&[1.0]).is_err());
    /// assert!(bank.update(&[1.0, f64::NAN]).is_err());
    /// bank.update(&[1.0, 2.0]).unwrap();
    /// assert_eq!(bank.samples(), 1);
    /// ```
    pub fn update(&mut self, y: &[f64]) -> Result<(), Error> {
        self.step(y, false)
    }

    fn step(&mut self, y: &[f64], parallel: bool) -> Result<(), Error> {
        self.core
            .update(y, Some((self.switch_at, &self.fading)), parallel)
    }

    /// [`update`](Self::update) with the channels split into blocks of [`PAR_CHUNK`] on the
    /// rayon pool; bit-for-bit equal to the serial update. Worth it for large `K` (≳ 10⁵).
    ///
    /// ```
    /// use seqsmooth::polynomial::bank::FadingBank;
    /// let mut a = FadingBank::new(2, 0.9, 1.0, 100_000).unwrap();
    /// let mut b = a.clone();
    /// let y: Vec<f64> = (0..100_000).map(|c| c as f64).collect();
    /// a.update(&y).unwrap();
    /// b.update_par(&y).unwrap();
    /// assert_eq!(a.scaled_row(0), b.scaled_row(0));
    /// ```
    pub fn update_par(&mut self, y: &[f64]) -> Result<(), Error> {
        self.step(y, true)
    }
}

bank_accessors!(FadingBank, "FadingBank::new(1, 0.5, 1.0, 2)");

/// `K` independent expanding-memory polynomial filters of degree `m` on evenly spaced samples
/// with step `τ`: the gains `h_k(n)` of Morrison Table 9.1 ([`ExpandingGainSchedule`]), the
/// least-squares fit over all samples so far, self-starting (§9.6).
///
/// ```
/// use seqsmooth::polynomial::bank::ExpandingBank;
/// let mut bank = ExpandingBank::new(1, 1.0, 1).unwrap();
/// for y in [1.0, 3.0, 2.0, 5.0, 4.0] {
///     bank.update(&[y]).unwrap();
/// }
/// let x = bank.estimate(0).unwrap(); // Morrison T9-02: (23/5, 4/5)
/// assert!((x[0] - 4.6).abs() < 1e-12 && (x[1] - 0.8).abs() < 1e-12);
/// ```
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct ExpandingBank {
    core: BankState,
}

impl ExpandingBank {
    /// A bank of `channels` filters of degree `m`, step `τ > 0`.
    pub fn new(m: usize, tau: f64, channels: usize) -> Result<Self, Error> {
        Ok(Self {
            core: BankState::new(m, tau, channels)?,
        })
    }

    /// One time step of every channel (see [`FadingBank::update`]).
    ///
    /// ```
    /// use seqsmooth::polynomial::bank::ExpandingBank;
    /// let mut bank = ExpandingBank::new(0, 1.0, 2).unwrap();
    /// bank.update(&[1.0, 3.0]).unwrap();
    /// bank.update(&[3.0, 5.0]).unwrap();
    /// assert_eq!(bank.estimate(1).unwrap(), vec![4.0]);
    /// ```
    pub fn update(&mut self, y: &[f64]) -> Result<(), Error> {
        self.step(y, false)
    }

    fn step(&mut self, y: &[f64], parallel: bool) -> Result<(), Error> {
        self.core.update(y, None, parallel)
    }

    /// The parallel update (see [`FadingBank::update_par`]).
    ///
    /// ```
    /// use seqsmooth::polynomial::bank::ExpandingBank;
    /// let mut bank = ExpandingBank::new(0, 1.0, 2).unwrap();
    /// bank.update_par(&[1.0, 3.0]).unwrap();
    /// assert_eq!(bank.estimate(0).unwrap(), vec![1.0]);
    /// ```
    pub fn update_par(&mut self, y: &[f64]) -> Result<(), Error> {
        self.step(y, true)
    }
}

bank_accessors!(ExpandingBank, "ExpandingBank::new(1, 1.0, 2)");

pub use super::stream::StreamBank;

impl BankState {
    /// A restored bank's invariants ([`crate::persist`]): degree in range, `m + 1` rows of
    /// `channels` values, the gains `m + 1`.
    fn check_saved(&self) -> Result<(), String> {
        check_engine_degree(self.m, Engine::Gain).map_err(|e| e.to_string())?;
        let rows_ok = self.z.len() == self.m + 1 && self.z.iter().all(|r| r.len() == self.channels);
        if !rows_ok || self.gains.len() != self.m + 1 || self.schedule.degree() != self.m {
            return Err(format!(
                "state is not {} rows of {} channels",
                self.m + 1,
                self.channels
            ));
        }
        Ok(())
    }
}

impl FadingBank {
    /// A restored bank's invariants ([`crate::persist`]).
    pub(crate) fn check_saved(&self) -> Result<(), String> {
        self.core.check_saved()?;
        if self.fading.len() != self.core.m + 1 || !(self.theta > 0.0 && self.theta < 1.0) {
            return Err("fading gains or θ out of range".into());
        }
        Ok(())
    }
}

impl ExpandingBank {
    /// A restored bank's invariants ([`crate::persist`]).
    pub(crate) fn check_saved(&self) -> Result<(), String> {
        self.core.check_saved()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::polynomial::engine::recursion::predict_correct;

    /// The structure-of-arrays kernel is the reference recursion per channel, bit for bit
    /// (the same operations in the same order), across block boundaries, degrees 0 … 8.
    #[test]
    fn kernel_is_the_reference_per_channel() {
        let channels = BLOCK + 3;
        for m in 0..=8usize {
            let h: Vec<f64> = (0..=m).map(|k| 0.7 / (k as f64 + 1.3)).collect();
            let mut rows: Vec<Vec<f64>> = (0..=m)
                .map(|k| {
                    (0..channels)
                        .map(|c| ((c * 31 + k * 7) % 17) as f64 * 0.1)
                        .collect()
                })
                .collect();
            let mut want: Vec<Vec<f64>> = (0..channels)
                .map(|c| (0..=m).map(|k| rows[k][c]).collect())
                .collect();
            for step in 0..5 {
                let y: Vec<f64> = (0..channels)
                    .map(|c| (c as f64 * 0.37 + step as f64).sin())
                    .collect();
                let mut z: Vec<&mut [f64]> = rows.iter_mut().map(|r| r.as_mut_slice()).collect();
                kernel(&mut z, &y, &h);
                for (zc, &yc) in want.iter_mut().zip(&y) {
                    predict_correct(zc, 1.0, &h, yc);
                }
            }
            for (c, zc) in want.iter().enumerate() {
                for k in 0..=m {
                    assert_eq!(
                        rows[k][c].to_bits(),
                        zc[k].to_bits(),
                        "m {m} channel {c} k {k}"
                    );
                }
            }
        }
    }
}
