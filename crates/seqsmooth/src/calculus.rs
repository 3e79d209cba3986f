//! Discrete calculus (Morrison ch. 2 and 4): factorial functions, binomial coefficients, the
//! Stirling matrices and the link ("associate Stirling") matrices, and a small dense polynomial
//! type used to build the orthogonal bases exactly.
//!
//! Everything is generic over [`Scalar`], so each function serves as its own exact oracle when
//! instantiated with [`crate::scalar::Rational`].

use crate::scalar::Scalar;
use nalgebra::DMatrix;
use num_bigint::BigInt;

/// `k!` in the field `T`.
///
/// ```
/// use seqsmooth::calculus::factorial;
/// assert_eq!(factorial::<f64>(5), 120.0);
/// ```
pub fn factorial<T: Scalar>(k: usize) -> T {
    let mut acc = T::one();
    for i in 2..=k {
        acc = acc * T::from_i64(i as i64);
    }
    acc
}

/// Backward (falling) factorial `x^(k) = x (x-1) ... (x-k+1)`, `x^(0) = 1` (Morrison (2.4.1)).
///
/// ```
/// use seqsmooth::calculus::falling_factorial;
/// assert_eq!(falling_factorial(7.0, 3), 210.0);
/// assert_eq!(falling_factorial(2.0, 3), 0.0); // zero for integer 0 <= x < k
/// ```
pub fn falling_factorial<T: Scalar>(x: T, k: usize) -> T {
    let mut acc = T::one();
    for i in 0..k {
        acc = acc * (x.clone() - T::from_i64(i as i64));
    }
    acc
}

/// Forward (rising) factorial `x^[k] = x (x+1) ... (x+k-1)` (Morrison (2.4.2)).
///
/// ```
/// use seqsmooth::calculus::rising_factorial;
/// assert_eq!(rising_factorial(3.0, 3), 60.0);
/// ```
pub fn rising_factorial<T: Scalar>(x: T, k: usize) -> T {
    let mut acc = T::one();
    for i in 0..k {
        acc = acc * (x.clone() + T::from_i64(i as i64));
    }
    acc
}

/// Binomial coefficient `C(x, k) = x^(k) / k!` for any `x` in the field (Morrison (2.5.1)).
///
/// ```
/// use seqsmooth::calculus::binomial;
/// assert_eq!(binomial(10.0, 3), 120.0);
/// assert_eq!(binomial(-1.0, 3), -1.0);
/// ```
pub fn binomial<T: Scalar>(x: T, k: usize) -> T {
    falling_factorial(x, k) / factorial::<T>(k)
}

/// Integer binomial coefficient `C(n, k)` in the field `T` (zero for `k > n`).
///
/// ```
/// use seqsmooth::calculus::choose;
/// assert_eq!(choose::<f64>(20, 10), 184756.0);
/// assert_eq!(choose::<f64>(3, 5), 0.0);
/// ```
pub fn choose<T: Scalar>(n: usize, k: usize) -> T {
    if k > n {
        return T::zero();
    }
    let k = k.min(n - k);
    let mut acc = T::one();
    for i in 0..k {
        acc = acc * T::from_i64((n - i) as i64) / T::from_i64((i + 1) as i64);
    }
    acc
}

/// [`choose`] as a big integer, by exact integer division: the partial product
/// `Π_{i<j} (n−i)/(i+1)` is `C(n, j)`, an integer, at every step (zero for `k > n`).
///
/// ```
/// use seqsmooth::calculus::choose_integer;
/// assert_eq!(choose_integer(60, 30).to_string(), "118264581564861424");
/// ```
pub fn choose_integer(n: usize, k: usize) -> BigInt {
    if k > n {
        return BigInt::from(0);
    }
    let k = k.min(n - k);
    let mut acc = BigInt::from(1);
    for i in 0..k {
        acc = acc * BigInt::from(n - i) / BigInt::from(i + 1);
    }
    acc
}

