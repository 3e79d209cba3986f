//! `kalman::bayes`: Morrison's ch. 10 test vectors (the notes' T10-1, T10-2, T10-4, T10-5,
//! exact or to the printed digits), the Bayes filter against the Kalman filter on random
//! problems (the inversion lemma, (10.5.4)), starting from no information against the batch
//! minimum-variance estimate (sequential equals batch, (10.2.48)), and refusals.

use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use seqsmooth::estimate::gauss_newton::{Epoch, GaussNewton, Measurement};
use seqsmooth::kalman::{BayesFilter, KalmanFilter};
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::measurement::NoiseCovariance;
use seqsmooth::model::observation::{LinearObservation, NonlinearObservation};

fn m(rows: usize, cols: usize, v: &[f64]) -> DMatrix<f64> {
    DMatrix::from_row_slice(rows, cols, v)
}

fn meas(t: f64, values: &[f64], noise: NoiseCovariance) -> Measurement {
    Measurement {
        time: t,
        values: values.iter().map(|&v| Some(v)).collect(),
        noise,
    }
}

fn bayes(
    obs: DMatrix<f64>,
    prior: DMatrix<f64>,
) -> BayesFilter<PolynomialDynamics, LinearObservation> {
    let n = prior.nrows();
    BayesFilter::new(
        PolynomialDynamics::new(n - 1, 1),
        LinearObservation::new(obs).unwrap(),
        0.0,
    )
    .unwrap()
    .with_prior(&DVector::zeros(n), &prior)
    .unwrap()
}

/// T10-1 (10.5.22): `S_{1,0} = I`, `M = (0, 1)`, `R = 1`: `S_{1,1} = [[1, 0], [0, 1/2]]`.
/// T10-4 (Ex. 10.25a/b): `M = (1, 0)`: `[[1/2, 0], [0, 1]]`, and from `[[1, .99], [.99, 1]]`:
/// `[[1/2, 99/200], [99/200, 10199/20000]]`.
#[test]
fn t10_1_and_t10_4() {
    let one = NoiseCovariance::Variances(vec![1.0]);
    let mut f = bayes(m(1, 2, &[0.0, 1.0]), DMatrix::identity(2, 2));
    f.update(&meas(0.0, &[0.0], one.clone())).unwrap();
    assert!((f.covariance().unwrap() - m(2, 2, &[1.0, 0.0, 0.0, 0.5])).amax() < 1e-15);
    let mut f = bayes(m(1, 2, &[1.0, 0.0]), DMatrix::identity(2, 2));
    f.update(&meas(0.0, &[0.0], one.clone())).unwrap();
    assert!((f.covariance().unwrap() - m(2, 2, &[0.5, 0.0, 0.0, 1.0])).amax() < 1e-15);
    let mut f = bayes(m(1, 2, &[1.0, 0.0]), m(2, 2, &[1.0, 0.99, 0.99, 1.0]));
    f.update(&meas(0.0, &[0.0], one)).unwrap();
    let want = m(2, 2, &[0.5, 0.495, 0.495, 10199.0 / 20000.0]);
    assert!((f.covariance().unwrap() - want).amax() < 1e-12);
}

/// One figure's observation row, its first five `(S00, S11)` and those at n = 199.
type Figure<'a> = (&'a [f64], [(f64, f64); 5], (f64, f64));

/// T10-2 (Figs. 10.1/10.2; τ = 1, R = 1): `Φ = [[1, 1], [0, 1]]`, `S_{1,0} = I`, one update
/// per unit step. `M = (0, 1)`: `(S00, S11)` for n = 1..5 = (1, 1/2), (4/3, 1/3), (2, 1/4),
/// (14/5, 1/5), (11/3, 1/6), and at n = 199 (197.020, 0.005); `M = (1, 0)`: (1/2, 1), (3/5,
/// 3/5), (2/3, 4/15), (8/13, 5/39), (47/86, 3/43), and (0.0198536, 1.50048e-6).
#[test]
fn t10_2_figures_10_1_and_10_2() {
    let cases: [Figure; 2] = [
        (
            &[0.0, 1.0],
            [
                (1.0, 0.5),
                (4.0 / 3.0, 1.0 / 3.0),
                (2.0, 0.25),
                (2.8, 0.2),
                (11.0 / 3.0, 1.0 / 6.0),
            ],
            (197.020, 0.005),
        ),
        (
            &[1.0, 0.0],
            [
                (0.5, 1.0),
                (0.6, 0.6),
                (2.0 / 3.0, 4.0 / 15.0),
                (8.0 / 13.0, 5.0 / 39.0),
                (47.0 / 86.0, 3.0 / 43.0),
            ],
            (0.0198536, 1.50048e-6),
        ),
    ];
    for (obs, first, at_199) in cases {
        let mut f = bayes(m(1, 2, obs), DMatrix::identity(2, 2));
        for n in 1..=199 {
            f.update(&meas(
                (n - 1) as f64,
                &[0.0],
                NoiseCovariance::Variances(vec![1.0]),
            ))
            .unwrap();
            let s = f.covariance().unwrap();
            if n <= 5 {
                let (s00, s11) = first[n - 1];
                assert!(
                    (s[(0, 0)] - s00).abs() < 1e-13 && (s[(1, 1)] - s11).abs() < 1e-13,
                    "{obs:?} n {n}: {s}"
                );
            }
            if n == 199 {
                let (s00, s11) = at_199;
                assert!(
                    (s[(0, 0)] / s00 - 1.0).abs() < 5e-6,
                    "{obs:?} S00 {}",
                    s[(0, 0)]
                );
                assert!(
                    (s[(1, 1)] / s11 - 1.0).abs() < 5e-6,
                    "{obs:?} S11 {}",
                    s[(1, 1)]
                );
            }
        }
    }
}

