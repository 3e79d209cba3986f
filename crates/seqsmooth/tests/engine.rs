//! What every engine of the expanding- and fading-memory filters shares: the covariance it
//! reports is that of its own estimator (impulse responses; the closed-form VRFs of Morrison
//! (1969) (9.3.x), (13.6.x) on even samples), and bad input gives typed errors naming the value.

mod common;

use common::engine::*;
use common::*;
use nalgebra::DMatrix;
use seqsmooth::polynomial::expanding::vrf::expanding_vrf;
use seqsmooth::polynomial::fading::vrf::fading_vrf;
use seqsmooth::polynomial::fixed::{FixedEngine, FixedMemory};
use seqsmooth::polynomial::form::{unscale, EstimateForm};
use seqsmooth::polynomial::MAX_DEGREE;
use seqsmooth::{Engine, Error, ExpandingMemory, FadingMemory, PolynomialFilter};

/// Covariance of a linear estimator computed from its impulse responses: run the estimator on
/// unit impulses `y = e_k` and sum `σ² g_k g_kᵀ` (independent of any covariance formula).
fn impulse_covariance(
    make: &dyn Fn(Option<f64>) -> Filter,
    times: &[f64],
    at: f64,
    sigma: f64,
    p: usize,
) -> nalgebra::DMatrix<f64> {
    let mut c = nalgebra::DMatrix::zeros(p, p);
    for k in 0..times.len() {
        let mut f = make(None);
        for (i, &t) in times.iter().enumerate() {
            f.update(t, if i == k { 1.0 } else { 0.0 }).unwrap();
        }
        let g = nalgebra::DVector::from_vec(f.estimate_at(at).unwrap().derivatives);
        c += &g * g.transpose() * (sigma * sigma);
    }
    c
}

fn assert_matrix_close(
    a: &nalgebra::DMatrix<f64>,
    b: &nalgebra::DMatrix<f64>,
    tol: f64,
    what: &str,
) {
    for i in 0..a.nrows() {
        for j in 0..a.ncols() {
            let scale = (b[(i, i)] * b[(j, j)]).sqrt();
            assert!(
                (a[(i, j)] - b[(i, j)]).abs() <= tol * scale,
                "{what} ({i},{j}): {} vs {}",
                a[(i, j)],
                b[(i, j)]
            );
        }
    }
}

type Maker = Box<dyn Fn(Option<f64>) -> Filter>;

#[test]
fn every_engine_reports_the_covariance_of_its_own_estimator() {
    // Irregular (±50% jittered) times: the reported covariance equals σ² Σ_k g_k g_kᵀ from impulse responses,
    // for both engines and both memories, at the current time and one step ahead.
    // (Jittered rather than Poisson times: the gain engine is an approximation meant for
    // near-even sampling, and on Poisson arrivals at degree 4 it amplifies rounding enough to
    // blur a 1e-9 comparison; the exact engines are checked on Poisson times elsewhere.)
    let sigma = 0.7;
    let times = jittered_times(40, 0.2, 0.5, 5);
    for m in [0, 1, 2, 4] {
        let makers: Vec<(&str, Maker)> = vec![
            (
                "expanding exact",
                Box::new(move |s| test_filter(false, Engine::Exact, m, s)),
            ),
            (
                "expanding gain",
                Box::new(move |s| test_filter(false, Engine::Gain, m, s)),
            ),
            (
                "fading exact",
                Box::new(move |s| test_filter(true, Engine::Exact, m, s)),
            ),
            (
                "fading gain",
                Box::new(move |s| test_filter(true, Engine::Gain, m, s)),
            ),
        ];
        for (label, make) in &makers {
            let mut f = make(Some(sigma));
            for &t in &times {
                f.update(t, 0.0).unwrap();
            }
            for at in [times[times.len() - 1], times[times.len() - 1] + 0.2] {
                let reported = f.estimate_at(at).unwrap().covariance.unwrap();
                let want = impulse_covariance(make.as_ref(), &times, at, sigma, m + 1);
                assert_matrix_close(&reported, &want, 1e-9, &format!("{label} m={m}"));
            }
        }
    }
}

/// Feeds `f` a constant at `times` (even, step τ) and checks the covariance it reports for the
/// current estimate at the last sample and the 1-step prediction against `vrf(form)` (to 1e-9).
fn assert_reports_vrf(
    mut f: Box<dyn PolynomialFilter>,
    times: &[f64],
    tau: f64,
    vrf: impl Fn(EstimateForm) -> DMatrix<f64>,
    label: &str,
) {
    for &t in times {
        f.update(t, 1.0).unwrap();
    }
    let last = times[times.len() - 1];
    for (form, at) in [
        (EstimateForm::Current, last),
        (EstimateForm::Predictor, last + tau),
    ] {
        let got = f.estimate_at(at).unwrap().covariance.unwrap();
        assert_matrix_close(&got, &vrf(form), 1e-9, &format!("{label} {form:?}"));
    }
}

