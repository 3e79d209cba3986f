//! `kalman::filter` with fading memory (Morrison ch. 14, (14.4.34)-(14.4.40)): against the
//! batch solution of the discounted criterion with its true covariance `W R Wᵀ` ((14.3.8),
//! (14.3.19), written out here with nalgebra) on irregular times; the count-based filter with the
//! polynomial model against the fading-memory polynomial gains and VRF of the core (Table 13.1,
//! (13.6.x)) and against the notes' numeric cross-check (θ = 0.9, m = 2, 500 cycles); `β = 1`
//! against the plain filter; time-based against count-based on even steps.

use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use seqsmooth::kalman::{Discount, KalmanFilter};
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::measurement::Measurement;
use seqsmooth::model::measurement::NoiseCovariance;
use seqsmooth::model::observation::LinearObservation;
use seqsmooth::polynomial::fading::gains::fading_gains;
use seqsmooth::polynomial::fading::vrf::fading_vrf;
use seqsmooth::polynomial::form::{EstimateForm, GainForm};

fn scalar(t: f64, y: f64, variance: f64) -> Measurement {
    Measurement {
        time: t,
        values: vec![Some(y)],
        noise: NoiseCovariance::Variances(vec![variance]),
    }
}

fn factorial(k: usize) -> f64 {
    (1..=k).map(|i| i as f64).product()
}

/// The count-based fading Kalman filter on unit steps with a polynomial model of degree m ≤ 4
/// settles to the fading-memory polynomial filter's gains and current-estimate VRF (σ = 1):
/// in derivatives, `K_k = h_k k!` and `S_X = D S_Z D`, `D = diag(k!)` (τ = 1); within 1e-10.
#[test]
fn count_based_fading_is_the_fading_memory_polynomial_filter() {
    let mut worst: f64 = 0.0;
    for m in 0..=4 {
        for theta in [0.5, 0.8, 0.9] {
            let n = m + 1;
            let mut f = KalmanFilter::new(
                PolynomialDynamics::new(m, 1),
                LinearObservation::value_of(n),
                DVector::zeros(n),
                DMatrix::identity(n, n) * 1e6,
                0.0,
            )
            .unwrap()
            .with_fading(Discount::PerUpdate(theta))
            .unwrap();
            let mut gain = DMatrix::zeros(n, 1);
            for k in 1..=2000 {
                let y = (k as f64 * 0.37).sin();
                gain = f.update(&scalar(k as f64, y, 1.0)).unwrap().unwrap().gain;
            }
            let h = fading_gains(m, theta, GainForm::Current);
            let s_z = fading_vrf(m, theta, EstimateForm::Current).unwrap();
            for k in 0..n {
                let want = h[k] * factorial(k);
                let e = (gain[(k, 0)] - want).abs() / want.abs().max(1e-300);
                worst = worst.max(e);
                assert!(
                    e <= 1e-10,
                    "m {m} θ {theta} K{k}: {} against {want}",
                    gain[(k, 0)]
                );
                for j in 0..n {
                    let want = s_z[(k, j)] * factorial(k) * factorial(j);
                    let got = f.covariance()[(k, j)];
                    let e = (got - want).abs() / want.abs().max(1e-300);
                    worst = worst.max(e);
                    assert!(
                        e <= 1e-10,
                        "m {m} θ {theta} S[{k},{j}]: {got} against {want}"
                    );
                }
            }
        }
    }
    println!("worst relative difference: {worst:e}");
}

/// The notes' cross-check between chs. 13 and 14 (ch10-15 §5.6): θ = 0.9, m = 2, P = S =
/// 1e6 I, 500 cycles: H = (0.271, 0.0285, 0.0005) and the scaled S* = [[0.19919195,
/// 0.017420144, 0.00027462553], [., 0.0019726594, 3.3924330e-5], [., ., 6.0579161e-7]] to the
/// printed digits.
#[test]
fn notes_cross_check_theta_0_9() {
    let mut f = KalmanFilter::new(
        PolynomialDynamics::new(2, 1),
        LinearObservation::value_of(3),
        DVector::zeros(3),
        DMatrix::identity(3, 3) * 1e6,
        0.0,
    )
    .unwrap()
    .with_fading(Discount::PerUpdate(0.9))
    .unwrap();
    let mut gain = DMatrix::zeros(3, 1);
    for k in 1..=500 {
        gain = f.update(&scalar(k as f64, 0.0, 1.0)).unwrap().unwrap().gain;
    }
    let d = [1.0, 1.0, 0.5]; // z_k = x^(k)/k! at τ = 1
    for (k, want) in [0.271, 0.0285, 0.0005].iter().enumerate() {
        assert!((gain[(k, 0)] * d[k] - want).abs() < 1e-10 * want, "H{k}");
    }
    let printed = [
        [0.19919195, 0.017420144, 0.00027462553],
        [0.017420144, 0.0019726594, 3.3924330e-5],
        [0.00027462553, 3.3924330e-5, 6.0579161e-7],
    ];
    for k in 0..3 {
        for j in 0..3 {
            let got = f.covariance()[(k, j)] * d[k] * d[j];
            let want = printed[k][j];
            assert!(
                (got - want).abs() <= 5e-8 * want,
                "S[{k},{j}]: {got} against {want}"
            );
        }
    }
}

