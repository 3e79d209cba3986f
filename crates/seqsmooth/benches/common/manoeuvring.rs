//! The manoeuvring series of the automatic filter's benchmarks (`benches/automatic.rs`,
//! `examples/auto_cost_cpu.rs`), included by path (`#[path = ...] mod manoeuvring;`): steps
//! 1 s ± 40 %, white noise σ = 10, acceleration steps `U(−3, 3)` every `U(40, 160)` s, 2 %
//! outliers of 5-10σ (as `tests/automatic_manoeuvres.rs`).

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};

/// `n` samples `(times, values)`; with `speed_bound` the acceleration changes sign whenever
/// the speed is beyond it (as `scripts/auto_speed.sh`'s input), so a long series stays a
/// track rather than a random walk of the speed.
pub fn series(n: usize, speed_bound: Option<f64>) -> (Vec<f64>, Vec<f64>) {
    let mut r = StdRng::seed_from_u64(20_261_206);
    let noise = Normal::new(0.0, 10.0).unwrap();
    let (mut x, mut v, mut a, mut t) = (0.0, 50.0, 0.0, 0.0);
    let mut next = r.gen_range(40.0..160.0);
    let (mut ts, mut ys) = (Vec::with_capacity(n), Vec::with_capacity(n));
    while ts.len() < n {
        let dt = 1.0 + 0.4 * (2.0 * r.gen::<f64>() - 1.0);
        x += v * dt + 0.5 * a * dt * dt;
        v += a * dt;
        t += dt;
        if t > next {
            a = r.gen_range(-3.0..3.0);
            next += r.gen_range(40.0..160.0);
        }
        if speed_bound.is_some_and(|b| v.abs() > b) {
            a = -a;
        }
        let outlier = if r.gen::<f64>() < 0.02 {
            r.gen_range(50.0..100.0) * if r.gen::<bool>() { 1.0 } else { -1.0 }
        } else {
            0.0
        };
        ts.push(t);
        ys.push(x + noise.sample(&mut r) + outlier);
    }
    (ts, ys)
}
