//! The fading-memory gains of any degree (Morrison Table 13.1, (13.5.28)-(13.5.30); Reyneke
//! et al. §6.5-6.6), generic over [`Scalar`].

use crate::calculus::{choose, choose_integer, factorial, stirling1};
use crate::polynomial::form::{apply_form, GainForm};
use crate::scalar::{rational_from_f64, Rational, Scalar};
use num_bigint::BigInt;

/// Fading-memory gains `h_0(θ) … h_m(θ)` of degree `m` (Morrison Table 13.1, `H = P(0) L`
/// (13.5.28)-(13.5.30); Reyneke §6.5-6.6):
///
/// `h_k = (1-θ) Σ_{j=k..m} Σ_{v=k..j} C(j,v) θ^(j-v) (1-θ)^v |s(v,k)| / v!`,
///
/// a sum of non-negative terms (so accurate in `f64` for every `θ ∈ (0,1)`). `h_0 = 1 - θ^(m+1)`.
///
/// ```
/// use seqsmooth::polynomial::fading::gains::fading_gains;
/// use seqsmooth::polynomial::form::GainForm;
/// let g = fading_gains(2, 0.9_f64, GainForm::Current);
/// assert!((g[0] - 0.271).abs() < 1e-15 && (g[1] - 0.0285).abs() < 1e-15 && (g[2] - 0.0005).abs() < 1e-16);
/// ```
pub fn fading_gains<T: Scalar>(m: usize, theta: T, form: GainForm) -> Vec<T> {
    let s1 = stirling1::<T>(m);
    let om = T::one() - theta.clone();
    let h: Vec<T> = (0..=m)
        .map(|k| {
            let mut acc = T::zero();
            for j in k..=m {
                for v in k..=j {
                    acc = acc
                        + choose::<T>(j, v)
                            * theta.powi_u(j - v)
                            * om.powi_u(v)
                            * s1[(v, k)].abs_val()
                            / factorial::<T>(v);
                }
            }
            om.clone() * acc
        })
        .collect();
    apply_form(m, h, form)
}

/// The current-estimate gains of [`fading_gains`] at an `f64` `θ`, exactly, computed on one
/// common denominator: with `θ = p/D` (`D` a power of two) and `1 − θ = q/D`,
/// `h_k = q·S_k / (D^(m+1) m!)`, `S_k = Σ_{j,v} C(j,v) |s(v,k)| (m!/v!) p^(j−v) q^v D^(m−j)`,
/// an integer. The same values as `fading_gains::<Rational>` without reducing a fraction at
/// every step, whose cost grows steeply with the degree.
pub(crate) fn fading_gains_exact(m: usize, theta: f64) -> Vec<Rational> {
    let theta = rational_from_f64(theta).expect("finite θ");
    let (p, d) = (theta.numer().clone(), theta.denom().clone());
    let q = &d - &p;
    let int = |r: &Rational| r.to_integer();
    let s1 = stirling1::<Rational>(m);
    let powers = |x: &BigInt| {
        let mut v = vec![BigInt::from(1)];
        for a in 0..m {
            let next = &v[a] * x;
            v.push(next);
        }
        v
    };
    let (pp, qp, dp) = (powers(&p), powers(&q), powers(&d));
    let fact = |k: usize| (1..=k).fold(BigInt::from(1), |acc, i| acc * BigInt::from(i));
    let m_fact = fact(m);
    let den = &dp[m] * &d * &m_fact;
    (0..=m)
        .map(|k| {
            let mut sum = BigInt::from(0);
            for j in k..=m {
                for v in k..=j {
                    let c = choose_integer(j, v) * int(&s1[(v, k)].abs_val()) * (&m_fact / fact(v));
                    sum += c * &pp[j - v] * &qp[v] * &dp[m - j];
                }
            }
            Rational::new(&q * sum, den.clone())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The common-denominator form equals the generic formula in rationals, term for term.
    #[test]
    fn exact_gains_equal_the_rational_formula() {
        for m in 0..=9 {
            for theta in [0.5, 0.9, 0.95, 0.99, 1.0 / 3.0, 0.123_456_789] {
                let want = fading_gains::<Rational>(
                    m,
                    rational_from_f64(theta).unwrap(),
                    GainForm::Current,
                );
                assert_eq!(fading_gains_exact(m, theta), want, "m={m} θ={theta}");
            }
        }
    }
}
