//! The Kalman filter's fixed-size path for the polynomial model (`kalman::filter`'s
//! prediction at compile-time sizes, taken without the user asking for
//! `PolynomialDynamics` of `n ≤ 9` states on `d ≤ 3` axes with `WhiteNoiseDerivative` or no
//! driving noise) against the generic path on the same model: the same models wrapped so that
//! they do not say what they are (`Dynamics::polynomial`,
//! `ProcessNoise::white_noise_derivative` and `Observation::linear_matrix` `None`), which sends
//! every step through `propagate_into`, `covariance_into`, `predict_into` and the slice kernels. Seeded random models of every
//! size in range and past it (degree and axes, 1-3 observed components of a random `M`,
//! identity, diagonal and full `R`, with and without driving noise and fading memory), on
//! irregular times with repeated and backward steps and missing components: every state,
//! covariance, NIS and log-likelihood bit for bit, and the RTS smoother's (`smooth_flat`) too;
//! errors the same.

use nalgebra::{DMatrix, DVector};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use seqsmooth::kalman::noise::{ProcessNoise, WhiteNoiseDerivative};
use seqsmooth::kalman::smoother::smooth_flat;
use seqsmooth::kalman::{Discount, KalmanFilter};
use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics, Propagation};
use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
use seqsmooth::model::observation::{LinearObservation, Observation, Predicted};
use seqsmooth::Error;

/// The polynomial model that does not say it is one: the generic path.
#[derive(Clone, Debug)]
struct Plain(PolynomialDynamics);

impl Dynamics for Plain {
    fn dimension(&self) -> usize {
        self.0.dimension()
    }
    fn propagate(&self, x: &DVector<f64>, a: f64, b: f64) -> Result<Propagation, Error> {
        self.0.propagate(x, a, b)
    }
    fn propagate_into(
        &self,
        x: &DVector<f64>,
        a: f64,
        b: f64,
        out: &mut DVector<f64>,
        phi: &mut DMatrix<f64>,
    ) -> Result<(), Error> {
        self.0.propagate_into(x, a, b, out, phi)
    }
}

/// The linear observation that does not say it is one: `G` and `M` through `predict_into`.
#[derive(Clone, Debug)]
struct PlainObservation(LinearObservation);

impl Observation for PlainObservation {
    fn components(&self) -> usize {
        self.0.components()
    }
    fn state_dimension(&self) -> usize {
        self.0.state_dimension()
    }
    fn predict(&self, x: &DVector<f64>, t: f64) -> Result<Predicted, Error> {
        self.0.predict(x, t)
    }
    fn predict_into(
        &self,
        x: &DVector<f64>,
        t: f64,
        value: &mut DVector<f64>,
        jacobian: &mut DMatrix<f64>,
    ) -> Result<(), Error> {
        self.0.predict_into(x, t, value, jacobian)
    }
}

/// The white-noise driving that does not say it is one.
#[derive(Clone, Debug)]
struct PlainNoise(WhiteNoiseDerivative);

impl ProcessNoise for PlainNoise {
    fn dimension(&self) -> usize {
        self.0.dimension()
    }
    fn covariance(&self, a: f64, b: f64) -> Result<DMatrix<f64>, Error> {
        self.0.covariance(a, b)
    }
    fn covariance_into(&self, a: f64, b: f64, out: &mut DMatrix<f64>) -> Result<(), Error> {
        self.0.covariance_into(a, b, out)
    }
}

/// One random case: the two filters (fixed path, generic path) and the measurements.
struct Case {
    fast: KalmanFilter<PolynomialDynamics, LinearObservation>,
    plain: KalmanFilter<Plain, PlainObservation>,
    rows: Vec<Measurement>,
}

/// The filter on the models as they are (the fixed path) and on the same models wrapped (the
/// generic path), from the same prior.
fn both(
    dynamics: PolynomialDynamics,
    observation: LinearObservation,
    x0: DVector<f64>,
    prior: DMatrix<f64>,
) -> (
    KalmanFilter<PolynomialDynamics, LinearObservation>,
    KalmanFilter<Plain, PlainObservation>,
) {
    let fast = KalmanFilter::new(
        dynamics,
        observation.clone(),
        x0.clone(),
        prior.clone(),
        0.0,
    );
    let plain = KalmanFilter::new(
        Plain(dynamics),
        PlainObservation(observation),
        x0,
        prior,
        0.0,
    );
    (fast.unwrap(), plain.unwrap())
}

