//! Luenberger (1967), "A simple polynomial estimator": expanding memory in continuous time.
//! The polynomial `P(T, t) = Σ_{i=1}^{n} a_i(T) t^{i−1}` minimising `∫_0^T [x(t) − P(T, t)]² dt`
//! follows `a_i'(T) = (b_i/T^i) ε(T)`, `ε(T) = x(T) − P(T, T)`, with `b = H⁻¹·1`, `H` the
//! `n × n` Hilbert matrix `[1/(i + j − 1)]` (his update law and `Hb = 1`; `n` coefficients,
//! degree `m = n − 1`).
//!
//! | what | function | |
//! |---|---|---|
//! | `b = H⁻¹·1` by exact inversion | [`hilbert_gains`] | any `n`, in rationals |
//! | `b_j = (−1)^(n+j) (n+j−1)! / (((j−1)!)² (n−j)!)` | [`luenberger_gains`] | his explicit expression, corrected |
//! | his explicit expression as printed | [`luenberger_gains_as_printed`] | `1/((i−1)!(j−1)!)` unsquared: wrong from `n = 3` |
//! | `g_k = Σ_{i=k+1}^{n} C(i−1, k) b_i` | [`taylor_gains`] | the law for Taylor coefficients about `T` |
//! | the estimator, discretised | [`ContinuousExpandingMemory`] | fourth-order Runge–Kutta on the Taylor form |
//!
//! The printed expression is the Trench–Scheinok inverse of the Cauchy matrix summed over a
//! row; its last factor must be squared (the inverse-Hilbert entry has `C(i+j−2, i−1)²`): as
//! printed it equals `H⁻¹·1` only for `n = 1, 2` (tests/expanding_continuous.rs).
//!
//! In Taylor coefficients about the current time, `c_k(T) = P^(k)(T, T)/k!`, the law reads
//! `c_k' = (k+1) c_{k+1} + g_k ε(T)/T^(k+1)` — the continuous counterpart of Morrison's expanding
//! memory, whose gains satisfy `n^(k+1) h_k(n) → g_k` (Table 9.1); `g_0 = (m+1)²`. It is
//! better conditioned than the law for the `a_i` (powers of `t` about 0), so the estimator runs
//! on it.

use crate::calculus::{choose, factorial};
use crate::error::{Error, Param};
use crate::linalg::inverse_exact;
use crate::scalar::{Rational, Scalar};
use nalgebra::DMatrix;
use num_traits::Zero;

/// The most coefficients `n` of the gain tables ([`hilbert_gains`], [`luenberger_gains`]) a
/// front end asks for: degree 59, where the exact inverse of the Hilbert matrix already holds
/// integers of over a hundred digits (a bound on one call's work).
pub const MAX_COEFFICIENTS: usize = 60;

/// The range of the coefficients `n` of a gain table: `1 ≤ n ≤ MAX_COEFFICIENTS` (every
/// front end's check).
///
/// ```
/// use seqsmooth::polynomial::expanding::continuous::{check_coefficients, MAX_COEFFICIENTS};
/// assert!(check_coefficients(1).is_ok() && check_coefficients(MAX_COEFFICIENTS).is_ok());
/// assert!(check_coefficients(0).is_err() && check_coefficients(MAX_COEFFICIENTS + 1).is_err());
/// ```
pub fn check_coefficients(n: usize) -> Result<(), Error> {
    if !(1..=MAX_COEFFICIENTS).contains(&n) {
        return Err(Error::InvalidParameter {
            name: Param::Coefficients,
            value: n.to_string(),
            reason: format!("must be from 1 to {MAX_COEFFICIENTS} coefficients"),
        });
    }
    Ok(())
}

/// `b = H⁻¹·1` by exact inversion of the `n × n` Hilbert matrix (use `T = Rational`; in `f64`
/// the inversion loses accuracy from `n ≈ 10`).
///
/// ```
/// use seqsmooth::polynomial::expanding::continuous::hilbert_gains;
/// use seqsmooth::scalar::Rational;
/// let b: Vec<Rational> = hilbert_gains(3);
/// assert_eq!(b, [3, -24, 30].map(|v| Rational::from_integer(v.into())));
/// ```
pub fn hilbert_gains<T: Scalar>(n: usize) -> Vec<T> {
    let h = DMatrix::from_fn(n, n, |i, j| T::ratio(1, (i + j + 1) as i64));
    let inverse = inverse_exact(&h).expect("the Hilbert matrix is invertible");
    (0..n)
        .map(|i| (0..n).fold(T::zero(), |s, j| s + inverse[(i, j)].clone()))
        .collect()
}

