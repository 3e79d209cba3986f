//! The calling thread's CPU time, for the examples that time a loop on a busy machine
//! (`examples/batch_sigma_cpu.rs`, `examples/auto_cost_cpu.rs`; included by path).

use std::time::Instant;

/// Nanoseconds this thread has run (user and system), or `None` without the Linux file.
pub fn cpu_ns() -> Option<u64> {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

/// Seconds `f` takes: CPU time where it can be read, else wall time.
pub fn seconds(f: impl FnOnce()) -> f64 {
    let (wall, cpu) = (Instant::now(), cpu_ns());
    f();
    match (cpu, cpu_ns()) {
        (Some(a), Some(b)) => (b - a) as f64 * 1e-9,
        _ => wall.elapsed().as_secs_f64(),
    }
}