#[test]
fn covariance_on_even_samples_equals_the_closed_form_vrf() {
    // Morrison (9.7.1)-(9.7.4) expanding at n; (13.6.20) fading steady state; D(τ) S D(τ).
    let sigma = 2.0;
    let tau = 0.5;
    for m in 0..=4 {
        for engine in [Engine::Exact, Engine::Gain] {
            let f = ExpandingMemory::new(m, engine)
                .unwrap()
                .with_noise_sigma(sigma)
                .unwrap();
            assert_reports_vrf(
                Box::new(f),
                &even_times(30, 0.0, tau),
                tau,
                |form| unscale(&expanding_vrf::<f64>(m, 29, form).unwrap(), tau) * (sigma * sigma),
                &format!("expanding {engine:?} m={m}"),
            );
        }
        for engine in [Engine::Exact, Engine::Gain] {
            let f = FadingMemory::new(m, 0.9, tau, engine)
                .unwrap()
                .with_noise_sigma(sigma)
                .unwrap();
            assert_reports_vrf(
                Box::new(f),
                &even_times(900, 0.0, tau),
                tau,
                |form| unscale(&fading_vrf(m, 0.9, form).unwrap(), tau) * (sigma * sigma),
                &format!("fading {engine:?} m={m}"),
            );
        }
    }
}

#[test]
fn bad_input_gives_typed_errors_naming_the_value() {
    let mut f = ExpandingMemory::new(2, Engine::Exact).unwrap();
    assert!(matches!(
        f.update(f64::NAN, 1.0),
        Err(Error::NonFinite { what: "time", .. })
    ));
    assert!(matches!(
        f.update(0.0, f64::INFINITY),
        Err(Error::NonFinite { what: "value", .. })
    ));
    f.update(1.0, 1.0).unwrap();
    assert_eq!(
        f.update(1.0, 2.0),
        Err(Error::TimeNotIncreasing {
            time: 1.0,
            previous: 1.0
        })
    );
    assert_eq!(
        f.update(0.5, 2.0),
        Err(Error::TimeNotIncreasing {
            time: 0.5,
            previous: 1.0
        })
    );
    assert_eq!(f.samples(), 1, "rejected samples must not change the state");
    assert_eq!(
        ExpandingMemory::new(MAX_DEGREE + 1, Engine::Gain).unwrap_err(),
        Error::DegreeOutOfRange {
            degree: MAX_DEGREE + 1,
            max: MAX_DEGREE
        }
    );
    for theta in [0.0, 1.0, -0.5, 1.5, f64::NAN] {
        let e = FadingMemory::new(1, theta, 1.0, Engine::Exact).unwrap_err();
        assert!(matches!(e, Error::ThetaOutOfRange { .. }), "{e}");
        assert!(e.to_string().contains(&theta.to_string()));
    }
    for tau in [0.0, -1.0, f64::INFINITY] {
        assert!(matches!(
            FadingMemory::new(1, 0.9, tau, Engine::Gain),
            Err(Error::TauOutOfRange { .. })
        ));
    }
    assert!(ExpandingMemory::new(1, Engine::Gain)
        .unwrap()
        .with_noise_sigma(-1.0)
        .is_err());
    // σ whose square (the variance every covariance is scaled by) is not a normal double:
    // refused with the reason, by every filter; the range's ends are accepted.
    for sigma in [1e-300, 1e-160, 1e160, 1e300] {
        let e = FadingMemory::new(1, 0.9, 1.0, Engine::Exact)
            .unwrap()
            .with_noise_sigma(sigma)
            .unwrap_err();
        assert!(e.to_string().contains("rescale the values"), "{e}");
        assert!(FixedMemory::new(1, 5, FixedEngine::Sliding)
            .unwrap()
            .with_noise_sigma(sigma)
            .is_err());
    }
    let mut f = FadingMemory::new(1, 0.9, 1.0, Engine::Gain)
        .unwrap()
        .with_noise_sigma(1.5e-154)
        .unwrap();
    f.update_many(&[0.0, 1.0, 2.0], &[0.0, 1.0, 2.0]).unwrap();
    let cov = f.estimate().unwrap().covariance.unwrap();
    assert!(
        cov.iter().all(|v| v.is_finite()) && cov[(0, 0)] > 0.0,
        "{cov}"
    );
    assert!(FadingMemory::new(1, 0.9, 1.0, Engine::Gain)
        .unwrap()
        .with_noise_sigma(1.3e154)
        .is_ok());
    let msg = Error::TimeNotIncreasing {
        time: 3.0,
        previous: 4.0,
    }
    .to_string();
    assert!(msg.contains('3') && msg.contains('4'), "{msg}");
}
