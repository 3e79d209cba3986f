//! Exact-arithmetic helpers shared by the conformance tests, written independently of the
//! library: rational literals, factorials and binomials (Morrison (2.4.1), (2.5.1)), dense
//! polynomials, and small matrix algebra over the rationals.

use nalgebra::DMatrix;
use num_bigint::BigInt;
use num_traits::{One, Zero};
use seqsmooth::scalar::{parse_rational, ratio_to_f64, Rational};

pub type Q = Rational;

pub fn z(v: i64) -> Q {
    Q::from_integer(BigInt::from(v))
}

pub fn fr(n: i64, d: i64) -> Q {
    Q::new(BigInt::from(n), BigInt::from(d))
}

/// A rational literal such as "3/7", "-2" or "0.125".
pub fn q(s: &str) -> Q {
    parse_rational(s).unwrap_or_else(|| panic!("bad rational literal {s}"))
}

pub fn f(x: &Q) -> f64 {
    ratio_to_f64(x)
}

pub fn to_f64(a: &DMatrix<Q>) -> DMatrix<f64> {
    a.map(|v| f(&v))
}

pub fn qpow(x: &Q, k: usize) -> Q {
    (0..k).fold(Q::one(), |a, _| a * x.clone())
}

/// (-1)^k.
pub fn sign(k: usize) -> Q {
    if k.is_multiple_of(2) {
        Q::one()
    } else {
        -Q::one()
    }
}

/// x (x-1) ... (x-k+1).
pub fn ff(x: &Q, k: usize) -> Q {
    (0..k).fold(Q::one(), |a, i| a * (x.clone() - z(i as i64)))
}

/// x (x+1) ... (x+k-1).
pub fn rf(x: &Q, k: usize) -> Q {
    (0..k).fold(Q::one(), |a, i| a * (x.clone() + z(i as i64)))
}

pub fn fact(k: usize) -> Q {
    (1..=k).fold(Q::one(), |a, i| a * z(i as i64))
}

/// Binomial C(x, k) for any rational x (Morrison (2.5.1)).
pub fn bin(x: &Q, k: usize) -> Q {
    ff(x, k) / fact(k)
}

/// Integer binomial C(n, k), zero outside 0 <= k <= n.
pub fn c<T>(n: T, k: T) -> Q
where
    T: TryInto<i64>,
    T::Error: std::fmt::Debug,
{
    let (n, k) = (n.try_into().unwrap(), k.try_into().unwrap());
    if k < 0 || n < 0 || k > n {
        Q::zero()
    } else {
        bin(&z(n), k as usize)
    }
}

/// Σ_k coeffs[k] x^k (integer coefficients, lowest power first).
pub fn poly(coeffs: &[i64], x: &Q) -> Q {
    coeffs
        .iter()
        .rev()
        .fold(Q::zero(), |a, c| a * x.clone() + z(*c))
}

/// Σ_k coeffs[k] x^(n-k): the coefficients read highest power first.
pub fn rev_poly(coeffs: &[i64], x: &Q) -> Q {
    let r: Vec<i64> = coeffs.iter().rev().copied().collect();
    poly(&r, x)
}

// Dense polynomials with rational coefficients, lowest power first.
pub fn padd(a: &[Q], b: &[Q]) -> Vec<Q> {
    let n = a.len().max(b.len());
    (0..n)
        .map(|k| {
            a.get(k).cloned().unwrap_or_else(Q::zero) + b.get(k).cloned().unwrap_or_else(Q::zero)
        })
        .collect()
}

pub fn pmul(a: &[Q], b: &[Q]) -> Vec<Q> {
    let mut out = vec![Q::zero(); a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            out[i + j] = out[i + j].clone() + x.clone() * y.clone();
        }
    }
    out
}

pub fn pscale(a: &[Q], s: &Q) -> Vec<Q> {
    a.iter().map(|x| x.clone() * s.clone()).collect()
}

