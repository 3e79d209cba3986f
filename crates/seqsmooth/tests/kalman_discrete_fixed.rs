//! The fixed-size batch of `LinearKalmanFilter::update_many` (constant matrices, `n ≤ 9`
//! states, `p ≤ 3` components: `kalman::discrete_fixed`) against the generic filter, on seeded
//! random models of every size in range and past it: the same numbers bit for bit, step by
//! step (`predict` + `update`) and as a batch forced onto the generic path (every step given
//! its `F`), missing components included; a step with its own matrices, and a refused step,
//! handed on to the generic path with the same numbers and errors.

use nalgebra::{DMatrix, DVector};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use seqsmooth::kalman::discrete::{LinearKalmanFilter, Pass, StepMatrices};
use seqsmooth::Error;

/// A random model of `n` states and `p` components: `F` near the identity and stable, `Q`,
/// `R` and `P0` full symmetric positive definite, `H` dense; and `steps` measurements of a
/// simulated run, `missing` of the components NaN (some steps all missing).
struct Model {
    filter: LinearKalmanFilter,
    f: DMatrix<f64>,
    zs: Vec<f64>,
}

fn model(rng: &mut StdRng, n: usize, p: usize, steps: usize, missing: f64) -> Model {
    let mut normal = |r: usize, c: usize| DMatrix::from_fn(r, c, |_, _| rng.sample(StandardNormal));
    let f = DMatrix::identity(n, n) * 0.95 + normal(n, n) * (0.2 / (n as f64).sqrt());
    // Stable (largest singular value at most 0.999), so that a long run stays bounded.
    let f = &f * (0.999 / f.singular_values().max()).min(1.0);
    let a = normal(n, n) * 0.1;
    let q = &a * a.transpose() + DMatrix::identity(n, n) * 1e-3;
    let h = normal(p, n);
    let b = normal(p, p) * 0.5;
    let r = &b * b.transpose() + DMatrix::identity(p, p) * 0.1;
    let c = normal(n, n);
    let p0 = &c * c.transpose() + DMatrix::identity(n, n);
    let x0 = DVector::from_fn(n, |_, _| rng.sample::<f64, _>(StandardNormal));
    let mut truth = x0.clone();
    let mut zs = Vec::with_capacity(steps * p);
    for _ in 0..steps {
        truth =
            &f * &truth + DVector::from_fn(n, |_, _| 0.05 * rng.sample::<f64, _>(StandardNormal));
        let z = &h * &truth;
        let all_missing = rng.gen_bool(missing / 3.0);
        for v in z.iter() {
            let gone = all_missing || rng.gen_bool(missing);
            zs.push(if gone {
                f64::NAN
            } else {
                v + 0.3 * rng.sample::<f64, _>(StandardNormal)
            });
        }
    }
    let filter = LinearKalmanFilter::new(x0, p0, f.clone(), h, q, r).unwrap();
    Model { filter, f, zs }
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// The batch, step `k` at a time through `predict` and `update` (the generic filter): the same
/// [`Pass`] as `update_many` gives.
fn stepwise<'a>(
    mut kf: LinearKalmanFilter,
    zs: &[f64],
    step: impl Fn(usize) -> StepMatrices<'a>,
) -> Pass {
    let p = kf.components();
    let mut pass = Pass::default();
    for (k, z) in zs.chunks_exact(p).enumerate() {
        let s = step(k);
        kf.predict(&s).unwrap();
        pass.predicted_states.extend(kf.state().iter());
        pass.predicted_covariances.extend(kf.covariance().iter());
        let nis = kf.update(z, &s).unwrap().map_or(f64::NAN, |i| i.nis);
        pass.states.extend(kf.state().iter());
        pass.covariances.extend(kf.covariance().iter());
        pass.nis.push(nis);
    }
    pass
}

fn assert_same(a: &Pass, b: &Pass, what: &str) {
    let same = |x: &[f64], y: &[f64], part: &str| {
        assert_eq!(x.len(), y.len(), "{what}: {part}: lengths");
        // NaN (no component present) has one bit pattern from both paths.
        let first = x
            .iter()
            .zip(y)
            .position(|(u, v)| u.to_bits() != v.to_bits());
        if let Some(i) = first {
            panic!("{what}: {part}: entry {i} is {:e}, not {:e}", x[i], y[i]);
        }
    };
    same(&a.states, &b.states, "states");
    same(&a.covariances, &b.covariances, "covariances");
    same(&a.predicted_states, &b.predicted_states, "predicted states");
    same(
        &a.predicted_covariances,
        &b.predicted_covariances,
        "predicted covariances",
    );
    same(&a.nis, &b.nis, "NIS");
}

/// The batch over `zs` from `filter` with constant matrices (the fixed-size path) and forced
/// onto the generic path (every step handed its `F`): each filter after, its pass, its result.
fn both_paths(
    filter: &LinearKalmanFilter,
    f: &DMatrix<f64>,
    zs: &[f64],
) -> [(LinearKalmanFilter, Pass, Result<(), Error>); 2] {
    let (mut fixed, mut generic) = (filter.clone(), filter.clone());
    let (mut pass, mut general) = (Pass::default(), Pass::default());
    let a = fixed.update_many(zs, |_| StepMatrices::default(), &mut pass);
    let forced = |_| StepMatrices {
        f: Some(f),
        ..StepMatrices::default()
    };
    let b = generic.update_many(zs, forced, &mut general);
    [(fixed, pass, a), (generic, general, b)]
}

