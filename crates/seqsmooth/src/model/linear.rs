//! Constant-coefficient linear dynamics `dX/dt = A X` (Morrison §4.6): the transition matrix
//! `Φ(ζ) = e^{ζA} = Σ_ν (ζA)^ν/ν!` (4.6.24)-(4.6.28), with `Φ(ζ₁)Φ(ζ₂) = Φ(ζ₁+ζ₂)`,
//! `Φ(0) = I` and `Φ(ζ)⁻¹ = Φ(−ζ)` (4.6.29)-(4.6.41), forwards or backwards in time.
//!
//! A nilpotent `A` (some power `A^k`, `k ≤ n`, exactly zero in doubles: every polynomial model,
//! (4.6.42)'s `[[−1, 1], [−1, 1]]`) gets the finite series `Σ_{ν<k} ζ^ν A^ν/ν!`, whose terms are
//! kept from construction and summed by Horner's rule (the powers are exact for an integer
//! `A`; a nilpotent `A` whose powers do not reach zero exactly in doubles is treated as any
//! other, to rounding). Any other `A` gets nalgebra's
//! `Matrix::exp` of `ζA` (scaling and squaring with a Padé approximant of degree 3 to 13 chosen
//! by the norm, Al-Mohy and Higham 2009).

use crate::error::{Error, Param};
use nalgebra::DMatrix;

/// `dX/dt = A X` with a constant square `A`.
///
/// ```
/// use nalgebra::DMatrix;
/// use seqsmooth::model::linear::LinearDynamics;
/// // Morrison (4.6.51): A = [[0, 1], [−1, 0]] gives the rotation [[cos ζ, sin ζ], [−sin ζ, cos ζ]].
/// let d = LinearDynamics::new(DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -1.0, 0.0])).unwrap();
/// let p = d.transition(0.5).unwrap();
/// assert!((p[(0, 1)] - 0.5_f64.sin()).abs() < 1e-15 && (p[(1, 1)] - 0.5_f64.cos()).abs() < 1e-15);
/// ```
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LinearDynamics {
    a: DMatrix<f64>,
    /// `A^ν/ν!` for `ν = 0..k` when `A^k = 0` (nilpotent), else empty.
    series: Vec<DMatrix<f64>>,
}

impl LinearDynamics {
    /// The dynamics of `A` (square, finite).
    ///
    /// ```
    /// use nalgebra::DMatrix;
    /// use seqsmooth::model::linear::LinearDynamics;
    /// assert!(LinearDynamics::new(DMatrix::zeros(2, 3)).is_err());
    /// ```
    pub fn new(a: DMatrix<f64>) -> Result<Self, Error> {
        let (n, cols) = a.shape();
        let bad = |value: String, reason: &str| Error::InvalidParameter {
            name: Param::DynamicsMatrixA,
            value,
            reason: reason.into(),
        };
        if n != cols || n == 0 {
            return Err(bad(format!("{n}x{cols}"), "must be square and not empty"));
        }
        if let Some((k, v)) = a.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(bad(
                format!("entry [{}, {}] = {v}", k % n, k / n),
                "must be finite",
            ));
        }
        // A^ν until a power vanishes (nilpotent: by ν = n at the latest). The powers are
        // multiplied undivided, so that an integer A's are exact and reach zero exactly.
        let mut series = vec![DMatrix::identity(n, n)];
        let mut power = DMatrix::identity(n, n);
        let mut factorial = 1.0;
        let mut nilpotent = false;
        for nu in 1..=n {
            power = &power * &a;
            if power.iter().all(|&v| v == 0.0) {
                nilpotent = true;
                break;
            }
            factorial *= nu as f64;
            series.push(&power / factorial);
        }
        if !nilpotent {
            series.clear();
        }
        Ok(Self { a, series })
    }

    /// `A`.
    ///
    /// ```
    /// use nalgebra::DMatrix;
    /// use seqsmooth::model::linear::LinearDynamics;
    /// let d = LinearDynamics::new(DMatrix::identity(2, 2)).unwrap();
    /// assert_eq!(d.matrix(), &DMatrix::identity(2, 2));
    /// ```
    pub fn matrix(&self) -> &DMatrix<f64> {
        &self.a
    }

    /// Whether `A` is nilpotent in doubles (then [`Self::transition`] is the finite series).
    ///
    /// ```
    /// use nalgebra::DMatrix;
    /// use seqsmooth::model::linear::LinearDynamics;
    /// let a = DMatrix::from_row_slice(2, 2, &[-1.0, 1.0, -1.0, 1.0]); // (4.6.42): A² = 0
    /// assert!(LinearDynamics::new(a).unwrap().is_nilpotent());
    /// ```
    pub fn is_nilpotent(&self) -> bool {
        !self.series.is_empty()
    }

    /// The state dimension `n`.
    ///
    /// ```
    /// use nalgebra::DMatrix;
    /// use seqsmooth::model::linear::LinearDynamics;
    /// assert_eq!(LinearDynamics::new(DMatrix::zeros(3, 3)).unwrap().dimension(), 3);
    /// ```
    pub fn dimension(&self) -> usize {
        self.a.nrows()
    }

    /// `Φ(ζ) = e^{ζA}`, taking a state from `t` to `t + ζ` (`ζ < 0`: backwards); refused when
    /// `ζ` is not finite or a number of `Φ(ζ)` is beyond the double range.
    ///
    /// ```
    /// use nalgebra::DMatrix;
    /// use seqsmooth::model::linear::LinearDynamics;
    /// // (4.6.42)-(4.6.50): Φ(ζ) = [[1 − ζ, ζ], [−ζ, 1 + ζ]], exactly.
    /// let d = LinearDynamics::new(DMatrix::from_row_slice(2, 2, &[-1.0, 1.0, -1.0, 1.0])).unwrap();
    /// assert_eq!(d.transition(3.0).unwrap(), DMatrix::from_row_slice(2, 2, &[-2.0, 3.0, -3.0, 4.0]));
    /// ```
    pub fn transition(&self, zeta: f64) -> Result<DMatrix<f64>, Error> {
        let refuse = |reason: &str| Error::InvalidParameter {
            name: Param::Step,
            value: zeta.to_string(),
            reason: reason.into(),
        };
        if !zeta.is_finite() {
            return Err(refuse("must be finite"));
        }
        let phi = match self.series.split_last() {
            Some((last, rest)) => rest
                .iter()
                .rev()
                .fold(last.clone(), |acc, term| acc * zeta + term),
            None => (&self.a * zeta).exp(),
        };
        if phi.iter().all(|v| v.is_finite()) {
            Ok(phi)
        } else {
            Err(refuse(
                "e^(step A) is beyond the double range (about 1.8e308)",
            ))
        }
    }
}