/// The batch solution of the time-discounted criterion (14.2.10) on irregular times, with the
/// prior as a pseudo-observation of the state at `t₀` (covariance `P₀`, discounted like the
/// rest): `X = (Tᵀ Q⁻¹ T)⁻¹ Tᵀ Q⁻¹ Y`, `Q = blockdiag(R_k β^−(t_n − t_k))` (14.3.4), and the true
/// covariance `W R Wᵀ` (14.3.19); the filter's state and covariance after every update within
/// 1e-9 of max(|x|, σ) and of σ_k σ_j, degrees 0-3, β = 0.8 and 0.95 per unit time.
#[test]
fn time_based_fading_equals_the_discounted_batch_estimate() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(31);
    let mut worst: f64 = 0.0;
    for m in 0..=3 {
        for beta in [0.8, 0.95] {
            let n = m + 1;
            let dynamics = PolynomialDynamics::new(m, 1);
            let x0 = DVector::from_fn(n, |_, _| rng.gen_range(-1.0..1.0));
            let p0 = DMatrix::from_diagonal(&DVector::from_fn(n, |_, _| rng.gen_range(1.0..3.0)));
            let mut f = KalmanFilter::new(
                dynamics,
                LinearObservation::value_of(n),
                x0.clone(),
                p0.clone(),
                0.0,
            )
            .unwrap()
            .with_fading(Discount::PerTime(beta))
            .unwrap();
            let (mut times, mut ys, mut rs) = (vec![], vec![], vec![]);
            let mut t = 0.0;
            for _ in 0..(3 * n + 8) {
                t += rng.gen_range(0.2..1.6);
                let (y, r) = (rng.gen_range(-3.0..3.0), rng.gen_range(0.5..2.0));
                f.update(&scalar(t, y, r)).unwrap();
                times.push(t);
                ys.push(y);
                rs.push(r);
                // The batch at t.
                let rows = n + times.len();
                let mut tm = DMatrix::zeros(rows, n);
                let mut yv = DVector::zeros(rows);
                let mut qinv = DMatrix::zeros(rows, rows);
                let mut rtrue = DMatrix::zeros(rows, rows);
                let back = dynamics.transition(0.0 - t); // Φ(t0, t)
                tm.view_mut((0, 0), (n, n)).copy_from(&back);
                yv.rows_mut(0, n).copy_from(&x0);
                let p0inv = p0.clone().try_inverse().unwrap();
                qinv.view_mut((0, 0), (n, n))
                    .copy_from(&(p0inv * beta.powf(t)));
                rtrue.view_mut((0, 0), (n, n)).copy_from(&p0);
                for (k, ((&tk, &yk), &rk)) in times.iter().zip(&ys).zip(&rs).enumerate() {
                    let row = dynamics.transition(tk - t).row(0).into_owned();
                    tm.row_mut(n + k).copy_from(&row);
                    yv[n + k] = yk;
                    qinv[(n + k, n + k)] = beta.powf(t - tk) / rk;
                    rtrue[(n + k, n + k)] = rk;
                }
                let gram = tm.transpose() * &qinv * &tm;
                let w = gram.try_inverse().unwrap() * tm.transpose() * &qinv;
                let x = &w * &yv;
                let s = &w * &rtrue * w.transpose();
                for k in 0..n {
                    let sk = s[(k, k)].sqrt();
                    let e = (f.state()[k] - x[k]).abs() / x[k].abs().max(sk);
                    worst = worst.max(e);
                    assert!(
                        e <= 1e-9,
                        "m {m} β {beta} t {t} x{k}: {} against {}",
                        f.state()[k],
                        x[k]
                    );
                    for j in 0..n {
                        let e = (f.covariance()[(k, j)] - s[(k, j)]).abs()
                            / (s[(k, k)] * s[(j, j)]).sqrt();
                        worst = worst.max(e);
                        assert!(e <= 1e-9, "m {m} β {beta} t {t} S[{k},{j}]");
                    }
                }
            }
        }
    }
    println!("worst: {worst:e}");
}

/// `β = 1` is the plain filter, to the last bit; on even steps of τ the time-based discount
/// `β` is the count-based `θ = β^τ` (within rounding of the power).
#[test]
fn no_discount_and_even_steps() {
    let new = || {
        KalmanFilter::new(
            PolynomialDynamics::new(2, 1),
            LinearObservation::value_of(3),
            DVector::zeros(3),
            DMatrix::identity(3, 3) * 100.0,
            0.0,
        )
        .unwrap()
    };
    let (mut plain, mut unit) = (new(), new().with_fading(Discount::PerTime(1.0)).unwrap());
    let tau = 0.25;
    let (mut by_time, mut by_count) = (
        new().with_fading(Discount::PerTime(0.7)).unwrap(),
        new()
            .with_fading(Discount::PerUpdate(0.7_f64.powf(tau)))
            .unwrap(),
    );
    for k in 1..200 {
        let z = scalar(k as f64 * tau, (k as f64 * 0.1).cos(), 0.3);
        let (a, b) = (
            plain.update(&z).unwrap().unwrap(),
            unit.update(&z).unwrap().unwrap(),
        );
        assert_eq!(plain.state(), unit.state());
        assert_eq!(plain.covariance(), unit.covariance());
        assert_eq!(a.nis, b.nis);
        by_time.update(&z).unwrap();
        by_count.update(&z).unwrap();
    }
    assert!((by_time.state() - by_count.state()).amax() < 1e-12);
    assert!((by_time.covariance() - by_count.covariance()).amax() < 1e-12);
    assert!(new().with_fading(Discount::PerTime(0.0)).is_err());
    assert!(new().with_fading(Discount::PerUpdate(1.5)).is_err());
    assert!(new().with_fading(Discount::PerUpdate(f64::NAN)).is_err());
}
