//! `estimate::batch`: the minimum-variance and least-squares estimates against Morrison's worked
//! examples (ch. 6, the running example `Z = (x, τẋ)`, `Φ(h) = [[1, h], [0, 1]]`, `M = (1, 0)`,
//! `L = 2`; Ex. 6.12-6.16), against the same estimate in exact rationals, and against the
//! polynomial fit on irregular times; the rank test of §8.9 (Examples 1 and 2); bad input.

use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use seqsmooth::estimate::batch::{least_squares, minimum_variance, NoiseCovariance};
use seqsmooth::estimate::PolynomialFit;
use seqsmooth::linalg::inverse_exact;
use seqsmooth::scalar::{rational_from_f64, Rational, Scalar};
use seqsmooth::Error;

/// Morrison (6.3.25)-(6.3.27): rows `M Φ(−k)`, `k = 0, 1, 2`.
fn running_t() -> DMatrix<f64> {
    DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 1.0, -1.0, 1.0, -2.0])
}

/// Morrison (6.5.15): `Y = (3.1, 2.2, 0.9)`.
fn running_y() -> DVector<f64> {
    DVector::from_vec(vec![3.1, 2.2, 0.9])
}

fn assert_matrix(got: &DMatrix<f64>, want: &[f64], tol: f64, what: &str) {
    let want = DMatrix::from_row_slice(got.nrows(), got.ncols(), want);
    let err = (got - &want).amax();
    assert!(err <= tol, "{what}: {got} against {want} (error {err:e})");
}

fn assert_vector(got: &DVector<f64>, want: &[f64], tol: f64, what: &str) {
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        assert!(
            (g - w).abs() <= tol * w.abs().max(1.0),
            "{what}[{k}]: {g} against {w}"
        );
    }
    assert_eq!(got.len(), want.len(), "{what}");
}

#[test]
fn least_squares_running_example() {
    // (6.5.15)-(6.5.23): X̂ = (19/6, 1.1); R = diag(1, 2, 2): Ŝ = (1/36)[[35, 21], [21, 27]].
    let r = NoiseCovariance::Variances(vec![1.0, 2.0, 2.0]);
    let e = least_squares(&running_t(), &running_y(), &r).unwrap();
    assert_vector(&e.state, &[19.0 / 6.0, 1.1], 1e-14, "X̂");
    let s = [35.0 / 36.0, 21.0 / 36.0, 21.0 / 36.0, 27.0 / 36.0];
    assert_matrix(&e.covariance, &s, 1e-15, "Ŝ");
    // Residual calibration (6.10.x) with P = I: residual (-1/15, 2/15, -1/15), e = 2/75.
    let e = least_squares(&running_t(), &running_y(), &NoiseCovariance::Identity).unwrap();
    assert!(
        (e.chi_squared - 2.0 / 75.0).abs() < 1e-15,
        "{}",
        e.chi_squared
    );
    assert_eq!(e.degrees_of_freedom, 1);
}

#[test]
fn minimum_variance_running_example() {
    // (6.6.36)-(6.6.39): S° = [[10/11, 6/11], [6/11, 8/11]], X° = W° Y = (69/22, 119/110).
    let r = NoiseCovariance::Variances(vec![1.0, 2.0, 2.0]);
    let e = minimum_variance(&running_t(), &running_y(), &r).unwrap();
    assert_vector(&e.state, &[69.0 / 22.0, 119.0 / 110.0], 1e-14, "X°");
    let s = [10.0 / 11.0, 6.0 / 11.0, 6.0 / 11.0, 8.0 / 11.0];
    assert_matrix(&e.covariance, &s, 1e-15, "S°");
    // Residual (-2/55, 8/55, -4/55), e° = 4/275, one degree of freedom.
    assert!(
        (e.chi_squared - 4.0 / 275.0).abs() < 1e-16,
        "{}",
        e.chi_squared
    );
    assert_eq!(e.degrees_of_freedom, 1);
    // (6.7.23): Ŝ − S° = (1/396)[[25, 15], [15, 9]], non-negative definite.
    let ls = least_squares(&running_t(), &running_y(), &r).unwrap();
    let d = [25.0 / 396.0, 15.0 / 396.0, 15.0 / 396.0, 9.0 / 396.0];
    assert_matrix(&(&ls.covariance - &e.covariance), &d, 1e-15, "Ŝ − S°");
}

