//! The scaled unscented transform (Julier and Uhlmann 1997, "A new extension of the Kalman
//! filter to nonlinear systems"; Julier 2002, "The scaled unscented transformation"; Wan and
//! van der Merwe 2000, "The unscented Kalman filter for nonlinear estimation", (15)): a mean
//! `x` and covariance `S` of `n` states are carried through a map by `2n + 1` sigma points,
//!
//! `λ = α²(n + κ) − n`, `𝒳_0 = x`, `𝒳_i = x + [√((n + λ) S)]_i`, `𝒳_{n+i} = x − [√((n + λ) S)]_i`
//! (`i = 1..n`, the columns of the lower Cholesky factor `L`, `L Lᵀ = (n + λ) S`),
//!
//! `W_0^(m) = λ/(n + λ)`, `W_0^(c) = λ/(n + λ) + 1 − α² + β`, `W_i^(m) = W_i^(c) = 1/(2(n + λ))`,
//!
//! the mean of the mapped points `ȳ = Σ W_i^(m) 𝒴_i` and their covariance
//! `Σ W_i^(c) (𝒴_i − ȳ)(𝒴_i − ȳ)ᵀ` (Wan and van der Merwe (15), (17)). The columns of `L` are
//! the rows of the upper factor `U = Lᵀ` that filterpy's `MerweScaledSigmaPoints` uses
//! (`scipy.linalg.cholesky`), in the same order: the same set of points.
//!
//! The mean is taken about the central point, `ȳ = 𝒴_0 + Σ_{i≥1} W_i^(m) r(𝒴_i, 𝒴_0)` with the
//! residual `r` of the quantity (an angle's wrapped): equal to `Σ W_i^(m) 𝒴_i` since the weights
//! sum to 1, but without the cancellation of the large `W_0^(m) ≈ −1/α²` against the other
//! weights when `α` is small (the plain sum loses about `|W_0^(m)| ε |ȳ|`), and correct for an
//! angle near `±π`.

use crate::error::{Error, Param};
use nalgebra::{Cholesky, DMatrix, DVector};

/// The scaled sigma points' parameters `α`, `β`, `κ` (Wan and van der Merwe 2000, (15)).
///
/// The default is `α = 1`, `β = 2`, `κ = 0`: `λ = 0`, the points at `±√n σ` along the
/// Cholesky columns, every covariance weight non-negative (`W_0^(c) = 2`, `W_i = 1/(2n)`), so
/// the transformed covariance is a sum of positive semidefinite terms. A small `α` (1e-3, a
/// common choice) puts the points at `±α √n σ` and weighs the central one by about `−1/α²`:
/// a central-difference filter whose covariance is a difference of large numbers.
///
/// ```
/// use seqsmooth::kalman::sigma_points::SigmaPoints;
/// let w = SigmaPoints::default().weights(2).unwrap();
/// assert_eq!((w.lambda, w.mean[0], w.covariance[0], w.mean[1]), (0.0, 0.0, 2.0, 0.25));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SigmaPoints {
    alpha: f64,
    beta: f64,
    kappa: f64,
}

impl Default for SigmaPoints {
    fn default() -> Self {
        Self {
            alpha: 1.0,
            beta: 2.0,
            kappa: 0.0,
        }
    }
}

impl SigmaPoints {
    /// `α > 0` (the spread), `β` (the prior's fourth moment; 2 for a Gaussian), `κ`
    /// (secondary spread; `n + κ > 0` is checked by [`Self::weights`]), all finite.
    ///
    /// ```
    /// use seqsmooth::kalman::sigma_points::SigmaPoints;
    /// assert!(SigmaPoints::new(0.5, 2.0, 0.0).is_ok());
    /// assert!(SigmaPoints::new(0.0, 2.0, 0.0).is_err());
    /// assert!(SigmaPoints::new(1.0, f64::NAN, 0.0).is_err());
    /// ```
    pub fn new(alpha: f64, beta: f64, kappa: f64) -> Result<Self, Error> {
        let bad = |name, value: f64, reason: &str| Error::InvalidParameter {
            name,
            value: value.to_string(),
            reason: reason.into(),
        };
        if !(alpha.is_finite() && alpha > 0.0) {
            return Err(bad(
                Param::SigmaPointAlpha,
                alpha,
                "must be finite and above 0",
            ));
        }
        if !beta.is_finite() {
            return Err(bad(Param::SigmaPointBeta, beta, "must be finite"));
        }
        if !kappa.is_finite() {
            return Err(bad(Param::SigmaPointKappa, kappa, "must be finite"));
        }
        Ok(Self { alpha, beta, kappa })
    }

