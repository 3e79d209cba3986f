//! Shared by the batch tests and the `accuracy_batch` example: deterministic data, the filters
//! compared, and the measured differences between `update_many` (the plain-`f64` kernels) and
//! the compensated per-sample path.

use seqsmooth::{
    Engine, ExpandingMemory, FadingMemory, FixedEngine, FixedMemory, PolynomialFilter,
};

/// Deterministic data: a slow sine, a trend and a unit pseudo-random term.
pub fn sample(n: usize) -> f64 {
    let mut s = (n as u64).wrapping_mul(0xD1B5_4A32_D192_ED03) ^ 0x9E37_79B9_7F4A_7C15;
    s ^= s >> 29;
    s = s.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    s ^= s >> 32;
    let noise = (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
    let t = n as f64;
    100.0 * (0.003 * t).sin() + 0.01 * t + noise
}

/// `n` times `k·0.1` (steps equal up to rounding) or, `irregular`, steps `0.1·(1 ± 0.3)`.
pub fn grid(n: usize, irregular: bool) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let k = k as f64;
            if irregular {
                0.1 * k + 0.03 * (1.7 * k).sin()
            } else {
                0.1 * k
            }
        })
        .collect()
}

pub fn filters(m: usize, irregular: bool) -> Vec<(String, Box<dyn PolynomialFilter>)> {
    let mut v: Vec<(String, Box<dyn PolynomialFilter>)> = Vec::new();
    for engine in [Engine::Exact, Engine::Gain] {
        v.push((
            format!("expanding {engine:?}"),
            Box::new(ExpandingMemory::new(m, engine).unwrap()),
        ));
        v.push((
            format!("fading {engine:?}"),
            Box::new(FadingMemory::new(m, 0.9, 0.1, engine).unwrap()),
        ));
    }
    v.push((
        "fixed".into(),
        Box::new(
            FixedMemory::new(
                m,
                20 + 2 * m,
                if irregular {
                    FixedEngine::Irregular
                } else {
                    FixedEngine::Sliding
                },
            )
            .unwrap(),
        ),
    ));
    v
}

/// Largest difference per derivative between two states, relative to `scale`.
pub fn rel_diff(a: &[f64], b: &[f64], scale: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .zip(scale)
        .map(|((x, y), s)| (x - y).abs() / s.max(1e-300))
        .fold(0.0, f64::max)
}

/// `update_many` in batches of varied lengths against per-sample `update`, on 3000 samples of
/// [`grid`] (even or irregular), for every filter of [`filters`]: compared at every batch end,
/// the largest difference per derivative relative to the largest `|x^(k)|` so far, per filter.
pub fn update_many_difference(m: usize, irregular: bool) -> Vec<(String, f64)> {
    let times = grid(3000, irregular);
    let ys: Vec<f64> = (0..times.len()).map(sample).collect();
    let mut out = Vec::new();
    for ((name, mut one), (_, mut many)) in
        filters(m, irregular).into_iter().zip(filters(m, irregular))
    {
        let mut scale = vec![0.0f64; m + 1];
        let mut worst = 0.0f64;
        // Batches of varied lengths, compared at every batch end.
        let mut i = 0;
        let mut len = 1;
        while i < times.len() {
            let j = (i + len).min(times.len());
            many.update_many(&times[i..j], &ys[i..j]).unwrap();
            for k in i..j {
                one.update(times[k], ys[k]).unwrap();
            }
            assert_eq!(one.samples(), many.samples());
            match (one.estimate(), many.estimate()) {
                (Some(a), Some(b)) => {
                    for (s, x) in scale.iter_mut().zip(&a.derivatives) {
                        *s = s.max(x.abs());
                    }
                    worst = worst.max(rel_diff(&a.derivatives, &b.derivatives, &scale));
                }
                (None, None) => {}
                (a, b) => panic!("{name}: determined {} vs {}", a.is_some(), b.is_some()),
            }
            i = j;
            len = len % 300 + 37;
        }
        out.push((name, worst));
    }
    out
}

