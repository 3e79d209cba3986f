//! Batch estimation: weighted least-squares polynomial fits on arbitrary timestamps, and the
//! minimum-variance and least-squares estimates of any state from stacked linear observations
//! ([`batch`]), and whether linear observations of linear dynamics determine the state
//! ([`observability`](mod@observability)).
//!
//! [`PolynomialFit`] solves the weighted least-squares problem by a Householder QR factorisation
//! in the Legendre basis on the data interval mapped to `[-1, 1]` (condition number of order
//! `√(2m+1)` on evenly spread data, against `~10^(0.6 m)` for monomials), never by the normal
//! equations (Morrison §6.5; Lear's note on conditioning). It is the batch counterpart of the
//! recursive filters and their test oracle.

pub mod batch;
pub mod bootstrap;
pub mod curve;
pub mod gauss_newton;
pub mod observability;
pub mod sliding;

pub use batch::{least_squares, minimum_variance, BatchEstimate, NoiseCovariance};
pub use observability::{observability, Observability};

use crate::basis::legendre::taylor_table;
use crate::error::{Error, Param};
use crate::model::taylor::scaling_diagonal;
use nalgebra::{DMatrix, DVector};

/// A weighted least-squares polynomial fit `p(t) = Σ_j c_j P_j((t - c)/w)`.
///
/// ```
/// use seqsmooth::estimate::PolynomialFit;
/// let t = [0.0, 1.0, 2.5, 4.0];
/// let y: Vec<f64> = t.iter().map(|t| 3.0 - t + 0.5 * t * t).collect();
/// let fit = PolynomialFit::new(&t, &y, None, 2).unwrap();
/// let d = fit.derivatives_at(4.0);
/// assert!((d[0] - 7.0).abs() < 1e-12 && (d[1] - 3.0).abs() < 1e-12 && (d[2] - 1.0).abs() < 1e-12);
/// ```
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct PolynomialFit {
    degree: usize,
    centre: f64,
    half_width: f64,
    coeffs: DVector<f64>,
    r: DMatrix<f64>,
    residual_sq: f64,
    samples: usize,
}

impl PolynomialFit {
    /// Fits a degree-`m` polynomial to `(t_k, y_k)` with optional weights `w_k > 0` (minimising
    /// `Σ w_k (y_k - p(t_k))²`). Needs at least `m+1` distinct times.
    ///
    /// ```
    /// use seqsmooth::estimate::PolynomialFit;
    /// use seqsmooth::Error;
    /// let fit = PolynomialFit::new(&[0.0, 1.0, 2.0], &[1.0, 2.0, 2.0], Some(&[1.0, 1.0, 4.0]), 1).unwrap();
    /// assert_eq!(fit.samples(), 3);
    /// assert!(matches!(PolynomialFit::new(&[0.0, 0.0], &[1.0, 2.0], None, 1), Err(Error::TooFewSamples { .. })));
    /// ```
    pub fn new(
        times: &[f64],
        values: &[f64],
        weights: Option<&[f64]>,
        m: usize,
    ) -> Result<Self, Error> {
        let n = times.len();
        if values.len() != n || weights.is_some_and(|w| w.len() != n) {
            return Err(Error::InvalidParameter {
                name: Param::InputLengths,
                value: format!("{} times, {} values", n, values.len()),
                reason: "times, values and weights must have the same length".into(),
            });
        }
        for (&t, &y) in times.iter().zip(values) {
            crate::error::check_sample(t, y, None)?;
        }
        let mut sorted: Vec<f64> = times.to_vec();
        sorted.sort_by(f64::total_cmp);
        sorted.dedup();
        if sorted.len() < m + 1 {
            return Err(Error::TooFewSamples {
                needed: m + 1,
                got: sorted.len(),
            });
        }
        let (lo, hi) = (sorted[0], sorted[sorted.len() - 1]);
        let centre = 0.5 * (lo + hi);
        let half_width = 0.5 * (hi - lo);
        let half_width = if half_width > 0.0 { half_width } else { 1.0 };
        let p = m + 1;
        let mut a = DMatrix::zeros(n, p);
        let mut b = DVector::zeros(n);
        for k in 0..n {
            let sw = weights.map_or(1.0, |w| w[k].sqrt());
            let v = crate::basis::legendre::values(m, (times[k] - centre) / half_width);
            for j in 0..p {
                a[(k, j)] = sw * v[j];
            }
            b[k] = sw * values[k];
        }
        let qr = a.qr();
        qr.q_tr_mul(&mut b);
        let r = qr.r();
        let mut c: Vec<f64> = b.iter().take(p).copied().collect();
        if !crate::linalg::solve_upper_in_place(&r, &mut c) {
            return Err(Error::TooFewSamples {
                needed: m + 1,
                got: sorted.len(),
            });
        }
        let residual_sq = b.iter().skip(p).map(|v| v * v).sum();
        Ok(Self {
            degree: m,
            centre,
            half_width,
            coeffs: DVector::from_vec(c),
            r,
            residual_sq,
            samples: n,
        })
    }