    /// `α`.
    ///
    /// ```
    /// use seqsmooth::kalman::sigma_points::SigmaPoints;
    /// assert_eq!(SigmaPoints::default().alpha(), 1.0);
    /// ```
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// `β`.
    ///
    /// ```
    /// use seqsmooth::kalman::sigma_points::SigmaPoints;
    /// assert_eq!(SigmaPoints::default().beta(), 2.0);
    /// ```
    pub fn beta(&self) -> f64 {
        self.beta
    }

    /// `κ`.
    ///
    /// ```
    /// use seqsmooth::kalman::sigma_points::SigmaPoints;
    /// assert_eq!(SigmaPoints::default().kappa(), 0.0);
    /// ```
    pub fn kappa(&self) -> f64 {
        self.kappa
    }

    /// The weights for `n ≥ 1` states (Wan and van der Merwe (15)); refused unless
    /// `n + λ = α²(n + κ) > 0` and every weight is finite.
    ///
    /// ```
    /// use seqsmooth::kalman::sigma_points::SigmaPoints;
    /// // α = 0.5, κ = 0, n = 6: λ = −4.5, W_0 = −3, W_i = 1/3.
    /// let w = SigmaPoints::new(0.5, 2.0, 0.0).unwrap().weights(6).unwrap();
    /// assert_eq!((w.lambda, w.mean[0], w.mean[12]), (-4.5, -3.0, 1.0 / 3.0));
    /// assert!(SigmaPoints::new(1.0, 2.0, -6.0).unwrap().weights(6).is_err());
    /// // α² underflows: α is named, not κ.
    /// let e = SigmaPoints::new(1e-170, 2.0, 0.0).unwrap().weights(6).unwrap_err();
    /// assert!(matches!(e, seqsmooth::Error::InvalidParameter {
    ///     name: seqsmooth::Param::SigmaPointAlpha, .. }));
    /// ```
    pub fn weights(&self, n: usize) -> Result<Weights, Error> {
        let nf = n as f64;
        let lambda = self.alpha * self.alpha * (nf + self.kappa) - nf;
        let spread = nf + lambda;
        let c = 0.5 / spread;
        let w0 = lambda / spread;
        let w0c = w0 + (1.0 - self.alpha * self.alpha + self.beta);
        if n == 0 || !(spread > 0.0 && c.is_finite() && w0.is_finite() && w0c.is_finite()) {
            // n + κ > 0 with α² (n + κ) not a positive normal number: α is at fault (its
            // square underflows or overflows); otherwise κ is.
            let alpha_at_fault = n > 0 && nf + self.kappa > 0.0;
            return Err(Error::InvalidParameter {
                name: if alpha_at_fault {
                    Param::SigmaPointAlpha
                } else {
                    Param::SigmaPointKappa
                },
                value: if alpha_at_fault {
                    self.alpha.to_string()
                } else {
                    self.kappa.to_string()
                },
                reason: format!(
                    "n + lambda = alpha^2 (n + kappa) must be positive with finite weights \
                     (n = {n}, alpha = {})",
                    self.alpha
                ),
            });
        }
        let mut mean = vec![c; 2 * n + 1];
        let mut covariance = mean.clone();
        mean[0] = w0;
        covariance[0] = w0c;
        Ok(Weights {
            n,
            lambda,
            mean,
            covariance,
        })
    }
}

/// The weights of the `2n + 1` points for `n` states, and the points themselves.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Weights {
    /// The state dimension `n`.
    pub n: usize,
    /// `λ = α²(n + κ) − n`.
    pub lambda: f64,
    /// `W_i^(m)`, `i = 0..2n`.
    pub mean: Vec<f64>,
    /// `W_i^(c)`, `i = 0..2n`.
    pub covariance: Vec<f64>,
}

