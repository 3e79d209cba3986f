//! Why `paml::OnlineSmoother` accumulates rather than running the paper's recursion
//! (ACCURACY.md, "Online smoothing"): recursive least squares as Villien & Ostertag 2009
//! eqs. 34-35 write it, `A_k = A_{k−1} + K_k (y_k − V_kᵀ A_{k−1})`, `K_k = w_k P_k V_k`, in the
//! Legendre basis of the segment's span, started exactly from the interpolating polynomial of
//! the first `n+1` samples (better than `P_0 = huge·I`), `P_k` from a square-root information
//! factor; against the accumulated fit, in units of the smallest polynomial-sample σ.
//!
//! `cargo run --release -p seqsmooth --example accuracy_paml_online`

use nalgebra::{DMatrix, DVector};
use seqsmooth::basis::legendre::values as legendre;
use seqsmooth::paml::SmootherGains;

/// `R ← the triangular factor of [R; s vᵀ]` by Givens rotations.
fn add_row(r: &mut DMatrix<f64>, v: &[f64], s: f64) {
    let mut row: Vec<f64> = v.iter().map(|v| s * v).collect();
    for i in 0..row.len() {
        let (a, b) = (r[(i, i)], row[i]);
        if b == 0.0 {
            continue;
        }
        let h = a.hypot(b);
        let (c, sn) = (a / h, b / h);
        for j in i..row.len() {
            let (x, y) = (r[(i, j)], row[j]);
            r[(i, j)] = c * x + sn * y;
            row[j] = c * y - sn * x;
        }
    }
}

fn main() {
    println!("N\tn\tmax |RLS − fit| / σ_min");
    for (count, n) in [
        (50usize, 3usize),
        (1_000, 5),
        (1_200, 5),
        (1_000, 8),
        (10_000, 5),
    ] {
        let t: Vec<f64> = (0..count).map(|k| k as f64 * 4e-6).collect();
        let sigma: Vec<f64> = (0..count).map(|k| 1.0 + (k % 7) as f64).collect();
        let y: Vec<f64> = t.iter().map(|t| 5.0 * (2000.0 * t).sin()).collect();
        let (c, h) = ((t[0] + t[count - 1]) / 2.0, (t[count - 1] - t[0]) / 2.0);
        let row = |s: f64| legendre(n, (s - c) / h);
        let size = n + 1;
        let v0 = DMatrix::from_fn(size, size, |k, i| row(t[k])[i]);
        let mut a = v0.try_inverse().unwrap() * DVector::from_fn(size, |k, _| y[k]);
        let mut r = DMatrix::<f64>::zeros(size, size);
        for k in 0..size {
            add_row(&mut r, &row(t[k]), 1.0 / sigma[k]);
        }
        for k in size..count {
            let v = row(t[k]);
            add_row(&mut r, &v, 1.0 / sigma[k]);
            let mut x = DVector::from_column_slice(&v);
            r.tr_solve_upper_triangular_mut(&mut x);
            r.solve_upper_triangular_mut(&mut x);
            let e = y[k] - v.iter().zip(a.iter()).map(|(v, a)| v * a).sum::<f64>();
            a += x * (e / (sigma[k] * sigma[k]));
        }
        let gains = SmootherGains::new(&t, &sigma, n).unwrap();
        let mut s = gains.smoother();
        s.push_all(&y).unwrap();
        let ps = s.polynomial_samples().unwrap();
        let worst = ps
            .offsets
            .iter()
            .zip(&ps.values)
            .map(|(&o, v)| {
                let rls: f64 = row(ps.centre + o)
                    .iter()
                    .zip(a.iter())
                    .map(|(b, a)| b * a)
                    .sum();
                (rls - v).abs()
            })
            .fold(0.0, f64::max);
        let sd = ps
            .variances
            .iter()
            .fold(f64::INFINITY, |m, v| m.min(v.sqrt()));
        println!("{count}\t{n}\t{:.1e}", worst / sd);
    }
}
