use crate::calculus::{choose, falling_factorial, Polynomial};
use crate::scalar::Scalar;
use nalgebra::DMatrix;

/// Discrete Legendre polynomials `p(x; j, L)` on the points `x = 0..L` (Morrison (3.2.20)):
///
/// `p(x; j, L) = Σ_{ν=0..j} (-1)^ν C(j,ν) C(j+ν,ν) x^(ν) / L^(ν)`, with `p(0; j, L) = 1`,
/// `Σ_x p_i p_j = δ_ij c_j²` and `c_j² = (L+j+1)^(j+1) / ((2j+1) L^(j))` (3.2.30). Defined for
/// `j ≤ L`. `x = 0` is the oldest sample of the window and `x = L` the newest.
///
/// ```
/// use seqsmooth::basis::DiscreteLegendre;
/// let b = DiscreteLegendre::new(4.0_f64);
/// assert_eq!(b.value(1, 1.0), 0.5);           // p1 = 1 - 2x/L
/// assert_eq!(b.norm_sq(0), 5.0);              // c0² = L + 1
/// assert_eq!(b.value(3, 4.0), -1.0);          // p_j(L) = (-1)^j
/// ```
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct DiscreteLegendre<T> {
    span: T,
}

impl<T: Scalar> DiscreteLegendre<T> {
    /// The family on `x = 0..L` (`span = L`, the memory length in samples minus one).
    ///
    /// ```
    /// use seqsmooth::basis::DiscreteLegendre;
    /// assert_eq!(*DiscreteLegendre::new(10.0_f64).span(), 10.0);
    /// ```
    pub fn new(span: T) -> Self {
        Self { span }
    }

    /// `L`.
    ///
    /// ```
    /// use seqsmooth::basis::DiscreteLegendre;
    /// assert_eq!(*DiscreteLegendre::new(4.0_f64).span(), 4.0);
    /// ```
    pub fn span(&self) -> &T {
        &self.span
    }

    /// `p(x; j, L)` as a polynomial in `x` (power basis).
    ///
    /// ```
    /// use seqsmooth::basis::DiscreteLegendre;
    /// let p = DiscreteLegendre::new(4.0_f64).polynomial(1);
    /// assert_eq!(p.coeffs, vec![1.0, -0.5]); // 1 − 2x/L
    /// ```
    pub fn polynomial(&self, j: usize) -> Polynomial<T> {
        let mut p = Polynomial::new(vec![T::zero()]);
        for nu in 0..=j {
            let c = choose::<T>(j, nu) * choose::<T>(j + nu, nu)
                / falling_factorial(self.span.clone(), nu);
            let c = if nu % 2 == 0 { c } else { -c };
            p = p.add(&Polynomial::falling(nu).scale(&c));
        }
        p
    }

    /// `p(x; j, L)` at any real `x`.
    ///
    /// ```
    /// use seqsmooth::basis::DiscreteLegendre;
    /// let b = DiscreteLegendre::new(4.0_f64);
    /// assert_eq!(b.value(2, 0.0), 1.0); // p_j(0) = 1
    /// ```
    pub fn value(&self, j: usize, x: T) -> T {
        let mut acc = T::zero();
        for nu in 0..=j {
            let c = choose::<T>(j, nu) * choose::<T>(j + nu, nu) * falling_factorial(x.clone(), nu)
                / falling_factorial(self.span.clone(), nu);
            acc = if nu % 2 == 0 { acc + c } else { acc - c };
        }
        acc
    }

    /// Taylor coefficient `(1/i!) dⁱp(x; j, L)/dxⁱ` at `x` (any order `i`).
    ///
    /// ```
    /// use seqsmooth::basis::DiscreteLegendre;
    /// let b = DiscreteLegendre::new(4.0_f64);
    /// assert_eq!(b.taylor(1, 1, &2.0), -0.5); // d/dx (1 − 2x/L)
    /// ```
    pub fn taylor(&self, i: usize, j: usize, x: &T) -> T {
        self.polynomial(j).taylor_coefficient(i, x)
    }

