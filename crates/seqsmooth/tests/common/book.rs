//! The printed formulas of Morrison (1969) Tables 9.1 and 13.1 and Reyneke et al. (2012) §6.4,
//! §6.6, written out here, and the check of a computed value against a printed decimal.

use super::rational::*;
use nalgebra::DMatrix;
use num_traits::Zero;

/// Unit of the last printed digit of a decimal literal such as "0.13719201" or "6.0579161e-07".
pub fn last_digit_unit(s: &str) -> f64 {
    let (mant, exp) = match s.split_once(['e', 'E']) {
        Some((m, e)) => (m, e.parse::<i32>().unwrap()),
        None => (s, 0),
    };
    let decimals = mant.split_once('.').map_or(0, |(_, d)| d.len()) as i32;
    10f64.powi(exp - decimals)
}

/// |got - printed| <= half a unit in the last printed digit (plus rounding slack).
pub fn assert_printed(got: f64, printed: &str, what: &str) {
    let want: f64 = printed.parse().unwrap();
    let tol = 0.5 * last_digit_unit(printed) * (1.0 + 1e-6) + 1e-15 * want.abs();
    assert!(
        (got - want).abs() <= tol,
        "{what}: computed {got:.10e}, printed {printed} (tolerance {tol:.1e})"
    );
}

pub fn rel_err(got: f64, want: f64) -> f64 {
    if want == 0.0 {
        got.abs()
    } else {
        ((got - want) / want).abs()
    }
}

/// Morrison Table 9.1 (m <= 3, (9.4.18)-(9.4.19)) and Reyneke §6.4 (m = 4, 5): expanding-memory
/// current-estimate gains h_0(n)..h_m(n), n = 0-based index of the newest sample.
pub fn emp_book(m: usize, n: &Q) -> Vec<Q> {
    let p = |cs: &[i64]| poly(cs, n);
    let den = ff(&(n.clone() + z(m as i64 + 1)), m + 1); // (n+m+1)^(m+1)
    let nums: Vec<Q> = match m {
        0 => vec![z(1)],
        1 => vec![z(2) * p(&[1, 2]), z(6)],
        2 => vec![z(3) * p(&[2, 3, 3]), z(18) * p(&[1, 2]), z(30)],
        3 => vec![
            z(8) * p(&[3, 7, 3, 2]),
            z(20) * p(&[5, 6, 6]),
            z(120) * p(&[1, 2]),
            z(140),
        ],
        4 => vec![
            z(5) * p(&[24, 50, 55, 10, 5]),
            z(25) * p(&[20, 46, 18, 12]),
            z(1050) * p(&[1, 1, 1]),
            z(700) * p(&[1, 2]),
            z(630),
        ],
        5 => vec![
            z(6) * p(&[1, 2]) * p(&[120, 74, 77, 6, 3]),
            z(126) * p(&[28, 50, 55, 10, 5]),
            z(420) * p(&[1, 2]) * p(&[15, 4, 4]),
            z(1260) * p(&[7, 6, 6]),
            z(3780) * p(&[1, 2]),
            z(2772),
        ],
        _ => unreachable!(),
    };
    nums.into_iter().map(|v| v / den.clone()).collect()
}

/// Morrison Table 13.1 (m <= 4; degree 3 reconstructed from (13.5.3)) and Reyneke §6.6
/// (m <= 5): fading-memory current-estimate gains h_0(θ)..h_m(θ).
pub fn fmp_book(m: usize, th: &Q) -> Vec<Q> {
    let om = z(1) - th.clone();
    let o = |k: usize| qpow(&om, k);
    let p = |cs: &[i64]| poly(cs, th);
    let h0 = z(1) - qpow(th, m + 1);
    match m {
        0 => vec![h0],
        1 => vec![h0, o(2)],
        2 => vec![h0, fr(3, 2) * o(2) * p(&[1, 1]), fr(1, 2) * o(3)],
        3 => vec![
            h0,
            fr(1, 6) * o(2) * p(&[11, 14, 11]),
            o(3) * p(&[1, 1]),
            fr(1, 6) * o(4),
        ],
        4 => vec![
            h0,
            fr(5, 12) * o(2) * p(&[5, 7, 7, 5]),
            fr(5, 24) * o(3) * p(&[7, 10, 7]),
            fr(5, 12) * o(4) * p(&[1, 1]),
            fr(1, 24) * o(5),
        ],
        5 => vec![
            h0,
            fr(1, 60) * o(2) * p(&[137, 202, 222, 202, 137]),
            fr(5, 8) * o(3) * p(&[1, 1]) * p(&[3, 2, 3]),
            fr(1, 24) * o(4) * p(&[17, 26, 17]),
            fr(1, 8) * o(5) * p(&[1, 1]),
            fr(1, 120) * o(6),
        ],
        _ => unreachable!(),
    }
}

pub fn exact_thetas() -> Vec<Q> {
    ["1/2", "9/10", "99/100", "1/3", "7/8", "1/10", "999/1000"]
        .iter()
        .map(|s| q(s))
        .collect()
}

/// The exact least-squares weight vector of the newest sample in the degree-m fit over
/// r = 0..L (y_{n-k} at lag k, row T_k = (1, -k, k², ...) in the scaled state with τ = 1):
/// H = (TᵀT)⁻¹ e0, since Z*_{n,n} = (TᵀT)⁻¹ Tᵀ Y and T_0 = e0ᵀ (Morrison (6.5.x), (9.2.x)).
pub fn ls_normal_matrix(m: usize, l: u64) -> DMatrix<Q> {
    DMatrix::from_fn(m + 1, m + 1, |i, j| {
        (0..=l as i64).fold(Q::zero(), |s, k| s + qpow(&z(-k), i + j))
    })
}

/// κ_ij(m) = Σ_{k=max(i,j)}^{m} (2k+1) (k+i)!(k+j)! / (i! j! (k-i)! (k-j)!) (Morrison (7.6.12),
/// end-point closed form).
pub fn kappa(m: usize, i: usize, j: usize) -> Q {
    (i.max(j)..=m).fold(Q::zero(), |s, k| {
        s + z(2 * k as i64 + 1) * fact(k + i) * fact(k + j)
            / (fact(i) * fact(j) * fact(k - i) * fact(k - j))
    })
}
