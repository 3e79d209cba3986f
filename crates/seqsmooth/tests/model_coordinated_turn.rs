//! `model::coordinated_turn`: the estimated-rate model's analytic `Φ` against central
//! differences of its closed-form propagation; the known-rate model's `Φ` against
//! `model::linear`'s `e^{Aζ}` and its `Q(ζ)` against `model::continuous`'s Van Loan integral,
//! within 1e-12, on irregular steps; `ω → 0` (near and at 0) equal to constant velocity, and
//! the series on either side of the closed form's limit; the refusals.

use nalgebra::{DMatrix, DVector};
use seqsmooth::kalman::noise::{ProcessNoise, WhiteNoiseDerivative};
use seqsmooth::model::continuous::ContinuousModel;
use seqsmooth::model::coordinated_turn::CoordinatedTurn;
use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
use seqsmooth::model::linear::LinearDynamics;
use seqsmooth::{Error, Param};

/// Irregular steps, forwards and backwards.
const STEPS: [f64; 7] = [1e-3, 0.0371, 0.61, 1.3, 7.3, 41.0, -2.9];

/// Turn rates across the series' limit and beyond (rad/s), and 0.
const RATES: [f64; 9] = [0.0, 1e-12, -3e-7, 0.03, -0.2, 0.7693, 0.7694, 1.9, -6.0];

fn state(w: f64) -> DVector<f64> {
    DVector::from_vec(vec![1e3, -2e3, 5e2, -150.0, 130.0, 2.0, w])
}

fn relative(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (a - b).amax() / b.amax().max(1e-300)
}

/// The analytic `Φ` is the derivative of the propagation: central differences with steps
/// `h` and `h/2` combined by Richardson's rule (error `O(h⁴)`), within 1e-7 of each entry's
/// scale.
#[test]
fn the_estimated_rate_transition_is_its_derivative() {
    let turn = CoordinatedTurn::estimated(1.0, 1e-6).unwrap();
    for w in RATES {
        for zeta in STEPS {
            let x = state(w);
            let phi = turn.propagate(&x, 10.0, 10.0 + zeta).unwrap().transition;
            let at = |x: &DVector<f64>| turn.propagate(x, 10.0, 10.0 + zeta).unwrap().state;
            for col in 0..7 {
                let h = if col == 6 {
                    1e-4
                } else {
                    1e-2 * x[col].abs().max(1.0)
                };
                let diff = |h: f64| {
                    let (mut up, mut down) = (x.clone(), x.clone());
                    up[col] += h;
                    down[col] -= h;
                    (at(&up) - at(&down)) / (2.0 * h)
                };
                let d = (diff(h / 2.0) * 4.0 - diff(h)) / 3.0;
                for row in 0..7 {
                    let scale = phi.column(col).amax().max(1.0);
                    assert!(
                        (d[row] - phi[(row, col)]).abs() < 1e-7 * scale,
                        "ω {w}, ζ {zeta}: ({row}, {col}) {} vs {}",
                        d[row],
                        phi[(row, col)]
                    );
                }
            }
        }
    }
}

