//! `seqsmooth::basis::DiscreteLaguerre` against Morrison (1969) §3.3: the explicit forms (3.3.9)
//! and (3.3.10), orthogonality and norms (3.3.16), end values (13.5.1), the leading coefficient
//! (3.3.14) and the inverse relation (13.9.17), in exact rationals.

mod common;

use common::rational::*;
use num_bigint::BigInt;
use num_traits::{One, Signed, Zero};
use seqsmooth::basis::DiscreteLaguerre;

/// Morrison (3.3.9): p(x; j, θ) = Σ_ν (-1)^(j-ν) C(j,ν) θ^ν C(x+ν, j).
fn laguerre_3_3_9(j: usize, th: &Q, x: &Q) -> Q {
    (0..=j).fold(Q::zero(), |a, nu| {
        a + sign(j - nu)
            * c(j as i64, nu as i64)
            * qpow(th, nu)
            * bin(&(x.clone() + z(nu as i64)), j)
    })
}

/// Morrison (3.3.10): p(x; j, θ) = θ^j Σ_ν (-1)^ν C(j,ν) ((1-θ)/θ)^ν C(x,ν).
fn laguerre_3_3_10(j: usize, th: &Q, x: &Q) -> Q {
    let a = (z(1) - th.clone()) / th.clone();
    qpow(th, j)
        * (0..=j).fold(Q::zero(), |s, nu| {
            s + sign(nu) * c(j as i64, nu as i64) * qpow(&a, nu) * bin(x, nu)
        })
}

const THETAS: [(i64, i64); 6] = [(1, 2), (9, 10), (1, 3), (3, 5), (7, 8), (99, 100)];

#[test]
fn discrete_laguerre_explicit_forms_3_3_9_and_3_3_10() {
    // Source: Morrison (3.3.9), (3.3.10), (3.3.11), (13.2.2).
    for (n, d) in THETAS {
        let th = fr(n, d);
        let b = DiscreteLaguerre::new(th.clone());
        assert_eq!(b.theta(), &th);
        let mut xs: Vec<Q> = (0..=10).map(z).collect();
        xs.extend([z(-1), fr(5, 2), fr(-7, 3), z(37)]);
        for j in 0..=8usize {
            for x in &xs {
                let a = laguerre_3_3_9(j, &th, x);
                let b10 = laguerre_3_3_10(j, &th, x);
                assert_eq!(a, b10, "(3.3.9) vs (3.3.10), j = {j}, θ = {th}, x = {x}");
                assert_eq!(b.value(j, x.clone()), a, "value({j}, {x}), θ = {th}");
                assert_eq!(b.polynomial(j).eval(x), a);
            }
        }
        // (3.3.11) first members: p1 = θ[1 - a x], p2 = θ²[1 - 2ax + a² x(x-1)/2].
        let a = (z(1) - th.clone()) / th.clone();
        for x in &xs {
            assert_eq!(
                b.value(1, x.clone()),
                th.clone() * (z(1) - a.clone() * x.clone())
            );
            assert_eq!(
                b.value(2, x.clone()),
                th.clone()
                    * th.clone()
                    * (z(1) - z(2) * a.clone() * x.clone()
                        + a.clone() * a.clone() * ff(x, 2) / z(2))
            );
        }
    }
}

#[test]
fn discrete_laguerre_printed_values_tv3_2() {
    // Source: values derived from Morrison (3.3.10), x = 0..5.
    let cases: [(&str, usize, [&str; 6]); 5] = [
        ("1/2", 1, ["1/2", "0", "-1/2", "-1", "-3/2", "-2"]),
        ("1/2", 2, ["1/4", "-1/4", "-1/2", "-1/2", "-1/4", "1/4"]),
        ("1/2", 3, ["1/8", "-1/4", "-1/4", "0", "3/8", "3/4"]),
        ("9/10", 1, ["9/10", "4/5", "7/10", "3/5", "1/2", "2/5"]),
        (
            "9/10",
            2,
            ["81/100", "63/100", "23/50", "3/10", "3/20", "1/100"],
        ),
    ];
    for (th, j, vals) in cases {
        let b = DiscreteLaguerre::new(q(th));
        for (x, v) in vals.iter().enumerate() {
            assert_eq!(b.value(j, z(x as i64)), q(v), "TV3.2 p_{j}({x}; {th})");
        }
    }
    let b = DiscreteLaguerre::new(fr(1, 2));
    for (j, s) in ["2", "1", "1/2", "1/4"].iter().enumerate() {
        assert_eq!(b.norm_sq(j), q(s));
    }
    let b = DiscreteLaguerre::new(fr(9, 10));
    for (j, s) in ["10", "9", "81/10", "729/100"].iter().enumerate() {
        assert_eq!(b.norm_sq(j), q(s));
    }
}

