//! The polynomials orthonormal for a positive measure `μ` on an interval, by their three-term
//! recurrence (the Jacobi matrix): `u b_k(u) = β_{k+1} b_{k+1}(u) + α_k b_k(u) + β_k b_{k−1}(u)`,
//! `b_0 = 1/√μ₀`, `μ₀ = ∫ dμ` (Villien & Ostertag 2009, eqs. 5, 8-9; the basis `{b_i}` of their
//! smoothing polynomial).
//!
//! The recurrence runs in `u = (t − c)/h ∈ [−1, 1]` for an interval `[c − h, c + h]` (their
//! §III), so it does not depend on the time origin or unit. Four measures:
//!
//! | constructor | measure `dμ(t)` | coefficients |
//! |---|---|---|
//! | [`legendre`](Jacobi::legendre) | `dt` on `[a, b]` | `α = 0`, `β_k = k/√(4k² − 1)` |
//! | [`chebyshev`](Jacobi::chebyshev) | `dt/√((t − a)(b − t))` | `α = 0`, `β_1 = 1/√2`, `β_k = 1/2` |
//! | [`discrete`](Jacobi::discrete) | `Σ_j w_j δ(t − t_j)` | Lanczos with full reorthogonalisation |
//! | [`continuous`](Jacobi::continuous) | `ω(t) dt` | the measure discretised, then `discrete` |
//!
//! The discrete case is the one polynomial samples need: with `w_j = 1/σ²(t_j)` over the
//! actual sample times the samples at the Gauss nodes are exactly uncorrelated (their §II,
//! Lemma 3 on the discrete inner product). The Lanczos process on `diag(u_j)` from
//! `√(w_j/μ₀)` (Gragg & Harrod's route to the recurrence; reorthogonalised twice against every
//! earlier vector) is backward stable where the Stieltjes procedure on moments is not.

use super::gauss::GaussRule;
use crate::error::{Error, Param};
use crate::numeric::double_word::{self as dw, DoubleWord};

/// The recurrence of the polynomials `b_0 … b_n` orthonormal for a measure, in the variable
/// `u = (t − centre)/half`.
#[derive(Clone, Debug, PartialEq)]
pub struct Jacobi {
    /// `α_0 … α_n`, the diagonal.
    pub alpha: Vec<f64>,
    /// `β_1 … β_n`, the off-diagonal (`β_k > 0`).
    pub beta: Vec<f64>,
    /// `μ₀`, the measure's mass (`∫ dμ`, in the units of `t` times those of the weight).
    pub mass: f64,
    /// The interval's centre `c` (time units).
    pub centre: f64,
    /// Its half-width `h` (time units, `> 0`).
    pub half: f64,
}