    /// Degree `m`.
    ///
    /// ```
    /// use seqsmooth::estimate::PolynomialFit;
    /// assert_eq!(PolynomialFit::new(&[0.0, 1.0, 2.0], &[1.0, 2.0, 2.0], None, 2).unwrap().degree(), 2);
    /// ```
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// Weighted residual sum of squares `Σ w_k (y_k - p(t_k))²`.
    ///
    /// ```
    /// use seqsmooth::estimate::PolynomialFit;
    /// // the best constant through 1, 3 is 2: residuals ±1
    /// let fit = PolynomialFit::new(&[0.0, 1.0], &[1.0, 3.0], None, 0).unwrap();
    /// assert!((fit.residual_sq() - 2.0).abs() < 1e-12);
    /// ```
    pub fn residual_sq(&self) -> f64 {
        self.residual_sq
    }

    /// The residual variance `e°/(N − m − 1)` of an unweighted fit of degree `m`
    /// ([`crate::stats::residual_variance`] of this fit; for a weighted fit, the variance of
    /// unit weight).
    ///
    /// ```
    /// use seqsmooth::estimate::PolynomialFit;
    /// let t = [0.0, 1.0, 2.0, 3.0];
    /// let y = [0.0, 1.0, 1.0, 2.0];
    /// let fit = PolynomialFit::new(&t, &y, None, 1).unwrap();
    /// // residuals -0.1, 0.3, -0.3, 0.1: e° = 0.2 over 4 − 2 dof
    /// assert!((fit.residual_variance().unwrap() - 0.1).abs() < 1e-12);
    /// ```
    pub fn residual_variance(&self) -> Result<f64, Error> {
        crate::stats::residual_variance(self.residual_sq, self.samples, self.degree + 1)
    }

    /// Number of samples fitted.
    ///
    /// ```
    /// use seqsmooth::estimate::PolynomialFit;
    /// assert_eq!(PolynomialFit::new(&[0.0, 1.0, 2.0, 3.0], &[0.0; 4], None, 1).unwrap().samples(), 4);
    /// ```
    pub fn samples(&self) -> usize {
        self.samples
    }

    /// A fit from its parts: the basis' `(centre, half width)`, the Legendre coefficients,
    /// the QR factor `R` they solve, the residual sum of squares and the sample count.
    pub(crate) fn from_parts(
        degree: usize,
        (centre, half_width): (f64, f64),
        coeffs: DVector<f64>,
        r: DMatrix<f64>,
        residual_sq: f64,
        samples: usize,
    ) -> Self {
        Self {
            degree,
            centre,
            half_width,
            coeffs,
            r,
            residual_sq,
            samples,
        }
    }

    /// The map from the coefficients to the derivatives at `t`.
    pub(crate) fn jacobian_at(&self, t: f64) -> DMatrix<f64> {
        self.jacobian(t)
    }