/// The known-rate model is `dX/dt = A X`: its `Φ` is `model::linear`'s `e^{Aζ}` (Padé, or
/// the finite series at `ω = 0`) and the estimated model's first six rows and columns at the
/// same `ω`; its `Q(ζ)` is Van Loan's for white acceleration of density `q` on the velocities.
#[test]
fn the_known_rate_model_is_its_exponential_and_van_loan() {
    let q = 0.7;
    let mut worst = (0.0f64, 0.0f64);
    for w in RATES {
        let known = CoordinatedTurn::known(w, q).unwrap();
        let a = known.matrix().unwrap();
        let linear = LinearDynamics::new(a.clone()).unwrap();
        let mut qc = DMatrix::zeros(6, 6);
        for k in 3..6 {
            qc[(k, k)] = q;
        }
        let continuous = ContinuousModel::new(a, qc).unwrap();
        let estimated = CoordinatedTurn::estimated(q, 0.0).unwrap();
        for zeta in STEPS {
            let x = state(w).rows(0, 6).into_owned();
            let p = known.propagate(&x, 3.0, 3.0 + zeta).unwrap();
            let exp = linear.transition(zeta).unwrap();
            let e_phi = relative(&p.transition, &exp);
            assert!(e_phi < 1e-12, "ω {w}, ζ {zeta}: Φ {e_phi:e}");
            assert!((&p.state - &exp * &x).amax() < 1e-12 * x.amax() * exp.amax());
            let full = estimated.propagate(&state(w), 3.0, 3.0 + zeta).unwrap();
            assert_eq!(full.transition.view((0, 0), (6, 6)), p.transition);
            assert_eq!(full.state.rows(0, 6), p.state);
            let q_turn = known.covariance(3.0, 3.0 + zeta).unwrap();
            let van_loan = continuous.noise_covariance(zeta.abs()).unwrap();
            let e_q = relative(&q_turn, &van_loan);
            assert!(e_q < 1e-12, "ω {w}, ζ {zeta}: Q {e_q:e}");
            worst = (worst.0.max(e_phi), worst.1.max(e_q));
        }
    }
    println!(
        "largest relative difference: Φ {:.1e}, Q {:.1e}",
        worst.0, worst.1
    );
}

/// At `ω = 0` the turn is constant velocity exactly, and `Q` constant velocity's; near 0 the
/// `ω` column is its Taylor series `∂a/∂ω = ζ²(−θ/3 + θ³/30)`, `∂b/∂ω = ζ²(1/2 − θ²/8 +
/// θ⁴/144)` to rounding, with no cancellation.
#[test]
fn a_vanishing_rate_is_constant_velocity() {
    let cv = PolynomialDynamics::new(1, 3);
    let turn = CoordinatedTurn::estimated(0.4, 1e-5).unwrap();
    for zeta in STEPS {
        let x = state(0.0);
        let p = turn.propagate(&x, 0.0, zeta).unwrap();
        let c = cv.propagate(&x.rows(0, 6).into_owned(), 0.0, zeta).unwrap();
        assert_eq!(p.transition.view((0, 0), (6, 6)), c.transition);
        assert_eq!(p.state.rows(0, 6), c.state);
        assert_eq!(p.state[6], 0.0);
        // The ω column at 0: ∂x/∂ω = −ẏ ζ²/2, ∂y/∂ω = ẋ ζ²/2, ∂ẋ/∂ω = −ζ ẏ, ∂ẏ/∂ω = ζ ẋ.
        let z2 = zeta * zeta;
        let want = [
            -x[4] * z2 / 2.0,
            x[3] * z2 / 2.0,
            0.0,
            -zeta * x[4],
            zeta * x[3],
            0.0,
            1.0,
        ];
        for (row, w) in want.iter().enumerate() {
            assert!(
                (p.transition[(row, 6)] - w).abs() <= 1e-15 * w.abs(),
                "ζ {zeta} row {row}"
            );
        }
        let q_cv = WhiteNoiseDerivative::new(1, 3, 0.4)
            .unwrap()
            .covariance(0.0, zeta)
            .unwrap();
        let q = turn.covariance(0.0, zeta).unwrap();
        assert!(relative(&q.view((0, 0), (6, 6)).into_owned(), &q_cv) < 1e-15);
        assert!((q[(6, 6)] - 1e-5 * zeta.abs()).abs() < 1e-20);
        let known = CoordinatedTurn::known(0.0, 0.4).unwrap();
        assert!(relative(&known.covariance(0.0, zeta).unwrap(), &q_cv) < 1e-15);
    }
    for w in [1e-9, -2e-6, 1e-4] {
        for zeta in STEPS {
            let x = state(w);
            let p = turn.propagate(&x, 0.0, zeta).unwrap();
            let t = w * zeta;
            let z2 = zeta * zeta;
            let da = z2 * (-t / 3.0 + t * t * t / 30.0);
            let db = z2 * (0.5 - t * t / 8.0 + t.powi(4) / 144.0);
            let want0 = x[3] * da - x[4] * db;
            let want1 = x[3] * db + x[4] * da;
            for (row, want) in [(0, want0), (1, want1)] {
                let got = p.transition[(row, 6)];
                assert!(
                    (got - want).abs() <= 1e-14 * want.abs(),
                    "ω {w} ζ {zeta}: {got} vs {want}"
                );
            }
        }
    }
}

