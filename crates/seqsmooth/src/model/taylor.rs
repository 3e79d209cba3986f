//! `Φ(h) z` as an in-place Taylor shift, and the scaling `D(τ) = diag(k!/τ^k)` between
//! Morrison's scaled state and unscaled derivatives (Morrison (4.2.15), (4.2.18)-(4.2.19)).
//!
//! If `z` holds the coefficients of `f(u) = Σ z_k u^k`, `Φ(h) z` holds those of `f(u + h)`:
//! repeated synthetic division, `z_k += h·z_{k+1}` for `i = 0 … m−1` and `k = m−1` down to
//! `i` (`O(m²)`, `for_each_shift_step` gives that order once for every variant: plain,
//! compensated, on arrays, on the rows of a bank). The factors `k!/τ^k` are running products
//! `k! = (k−1)!·k`, `τ^k = τ^(k−1)·τ` (`factorial_powers`), the same operations wherever
//! they are used.

use crate::calculus::factorial;
use crate::numeric::double_word::{two_prod, two_sum};
use crate::numeric::unrolled::unrolled_sizes;
use crate::scalar::Scalar;
use nalgebra::DMatrix;

/// The order of the Taylor shift of `n` coefficients: calls `step(k)` for
/// `z_k += h·z_{k+1}`, for `i = 0 … n−2` and `k = n−2` down to `i`.
#[inline(always)]
pub(crate) fn for_each_shift_step(n: usize, mut step: impl FnMut(usize)) {
    for i in 0..n.saturating_sub(1) {
        for k in (i..n - 1).rev() {
            step(k);
        }
    }
}

/// In-place Taylor shift `z ← Φ(h) z` in `O(m²)` operations: if `z` holds the coefficients of
/// `f(u) = Σ z_k u^k`, afterwards it holds those of `f(u + h)` (repeated synthetic division).
///
/// ```
/// use seqsmooth::model::shift_scaled;
/// let mut z = [1.0, 2.0, 3.0];      // 1 + 2u + 3u²
/// shift_scaled(&mut z, 1.0);        // 6 + 8u + 3u²
/// assert_eq!(z, [6.0, 8.0, 3.0]);
/// ```
pub fn shift_scaled(z: &mut [f64], h: f64) {
    if z.len() < 2 || h == 0.0 {
        return;
    }
    // Fixed lengths unroll completely (the same operations in the same order).
    unrolled_sizes!(z.len(), N => shift_any(&mut z[..N], h), _ => shift_any(z, h));
}

/// [`shift_scaled`] for a length known at compile time (unrolled where it is inlined; the
/// same operations in the same order).
#[inline(always)]
pub(crate) fn shift_scaled_array<const N: usize>(z: &mut [f64; N], h: f64) {
    if N >= 2 && h != 0.0 {
        shift_any(z, h);
    }
}

#[inline(always)]
fn shift_any(z: &mut [f64], h: f64) {
    for_each_shift_step(z.len(), |k| z[k] += h * z[k + 1]);
}

/// [`shift_scaled`] in compensated (double-word) arithmetic: the state is `hi + lo` per
/// component, each product's and sum's rounding error is carried in `lo` (TwoSum and
/// Dekker's product, [`crate::numeric::double_word`]; Graillat–Langlois–Louvet's compensated
/// Horner scheme). The result is as accurate as if computed in twice the working precision,
/// which matters because the Taylor coefficients of a polynomial about the end of its data
/// interval are an ill-conditioned representation (cancellation of order `(1+√2)^(2m)` at
/// degree `m`).
///
/// ```
/// use seqsmooth::model::shift_scaled_compensated;
/// let mut hi = [1.0, 2.0, 3.0];
/// let mut lo = [0.0; 3];
/// shift_scaled_compensated(&mut hi, &mut lo, 1.0);
/// assert_eq!(hi, [6.0, 8.0, 3.0]);
/// ```
pub fn shift_scaled_compensated(hi: &mut [f64], lo: &mut [f64], h: f64) {
    let n = hi.len();
    if n < 2 || h == 0.0 {
        return;
    }
    for_each_shift_step(n, |k| {
        let (p, pe) = two_prod(h, hi[k + 1]);
        let (s, se) = two_sum(hi[k], p);
        lo[k] += h * lo[k + 1] + pe + se;
        hi[k] = s;
    });
    for k in 0..n {
        let (s, e) = two_sum(hi[k], lo[k]);
        hi[k] = s;
        lo[k] = e;
    }
}

/// `(k!, τ^k)` for `k = 0, 1, 2, …`, as running products.
#[inline(always)]
pub(crate) fn factorial_powers(tau: f64) -> impl Iterator<Item = (f64, f64)> {
    (0..).scan((1.0, 1.0), move |(f, tk), k: usize| {
        if k > 0 {
            *f *= k as f64;
            *tk *= tau;
        }
        Some((*f, *tk))
    })
}

/// `z·k!/τ^k` one factor at a time, for a `τ` whose powers leave the double range (`τ^k`
/// over- or underflows, so that `k!/τ^k` would be infinite or zero): a zero stays zero, and the
/// result over- or underflows only where the derivative itself does.
pub(crate) fn unscale_stepwise(z: f64, k: usize, tau: f64) -> f64 {
    (1..=k).fold(z, |x, i| x * i as f64 / tau)
}