/// Samples in the long-run kernel comparisons.
pub const LONG_RUN: usize = 60_000;

/// The plain-`f64` fading-memory steady kernel against the compensated per-sample path over a
/// long run ([`LONG_RUN`] samples at `t = k·0.1`, `τ = 0.1`): one batch of 20 000 (long enough
/// for the block map to be built, degrees ≤ 5), then batches of 101 (a block map and 37
/// recursion steps each). Returns the worst difference over the second half of the run (every
/// 101st sample), relative to the largest `|x^(k)|` there, worst over derivatives, and the
/// sample at which the filter switched to fading memory.
pub fn plain_steady_kernel_error(m: usize, theta: f64) -> (f64, u64) {
    let n = LONG_RUN;
    let times = grid(n, false);
    let ys: Vec<f64> = (0..n).map(sample).collect();
    let batches = || {
        std::iter::once(0..20_000).chain((20_000..n).step_by(101).map(move |i| i..(i + 101).min(n)))
    };
    let mut one = FadingMemory::new(m, theta, 0.1, Engine::Gain).unwrap();
    let mut many = FadingMemory::new(m, theta, 0.1, Engine::Gain).unwrap();
    let mut scale = vec![0.0f64; m + 1];
    let mut worst = vec![0.0f64; m + 1];
    for r in batches() {
        let (tc, yc) = (&times[r.clone()], &ys[r]);
        many.update_many(tc, yc).unwrap();
        for (t, y) in tc.iter().zip(yc) {
            one.update(*t, *y).unwrap();
        }
        if one.samples() < n as u64 / 2 {
            continue;
        }
        record_difference(&one, &many, &mut scale, &mut worst);
    }
    let switched = many.switched_at().expect("switched within the run");
    (relative_worst(&worst, &scale), switched)
}

/// The plain-`f64` expanding-memory kernel against the compensated per-sample path:
/// [`LONG_RUN`] samples, even (`t = k·0.1`) or jittered (±30 %) times, in batches of 101; the
/// worst difference over the run from sample `10(m+1)` (every 101st sample), relative to the
/// largest `|x^(k)|` there, worst over derivatives.
pub fn plain_expanding_kernel_error(m: usize, jitter: bool) -> f64 {
    let n = LONG_RUN;
    let times = grid(n, jitter);
    let ys: Vec<f64> = (0..n).map(sample).collect();
    let mut one = ExpandingMemory::new(m, Engine::Gain).unwrap();
    let mut many = ExpandingMemory::new(m, Engine::Gain).unwrap();
    let mut scale = vec![0.0f64; m + 1];
    let mut worst = vec![0.0f64; m + 1];
    for (tc, yc) in times.chunks(101).zip(ys.chunks(101)) {
        many.update_many(tc, yc).unwrap();
        for (t, y) in tc.iter().zip(yc) {
            one.update(*t, *y).unwrap();
        }
        if one.samples() < 10 * (m as u64 + 1) {
            continue;
        }
        record_difference(&one, &many, &mut scale, &mut worst);
    }
    relative_worst(&worst, &scale)
}

/// Updates the running `max |x^(k)|` of `one` and `max |Δx^(k)|` between the two filters.
fn record_difference(
    one: &dyn PolynomialFilter,
    many: &dyn PolynomialFilter,
    scale: &mut [f64],
    worst: &mut [f64],
) {
    let a = one.estimate().unwrap().derivatives;
    let b = many.estimate().unwrap().derivatives;
    for k in 0..a.len() {
        scale[k] = scale[k].max(a[k].abs());
        worst[k] = worst[k].max((a[k] - b[k]).abs());
    }
}

/// `max_k worst_k / scale_k`.
fn relative_worst(worst: &[f64], scale: &[f64]) -> f64 {
    worst
        .iter()
        .zip(scale)
        .map(|(w, s)| w / s)
        .fold(0.0, f64::max)
}
