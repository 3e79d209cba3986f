//! When two sampling steps count as the same step.
//!
//! A step `ζ` (in units of `u`: `τ` for the gain engine, `1` for time units) ending at time
//! `t` equals the typical step `ζ̄` when
//!
//! `|ζ − ζ̄| ≤ 1e-12·ζ̄ + 8ε·|t|/u`,
//!
//! i.e. to a relative `1e-12` plus a few rounding units of the timestamp: evenly spaced
//! times computed in `f64` as `t = k·Δ` have steps that differ by `ulp(t)`. The gain engine
//! scales its gains for the typical step and runs its batch kernels (Morrison Tables 9.1,
//! 13.1 with the variable-step scaling of Reyneke et al. §6) while the steps agree; the
//! relative term alone decides when a mean step is the step itself.

/// The relative part of the tolerance.
pub const STEP_RELATIVE_TOLERANCE: f64 = 1e-12;

/// The rounding allowance per unit of `|t|/u`: a few ulps of the timestamp.
pub const TIMESTAMP_ROUNDING: f64 = 8.0 * f64::EPSILON;

/// How far a step may differ from the typical step `step` and still be the same step, for a
/// step ending at `t`, both in units of `unit`: `1e-12·step + 8ε|t|/unit`.
///
/// ```
/// use seqsmooth::numeric::steps::step_tolerance;
/// assert_eq!(step_tolerance(1.0, 0.0, 1.0), 1e-12);
/// ```
#[inline]
pub fn step_tolerance(step: f64, t: f64, unit: f64) -> f64 {
    tolerance_within(step, t, unit, STEP_RELATIVE_TOLERANCE, TIMESTAMP_ROUNDING)
}

/// `relative·|step| + rounding·|t|/unit`: the tolerance with its two constants explicit.
#[inline(always)]
fn tolerance_within(step: f64, t: f64, unit: f64, relative: f64, rounding: f64) -> f64 {
    relative * step.abs() + rounding * t.abs() / unit
}

/// [`same_step`] with its own relative tolerance and rounding allowance (per unit of
/// `|t|/unit`): `|ζ − ζ̄| ≤ relative·|ζ̄| + rounding·|t|/unit`. The fixed-memory filters'
/// even-spacing rule is this with `1e-9` and `2ε` in time units.
///
/// ```
/// use seqsmooth::numeric::steps::same_step_within;
/// assert!(same_step_within(1.0 + 5e-10, 1.0, 6.0, 1.0, 1e-9, 2.0 * f64::EPSILON));
/// assert!(!same_step_within(1.0 + 5e-10, 1.0, 6.0, 1.0, 1e-12, 8.0 * f64::EPSILON));
/// ```
#[inline]
pub fn same_step_within(
    zeta: f64,
    step: f64,
    t: f64,
    unit: f64,
    relative: f64,
    rounding: f64,
) -> bool {
    (zeta - step).abs() <= tolerance_within(step, t, unit, relative, rounding)
}

/// Whether `zeta` (a step ending at `t`) is the typical step `step`, all in units of `unit`
/// ([`step_tolerance`]).
///
/// ```
/// use seqsmooth::numeric::steps::same_step;
/// let t = 1e6 * 0.1; // a timestamp computed as k·Δ
/// assert!(same_step(0.1 + 1e-11, 0.1, t, 1.0));
/// assert!(!same_step(0.1 + 1e-6, 0.1, t, 1.0));
/// ```
#[inline]
pub fn same_step(zeta: f64, step: f64, t: f64, unit: f64) -> bool {
    (zeta - step).abs() <= step_tolerance(step, t, unit)
}

/// Whether a mean step `mean` equals the step `step` up to rounding (relative `1e-12`): then
/// the step itself is used.
#[inline]
pub(crate) fn snaps_to(mean: f64, step: f64) -> bool {
    (mean - step).abs() <= STEP_RELATIVE_TOLERANCE * step
}

/// [`same_step`] with the typical step and unit fixed, its two parts precomputed for a
/// kernel's inner loop: a step `ζ` ending at `t` agrees when `|ζ − ζ̄| ≤ a + b|t|`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StepCheck {
    step: f64,
    fixed: f64,
    per_time: f64,
}

impl StepCheck {
    #[inline]
    pub(crate) fn new(step: f64, unit: f64) -> Self {
        Self {
            step,
            fixed: step_tolerance(step, 0.0, unit),
            per_time: step_tolerance(0.0, 1.0, unit),
        }
    }

    /// Whether the step `zeta` (in units of the unit) ending at `t` is the typical step.
    #[inline(always)]
    pub(crate) fn agrees(&self, zeta: f64, t: f64) -> bool {
        (zeta - self.step).abs() <= self.fixed + self.per_time * t.abs()
    }

    /// Whether every step of `ts` (the first from `prev`) agrees, the steps formed as
    /// `(t − p)·inv_unit`: no early exit, so that it vectorises.
    pub(crate) fn all_agree(&self, ts: &[f64], prev: f64, inv_unit: f64) -> bool {
        let even = |t: f64, p: f64| self.agrees((t - p) * inv_unit, t);
        let Some((&first, _)) = ts.split_first() else {
            return true;
        };
        let uneven = usize::from(!even(first, prev))
            + ts[1..]
                .iter()
                .zip(ts)
                .map(|(&t, &p)| usize::from(!even(t, p)))
                .sum::<usize>();
        uneven == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The precomputed check is the scalar rule on the boundary cases: exact grids `k·Δ`
    /// agree at any magnitude of `t`, a relative change of 1e-11 does not (at small `t`).
    #[test]
    fn precomputed_check_is_the_rule() {
        for &(step, unit) in &[(1.0, 1.0), (0.1, 0.1), (1e-3, 1.0), (2.5, 0.5)] {
            let check = StepCheck::new(step / unit, unit);
            for k in [1u64, 10, 1_000, 1_000_000, 1_000_000_000] {
                let (t, p) = (k as f64 * step, (k - 1) as f64 * step);
                let zeta = (t - p) / unit;
                assert!(check.agrees(zeta, t), "{step} {unit} {k}");
                assert!(same_step(zeta, step / unit, t, unit), "{step} {unit} {k}");
                let off = zeta * (1.0 + 1e-11);
                assert_eq!(
                    check.agrees(off, 1.0),
                    same_step(off, step / unit, 1.0, unit)
                );
                assert!(!check.agrees(off, 1.0));
            }
            let ts: Vec<f64> = (1..100).map(|k| k as f64 * step).collect();
            assert!(check.all_agree(&ts, 0.0, 1.0 / unit));
            let mut bad = ts.clone();
            bad[50] += 1e-6 * step;
            assert!(!check.all_agree(&bad, 0.0, 1.0 / unit));
            assert!(check.all_agree(&[], 0.0, 1.0 / unit));
        }
        assert!(snaps_to(1.0 + 1e-13, 1.0) && !snaps_to(1.0 + 1e-11, 1.0));
    }
}