/// Either side of the series' limit `|ωζ| = 1` the functions agree to rounding: no jump
/// where the closed form takes over.
#[test]
fn the_series_meets_the_closed_form() {
    let turn = CoordinatedTurn::estimated(1.0, 0.0).unwrap();
    let zeta = 2.0;
    let below = turn
        .propagate(&state(0.5 * (1.0 - 1e-15)), 0.0, zeta)
        .unwrap();
    let above = turn
        .propagate(&state(0.5 * (1.0 + 1e-15)), 0.0, zeta)
        .unwrap();
    let e = relative(&below.transition, &above.transition);
    assert!(e < 1e-13, "{e:e}");
    let qb = CoordinatedTurn::known(0.5 * (1.0 - 1e-15), 1.0).unwrap();
    let qa = CoordinatedTurn::known(0.5 * (1.0 + 1e-15), 1.0).unwrap();
    let e = relative(
        &qb.noise_covariance(zeta).unwrap(),
        &qa.noise_covariance(zeta).unwrap(),
    );
    assert!(e < 1e-13, "{e:e}");
}

/// A turn keeps the speed, and a step there and back is the identity.
#[test]
fn a_turn_keeps_the_speed_and_reverses() {
    let turn = CoordinatedTurn::estimated(1.0, 0.0).unwrap();
    let x = state(0.3);
    let p = turn.propagate(&x, 0.0, 7.7).unwrap();
    let speed = |v: &DVector<f64>| v[3].hypot(v[4]);
    assert!((speed(&p.state) - speed(&x)).abs() < 1e-12 * speed(&x));
    let back = turn.propagate(&p.state, 7.7, 0.0).unwrap();
    assert!((&back.state - &x).amax() < 1e-9);
    let scale = back.transition.amax() * p.transition.amax();
    assert!((back.transition * &p.transition - DMatrix::identity(7, 7)).amax() < 1e-14 * scale);
}

#[test]
fn bad_settings_and_states_are_refused() {
    let param = |e: Error| match e {
        Error::InvalidParameter { name, .. } => Some(name),
        _ => None,
    };
    assert_eq!(
        param(CoordinatedTurn::known(f64::INFINITY, 1.0).unwrap_err()),
        Some(Param::TurnRate)
    );
    assert_eq!(
        param(CoordinatedTurn::known(0.1, -1.0).unwrap_err()),
        Some(Param::Q)
    );
    assert_eq!(
        param(CoordinatedTurn::estimated(1.0, f64::NAN).unwrap_err()),
        Some(Param::TurnRateNoise)
    );
    let turn = CoordinatedTurn::estimated(1.0, 0.0).unwrap();
    assert!(turn.propagate(&DVector::zeros(6), 0.0, 1.0).is_err());
    assert!(turn.propagate(&state(f64::NAN), 0.0, 1.0).is_err());
    assert!(turn.propagate(&state(0.1), 0.0, f64::INFINITY).is_err());
    assert!(turn.covariance(0.0, f64::NAN).is_err());
    // A state whose turn overflows is refused, not carried as infinity.
    let mut huge = state(0.1);
    huge[3] = 1e308;
    assert!(turn.propagate(&huge, 0.0, 1e10).is_err());
}
