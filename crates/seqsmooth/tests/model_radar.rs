//! `model::radar` (Morrison §8.5, (8.5.3)-(8.5.7)): the predicted range, azimuth and elevation
//! against the spherical coordinates a position was built from (random geometries in all four
//! azimuth quadrants, negative elevations, sites away from the origin), with a tolerance from
//! the rounding of that position; the Jacobian against fourth-order central differences (1e-7
//! relative per row); the range rate against the differenced range along the motion; `wrap` at
//! and around ±π and its multiples; the residual wrapped for azimuth only; refusal at, above and
//! below the site. `to_cartesian`: the position through the round trip with `predict`, the
//! covariance against `J R Jᵀ` with `J` the inverse of `predict`'s Jacobian, and Monte Carlo
//! (10⁵ draws, σ_ρ 10 m, σ 1 mrad at 10 km): the sample covariance within 5 of its standard
//! errors `sqrt((C_ii C_jj + C_ij²)/N)`, and the mean offset along the line of sight equal to
//! `−bias` within 5 standard errors of the mean plus the bias formula's own `O(σ⁴)` error.

use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use seqsmooth::error::Param;
use seqsmooth::model::observation::Observation;
use seqsmooth::model::radar::{wrap, Radar};
use seqsmooth::Error;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// `site + ρ (cos θ cos ψ, cos θ sin ψ, sin θ)`.
fn spherical(site: [f64; 3], rho: f64, psi: f64, theta: f64) -> [f64; 3] {
    [
        site[0] + rho * theta.cos() * psi.cos(),
        site[1] + rho * theta.cos() * psi.sin(),
        site[2] + rho * theta.sin(),
    ]
}

fn state(p: [f64; 3], vel: [f64; 3]) -> DVector<f64> {
    DVector::from_vec(vec![p[0], p[1], p[2], vel[0], vel[1], vel[2]])
}

/// A random geometry: azimuth in quadrant `q` (0: (−π, −π/2], …, 3: (π/2, π]), elevation in
/// (−1.5, 1.5), range 1 m to 10⁶ m log-uniform, the site within 10⁴ m of the origin.
fn geometry(rng: &mut impl Rng, q: usize) -> ([f64; 3], f64, f64, f64) {
    let site = [
        rng.gen_range(-1e4..1e4),
        rng.gen_range(-1e4..1e4),
        rng.gen_range(-1e3..1e3),
    ];
    let psi = -PI + FRAC_PI_2 * (q as f64 + rng.gen_range(0.0..1.0));
    let theta = rng.gen_range(-1.5..1.5);
    let rho = 10f64.powf(rng.gen_range(0.0..6.0));
    (site, rho, psi, theta)
}

