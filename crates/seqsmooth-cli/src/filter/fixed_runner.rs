//! The fixed-memory filter of `seqsmooth filter` on any timestamps: the sliding engine while
//! the times are evenly spaced, the irregular one from the first uneven step on (the same
//! least-squares fit). Kept apart so that it goes in one piece once the library has an
//! adaptive fixed-memory engine.

use seqsmooth::{Error, FixedEngine, FixedMemory, PolynomialFilter, PolynomialState};
use std::collections::VecDeque;

/// The fixed-memory filter of the command: least squares over the last `W` samples on any
/// timestamps.
///
/// The library's even-spacing engines reject a step that differs from the first; this runs
/// [`FixedEngine::Sliding`] (`O(m²)` per sample) while the times are evenly spaced, keeping the
/// newest `W` samples, and at the first uneven step replays them into a
/// [`FixedEngine::Irregular`] filter (a QR refit of the window per sample) that carries on: the
/// same least-squares fit either way, up to rounding.
#[derive(Clone, Debug)]
pub struct FixedRunner {
    filter: FixedMemory,
    degree: usize,
    window: usize,
    sigma: Option<f64>,
    /// The newest `window` samples while the sliding engine runs.
    recent: VecDeque<(f64, f64)>,
}

impl FixedRunner {
    /// A degree-`degree` filter over `window` samples, with noise `sigma` for the covariance.
    pub fn new(degree: usize, window: usize, sigma: Option<f64>) -> Result<Self, Error> {
        Ok(Self {
            filter: Self::make(degree, window, sigma, FixedEngine::Sliding)?,
            degree,
            window,
            sigma,
            recent: VecDeque::new(),
        })
    }

    fn make(
        degree: usize,
        window: usize,
        sigma: Option<f64>,
        engine: FixedEngine,
    ) -> Result<FixedMemory, Error> {
        let f = FixedMemory::new(degree, window, engine)?;
        match sigma {
            Some(s) => f.with_noise_sigma(s),
            None => Ok(f),
        }
    }

    /// The engine running now: sliding until the first uneven step, irregular from then on.
    pub fn engine(&self) -> FixedEngine {
        self.filter.engine()
    }

    /// Processes one sample.
    pub fn update(&mut self, t: f64, y: f64) -> Result<(), Error> {
        if self.filter.engine() != FixedEngine::Irregular {
            if self.filter.update(t, y).is_ok() {
                self.recent.push_back((t, y));
                if self.recent.len() > self.window {
                    self.recent.pop_front();
                }
                return Ok(());
            }
            // The first uneven step (the input is already checked to be finite and
            // increasing): the same fit on the irregular engine, from the newest samples.
            let mut f = Self::make(self.degree, self.window, self.sigma, FixedEngine::Irregular)?;
            for &(t, y) in &self.recent {
                f.update(t, y)?;
            }
            self.filter = f;
            self.recent = VecDeque::new();
        }
        self.filter.update(t, y)
    }
}

impl PolynomialFilter for FixedRunner {
    fn degree(&self) -> usize {
        self.degree
    }
    fn samples(&self) -> u64 {
        self.filter.samples()
    }
    fn update(&mut self, t: f64, y: f64) -> Result<(), Error> {
        FixedRunner::update(self, t, y)
    }
    fn estimate_at(&self, t: f64) -> Option<PolynomialState> {
        self.filter.estimate_at(t)
    }
    fn last_time(&self) -> Option<f64> {
        self.filter.last_time()
    }
}
