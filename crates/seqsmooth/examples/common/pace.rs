//! Back-to-back timing of a pair in the calling thread's CPU time, for the examples that
//! measure the library against a hand-written floor on a busy machine
//! (`examples/kalman_floor_pace.rs`, `examples/gauss_newton_floor_pace.rs`; included by path).

use std::hint::black_box;

/// The calling thread's CPU time, seconds (`CLOCK_THREAD_CPUTIME_ID`).
pub fn cpu_seconds() -> f64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `t` is a valid timespec for clock_gettime to write.
    let ok = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) };
    assert_eq!(ok, 0, "clock_gettime");
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}

/// CPU seconds of one call of `f` (the thread's: other processes on a loaded machine excluded).
pub fn seconds(f: &mut impl FnMut() -> f64) -> f64 {
    let start = cpu_seconds();
    black_box(f());
    cpu_seconds() - start
}

/// `a` and `b` timed back to back `reps` times: each side's best, and the ratios `b / a` of
/// the pairs (min, median, max).
pub fn pair(reps: usize, mut a: impl FnMut() -> f64, mut b: impl FnMut() -> f64) -> [f64; 5] {
    let (mut best_a, mut best_b, mut ratios) = (f64::INFINITY, f64::INFINITY, Vec::new());
    for _ in 0..reps {
        let (ta, tb) = (seconds(&mut a), seconds(&mut b));
        best_a = best_a.min(ta);
        best_b = best_b.min(tb);
        ratios.push(tb / ta);
    }
    ratios.sort_by(f64::total_cmp);
    [
        best_a,
        best_b,
        ratios[0],
        ratios[reps / 2],
        ratios[reps - 1],
    ]
}