/// Whether `k!/τ^k`, `k ≤ m`, are all normal doubles (else [`unscale_stepwise`]).
pub(crate) fn unscale_in_range(m: usize, tau: f64) -> bool {
    derivative_scale(tau).take(m + 1).all(f64::is_normal)
}

/// The diagonal of `D(τ)`, `k!/τ^k` for `k = 0, 1, 2, …` (each rounded once from the running
/// products of [`factorial_powers`]).
#[inline(always)]
pub(crate) fn derivative_scale(tau: f64) -> impl Iterator<Item = f64> {
    factorial_powers(tau).map(|(f, tk)| f / tk)
}

/// The scaling matrix `D(τ) = diag(k!/τ^k)` with `X = D(τ) Z` (Morrison (4.2.18)-(4.2.19)).
///
/// ```
/// use seqsmooth::model::scaling;
/// let d = scaling(2, 0.5_f64);
/// assert_eq!(d[(2, 2)], 8.0); // 2!/0.5²
/// ```
pub fn scaling<T: Scalar>(m: usize, tau: T) -> DMatrix<T> {
    let d = scaling_diagonal(m, tau);
    DMatrix::from_fn(
        m + 1,
        m + 1,
        |i, j| if i == j { d[i].clone() } else { T::zero() },
    )
}

/// The diagonal of [`scaling`], `k!/τ^k` for `k = 0 … m`, each as `k!` over `τ.powi_u(k)`
/// (for `f64`: `factorial(k) / τ.powi(k)`, the form of the matrices built from it; the
/// recursions' read-outs use the running products of [`derivative_scale`]).
pub(crate) fn scaling_diagonal<T: Scalar>(m: usize, tau: T) -> Vec<T> {
    (0..=m).map(|k| factorial::<T>(k) / tau.powi_u(k)).collect()
}

/// Converts Morrison's scaled state `Z` (unit `τ`) to unscaled derivatives `X = D(τ) Z`.
///
/// ```
/// use seqsmooth::model::scaled_to_derivatives;
/// assert_eq!(scaled_to_derivatives(&[1.0, 2.0, 3.0], 2.0), vec![1.0, 1.0, 1.5]);
/// ```
pub fn scaled_to_derivatives(z: &[f64], tau: f64) -> Vec<f64> {
    z.iter()
        .zip(factorial_powers(tau))
        .enumerate()
        .map(|(k, (&v, (f, tk)))| {
            if tk.is_normal() {
                v * f / tk
            } else {
                unscale_stepwise(v, k, tau)
            }
        })
        .collect()
}

/// Converts unscaled derivatives `X` to Morrison's scaled state `Z = D(τ)⁻¹ X`.
///
/// ```
/// use seqsmooth::model::derivatives_to_scaled;
/// assert_eq!(derivatives_to_scaled(&[1.0, 1.0, 1.5], 2.0), vec![1.0, 2.0, 3.0]);
/// ```
pub fn derivatives_to_scaled(x: &[f64], tau: f64) -> Vec<f64> {
    x.iter()
        .zip(factorial_powers(tau))
        .map(|(&v, (f, tk))| v * tk / f)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::phi;
    use crate::scalar::{rational_from_f64, Rational};

    /// The running products are `k!` and `τ^k` (exact for τ a power of two), and
    /// `derivative_scale` is their quotient.
    #[test]
    fn factorial_powers_are_factorials_and_powers() {
        let got: Vec<(f64, f64)> = factorial_powers(0.5).take(6).collect();
        let want: Vec<(f64, f64)> = (0..6)
            .map(|k| (factorial::<f64>(k), 0.5f64.powi(k as i32)))
            .collect();
        assert_eq!(got, want);
        let d: Vec<f64> = derivative_scale(2.0).take(4).collect();
        assert_eq!(d, vec![1.0, 0.5, 0.5, 0.75]);
    }

    /// Every shift variant against `Φ(h) z` in exact rationals, degrees 0 … 8.
    #[test]
    fn shifts_match_the_exact_transition() {
        for n in 1..=9usize {
            let z: Vec<f64> = (0..n).map(|k| 1.0 / (k as f64 + 1.5)).collect();
            for h in [0.0, 1.0, -0.75, 3.3] {
                let p = phi::<Rational>(n - 1, rational_from_f64(h).unwrap());
                let zr: Vec<Rational> = z.iter().map(|&v| rational_from_f64(v).unwrap()).collect();
                let want: Vec<f64> = (0..n)
                    .map(|i| {
                        (0..n)
                            .fold(Rational::from_i64(0), |acc, j| acc + &p[(i, j)] * &zr[j])
                            .to_f64()
                    })
                    .collect();
                let scale = want.iter().fold(1.0f64, |a, w| a.max(w.abs()));
                let mut plain = z.clone();
                shift_scaled(&mut plain, h);
                let mut arr = [0.0; 9];
                arr[..n].copy_from_slice(&z);
                let (mut hi, mut lo) = (z.clone(), vec![0.0; n]);
                shift_scaled_compensated(&mut hi, &mut lo, h);
                for k in 0..n {
                    assert!((plain[k] - want[k]).abs() <= 1e-13 * scale, "n {n} h {h}");
                    assert!(
                        (hi[k] + lo[k] - want[k]).abs() <= 1e-16 * scale,
                        "n {n} h {h}"
                    );
                }
                if n == 9 {
                    shift_scaled_array(&mut arr, h);
                    assert_eq!(&arr[..], &plain[..]);
                }
            }
        }
    }
}
