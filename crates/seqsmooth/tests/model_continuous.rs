//! `model::continuous`: `Φ(ζ) = e^{Aζ}` and Van Loan's `Q(ζ) = ∫₀^ζ e^{As} Q_c e^{Aᵀs} ds`
//! against exact rational sums of their series (finite for the nilpotent polynomial models;
//! summed far past convergence for the Singer model), entry by entry within 1e-12 relative on
//! irregular steps from 1e-3 to 1e2; the polynomial model against Morrison (15.2.23)'s closed
//! form; symmetry and positive semi-definiteness; the refusals; and the model in a Kalman
//! filter.

use nalgebra::{DMatrix, DVector};
use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{Signed, ToPrimitive, Zero};
use seqsmooth::kalman::noise::{ProcessNoise, WhiteNoiseDerivative};
use seqsmooth::kalman::KalmanFilter;
use seqsmooth::model::continuous::ContinuousModel;
use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
use seqsmooth::model::observation::LinearObservation;
use seqsmooth::{Error, Param};

/// Irregular steps across 1e-3 … 1e2.
const STEPS: [f64; 7] = [1e-3, 0.0371, 0.25, 0.9, 7.3, 41.0, 100.0];

type Mat = Vec<Vec<BigRational>>;

fn exact(x: f64) -> BigRational {
    BigRational::from_float(x).expect("finite")
}

fn to_rational(m: &DMatrix<f64>) -> Mat {
    (0..m.nrows())
        .map(|i| (0..m.ncols()).map(|j| exact(m[(i, j)])).collect())
        .collect()
}

fn mul(a: &Mat, b: &Mat) -> Mat {
    let n = a.len();
    (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    (0..n)
                        .filter(|&k| !a[i][k].is_zero() && !b[k][j].is_zero())
                        .fold(BigRational::zero(), |s, k| s + &a[i][k] * &b[k][j])
                })
                .collect()
        })
        .collect()
}

fn transpose(a: &Mat) -> Mat {
    let n = a.len();
    (0..n)
        .map(|i| (0..n).map(|j| a[j][i].clone()).collect())
        .collect()
}

fn largest(a: &Mat) -> f64 {
    a.iter()
        .flatten()
        .map(|v| v.abs().to_f64().unwrap())
        .fold(0.0, f64::max)
}

/// `Σ_k ζ^k A^k/k!` and `Σ_k ζ^{k+1}/(k+1)! L^k(Q_c)`, `L(X) = AX + XAᵀ`, in exact rationals:
/// each series summed until its terms vanish (nilpotent `A`) or have stayed below 1e-40 of the
/// sum for 8 terms past their peak.
fn series(a: &DMatrix<f64>, qc: &DMatrix<f64>, zeta: f64) -> (Mat, Mat) {
    let (a, qc, z) = (to_rational(a), to_rational(qc), exact(zeta));
    let at = transpose(&a);
    let n = a.len();
    let sum = |first: Mat, next: &dyn Fn(&Mat, usize) -> Mat| {
        let mut total = first.clone();
        let (mut term, mut small) = (first, 0);
        for k in 1..5000 {
            term = next(&term, k);
            for (s, t) in total.iter_mut().flatten().zip(term.iter().flatten()) {
                *s += t;
            }
            let (t, s) = (largest(&term), largest(&total));
            if t == 0.0 {
                break;
            }
            small = if t < 1e-40 * s { small + 1 } else { 0 };
            if small == 8 {
                break;
            }
        }
        total
    };
    let identity: Mat = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| BigRational::from_integer(BigInt::from(i32::from(i == j))))
                .collect()
        })
        .collect();
    let phi = sum(identity, &|t, k| {
        let f = &z / BigRational::from_integer(BigInt::from(k));
        mul(t, &a)
            .into_iter()
            .map(|r| r.into_iter().map(|v| v * &f).collect())
            .collect()
    });
    let first: Mat = qc
        .iter()
        .map(|r| r.iter().map(|v| v * &z).collect())
        .collect();
    let q = sum(first, &|t, k| {
        let f = &z / BigRational::from_integer(BigInt::from(k as i64 + 1));
        let (l, r) = (mul(&a, t), mul(t, &at));
        l.into_iter()
            .zip(r)
            .map(|(l, r)| l.into_iter().zip(r).map(|(x, y)| (x + y) * &f).collect())
            .collect()
    });
    (phi, q)
}

