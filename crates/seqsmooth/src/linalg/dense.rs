//! Dense kernels on column-major slices, for the Kalman filter's covariance arithmetic
//! (`kalman::correct`): products with a matrix given entry by entry (its zeros skipped),
//! symmetrisation, and the square-root-free Cholesky factorisation `V = L D Lᵀ` with
//! `ln det V`.
//!
//! They index slices in loops over `0..n`, with `n` a constant in every size
//! `unrolled_sizes!` dispatches (their callers are generic over `numeric::unrolled::Size`,
//! and these are inlined into them), so that the loops have constant trip counts and unroll.

/// `out = A Bᵀ` for `A` `n × n` (column-major `a`) and `B` `cols × n` (its entries `b(i, l)`),
/// column-major `out` (`n × cols`): each column of `out` an `axpy` of the columns of `A` with
/// `B`'s entries as the scalars, skipping the entries that are zero (adding `0 · a` changes
/// nothing for a finite `a`): `Φ` of the polynomial model is `Ψ ⊗ I`, mostly zeros, and so is
/// a radar's `M`.
#[inline(always)]
pub(crate) fn times_transpose(
    n: usize,
    a: &[f64],
    cols: usize,
    b: impl Fn(usize, usize) -> f64,
    out: &mut [f64],
) {
    let a = &a[..n * n];
    for i in 0..cols {
        let column = &mut out[i * n..(i + 1) * n];
        column.fill(0.0);
        for l in 0..n {
            let scale = b(i, l);
            if scale != 0.0 {
                let a = &a[l * n..(l + 1) * n];
                for r in 0..n {
                    column[r] += a[r] * scale;
                }
            }
        }
    }
}

/// `out = Σ_c b(c) a[:, c]` for one column `out` (`n`) and `a` `n × k`: each entry summed
/// over `c` in order (in a register, with both sizes constants).
#[inline(always)]
pub(crate) fn combine(n: usize, k: usize, a: &[f64], b: impl Fn(usize) -> f64, out: &mut [f64]) {
    let (a, out) = (&a[..n * k], &mut out[..n]);
    for r in 0..n {
        let mut acc = 0.0;
        for c in 0..k {
            acc += a[r + c * n] * b(c);
        }
        out[r] = acc;
    }
}

/// `a ← (a + aᵀ)/2` for an `n × n` column-major `a`.
#[inline(always)]
pub(crate) fn symmetrize(n: usize, a: &mut [f64]) {
    let a = &mut a[..n * n];
    for j in 0..n {
        for i in j + 1..n {
            let v = (a[i + j * n] + a[j + i * n]) * 0.5;
            a[i + j * n] = v;
            a[j + i * n] = v;
        }
    }
}

/// `a ← aᵀ` for an `n × n` column-major `a`.
#[inline(always)]
pub(crate) fn transpose(n: usize, a: &mut [f64]) {
    let a = &mut a[..n * n];
    for j in 0..n {
        for i in j + 1..n {
            a.swap(i + j * n, j + i * n);
        }
    }
}

/// Whether every entry of `a` is finite (no early exit: a reduction the compiler unrolls).
#[inline(always)]
pub(crate) fn all_finite(a: &[f64]) -> bool {
    a.iter().fold(true, |ok, v| ok & v.is_finite())
}

/// `V = L D Lᵀ` (`k × k`, column-major) into `l`: the unit lower triangle `L` below the
/// diagonal, `D` on it (left-looking: column `j` of `V` less `L_{·c} D_c L_{jc}` for `c < j`,
/// then divided by its pivot `D_j`); `false` if a pivot is not positive (`V` is not positive
/// definite). The square-root-free Cholesky factorisation: `V⁻¹` and `ln det V` follow from it
/// with no square root and fewer roundings.
#[inline(always)]
pub(crate) fn ldl(k: usize, v: &[f64], l: &mut [f64]) -> bool {
    let l = &mut l[..k * k];
    l.copy_from_slice(&v[..k * k]);
    for j in 0..k {
        for c in 0..j {
            let scale = l[j + c * k] * l[c + c * k];
            for i in j..k {
                l[i + j * k] -= l[i + c * k] * scale;
            }
        }
        let d = l[j + j * k];
        if d.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return false;
        }
        for i in j + 1..k {
            l[i + j * k] /= d;
        }
    }
    true
}

/// `ln det V = Σ ln D_c` from `V`'s [`ldl`] factors: one logarithm of the product while it
/// stays a normal number, else the sum of the logarithms.
#[inline(always)]
pub(crate) fn log_det(k: usize, l: &[f64]) -> f64 {
    let product: f64 = (0..k).map(|c| l[c + c * k]).product();
    if product.is_normal() {
        product.ln()
    } else {
        (0..k).map(|c| l[c + c * k].ln()).sum::<f64>()
    }
}