#[test]
fn predictions_invert_the_spherical_coordinates() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(21);
    let mut worst = [0.0f64; 3];
    for q in 0..4 {
        for k in 0..2000 {
            let (site, rho, psi, theta) = geometry(&mut rng, q);
            let site = if k % 10 == 0 { [0.0; 3] } else { site };
            let p = spherical(site, rho, psi, theta);
            let radar = Radar::new(site, 6).unwrap();
            let pred = radar.predict(&state(p, [1.0, 2.0, 3.0]), 5.0).unwrap();
            // The position carries rounding of at most δ = ε (|site| + ρ) per coordinate.
            let scale = site.iter().fold(rho, |a, s| a.max(s.abs()));
            let delta = f64::EPSILON * (scale + rho);
            let errs = [
                (pred.value[0] - rho).abs() / (delta * 2.0 + 4.0 * f64::EPSILON * rho),
                wrap(pred.value[1] - psi).abs()
                    / (2.0 * delta / (rho * theta.cos()) + 8.0 * f64::EPSILON),
                (pred.value[2] - theta).abs() / (2.0 * delta / rho + 8.0 * f64::EPSILON),
            ];
            for (w, e) in worst.iter_mut().zip(errs) {
                *w = w.max(e);
            }
            assert!(
                errs.iter().all(|&e| e <= 1.0),
                "site {site:?}, ρ {rho}, ψ {psi}, θ {theta}: {:?} (in units of the bound {errs:?})",
                pred.value
            );
            assert!(pred.value[1] > -PI && pred.value[1] <= PI);
        }
    }
    // On the axes, exactly.
    let radar = Radar::new([1.0, -2.0, 3.0], 3).unwrap();
    let at = |p: [f64; 3]| {
        radar
            .predict(&DVector::from_vec(p.to_vec()), 0.0)
            .unwrap()
            .value
    };
    assert_eq!(at([6.0, -2.0, 3.0]).as_slice(), &[5.0, 0.0, 0.0]);
    assert_eq!(at([1.0, 5.0, 3.0]).as_slice(), &[7.0, FRAC_PI_2, 0.0]);
    assert_eq!(at([1.0, -9.0, 3.0]).as_slice(), &[7.0, -FRAC_PI_2, 0.0]);
    assert_eq!(at([-3.0, -2.0, 3.0]).as_slice(), &[4.0, PI, 0.0]);
    assert_eq!(
        at([4.0, 2.0, -9.0]).as_slice(),
        &[13.0, (4.0f64).atan2(3.0), -(12.0f64).atan2(5.0)]
    );
    // Behind the site with a negative zero across: still π, not −π (the range is (−π, π]).
    let origin = Radar::new([0.0; 3], 3).unwrap();
    let v = origin
        .predict(&DVector::from_vec(vec![-5.0, -0.0, 1.0]), 0.0)
        .unwrap()
        .value;
    assert_eq!(v[1], PI);
    eprintln!("predictions: worst error in units of the rounding bound {worst:?}");
}

/// `∂G/∂X` by fourth-order central differences, `h = 10⁻⁴ ρ` on position, `10⁻⁴ max(|v|, 1)`
/// on velocity.
fn differenced(radar: &Radar, x: &DVector<f64>, rho: f64) -> DMatrix<f64> {
    let rows = radar.components();
    let mut out = DMatrix::zeros(rows, x.len());
    let speed = x.rows(3, 3).norm().max(1.0);
    for c in 0..x.len() {
        let h0 = 1e-4 * if c < 3 { rho } else { speed };
        let h = (x[c] + h0) - x[c];
        let g = |m: f64| {
            let mut p = x.clone();
            p[c] += m * h;
            let mut v = radar.predict(&p, 0.0).unwrap().value;
            // Keep the azimuth continuous across ±π.
            v[1] = wrap(v[1] - radar.predict(x, 0.0).unwrap().value[1]);
            v
        };
        out.set_column(
            c,
            &((g(-2.0) - g(-1.0) * 8.0 + g(1.0) * 8.0 - g(2.0)) / (12.0 * h)),
        );
    }
    out
}

#[test]
fn jacobian_matches_central_differences() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(22);
    let mut worst: f64 = 0.0;
    for q in 0..4 {
        for _ in 0..250 {
            let (site, rho, psi, theta) = geometry(&mut rng, q);
            let vel = [
                rng.gen_range(-300.0..300.0),
                rng.gen_range(-300.0..300.0),
                rng.gen_range(-300.0..300.0),
            ];
            let x = state(spherical(site, rho, psi, theta), vel);
            let radar = Radar::new(site, 6).unwrap().with_range_rate().unwrap();
            let got = radar.predict(&x, 0.0).unwrap().jacobian;
            let want = differenced(&radar, &x, rho);
            for r in 0..4 {
                let e = (got.row(r) - want.row(r)).amax() / want.row(r).amax();
                worst = worst.max(e);
                assert!(e <= 1e-7, "row {r}, ρ {rho}, ψ {psi}, θ {theta}: {e:e}");
            }
            // Range, azimuth and elevation do not depend on the velocity.
            assert_eq!(got.view((0, 3), (3, 3)), Matrix3::zeros());
        }
    }
    // A state longer than position and velocity: zero columns beyond.
    let radar = Radar::new([0.0; 3], 9).unwrap().with_range_rate().unwrap();
    let x = DVector::from_fn(9, |i, _| 1.0 + i as f64);
    let j = radar.predict(&x, 0.0).unwrap().jacobian;
    assert_eq!(j.shape(), (4, 9));
    assert!(j.columns(6, 3).iter().all(|&v| v == 0.0));
    eprintln!("Jacobian against central differences: worst relative error {worst:e}");
}

