//! Small dense linear algebra the library needs beyond nalgebra: exact (field-generic) inversion
//! for the rational oracles, triangular solves, and (`dense`) the column-major kernels and
//! `L D Lᵀ` factorisation of the Kalman filter's covariance arithmetic.

pub(crate) mod dense;
pub(crate) mod invariant;

use crate::error::Error;
use crate::numeric::sigma::std_dev;
use crate::scalar::Scalar;
use nalgebra::{DMatrix, DVector};

/// Inverse of a square matrix over any field by Gauss–Jordan elimination with pivot search on
/// non-zero entries. Meant for exact rationals (conditioning is irrelevant there); `None` when
/// the matrix is singular.
///
/// ```
/// use seqsmooth::linalg::inverse_exact;
/// use seqsmooth::scalar::Rational;
/// use nalgebra::DMatrix;
/// let h = DMatrix::from_fn(3, 3, |i, j| Rational::new(1.into(), ((i + j + 1) as i64).into()));
/// let hi = inverse_exact(&h).unwrap();
/// assert_eq!(hi[(0, 0)], Rational::from_integer(9.into())); // inverse Hilbert matrix
/// ```
pub fn inverse_exact<T: Scalar>(a: &DMatrix<T>) -> Option<DMatrix<T>> {
    let n = a.nrows();
    if a.ncols() != n {
        return None;
    }
    let mut m = a.clone();
    let mut inv = DMatrix::from_fn(n, n, |i, j| if i == j { T::one() } else { T::zero() });
    for col in 0..n {
        let pivot = (col..n).find(|&r| !m[(r, col)].is_zero())?;
        if pivot != col {
            m.swap_rows(pivot, col);
            inv.swap_rows(pivot, col);
        }
        let p = m[(col, col)].clone();
        for j in 0..n {
            m[(col, j)] = m[(col, j)].clone() / p.clone();
            inv[(col, j)] = inv[(col, j)].clone() / p.clone();
        }
        for r in 0..n {
            if r == col || m[(r, col)].is_zero() {
                continue;
            }
            let f = m[(r, col)].clone();
            for j in 0..n {
                m[(r, j)] = m[(r, j)].clone() - f.clone() * m[(col, j)].clone();
                inv[(r, j)] = inv[(r, j)].clone() - f.clone() * inv[(col, j)].clone();
            }
        }
    }
    Some(inv)
}

/// Solves `R x = b` in place for upper-triangular `R` (back substitution). Returns `false`
/// (leaving `b` partly overwritten) if a diagonal entry is zero.
pub fn solve_upper_in_place(r: &DMatrix<f64>, b: &mut [f64]) -> bool {
    substitute(r, b, false)
}

/// Solves `Rᵀ x = b` in place for upper-triangular `R` (forward substitution).
pub fn solve_upper_transpose_in_place(r: &DMatrix<f64>, b: &mut [f64]) -> bool {
    substitute(r, b, true)
}

/// Back substitution with `R` (`transpose` false: `i = n−1 … 0`, `x_i = (b_i − Σ_{j>i} r_ij
/// x_j)/r_ii`) or forward substitution with `Rᵀ` (`i = 0 … n−1`, `x_i = (b_i − Σ_{j<i} r_ji
/// x_j)/r_ii`); false at a zero diagonal entry.
fn substitute(r: &DMatrix<f64>, b: &mut [f64], transpose: bool) -> bool {
    let n = b.len();
    for step in 0..n {
        let i = if transpose { step } else { n - 1 - step };
        let others = if transpose { 0..i } else { i + 1..n };
        let mut s = b[i];
        for j in others {
            s -= if transpose { r[(j, i)] } else { r[(i, j)] } * b[j];
        }
        let d = r[(i, i)];
        if d == 0.0 {
            return false;
        }
        b[i] = s / d;
    }
    true
}

/// Matrix product over any field (nalgebra's operators need more trait bounds than exact
/// rationals and `f64` share through [`Scalar`]).
///
/// ```
/// use seqsmooth::linalg::mul;
/// use nalgebra::DMatrix;
/// let a = DMatrix::from_row_slice(1, 2, &[1.0, 2.0]);
/// let b = DMatrix::from_row_slice(2, 1, &[3.0, 4.0]);
/// assert_eq!(mul(&a, &b)[(0, 0)], 11.0);
/// ```
pub fn mul<T: Scalar>(a: &DMatrix<T>, b: &DMatrix<T>) -> DMatrix<T> {
    assert_eq!(a.ncols(), b.nrows(), "matrix product dimensions");
    DMatrix::from_fn(a.nrows(), b.ncols(), |i, j| {
        (0..a.ncols()).fold(T::zero(), |acc, k| {
            acc + a[(i, k)].clone() * b[(k, j)].clone()
        })
    })
}

/// `A B Aᵀ` over any field.
pub fn congruence<T: Scalar>(a: &DMatrix<T>, b: &DMatrix<T>) -> DMatrix<T> {
    mul(&mul(a, b), &a.transpose())
}

/// The iterations [`singular_values`] allows: far above the few dozen sweeps a well-scaled
/// matrix of a filter's size takes (nalgebra's own limit, none, can loop forever on entries
/// that span hundreds of orders of magnitude).
pub const SVD_ITERATIONS: usize = 10_000;

/// The singular values of `m`, or [`Error::SvdNotConverged`] when the iteration does not
/// converge within [`SVD_ITERATIONS`], or [`Error::NonFinite`] (`what` `"matrix entry"`, the
/// first such entry) when `m` holds an infinity or a NaN (nalgebra's SVD would panic on the
/// NaN singular values: a QR factor of a system whose column norms overflow, as a window fit
/// of times ~1e200 at an epoch far away gives).
///
/// ```
/// use nalgebra::DMatrix;
/// use seqsmooth::linalg::singular_values;
/// let sv = singular_values(&DMatrix::from_row_slice(2, 2, &[3.0, 0.0, 0.0, 4.0])).unwrap();
/// assert_eq!((sv.max(), sv.min()), (4.0, 3.0));
/// assert!(singular_values(&DMatrix::from_row_slice(1, 2, &[f64::NAN, 1.0])).is_err());
/// ```
pub fn singular_values(m: &DMatrix<f64>) -> Result<DVector<f64>, Error> {
    if let Some(&value) = m.iter().find(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            what: "matrix entry",
            value,
        });
    }
    nalgebra::linalg::SVD::try_new(m.clone(), false, false, f64::EPSILON, SVD_ITERATIONS)
        .map(|svd| svd.singular_values)
        .ok_or(Error::SvdNotConverged {
            rows: m.nrows(),
            cols: m.ncols(),
            iterations: SVD_ITERATIONS,
        })
}

/// The 1σ of each component of an estimate of covariance `S`: `√S_ii` by
/// [`std_dev`] (a rounding below zero reads as +0, a NaN stays
/// NaN). The one rule behind every `std_devs` of the library.
///
/// ```
/// use nalgebra::DMatrix;
/// use seqsmooth::linalg::std_devs;
/// assert_eq!(std_devs(&DMatrix::from_row_slice(2, 2, &[4.0, 1.0, 1.0, -0.0])), vec![2.0, 0.0]);
/// ```
pub fn std_devs(s: &DMatrix<f64>) -> Vec<f64> {
    s.diagonal().iter().map(|&v| std_dev(v)).collect()
}
