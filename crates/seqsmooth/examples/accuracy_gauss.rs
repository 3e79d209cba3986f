//! The accuracy of `basis::GaussRule` (ACCURACY.md, "Gauss rules"): the classical rules
//! against their independent values, and the discrete rule's exactness (Villien & Ostertag
//! 2009, Lemma 3) on samples with varying variances, by degree and sample count.
//!
//! `cargo run --release -p seqsmooth --example accuracy_gauss`

use seqsmooth::basis::Jacobi;
use std::f64::consts::PI;

fn legendre_by_newton(m: usize) -> (Vec<f64>, Vec<f64>) {
    let mut rule: Vec<(f64, f64)> = (0..m)
        .map(|k| {
            let mut x = (PI * (k as f64 + 0.75) / (m as f64 + 0.5)).cos();
            let mut dp = 0.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for j in 1..m {
                    let p2 = ((2 * j + 1) as f64 * x * p1 - j as f64 * p0) / (j + 1) as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = m as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-17 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect();
    rule.sort_by(|a, b| a.0.total_cmp(&b.0));
    rule.into_iter().unzip()
}

fn worst(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn main() {
    println!("n\tlegendre nodes\tlegendre weights\tchebyshev nodes\tchebyshev weights");
    for n in [5, 10, 20, 30, 50, 100] {
        let g = Jacobi::legendre(n, -1.0, 1.0).unwrap().gauss().unwrap();
        let (x, w) = legendre_by_newton(n + 1);
        let c = Jacobi::chebyshev(n, -1.0, 1.0).unwrap().gauss().unwrap();
        let m = (n + 1) as f64;
        let mut cx: Vec<f64> = (0..=n)
            .map(|k| ((2 * k + 1) as f64 * PI / (2.0 * m)).cos())
            .collect();
        cx.reverse();
        println!(
            "{n}\t{:.1e}\t{:.1e}\t{:.1e}\t{:.1e}",
            worst(&g.offsets, &x),
            worst(&g.weights, &w),
            worst(&c.offsets, &cx),
            worst(&c.weights, &vec![PI / m; n + 1])
        );
    }
    println!("\nN\tn\tworst |Σλf − Σwf| / Σw|f| over f = T_0..T_2n+1");
    for count in [50usize, 100, 200, 500, 1_000, 10_000, 100_000] {
        let mut t = Vec::with_capacity(count);
        let mut now = 1.7e9;
        for j in 0..count {
            now += 0.001 * (1.0 + ((j * 7919) % 97) as f64 / 10.0);
            t.push(now);
        }
        let w: Vec<f64> = (0..count)
            .map(|j| 1.0 / (1e-2 + ((j * 31) % 101) as f64))
            .collect();
        for n in [5, 10, 20, 30] {
            if n + 1 > count {
                continue;
            }
            let jac = Jacobi::discrete(&t, &w, n).unwrap();
            let g = jac.gauss().unwrap();
            let (c, h) = (jac.centre, jac.half);
            let mut bad: f64 = 0.0;
            for d in 0..=2 * n + 1 {
                let f = |o: f64| {
                    let u = o / h;
                    let (mut a, mut b) = (1.0, u);
                    if d == 0 {
                        return 1.0;
                    }
                    for _ in 1..d {
                        let next = 2.0 * u * b - a;
                        a = b;
                        b = next;
                    }
                    b
                };
                let exact: f64 = t.iter().zip(&w).map(|(&s, w)| w * f(s - c)).sum();
                let scale: f64 = t.iter().zip(&w).map(|(&s, w)| w * f(s - c).abs()).sum();
                bad = bad.max((g.integrate_offsets(f) - exact).abs() / scale);
            }
            println!("{count}\t{n}\t{bad:.1e}");
        }
    }
}