/// Signed Stirling numbers of the first kind as the lower-triangular `(order+1)²` matrix `S1`
/// with `x^(i) = Σ_j [S1]_ij x^j` (Morrison (2.4.8)-(2.4.10), Table 2.1).
///
/// ```
/// use seqsmooth::calculus::stirling1;
/// let s = stirling1::<f64>(4);
/// assert_eq!(s[(4, 2)], 11.0);
/// assert_eq!(s[(4, 1)], -6.0);
/// ```
pub fn stirling1<T: Scalar>(order: usize) -> DMatrix<T> {
    stirling_triangle(order, |i, _| -T::from_i64((i - 1) as i64))
}

/// The triangle `s_00 = 1`, `s_ij = s_(i−1)(j−1) + c(i, j) s_(i−1)j` of both kinds of Stirling
/// numbers (Morrison (2.4.8), (2.4.15)).
fn stirling_triangle<T: Scalar>(order: usize, c: impl Fn(usize, usize) -> T) -> DMatrix<T> {
    let mut s = DMatrix::from_element(order + 1, order + 1, T::zero());
    s[(0, 0)] = T::one();
    for i in 1..=order {
        for j in 1..=i {
            let a = s[(i - 1, j - 1)].clone();
            let b = s[(i - 1, j)].clone() * c(i, j);
            s[(i, j)] = a + b;
        }
    }
    s
}

/// Stirling numbers of the second kind as the lower-triangular matrix `S2 = S1⁻¹` with
/// `x^i = Σ_j [S2]_ij x^(j)` (Morrison (2.4.13)-(2.4.15), Table 2.2).
///
/// ```
/// use seqsmooth::calculus::stirling2;
/// assert_eq!(stirling2::<f64>(5)[(5, 3)], 25.0);
/// ```
pub fn stirling2<T: Scalar>(order: usize) -> DMatrix<T> {
    stirling_triangle(order, |_, j| T::from_i64(j as i64))
}

/// The link matrix `𝒮` (Morrison's associate Stirling matrix of the first kind, (4.4.8),
/// Table 4.1): `Z = 𝒮 V` maps the scaled backward-difference vector
/// `V = (x, ∇x, ∇²x/2!, …, ∇^m x/m!)` to the scaled derivative vector `Z`.
/// `[𝒮]_ij = |s(j, i)|`, upper triangular with unit diagonal.
///
/// ```
/// use seqsmooth::calculus::link_matrix;
/// let sa = link_matrix::<f64>(8);
/// assert_eq!(sa[(5, 8)], 1960.0); // Morrison's worked example, ch. 4 notes
/// ```
pub fn link_matrix<T: Scalar>(m: usize) -> DMatrix<T> {
    let s1 = stirling1::<T>(m);
    DMatrix::from_fn(m + 1, m + 1, |i, j| s1[(j, i)].abs_val())
}

/// The inverse link matrix `𝒮⁻¹` (Morrison (4.4.5), Table 4.2): `V = 𝒮⁻¹ Z`,
/// `[𝒮⁻¹]_ij = (-1)^(j-i) S2(j, i)`.
///
/// ```
/// use seqsmooth::calculus::link_matrix_inverse;
/// let si = link_matrix_inverse::<f64>(3);
/// assert_eq!(si[(1, 3)], 1.0);
/// assert_eq!(si[(2, 3)], -3.0);
/// ```
pub fn link_matrix_inverse<T: Scalar>(m: usize) -> DMatrix<T> {
    let s2 = stirling2::<T>(m);
    DMatrix::from_fn(m + 1, m + 1, |i, j| {
        if j < i {
            T::zero()
        } else if (j - i) % 2 == 0 {
            s2[(j, i)].clone()
        } else {
            -s2[(j, i)].clone()
        }
    })
}

/// A dense polynomial `Σ_k c_k x^k` over a field, lowest power first.
///
/// ```
/// use seqsmooth::calculus::Polynomial;
/// let p = Polynomial::falling(3); // x(x-1)(x-2)
/// assert_eq!(p.eval(&5.0_f64), 60.0);
/// assert_eq!(p.taylor_coefficient(1, &0.0), 2.0); // p'(0)/1!
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Polynomial<T> {
    /// Coefficients, lowest power first.
    pub coeffs: Vec<T>,
}

