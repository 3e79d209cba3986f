//! The window fit on any strictly increasing timestamps: the newest `window` samples, refitted
//! by Householder QR in a centred, scaled Legendre basis ([`PolynomialFit`], Morrison §6.5)
//! after each sample.

use super::ring::Ring;
use crate::error::Error;
use crate::estimate::PolynomialFit;

/// The newest `window` samples `(t, y)` and, once full, their least-squares fit of degree `m`.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub(super) struct IrregularWindow {
    m: usize,
    ring: Ring<(f64, f64)>,
    fit: Option<PolynomialFit>,
    scratch_t: Vec<f64>,
    scratch_y: Vec<f64>,
}

impl IrregularWindow {
    pub(super) fn new(m: usize, window: usize) -> Self {
        Self {
            m,
            ring: Ring::new(window),
            fit: None,
            scratch_t: Vec::new(),
            scratch_y: Vec::new(),
        }
    }

    /// A window already holding `samples` (oldest first, at most `window` of them), not yet
    /// fitted: the next [`Self::update`] fits it.
    pub(super) fn with_samples(
        m: usize,
        window: usize,
        samples: impl Iterator<Item = (f64, f64)>,
    ) -> Self {
        let mut w = Self::new(m, window);
        for s in samples {
            w.ring.push(s);
        }
        w
    }

    /// Takes the sample `(t, y)` and refits once the window is full.
    pub(super) fn update(&mut self, t: f64, y: f64) -> Result<(), Error> {
        self.ring.push((t, y));
        if self.ring.is_full() {
            self.scratch_t.clear();
            self.scratch_y.clear();
            for &(t, y) in self.ring.iter() {
                self.scratch_t.push(t);
                self.scratch_y.push(y);
            }
            self.fit = Some(PolynomialFit::new(
                &self.scratch_t,
                &self.scratch_y,
                None,
                self.m,
            )?);
        }
        Ok(())
    }

    /// The fit of the newest full window (`None` until the window is full).
    pub(super) fn fit(&self) -> Option<&PolynomialFit> {
        self.fit.as_ref()
    }
}

impl IrregularWindow {
    /// A restored window's invariants ([`crate::persist`]): its degree and ring.
    pub(super) fn check_saved(&self, m: usize, window: usize) -> bool {
        self.m == m && self.ring.check_saved(window)
    }
}