/// T10-5 (Ex. 10.27): `S_{1,0} = [[1, −0.5], [−0.5, 0.75]]`, `R = 0.01 I₄`, `T = ones(4, 2)`:
/// `S_{1,1} = [[0.667774, −0.666113], [−0.666113, 0.666944]]` (the notes' tolerance 2e-5 for
/// the book's printing; here against the exact inverse); with `T = [[1,1],[1,1],[1,1],[1,2]]`:
/// `[[0.0227538, −0.0162388], [−0.0162388, 0.0130137]]`.
#[test]
fn t10_5_very_precise_data() {
    let prior = m(2, 2, &[1.0, -0.5, -0.5, 0.75]);
    for (t, want) in [
        (
            [1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0],
            [0.667774, -0.666113, 0.666944],
        ),
        (
            [1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 2.0],
            [0.0227538, -0.0162388, 0.0130137],
        ),
    ] {
        let tm = m(4, 2, &t);
        // A static state observed through four rows at one time.
        let mut f = BayesFilter::new(
            PolynomialDynamics::new(0, 2),
            LinearObservation::new(tm.clone()).unwrap(),
            0.0,
        )
        .unwrap()
        .with_prior(&DVector::zeros(2), &prior)
        .unwrap();
        f.update(&meas(
            0.0,
            &[0.0; 4],
            NoiseCovariance::Variances(vec![0.01; 4]),
        ))
        .unwrap();
        let exact = (prior.clone().try_inverse().unwrap() + tm.transpose() * &tm * 100.0)
            .try_inverse()
            .unwrap();
        let s = f.covariance().unwrap();
        assert!(
            (&s - &exact).amax() < 1e-12 * exact.amax(),
            "{s} against {exact}"
        );
        for (got, w) in [s[(0, 0)], s[(0, 1)], s[(1, 1)]].iter().zip(want) {
            assert!((got - w).abs() < 5e-7, "{got} against {w}");
        }
    }
}

/// The Bayes filter equals the Kalman filter from the same prior on random problems (polynomial
/// degrees 0-3, irregular times, two-component observations with full R and missing
/// components): states and covariances within 1e-9 of max(|x|, σ) and σ_k σ_j.
#[test]
fn bayes_equals_kalman() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(41);
    let mut worst: f64 = 0.0;
    for degree in 0..=3 {
        let n = degree + 1;
        let dynamics = PolynomialDynamics::new(degree, 1);
        let mut obs = DMatrix::zeros(2, n);
        obs[(0, 0)] = 1.0;
        obs[(1, n - 1)] = 1.5;
        let observation = LinearObservation::new(obs).unwrap();
        let x0 = DVector::from_fn(n, |_, _| rng.gen_range(-1.0..1.0));
        let s0 = DMatrix::from_diagonal(&DVector::from_fn(n, |_, _| rng.gen_range(0.5..3.0)));
        let mut b = BayesFilter::new(dynamics, observation.clone(), 1.0)
            .unwrap()
            .with_prior(&x0, &s0)
            .unwrap();
        let mut k = KalmanFilter::new(dynamics, observation, x0, s0, 1.0).unwrap();
        let mut t = 1.0;
        for i in 0..25 {
            t += rng.gen_range(0.2..1.4);
            let second = (i % 4 != 0).then(|| rng.gen_range(-4.0..4.0));
            let z = Measurement {
                time: t,
                values: vec![Some(rng.gen_range(-4.0..4.0)), second],
                noise: NoiseCovariance::Full(m(2, 2, &[1.2, 0.4, 0.4, 0.9])),
            };
            b.update(&z).unwrap();
            k.update(&z).unwrap();
            let (bx, bs) = (b.estimate().unwrap(), b.covariance().unwrap());
            for a in 0..n {
                let e = (bx[a] - k.state()[a]).abs() / bx[a].abs().max(bs[(a, a)].sqrt());
                worst = worst.max(e);
                assert!(e < 1e-9, "degree {degree} step {i} x{a}");
                for c in 0..n {
                    let e = (bs[(a, c)] - k.covariance()[(a, c)]).abs()
                        / (bs[(a, a)] * bs[(c, c)]).sqrt();
                    worst = worst.max(e);
                    assert!(e < 1e-9, "degree {degree} step {i} S[{a},{c}]");
                }
            }
        }
    }
    println!("worst: {worst:e}");
}

