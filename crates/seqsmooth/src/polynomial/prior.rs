//! A prior for the expanding- and fading-memory polynomial filters: the derivatives
//! `x = (x, x', …, x^(m))` at a time `t₀` with their covariance `P`, so that the filter starts
//! from that information instead of from none.
//!
//! With a prior the expanding-memory filter is the Bayes filter of Morrison ch. 10: its
//! estimate minimises `(X − x)ᵀ P⁻¹ (X − x) + Σ_k (y_k − p(t_k))²/σ²`, (10.3.8)
//! `X* = [S⁻¹ + TᵀR⁻¹T]⁻¹ [TᵀR⁻¹Y + S⁻¹x]` with `S = P`, carried on by (10.2.40)-(10.2.44);
//! the prior enters as `m + 1` whitened pseudo-observations `L⁻¹ X ≈ L⁻¹ x` (`P = L Lᵀ`). The
//! fading-memory filter discounts the prior like a sample taken at `t₀` (the criterion
//! (13.2.1), or (14.2.10)-(14.2.11) per time, with the prior's term weighted
//! `θ^((t_n − t₀)/τ)`: the fading-memory Bayes filter (14.4.26)-(14.4.32)); its reported
//! covariance stays the true one (14.3.11), the prior counted as one more whitened
//! observation. The samples carry the noise `σ`, so the prior's weight against them needs it
//! (`σ²P⁻¹` in the engine's units): a prior needs the filter's noise σ. The gain engine's
//! fixed gains (Tables 9.1, 13.1) assume no prior and refuse one.

use crate::calculus::factorial;
use crate::error::{Error, Param};
use crate::kalman::noise::check_covariance;
use nalgebra::{Cholesky, DMatrix, DVector};

/// The prior of a polynomial filter: `state`, the derivatives `x, x', …, x^(m)` at `time`
/// (unscaled, in the caller's time units), and their `covariance` (symmetric positive
/// definite).
///
/// ```
/// use nalgebra::DMatrix;
/// use seqsmooth::polynomial::prior::Prior;
/// let p = Prior::new(0.0, vec![1.0, 2.0], DMatrix::identity(2, 2)).unwrap();
/// assert_eq!(p.degree(), 1);
/// assert!(Prior::new(0.0, vec![1.0, 2.0], DMatrix::zeros(2, 2)).is_err()); // no information form
/// ```
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Prior {
    /// The time `t₀` the prior refers to.
    pub time: f64,
    /// The derivatives at `time`.
    pub state: Vec<f64>,
    /// Their covariance.
    pub covariance: DMatrix<f64>,
}

impl Prior {
    /// A prior, checked: the time and state finite ([`Param::Prior`]), the covariance finite,
    /// symmetric and positive definite ([`Param::PriorCovariance`]: its inverse is the
    /// prior's information).
    pub fn new(time: f64, state: Vec<f64>, covariance: DMatrix<f64>) -> Result<Self, Error> {
        if !time.is_finite() || state.is_empty() || state.iter().any(|v| !v.is_finite()) {
            return Err(Error::InvalidParameter {
                name: Param::Prior,
                value: format!("state {state:?} at time {time}"),
                reason: "must be finite numbers at a finite time".into(),
            });
        }
        let n = state.len();
        check_covariance(&covariance, n, Param::PriorCovariance)?;
        if Cholesky::new(covariance.clone()).is_none() {
            return Err(Error::InvalidParameter {
                name: Param::PriorCovariance,
                value: format!("{covariance:?}"),
                reason: "must be positive definite (the filter holds its inverse)".into(),
            });
        }
        Ok(Self {
            time,
            state,
            covariance,
        })
    }

    /// The degree `m` of the state (`m + 1` derivatives).
    pub fn degree(&self) -> usize {
        self.state.len() - 1
    }

    /// Refuses a prior of other than degree `m`.
    pub(crate) fn check_degree(&self, m: usize) -> Result<(), Error> {
        if self.degree() != m {
            return Err(Error::InvalidParameter {
                name: Param::Prior,
                value: format!("of {} derivatives", self.state.len()),
                reason: format!("the filter of degree {m} has {} states", m + 1),
            });
        }
        Ok(())
    }

    /// The prior as whitened pseudo-observations of the coefficients `a` of
    /// `p(t) = Σ a_k (t − t₀)^k` (`x = D a`, `D = diag(k!)`), in the engine's units of noise
    /// `σ`: rows `W = σ L⁻¹ D` and values `σ L⁻¹ x` (`P = L Lᵀ`), so that `Wᵀ W / σ² = D P⁻¹ D`,
    /// the information of `a`.
    pub(crate) fn rows(&self, sigma: f64) -> (DMatrix<f64>, DVector<f64>) {
        let n = self.state.len();
        let l = Cholesky::new(self.covariance.clone())
            .expect("checked positive definite")
            .l();
        let d = DMatrix::from_fn(n, n, |i, j| if i == j { factorial(i) } else { 0.0 });
        let whiten = |m: DMatrix<f64>| {
            l.solve_lower_triangular(&m)
                .expect("a Cholesky factor is invertible")
                * sigma
        };
        let x = DMatrix::from_column_slice(n, 1, &self.state);
        (whiten(d), whiten(x).column(0).into_owned())
    }
}

/// Refuses a new noise σ once a prior is set (`prior` is `Some`): the prior was weighed
/// against the samples by the σ it was given with.
pub(crate) fn check_no_prior<T>(prior: Option<&T>) -> Result<(), Error> {
    match prior {
        Some(_) => Err(Error::InvalidParameter {
            name: Param::Prior,
            value: "set before the noise sigma".into(),
            reason: "the prior is weighed by the noise sigma: give sigma first".into(),
        }),
        None => Ok(()),
    }
}
