//! The fading-memory filter (`seqsmooth::FadingMemory`; Morrison (1969) ch. 13) against exact
//! discounted least squares once the start-up has decayed.

mod common;

use common::engine::*;

#[test]
fn fading_memory_equals_exact_discounted_least_squares_once_the_start_up_has_decayed() {
    // Morrison (13.2.1) criterion with weights θ^(n-k), θ = 9/10, against exact rational least
    // squares. Gain engine: expanding-memory start, switch (§13.8), then the switch transient
    // decays like θ^n·poly(n) (§13.4); checked from sample 700 on. Exact engine: from the first
    // determinable sample.
    for m in 0..=8 {
        let (g, e) = fading_even_errors(m);
        assert!(g < TOL && e < TOL, "m={m}: gain {g:e} exact {e:e}");
    }
}
