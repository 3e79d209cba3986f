//! Both engines of the expanding- and fading-memory filters against independent oracles:
//! batch least squares by Householder QR in a Legendre basis (`estimate::PolynomialFit`, a
//! different algorithm from the recursive engines) and, for small cases, exact rational least
//! squares. Issue #2 "must show" 2 and 3: ≤ 1e-9 relative, degrees 0-8.

mod common;

use common::*;
use seqsmooth::polynomial::vrf::{expanding_vrf, fading_vrf, unscale, EstimateForm};
use seqsmooth::polynomial::MAX_DEGREE;
use seqsmooth::{DiscountMode, Engine, Error, ExpandingMemory, FadingMemory, PolynomialFilter};

/// Relative tolerance required by the issue.
const TOL: f64 = 1e-9;

/// Per-derivative floors for the relative error: 1e-3 of the largest magnitude the oracle
/// reaches over the run (a derivative that crosses zero is judged against its own scale).
fn floors(oracle: &[Vec<f64>]) -> Vec<f64> {
    let p = oracle[0].len();
    (0..p)
        .map(|k| 1e-3 * oracle.iter().map(|v| v[k].abs()).fold(1e-300, f64::max))
        .collect()
}

type Filter = Box<dyn PolynomialFilter>;

/// Derivatives of the estimate valid at `t`.
fn at(f: &Filter, t: f64) -> Option<Vec<f64>> {
    f.estimate_at(t).map(|s| s.derivatives)
}

/// Runs the filter and, for every sample index in `check`, compares the current estimate and
/// the estimate at the next sample's time (the 1-step prediction) with the oracle fit.
/// Returns the largest relative error.
fn compare(
    mut filter: Filter,
    times: &[f64],
    ys: &[f64],
    m: usize,
    check: impl Fn(usize) -> bool,
    weights: impl Fn(usize) -> Option<Vec<f64>>,
) -> f64 {
    let mut got = Vec::new();
    let mut want = Vec::new();
    for n in 0..times.len() - 1 {
        filter.update(times[n], ys[n]).unwrap();
        if n < m {
            assert!(
                at(&filter, times[n]).is_none(),
                "estimate before m+1 samples"
            );
            continue;
        }
        if !check(n) {
            continue;
        }
        let w = weights(n);
        let fit = batch_fit(&times[..=n], &ys[..=n], w.as_deref(), m);
        for at in [times[n], times[n + 1]] {
            got.push(filter.estimate_at(at).expect("determined").derivatives);
            want.push(fit.derivatives_at(at));
        }
    }
    let fl = floors(&want);
    got.iter()
        .zip(&want)
        .map(|(a, b)| rel_err(a, b, &fl))
        .fold(0.0, f64::max)
}

#[test]
fn expanding_even_both_engines_equal_batch_qr_degrees_0_to_8() {
    // Morrison §9.6: the gain recursion is exact least squares from n = m whatever its initial
    // state; the exact engine is least squares by construction.
    for m in 0..=8 {
        let times = even_times(200, 5.0, 0.25);
        let ys = noisy_polynomial(&times, m, 50.0, 0.3, 100 + m as u64);
        let exact = compare(
            Box::new(ExpandingMemory::new(m, Engine::Exact).unwrap()),
            &times,
            &ys,
            m,
            |_| true,
            |_| None,
        );
        let gain = compare(
            Box::new(ExpandingMemory::new(m, Engine::Gain).unwrap()),
            &times,
            &ys,
            m,
            |_| true,
            |_| None,
        );
        eprintln!("expanding even m={m}: exact {exact:.2e}, gain {gain:.2e}");
        assert!(exact < TOL, "m={m} exact {exact:e}");
        assert!(gain < TOL, "m={m} gain {gain:e}");
    }
}

