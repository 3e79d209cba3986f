//! Classical Legendre polynomials `P_j(u)` on `[-1, 1]` with derivatives of any order: the
//! well-conditioned basis for least-squares fits on arbitrary timestamps (the batch oracle of
//! [`crate::estimate`]).

use nalgebra::DMatrix;

/// Taylor coefficients `T[(k, j)] = P_j^(k)(u) / k!` for `j = 0..=degree`, `k = 0..=order`, by the
/// differentiated three-term recurrence
/// `T_{j+1}^k = ((2j+1)(u T_j^k + T_j^{k-1}) - j T_{j-1}^k) / (j+1)`.
///
/// ```
/// use seqsmooth::basis::legendre::taylor_table;
/// let t = taylor_table(2, 2, 0.5);
/// assert!((t[(0, 2)] - (-0.125)).abs() < 1e-15); // P2(0.5) = (3·0.25 - 1)/2
/// assert!((t[(1, 2)] - 1.5).abs() < 1e-15);      // P2'(u) = 3u
/// assert!((t[(2, 2)] - 1.5).abs() < 1e-15);      // P2''/2! = 3/2
/// ```
pub fn taylor_table(degree: usize, order: usize, u: f64) -> DMatrix<f64> {
    let mut t = DMatrix::zeros(order + 1, degree + 1);
    t[(0, 0)] = 1.0;
    if degree >= 1 {
        t[(0, 1)] = u;
        if order >= 1 {
            t[(1, 1)] = 1.0;
        }
    }
    for j in 1..degree {
        let jf = j as f64;
        for k in 0..=order {
            let lower = if k > 0 { t[(k - 1, j)] } else { 0.0 };
            t[(k, j + 1)] =
                ((2.0 * jf + 1.0) * (u * t[(k, j)] + lower) - jf * t[(k, j - 1)]) / (jf + 1.0);
        }
    }
    t
}

/// Values `P_0(u) … P_degree(u)`.
///
/// ```
/// use seqsmooth::basis::legendre::values;
/// assert_eq!(values(3, 1.0), vec![1.0, 1.0, 1.0, 1.0]);
/// ```
pub fn values(degree: usize, u: f64) -> Vec<f64> {
    let mut v = Vec::with_capacity(degree + 1);
    v.push(1.0);
    if degree >= 1 {
        v.push(u);
    }
    for j in 1..degree {
        let jf = j as f64;
        let next = ((2.0 * jf + 1.0) * u * v[j] - jf * v[j - 1]) / (jf + 1.0);
        v.push(next);
    }
    v
}