fn case(rng: &mut StdRng, degree: usize, axes: usize, p: usize, steps: usize) -> Case {
    let n = (degree + 1) * axes;
    let mut normal =
        |r: usize, c: usize| DMatrix::from_fn(r, c, |_, _| rng.sample::<f64, _>(StandardNormal));
    // M with some zeros (the kernels skip them), at least its first column not all zero.
    let mut m = normal(p, n);
    for v in m.iter_mut().skip(p) {
        if v.abs() < 0.6 {
            *v = 0.0;
        }
    }
    let c = normal(n, n);
    let prior = &c * c.transpose() + DMatrix::identity(n, n);
    let x0 = DVector::from_fn(n, |i, _| c[(i, 0)]);
    let b = normal(p, p) * 0.4;
    let full = &b * b.transpose() + DMatrix::identity(p, p) * 0.2;
    // M of unit rows now and then (each row one state component, as
    // `LinearObservation::value_of`).
    if rng.gen_bool(0.3) {
        let picks: Vec<usize> = (0..p).map(|_| rng.gen_range(0..n)).collect();
        m = DMatrix::from_fn(p, n, |r, c| if c == picks[r] { 1.0 } else { 0.0 });
    } else if p <= n && rng.gen_bool(0.3) {
        // M = [I_p 0] (the first p state components, as `value_of` and a position on each
        // axis), which the fixed-size update reads as a pattern, not as numbers.
        m = DMatrix::from_fn(p, n, |r, c| if c == r { 1.0 } else { 0.0 });
    }
    let dynamics = PolynomialDynamics::new(degree, axes);
    let observation = LinearObservation::new(m).unwrap();
    let (mut fast, mut plain) = both(dynamics, observation, x0, prior);
    if rng.gen_bool(0.7) {
        let psd = 10f64.powf(rng.gen_range(-3.0..1.0));
        let q = WhiteNoiseDerivative::new(degree, axes, psd).unwrap();
        fast.set_process_noise(q).unwrap();
        plain.set_process_noise(PlainNoise(q)).unwrap();
    }
    if rng.gen_bool(0.2) {
        let discount = if rng.gen_bool(0.5) {
            Discount::PerUpdate { theta: 0.9 }
        } else {
            Discount::PerTime {
                theta: 0.8,
                tau: 2.0,
            }
        };
        fast.set_fading(discount).unwrap();
        plain.set_fading(discount).unwrap();
    }
    let kind = rng.gen_range(0..3);
    let mut t = 0.0;
    let rows = (0..steps)
        .map(|k| {
            // Irregular steps, a repeated time now and then, and one step backwards.
            match rng.gen_range(0..10) {
                0 => {}
                1 if k == steps / 2 => t -= 0.3,
                _ => t += rng.gen_range(0.05..1.5),
            }
            let values = (0..p)
                .map(|_| {
                    rng.gen_bool(0.8)
                        .then(|| 3.0 * rng.sample::<f64, _>(StandardNormal))
                })
                .collect();
            let noise = match kind {
                0 => NoiseCovariance::Identity,
                1 => NoiseCovariance::Variances((0..p).map(|c| full[(c, c)]).collect()),
                _ => NoiseCovariance::Full(full.clone()),
            };
            Measurement {
                time: t,
                values,
                noise,
            }
        })
        .collect();
    Case { fast, plain, rows }
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// Every size in range (and past it: 4-9 axes, degree 9) on both paths: the same numbers.
#[test]
fn fixed_path_is_the_generic_path_bit_for_bit() {
    let mut rng = StdRng::seed_from_u64(20_261_207);
    let mut cases = 0;
    for axes in 1..=5 {
        for degree in 0..=9 {
            let n = (degree + 1) * axes;
            if n > 12 {
                continue;
            }
            for p in 1..=3 {
                for _ in 0..3 {
                    let Case {
                        mut fast,
                        mut plain,
                        rows,
                    } = case(&mut rng, degree, axes, p, 40);
                    for (k, m) in rows.iter().enumerate() {
                        let what =
                            format!("degree {degree}, {axes} axes, {p} components, step {k}");
                        // The whole `Innovation` from `update`, the statistics alone from
                        // `update_stats` (the fixed path writes less for it), in turn.
                        let (a, b) = if k % 3 == 2 {
                            let stats = |s: Option<seqsmooth::kalman::filter::InnovationStats>| {
                                s.map(|s| {
                                    let s =
                                        (s.components, s.nis.to_bits(), s.log_likelihood.to_bits());
                                    (s, Vec::new(), Vec::new(), Vec::new(), Vec::new())
                                })
                            };
                            (
                                fast.update_stats(m).map(stats),
                                plain.update_stats(m).map(stats),
                            )
                        } else {
                            let whole = |i: Option<seqsmooth::kalman::filter::Innovation>| {
                                i.map(|i| {
                                    (
                                        (
                                            i.innovation.len(),
                                            i.nis.to_bits(),
                                            i.log_likelihood.to_bits(),
                                        ),
                                        i.components,
                                        bits(i.innovation.as_slice()),
                                        bits(i.covariance.as_slice()),
                                        bits(i.gain.as_slice()),
                                    )
                                })
                            };
                            (fast.update(m).map(whole), plain.update(m).map(whole))
                        };
                        match (a, b) {
                            (Ok(a), Ok(b)) => assert_eq!(a, b, "{what}"),
                            (a, b) => assert_eq!(
                                a.map(|_| ()).map_err(|e| e.to_string()),
                                b.map(|_| ()).map_err(|e| e.to_string()),
                                "{what}"
                            ),
                        }
                        assert_eq!(
                            bits(fast.state().as_slice()),
                            bits(plain.state().as_slice()),
                            "{what}"
                        );
                        assert_eq!(
                            bits(fast.covariance().as_slice()),
                            bits(plain.covariance().as_slice()),
                            "{what}"
                        );
                        assert_eq!(fast.time(), plain.time());
                    }
                    // A prediction alone, forwards.
                    let t = fast.time() + 0.7;
                    fast.predict(t).unwrap();
                    plain.predict(t).unwrap();
                    assert_eq!(
                        bits(fast.covariance().as_slice()),
                        bits(plain.covariance().as_slice())
                    );
                    cases += 1;
                }
            }
        }
    }
    assert!(cases >= 200, "{cases} cases");
}

/// The RTS smoother over both paths (its forward pass the filter's): the same numbers.
#[test]
fn smoother_over_the_fixed_path_is_the_generic_smoother() {
    let mut rng = StdRng::seed_from_u64(7);
    for (degree, axes) in [
        (0, 1),
        (1, 1),
        (2, 1),
        (1, 2),
        (2, 3),
        (8, 1),
        (1, 3),
        (2, 2),
    ] {
        for p in 1..=3 {
            let Case { fast, plain, rows } = case(&mut rng, degree, axes, p, 60);
            // Forwards in time only (the smoother refuses a step back).
            let mut rows = rows;
            let mut last = f64::NEG_INFINITY;
            rows.retain(|m| {
                let keep = m.time >= last;
                last = last.max(m.time);
                keep
            });
            let (a, b) = (smooth_flat(fast, &rows), smooth_flat(plain, &rows));
            match (a, b) {
                (Ok(a), Ok(b)) => {
                    assert_eq!(bits(&a.states), bits(&b.states));
                    assert_eq!(bits(&a.covariances), bits(&b.covariances));
                    assert_eq!(bits(&a.filtered_covariances), bits(&b.filtered_covariances));
                    assert_eq!(bits(&a.gains), bits(&b.gains));
                }
                (a, b) => assert_eq!(
                    a.map(|_| ()).map_err(|e| e.to_string()),
                    b.map(|_| ()).map_err(|e| e.to_string())
                ),
            }
        }
    }
}

/// A step too long for `ζ^k/k!` to be finite: the fixed path steps aside and the generic
/// path's error is given, the filter unchanged.
#[test]
fn a_step_past_the_numbers_gives_the_generic_error() {
    let mut rng = StdRng::seed_from_u64(11);
    let Case {
        mut fast,
        mut plain,
        ..
    } = case(&mut rng, 2, 1, 1, 1);
    let far = 1e200;
    let (a, b) = (fast.predict(far), plain.predict(far));
    assert!(a.is_err());
    assert_eq!(a.unwrap_err().to_string(), b.unwrap_err().to_string());
    assert_eq!(fast.time(), 0.0);
}

/// Signed zeros: `M = [I_p 0]` and `M` with a `−0` entry (not the pattern: its `−0·x` terms
/// set signs), a state entry `−0` beside positive ones and a measured `−0`. The innovation's
/// zeros have the generic path's signs (its `G` sums every column from `−0`).
#[test]
fn signed_zeros_are_the_generic_paths() {
    let identity = DMatrix::identity(2, 2);
    let matrices = [
        DMatrix::from_row_slice(1, 2, &[1.0, 0.0]),
        DMatrix::from_row_slice(1, 2, &[1.0, -0.0]),
        DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 1.0]),
    ];
    for m in matrices {
        for x0 in [[-0.0, 1.0], [-0.0, -1.0], [0.0, -0.0], [-0.0, -0.0]] {
            let p = m.nrows();
            let observation = LinearObservation::new(m.clone()).unwrap();
            let dynamics = PolynomialDynamics::new(1, 1);
            let x0 = DVector::from_row_slice(&x0);
            let (mut fast, mut plain) = both(dynamics, observation, x0, identity.clone());
            let row = Measurement {
                time: 0.0,
                values: vec![Some(-0.0); p],
                noise: NoiseCovariance::Identity,
            };
            let (a, b) = (
                fast.update(&row).unwrap().unwrap(),
                plain.update(&row).unwrap().unwrap(),
            );
            let what = format!("M {m:?}, x0 {:?}", fast.state());
            assert_eq!(
                bits(a.innovation.as_slice()),
                bits(b.innovation.as_slice()),
                "{what}"
            );
            assert_eq!(
                bits(fast.state().as_slice()),
                bits(plain.state().as_slice()),
                "{what}"
            );
        }
    }
}