#[test]
fn gain_recursion_is_self_starting_from_any_initial_state_in_exact_arithmetic() {
    // Morrison §9.6 (T9-10): with the Table 9.1 gains (here: the library's exact rational
    // gains) the recursion Z ← Φ(1)Z, ε = y - z0, Z ← Z + H ε reaches the least-squares fit at
    // n = m from ANY initial state Z*_{0,-1}; in exact arithmetic the equality is exact. The f64
    // gain engine starts from exactly that state (computed directly: see its docs) and the
    // tests above check it against batch QR.
    use rand::Rng;
    use seqsmooth::polynomial::gains::{expanding_gains, GainForm};
    use seqsmooth::scalar::{rational_from_f64, Rational};
    let mut r = rng(2024);
    for m in 0..=5 {
        let ys: Vec<f64> = (0..m + 8)
            .map(|_| (r.gen::<f64>() * 64.0).round() / 8.0)
            .collect();
        let times: Vec<f64> = (0..ys.len()).map(|k| k as f64).collect();
        for trial in 0..3 {
            let mut z: Vec<Rational> = (0..=m)
                .map(|_| rational_from_f64((r.gen::<f64>() - 0.5) * 1e3 * trial as f64).unwrap())
                .collect();
            for n in 0..ys.len() {
                if n > 0 {
                    seqsmooth::calculus::Polynomial::new(z.clone()); // keep types explicit
                    let p = seqsmooth::model::phi(m, Rational::from_integer(1.into()));
                    z = (0..=m)
                        .map(|i| {
                            (i..=m).fold(Rational::from_integer(0.into()), |a, j| {
                                a + p[(i, j)].clone() * z[j].clone()
                            })
                        })
                        .collect();
                }
                let e = rational_from_f64(ys[n]).unwrap() - z[0].clone();
                let h = expanding_gains::<Rational>(m, n as u64, GainForm::Current);
                for k in 0..=m {
                    z[k] = z[k].clone() + h[k].clone() * e.clone();
                }
                if n >= m {
                    // exact least squares at t_n, as scaled Taylor coefficients (τ = 1)
                    let want = exact_ls_derivatives(&times[..=n], &ys[..=n], None, m, times[n]);
                    let mut fact = 1.0;
                    for k in 0..=m {
                        if k > 0 {
                            fact *= k as f64;
                        }
                        let got = seqsmooth::scalar::Scalar::to_f64(&z[k]) * fact;
                        assert!(
                            (got - want[k]).abs() <= 1e-12 * want[k].abs().max(1e-12),
                            "m={m} n={n} k={k}: {got} vs {}",
                            want[k]
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn expanding_even_long_run_stays_exact() {
    // 10^5 samples: both engines against batch QR at checkpoints (stability, Morrison §9.5).
    let n = 100_001;
    for m in [1, 2, 4, 8] {
        let times = even_times(n, 0.0, 1e-3);
        let ys = noisy_polynomial(&times, m, 100.0, 0.1, 7 + m as u64);
        let checkpoints = [999usize, 9_999, 99_999];
        for engine in [Engine::Exact, Engine::Gain] {
            let err = compare(
                Box::new(ExpandingMemory::new(m, engine).unwrap()),
                &times,
                &ys,
                m,
                |k| checkpoints.contains(&k),
                |_| None,
            );
            eprintln!("expanding long m={m} {engine:?}: {err:.2e}");
            assert!(err < TOL, "m={m} {engine:?} {err:e}");
        }
    }
}

#[test]
fn expanding_irregular_exact_engine_equals_batch_qr() {
    for m in 0..=8 {
        for (label, times) in [
            ("jittered", jittered_times(150, 0.1, 0.4, 11 + m as u64)),
            ("random", random_times(150, 0.1, 21 + m as u64)),
        ] {
            let ys = noisy_polynomial(&times, m, 15.0, 0.2, 31 + m as u64);
            let err = compare(
                Box::new(ExpandingMemory::new(m, Engine::Exact).unwrap()),
                &times,
                &ys,
                m,
                |_| true,
                |_| None,
            );
            eprintln!("expanding {label} m={m}: {err:.2e}");
            assert!(err < TOL, "m={m} {label} {err:e}");
        }
    }
}

#[test]
fn expanding_irregular_exact_engine_equals_rational_least_squares() {
    // Exact rational normal equations: an oracle free of rounding.
    for m in 0..=4 {
        let times = random_times(25, 0.3, 41 + m as u64);
        let ys = noisy_polynomial(&times, m, 7.0, 0.5, 51 + m as u64);
        let mut f = ExpandingMemory::new(m, Engine::Exact).unwrap();
        let mut got = Vec::new();
        let mut want = Vec::new();
        for n in 0..times.len() {
            f.update(times[n], ys[n]).unwrap();
            if n >= m {
                got.push(f.estimate().unwrap().derivatives);
                want.push(exact_ls_derivatives(
                    &times[..=n],
                    &ys[..=n],
                    None,
                    m,
                    times[n],
                ));
            }
        }
        let fl = floors(&want);
        let err = got
            .iter()
            .zip(&want)
            .map(|(a, b)| rel_err(a, b, &fl))
            .fold(0.0, f64::max);
        eprintln!("expanding rational m={m}: {err:.2e}");
        assert!(err < TOL, "m={m} {err:e}");
    }
}

fn discount_weights(times: &[f64], n: usize, theta: f64, tau: f64, mode: DiscountMode) -> Vec<f64> {
    (0..=n)
        .map(|k| match mode {
            DiscountMode::PerTime => theta.powf((times[n] - times[k]) / tau),
            DiscountMode::PerUpdate => theta.powi((n - k) as i32),
        })
        .collect()
}

#[test]
fn fading_irregular_exact_engine_equals_discounted_batch_qr() {
    // Weights θ^((t_n - t_k)/τ) (and θ^(n-k) per update) from the first determinable sample.
    for m in 0..=8 {
        for mode in [DiscountMode::PerTime, DiscountMode::PerUpdate] {
            let theta = 0.93;
            let tau = 0.1;
            let times = jittered_times(400, 0.1, 0.5, 61 + m as u64);
            let ys = noisy_polynomial(&times, m, 10.0, 0.2, 71 + m as u64);
            let f = FadingMemory::new(m, theta, tau, Engine::Exact)
                .unwrap()
                .with_discount_mode(mode)
                .unwrap();
            let err = compare(
                Box::new(f),
                &times,
                &ys,
                m,
                |n| n < 60 || n % 7 == 0,
                |n| Some(discount_weights(&times, n, theta, tau, mode)),
            );
            eprintln!("fading irregular {mode:?} m={m}: {err:.2e}");
            assert!(err < TOL, "m={m} {mode:?} {err:e}");
        }
    }
}

/// A smooth bounded signal whose derivatives all matter over a fading memory of a few tens of
/// samples (a polynomial truth over a long run would leave the high derivatives far below the
/// rounding of the values, and no oracle could judge them relatively), plus noise.
fn wavy(times: &[f64], scale: f64, sigma: f64, seed: u64) -> Vec<f64> {
    use rand_distr::{Distribution, Normal};
    let mut r = rng(seed);
    let noise = Normal::new(0.0, sigma).unwrap();
    times
        .iter()
        .map(|&t| {
            (t / (15.0 * scale)).sin()
                + 0.5 * (t / (23.0 * scale) + 1.0).cos()
                + noise.sample(&mut r)
        })
        .collect()
}

/// Exact discounted least squares at sample `n` with weights `(p/q)^(n-k)` on the evenly
/// spaced `times` (step `step`), evaluated at `at` (a sample time or one step beyond).
fn exact_discounted(
    times: &[f64],
    ys: &[f64],
    n: usize,
    pq: (u64, u64),
    m: usize,
    at: f64,
) -> Vec<f64> {
    let step = times[1] - times[0];
    let u: Vec<i64> = times[..=n]
        .iter()
        .map(|t| ((t - at) / step).round() as i64)
        .collect();
    exact_discounted_even(&u, &ys[..=n], pq.0, pq.1, m, step)
}

fn compare_fading_exact(
    f: &mut FadingMemory,
    times: &[f64],
    ys: &[f64],
    m: usize,
    theta_per_sample: (u64, u64),
    checks: &[usize],
) -> f64 {
    let mut got = Vec::new();
    let mut want = Vec::new();
    for n in 0..times.len() - 1 {
        f.update(times[n], ys[n]).unwrap();
        if checks.contains(&n) {
            for at in [times[n], times[n + 1]] {
                got.push(f.estimate_at(at).unwrap().derivatives);
                want.push(exact_discounted(times, ys, n, theta_per_sample, m, at));
            }
        }
    }
    let fl = floors(&want);
    got.iter()
        .zip(&want)
        .map(|(a, b)| rel_err(a, b, &fl))
        .fold(0.0, f64::max)
}

#[test]
fn fading_memory_equals_exact_discounted_least_squares_once_the_start_up_has_decayed() {
    // Morrison (13.2.1) criterion with weights θ^(n-k), θ = 9/10, against exact rational least
    // squares. Gain engine: expanding-memory start, switch (§13.8), then the switch transient
    // decays like θ^n·poly(n) (§13.4); checked from sample 700 on. Exact engine: from the first
    // determinable sample.
    let theta = (9, 10);
    let times = even_times(1000, 0.0, 1.0);
    for m in 0..=8 {
        let ys = dyadic(&wavy(&times, 1.0, 0.01, 81 + m as u64));
        let mut gain = FadingMemory::new(m, 0.9, 1.0, Engine::Gain).unwrap();
        let g = compare_fading_exact(&mut gain, &times, &ys, m, theta, &[700, 850, 998]);
        let mut exact = FadingMemory::new(m, 0.9, 1.0, Engine::Exact).unwrap();
        let checks: Vec<usize> = [m, m + 1, m + 5, 40, 200, 998]
            .into_iter()
            .filter(|&n| n >= m)
            .collect();
        let e = compare_fading_exact(&mut exact, &times, &ys, m, theta, &checks);
        eprintln!("fading even m={m}: gain {g:.2e}, exact {e:.2e}");
        assert!(g < TOL && e < TOL, "m={m}: gain {g:e} exact {e:e}");
    }
}

#[test]
fn gain_engine_is_exact_on_even_steps_that_differ_from_tau() {
    // ../shared/spec/others.md §4.8: with n = sample count, gains h_k/ζ^k and θ_eff = θ^ζ the
    // variable-step recursion is exact for a constant step ζτ ≠ τ (the paper's rule is not).
    for m in 0..=8 {
        let times = even_times(300, 1.0, 0.375);
        let ys = noisy_polynomial(&times, m, 100.0, 0.3, 91 + m as u64);
        let err = compare(
            Box::new(ExpandingMemory::new(m, Engine::Gain).unwrap()),
            &times,
            &ys,
            m,
            |_| true,
            |_| None,
        );
        assert!(err < TOL, "expanding m={m} {err:e}");
        // θ = 0.81 per τ = 1: per-sample discount 0.9 at step 0.5 and 0.6561 at step 2, exact
        // rationals for the oracle.
        for (step, per_sample, len) in [(0.5, (9, 10), 1000), (2.0, (6561, 10000), 400)] {
            let times = even_times(len, 0.0, step);
            let ys = dyadic(&wavy(&times, step, 0.01, 101 + m as u64));
            let mut f = FadingMemory::new(m, 0.81, 1.0, Engine::Gain).unwrap();
            let err =
                compare_fading_exact(&mut f, &times, &ys, m, per_sample, &[len - 100, len - 2]);
            eprintln!("fading gain step={step} m={m}: {err:.2e}");
            assert!(err < TOL, "fading m={m} step={step} {err:e}");
        }
    }
}

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

/// An expanding- or fading-memory (θ = 0.8 per 0.2) filter, with covariance when `sigma` is set.
fn test_filter(fading: bool, engine: Engine, m: usize, sigma: Option<f64>) -> Filter {
    match (fading, sigma) {
        (false, None) => Box::new(ExpandingMemory::new(m, engine).unwrap()),
        (false, Some(s)) => Box::new(
            ExpandingMemory::new(m, engine)
                .unwrap()
                .with_noise_sigma(s)
                .unwrap(),
        ),
        (true, None) => Box::new(FadingMemory::new(m, 0.8, 0.2, engine).unwrap()),
        (true, Some(s)) => Box::new(
            FadingMemory::new(m, 0.8, 0.2, engine)
                .unwrap()
                .with_noise_sigma(s)
                .unwrap(),
        ),
    }
}

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

#[test]
fn covariance_on_even_samples_equals_the_closed_form_vrf() {
    // Morrison (9.7.1)-(9.7.4) expanding at n; (13.6.20) fading steady state; D(τ) S D(τ).
    let sigma = 2.0;
    let tau = 0.5;
    for m in 0..=4 {
        let times = even_times(30, 0.0, tau);
        for engine in [Engine::Exact, Engine::Gain] {
            let mut f = ExpandingMemory::new(m, engine)
                .unwrap()
                .with_noise_sigma(sigma)
                .unwrap();
            for &t in &times {
                f.update(t, 1.0).unwrap();
            }
            for (form, at) in [
                (EstimateForm::Current, times[29]),
                (EstimateForm::Predictor, times[29] + tau),
            ] {
                let vrf =
                    unscale(&expanding_vrf::<f64>(m, 29, form).unwrap(), tau) * (sigma * sigma);
                let got = f.estimate_at(at).unwrap().covariance.unwrap();
                assert_matrix_close(
                    &got,
                    &vrf,
                    1e-9,
                    &format!("expanding {engine:?} m={m} {form:?}"),
                );
            }
        }
        let times = even_times(900, 0.0, tau);
        for engine in [Engine::Exact, Engine::Gain] {
            let mut f = FadingMemory::new(m, 0.9, tau, engine)
                .unwrap()
                .with_noise_sigma(sigma)
                .unwrap();
            for &t in &times {
                f.update(t, 1.0).unwrap();
            }
            for (form, at) in [
                (EstimateForm::Current, times[899]),
                (EstimateForm::Predictor, times[899] + tau),
            ] {
                let vrf = unscale(&fading_vrf(m, 0.9, form).unwrap(), tau) * (sigma * sigma);
                let got = f.estimate_at(at).unwrap().covariance.unwrap();
                assert_matrix_close(
                    &got,
                    &vrf,
                    1e-9,
                    &format!("fading {engine:?} m={m} {form:?}"),
                );
            }
        }
    }
}

#[test]
fn high_degree_exact_engine_accuracy_is_measured() {
    // Conditioning limit of the centred monomial square-root information form, documented in
    // the crate docs: measured against batch QR in the Legendre basis on 2000 irregular samples.
    // Bounds: 1e-9 to degree 12, 1e-6 to degree 16, 1e-3 to MAX_DEGREE.
    for m in [10, 12, 14, 16, 20, MAX_DEGREE] {
        let times = jittered_times(2000, 0.01, 0.3, 111 + m as u64);
        let ys = noisy_polynomial(&times, m, 20.0, 1e-3, 121 + m as u64);
        let check = [m, m + 5, 100, 500, 1998];
        let expanding = compare(
            Box::new(ExpandingMemory::new(m, Engine::Exact).unwrap()),
            &times,
            &ys,
            m,
            |n| check.contains(&n),
            |_| None,
        );
        let theta = 0.99;
        let fading = compare(
            Box::new(FadingMemory::new(m, theta, 0.01, Engine::Exact).unwrap()),
            &times,
            &ys,
            m,
            |n| check.contains(&n),
            |n| {
                Some(discount_weights(
                    &times,
                    n,
                    theta,
                    0.01,
                    DiscountMode::PerTime,
                ))
            },
        );
        eprintln!("high degree m={m}: expanding {expanding:.2e}, fading {fading:.2e}");
        let bound = if m <= 12 {
            1e-9
        } else if m <= 16 {
            1e-6
        } else {
            1e-3
        };
        assert!(
            expanding < bound && fading < bound,
            "m={m}: {expanding:e} {fading:e}"
        );
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
    let msg = Error::TimeNotIncreasing {
        time: 3.0,
        previous: 4.0,
    }
    .to_string();
    assert!(msg.contains('3') && msg.contains('4'), "{msg}");
}

#[test]
fn gain_engine_stays_close_to_least_squares_on_irregular_schedules() {
    // Regression guard (gain scaling by the current step diverged to 1e30 on Poisson arrivals;
    // see the table in the `polynomial` docs). In units of the exact estimate's own standard
    // deviation, after start-up: on ±50% jitter (expanding and fading, degree ≤ 3) the gain
    // engine stays within 10σ of the exact engine at every sample; on Poisson arrivals (fading,
    // degree ≤ 3) it does not diverge: RMS deviation below 5σ (measured 0.5σ to 2.2σ; single
    // samples stray further, to 27σ).
    for m in 1..=3 {
        let cases = [
            (false, jittered_times(150, 1.0, 0.5, 300 + m as u64), false),
            (true, jittered_times(400, 1.0, 0.5, 310 + m as u64), false),
            (true, random_times(400, 1.0, 320 + m as u64), true),
        ];
        for (fading, times, poisson) in cases {
            let ys = noisy_polynomial(&times, m, times[times.len() - 1] - times[0], 1.0, 7);
            let mut g = test_filter(fading, Engine::Gain, m, None);
            let mut e = test_filter(fading, Engine::Exact, m, Some(1.0));
            let from = if fading { 200 } else { 4 * (m + 1) };
            let (mut worst, mut sum_sq, mut count): (f64, f64, f64) = (0.0, 0.0, 0.0);
            for (k, (&t, &y)) in times.iter().zip(&ys).enumerate() {
                g.update(t, y).unwrap();
                e.update(t, y).unwrap();
                if k >= from {
                    let (a, b) = (g.estimate().unwrap(), e.estimate().unwrap());
                    let sd = b.std_devs().unwrap();
                    for ((x, y), s) in a.derivatives.iter().zip(&b.derivatives).zip(&sd) {
                        let d = (x - y).abs() / s;
                        worst = worst.max(d);
                        sum_sq += d * d;
                        count += 1.0;
                    }
                }
            }
            let rms = (sum_sq / count).sqrt();
            eprintln!("gain vs exact, fading={fading} poisson={poisson} m={m}: max {worst:.2} σ, rms {rms:.2} σ");
            if poisson {
                assert!(rms < 5.0, "m={m}: rms {rms} σ");
            } else {
                assert!(worst < 10.0, "fading={fading} m={m}: {worst} σ");
            }
        }
    }
}