#[test]
fn full_noise_covariance_ex_6_12_and_6_13() {
    // R = [[2, −1, 0], [−1, 2, −1], [0, −1, 2]]: S° = [[6/5, 1], [1, 1]] (Ex. 6.12);
    // least squares Ŝ = [[11/9, 1], [1, 1]] (Ex. 6.13), Ŝ − S° = diag(1/45, 0).
    let r = DMatrix::from_row_slice(3, 3, &[2.0, -1.0, 0.0, -1.0, 2.0, -1.0, 0.0, -1.0, 2.0]);
    let r = NoiseCovariance::Full(r);
    let mv = minimum_variance(&running_t(), &running_y(), &r).unwrap();
    assert_matrix(&mv.covariance, &[1.2, 1.0, 1.0, 1.0], 1e-15, "S°");
    // W° = [[4/5, 2/5, −1/5], [1/2, 0, −1/2]] applied to Y.
    let (y0, y1, y2) = (3.1, 2.2, 0.9);
    let want = [0.8 * y0 + 0.4 * y1 - 0.2 * y2, 0.5 * y0 - 0.5 * y2];
    assert_vector(&mv.state, &want, 1e-14, "X°");
    let ls = least_squares(&running_t(), &running_y(), &r).unwrap();
    assert_matrix(&ls.covariance, &[11.0 / 9.0, 1.0, 1.0, 1.0], 1e-15, "Ŝ");
}

#[test]
fn mixed_observations_ex_6_16() {
    // Positions and velocities 1 s apart, X = (x, ẋ) at t_n, R = I in feet: (12/5, 9/5).
    let t = DMatrix::from_row_slice(4, 2, &[1.0, 0.0, 0.0, 1.0, 1.0, -1.0, 0.0, 1.0]);
    let y = DVector::from_vec(vec![2.0, 2.0, 1.0, 2.0]);
    let e = minimum_variance(&t, &y, &NoiseCovariance::Identity).unwrap();
    assert_vector(&e.state, &[2.4, 1.8], 1e-15, "X°");
    // The same in inches for the positions, R transformed with them (R_A = Q R Qᵀ): the
    // minimum-variance estimate does not depend on the units of the observations.
    let q = [12.0, 1.0, 12.0, 1.0];
    let tq = DMatrix::from_fn(4, 2, |i, j| q[i] * t[(i, j)]);
    let yq = DVector::from_fn(4, |i, _| q[i] * y[i]);
    let rq = NoiseCovariance::Variances(q.iter().map(|q| q * q).collect());
    let e = minimum_variance(&tq, &yq, &rq).unwrap();
    assert_vector(&e.state, &[2.4, 1.8], 1e-14, "X° with positions in inches");
}

/// `(Tᵀ R⁻¹ T)⁻¹ Tᵀ R⁻¹ Y` and `(Tᵀ R⁻¹ T)⁻¹` in exact rationals.
fn exact_minimum_variance(
    t: &DMatrix<f64>,
    y: &DVector<f64>,
    r: &DMatrix<f64>,
) -> (Vec<f64>, DMatrix<f64>) {
    let q = |m: &DMatrix<f64>| m.map(|v| rational_from_f64(v).unwrap());
    let (t, r) = (q(t), q(r));
    let y = DMatrix::from_fn(y.len(), 1, |i, _| rational_from_f64(y[i]).unwrap());
    let mul = seqsmooth::linalg::mul::<Rational>;
    let r_inv = inverse_exact(&r).unwrap();
    let tt = t.transpose();
    let gram = mul(&mul(&tt, &r_inv), &t);
    let s = inverse_exact(&gram).unwrap();
    let x = mul(&mul(&mul(&s, &tt), &r_inv), &y);
    (
        x.iter().map(Scalar::to_f64).collect(),
        s.map(|v| v.to_f64()),
    )
}