    /// Squared norm `c(j, L)² = (L+j+1)^(j+1) / ((2j+1) L^(j))` (Morrison (3.2.30)).
    ///
    /// ```
    /// use seqsmooth::basis::DiscreteLegendre;
    /// let b = DiscreteLegendre::new(4.0_f64);
    /// let direct: f64 = (0..=4).map(|x| b.value(1, x as f64).powi(2)).sum();
    /// assert!((b.norm_sq(1) - direct).abs() < 1e-14);
    /// ```
    pub fn norm_sq(&self, j: usize) -> T {
        falling_factorial(self.span.clone() + T::from_i64(j as i64 + 1), j + 1)
            / (T::from_i64(2 * j as i64 + 1) * falling_factorial(self.span.clone(), j))
    }

    /// The matrix `G` of scaled backward differences at the newest point `x = L`
    /// (Morrison (7.4.13)-(7.4.14), Appendix I (A1.7)):
    /// `[G]_ij = (1/i!) ∇ⁱ p_j(L) = (-1)^j C(j,i) C(j+i,i) / L^(i)`, `0 ≤ i, j ≤ m`.
    /// With the link matrix, `P = 𝒮 G` holds the Taylor coefficients `(1/i!) dⁱp_j/dxⁱ` at `x = L`
    /// (7.4.15).
    ///
    /// ```
    /// use seqsmooth::basis::DiscreteLegendre;
    /// let g = DiscreteLegendre::new(4.0_f64).end_differences(1);
    /// assert_eq!((g[(0, 0)], g[(0, 1)], g[(1, 1)]), (1.0, -1.0, -0.5)); // p1(L) = −1, ∇p1 = −2/L
    /// ```
    pub fn end_differences(&self, m: usize) -> DMatrix<T> {
        DMatrix::from_fn(m + 1, m + 1, |i, j| {
            if j < i {
                return T::zero();
            }
            let v =
                choose::<T>(j, i) * choose::<T>(j + i, i) / falling_factorial(self.span.clone(), i);
            if j % 2 == 0 {
                v
            } else {
                -v
            }
        })
    }

    /// Values of `dⁱp_j/dxⁱ` for `j = 0..=m` at `x` by the three-term recursion of Morrison's
    /// Appendix I (A1.1)-(A1.6), which avoids the cancellation of the explicit sum.
    /// Returns a `(m+1) × (order+1)` matrix: entry `(j, i)` is `dⁱp_j/dxⁱ(x)`. Requires `m ≤ L`.
    ///
    /// ```
    /// use seqsmooth::basis::DiscreteLegendre;
    /// let b = DiscreteLegendre::new(6.0_f64);
    /// let d = b.derivatives_by_recursion(3, 2, &2.0);
    /// for j in 0..=3 {
    ///     assert!((d[(j, 0)] - b.value(j, 2.0)).abs() < 1e-12);
    ///     assert!((d[(j, 2)] - 2.0 * b.taylor(2, j, &2.0)).abs() < 1e-12);
    /// }
    /// ```
    pub fn derivatives_by_recursion(&self, m: usize, order: usize, x: &T) -> DMatrix<T> {
        let l = self.span.clone();
        let mut d = DMatrix::from_element(m + 1, order + 1, T::zero());
        d[(0, 0)] = T::one();
        if m >= 1 {
            let two = T::from_i64(2);
            d[(1, 0)] = T::one() - two.clone() * x.clone() / l.clone();
            if order >= 1 {
                d[(1, 1)] = -two / l.clone();
            }
        }
        for j in 2..=m {
            let jj = T::from_i64(j as i64);
            let denom = jj.clone() * (l.clone() - jj.clone() + T::one());
            let two_j_minus_1 = T::from_i64(2 * j as i64 - 1);
            let a = -T::from_i64(2) * two_j_minus_1.clone() / denom.clone();
            let b = l.clone() * two_j_minus_1 / denom.clone();
            let c = (jj.clone() - T::one()) * (l.clone() + jj) / denom;
            for i in 0..=order {
                let mut v = (a.clone() * x.clone() + b.clone()) * d[(j - 1, i)].clone()
                    - c.clone() * d[(j - 2, i)].clone();
                if i > 0 {
                    v = v + T::from_i64(i as i64) * a.clone() * d[(j - 1, i - 1)].clone();
                }
                d[(j, i)] = v;
            }
        }
        d
    }
}
