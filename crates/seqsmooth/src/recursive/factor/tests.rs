use super::*;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

/// Largest relative difference between two matrices (relative to the larger's max entry).
fn rel_diff(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    let scale = a.amax().max(b.amax()).max(f64::MIN_POSITIVE);
    (a - b).amax() / scale
}

/// Gentleman's sequential rotations for any state (the reference for the reciprocal form).
fn add_row_sequential(f: &mut TriangularFactor, a: &[f64], b: f64, weight: f64) {
    f.scratch.clear();
    f.scratch.extend_from_slice(a);
    f.add_row_gentleman_any(b, weight);
    f.refresh_positive();
}

fn random_row(rng: &mut StdRng, p: usize) -> (Vec<f64>, f64, f64) {
    let a = (0..p).map(|_| rng.gen_range(-2.0..2.0)).collect();
    (a, rng.gen_range(-5.0..5.0), rng.gen_range(0.1..10.0))
}

#[test]
fn reciprocal_form_equals_sequential_rotations() {
    // Sizes with and without a fixed-size kernel; weights over many decades, as the lazy
    // fading-memory discount produces.
    let mut rng = StdRng::seed_from_u64(7);
    for p in 1..=12 {
        let mut fast = TriangularFactor::new(p);
        let mut reference = TriangularFactor::new(p);
        for k in 0..200usize {
            let (a, b, w) = random_row(&mut rng, p);
            // Weights growing by 1.2 per row (cosines near 1), then by 4 (cosines near 1/4).
            let w = w * if k < 100 {
                1.2f64.powi(k as i32)
            } else {
                4f64.powi(k as i32 - 100)
            };
            fast.add_row(&a, b, w);
            add_row_sequential(&mut reference, &a, b, w);
            if k >= p {
                assert!(fast.positive, "p={p} k={k}");
            }
        }
        let (r, r0) = (fast.r(), reference.r());
        let d = rel_diff(&r, &r0);
        let rhs = rel_diff(
            &DMatrix::from_column_slice(p, 1, fast.rhs().as_slice()),
            &DMatrix::from_column_slice(p, 1, reference.rhs().as_slice()),
        );
        let res = (fast.residual_sq() - reference.residual_sq()).abs() / reference.residual_sq();
        eprintln!("p={p}: R {d:.1e}, rhs {rhs:.1e}, residual {res:.1e}");
        assert!(
            d < 1e-14 && rhs < 1e-14 && res < 1e-12,
            "p={p}: {d:e} {rhs:e} {res:e}"
        );
    }
}

#[test]
fn rows_equal_the_normal_equations() {
    // Independent check of both forms: RᵀR = Σ w a aᵀ, Rᵀd = Σ w a b.
    let mut rng = StdRng::seed_from_u64(8);
    for p in [1, 3, 6, 9, 11] {
        let mut f = TriangularFactor::new(p);
        let mut gram = DMatrix::zeros(p, p);
        let mut atb = DVector::zeros(p);
        for _ in 0..3 * p + 5 {
            let (a, b, w) = random_row(&mut rng, p);
            f.add_row(&a, b, w);
            let a = DVector::from_vec(a);
            gram += &a * a.transpose() * w;
            atb += &a * (w * b);
        }
        assert!(rel_diff(&f.gram(), &gram) < 1e-13, "p={p}");
        let rtd = f.r().transpose() * f.rhs();
        assert!(
            rel_diff(
                &DMatrix::from_column_slice(p, 1, rtd.as_slice()),
                &DMatrix::from_column_slice(p, 1, atb.as_slice())
            ) < 1e-12,
            "p={p}"
        );
    }
}