/// `b_j = (−1)^(n+j) (n+j−1)! / (((j−1)!)² (n−j)!)`, `j = 1..n`: Luenberger's explicit
/// expression with its factorial squared, summed in closed form (integers, `Σ b_j = n²`).
///
/// ```
/// use seqsmooth::polynomial::expanding::continuous::luenberger_gains;
/// assert_eq!(luenberger_gains::<f64>(4), vec![-4.0, 60.0, -180.0, 140.0]);
/// ```
pub fn luenberger_gains<T: Scalar>(n: usize) -> Vec<T> {
    // In exact integers, rounded once (so that f64 holds them exactly while they are below
    // 2^53, to n = 21).
    (1..=n)
        .map(|j| {
            let f = factorial::<Rational>(j - 1);
            let b =
                factorial::<Rational>(n + j - 1) / (f.clone() * f * factorial::<Rational>(n - j));
            T::from_rational(&if (n + j).is_multiple_of(2) { b } else { -b })
        })
        .collect()
}

/// Luenberger's explicit expression exactly as printed,
/// `b_j = Σ_i (−1)^(i+j)/(i+j−1) · (n−1+i)!(n−1+j)!/((n−i)!(n−j)!) · 1/((i−1)!(j−1)!)`:
/// kept to show the misprint (it is `H⁻¹·1` only for `n ≤ 2`); use [`luenberger_gains`].
///
/// ```
/// use seqsmooth::polynomial::expanding::continuous::{luenberger_gains, luenberger_gains_as_printed};
/// assert_eq!(luenberger_gains_as_printed::<f64>(2), luenberger_gains::<f64>(2));
/// assert_ne!(luenberger_gains_as_printed::<f64>(3), luenberger_gains::<f64>(3));
/// ```
pub fn luenberger_gains_as_printed<T: Scalar>(n: usize) -> Vec<T> {
    (1..=n)
        .map(|j| {
            (1..=n).fold(T::zero(), |s, i| {
                let sign = if (i + j).is_multiple_of(2) {
                    T::one()
                } else {
                    -T::one()
                };
                let term = factorial::<T>(n - 1 + i) * factorial::<T>(n - 1 + j)
                    / (factorial::<T>(n - i)
                        * factorial::<T>(n - j)
                        * factorial::<T>(i - 1)
                        * factorial::<T>(j - 1)
                        * T::from_i64((i + j - 1) as i64));
                s + sign * term
            })
        })
        .collect()
}

/// The Taylor-form gains of degree `m` (`n = m + 1` coefficients):
/// `g_k = Σ_{i=k+1}^{n} C(i−1, k) b_i`, `k = 0..m`.
///
/// ```
/// use seqsmooth::polynomial::expanding::continuous::taylor_gains;
/// assert_eq!(taylor_gains::<f64>(2), vec![9.0, 36.0, 30.0]);
/// ```
pub fn taylor_gains<T: Scalar>(m: usize) -> Vec<T> {
    let b = luenberger_gains::<Rational>(m + 1);
    (0..=m)
        .map(|k| {
            let g = (k + 1..=m + 1).fold(Rational::zero(), |s, i| {
                s + choose::<Rational>(i - 1, k) * b[i - 1].clone()
            });
            T::from_rational(&g)
        })
        .collect()
}

/// Luenberger's estimator of degree `m` on a continuously observed `x(t)`, discretised: the
/// Taylor form `c_k' = (k+1) c_{k+1} + g_k (x(T) − c_0)/T^(k+1)` integrated by the classical
/// fourth-order Runge–Kutta method in steps of `h`, so that the coefficients follow the
/// least-squares polynomial of `x` over `[start, start + T]` to `O(h⁴)`. The law is singular
/// at `T = 0`: the estimator starts at `T₀ > 0` from the fit over `[start, start + T₀]`.
///
/// ```
/// use seqsmooth::polynomial::expanding::continuous::ContinuousExpandingMemory;
/// // a line is its own fit: the estimator keeps it exactly
/// let mut f = ContinuousExpandingMemory::new(1, 0.0, 1.0, &[3.0, 2.0])?; // x = 1 + 2t at T = 1
/// f.advance(|t| 1.0 + 2.0 * t, 4.0, 40)?;
/// let x = f.derivatives();
/// assert!((x[0] - 11.0).abs() < 1e-12 && (x[1] - 2.0).abs() < 1e-12);
/// # Ok::<(), seqsmooth::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct ContinuousExpandingMemory {
    start: f64,
    elapsed: f64,
    /// `c_k = x^(k)/k!` about `start + elapsed`.
    c: Vec<f64>,
    g: Vec<f64>,
}

