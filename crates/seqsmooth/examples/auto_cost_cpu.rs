//! The automatic filter's cost per sample against the fading-memory filter's with σ, in the
//! calling thread's CPU time (which a busy machine disturbs less than wall time), without the
//! command's reading and writing: what each of its parts costs. On the manoeuvring series of
//! `benches/automatic.rs` with the speed bound of `scripts/auto_speed.sh` (steps 1 s ± 40 %,
//! σ = 10, acceleration steps every 40-160 s, 2 % outliers of 5-10σ), degree 2, θ = 0.95 per
//! τ = 1 s, exact engine; best of 3:
//!
//! - `fading σ`: the fading-memory filter's batch σ path (`update_many_sigma_into`, the rows
//!   `d0..d2, s0..s2` of `seqsmooth filter --sigma`);
//! - `auto`: the automatic filter at its defaults, one `update` a sample (the command's path);
//! - `auto, memory_levels 2`: one more shorter memory (`θ⁴` and `θ¹⁶`; the default runs `θ⁴`
//!   alone; `tests/automatic_manoeuvres.rs` scores it with `SEQSMOOTH_AUTO_MEMORY_LEVELS`);
//! - `auto, memory_levels 0`: without the shorter memories (Morrison §7.13's adaptive memory);
//! - `auto, review_window 0`: without the review (the gate's decisions);
//! - `auto, both 0`: neither.
//!
//! All but `auto` are not the filter the command runs (its Monte Carlo figures in ACCURACY.md
//! are for the defaults); they bound what a part costs. With `review_window 0` the review keeps
//! the state before every sample (none waits for a decision, and the first one waiting keeps
//! it), so that variant costs more, not less: it is no measure of the review's own cost.
//!
//! Run: `cargo run --release -p seqsmooth --example auto_cost_cpu -- [SAMPLES] [VARIANT]`
//! (default 10⁶ samples, every variant; `VARIANT`, e.g. `auto`, runs that one after the fading
//! filter, for a profiler).
//! The CPU time is read from `/proc/thread-self/schedstat` (Linux); elsewhere the wall time.

#[path = "common/cpu.rs"]
mod cpu;
#[path = "../benches/common/manoeuvring.rs"]
mod manoeuvring;

use cpu::{cpu_ns, seconds};
use seqsmooth::polynomial::automatic::AutomaticFilter;
use seqsmooth::{Engine, FadingMemory, PolynomialFilter};

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map_or(1_000_000, |s| s.parse().expect("SAMPLES"));
    // A second argument runs only the variant of that name (for a profiler).
    let only = std::env::args().nth(2);
    let (ts, ys) = manoeuvring::series(n, Some(400.0));
    let unit = if cpu_ns().is_some() { "CPU" } else { "wall" };
    println!("{n} samples, best of 3, {unit} time");
    let best = |f: &dyn Fn() -> f64| (0..3).map(|_| f()).fold(f64::INFINITY, f64::min);
    let fading = best(&|| {
        let mut f = FadingMemory::new(2, 0.95, 1.0, Engine::Exact)
            .unwrap()
            .with_noise_sigma(10.0)
            .unwrap();
        let mut rows = vec![0.0; 6 * 65_536];
        seconds(|| {
            for (tc, yc) in ts.chunks(65_536).zip(ys.chunks(65_536)) {
                f.update_many_sigma_into(tc, yc, &mut rows[..6 * tc.len()])
                    .unwrap();
            }
            std::hint::black_box(&rows);
        })
    });
    println!(
        "{:24} {:7.3} s  {:6.0} ns/sample",
        "fading σ",
        fading,
        fading / n as f64 * 1e9
    );
    let auto = AutomaticFilter::new(2, 0.95, 1.0).unwrap();
    let variants = [
        ("auto", auto.clone()),
        (
            "auto, memory_levels 2",
            auto.clone().with_memory_levels(2).unwrap(),
        ),
        (
            "auto, memory_levels 0",
            auto.clone().with_memory_levels(0).unwrap(),
        ),
        (
            "auto, review_window 0",
            auto.clone().with_review_window(0).unwrap(),
        ),
        (
            "auto, both 0",
            auto.with_memory_levels(0)
                .unwrap()
                .with_review_window(0)
                .unwrap(),
        ),
    ];
    for (name, filter) in variants {
        if only.as_deref().is_some_and(|o| o != name) {
            continue;
        }
        let secs = best(&|| {
            let mut f = filter.clone();
            seconds(|| {
                let mut acc = 0.0;
                for (&t, &y) in ts.iter().zip(&ys) {
                    PolynomialFilter::update(&mut f, t, y).unwrap();
                    let o = f.last_output().unwrap();
                    acc += o.estimate.as_ref().map_or(0.0, |s| s.derivatives[0]);
                }
                std::hint::black_box(acc);
            })
        });
        println!(
            "{name:24} {secs:7.3} s  {:6.0} ns/sample  {:5.2}× fading σ",
            secs / n as f64 * 1e9,
            secs / fading
        );
    }
}