#[test]
fn zero_pivots_and_zero_weights_leave_the_factor_alone() {
    for p in [3, 4, 10] {
        let mut f = TriangularFactor::new(p);
        // Rows reaching only the first pivots: the rest stay empty (zero pivots).
        let mut a = vec![0.0; p];
        a[0] = 1.0;
        f.add_row(&a, 2.0, 1.0);
        a[1] = 3.0;
        f.add_row(&a, 1.0, 0.5);
        assert!(!f.is_determined() && !f.positive);
        assert!(f.d[2..].iter().all(|d| d.0 == 0.0) && f.u.iter().all(|v| v.is_finite()));
        for k in 0..p {
            let mut a = vec![0.0; p];
            a[k] = 1.0 + k as f64;
            a[p - 1] += 0.5;
            f.add_row(&a, k as f64, 2.0);
        }
        assert!(f.is_determined() && f.positive);
        let before = (f.r(), f.rhs(), f.residual_sq());
        f.add_row(&vec![1.0; p], 3.0, 0.0);
        f.add_row_powers(0.5, 3.0, 0.0);
        assert_eq!((f.r(), f.rhs(), f.residual_sq()), before);
    }
}

#[test]
fn underflowing_discount_falls_back_to_sequential_rotations() {
    let mut f = TriangularFactor::new(3);
    for v in [-1.0, 0.0, 1.0, 2.0] {
        f.add_row_powers(v, v * v, 1.0);
    }
    assert!(f.positive);
    f.discount(1e-310);
    assert!(!f.positive && f.is_determined());
    f.add_row_powers(0.5, 0.25, 1.0);
    let mut x = [0.0; 3];
    assert!(f.solve_into(&mut x));
    assert!((x[0]).abs() < 1e-12 && x[1].abs() < 1e-12 && (x[2] - 1.0).abs() < 1e-12);
}

#[test]
fn polynomial_change_of_variables_equals_the_explicit_matrix() {
    let mut rng = StdRng::seed_from_u64(9);
    for p in 1..=12 {
        let mut worst = 0.0f64;
        for (alpha, beta) in [
            (1.0, 0.375),
            (2.0, -1.25),
            (0.5, 0.0),
            (0.25, 3.5),
            (1.5, -0.3),
        ] {
            let mut f = TriangularFactor::new(p);
            for _ in 0..p + 3 {
                let (a, b, w) = random_row(&mut rng, p);
                f.add_row(&a, b, w);
            }
            let mut g = f.clone();
            f.change_variables_polynomial(alpha, beta);
            let a = DMatrix::from_fn(p, p, |k, j| {
                if j < k {
                    0.0
                } else {
                    crate::calculus::choose::<f64>(j, k) * (-beta).powi((j - k) as i32)
                        / alpha.powi(j as i32)
                }
            });
            g.change_variables_upper(&a);
            let d = rel_diff(&f.r(), &g.r());
            let rhs = rel_diff(
                &DMatrix::from_column_slice(p, 1, f.rhs().as_slice()),
                &DMatrix::from_column_slice(p, 1, g.rhs().as_slice()),
            );
            assert!(
                d < 1e-14 && rhs < 1e-14,
                "p={p} α={alpha} β={beta}: {d:e} {rhs:e}"
            );
            worst = worst.max(d).max(rhs);
        }
        eprintln!("p={p}: worst {worst:.1e}");
    }
}

#[test]
fn power_rows_equal_explicit_rows() {
    let mut rng = StdRng::seed_from_u64(10);
    for p in [1, 5, 9, 10, 14] {
        let (mut f, mut g) = (TriangularFactor::new(p), TriangularFactor::new(p));
        for _ in 0..2 * p + 3 {
            let v: f64 = rng.gen_range(-1.5..1.5);
            let mut a = vec![1.0; p];
            for k in 1..p {
                a[k] = a[k - 1] * v;
            }
            f.add_row_powers(v, v.sin(), 3.0);
            g.add_row(&a, v.sin(), 3.0);
        }
        assert_eq!(
            (f.r(), f.rhs(), f.residual_sq()),
            (g.r(), g.rhs(), g.residual_sq())
        );
    }
}