pub fn peval(a: &[Q], x: &Q) -> Q {
    a.iter()
        .rev()
        .fold(Q::zero(), |acc, c| acc * x.clone() + c.clone())
}

/// i-th derivative.
pub fn pderiv(a: &[Q], i: usize) -> Vec<Q> {
    if i >= a.len() {
        return vec![Q::zero()];
    }
    (i..a.len())
        .map(|k| a[k].clone() * ff(&z(k as i64), i))
        .collect()
}

/// The falling factorial x^(k) as a power-basis polynomial.
pub fn falling_poly(k: usize) -> Vec<Q> {
    (0..k).fold(vec![Q::one()], |p, i| pmul(&p, &[z(-(i as i64)), Q::one()]))
}

/// Σ_{x>=0} p(x) θ^x exactly for a polynomial p of degree <= deg: by Newton's forward series
/// p(x) = Σ_ν Δ^ν p(0) C(x,ν) (Morrison Ex 2.14) and Σ_x C(x,ν) θ^x = θ^ν/(1-θ)^(ν+1)
/// (Ex 3.11, (3.3.15)).
pub fn weighted_series_sum(p: impl Fn(&Q) -> Q, deg: usize, th: &Q) -> Q {
    let mut vals: Vec<Q> = (0..=deg).map(|x| p(&z(x as i64))).collect();
    let om = z(1) - th.clone();
    let mut total = Q::zero();
    for nu in 0..=deg {
        total += vals[0].clone() * qpow(th, nu) / qpow(&om, nu + 1);
        vals = vals
            .windows(2)
            .map(|w| w[1].clone() - w[0].clone())
            .collect();
    }
    total
}

pub fn mm(a: &DMatrix<Q>, b: &DMatrix<Q>) -> DMatrix<Q> {
    assert_eq!(a.ncols(), b.nrows());
    DMatrix::from_fn(a.nrows(), b.ncols(), |i, j| {
        (0..a.ncols()).fold(Q::zero(), |s, k| s + a[(i, k)].clone() * b[(k, j)].clone())
    })
}

pub fn eye(n: usize) -> DMatrix<Q> {
    DMatrix::from_fn(n, n, |i, j| if i == j { Q::one() } else { Q::zero() })
}

pub fn rows_to_matrix(rows: &[&[Q]]) -> DMatrix<Q> {
    DMatrix::from_fn(rows.len(), rows[0].len(), |i, j| rows[i][j].clone())
}

/// Morrison's scaled transition Φ(h), [Φ(h)]_ij = C(j,i) h^(j-i) (4.2.15), built here.
pub fn pascal(m: usize, h: &Q) -> DMatrix<Q> {
    DMatrix::from_fn(m + 1, m + 1, |i, j| {
        if j < i {
            Q::zero()
        } else {
            c(j, i) * qpow(h, j - i)
        }
    })
}

/// Exact inverse by Gauss-Jordan (own implementation).
pub fn inv(a: &DMatrix<Q>) -> DMatrix<Q> {
    let n = a.nrows();
    let mut m = a.clone();
    let mut r = eye(n);
    for col in 0..n {
        let p = (col..n)
            .find(|&i| !m[(i, col)].is_zero())
            .expect("singular");
        m.swap_rows(p, col);
        r.swap_rows(p, col);
        let d = m[(col, col)].clone();
        for j in 0..n {
            m[(col, j)] = m[(col, j)].clone() / d.clone();
            r[(col, j)] = r[(col, j)].clone() / d.clone();
        }
        for i in 0..n {
            if i != col && !m[(i, col)].is_zero() {
                let fct = m[(i, col)].clone();
                for j in 0..n {
                    m[(i, j)] = m[(i, j)].clone() - fct.clone() * m[(col, j)].clone();
                    r[(i, j)] = r[(i, j)].clone() - fct.clone() * r[(col, j)].clone();
                }
            }
        }
    }
    r
}
