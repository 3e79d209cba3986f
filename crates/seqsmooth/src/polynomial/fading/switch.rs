//! Memory equivalences and the expanding → fading-memory switch (Morrison §13.7-13.8,
//! Table 13.4; Reyneke et al. §7.2, Table 1).
//!
//! A fading-memory filter with discount `θ` smooths about as much as a fixed-memory filter of
//! `L ≈ c_im / (1-θ)` samples, where `c_im` equates the variance-reduction factors of derivative
//! `i` near `θ = 1` ([`memory_length_constant`], Table 13.4). The fading-memory filter is not
//! self-starting; it starts as an expanding-memory filter and switches to its constant gains at a
//! sample chosen by a [`SwitchRule`].

use super::vrf::{fading_vrf, fading_vrf_limit};
use crate::calculus::{choose_integer, falling_factorial};
use crate::error::{Error, Param};
use crate::numeric::memo::Memo;
use crate::polynomial::expanding::gains::ExpandingGainSchedule;
use crate::polynomial::form::EstimateForm;
use crate::scalar::{Rational, Scalar};
use num_bigint::BigInt;

/// Morrison's Table 13.4 constant `c_im = (κ_ii(m)/λ_ii(m))^(1/(2i+1))`: a fading-memory filter
/// of degree `m` and discount `θ` has the variance reduction in derivative `i` of a fixed-memory
/// filter with `L = c_im/(1-θ)` (asymptotically, `θ → 1`). Requires `i ≤ m`.
///
/// ```
/// use seqsmooth::polynomial::fading::switch::memory_length_constant;
/// assert!((memory_length_constant(0, 1) - 3.2).abs() < 1e-15);
/// assert!((memory_length_constant(1, 1) - 3.6342).abs() < 1e-4);
/// ```
pub fn memory_length_constant(i: usize, m: usize) -> f64 {
    assert!(i <= m, "derivative index {i} exceeds degree {m}");
    static CONSTANTS: Memo<(usize, usize), f64> = Memo::new();
    *CONSTANTS.get((i, m), || {
        let (k, l) = vrf_limit_diagonals(i, m);
        (k.to_f64() / l.to_f64()).powf(1.0 / (2 * i + 1) as f64)
    })
}

/// The diagonal entries `κ_ii` of [`crate::polynomial::fixed::fixed_memory_vrf_limit`] and `λ_ii` of
/// [`fading_vrf_limit`], in integers: `κ = V H⁻¹ Vᵀ` with the inverse Hilbert matrix in its
/// closed form `(H⁻¹)_jk = (−1)^(j+k) (j+k+1) C(m+1+j, m−k) C(m+1+k, m−j) C(j+k, j)²` and
/// `V_ij = j^(i)`; `λ = G B Gᵀ` with `G_ij = C(j,i)`, `B_jk = C(j+k, j)/2^(j+k+1)`. One entry
/// each, `O(m²)` integer products, instead of the whole rational matrices.
fn vrf_limit_diagonals(i: usize, m: usize) -> (Rational, Rational) {
    let int = |r: Rational| r.to_integer();
    let c = choose_integer;
    let v: Vec<BigInt> = (0..=m)
        .map(|j| int(falling_factorial(Rational::from_i64(j as i64), i)))
        .collect();
    let (mut kappa, mut lambda) = (BigInt::from(0), BigInt::from(0));
    for j in 0..=m {
        for k in 0..=m {
            let mut h = BigInt::from((j + k + 1) as i64)
                * c(m + 1 + j, m - k)
                * c(m + 1 + k, m - j)
                * c(j + k, j).pow(2);
            if (j + k) % 2 == 1 {
                h = -h;
            }
            kappa += &v[j] * &v[k] * h;
            // λ_ii on the common denominator 2^(2m+1).
            lambda += c(j, i) * c(k, i) * c(j + k, j) * (BigInt::from(1) << (2 * m - j - k));
        }
    }
    let two = BigInt::from(1) << (2 * m + 1);
    (Rational::from_integer(kappa), Rational::new(lambda, two))
}