#[test]
fn range_rate_is_the_derivative_of_range() {
    // ρ̇ against [ρ(t − 2h) − 8ρ(t − h) + 8ρ(t + h) − ρ(t + 2h)]/(12h) along p + v t.
    let mut rng = rand::rngs::StdRng::seed_from_u64(23);
    let mut worst: f64 = 0.0;
    for q in 0..4 {
        for _ in 0..500 {
            let (site, rho, psi, theta) = geometry(&mut rng, q);
            let vel = [
                rng.gen_range(-300.0..300.0),
                rng.gen_range(-300.0..300.0),
                rng.gen_range(-300.0..300.0),
            ];
            let p = spherical(site, rho, psi, theta);
            let radar = Radar::new(site, 6).unwrap().with_range_rate().unwrap();
            let rate = radar.predict(&state(p, vel), 0.0).unwrap().value[3];
            let h = 1e-4 * rho / 300.0;
            let range = |t: f64| {
                let q = [p[0] + vel[0] * t, p[1] + vel[1] * t, p[2] + vel[2] * t];
                radar.predict(&state(q, vel), 0.0).unwrap().value[0]
            };
            let want =
                (range(-2.0 * h) - 8.0 * range(-h) + 8.0 * range(h) - range(2.0 * h)) / (12.0 * h);
            let speed = Vector3::from(vel).norm();
            let e = (rate - want).abs() / speed;
            worst = worst.max(e);
            assert!(e <= 1e-7, "ρ {rho}: ρ̇ {rate}, differenced {want}: {e:e}");
        }
    }
    // Radial motion: ±|v|; tangential motion: 0.
    let radar = Radar::new([10.0, 20.0, 30.0], 6)
        .unwrap()
        .with_range_rate()
        .unwrap();
    let rate = |p: [f64; 3], v: [f64; 3]| radar.predict(&state(p, v), 0.0).unwrap().value[3];
    assert_eq!(rate([13.0, 24.0, 30.0], [6.0, 8.0, 0.0]), 10.0);
    assert_eq!(rate([13.0, 24.0, 30.0], [-3.0, -4.0, 0.0]), -5.0);
    assert_eq!(rate([13.0, 24.0, 30.0], [-4.0, 3.0, 7.0]), 0.0);
    eprintln!("range rate against the differenced range: worst error / |v| {worst:e}");
}

#[test]
fn wrap_at_and_around_pi() {
    // Exactly: (−π, π] is left alone, −π goes to π.
    for a in [
        0.0,
        1e-300,
        -1e-300,
        1.0,
        -1.0,
        3.0,
        -3.0,
        PI,
        -PI + 4e-16,
        FRAC_PI_2,
    ] {
        assert_eq!(wrap(a), a, "{a}");
    }
    assert_eq!(wrap(-PI), PI);
    // Just past ±π, to the other side.
    assert!((wrap(PI + 1e-9) - (-PI + 1e-9)).abs() <= 1e-15);
    assert!((wrap(-PI - 1e-9) - (PI - 1e-9)).abs() <= 1e-15);
    assert!((wrap(1.5 * PI) + FRAC_PI_2).abs() <= 1e-15);
    // Multiples of π and of 2π and random angles up to 10⁶: the result lies in (−π, π] and
    // differs from the argument by a multiple of 2π, to the argument's rounding.
    let mut rng = rand::rngs::StdRng::seed_from_u64(24);
    let mut angles: Vec<f64> = (-200..=200).map(|k| f64::from(k) * PI).collect();
    angles.extend((-200..=200).map(|k| f64::from(k) * TAU));
    angles.extend((-200..=200).map(|k| f64::from(k) * TAU + 0.5));
    angles.extend((0..10_000).map(|_| rng.gen_range(-1e6..1e6)));
    for &a in &angles {
        let w = wrap(a);
        assert!(w > -PI && w <= PI, "wrap({a}) = {w}");
        let k = ((a - w) / TAU).round();
        let off = (a - w - k * TAU).abs();
        assert!(
            off <= 4.0 * f64::EPSILON * a.abs().max(1.0),
            "wrap({a}) = {w}: {off:e}"
        );
    }
    // The odd multiples of π land on ±π to their rounding, the even ones on 0.
    for k in -50..=50 {
        let a = f64::from(k) * PI;
        let w = wrap(a);
        let want = if k % 2 == 0 { 0.0 } else { PI };
        assert!(
            (w.abs() - want).abs() <= 4.0 * f64::EPSILON * a.abs(),
            "{k}π: {w}"
        );
    }
    assert!(wrap(f64::NAN).is_nan());
}

