//! The expanding-memory gains of any degree (Morrison Table 9.1, (9.4.28)-(9.4.30); Reyneke
//! et al. §6.3-6.4), generic over [`Scalar`] (exact rationals or `f64`).
//!
//! Convention: Morrison's scaled current-estimate gains `h_k` (Reyneke's `Γ_Φ(k, m)`), indexed
//! by derivative order `k = 0..m`, used as `Z*_{n,n} = Z*_{n,n-1} + H ε_n`; the 1-step-predictor
//! form uses `Φ(1) H` ([`GainForm`]).

use crate::calculus::{choose_integer, falling_factorial, link_matrix, Polynomial};
use crate::numeric::memo::Memo;
use crate::polynomial::form::{apply_form, GainForm};
use crate::scalar::{Rational, Scalar};
use nalgebra::DVector;
use num_bigint::BigInt;
use std::sync::Arc;

/// The expanding-memory gains as rational functions of the sample index `n`:
/// `h_k(n) = N_k(n) / (n+m+1)^(m+1)` with integer polynomial numerators
///
/// `N_k(n) = Σ_{i=k..m} 𝒮_ki Σ_{j=i..m} C(j,i) C(j+i,i) (2j+1) (n-i)^(j-i) (n+m+1)^(m-j)`,
///
/// which is Morrison's `H_n = P(n) K(n)` (9.4.28)-(9.4.30) with `P = 𝒮 G` (7.4.15),
/// `[G]_ij = (-1)^j C(j,i) C(j+i,i)/n^(i)`, `[K]_j = (-1)^j / c(j,n)²`, over the common
/// denominator. The numerators' coefficients are exact; [`ExpandingGainSchedule`] evaluates them
/// in `f64`.
///
/// ```
/// use seqsmooth::polynomial::expanding::gains::expanding_gain_numerators;
/// use seqsmooth::scalar::Rational;
/// let num = expanding_gain_numerators(1);
/// // h0 = 2(2n+1)/((n+2)(n+1)), h1 = 6/((n+2)(n+1))  (Morrison (9.4.18)-(9.4.19))
/// assert_eq!(num[0].coeffs, vec![Rational::from_integer(2.into()), Rational::from_integer(4.into())]);
/// assert_eq!(num[1].coeffs, vec![Rational::from_integer(6.into()), Rational::from_integer(0.into())]);
/// ```
pub fn expanding_gain_numerators(m: usize) -> Vec<Polynomial<Rational>> {
    // Everything is an integer (the link matrix holds unsigned Stirling numbers), so the
    // polynomials are carried as big-integer coefficient vectors, lowest power first.
    type Poly = Vec<BigInt>;
    let int = |r: Rational| r.to_integer();
    // falling(start)[c] = (n + start)(n + start − 1) … (c factors), c = 0 … m, one linear factor
    // at a time.
    let falling = |start: i64| {
        let mut p: Vec<Poly> = vec![vec![BigInt::from(1)]];
        for l in 0..m {
            let a = BigInt::from(start - l as i64);
            let prev = &p[l];
            let mut next = vec![BigInt::from(0); prev.len() + 1];
            for (d, c) in prev.iter().enumerate() {
                next[d] += &a * c;
                next[d + 1] += c;
            }
            p.push(next);
        }
        p
    };
    let mul_into = |acc: &mut Poly, a: &Poly, b: &Poly, scale: &BigInt| {
        for (i, x) in a.iter().enumerate() {
            let xs = x * scale;
            for (j, y) in b.iter().enumerate() {
                acc[i + j] += &xs * y;
            }
        }
    };
    let upper = falling(m as i64 + 1);
    // The inner sum does not depend on k: Q_i = Σ_j C(j,i) C(j+i,i) (2j+1) (n−i)^(j−i) (n+m+1)^(m−j),
    // so N_k = Σ_i 𝒮_ki Q_i.
    let q: Vec<Poly> = (0..=m)
        .map(|i| {
            let lower = falling(-(i as i64));
            let mut total = vec![BigInt::from(0); m + 1];
            for j in i..=m {
                let c = choose_integer(j, i) * choose_integer(j + i, i) * BigInt::from(2 * j + 1);
                mul_into(&mut total, &lower[j - i], &upper[m - j], &c);
            }
            total
        })
        .collect();
    let sa = link_matrix::<Rational>(m);
    (0..=m)
        .map(|k| {
            let mut total = vec![BigInt::from(0); m + 1];
            for (i, qi) in q.iter().enumerate().skip(k) {
                let s = int(sa[(k, i)].clone());
                for (t, c) in total.iter_mut().zip(qi) {
                    *t += &s * c;
                }
            }
            Polynomial::new(total.into_iter().map(Rational::from_integer).collect())
        })
        .collect()
}

/// Expanding-memory gains `h_0(n) … h_m(n)` of degree `m` at the 0-based index `n` of the
/// newest sample, in the field `T` (Morrison Table 9.1; Reyneke §6.3-6.4), current-estimate or
/// 1-step-predictor form. Finite for every `n ≥ 0`; the filter is exact least squares from
/// `n = m` on whatever its initial state (Morrison §9.6).
///
/// ```
/// use seqsmooth::polynomial::expanding::gains::expanding_gains;
/// use seqsmooth::polynomial::form::GainForm;
/// use seqsmooth::scalar::parse_rational;
/// let g = expanding_gains::<seqsmooth::scalar::Rational>(2, 10, GainForm::Current);
/// let want: Vec<_> = ["83/143", "63/286", "5/286"].iter().map(|s| parse_rational(s).unwrap()).collect();
/// assert_eq!(g, want); // Reyneke §6.4 test vector at n = 10
/// ```
pub fn expanding_gains<T: Scalar>(m: usize, n: u64, form: GainForm) -> Vec<T> {
    let num = expanding_gain_numerators(m);
    let nr = Rational::from_integer(n.into());
    let den = falling_factorial(nr.clone() + Rational::from_i64(m as i64 + 1), m + 1);
    let h: Vec<Rational> = num.iter().map(|p| p.eval(&nr) / den.clone()).collect();
    apply_form(m, h, form)
        .iter()
        .map(T::from_rational)
        .collect()
}