/// Every size in the fixed range (n = 1..=9, p = 1..=3) and past it (n = 10, 11; p = 4),
/// three seeded models each, 300 steps with 15 % of the components missing: the batch with
/// constant matrices equals the generic filter step by step and the batch forced onto the
/// generic path, bit for bit; the filter afterwards too.
#[test]
fn fixed_batch_is_the_generic_filter_bit_for_bit() {
    let mut rng = StdRng::seed_from_u64(0x5eed_f1c5);
    for n in 1..=11 {
        for p in 1..=4 {
            for _ in 0..3 {
                let Model { filter, f, zs } = model(&mut rng, n, p, 300, 0.15);
                let what = format!("n = {n}, p = {p}");
                let [(fixed, pass, a), (generic, general, b)] = both_paths(&filter, &f, &zs);
                a.unwrap();
                b.unwrap();
                assert_same(&pass, &general, &what);
                let by_step = stepwise(filter, &zs, |_| StepMatrices::default());
                assert_same(&pass, &by_step, &what);
                assert!(
                    pass.nis.iter().any(|v| v.is_nan()),
                    "{what}: a step all missing"
                );
                assert_eq!(fixed.steps(), 300);
                assert_eq!(
                    bits(fixed.state().as_slice()),
                    bits(generic.state().as_slice())
                );
                let (a, b) = (fixed.covariance(), generic.covariance());
                assert_eq!(bits(a.as_slice()), bits(b.as_slice()));
            }
        }
    }
}

/// 10⁴ steps of the benchmark's size (4 states, 2 components): still bit for bit, and two
/// batches in a row are one batch (the filter's estimate and step count carried over).
#[test]
fn long_batch_and_batches_in_a_row() {
    let mut rng = StdRng::seed_from_u64(42);
    let Model { filter, f, zs } = model(&mut rng, 4, 2, 10_000, 0.1);
    let [(_, pass, a), (_, general, b)] = both_paths(&filter, &f, &zs);
    a.unwrap();
    b.unwrap();
    assert_same(&pass, &general, "10^4 steps");
    let mut halves = filter;
    let (mut first, mut second) = (Pass::default(), Pass::default());
    let cut = 2 * 4_321;
    halves
        .update_many(&zs[..cut], |_| StepMatrices::default(), &mut first)
        .unwrap();
    halves
        .update_many(&zs[cut..], |_| StepMatrices::default(), &mut second)
        .unwrap();
    assert_eq!(halves.steps(), 10_000);
    let joined: Vec<f64> = first.states.iter().chain(&second.states).copied().collect();
    assert_eq!(bits(&joined), bits(&pass.states));
}

/// Steps with their own `R` (step 0), `Q` (step 120) and `H` (steps 200, 201) in a constant
/// batch: the generic filter takes those, the fixed path the runs between them, and the batch
/// equals the generic filter step by step.
#[test]
fn step_matrices_hand_over_to_the_generic_path() {
    let mut rng = StdRng::seed_from_u64(7);
    let Model { filter, zs, .. } = model(&mut rng, 5, 3, 300, 0.1);
    let q = DMatrix::identity(5, 5) * 0.5;
    let h = DMatrix::from_fn(3, 5, |i, j| f64::from(i == j));
    let r = DMatrix::identity(3, 3) * 2.0;
    let step = |k: usize| StepMatrices {
        r: (k == 0).then_some(&r),
        q: (k == 120).then_some(&q),
        h: (k == 200 || k == 201).then_some(&h),
        ..StepMatrices::default()
    };
    let mut pass = Pass::default();
    filter.clone().update_many(&zs, step, &mut pass).unwrap();
    assert_same(&pass, &stepwise(filter, &zs, step), "per-step Q and H");
}

/// An infinite measurement value at step 150: the batch's error names the step (the generic
/// path's error), the 150 steps before it are taken and given, equal to the generic batch.
#[test]
fn a_refused_step_is_the_generic_paths_error() {
    let mut rng = StdRng::seed_from_u64(11);
    let Model { filter, f, mut zs } = model(&mut rng, 3, 1, 300, 0.1);
    zs[150] = f64::INFINITY;
    let [(fixed, pass, a), (generic, general, b)] = both_paths(&filter, &f, &zs);
    let (err, want) = (a.unwrap_err(), b.unwrap_err());
    assert!(matches!(err, Error::InBatch { index: 150, .. }), "{err:?}");
    assert_eq!(format!("{err}"), format!("{want}"));
    assert_same(&pass, &general, "before the refused step");
    assert_eq!((fixed.steps(), generic.steps()), (150, 150));
    assert_eq!(
        bits(fixed.state().as_slice()),
        bits(generic.state().as_slice())
    );
}