#[test]
fn residuals_wrap_the_azimuth_only() {
    let radar = Radar::new([0.0; 3], 6).unwrap().with_range_rate().unwrap();
    // Across ±π the azimuth residual is the short way round.
    let r = radar.residual(1, PI - 0.01, -PI + 0.01);
    assert!((r + 0.02).abs() <= 1e-15, "{r}");
    let r = radar.residual(1, -PI + 0.01, PI - 0.01);
    assert!((r - 0.02).abs() <= 1e-15, "{r}");
    assert!((radar.residual(1, -3.0, 3.0) - (TAU - 6.0)).abs() <= 1e-15);
    assert_eq!(radar.residual(1, 0.5, 0.25), 0.25);
    // Range, elevation and range rate: plain differences, however large.
    assert_eq!(radar.residual(0, 10.0, 3.0), 7.0);
    assert_eq!(radar.residual(2, 3.0, -3.0), 6.0);
    assert_eq!(radar.residual(3, -400.0, 400.0), -800.0);
}

#[test]
fn refusals_are_typed() {
    let geometry_error = |e: &Error| {
        matches!(
            e,
            Error::InvalidParameter {
                name: Param::RadarGeometry,
                ..
            }
        )
    };
    let site = [100.0, -50.0, 7.0];
    let radar = Radar::new(site, 6).unwrap();
    // At the site, directly above and below it (and far above).
    for p in [
        [100.0, -50.0, 7.0],
        [100.0, -50.0, 1e4],
        [100.0, -50.0, -3.0],
        [100.0, -50.0, 1e300],
    ] {
        let e = radar.predict(&state(p, [0.0; 3]), 2.0).unwrap_err();
        assert!(geometry_error(&e), "{p:?}: {e}");
    }
    // A position so far that its distance overflows.
    let e = radar
        .predict(&state([1e200, 1e200, 0.0], [0.0; 3]), 0.0)
        .unwrap_err();
    assert!(
        matches!(e, Error::InvalidParameter { .. } | Error::NonFinite { .. }),
        "{e}"
    );
    // Just off the vertical is fine.
    assert!(radar
        .predict(&state([100.0 + 1e-6, -50.0, 1e4], [0.0; 3]), 0.0)
        .is_ok());
    let e = radar.predict(&DVector::zeros(3), 0.0).unwrap_err();
    assert!(
        matches!(
            e,
            Error::InvalidParameter {
                name: Param::State,
                ..
            }
        ),
        "{e}"
    );
    let e = radar
        .predict(&state([1.0, f64::NAN, 0.0], [0.0; 3]), 0.0)
        .unwrap_err();
    assert!(
        matches!(
            e,
            Error::NonFinite {
                what: "state entry",
                ..
            }
        ),
        "{e}"
    );
    let e = Radar::new([0.0, f64::INFINITY, 0.0], 6).unwrap_err();
    assert!(
        matches!(
            e,
            Error::InvalidParameter {
                name: Param::Site,
                ..
            }
        ),
        "{e}"
    );
    let e = Radar::new([0.0; 3], 2).unwrap_err();
    assert!(
        matches!(
            e,
            Error::InvalidParameter {
                name: Param::StateDimension,
                ..
            }
        ),
        "{e}"
    );
    let e = Radar::new([0.0; 3], 5)
        .unwrap()
        .with_range_rate()
        .unwrap_err();
    assert!(
        matches!(
            e,
            Error::InvalidParameter {
                name: Param::StateDimension,
                ..
            }
        ),
        "{e}"
    );
    assert_eq!(radar.site(), site);
    assert_eq!((radar.components(), radar.state_dimension()), (3, 6));
    // to_cartesian: a non-positive range, a non-finite entry, a covariance that is not
    // symmetric positive definite.
    let r = Matrix3::from_diagonal(&Vector3::new(100.0, 1e-6, 1e-6));
    for rho in [0.0, -5.0] {
        let e = radar.to_cartesian([rho, 0.1, 0.1], &r).unwrap_err();
        assert!(
            matches!(
                e,
                Error::InvalidParameter {
                    name: Param::Range,
                    ..
                }
            ),
            "{e}"
        );
    }
    let e = radar.to_cartesian([1e3, f64::NAN, 0.1], &r).unwrap_err();
    assert!(matches!(e, Error::NonFinite { .. }), "{e}");
    let mut nan = r;
    nan[(0, 2)] = f64::NAN;
    assert!(matches!(
        radar.to_cartesian([1e3, 0.1, 0.1], &nan),
        Err(Error::NonFinite { .. })
    ));
    let mut asym = r;
    asym[(0, 1)] = 1e-3;
    let indefinite = Matrix3::from_diagonal(&Vector3::new(100.0, -1e-6, 1e-6));
    for bad in [asym, indefinite, Matrix3::zeros()] {
        let e = radar.to_cartesian([1e3, 0.1, 0.1], &bad).unwrap_err();
        assert!(
            matches!(
                e,
                Error::InvalidParameter {
                    name: Param::MeasurementCovariance,
                    ..
                }
            ),
            "{bad}: {e}"
        );
    }
}