    fn jacobian(&self, t: f64) -> DMatrix<f64> {
        // Row k maps the Legendre coefficients to the k-th derivative at t.
        let u = (t - self.centre) / self.half_width;
        let tt = taylor_table(self.degree, self.degree, u);
        let d = scaling_diagonal::<f64>(self.degree, self.half_width);
        DMatrix::from_fn(self.degree + 1, self.degree + 1, |k, j| tt[(k, j)] * d[k])
    }

    /// `p(t), p'(t), …, p^(m)(t)` at any `t`.
    ///
    /// ```
    /// use seqsmooth::estimate::PolynomialFit;
    /// let fit = PolynomialFit::new(&[0.0, 1.0, 3.0], &[1.0, 3.0, 7.0], None, 1).unwrap(); // y = 1 + 2t
    /// let d = fit.derivatives_at(10.0);
    /// assert!((d[0] - 21.0).abs() < 1e-12 && (d[1] - 2.0).abs() < 1e-12);
    /// ```
    pub fn derivatives_at(&self, t: f64) -> Vec<f64> {
        (self.jacobian(t) * &self.coeffs).iter().copied().collect()
    }

    /// `p(t)` and its variance for unit noise, `x(t)ᵀ(AᵀWA)⁻¹x(t)` (the `(0, 0)` entry of
    /// [`Self::covariance_at`]), from the Legendre values at `t` alone: `O(m²)`, for the many
    /// points of a window (leverages, deleted residuals).
    ///
    /// ```
    /// use seqsmooth::estimate::PolynomialFit;
    /// let fit = PolynomialFit::new(&[0.0, 1.0, 3.0, 4.0], &[1.0, 3.1, 6.9, 9.0], None, 1).unwrap();
    /// let (p, v) = fit.value_and_vrf_at(2.0);
    /// assert!((p - fit.derivatives_at(2.0)[0]).abs() < 1e-12);
    /// assert!((v - fit.covariance_at(2.0)[(0, 0)]).abs() < 1e-15);
    /// assert!((v - 0.25).abs() < 1e-15); // at the centre of a line's symmetric samples: 1/n
    /// ```
    pub fn value_and_vrf_at(&self, t: f64) -> (f64, f64) {
        let mut x =
            crate::basis::legendre::values(self.degree, (t - self.centre) / self.half_width);
        let p = x.iter().zip(self.coeffs.iter()).map(|(a, c)| a * c).sum();
        crate::linalg::solve_upper_transpose_in_place(&self.r, &mut x);
        (p, x.iter().map(|v| v * v).sum())
    }

    /// Covariance of [`Self::derivatives_at`] when the weights are inverse variances (or
    /// `σ² ×` it for unit weights and noise variance `σ²`).
    ///
    /// ```
    /// use seqsmooth::estimate::PolynomialFit;
    /// // the mean of n unit-variance samples has variance 1/n
    /// let fit = PolynomialFit::new(&[0.0, 1.0, 2.0, 3.0], &[1.0, 2.0, 0.0, 1.0], None, 0).unwrap();
    /// assert!((fit.covariance_at(1.5)[(0, 0)] - 0.25).abs() < 1e-14);
    /// ```
    pub fn covariance_at(&self, t: f64) -> DMatrix<f64> {
        // (J R⁻¹)(J R⁻¹)ᵀ, row by row: (J R⁻¹)ᵀ = R⁻ᵀ Jᵀ by forward substitution.
        let j = self.jacobian(t);
        let p = self.degree + 1;
        let mut jr = DMatrix::zeros(p, p);
        let mut row = vec![0.0; p];
        for i in 0..p {
            for (c, v) in row.iter_mut().enumerate() {
                *v = j[(i, c)];
            }
            crate::linalg::solve_upper_transpose_in_place(&self.r, &mut row);
            for (c, v) in row.iter().enumerate() {
                jr[(i, c)] = *v;
            }
        }
        &jr * jr.transpose()
    }
}