/// Reyneke's Table 1 switch constant (= Table 13.4 row 0), exactly: `(m+1)² / λ_00(m)`, the
/// limit ratio of `n·VRF_expanding(n)` to `VRF_fading(θ)/(1-θ)` for the position. Switch at
/// `n_s = c/(1-θ)`, or choose `θ = 1 - c/n_s` for a planned switch at `n_s`.
///
/// ```
/// use seqsmooth::polynomial::fading::switch::switch_constant;
/// use seqsmooth::scalar::parse_rational;
/// assert_eq!(switch_constant(2), parse_rational("48/11").unwrap());
/// assert_eq!(switch_constant(5), parse_rational("6144/793").unwrap());
/// ```
pub fn switch_constant(m: usize) -> Rational {
    let lam = fading_vrf_limit(m)[(0, 0)].clone();
    Rational::from_i64(((m + 1) * (m + 1)) as i64) / lam
}

/// When a fading-memory filter hands over from its expanding-memory start-up (Morrison §13.8).
///
/// The rules count samples, so they use the discount per sample: `θ` itself with
/// [`crate::DiscountMode::PerUpdate`], and `θ^(ζ̄)` with [`crate::DiscountMode::PerTime`], where
/// `ζ̄` is the mean step so far in units of `τ` (the filter re-evaluates the rule at every sample
/// until it switches; [`SwitchRule::switch_index`] gives the index for a known per-sample `θ`).
#[derive(Clone, Copy, Debug, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub enum SwitchRule {
    /// At `n = ⌊c_0m/(1-θ)⌋`, the position row of Table 13.4 (Reyneke Table 1; Morrison's text
    /// example (13.8.8): `m = 1, θ = 0.9 → n = 32`). The default.
    #[default]
    Position,
    /// At `n = (mean over i of c_im)/(1-θ)`, the rule behind Morrison's Ex. 13.21 answers.
    ColumnMean,
    /// At `n = c_im/(1-θ)` for derivative `i`.
    Derivative(usize),
    /// At the first `n` where the expanding-memory position variance of the current estimate
    /// falls to the fading-memory one: the exact crossover (earlier than the asymptotic rules).
    ExactCrossover,
    /// At an explicit 0-based sample index.
    AtSample(u64),
}

/// Indices past the degree that [`SwitchRule::ExactCrossover`] checks one by one before it
/// searches by bisection.
const LINEAR_SCAN: u64 = 4096;

impl SwitchRule {
    /// The 0-based index of the first sample processed with the fading-memory gains, for degree
    /// `m` and discount `θ`. Never less than `m + 1`, so that the expanding-memory start has
    /// determined the state.
    ///
    /// ```
    /// use seqsmooth::polynomial::fading::switch::SwitchRule;
    /// assert_eq!(SwitchRule::Position.switch_index(1, 0.9).unwrap(), 32);  // Morrison (13.8.8)
    /// assert_eq!(SwitchRule::ColumnMean.switch_index(2, 0.93).unwrap(), 68); // Ex. 13.21
    /// assert_eq!(SwitchRule::ExactCrossover.switch_index(0, 0.9).unwrap(), 18);
    /// ```
    pub fn switch_index(&self, m: usize, theta: f64) -> Result<u64, Error> {
        if !(theta > 0.0 && theta < 1.0) {
            return Err(Error::ThetaOutOfRange { theta });
        }
        if let SwitchRule::Derivative(i) = *self {
            if i > m {
                return Err(Error::InvalidParameter {
                    name: Param::SwitchDerivative,
                    value: i.to_string(),
                    reason: format!("must be at most the degree {m}"),
                });
            }
        }
        let n = match (*self, self.asymptotic_constant(m)) {
            (SwitchRule::AtSample(n), _) => n,
            (_, Some(c)) => Self::asymptotic_index(c, theta),
            _ => {
                let target = fading_vrf(m, theta, EstimateForm::Current)?[(0, 0)];
                Self::crossover_index(&ExpandingGainSchedule::new(m), target)
            }
        };
        Ok(n.max(m as u64 + 1))
    }