/// Every entry of `got` within `tol` of `want`'s, relative (an exact zero must be zero).
fn assert_entries(got: &DMatrix<f64>, want: &Mat, tol: f64, what: &str) {
    for (i, row) in want.iter().enumerate() {
        for (j, w) in row.iter().enumerate() {
            let w = w.to_f64().unwrap();
            let g = got[(i, j)];
            assert!(
                (g - w).abs() <= tol * w.abs(),
                "{what} [{i}, {j}]: {g:e} against {w:e} (relative {:e})",
                ((g - w) / w).abs()
            );
        }
    }
}

/// The worst entry-by-entry relative difference of `got` from `want` (both zero counts 0).
fn worst(got: &DMatrix<f64>, want: &DMatrix<f64>) -> f64 {
    got.iter()
        .zip(want.iter())
        .map(|(g, w)| if g == w { 0.0 } else { ((g - w) / w).abs() })
        .fold(0.0, f64::max)
}

fn assert_symmetric_psd(q: &DMatrix<f64>, what: &str) {
    assert_eq!(q, &q.transpose(), "{what}: not symmetric");
    let least = q.clone().symmetric_eigenvalues().min();
    assert!(least >= -1e-13 * q.amax(), "{what}: eigenvalue {least:e}");
}

#[test]
fn nilpotent_models_equal_their_exact_finite_series() {
    let mut models = vec![
        (
            "ncv",
            ContinuousModel::nearly_constant_velocity(&[0.7, 3.0]).unwrap(),
        ),
        (
            "nca",
            ContinuousModel::nearly_constant_acceleration(&[2.5]).unwrap(),
        ),
    ];
    for m in 0..=8 {
        models.push((
            "polynomial",
            ContinuousModel::polynomial(m, &[0.3, 1.7]).unwrap(),
        ));
    }
    for (name, model) in &models {
        for zeta in STEPS {
            let (phi, q) = model.discretise(zeta).unwrap();
            let (want_phi, want_q) =
                series(model.dynamics().matrix(), model.spectral_density(), zeta);
            let what = format!("{name} n={} ζ={zeta}", phi.nrows());
            assert_entries(&phi, &want_phi, 1e-12, &format!("Φ {what}"));
            assert_entries(&q, &want_q, 1e-12, &format!("Q {what}"));
            assert_symmetric_psd(&q, &what);
        }
    }
}

#[test]
fn singer_equals_its_series_summed_exactly() {
    // (α, axes, σ_m²) and the steps with αζ ≤ 25 (e^{−αζ} far inside the double range).
    for (alpha, axes, variance) in [(0.25, 1, 2.0), (2.0, 2, 0.5), (0.015625, 1, 30.0)] {
        let model = ContinuousModel::singer(axes, alpha, variance).unwrap();
        for zeta in STEPS.into_iter().filter(|z| alpha * z <= 25.0) {
            let (phi, q) = model.discretise(zeta).unwrap();
            let (want_phi, want_q) =
                series(model.dynamics().matrix(), model.spectral_density(), zeta);
            let what = format!("Singer α={alpha} ζ={zeta}");
            assert_entries(&phi, &want_phi, 1e-12, &format!("Φ {what}"));
            assert_entries(&q, &want_q, 1e-12, &format!("Q {what}"));
            assert_symmetric_psd(&q, &what);
            // The acceleration's own variance in closed form, σ_m² (1 − e^{−2αζ}).
            let want = variance * -(-2.0 * alpha * zeta).exp_m1();
            let got = q[(2 * axes, 2 * axes)];
            assert!(
                (got - want).abs() <= 1e-13 * want,
                "{what}: {got} against {want}"
            );
        }
    }
}