#[test]
fn minimum_variance_equals_exact_rationals() {
    // Dyadic entries, so the f64 inputs are exactly the rationals.
    let mut rng = rand::rngs::StdRng::seed_from_u64(8);
    let dyadic = |rng: &mut rand::rngs::StdRng| f64::from(rng.gen_range(-64..=64)) / 8.0;
    for case in 0..60 {
        let states = 1 + case % 5;
        let rows = states + rng.gen_range(0..6);
        let t = DMatrix::from_fn(rows, states, |_, _| dyadic(&mut rng));
        let y = DVector::from_fn(rows, |_, _| dyadic(&mut rng));
        // R = B Bᵀ + I (symmetric positive definite), or diagonal.
        let r = if case % 2 == 0 {
            let b = DMatrix::from_fn(rows, rows, |_, _| dyadic(&mut rng) / 4.0);
            &b * b.transpose() + DMatrix::identity(rows, rows)
        } else {
            DMatrix::from_diagonal(&DVector::from_fn(rows, |_, _| {
                f64::from(rng.gen_range(1..=16)) / 4.0
            }))
        };
        let noise = if case % 2 == 0 {
            NoiseCovariance::Full(r.clone())
        } else {
            NoiseCovariance::Variances(r.diagonal().iter().copied().collect())
        };
        let e = match minimum_variance(&t, &y, &noise) {
            Ok(e) => e,
            // A random T can be rank deficient; then so is the exact Gram matrix.
            Err(Error::Unobservable { .. }) => {
                let q = t.map(|v| rational_from_f64(v).unwrap());
                let gram = seqsmooth::linalg::mul(&q.transpose(), &q);
                assert!(
                    inverse_exact(&gram).is_none(),
                    "case {case}: T has full rank"
                );
                continue;
            }
            Err(other) => panic!("case {case}: {other}"),
        };
        let (x, s) = exact_minimum_variance(&t, &y, &r);
        let scale = e.condition_number.max(1.0);
        for (k, (g, w)) in e.state.iter().zip(&x).enumerate() {
            let tol = 1e-15 * scale * scale * w.abs().max(1.0);
            assert!((g - w).abs() <= tol, "case {case} X[{k}]: {g} against {w}");
        }
        let err = (&e.covariance - &s).amax() / s.amax();
        // Backward stable QR: error within a few ε κ² (κ below 100 here; measured ≤ 1.4e-14,
        // where the bound is 3.8e-12).
        assert!(err <= 1e-15 * scale * scale, "case {case}: S error {err:e}");
    }
}

#[test]
fn polynomial_model_equals_the_polynomial_fit_on_irregular_times() {
    // (8.3.6): row k of T is ((t_k − t_n)^j)_j for the state (x, ẋ, ẍ/2!, …) at t_n; R = I.
    let mut rng = rand::rngs::StdRng::seed_from_u64(11);
    for m in 0..=8 {
        let n = 2 * m + 5;
        let mut times = vec![0.0];
        for _ in 1..n {
            let last = *times.last().unwrap();
            times.push(last + rng.gen_range(0.2..1.8));
        }
        let values: Vec<f64> = times
            .iter()
            .map(|t: &f64| (0.7 * t).sin() * 10.0 + rng.gen_range(-0.5..0.5))
            .collect();
        let end = *times.last().unwrap();
        // Scaled to the span, so that T stays well conditioned at degree 8.
        let span = end - times[0];
        let t = DMatrix::from_fn(n, m + 1, |k, j| ((times[k] - end) / span).powi(j as i32));
        let y = DVector::from_vec(values.clone());
        let e = minimum_variance(&t, &y, &NoiseCovariance::Identity).unwrap();
        let fit = PolynomialFit::new(&times, &values, None, m).unwrap();
        let d = fit.derivatives_at(end);
        let mut factorial = 1.0;
        for (j, dj) in d.iter().enumerate() {
            if j > 0 {
                factorial *= j as f64;
            }
            let want = dj / factorial * span.powi(j as i32);
            let tol = 1e-10 * want.abs().max(d[0].abs());
            assert!(
                (e.state[j] - want).abs() <= tol,
                "degree {m}, component {j}: {} against {want}",
                e.state[j]
            );
        }
    }
}