/// From no information the Bayes filter's estimate, once determined, is the batch
/// minimum-variance estimate of all the measurements so far (`GaussNewton`, no prior), degrees
/// 0-4, irregular times from a Unix-epoch-sized origin: within 1e-9 of max(|x|, σ).
#[test]
fn from_no_information_equals_batch() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(43);
    for degree in 0..=4 {
        let n = degree + 1;
        let dynamics = PolynomialDynamics::new(degree, 1);
        let observation = LinearObservation::value_of(n);
        let mut f = BayesFilter::new(dynamics, observation.clone(), 0.0).unwrap();
        let mut rows = Vec::new();
        let mut t = 0.0;
        for i in 0..(2 * n + 5) {
            t += rng.gen_range(0.3..1.2);
            let z = meas(
                t,
                &[rng.gen_range(-2.0..2.0)],
                NoiseCovariance::Variances(vec![rng.gen_range(0.5..2.0)]),
            );
            f.update(&z).unwrap();
            rows.push(z);
            assert_eq!(
                f.estimate().is_some(),
                i >= degree,
                "degree {degree} row {i}"
            );
            if let Some(x) = f.estimate() {
                let s = f.covariance().unwrap();
                let batch = GaussNewton::default()
                    .fit(
                        &dynamics,
                        &observation,
                        &rows,
                        Epoch::At(t),
                        &DVector::zeros(n),
                        None,
                    )
                    .unwrap();
                for a in 0..n {
                    let scale = batch.state[a].abs().max(batch.covariance[(a, a)].sqrt());
                    assert!(
                        (x[a] - batch.state[a]).abs() < 1e-9 * scale,
                        "degree {degree} row {i} x{a}"
                    );
                    assert!((s[(a, a)] / batch.covariance[(a, a)] - 1.0).abs() < 1e-9);
                }
            }
        }
    }
}

/// Refusals: nonlinear dynamics are not offered here; a perfect observation; a nonlinear
/// observation with nothing to linearise about; a NaN; the filter unchanged after each.
#[test]
fn refusals() {
    use seqsmooth::model::nonlinear::NonlinearDynamics;
    assert!(BayesFilter::new(
        NonlinearDynamics::new(1, |_t, x: &DVector<f64>| x.map(|v| v * v)),
        LinearObservation::value_of(1),
        0.0
    )
    .is_err());
    let mut f = BayesFilter::new(
        PolynomialDynamics::new(1, 1),
        LinearObservation::value_of(2),
        0.0,
    )
    .unwrap();
    assert!(f
        .update(&meas(1.0, &[1.0], NoiseCovariance::Variances(vec![0.0])))
        .is_err());
    assert!(f
        .update(&meas(1.0, &[f64::NAN], NoiseCovariance::Identity))
        .is_err());
    assert_eq!(f.time(), 0.0);
    let range = NonlinearObservation::new(1, 2, |_t, x: &DVector<f64>| {
        DVector::from_vec(vec![(9.0 + x[0] * x[0]).sqrt()])
    });
    let mut g = BayesFilter::new(PolynomialDynamics::new(1, 1), range, 0.0).unwrap();
    assert!(g
        .update(&meas(1.0, &[5.0], NoiseCovariance::Identity))
        .is_err());
    assert_eq!(g.time(), 0.0);
}

/// An update after which the estimate leaves the double range (a slope of −2e308 per unit
/// time) is refused with the value, and the filter is as before it.
#[test]
fn an_estimate_beyond_the_double_range_is_refused() {
    use seqsmooth::kalman::BayesFilter;
    use seqsmooth::model::dynamics::PolynomialDynamics;
    use seqsmooth::model::measurement::Measurement;
    use seqsmooth::model::measurement::NoiseCovariance;
    use seqsmooth::model::observation::LinearObservation;
    use seqsmooth::Error;
    let row = |time: f64, y: f64| Measurement {
        time,
        values: vec![Some(y)],
        noise: NoiseCovariance::Variances(vec![1.0]),
    };
    let mut f = BayesFilter::new(
        PolynomialDynamics::new(1, 1),
        LinearObservation::value_of(2),
        0.0,
    )
    .unwrap();
    f.update(&row(0.0, 1e308)).unwrap();
    let before = (f.time(), f.estimate());
    let e = f.update(&row(1.0, -1e308)).unwrap_err();
    assert!(
        matches!(e, Error::NonFinite { value, .. } if value.is_infinite()),
        "{e}"
    );
    assert_eq!((f.time(), f.estimate()), before);
    f.update(&row(1.0, 1.5e308)).unwrap();
    assert!((f.estimate().unwrap()[1] - 0.5e308).abs() <= 1e294);
}
