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

#[cfg(test)]
mod tests {
    use super::*;

    /// The fixed-memory runner falls back from the sliding engine to the irregular one at the
    /// first uneven step, and its estimates are the irregular engine's from the start (up to
    /// rounding) on both sides of the switch.
    #[test]
    fn fixed_runner_switches_engine_at_first_uneven_step() {
        let mut runner = FixedRunner::new(2, 6, Some(0.5)).unwrap();
        let mut reference = FixedMemory::new(2, 6, FixedEngine::Irregular)
            .unwrap()
            .with_noise_sigma(0.5)
            .unwrap();
        let mut t = 0.0;
        for k in 0..40 {
            t += if k < 15 {
                0.25
            } else {
                0.25 + 0.1 * ((k % 3) as f64)
            };
            let y = (0.7 * t).sin() + 0.1 * ((k * 7 % 5) as f64);
            runner.update(t, y).unwrap();
            reference.update(t, y).unwrap();
            let engine = runner.filter.engine();
            assert_eq!(engine == FixedEngine::Irregular, k >= 16, "k = {k}");
            assert_eq!((runner.samples() as usize).min(6), (k + 1).min(6));
            for lead in [0.0, 0.3, -0.6] {
                match (
                    runner.estimate_at(t + lead),
                    reference.estimate_at(t + lead),
                ) {
                    (None, None) => assert!(k < 5),
                    (Some(a), Some(b)) => {
                        for (x, y) in a.derivatives.iter().zip(&b.derivatives) {
                            assert!((x - y).abs() <= 1e-9 * (1.0 + y.abs()), "k = {k}: {x} {y}");
                        }
                        let (sa, sb) = (a.std_devs().unwrap(), b.std_devs().unwrap());
                        for (x, y) in sa.iter().zip(&sb) {
                            assert!((x - y).abs() <= 1e-9 * (1.0 + y.abs()), "k = {k}: {x} {y}");
                        }
                    }
                    _ => panic!("k = {k}: one estimate is missing"),
                }
            }
        }
    }
}
