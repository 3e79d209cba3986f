//! The fading-memory gains of any degree (Morrison Table 13.1, (13.5.28)-(13.5.30); Reyneke
//! et al. §6.5-6.6), generic over [`Scalar`].

use crate::calculus::{choose, factorial, stirling1};
use crate::polynomial::form::{apply_form, GainForm};
use crate::scalar::Scalar;

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