impl<T: Scalar> Polynomial<T> {
    /// The polynomial with the given coefficients (lowest power first).
    pub fn new(coeffs: Vec<T>) -> Self {
        Self { coeffs }
    }

    /// The constant `c`.
    pub fn constant(c: T) -> Self {
        Self { coeffs: vec![c] }
    }

    /// The falling factorial `x^(k)` as a polynomial (row `k` of [`stirling1`]).
    pub fn falling(k: usize) -> Self {
        let mut p = Self::constant(T::one());
        for i in 0..k {
            p = p.mul(&Self::new(vec![-T::from_i64(i as i64), T::one()]));
        }
        p
    }

    /// Degree bound (number of coefficients minus one).
    pub fn len(&self) -> usize {
        self.coeffs.len()
    }

    /// True when there are no coefficients.
    pub fn is_empty(&self) -> bool {
        self.coeffs.is_empty()
    }

    /// Sum of two polynomials.
    pub fn add(&self, other: &Self) -> Self {
        let n = self.coeffs.len().max(other.coeffs.len());
        let coeffs = (0..n)
            .map(|k| {
                let a = self.coeffs.get(k).cloned().unwrap_or_else(T::zero);
                let b = other.coeffs.get(k).cloned().unwrap_or_else(T::zero);
                a + b
            })
            .collect();
        Self { coeffs }
    }

    /// Product of two polynomials.
    pub fn mul(&self, other: &Self) -> Self {
        if self.coeffs.is_empty() || other.coeffs.is_empty() {
            return Self { coeffs: vec![] };
        }
        let mut c = vec![T::zero(); self.coeffs.len() + other.coeffs.len() - 1];
        for (i, a) in self.coeffs.iter().enumerate() {
            for (j, b) in other.coeffs.iter().enumerate() {
                c[i + j] = c[i + j].clone() + a.clone() * b.clone();
            }
        }
        Self { coeffs: c }
    }

    /// The polynomial multiplied by the scalar `s`.
    pub fn scale(&self, s: &T) -> Self {
        Self {
            coeffs: self.coeffs.iter().map(|c| c.clone() * s.clone()).collect(),
        }
    }

    /// Value at `x` (Horner).
    pub fn eval(&self, x: &T) -> T {
        let mut acc = T::zero();
        for c in self.coeffs.iter().rev() {
            acc = acc * x.clone() + c.clone();
        }
        acc
    }

    /// The `i`-th derivative.
    pub fn derivative(&self, i: usize) -> Self {
        if i >= self.coeffs.len() {
            return Self { coeffs: vec![] };
        }
        let coeffs = (i..self.coeffs.len())
            .map(|k| self.coeffs[k].clone() * falling_factorial(T::from_i64(k as i64), i))
            .collect();
        Self { coeffs }
    }

    /// The Taylor coefficient `(1/i!) dⁱp/dxⁱ` at `x`.
    pub fn taylor_coefficient(&self, i: usize, x: &T) -> T {
        // Σ_k c_k C(k, i) x^(k-i), by Horner over k.
        let mut acc = T::zero();
        for k in (i..self.coeffs.len()).rev() {
            acc = acc * x.clone() + self.coeffs[k].clone() * choose::<T>(k, i);
        }
        acc
    }
}

/// Backward difference `∇^k f` of a sequence, returned for the newest sample
/// (`Σ_j (-1)^j C(k, j) f[n-j]`, Morrison (2.5.13)); `None` if fewer than `k+1` samples.
///
/// ```
/// use seqsmooth::calculus::backward_difference;
/// let f: Vec<f64> = (-2..=3).map(|n: i32| (n * n * n - 2 * n) as f64).collect();
/// assert_eq!(backward_difference(&f, 3), Some(6.0)); // Morrison TV2.1
/// ```
pub fn backward_difference<T: Scalar>(f: &[T], k: usize) -> Option<T> {
    if f.len() < k + 1 {
        return None;
    }
    let n = f.len() - 1;
    let mut acc = T::zero();
    for j in 0..=k {
        let term = choose::<T>(k, j) * f[n - j].clone();
        acc = if j % 2 == 0 { acc + term } else { acc - term };
    }
    Some(acc)
}