/// A weight function on `[a, b]` for [`Jacobi::continuous`]: how it behaves at the ends decides
/// the rule that discretises it.
#[derive(Clone, Copy)]
pub enum Weight<'a> {
    /// `ω(t) = f(t)`, smooth on `[a, b]` (discretised by Gauss–Legendre).
    Smooth(&'a dyn Fn(f64) -> f64),
    /// `ω(t) = f(t)/√((t − a)(b − t))` with `f` smooth: the Chebyshev ends (discretised by
    /// Gauss–Chebyshev, which takes the end factor exactly).
    ChebyshevEnds(&'a dyn Fn(f64) -> f64),
}

/// Discretisations [`Jacobi::continuous`] tries, doubling from the first: the coefficients of
/// two successive ones must agree to [`DISCRETISATION_TOLERANCE`].
const DISCRETISATION_POINTS: [usize; 5] = [64, 128, 256, 512, 1024];

/// How close (in `u`, where the coefficients are of order 1) two discretisations' recurrence
/// coefficients must be for [`Jacobi::continuous`] to take the finer one.
const DISCRETISATION_TOLERANCE: f64 = 1e-14;

/// The largest degree `n` of a [`Jacobi`] recurrence (its Gauss rule has `n + 1` nodes, found
/// in `O(n²)` by Golub–Welsch): that of the finest Legendre rule the continuous measures are
/// discretised by (1,024 points), far beyond PAML's segments (`paml::MAX_DEGREE`), and a bound
/// on the work and memory one call may ask for.
///
/// ```
/// use seqsmooth::basis::{Jacobi, MAX_JACOBI_DEGREE};
/// assert!(Jacobi::legendre(MAX_JACOBI_DEGREE, -1.0, 1.0).is_ok());
/// assert!(Jacobi::legendre(MAX_JACOBI_DEGREE + 1, -1.0, 1.0).is_err());
/// ```
pub const MAX_JACOBI_DEGREE: usize = 1_023;

const _: () =
    assert!(DISCRETISATION_POINTS[DISCRETISATION_POINTS.len() - 1] == MAX_JACOBI_DEGREE + 1);

/// The range of a [`Jacobi`] recurrence's degree: `n ≤ MAX_JACOBI_DEGREE` (every
/// constructor's check).
pub fn check_jacobi_degree(n: usize) -> Result<(), Error> {
    crate::error::check_degree_at_most(n, MAX_JACOBI_DEGREE)
}

fn check_interval(a: f64, b: f64) -> Result<(f64, f64), Error> {
    if !(a.is_finite() && b.is_finite() && a < b && ((b - a) / 2.0).is_normal()) {
        return Err(Error::InvalidParameter {
            name: Param::Interval,
            value: format!("[{a}, {b}]"),
            reason: "needs finite ends a < b".into(),
        });
    }
    Ok(((a + b) / 2.0, (b - a) / 2.0))
}

impl Jacobi {
    /// Legendre: `dμ = dt` on `[a, b]`, `α_k = 0`, `β_k = k/√(4k² − 1)`, `μ₀ = b − a`.
    ///
    /// ```
    /// use seqsmooth::basis::Jacobi;
    /// let j = Jacobi::legendre(2, -1.0, 1.0)?;
    /// assert_eq!(j.beta, vec![1.0 / 3f64.sqrt(), 2.0 / 15f64.sqrt()]);
    /// // b_1(u) = √(3/2) u, orthonormal on [-1, 1]
    /// assert!((j.orthonormal(0.5)[1] - 1.5f64.sqrt() * 0.5).abs() < 1e-15);
    /// # Ok::<(), seqsmooth::Error>(())
    /// ```
    pub fn legendre(n: usize, a: f64, b: f64) -> Result<Self, Error> {
        check_jacobi_degree(n)?;
        let (centre, half) = check_interval(a, b)?;
        let beta = (1..=n)
            .map(|k| {
                let k = k as f64;
                k / (4.0 * k * k - 1.0).sqrt()
            })
            .collect();
        Ok(Self {
            alpha: vec![0.0; n + 1],
            beta,
            mass: 2.0 * half,
            centre,
            half,
        })
    }

    /// Chebyshev (first kind): `dμ = dt/√((t − a)(b − t))`, `α_k = 0`, `β_1 = 1/√2`,
    /// `β_k = 1/2`, `μ₀ = π`.
    ///
    /// ```
    /// use seqsmooth::basis::Jacobi;
    /// let j = Jacobi::chebyshev(3, 0.0, 2.0)?;
    /// assert_eq!(j.beta, vec![0.5f64.sqrt(), 0.5, 0.5]);
    /// # Ok::<(), seqsmooth::Error>(())
    /// ```
    pub fn chebyshev(n: usize, a: f64, b: f64) -> Result<Self, Error> {
        check_jacobi_degree(n)?;
        let (centre, half) = check_interval(a, b)?;
        let beta = (1..=n)
            .map(|k| if k == 1 { 0.5f64.sqrt() } else { 0.5 })
            .collect();
        Ok(Self {
            alpha: vec![0.0; n + 1],
            beta,
            mass: std::f64::consts::PI,
            centre,
            half,
        })
    }

    /// The discrete measure `Σ_j w_j δ(t − t_j)` (times in any order, weights `> 0`, e.g.
    /// `1/σ²(t_j)`), degrees `0..=n`: needs at least `n+1` distinct times. The interval is
    /// the times' span.
    ///
    /// ```
    /// use seqsmooth::basis::Jacobi;
    /// // three equal weights at -1, 0, 1: α = 0, β_1 = √(2/3), β_2 = √(1/3) (the discrete
    /// // Chebyshev polynomials of three points)
    /// let j = Jacobi::discrete(&[-1.0, 0.0, 1.0], &[1.0; 3], 2)?;
    /// assert!(j.alpha.iter().all(|a| a.abs() < 1e-15));
    /// assert!((j.beta[0] - (2.0f64 / 3.0).sqrt()).abs() < 1e-15);
    /// assert!((j.beta[1] - (1.0f64 / 3.0).sqrt()).abs() < 1e-15);
    /// assert!(Jacobi::discrete(&[0.0, 1.0], &[1.0; 2], 2).is_err()); // two times, degree 2
    /// # Ok::<(), seqsmooth::Error>(())
    /// ```
    pub fn discrete(times: &[f64], weights: &[f64], n: usize) -> Result<Self, Error> {
        check_jacobi_degree(n)?;
        if times.len() != weights.len() {
            return Err(Error::InvalidParameter {
                name: Param::Weights,
                value: weights.len().to_string(),
                reason: format!("one per time ({} times)", times.len()),
            });
        }
        crate::error::check_finite("time", times)?;
        if let Some((j, &w)) = weights
            .iter()
            .enumerate()
            .find(|(_, w)| !(w.is_finite() && **w > 0.0))
        {
            return Err(Error::InvalidParameter {
                name: Param::Weight,
                value: w.to_string(),
                reason: format!("weight {j} must be finite and above 0"),
            });
        }
        let mut sorted = times.to_vec();
        sorted.sort_by(f64::total_cmp);
        sorted.dedup();
        if sorted.len() <= n {
            return Err(Error::TooFewSamples {
                needed: n + 1,
                got: sorted.len(),
            });
        }
        let (a, b) = (sorted[0], sorted[sorted.len() - 1]);
        let (centre, half) = if a < b {
            check_interval(a, b)?
        } else {
            (a, 1.0) // one time, degree 0
        };
        let u: Vec<f64> = times.iter().map(|t| (t - centre) / half).collect();
        Self::from_points(&u, weights, n, centre, half)
    }

    /// The recurrence of the discrete measure at `u_j = (t_j − centre)/half` (weights checked).
    fn from_points(u: &[f64], w: &[f64], n: usize, centre: f64, half: f64) -> Result<Self, Error> {
        let mass: f64 = w.iter().sum();
        if !mass.is_normal() {
            return Err(Error::InvalidParameter {
                name: Param::Weights,
                value: mass.to_string(),
                reason: "their sum must be a normal double".into(),
            });
        }
        let (alpha, beta) = lanczos(u, w, mass, n)?;
        Ok(Self {
            alpha,
            beta,
            mass,
            centre,
            half,
        })
    }

    /// The measure `ω(t) dt` on `[a, b]`, degrees `0..=n`: the measure discretised (Gauss–
    /// Legendre or Gauss–Chebyshev of 64, 128, … points, by [`Weight`]) and taken as
    /// [`discrete`](Self::discrete) until two successive discretisations agree to `1e-14`
    /// (Gautschi's discretised Stieltjes procedure). `ω` must be finite and positive at the
    /// rule's points.
    ///
    /// ```
    /// use seqsmooth::basis::{Jacobi, Weight};
    /// // ω = 1 is Legendre
    /// let j = Jacobi::continuous(Weight::Smooth(&|_| 1.0), -1.0, 1.0, 4)?;
    /// let l = Jacobi::legendre(4, -1.0, 1.0)?;
    /// assert!(j.beta.iter().zip(&l.beta).all(|(a, b)| (a - b).abs() < 1e-14));
    /// # Ok::<(), seqsmooth::Error>(())
    /// ```
    pub fn continuous(weight: Weight<'_>, a: f64, b: f64, n: usize) -> Result<Self, Error> {
        check_jacobi_degree(n)?;
        let (centre, half) = check_interval(a, b)?;
        let mut previous: Option<Self> = None;
        for points in DISCRETISATION_POINTS {
            let (u, w) = discretise(weight, centre, half, points)?;
            let j = Self::from_points(&u, &w, n, centre, half)?;
            if let Some(p) = &previous {
                let change = j
                    .alpha
                    .iter()
                    .zip(&p.alpha)
                    .chain(j.beta.iter().zip(&p.beta))
                    .map(|(x, y)| (x - y).abs())
                    .fold(0.0, f64::max);
                if change <= DISCRETISATION_TOLERANCE {
                    return Ok(j);
                }
            }
            previous = Some(j);
        }
        Err(Error::InvalidParameter {
            name: Param::Weight,
            value: format!("on [{a}, {b}]"),
            reason: format!(
                "its recurrence did not settle to {DISCRETISATION_TOLERANCE:e} with {} points \
                 (a weight with singularities or sharp features: split the interval or use \
                 Weight::ChebyshevEnds for 1/sqrt end behaviour)",
                DISCRETISATION_POINTS[DISCRETISATION_POINTS.len() - 1]
            ),
        })
    }

    /// The degree `n` (the recurrence gives `b_0 … b_n`).
    pub fn degree(&self) -> usize {
        self.alpha.len() - 1
    }

    /// `b_0(t) … b_n(t)`, the orthonormal polynomials at time `t`, by the recurrence.
    pub fn orthonormal(&self, t: f64) -> Vec<f64> {
        self.orthonormal_at_offset(t - self.centre)
    }

    /// [`orthonormal`](Self::orthonormal) at `t = centre + offset`, for times too large to
    /// carry the offset's precision (Unix-epoch seconds).
    pub fn orthonormal_at_offset(&self, offset: f64) -> Vec<f64> {
        let u = offset / self.half;
        let mut b = Vec::with_capacity(self.alpha.len());
        b.push(1.0 / self.mass.sqrt());
        for k in 0..self.beta.len() {
            let before = if k > 0 {
                self.beta[k - 1] * b[k - 1]
            } else {
                0.0
            };
            b.push(((u - self.alpha[k]) * b[k] - before) / self.beta[k]);
        }
        b
    }

    /// The Gauss rule of `n+1` nodes for this measure ([`GaussRule::new`]).
    pub fn gauss(&self) -> Result<GaussRule, Error> {
        GaussRule::new(self)
    }
}

/// `points` nodes `u_j ∈ (−1, 1)` and weights (`ω(t_j)` times the rule's weight, in `t`)
/// discretising `ω(t) dt` on `[c − h, c + h]`.
fn discretise(
    weight: Weight<'_>,
    centre: f64,
    half: f64,
    points: usize,
) -> Result<(Vec<f64>, Vec<f64>), Error> {
    let (u, rule, f): (Vec<f64>, Vec<f64>, &dyn Fn(f64) -> f64) = match weight {
        Weight::Smooth(f) => {
            let g = Jacobi::legendre(points - 1, -1.0, 1.0)?.gauss()?;
            // dt = h du
            let w = g.weights.iter().map(|w| w * half).collect();
            (g.offsets, w, f) // centre 0: the offsets are u
        }
        Weight::ChebyshevEnds(f) => {
            // dt/√((t−a)(b−t)) = du/√(1−u²): Gauss–Chebyshev, nodes cos((2j+1)π/2M), weights π/M
            let m = points as f64;
            let u = (0..points)
                .map(|j| ((2 * j + 1) as f64 * std::f64::consts::PI / (2.0 * m)).cos())
                .collect();
            (u, vec![std::f64::consts::PI / m; points], f)
        }
    };
    let mut w = Vec::with_capacity(points);
    for (&u, r) in u.iter().zip(rule) {
        let t = centre + half * u;
        let v = f(t);
        if !(v.is_finite() && v > 0.0) {
            return Err(Error::InvalidParameter {
                name: Param::Weight,
                value: v.to_string(),
                reason: format!("ω({t}) must be finite and above 0 inside the interval"),
            });
        }
        w.push(r * v);
    }
    Ok((u, w))
}

/// The Lanczos process on `diag(u)` from `q_0 = √(w/μ₀)` in double-word arithmetic, each new
/// vector orthogonalised once against all before it: `α_0 … α_n`, `β_1 … β_n`, rounded to
/// `f64`. In `f64` (twice reorthogonalised) the recurrence carried errors of order `ε` that
/// the quadrature of degree `2n+1` amplifies by up to `(2n+1)²`: Lemma 3 held to 3.4e-12 at
/// `N = 100`, `n = 20`; in double words to 3.2e-13 (ACCURACY.md, "Gauss rules"), at 5-8× the
/// cost of this offline step.
fn lanczos(u: &[f64], w: &[f64], mass: f64, n: usize) -> Result<(Vec<f64>, Vec<f64>), Error> {
    let root_mass = dw::sqrt((mass, 0.0));
    let mut q: Vec<Vec<DoubleWord>> = vec![w
        .iter()
        .map(|&w| dw::div(dw::sqrt((w, 0.0)), root_mass))
        .collect()];
    let (mut alpha, mut beta) = (Vec::with_capacity(n + 1), Vec::with_capacity(n));
    for k in 0..=n {
        let mut v: Vec<DoubleWord> = u
            .iter()
            .zip(&q[k])
            .map(|(&u, q)| dw::mul_f64(*q, u))
            .collect();
        alpha.push(dw::round(&dw::dot(&q[k], &v)));
        if k == n {
            break;
        }
        for qi in &q {
            let c = dw::dot(qi, &v);
            v.iter_mut()
                .zip(qi)
                .for_each(|(v, q)| *v = dw::sub(*v, dw::mul(c, *q)));
        }
        let norm = dw::sqrt(dw::dot(&v, &v));
        // With n+1 distinct points the next polynomial is not zero on them; rounding alone
        // leaves a norm near ε.
        if norm.0.is_nan() || norm.0 <= 1e3 * f64::EPSILON {
            return Err(Error::NotDetermined {
                samples: u.len() as u64,
                why: format!(
                    "the points carry no polynomial of degree {} (their weights leave the \
                     recurrence degenerate)",
                    k + 1
                ),
            });
        }
        beta.push(dw::round(&norm));
        let inverse = dw::div((1.0, 0.0), norm);
        v.iter_mut().for_each(|v| *v = dw::mul(*v, inverse));
        q.push(v);
    }
    Ok((alpha, beta))
}
