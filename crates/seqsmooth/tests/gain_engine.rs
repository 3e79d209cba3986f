//! The gain engine (Morrison (1969) (9.4.18), (13.5.3) recursions): self-starting from any
//! initial state in exact arithmetic, exact on even steps that differ from τ, and close to least
//! squares on irregular schedules.

mod common;

use common::engine::*;
use common::*;
use seqsmooth::{Engine, ExpandingMemory, FadingMemory};

#[test]
fn gain_recursion_is_self_starting_from_any_initial_state_in_exact_arithmetic() {
    // Morrison §9.6 (T9-10): with the Table 9.1 gains (here: the library's exact rational
    // gains) the recursion Z ← Φ(1)Z, ε = y - z0, Z ← Z + H ε reaches the least-squares fit at
    // n = m from ANY initial state Z*_{0,-1}; in exact arithmetic the equality is exact. The f64
    // gain engine starts from exactly that state (computed directly: see its docs) and the
    // tests above check it against batch QR.
    use rand::Rng;
    use seqsmooth::polynomial::expanding::gains::expanding_gains;
    use seqsmooth::polynomial::form::GainForm;
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
fn gain_engine_is_exact_on_even_steps_that_differ_from_tau() {
    // Reyneke et al. §6: with n = sample count, gains h_k/ζ^k and θ_eff = θ^ζ the
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
            assert!(err < TOL, "fading m={m} step={step} {err:e}");
        }
    }
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
            if poisson {
                assert!(rms < 5.0, "m={m}: rms {rms} σ");
            } else {
                assert!(worst < 10.0, "fading={fading} m={m}: {worst} σ");
            }
        }
    }
}

/// The gain engine's degree bound ([`GAIN_MAX_DEGREE`]): every constructor that runs the
/// fixed-gain recursion refuses a higher degree with a typed error naming the bound, while the
/// exact engine accepts it.
#[test]
fn gain_engine_refuses_degrees_above_its_bound() {
    use seqsmooth::polynomial::automatic::AutomaticFilter;
    use seqsmooth::polynomial::bank::{ExpandingBank, FadingBank};
    use seqsmooth::polynomial::{GAIN_MAX_DEGREE, MAX_DEGREE};
    use seqsmooth::Error;
    let refused = |e: Error, m: usize| {
        assert_eq!(
            e,
            Error::GainDegreeOutOfRange {
                degree: m,
                max: GAIN_MAX_DEGREE
            }
        );
        assert!(e.to_string().contains("use the exact engine"), "{e}");
    };
    for m in GAIN_MAX_DEGREE + 1..=MAX_DEGREE {
        refused(ExpandingMemory::new(m, Engine::Gain).unwrap_err(), m);
        refused(FadingMemory::new(m, 0.9, 1.0, Engine::Gain).unwrap_err(), m);
        refused(ExpandingBank::new(m, 1.0, 4).unwrap_err(), m);
        refused(FadingBank::new(m, 0.9, 1.0, 4).unwrap_err(), m);
        let auto = AutomaticFilter::new(m, 0.9, 1.0).and_then(|f| f.with_engine(Engine::Gain));
        refused(auto.expect_err("the automatic filter refuses too"), m);
        assert!(ExpandingMemory::new(m, Engine::Exact).is_ok());
        assert!(FadingMemory::new(m, 0.9, 1.0, Engine::Exact).is_ok());
    }
    for m in 0..=GAIN_MAX_DEGREE {
        assert!(ExpandingMemory::new(m, Engine::Gain).is_ok());
        assert!(FadingMemory::new(m, 0.9, 1.0, Engine::Gain).is_ok());
    }
    // The automatic filter at the bound: its degree m+1 companions (bias) run on the exact
    // engine there, so it builds and runs.
    use seqsmooth::PolynomialFilter;
    let mut auto = AutomaticFilter::new(GAIN_MAX_DEGREE, 0.9, 1.0)
        .and_then(|f| f.with_engine(Engine::Gain))
        .unwrap();
    for k in 0..40 {
        let t = k as f64;
        PolynomialFilter::update(&mut auto, t, (0.1 * t).sin()).unwrap();
    }
    assert!(auto.estimate_at(39.0).is_some());
}

/// At its highest degree the gain engine is still what ACCURACY.md says: on even steps equal
/// to exact least squares to rounding, on 20%-jittered steps within a few σ of it (the
/// approximation of gains scheduled for even spacing), not diverging. Oracle: the exact engine
/// (itself checked against batch QR), with its own σ for unit noise as the unit.
#[test]
fn gain_engine_at_its_highest_degree_stays_close_to_least_squares() {
    use rand::{Rng, SeedableRng};
    use rand_distr::{Distribution, StandardNormal};
    use seqsmooth::polynomial::GAIN_MAX_DEGREE;
    use seqsmooth::PolynomialFilter;
    let m = GAIN_MAX_DEGREE;
    // Bounds: ACCURACY.md measures at most 6e-10σ on even steps and 6.5σ on jittered ones
    // (10 seeds, expanding memory; 1.1σ fading); at degree 12 the largest is 36σ, at 14 1.6e3σ.
    for (jitter, bound) in [(0.0, 1e-7), (0.2, 10.0)] {
        for theta in [None, Some(0.5), Some(0.9)] {
            let mut r = rand::rngs::StdRng::seed_from_u64(23);
            let n = if theta.is_none() { 400 } else { 2000 };
            let mut t = 0.0;
            let build = |engine: Engine| -> Box<dyn PolynomialFilter> {
                match theta {
                    None => Box::new(
                        ExpandingMemory::new(m, engine)
                            .unwrap()
                            .with_noise_sigma(1.0)
                            .unwrap(),
                    ),
                    Some(th) => Box::new(
                        FadingMemory::new(m, th, 1.0, engine)
                            .unwrap()
                            .with_noise_sigma(1.0)
                            .unwrap(),
                    ),
                }
            };
            let (mut gain, mut exact) = (build(Engine::Gain), build(Engine::Exact));
            let mut worst = 0.0f64;
            for i in 0..n {
                let noise: f64 = StandardNormal.sample(&mut r);
                let y = 1e4 + 30.0 * t - 0.01 * t * t + noise;
                gain.update(t, y).unwrap();
                exact.update(t, y).unwrap();
                if i >= n * 3 / 4 {
                    let g = gain.estimate_at(t).unwrap().derivatives[0];
                    let e = exact.estimate_at(t).unwrap();
                    let sigma = e.covariance.unwrap()[(0, 0)].sqrt();
                    assert!(g.is_finite(), "{theta:?} jitter {jitter}: sample {i}");
                    worst = worst.max((g - e.derivatives[0]).abs() / sigma);
                }
                t += 1.0 + jitter * (r.gen::<f64>() - 0.5) * 2.0;
            }
            assert!(worst <= bound, "θ {theta:?} jitter {jitter}: {worst:e}σ");
        }
    }
}
