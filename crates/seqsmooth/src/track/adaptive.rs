//! The innovation monitor of the radar tracker's Kalman methods (and the window method's
//! gate) (Morrison §14.8): each
//! update's normalised innovation squared `NIS = νᵀ V⁻¹ ν` is `χ²(p)` for `p` components while
//! the model holds, and the sum over the last [`WINDOW`] updates is `χ²` with their summed
//! components (14.8.4)-(14.8.5).
//!
//! | test | on failing | the row's flag |
//! |---|---|---|
//! | one update's NIS above the gate, `χ²_p` at `1 − GATE_ALPHA`, after an update that passed it, while the window test holds | the measurement is left out: the estimate is the prediction | [`TrackFlag::Outlier`] |
//! | the window's NIS sum above `χ²` at `1 − MISFIT_ALPHA` (or one update above the gate that is used: the second in a row, or during a misfit) | the memory is shortened (adaptive methods) | [`TrackFlag::Misfit`] |
//!
//! A misfit means the model (constant velocity, with its driving noise or memory) no longer
//! follows the target, so the estimate's σ need not cover its error: "if it is exceeded
//! repeatedly, then a bias error can be assumed to have developed" (§14.8). An adaptive filter
//! (the tracker's default, without a given driving noise or discount) answers by a shorter
//! memory: one level up per misfit update whose NIS is still above its mean `p`, two for an
//! update above the gate; one level down after `3 WINDOW` updates without a change whose window
//! sum is below its mean (the memory longer than needed). A level is a driving-noise density
//! `q₀ 4^ℓ` (the Kalman filter, ch. 15) or a fading discount `θ = 1 − (1 − θ₀) 2^ℓ` (ch. 14).

use crate::error::Error;
use crate::stats::{chi_squared_quantile, InnovationChiSquared};

/// The updates in the window test.
pub const WINDOW: usize = 5;

/// The window test's false-alarm rate per update.
pub const MISFIT_ALPHA: f64 = 0.01;

/// The outlier gate's false-alarm rate per update.
pub const GATE_ALPHA: f64 = 1e-3;

/// How a row's estimate stands: what `seqsmooth track`'s `flag` column, and the Python
/// tracker's `flags`, name.
///
/// ```
/// use seqsmooth::track::TrackFlag;
/// assert_eq!(TrackFlag::Misfit.name(), "misfit");
/// assert_eq!(TrackFlag::None.name(), "");
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum TrackFlag {
    /// The model holds as far as the tests see: the σ covers the error.
    #[default]
    None,
    /// The row's measurement failed the outlier gate and was left out; the estimate is the
    /// prediction from the rows before (the window method: the fit of the window without it),
    /// whose σ covers that.
    Outlier,
    /// The model does not follow the data here (a manoeuvre): the innovation test (Kalman
    /// methods) or the window's χ² (the sliding fit) failed, so the σ may not cover the error.
    Misfit,
}

impl TrackFlag {
    /// The flag's name in the front ends: `""`, `"outlier"` or `"misfit"`.
    ///
    /// ```
    /// use seqsmooth::track::TrackFlag;
    /// assert_eq!(TrackFlag::Outlier.name(), "outlier");
    /// ```
    pub fn name(self) -> &'static str {
        match self {
            TrackFlag::None => "",
            TrackFlag::Outlier => "outlier",
            TrackFlag::Misfit => "misfit",
        }
    }
}

/// The monitor: the gate, the window test and the adaptive level.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub(crate) struct Monitor {
    test: InnovationChiSquared,
    /// `gates[p − 1]`: the gate for `p` components.
    gates: Vec<f64>,
    /// Whether the last update used crossed the gate, or the last was left out.
    crossed: bool,
    /// The level, within `lowest..=highest`; `None` for a fixed memory.
    level: Option<i32>,
    lowest: i32,
    highest: i32,
    /// Updates since the level last changed.
    since: usize,
}

impl Monitor {
    /// A monitor of updates of up to `components` components; adaptive over the levels
    /// `lowest..=highest` (from 0) when `adaptive`.
    pub(crate) fn new(
        components: usize,
        adaptive: bool,
        lowest: i32,
        highest: i32,
    ) -> Result<Self, Error> {
        let gates = (1..=components)
            .map(|p| chi_squared_quantile(p as f64, 1.0 - GATE_ALPHA))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            test: InnovationChiSquared::new(WINDOW, MISFIT_ALPHA)?,
            gates,
            crossed: false,
            level: adaptive.then_some(0),
            lowest,
            highest,
            since: 0,
        })
    }

    /// The level (0 for a fixed memory).
    pub(crate) fn level(&self) -> i32 {
        self.level.unwrap_or(0)
    }

    /// The gate of `p` components.
    fn gate(&self, p: usize) -> f64 {
        self.gates
            .get(p.saturating_sub(1))
            .copied()
            .unwrap_or(f64::INFINITY)
    }

    /// Whether an update of `p` components with this NIS is used: within the gate, or after
    /// a crossing (a second one in a row is a manoeuvre, not an outlier), or during a misfit.
    pub(crate) fn accepts(&self, nis: f64, p: usize) -> bool {
        nis <= self.gate(p) || self.crossed || self.test.is_misfit()
    }

    /// Records an update (`used` as [`Self::accepts`] said) and returns the row's flag and
    /// whether the level changed.
    pub(crate) fn record(&mut self, nis: f64, p: usize, used: bool) -> (TrackFlag, bool) {
        if !used {
            self.crossed = true;
            return (TrackFlag::Outlier, false);
        }
        let crossed = nis > self.gate(p);
        self.crossed = crossed;
        let misfit = self.test.push_nis(nis, p).map(|o| o.misfit).unwrap_or(true);
        let flag = if misfit || crossed {
            TrackFlag::Misfit
        } else {
            TrackFlag::None
        };
        let Some(level) = self.level else {
            return (flag, false);
        };
        let mut next = level;
        if crossed {
            next = (level + 2).min(self.highest);
        } else if misfit && nis > p as f64 {
            next = (level + 1).min(self.highest);
        } else {
            self.since += 1;
            let dof = p * self.test.len();
            if self.since >= 3 * WINDOW && self.test.statistic() < dof as f64 {
                next = (level - 1).max(self.lowest);
            }
        }
        let changed = next != level;
        if changed {
            self.since = 0;
            self.level = Some(next);
        }
        (flag, changed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One crossing is an outlier, a second in a row is a misfit that raises the level two
    /// steps; quiet updates bring it down one step after `3 WINDOW` of them.
    #[test]
    fn gate_then_manoeuvre_then_back() {
        let mut m = Monitor::new(3, true, -2, 4).unwrap();
        assert!(m.accepts(3.0, 3));
        assert_eq!(m.record(3.0, 3, true), (TrackFlag::None, false));
        assert!(!m.accepts(40.0, 3));
        assert_eq!(m.record(40.0, 3, false), (TrackFlag::Outlier, false));
        assert!(m.accepts(40.0, 3));
        assert_eq!(m.record(40.0, 3, true), (TrackFlag::Misfit, true));
        assert_eq!(m.level(), 2);
        let mut changes = 0;
        for _ in 0..3 * WINDOW {
            changes += usize::from(m.record(1.0, 3, true).1);
        }
        assert_eq!((changes, m.level()), (1, 1));
    }
}