    /// The constant `c` of the asymptotic rules (switch at `⌊c/(1−θ)⌋`): `c_0m` for
    /// [`Position`](Self::Position), the mean of `c_im` over `i` for
    /// [`ColumnMean`](Self::ColumnMean), `c_im` (`i` clamped to `m`) for
    /// [`Derivative`](Self::Derivative); `None` for the other rules.
    pub(crate) fn asymptotic_constant(&self, m: usize) -> Option<f64> {
        match *self {
            SwitchRule::Position => Some(memory_length_constant(0, m)),
            SwitchRule::ColumnMean => {
                Some((0..=m).map(|i| memory_length_constant(i, m)).sum::<f64>() / (m + 1) as f64)
            }
            SwitchRule::Derivative(i) => Some(memory_length_constant(i.min(m), m)),
            SwitchRule::ExactCrossover | SwitchRule::AtSample(_) => None,
        }
    }

    /// `⌊c/(1−θ)⌋`, truncated with a 1e-9 allowance for the rounding of `c/(1−θ)`: reproduces
    /// every switch time the book gives, (13.8.8) 32, Ex. 13.21 68/32/170, Figs. 13.3/13.5
    /// 75/100. Saturates at `u64::MAX`.
    fn asymptotic_index(c: f64, theta: f64) -> u64 {
        (c / (1.0 - theta) + 1e-9).floor() as u64
    }