#[test]
fn discrete_laguerre_orthogonality_and_norms_3_3_16() {
    // Source: Morrison (3.3.1), (3.3.12), (3.3.16): Σ_{x>=0} p_i p_j θ^x = δ_ij θ^j/(1-θ);
    // Reyneke et al. eq 24 (θ = 1/3 and 3/5).
    // (a) Exact infinite sums by the closed form of `weighted_series_sum`, j <= 6.
    for (n, d) in THETAS {
        let th = fr(n, d);
        let b = DiscreteLaguerre::new(th.clone());
        for i in 0..=6usize {
            for j in 0..=6usize {
                let s = weighted_series_sum(
                    |x| b.value(i, x.clone()) * b.value(j, x.clone()),
                    i + j,
                    &th,
                );
                let want = if i == j {
                    qpow(&th, j) / (z(1) - th.clone())
                } else {
                    Q::zero()
                };
                assert_eq!(s, want, "θ = {th}, ({i},{j})");
                if i == j {
                    assert_eq!(b.norm_sq(j), want);
                }
            }
        }
    }
    // (b) Brute-force partial sums to x = 400 in exact arithmetic, θ = 1/3 and 3/5, j <= 4.
    // Tail bound: |p_j(x)| <= Σ_ν C(j,ν) θ^(j-ν) (1-θ)^ν x^ν/ν! <= (1+x)^j, so the tail beyond 400
    // is below Σ_{x>400} (1+x)^8 θ^x < 401^8 θ^401 / (1 - θ(402/401)^8) < 1e-60.
    for th in [fr(1, 3), fr(3, 5)] {
        let b = DiscreteLaguerre::new(th.clone());
        let mut sums = vec![vec![Q::zero(); 5]; 5];
        let mut w = Q::one();
        for x in 0..=400i64 {
            let p: Vec<Q> = (0..=4).map(|j| b.value(j, z(x))).collect();
            for (i, row) in sums.iter_mut().enumerate() {
                for (j, cell) in row.iter_mut().enumerate().skip(i) {
                    *cell += p[i].clone() * p[j].clone() * w.clone();
                }
            }
            w *= th.clone();
        }
        let eps = fr(1, 1) / Q::from_integer(num_traits::pow(BigInt::from(10), 60));
        for (i, row) in sums.iter().enumerate() {
            for (j, sum) in row.iter().enumerate().skip(i) {
                let want = if i == j {
                    qpow(&th, j) / (z(1) - th.clone())
                } else {
                    Q::zero()
                };
                let err = (sum.clone() - want).abs();
                assert!(
                    err < eps,
                    "θ = {th}, ({i},{j}): partial-sum error too large"
                );
            }
        }
    }
}

#[test]
fn discrete_laguerre_end_values_13_5_1_and_leading_coefficient_3_3_14() {
    // Source: Morrison (13.5.1) p_j(-1) = 1; p(0; j, θ) = θ^j (3.3.11 note); (3.3.14) the
    // coefficient of x^(j) is (-1)^j (1-θ)^j / j!.
    for (n, d) in THETAS {
        let th = fr(n, d);
        let b = DiscreteLaguerre::new(th.clone());
        for j in 0..=12usize {
            assert_eq!(b.value(j, z(-1)), z(1), "p_{j}(-1), θ = {th}");
            assert_eq!(b.value(j, z(0)), qpow(&th, j));
            let poly = b.polynomial(j);
            let lead = poly.coeffs.get(j).cloned().unwrap_or_else(Q::zero);
            assert_eq!(
                lead,
                sign(j) * qpow(&(z(1) - th.clone()), j) / fact(j),
                "(3.3.14)"
            );
            assert!(poly.coeffs.iter().skip(j + 1).all(|v| v.is_zero()));
            // Taylor coefficients, used by the fading VRF (13.6.17), against the explicit form.
            let ex: Vec<Q> = (0..=j).fold(vec![Q::zero()], |acc, nu| {
                let a = (z(1) - th.clone()) / th.clone();
                let coef =
                    qpow(&th, j) * sign(nu) * c(j as i64, nu as i64) * qpow(&a, nu) / fact(nu);
                padd(&acc, &pscale(&falling_poly(nu), &coef))
            });
            for i in 0..=j {
                for x in [z(0), z(-1), fr(3, 2)] {
                    assert_eq!(b.taylor(i, j, &x), peval(&pderiv(&ex, i), &x) / fact(i));
                }
            }
        }
    }
    let bf = DiscreteLaguerre::new(0.5_f64);
    assert_eq!(bf.value(3, -1.0), 1.0);
}

#[test]
fn laguerre_inverse_relation_13_9_17() {
    // Source: Morrison (13.9.17) / Ex 13.22:
    // r^(i) = i! (θ/(1-θ))^i Σ_j (-1)^j C(i,j) p_j(r)/θ^j.
    for (n, d) in THETAS {
        let th = fr(n, d);
        let b = DiscreteLaguerre::new(th.clone());
        let ratio = th.clone() / (z(1) - th.clone());
        for i in 0..=7usize {
            for r in [z(0), z(4), fr(-3, 2), z(11)] {
                let s = (0..=i).fold(Q::zero(), |a, j| {
                    a + sign(j) * c(i as i64, j as i64) * b.value(j, r.clone()) / qpow(&th, j)
                });
                assert_eq!(
                    fact(i) * qpow(&ratio, i) * s,
                    ff(&r, i),
                    "i = {i}, θ = {th}, r = {r}"
                );
            }
        }
    }
}
