//! The memory of the radar tracker's Kalman methods (Morrison ch. 14-15, §14.8): a driving
//! noise density `q` (the acceleration's white noise, (15.2.23)) or a fading discount, fixed or
//! adaptive, set on the filter at the level its innovation monitor ([`super::adaptive`])
//! chooses: `q₀ 4^ℓ` or `θ = 1 − (1 − θ₀) 2^ℓ`; and the gated update of each row through it.

use super::adaptive::{Monitor, TrackFlag};
use super::model::{MotionModel, TrackDynamics};
use crate::discount::Discount;
use crate::error::Error;
use crate::kalman::filter::KalmanFilter;
use crate::kalman::fixed_lag::FixedLagSmoother;
use crate::kalman::smoother::Smoothed;
use crate::model::measurement::Measurement;
use crate::model::measurement::NoiseCovariance;
use crate::model::radar::Radar;

/// The filter of the Kalman methods.
pub(super) type Filter = KalmanFilter<TrackDynamics, Radar>;

/// The memory of a Kalman method: a driving noise or a discount, fixed or adaptive, with the
/// innovation monitor that flags its rows.
#[derive(Clone, Debug)]
pub(super) struct Memory {
    model: MotionModel,
    kind: MemoryKind,
    monitor: Monitor,
}

/// What a level sets.
#[derive(Clone, Copy, Debug)]
pub(super) enum MemoryKind {
    /// The driving noise `q` (Singer's `σ_m²`) at level 0 (`q₀` when adaptive).
    Noise(f64),
    /// The discount at level 0.
    Fading(Discount),
}

impl Memory {
    /// The memory `kind` of `model` at level 0, adaptive between the levels
    /// `lowest..=highest` or fixed.
    pub(super) fn new(
        model: MotionModel,
        kind: MemoryKind,
        adaptive: bool,
        (lowest, highest): (i32, i32),
    ) -> Result<Self, Error> {
        Ok(Self {
            model,
            kind,
            monitor: Monitor::new(3, adaptive, lowest, highest)?,
        })
    }

    /// Sets the filter's driving noise or discount to the monitor's level.
    pub(super) fn apply(&self, f: &mut Filter) -> Result<(), Error> {
        let level = self.monitor.level();
        match self.kind {
            MemoryKind::Noise(q) => self.model.set_noise(f, q, 4f64.powi(level)),
            MemoryKind::Fading(d) if level == 0 => f.set_fading(d),
            MemoryKind::Fading(d) => {
                f.set_fading(d.with_theta(1.0 - (1.0 - d.theta()) * 2f64.powi(level))?)
            }
        }
    }

    /// One row through `filter`: the gated update, the row's flag, and the level changed
    /// where the monitor says so. Returns the NIS (`None` with no component) and the flag.
    pub(super) fn step(
        &mut self,
        f: &mut Filter,
        m: &Measurement,
    ) -> Result<(Option<f64>, TrackFlag), Error> {
        let monitor = &self.monitor;
        let Some((stats, used)) = f.update_gated(m, |s| monitor.accepts(s.nis, s.components))?
        else {
            return Ok((None, TrackFlag::None));
        };
        let (flag, changed) = self.monitor.record(stats.nis, stats.components, used);
        if changed {
            self.apply(f)?;
        }
        Ok((Some(stats.nis), flag))
    }

    /// [`Self::step`] for the smoother: the gate decided on a copy of its filter, then the row
    /// (or, left out, the prediction to its time) pushed and the level changed where the
    /// monitor says so. Returns the row the smoother gave (if any), the NIS and the flag. On
    /// an error the smoother and the memory are unchanged (the new level is tried on the copy
    /// before the push).
    pub(super) fn step_smoother(
        &mut self,
        s: &mut FixedLagSmoother<TrackDynamics, Radar>,
        m: &Measurement,
    ) -> Result<(Option<Smoothed>, Option<f64>, TrackFlag), Error> {
        let mut probe = s.filter().clone();
        let monitor = &self.monitor;
        let gated = probe.update_gated(m, |s| monitor.accepts(s.nis, s.components))?;
        let Some((stats, used)) = gated else {
            return Ok((s.push(m)?, None, TrackFlag::None));
        };
        let mut memory = self.clone();
        let (flag, changed) = memory.monitor.record(stats.nis, stats.components, used);
        if changed {
            memory.apply(&mut probe)?;
        }
        let given = if used {
            s.push(m)?
        } else {
            let mut predicted = m.clone();
            predicted.values.iter_mut().for_each(|v| *v = None);
            s.push(&predicted)?
        };
        if changed {
            memory.apply(s.filter_mut())?;
        }
        *self = memory;
        Ok((given, Some(stats.nis), flag))
    }
}

/// The adaptive driving noise's level 0, `q₀ = σ_r² / T^(2m+1)` for white noise on the
/// `m`-th derivative: the range's noise variance (of the last row) over the rows' mean step
/// to that power (`T³` for constant velocity), the density whose tracking index
/// `√(q T^(2m+1)) / σ_r` is 1.
pub(super) fn base_noise<'a>(rows: impl Iterator<Item = &'a Measurement>, m: i32) -> f64 {
    let (mut first, mut last, mut count, mut variance) = (f64::NAN, f64::NAN, 0usize, 1.0);
    for m in rows {
        if count == 0 {
            first = m.time;
        }
        last = m.time;
        count += 1;
        if m.values.first().is_some_and(Option::is_some) {
            variance = match &m.noise {
                NoiseCovariance::Identity => 1.0,
                NoiseCovariance::Variances(v) => v.first().copied().unwrap_or(1.0),
                NoiseCovariance::Full(r) => r[(0, 0)],
            };
        }
    }
    let step = (last - first) / count.saturating_sub(1).max(1) as f64;
    let q = variance / (0..2 * m + 1).fold(1.0, |p, _| p * step);
    if q.is_finite() && q > 0.0 {
        q
    } else {
        1.0
    }
}