/// A random symmetric positive definite measurement covariance: σ_ρ up to 30 m, angles up to
/// 5 mrad, correlations up to ±0.6.
fn random_r(rng: &mut impl Rng) -> Matrix3<f64> {
    let s = Vector3::new(
        rng.gen_range(1.0..30.0),
        rng.gen_range(1e-4..5e-3),
        rng.gen_range(1e-4..5e-3),
    );
    let mut c = Matrix3::identity();
    for (i, j) in [(0, 1), (0, 2), (1, 2)] {
        let v = rng.gen_range(-0.6..0.6) / 1.5;
        c[(i, j)] = v;
        c[(j, i)] = v;
    }
    Matrix3::from_diagonal(&s) * c * Matrix3::from_diagonal(&s)
}

#[test]
fn conversion_position_and_first_order_covariance() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(25);
    let mut worst: (f64, f64) = (0.0, 0.0);
    for q in 0..4 {
        for _ in 0..500 {
            let (site, rho, psi, theta) = geometry(&mut rng, q);
            let radar = Radar::new(site, 3).unwrap();
            let r = random_r(&mut rng);
            let c = radar.to_cartesian([rho, psi, theta], &r).unwrap();
            // The round trip: predict of the converted position gives the measurement back.
            let back = radar
                .predict(&DVector::from_column_slice(c.position.as_slice()), 0.0)
                .unwrap();
            let scale = site.iter().fold(rho, |a, s| a.max(s.abs()));
            let delta = f64::EPSILON * (scale + rho);
            let e_pos = ((back.value[0] - rho).abs() / (2.0 * delta + 4.0 * f64::EPSILON * rho))
                .max(
                    wrap(back.value[1] - psi).abs()
                        / (2.0 * delta / (rho * theta.cos()) + 8.0 * f64::EPSILON),
                )
                .max((back.value[2] - theta).abs() / (2.0 * delta / rho + 8.0 * f64::EPSILON));
            worst.0 = worst.0.max(e_pos);
            assert!(
                e_pos <= 1.0,
                "round trip ρ {rho}, ψ {psi}, θ {theta}: {e_pos}"
            );
            // J = ∂(x, y, z)/∂(ρ, ψ, θ) is the inverse of predict's ∂(ρ, ψ, θ)/∂(x, y, z).
            let m = back.jacobian.fixed_view::<3, 3>(0, 0).into_owned();
            let j = m.try_inverse().unwrap();
            let want = j * r * j.transpose();
            for a in 0..3 {
                for b in 0..3 {
                    let norm = (want[(a, a)] * want[(b, b)]).sqrt();
                    let e = (c.covariance[(a, b)] - want[(a, b)]).abs() / norm;
                    worst.1 = worst.1.max(e);
                    assert!(e <= 1e-9, "({a}, {b}), ρ {rho}, ψ {psi}, θ {theta}: {e:e}");
                }
            }
            assert_eq!(c.covariance, c.covariance.transpose());
            // bias = ρ (σ_ψ² cos²θ + σ_θ²)/2.
            let bias = rho * (r[(1, 1)] * theta.cos().powi(2) + r[(2, 2)]) / 2.0;
            assert!((c.bias - bias).abs() <= 1e-14 * bias);
        }
    }
    // Along +x from the site: exactly the site plus the range.
    let radar = Radar::new([1.0, 2.0, 3.0], 6).unwrap();
    let r = Matrix3::from_diagonal(&Vector3::new(100.0, 1e-6, 4e-6));
    let c = radar.to_cartesian([1e4, 0.0, 0.0], &r).unwrap();
    assert_eq!(c.position, Vector3::new(10_001.0, 2.0, 3.0));
    assert_eq!(
        c.covariance,
        Matrix3::from_diagonal(&Vector3::new(100.0, 100.0, 400.0))
    );
    assert!((c.bias - 0.025).abs() <= 1e-17, "{}", c.bias);
    eprintln!(
        "conversion: round trip {:.3} of the rounding bound; covariance worst {:e}",
        worst.0, worst.1
    );
}