#[test]
fn observability_morrison_8_9_examples() {
    // Example 1: A the 3×3 shift, M = (1, 0, 0): rows (1, −k, k²/2); rank 2 at L = 1, 3 at L ≥ 2.
    let ex1 = |l: usize| {
        DMatrix::from_fn(l + 1, 3, |k, j| {
            let k = k as f64;
            [1.0, -k, k * k / 2.0][j]
        })
    };
    let y = |rows: usize| DVector::from_element(rows, 1.0);
    match minimum_variance(&ex1(1), &y(2), &NoiseCovariance::Identity) {
        Err(Error::Unobservable {
            rank: 2, states: 3, ..
        }) => {}
        other => panic!("L = 1: {other:?}"),
    }
    for l in 2..10 {
        minimum_variance(&ex1(l), &y(l + 1), &NoiseCovariance::Identity).unwrap();
    }
    // Example 2: M = (0, 1, 0): rows (0, 1, −k), rank 2 for every L.
    for l in [2, 5, 50] {
        let t = DMatrix::from_fn(l + 1, 3, |k, j| [0.0, 1.0, -(k as f64)][j]);
        let e = minimum_variance(&t, &y(l + 1), &NoiseCovariance::Identity).unwrap_err();
        assert!(
            matches!(
                e,
                Error::Unobservable {
                    rank: 2,
                    states: 3,
                    ..
                }
            ),
            "L = {l}: {e:?}"
        );
        assert!(e.to_string().contains("only 2 of the 3"), "{e}");
    }
    // The polynomial model with fewer than m + 1 distinct times (a repeated time).
    let times = [0.0, 1.0, 1.0, 2.0];
    let t = DMatrix::from_fn(4, 4, |k, j| (times[k] - 2.0_f64).powi(j as i32));
    match minimum_variance(&t, &y(4), &NoiseCovariance::Identity) {
        Err(Error::Unobservable {
            rank: 3, states: 4, ..
        }) => {}
        other => panic!("repeated time: {other:?}"),
    }
}