    /// The first `n ≥ m` at which the expanding-memory current position VRF, its position gain
    /// `h_0(n)`, has fallen to `target`: sample by sample for the first [`LINEAR_SCAN`] indices
    /// (every θ up to about 0.9995 at degree 0), then by doubling and bisection, since `h_0`
    /// falls monotonically (each sample adds information), so that θ within 1e-12 of 1 (a
    /// crossover near 2e12) costs about 80 evaluations, not 10¹².
    fn crossover_index(sched: &ExpandingGainSchedule, target: f64) -> u64 {
        let reached = |n: u64| Self::crossover_reached(sched.position_gain(n), target);
        let m = sched.degree() as u64;
        let scan_end = m + LINEAR_SCAN;
        if let Some(n) = (m..scan_end).find(|&n| reached(n)) {
            return n;
        }
        // Not reached at `lo`, reached at `hi` (u64::MAX: h_0 ≈ (m+1)²/n ≈ 0 there).
        let (mut lo, mut hi) = (scan_end - 1, scan_end.saturating_mul(2));
        while hi < u64::MAX && !reached(hi) {
            lo = hi;
            hi = hi.saturating_mul(2);
        }
        while hi - lo > 1 {
            let mid = lo + (hi - lo) / 2;
            if reached(mid) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        hi
    }

    /// The exact crossover: the expanding-memory position VRF `h0` has fallen to the
    /// fading-memory one `target`, with a relative slack of 1e-12 that absorbs the rounding
    /// of an exact tie (`m = 0`: `n* = 2θ/(1−θ)` exactly).
    fn crossover_reached(h0: f64, target: f64) -> bool {
        h0 <= target * (1.0 + 1e-12)
    }

    /// The rule for a filter that evaluates it sample by sample (the gain engine, the automatic
    /// filter): whether the sample with index `n` is the first with the fading gains, for the
    /// per-sample discount so far `theta_s`, the rule's [`asymptotic_constant`]
    /// (`constant`, cached by the caller) and, for [`ExactCrossover`](Self::ExactCrossover)
    /// only, `crossover()` = (the expanding-memory position VRF at `n`, the fading-memory one
    /// at `theta_s`). The same rule as [`switch_index`](Self::switch_index): never before
    /// `n = m + 1`.
    ///
    /// [`asymptotic_constant`]: Self::asymptotic_constant
    pub(crate) fn switches<E>(
        &self,
        m: usize,
        n: u64,
        theta_s: f64,
        constant: Option<f64>,
        crossover: impl FnOnce() -> Result<(f64, f64), E>,
    ) -> Result<bool, E> {
        let index = match (*self, constant) {
            (SwitchRule::AtSample(k), _) => k,
            (_, Some(c)) => Self::asymptotic_index(c, theta_s),
            _ => {
                let (h0, target) = crossover()?;
                return Ok(n > m as u64 && Self::crossover_reached(h0, target));
            }
        };
        Ok(n >= index.max(m as u64 + 1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The per-sample rule switches first at the index `switch_index` gives, for every rule
    /// (the oracle for the constant rules: the book's switch times in the doc examples).
    #[test]
    fn per_sample_rule_agrees_with_the_index() {
        for m in 0..=4usize {
            for theta in [0.5, 0.9, 0.93, 0.99] {
                for rule in [
                    SwitchRule::Position,
                    SwitchRule::ColumnMean,
                    SwitchRule::Derivative(1),
                    SwitchRule::ExactCrossover,
                    SwitchRule::AtSample(7),
                ] {
                    if matches!(rule, SwitchRule::Derivative(1)) && m == 0 {
                        continue;
                    }
                    let index = rule.switch_index(m, theta).unwrap();
                    let c = rule.asymptotic_constant(m);
                    let sched = ExpandingGainSchedule::new(m);
                    let target = fading_vrf(m, theta, EstimateForm::Current).unwrap()[(0, 0)];
                    let first = (m as u64 + 1..)
                        .find(|&n| {
                            rule.switches(m, n, theta, c, || {
                                let mut h = vec![0.0; m + 1];
                                sched.gains(n, &mut h);
                                Ok::<_, Error>((h[0], target))
                            })
                            .unwrap()
                        })
                        .unwrap();
                    assert_eq!(first, index, "{rule:?} m {m} θ {theta}");
                }
            }
        }
    }

    /// The exact crossover for θ near 1, where it lies beyond the sample-by-sample scan: at
    /// degree 0 it is the closed form `⌈2θ/(1−θ)⌉` (`1/(n+1) ≤ (1−θ)/(1+θ)`, Morrison
    /// (13.4.3), (13.8.2)); at every degree the search equals a scan one index at a time
    /// (here to 1.2e5), and θ = 1 − 1e-13 takes a bounded search (it took 10¹³ steps).
    #[test]
    fn exact_crossover_near_theta_one() {
        for theta in [0.9999, 0.99999, 1.0 - 1e-7, 1.0 - 1e-10] {
            let n = SwitchRule::ExactCrossover.switch_index(0, theta).unwrap();
            let closed = 2.0 * theta / (1.0 - theta);
            assert!(
                (n as f64 - closed.ceil()).abs() <= 1.0,
                "θ {theta}: {n} against {closed}"
            );
        }
        for m in [1usize, 3, 8] {
            let theta = 1.0 - 1e-4 * (m + 1) as f64;
            let sched = ExpandingGainSchedule::new(m);
            let target = fading_vrf(m, theta, EstimateForm::Current).unwrap()[(0, 0)];
            let scanned = (m as u64..)
                .find(|&n| SwitchRule::crossover_reached(sched.position_gain(n), target))
                .unwrap();
            assert!(scanned > m as u64 + LINEAR_SCAN, "m {m}: {scanned}");
            assert_eq!(
                SwitchRule::ExactCrossover.switch_index(m, theta).unwrap(),
                scanned,
                "m {m}"
            );
        }
        let far = SwitchRule::ExactCrossover
            .switch_index(4, 1.0 - 1e-13)
            .unwrap();
        assert!(far > 1_000_000_000_000, "{far}");
    }

    /// The integer closed forms equal the diagonals of the exact rational matrices.
    #[test]
    fn limit_diagonals_equal_the_rational_matrices() {
        for m in 0..=10 {
            let (kappa, lambda) = (
                crate::polynomial::fixed::fixed_memory_vrf_limit(m),
                fading_vrf_limit(m),
            );
            for i in 0..=m {
                assert_eq!(
                    vrf_limit_diagonals(i, m),
                    (kappa[(i, i)].clone(), lambda[(i, i)].clone()),
                    "m={m} i={i}"
                );
            }
        }
    }
}
