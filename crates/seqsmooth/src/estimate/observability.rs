//! Observability (Morrison §8.9): whether observations `Y = M X` of constant-coefficient
//! linear dynamics `dX/dt = A X` determine the state once enough of them are taken.
//!
//! Theorem 8.1: the stacked `T = [M Φ(0); M Φ(−1); …; M Φ(−L)]` reaches full column rank for
//! `L` large enough iff `G = [M; M A; …; M A^(n−1)]` has full column rank `n` (the powers up
//! to the minimal polynomial's degree suffice; `n − 1` covers every `A`). The rank is the count
//! of singular values above `max(rows, n) ε σ_max`, the tolerance [`super::batch`] uses for `T`.

use crate::error::{Error, Param};
use crate::model::linear::LinearDynamics;
use nalgebra::DMatrix;

/// The rank of a matrix from its singular values: those above `max(rows, cols) ε σ_max`
/// (numpy's `matrix_rank`), 0 for a zero matrix.
pub(crate) fn numerical_rank(singular_values: &[f64], rows: usize, cols: usize) -> usize {
    let largest = singular_values.iter().copied().fold(0.0, f64::max);
    if largest == 0.0 {
        return 0;
    }
    let tolerance = rows.max(cols) as f64 * f64::EPSILON * largest;
    singular_values.iter().filter(|&&s| s > tolerance).count()
}

/// What Theorem 8.1's test finds.
#[derive(Clone, Debug, PartialEq)]
pub struct Observability {
    /// The rank of `G = [M; M A; …; M A^(n−1)]`.
    pub rank: usize,
    /// The state dimension `n`.
    pub states: usize,
    /// `G`'s smallest singular value (0 when `G` has fewer rows than `n`).
    pub smallest_singular_value: f64,
    /// `G`'s largest singular value.
    pub largest_singular_value: f64,
}

impl Observability {
    /// Whether the observations determine the state (`rank = n`).
    ///
    /// ```
    /// use nalgebra::DMatrix;
    /// use seqsmooth::estimate::observability::observability;
    /// use seqsmooth::model::linear::LinearDynamics;
    /// // Morrison §8.9 Example 1: the 3-state polynomial model observed in position.
    /// let a = DMatrix::from_row_slice(3, 3, &[0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]);
    /// let m = DMatrix::from_row_slice(1, 3, &[1.0, 0.0, 0.0]);
    /// assert!(observability(&LinearDynamics::new(a).unwrap(), &m).unwrap().is_observable());
    /// ```
    pub fn is_observable(&self) -> bool {
        self.rank == self.states
    }

    /// `Ok` when observable, else [`Error::Unobservable`] naming the rank.
    ///
    /// ```
    /// use nalgebra::DMatrix;
    /// use seqsmooth::estimate::observability::observability;
    /// use seqsmooth::model::linear::LinearDynamics;
    /// // Example 2: the same model observed in velocity only: rank 2.
    /// let a = DMatrix::from_row_slice(3, 3, &[0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]);
    /// let m = DMatrix::from_row_slice(1, 3, &[0.0, 1.0, 0.0]);
    /// let e = observability(&LinearDynamics::new(a).unwrap(), &m).unwrap().check().unwrap_err();
    /// assert!(e.to_string().contains("only 2 of the 3"));
    /// ```
    pub fn check(&self) -> Result<(), Error> {
        if self.is_observable() {
            Ok(())
        } else {
            Err(Error::Unobservable {
                rank: self.rank,
                states: self.states,
                smallest_singular_value: self.smallest_singular_value,
                largest_singular_value: self.largest_singular_value,
            })
        }
    }
}

/// Theorem 8.1's test for observations `M` (one row per observed component, `n` columns) of the
/// dynamics `A`.
///
/// ```
/// use nalgebra::DMatrix;
/// use seqsmooth::estimate::observability::observability;
/// use seqsmooth::model::linear::LinearDynamics;
/// // Ex. 8.25: Φ = [[1, ζ, 0], [0, 1, 0], [0, ζ, 1]], M = (1, 0, 1): rank 2.
/// let a = DMatrix::from_row_slice(3, 3, &[0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
/// let m = DMatrix::from_row_slice(1, 3, &[1.0, 0.0, 1.0]);
/// assert_eq!(observability(&LinearDynamics::new(a).unwrap(), &m).unwrap().rank, 2);
/// ```
pub fn observability(dynamics: &LinearDynamics, m: &DMatrix<f64>) -> Result<Observability, Error> {
    let a = dynamics.matrix();
    let n = a.nrows();
    let (components, cols) = m.shape();
    if cols != n || components == 0 {
        return Err(Error::InvalidParameter {
            name: Param::ObservationMatrixM,
            value: format!("{components}x{cols}"),
            reason: format!("must have at least one row and one column per state ({n})"),
        });
    }
    if let Some((k, v)) = m.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(Error::InvalidParameter {
            name: Param::ObservationMatrixM,
            value: format!("entry [{}, {}] = {v}", k % components, k / components),
            reason: "must be finite".into(),
        });
    }
    let rows = components * n;
    let mut g = DMatrix::zeros(rows, n);
    let mut block = m.clone();
    for k in 0..n {
        g.rows_mut(k * components, components).copy_from(&block);
        block = &block * a;
    }
    if !g.iter().all(|v| v.is_finite()) {
        return Err(Error::InvalidParameter {
            name: Param::DynamicsMatrixA,
            value: format!("{a}").trim().replace('\n', " "),
            reason: "its powers up to n - 1 leave the double range".into(),
        });
    }
    let sv = crate::linalg::singular_values(&g)?;
    let sv = sv.as_slice();
    Ok(Observability {
        rank: numerical_rank(sv, rows, n),
        states: n,
        smallest_singular_value: if rows < n {
            0.0
        } else {
            sv.iter().copied().fold(f64::INFINITY, f64::min)
        },
        largest_singular_value: sv.iter().copied().fold(0.0, f64::max),
    })
}