#[test]
fn a_general_model_equals_its_series() {
    // A damped oscillator with a full Q_c: e^{Aζ} with entries of both signs (here the
    // accuracy is relative to the largest entry).
    let a = DMatrix::from_row_slice(3, 3, &[0.0, 1.0, 0.0, -2.0, -0.5, 0.25, 0.0, 0.0, -1.0]);
    let qc = DMatrix::from_row_slice(3, 3, &[1.0, 0.5, 0.0, 0.5, 2.0, 0.25, 0.0, 0.25, 1.0]);
    let model = ContinuousModel::new(a.clone(), qc.clone()).unwrap();
    for zeta in [1e-3, 0.0371, 0.9, 7.3] {
        let (phi, q) = model.discretise(zeta).unwrap();
        let (want_phi, want_q) = series(&a, &qc, zeta);
        for (got, want, what) in [(&phi, &want_phi, "Φ"), (&q, &want_q, "Q")] {
            let scale = largest(want);
            for (i, row) in want.iter().enumerate() {
                for (j, w) in row.iter().enumerate() {
                    let d = (got[(i, j)] - w.to_f64().unwrap()).abs();
                    assert!(
                        d <= 1e-12 * scale,
                        "{what} ζ={zeta} [{i}, {j}]: off by {d:e}"
                    );
                }
            }
        }
        assert_symmetric_psd(&q, "oscillator");
    }
}

#[test]
fn polynomial_model_equals_the_closed_form() {
    let mut worst_seen: f64 = 0.0;
    for m in 0..=8 {
        for axes in 1..=3 {
            let psd = [0.4, 2.0, 11.0];
            for &q in &psd {
                let model = ContinuousModel::polynomial(m, &vec![q; axes]).unwrap();
                let closed = WhiteNoiseDerivative::new(m, axes, q).unwrap();
                for zeta in STEPS {
                    let got = model.noise_covariance(zeta).unwrap();
                    let want = closed.covariance(0.0, zeta).unwrap();
                    let w = worst(&got, &want);
                    worst_seen = worst_seen.max(w);
                    assert!(w <= 1e-12, "degree {m}, {axes} axes, ζ={zeta}: {w:e}");
                }
            }
        }
    }
    eprintln!("worst relative difference from (15.2.23): {worst_seen:e}");
}

#[test]
fn per_axis_densities_stay_on_their_axes() {
    let model = ContinuousModel::nearly_constant_velocity(&[1.0, 0.0, 4.0]).unwrap();
    let q = model.noise_covariance(2.0).unwrap();
    for axis in 0..3 {
        let want = WhiteNoiseDerivative::new(1, 1, [1.0, 0.0, 4.0][axis])
            .unwrap()
            .covariance(0.0, 2.0)
            .unwrap();
        for (i, j) in [(0, 0), (0, 1), (1, 1)] {
            assert_eq!(q[(i * 3 + axis, j * 3 + axis)], want[(i, j)]);
        }
        for other in (0..3).filter(|&o| o != axis) {
            assert_eq!(q[(axis, 3 + other)], 0.0);
        }
    }
}