/// Precomputed expanding-memory gain schedule in `f64`: the exact integer numerator coefficients
/// of [`expanding_gain_numerators`] evaluated by Horner's rule, `O(m)` per gain. The numerator
/// coefficients are all non-negative (checked at construction for the degree in use), so the
/// evaluation is accurate to a few ulps for every `n ≥ 0`.
///
/// ```
/// use seqsmooth::polynomial::expanding::gains::ExpandingGainSchedule;
/// let s = ExpandingGainSchedule::new(1);
/// let mut h = [0.0; 2];
/// s.gains(3, &mut h);
/// assert_eq!(h, [0.7, 0.3]); // Morrison T9-01: (7/10, 3/10)
/// ```
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct ExpandingGainSchedule {
    m: usize,
    /// The numerators' coefficients in `f64`, shared by every schedule of degree `m`.
    numerators: Arc<Vec<Vec<f64>>>,
}

impl ExpandingGainSchedule {
    /// The schedule for degree `m`.
    ///
    /// ```
    /// use seqsmooth::polynomial::expanding::gains::ExpandingGainSchedule;
    /// assert_eq!(ExpandingGainSchedule::new(2).degree(), 2);
    /// ```
    pub fn new(m: usize) -> Self {
        static NUMERATORS: Memo<usize, Vec<Vec<f64>>> = Memo::new();
        let numerators = NUMERATORS.get(m, || {
            expanding_gain_numerators(m)
                .iter()
                .map(|p| p.coeffs.iter().map(|c| c.to_f64()).collect())
                .collect()
        });
        Self { m, numerators }
    }

    /// Degree.
    ///
    /// ```
    /// use seqsmooth::polynomial::expanding::gains::ExpandingGainSchedule;
    /// assert_eq!(ExpandingGainSchedule::new(3).degree(), 3);
    /// ```
    pub fn degree(&self) -> usize {
        self.m
    }

    /// Writes `h_0(n) … h_m(n)` (current-estimate form) into `out`.
    ///
    /// ```
    /// use seqsmooth::polynomial::expanding::gains::ExpandingGainSchedule;
    /// let mut h = [0.0; 1];
    /// ExpandingGainSchedule::new(0).gains(4, &mut h);
    /// assert_eq!(h, [0.2]); // the running mean: 1/(n+1)
    /// ```
    pub fn gains(&self, n: u64, out: &mut [f64]) {
        let nf = n as f64;
        let mut den = 1.0;
        for l in 1..=self.m + 1 {
            den *= nf + l as f64;
        }
        for (o, num) in out.iter_mut().zip(self.numerators.iter()) {
            let mut acc = 0.0;
            for c in num.iter().rev() {
                acc = acc * nf + c;
            }
            *o = acc / den;
        }
    }

    /// The position gain `h_0(n)` (the current position VRF) for any `n`, huge ones included:
    /// the rational function of [`gains`](Self::gains), `P(n)/Π_{j=1}^{m+1} (n+j)`, written in
    /// `x = 1/(n+1)` and `r = n/(n+1)` as `x^(m+1−D) Σ_k c_k r^k x^(D−k) / Π_{j=0}^{m} (1+jx)`
    /// (`D` the degree of `P`), a homogeneous Horner sum of non-negative terms in which neither
    /// `n^D` nor `Π (n+j)` can overflow.
    ///
    /// ```
    /// use seqsmooth::polynomial::expanding::gains::ExpandingGainSchedule;
    /// let s = ExpandingGainSchedule::new(1);
    /// assert!((s.position_gain(3) - 0.7).abs() < 1e-15); // Morrison T9-01
    /// // 2(2n+1)/((n+1)(n+2)) → 4/n (Morrison (13.4.8)): 4e-18 at n = 1e18
    /// assert!((s.position_gain(1_000_000_000_000_000_000) * 1e18 - 4.0).abs() < 1e-12);
    /// ```
    pub fn position_gain(&self, n: u64) -> f64 {
        let x = 1.0 / (n as f64 + 1.0);
        let r = n as f64 * x;
        let coeffs = &self.numerators[0];
        let top = coeffs.len() - 1;
        let (mut acc, mut xp) = (0.0, 1.0);
        for c in coeffs.iter().rev() {
            acc = acc * r + c * xp;
            xp *= x;
        }
        let den: f64 = (0..=self.m).map(|j| 1.0 + j as f64 * x).product();
        acc * x.powi((self.m + 1 - top) as i32) / den
    }

    /// The gains as a vector.
    ///
    /// ```
    /// use seqsmooth::polynomial::expanding::gains::ExpandingGainSchedule;
    /// assert_eq!(ExpandingGainSchedule::new(1).gains_vec(3).as_slice(), &[0.7, 0.3]);
    /// ```
    pub fn gains_vec(&self, n: u64) -> DVector<f64> {
        let mut v = DVector::zeros(self.m + 1);
        self.gains(n, v.as_mut_slice());
        v
    }
}