#[test]
fn bad_input_is_refused_by_name() {
    let (t, y) = (running_t(), running_y());
    let refused = |t: &DMatrix<f64>, y: &DVector<f64>, r: &NoiseCovariance, part: &str| {
        for e in [
            minimum_variance(t, y, r).unwrap_err(),
            least_squares(t, y, r).unwrap_err(),
        ] {
            assert!(e.to_string().contains(part), "{e}");
        }
    };
    let id = NoiseCovariance::Identity;
    let mut bad_t = t.clone();
    bad_t[(2, 1)] = f64::NAN;
    refused(&bad_t, &y, &id, "entry [2, 1] = NaN");
    let mut bad_y = y.clone();
    bad_y[1] = f64::INFINITY;
    refused(&t, &bad_y, &id, "entry 1 = inf");
    refused(
        &t,
        &DVector::from_element(2, 1.0),
        &id,
        "one value per row of T (3)",
    );
    refused(
        &DMatrix::zeros(3, 0),
        &y,
        &id,
        "at least one row and one column",
    );
    let v = NoiseCovariance::Variances(vec![1.0, 0.0, 1.0]);
    refused(&t, &y, &v, "0 (observation 1)");
    refused(
        &t,
        &y,
        &NoiseCovariance::Variances(vec![1.0]),
        "one variance per row",
    );
    let not_pd = DMatrix::from_row_slice(3, 3, &[1.0, 2.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
    refused(&t, &y, &NoiseCovariance::Full(not_pd), "positive definite");
    let asym = DMatrix::from_row_slice(3, 3, &[2.0, 1.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 2.0]);
    refused(&t, &y, &NoiseCovariance::Full(asym), "must be symmetric");
    refused(
        &t,
        &y,
        &NoiseCovariance::Full(DMatrix::identity(2, 2)),
        "must be 3x3",
    );
}

/// T8-01, §8.8: Ex. 8.17's `det R'` (0.0740741, 0.0256312, 0.00312474 at α = 1, 0.1, 0.01;
/// 2/27 at α = 1), 1 for a diagonal `R` (Ex. 8.16), Ex. 8.18's indefinite matrix
/// (`det R' = −10000/(10000 · 39999)`), and refusals.
#[test]
fn correlation_determinant_ex_8_16_to_8_18() {
    use seqsmooth::estimate::batch::correlation_determinant;
    let a = |al: f64| {
        DMatrix::from_row_slice(
            3,
            3,
            &[
                5.0 + al,
                4.0 + al,
                3.0 + 2.0 * al,
                4.0 + al,
                5.0 + al,
                3.0 + 2.0 * al,
                3.0 + 2.0 * al,
                3.0 + 2.0 * al,
                2.0 + 4.0 * al,
            ],
        )
    };
    // The printed det R' and half a unit of its last printed digit.
    for (al, det, det_r, half_digit) in [
        (1.0, 16.0, 0.0740741, 5e-8),
        (0.1, 8.0 / 5.0, 0.0256312, 5e-8),
        (0.01, 4.0 / 25.0, 0.00312474, 5e-9),
    ] {
        let m = a(al);
        assert!(
            (m.determinant() - det).abs() < 1e-12 * det.max(1.0),
            "det A({al})"
        );
        let got = correlation_determinant(&m).unwrap();
        // det R' = det A / Π a_ii (the LU's rounding grows as R' nears singular: 3e-14
        // relative at α = 0.01), printed to 6 significant digits.
        let exact = det / m.diagonal().product();
        assert!(
            (got - exact).abs() < 1e-12 * exact,
            "{al}: {got} against {exact}"
        );
        assert!(
            (got - det_r).abs() <= half_digit,
            "{al}: {got} against {det_r}"
        );
    }
    assert!((correlation_determinant(&a(1.0)).unwrap() - 2.0 / 27.0).abs() < 1e-15);
    let diagonal = DMatrix::from_diagonal(&DVector::from_vec(vec![4.0, 1e-6, 3e8]));
    assert_eq!(correlation_determinant(&diagonal).unwrap(), 1.0);
    let ex_8_18 = DMatrix::from_row_slice(2, 2, &[10000.0, 20000.0, 20000.0, 39999.0]);
    let got = correlation_determinant(&ex_8_18).unwrap();
    let want = -10000.0 / (10000.0 * 39999.0);
    assert!((got - want).abs() < 1e-9 * want.abs(), "{got}");
    assert!((got + 2.5e-5).abs() < 1e-9);
    for bad in [
        DMatrix::from_row_slice(2, 2, &[1.0, 0.5, 0.4, 1.0]),
        DMatrix::from_row_slice(2, 2, &[0.0, 0.0, 0.0, 1.0]),
        DMatrix::from_row_slice(1, 2, &[1.0, 0.0]),
        DMatrix::from_row_slice(1, 1, &[f64::NAN]),
        DMatrix::zeros(0, 0),
    ] {
        assert!(correlation_determinant(&bad).is_err(), "{bad:?}");
    }
}

/// T8-01, Ex. 8.18: `10000x + 20000y = 30000`, `20000x + 39999y = 59999` gives `x = y = 1`;
/// changing 39999 to 39998 (one part in 4e4) gives `x = 2`, `y = 1/2`. The square system
/// through `least_squares` (QR), with the condition number it reports (σ_max/σ_min ≈ 1.25e5 and 2.5e5,
/// from nalgebra's SVD); errors within κ ε.
#[test]
fn ill_conditioned_system_ex_8_18() {
    for (c, want) in [(39999.0, [1.0, 1.0]), (39998.0, [2.0, 0.5])] {
        let t = DMatrix::from_row_slice(2, 2, &[10000.0, 20000.0, 20000.0, c]);
        let y = DVector::from_vec(vec![30000.0, 59999.0]);
        let e = least_squares(&t, &y, &NoiseCovariance::Identity).unwrap();
        let sv = t.clone().svd(false, false).singular_values;
        let kappa = sv.max() / sv.min();
        assert!(
            (e.condition_number / kappa - 1.0).abs() < 1e-6,
            "{}",
            e.condition_number
        );
        assert!(kappa > 1e5 && kappa < 3e5, "{kappa}");
        for (k, w) in want.iter().enumerate() {
            assert!(
                (e.state[k] - w).abs() < 4.0 * kappa * f64::EPSILON * w.abs(),
                "c {c} x{k}: {} against {w}",
                e.state[k]
            );
        }
        assert_eq!(e.degrees_of_freedom, 0);
    }
}

/// T8-01, the §8.8 inverse example ((8.8.2)-(8.8.6)): `A = [[s, 1], [1, 1]]`, `s = 1 + ε`,
/// `A⁻¹ = (1/ε)[[1, −1], [−1, s]]`. Six-digit arithmetic, which stores ε = 0.000015 as
/// 0.00001, makes a 5e-6 relative error in `s` a 50% error in `A⁻¹`; the covariance of
/// `minimum_variance` with `Tᵀ T = A` (`T` the Cholesky factor) holds it to within κ ε.
#[test]
fn inverse_example_8_8() {
    for eps in [0.000015_f64, 0.00001] {
        let s = 1.0 + eps;
        // T = Lᵀ with A = L Lᵀ.
        let (l11, l21) = (s.sqrt(), 1.0 / s.sqrt());
        let l22 = (1.0 - 1.0 / s).sqrt();
        let t = DMatrix::from_row_slice(2, 2, &[l11, l21, 0.0, l22]);
        let y = DVector::from_vec(vec![0.0, 0.0]);
        let e = minimum_variance(&t, &y, &NoiseCovariance::Identity).unwrap();
        // The exact inverse of the A that T represents in doubles.
        let a = t.transpose() * &t;
        let d = a[(0, 0)] * a[(1, 1)] - a[(0, 1)] * a[(1, 0)];
        let inverse = [a[(1, 1)] / d, -a[(0, 1)] / d, -a[(1, 0)] / d, a[(0, 0)] / d];
        let kappa = e.condition_number * e.condition_number;
        for (k, want) in inverse.iter().enumerate() {
            let got = e.covariance[(k / 2, k % 2)];
            assert!(
                (got - want).abs() <= 4.0 * kappa * f64::EPSILON * want.abs(),
                "eps {eps} [{k}]: {got} against {want}"
            );
        }
        // The book's figures: 66666.7 and 66667.7 at ε = 0.000015, 1e5 and 100001 at 0.00001.
        let book = [1.0 / eps, (1.0 + eps) / eps];
        assert!((e.covariance[(0, 0)] / book[0] - 1.0).abs() < 1e-9);
        assert!((e.covariance[(1, 1)] / book[1] - 1.0).abs() < 1e-9);
    }
}