impl Weights {
    /// The sigma points of `(x, S)` as the columns of an `n × (2n + 1)` matrix (the order of
    /// the module's formula: the centre, then `x + L_i`, then `x − L_i`). `S` must be positive
    /// definite: when the Cholesky factorisation of `(n + λ) S` fails the error names the
    /// covariance as `what` with `t`, and a non-finite point is refused.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::sigma_points::SigmaPoints;
    /// use seqsmooth::Param;
    /// let w = SigmaPoints::default().weights(2).unwrap(); // n + λ = 2
    /// let x = DVector::from_vec(vec![1.0, 0.0]);
    /// let p = w.points(&x, &DMatrix::from_diagonal(&DVector::from_vec(vec![2.0, 8.0])), Param::Covariance, 0.0).unwrap();
    /// assert_eq!(p.column(1).as_slice(), &[3.0, 0.0]); // x + √(2·2) e_1
    /// assert_eq!(p.column(4).as_slice(), &[1.0, -4.0]); // x − √(2·8) e_2
    /// let not_pd = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 1.0]);
    /// assert!(w.points(&x, &not_pd, Param::Covariance, 0.0).is_err());
    /// ```
    pub fn points(
        &self,
        x: &DVector<f64>,
        s: &DMatrix<f64>,
        what: Param,
        t: f64,
    ) -> Result<DMatrix<f64>, Error> {
        let n = self.n;
        let scaled = s * (n as f64 + self.lambda);
        let Some(factor) = Cholesky::new(scaled) else {
            return Err(Error::InvalidParameter {
                name: what,
                value: format!("at t = {t}"),
                reason: "is not positive definite: the Cholesky factorisation of (n + lambda) S \
                         fails, so it has no sigma points"
                    .into(),
            });
        };
        let l = factor.l();
        let mut points = DMatrix::zeros(n, 2 * n + 1);
        points.column_mut(0).copy_from(x);
        for i in 0..n {
            let column = l.column(i);
            points.column_mut(i + 1).copy_from(&(x + column));
            points.column_mut(n + i + 1).copy_from(&(x - column));
        }
        if let Some(&value) = points.iter().find(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "sigma point entry",
                value,
            });
        }
        Ok(points)
    }

    /// The weighted mean of mapped points (the columns of `mapped`), about the central one:
    /// `ȳ_c = 𝒴_0c + Σ_{i≥1} W_i^(m) r(c, 𝒴_ic, 𝒴_0c)` with `r(c, a, b)` the residual `a − b` of
    /// component `c` (wrapped for an angle).
    ///
    /// ```
    /// use nalgebra::DMatrix;
    /// use seqsmooth::kalman::sigma_points::SigmaPoints;
    /// let w = SigmaPoints::default().weights(1).unwrap(); // W = (0, 1/2, 1/2)
    /// let y = DMatrix::from_row_slice(1, 3, &[0.0, 1.0, 3.0]);
    /// assert_eq!(w.mean_of(&y, |_, a, b| a - b)[0], 2.0);
    /// ```
    pub fn mean_of(
        &self,
        mapped: &DMatrix<f64>,
        residual: impl Fn(usize, f64, f64) -> f64,
    ) -> DVector<f64> {
        DVector::from_fn(mapped.nrows(), |c, _| {
            let centre = mapped[(c, 0)];
            let offset: f64 = (1..mapped.ncols())
                .map(|i| self.mean[i] * residual(c, mapped[(c, i)], centre))
                .sum();
            centre + offset
        })
    }

    /// The deviations `r(𝒴_i, ȳ)` of mapped points from their mean, one column per point.
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::kalman::sigma_points::SigmaPoints;
    /// let w = SigmaPoints::default().weights(1).unwrap();
    /// let y = DMatrix::from_row_slice(1, 3, &[0.0, 1.0, 3.0]);
    /// let d = w.deviations(&y, &DVector::from_vec(vec![2.0]), |_, a, b| a - b);
    /// assert_eq!(d.as_slice(), &[-2.0, -1.0, 1.0]);
    /// ```
    pub fn deviations(
        &self,
        mapped: &DMatrix<f64>,
        mean: &DVector<f64>,
        residual: impl Fn(usize, f64, f64) -> f64,
    ) -> DMatrix<f64> {
        DMatrix::from_fn(mapped.nrows(), mapped.ncols(), |c, i| {
            residual(c, mapped[(c, i)], mean[c])
        })
    }

    /// `Σ_i W_i^(c) a_i b_iᵀ` for deviations `a` and `b` (one column per point): a covariance
    /// (`a` and `b` the same matrix: then exactly symmetric, its lower triangle the upper's) or
    /// a cross-covariance (Wan and van der Merwe (17)).
    ///
    /// ```
    /// use nalgebra::DMatrix;
    /// use seqsmooth::kalman::sigma_points::SigmaPoints;
    /// let w = SigmaPoints::default().weights(1).unwrap(); // Wc = (2, 1/2, 1/2)
    /// let d = DMatrix::from_row_slice(1, 3, &[0.0, -1.0, 1.0]);
    /// assert_eq!(w.covariance_of(&d, &d)[(0, 0)], 1.0);
    /// ```
    pub fn covariance_of(&self, a: &DMatrix<f64>, b: &DMatrix<f64>) -> DMatrix<f64> {
        let mut out = DMatrix::zeros(a.nrows(), b.nrows());
        for (i, &w) in self.covariance.iter().enumerate() {
            let (ai, bi) = (a.column(i), b.column(i));
            for c in 0..b.nrows() {
                let wb = w * bi[c];
                for r in 0..a.nrows() {
                    out[(r, c)] += ai[r] * wb;
                }
            }
        }
        if std::ptr::eq(a, b) {
            for c in 0..out.ncols() {
                for r in c + 1..out.nrows() {
                    out[(r, c)] = out[(c, r)];
                }
            }
        }
        out
    }
}
