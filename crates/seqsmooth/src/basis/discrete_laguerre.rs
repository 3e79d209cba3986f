use crate::calculus::{choose, factorial, Polynomial};
use crate::scalar::Scalar;

/// Discrete Laguerre polynomials `p(x; j, θ)`, orthogonal with weight `θ^x` on `x = 0, 1, 2, …`
/// (Morrison (3.3.10), (13.2.2)):
///
/// `p(x; j, θ) = θ^j Σ_{ν=0..j} (-1)^ν C(j,ν) ((1-θ)/θ)^ν C(x,ν)`, with
/// `Σ_x p_i p_j θ^x = δ_ij θ^j/(1-θ)` (3.3.16). Here `x` is the age in samples (`0` = newest),
/// and `p(-1; j, θ) = 1` (13.5.1).
///
/// ```
/// use seqsmooth::basis::DiscreteLaguerre;
/// let b = DiscreteLaguerre::new(0.5_f64);
/// assert_eq!(b.value(1, 0.0), 0.5);     // p1(0) = θ
/// assert_eq!(b.value(3, -1.0), 1.0);    // p_j(-1) = 1
/// assert_eq!(b.norm_sq(2), 0.5);        // θ²/(1-θ)
/// ```
#[derive(Clone, Debug)]
pub struct DiscreteLaguerre<T> {
    theta: T,
}

impl<T: Scalar> DiscreteLaguerre<T> {
    /// The family for the discount factor `θ` (`0 < θ < 1`).
    ///
    /// ```
    /// use seqsmooth::basis::DiscreteLaguerre;
    /// assert_eq!(*DiscreteLaguerre::new(0.9_f64).theta(), 0.9);
    /// ```
    pub fn new(theta: T) -> Self {
        Self { theta }
    }

    /// `θ`.
    ///
    /// ```
    /// use seqsmooth::basis::DiscreteLaguerre;
    /// assert_eq!(*DiscreteLaguerre::new(0.5_f64).theta(), 0.5);
    /// ```
    pub fn theta(&self) -> &T {
        &self.theta
    }

    /// `p(x; j, θ) = Σ_ν (-1)^ν C(j,ν) θ^(j-ν) (1-θ)^ν x^(ν)/ν!` as a polynomial in `x`.
    ///
    /// ```
    /// use seqsmooth::basis::DiscreteLaguerre;
    /// let p = DiscreteLaguerre::new(0.5_f64).polynomial(1);
    /// assert_eq!(p.coeffs, vec![0.5, -0.5]); // θ − (1−θ)x
    /// ```
    pub fn polynomial(&self, j: usize) -> Polynomial<T> {
        let one_minus = T::one() - self.theta.clone();
        let mut p = Polynomial::new(vec![T::zero()]);
        for nu in 0..=j {
            let c = choose::<T>(j, nu) * self.theta.powi_u(j - nu) * one_minus.powi_u(nu)
                / factorial::<T>(nu);
            let c = if nu % 2 == 0 { c } else { -c };
            p = p.add(&Polynomial::falling(nu).scale(&c));
        }
        p
    }

    /// `p(x; j, θ)` at any real `x`.
    ///
    /// ```
    /// use seqsmooth::basis::DiscreteLaguerre;
    /// assert_eq!(DiscreteLaguerre::new(0.5_f64).value(2, -1.0), 1.0); // p_j(−1) = 1
    /// ```
    pub fn value(&self, j: usize, x: T) -> T {
        self.polynomial(j).eval(&x)
    }

    /// Taylor coefficient `(1/i!) dⁱp(x; j, θ)/dxⁱ` at `x`.
    ///
    /// ```
    /// use seqsmooth::basis::DiscreteLaguerre;
    /// assert_eq!(DiscreteLaguerre::new(0.5_f64).taylor(1, 1, &0.0), -0.5); // d/dx (θ − (1−θ)x)
    /// ```
    pub fn taylor(&self, i: usize, j: usize, x: &T) -> T {
        self.polynomial(j).taylor_coefficient(i, x)
    }

    /// Squared norm `c(j, θ)² = θ^j / (1-θ)` (Morrison (3.3.16)).
    ///
    /// ```
    /// use seqsmooth::basis::DiscreteLaguerre;
    /// let b = DiscreteLaguerre::new(0.5_f64);
    /// let direct: f64 = (0..200).map(|x| b.value(1, x as f64).powi(2) * 0.5f64.powi(x)).sum();
    /// assert!((b.norm_sq(1) - direct).abs() < 1e-12);
    /// ```
    pub fn norm_sq(&self, j: usize) -> T {
        self.theta.powi_u(j) / (T::one() - self.theta.clone())
    }
}