/// Draws `n` measurements of `(ρ, ψ, θ)` with independent Gaussian errors of standard
/// deviations `sigma`, converts each exactly, and returns the converted result of the true
/// measurement, the sample mean and covariance, and the mean and standard error of the offset
/// along the line of sight (raw, and with the range error's own sample mean removed).
struct Sampled {
    mean: Vector3<f64>,
    covariance: Matrix3<f64>,
    los_mean: f64,
    los_se: f64,
    los_cv_mean: f64,
    los_cv_se: f64,
}

fn sample(radar: &Radar, truth: [f64; 3], sigma: [f64; 3], n: usize, seed: u64) -> Sampled {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let [rho, psi, theta] = truth;
    let u = Vector3::new(
        theta.cos() * psi.cos(),
        theta.cos() * psi.sin(),
        theta.sin(),
    );
    let x0 = Vector3::from(spherical(radar.site(), rho, psi, theta));
    let mut sum = Vector3::zeros();
    let mut outer = Matrix3::zeros();
    let (mut s1, mut s2, mut c1, mut c2) = (0.0, 0.0, 0.0, 0.0);
    for _ in 0..n {
        let e: [f64; 3] = std::array::from_fn(|k| sigma[k] * rng.sample::<f64, _>(StandardNormal));
        let x = Vector3::from(spherical(
            radar.site(),
            rho + e[0],
            psi + e[1],
            theta + e[2],
        ));
        let d = x - x0;
        sum += d;
        outer += d * d.transpose();
        let los = d.dot(&u);
        s1 += los;
        s2 += los * los;
        c1 += los - e[0];
        c2 += (los - e[0]).powi(2);
    }
    let nf = n as f64;
    let mean = sum / nf;
    let covariance = (outer - mean * mean.transpose() * nf) / (nf - 1.0);
    let se = |s1: f64, s2: f64| ((s2 / nf - (s1 / nf).powi(2)) / nf).sqrt();
    Sampled {
        mean: mean + x0,
        covariance,
        los_mean: s1 / nf,
        los_se: se(s1, s2),
        los_cv_mean: c1 / nf,
        los_cv_se: se(c1, c2),
    }
}