#[test]
fn refusals_are_typed() {
    let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 0.0]);
    let ok = DMatrix::from_row_slice(2, 2, &[0.0, 0.0, 0.0, 1.0]);
    let param = |e: Error| match e {
        Error::InvalidParameter { name, .. } => name,
        e => panic!("not a parameter error: {e:?}"),
    };
    let new = |a: DMatrix<f64>, q: DMatrix<f64>| param(ContinuousModel::new(a, q).unwrap_err());
    assert_eq!(
        new(DMatrix::zeros(2, 3), ok.clone()),
        Param::DynamicsMatrixA
    );
    assert_eq!(new(a.clone(), DMatrix::zeros(3, 3)), Param::SpectralDensity);
    assert_eq!(new(a.clone(), DMatrix::zeros(2, 3)), Param::SpectralDensity);
    let not_symmetric = DMatrix::from_row_slice(2, 2, &[1.0, 0.5, 0.0, 1.0]);
    assert_eq!(new(a.clone(), not_symmetric), Param::SpectralDensity);
    let not_psd = DMatrix::from_row_slice(2, 2, &[0.0, 0.0, 0.0, -1e-3]);
    assert_eq!(new(a.clone(), not_psd), Param::SpectralDensity);
    let mut nan = ok.clone();
    nan[(1, 1)] = f64::NAN;
    assert_eq!(new(a.clone(), nan), Param::SpectralDensity);
    let mut inf_a = a.clone();
    inf_a[(0, 0)] = f64::INFINITY;
    assert_eq!(new(inf_a, ok.clone()), Param::DynamicsMatrixA);
    // Finite entries whose column sum overflows: refused, where the scaling would halve every
    // step to zero and give Q = 0.
    let mut huge = DMatrix::zeros(3, 3);
    huge[(0, 2)] = 1e308;
    huge[(1, 2)] = 1e308;
    let qc3 = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![1.0, 0.0, 0.0]));
    assert_eq!(new(huge, qc3), Param::DynamicsMatrixA);
    let model = ContinuousModel::new(a, ok).unwrap();
    for zeta in [-1e-9, -1.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert_eq!(param(model.discretise(zeta).unwrap_err()), Param::Step);
        assert_eq!(
            param(model.noise_covariance(zeta).unwrap_err()),
            Param::Step
        );
        assert_eq!(param(model.transition(zeta).unwrap_err()), Param::Step);
    }
    // A growing mode beyond the double range is refused, not returned as infinity.
    let grows = ContinuousModel::new(DMatrix::identity(1, 1), DMatrix::identity(1, 1)).unwrap();
    assert_eq!(param(grows.discretise(400.0).unwrap_err()), Param::Step);
    assert!(grows.discretise(300.0).is_ok());
    let s = |alpha: f64, var: f64| param(ContinuousModel::singer(1, alpha, var).unwrap_err());
    for alpha in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert_eq!(s(alpha, 1.0), Param::ManoeuvreAlpha);
    }
    for var in [-1.0, f64::NAN, f64::INFINITY] {
        assert_eq!(s(1.0, var), Param::ManoeuvreVariance);
    }
    assert_eq!(
        param(ContinuousModel::singer(0, 1.0, 1.0).unwrap_err()),
        Param::Axes
    );
    assert_eq!(
        param(ContinuousModel::polynomial(1, &[]).unwrap_err()),
        Param::Axes
    );
    for q in [-1.0, f64::NAN] {
        assert_eq!(
            param(ContinuousModel::nearly_constant_acceleration(&[1.0, q]).unwrap_err()),
            Param::DrivingNoiseQ
        );
    }
    let noise = ContinuousModel::nearly_constant_velocity(&[1.0]).unwrap();
    assert!(matches!(
        noise.covariance(f64::NAN, 1.0),
        Err(Error::NonFinite { .. })
    ));
}

/// The two positions of a two-axis constant-velocity state `(x0, x1, v0, v1)`.
fn positions() -> LinearObservation {
    LinearObservation::new(DMatrix::from_row_slice(
        2,
        4,
        &[1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0],
    ))
    .unwrap()
}

#[test]
fn in_a_kalman_filter_it_is_the_polynomial_filter_with_its_closed_form() {
    // Nearly constant velocity on two axes, irregular steps, a component missing at times:
    // the continuous model as dynamics and noise against PolynomialDynamics with
    // WhiteNoiseDerivative.
    let model = ContinuousModel::nearly_constant_velocity(&[0.8, 0.8]).unwrap();
    let prior = (DVector::zeros(4), DMatrix::identity(4, 4) * 100.0);
    let mut a = KalmanFilter::new(
        model.clone(),
        positions(),
        prior.0.clone(),
        prior.1.clone(),
        0.0,
    )
    .unwrap()
    .with_process_noise(model.clone())
    .unwrap();
    let mut b = KalmanFilter::new(
        PolynomialDynamics::new(1, 2),
        positions(),
        prior.0,
        prior.1,
        0.0,
    )
    .unwrap()
    .with_process_noise(WhiteNoiseDerivative::new(1, 2, 0.8).unwrap())
    .unwrap();
    let mut t = 0.0;
    for k in 0..200 {
        t += 0.05 + ((k * 37) % 11) as f64 * 0.3;
        let values = vec![
            Some((0.1 * t).sin() * 50.0),
            (k % 7 != 3).then_some(0.5 * t),
        ];
        let m = Measurement {
            time: t,
            values,
            noise: NoiseCovariance::Variances(vec![4.0, 9.0]),
        };
        a.update(&m).unwrap();
        b.update(&m).unwrap();
        let ds = (a.state() - b.state()).amax() / b.state().amax();
        let dp = (a.covariance() - b.covariance()).amax() / b.covariance().amax();
        assert!(ds < 1e-12 && dp < 1e-12, "sample {k}: {ds:e} {dp:e}");
    }
    assert_eq!(Dynamics::dimension(&model), 4);
}
