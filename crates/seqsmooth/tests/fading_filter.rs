//! The fading-memory filter (`seqsmooth::FadingMemory`; Morrison (1969) ch. 13) against exact
//! discounted least squares once the start-up has decayed.

mod common;

use common::engine::*;
use common::*;
use seqsmooth::{Engine, FadingMemory};

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