#[test]
fn conversion_monte_carlo() {
    const N: usize = 100_000;
    let radar = Radar::new([300.0, -120.0, 15.0], 6).unwrap();
    // The brief's case at negative elevation in the third quadrant, and large angle errors
    // where the bias is resolved without help.
    for (truth, sigma, seed) in [
        ([1e4, -2.3, -0.4], [10.0, 1e-3, 1e-3], 31),
        ([1e4, 0.7, 0.5], [1.0, 0.02, 0.02], 32),
    ] {
        let r = Matrix3::from_diagonal(&Vector3::from(sigma.map(|s| s * s)));
        let c = radar.to_cartesian(truth, &r).unwrap();
        let s = sample(&radar, truth, sigma, N, seed);
        // Covariance: each entry within 5 standard errors of the sample covariance.
        for a in 0..3 {
            for b in 0..3 {
                let want = c.covariance[(a, b)];
                let se =
                    ((c.covariance[(a, a)] * c.covariance[(b, b)] + want * want) / N as f64).sqrt();
                let z = (s.covariance[(a, b)] - want) / se;
                eprintln!(
                    "σ {sigma:?} covariance ({a}, {b}): {:.2} standard errors",
                    z
                );
                // First order only: asserted where the angle errors are small.
                if sigma[1] < 0.01 {
                    assert!(
                        z.abs() <= 5.0,
                        "({a}, {b}): sample {} vs {want}: {z:.2} se",
                        s.covariance[(a, b)]
                    );
                }
            }
        }
        // The mean offset along the line of sight is −bias. Its exact expectation is
        // −ρ (1 − e^{−σ_θ²/2} (cos²θ e^{−σ_ψ²/2} + sin²θ)); the bias formula is its second-order
        // part, off by O(ρσ⁴), which joins the tolerance.
        let [rho, _, theta] = truth;
        let (cs, sn) = (theta.cos().powi(2), theta.sin().powi(2));
        let exact = rho
            * (1.0
                - (-sigma[2] * sigma[2] / 2.0).exp()
                    * (cs * (-sigma[1] * sigma[1] / 2.0).exp() + sn));
        let model_error = (exact - c.bias).abs();
        let raw = (s.los_mean + c.bias).abs();
        let cv = (s.los_cv_mean + c.bias).abs();
        eprintln!(
            "σ {sigma:?}: bias {:.6}, exact {exact:.6}; offset {:.6} ± {:.6}, without the range error {:.6} ± {:.2e}",
            c.bias, s.los_mean, s.los_se, s.los_cv_mean, s.los_cv_se
        );
        assert!(raw <= 5.0 * s.los_se + model_error, "raw: {raw:e}");
        assert!(
            cv <= 5.0 * s.los_cv_se + model_error,
            "control variate: {cv:e}"
        );
        // And the bias is resolved: zero is excluded.
        assert!(c.bias > 20.0 * s.los_cv_se + model_error);
        // The sample mean sits at the converted position pulled back by the bias along the
        // line of sight, within 5 standard errors per axis.
        let u = (c.position - Vector3::from(radar.site())).normalize();
        let predicted_mean = c.position - u * c.bias;
        for a in 0..3 {
            let se = (s.covariance[(a, a)] / N as f64).sqrt();
            let dev = (s.mean[a] - predicted_mean[a]).abs();
            assert!(
                dev <= 5.0 * se + model_error,
                "mean axis {a}: {dev:e} vs se {se:e}"
            );
        }
    }
}