impl ContinuousExpandingMemory {
    /// Degree `m` (`≤ 20`: `b` is then exact in `f64`), observation from `start`, started at
    /// `start + elapsed` (`elapsed > 0`) with the fit's derivatives there (`m+1` values).
    pub fn new(m: usize, start: f64, elapsed: f64, derivatives: &[f64]) -> Result<Self, Error> {
        if m > 20 {
            return Err(Error::DegreeOutOfRange { degree: m, max: 20 });
        }
        crate::error::check_finite("start", &[start])?;
        if !(elapsed.is_finite() && elapsed > 0.0) {
            return Err(Error::InvalidParameter {
                name: Param::Elapsed,
                value: elapsed.to_string(),
                reason: "the law is singular at T = 0: start from a fit over some T > 0".into(),
            });
        }
        if derivatives.len() != m + 1 {
            return Err(Error::InvalidParameter {
                name: Param::Derivatives,
                value: derivatives.len().to_string(),
                reason: format!("degree {m} needs {} (x, x', …)", m + 1),
            });
        }
        crate::error::check_finite("derivative", derivatives)?;
        let c = derivatives
            .iter()
            .enumerate()
            .map(|(k, d)| d / factorial::<f64>(k))
            .collect();
        Ok(Self {
            start,
            elapsed,
            c,
            g: taylor_gains(m),
        })
    }

    /// `T`, the time observed so far.
    pub fn elapsed(&self) -> f64 {
        self.elapsed
    }

    /// The fit's derivatives `x^(k) = k! c_k` at `start + T`.
    pub fn derivatives(&self) -> Vec<f64> {
        self.c
            .iter()
            .enumerate()
            .map(|(k, c)| c * factorial::<f64>(k))
            .collect()
    }

    /// Observes `x` for `duration` more, in `steps` Runge–Kutta steps; on an error (a
    /// non-finite `x` or coefficient) the estimator is as before.
    pub fn advance(
        &mut self,
        x: impl Fn(f64) -> f64,
        duration: f64,
        steps: usize,
    ) -> Result<(), Error> {
        if !(duration.is_finite() && duration > 0.0) || steps == 0 {
            return Err(Error::InvalidParameter {
                name: Param::Duration,
                value: format!("{duration} in {steps} steps"),
                reason: "needs a duration above 0 and at least one step".into(),
            });
        }
        let h = duration / steps as f64;
        let mut c = self.c.clone();
        let mut t = self.elapsed;
        let rate = |t: f64, c: &[f64]| -> Vec<f64> {
            let e = x(self.start + t) - c[0];
            let mut power = t;
            (0..c.len())
                .map(|k| {
                    let next = c.get(k + 1).map_or(0.0, |c| (k + 1) as f64 * c);
                    let r = next + self.g[k] * e / power;
                    power *= t;
                    r
                })
                .collect()
        };
        let along = |c: &[f64], k: &[f64], s: f64| -> Vec<f64> {
            c.iter().zip(k).map(|(c, k)| c + s * k).collect()
        };
        for i in 0..steps {
            let k1 = rate(t, &c);
            let k2 = rate(t + h / 2.0, &along(&c, &k1, h / 2.0));
            let k3 = rate(t + h / 2.0, &along(&c, &k2, h / 2.0));
            let k4 = rate(t + h, &along(&c, &k3, h));
            for (j, cj) in c.iter_mut().enumerate() {
                *cj += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
            }
            t = self.elapsed + (i + 1) as f64 * h;
        }
        crate::error::check_finite("coefficient", &c)?;
        self.c = c;
        self.elapsed = t;
        Ok(())
    }
}
