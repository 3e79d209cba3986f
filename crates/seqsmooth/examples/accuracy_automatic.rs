//! Prints the scores of the automatic filter on the manoeuvring-target scenarios: ±3σ
//! coverage, outlier detection, false alarms, misfit on straight segments and restarts. The
//! tests `tests/automatic_*.rs` assert bounds on the same scores (`tests/common/automatic.rs`,
//! which also describes the scenarios: 100 runs of 2200 samples, fixed seeds).
//!
//! Run: `cargo run --release -p seqsmooth --example accuracy_automatic`

#[path = "../tests/common/mod.rs"]
mod common;

use common::automatic::{main_config, score, GENTLE, SHARP};
use seqsmooth::polynomial::automatic::{MisfitResponse, NoiseSource, OutlierRule};
use seqsmooth::{DiscountMode, Engine};

fn main() {
    let (s, _) = score(&main_config(), GENTLE);
    s.print("gentle manoeuvre, degree 2, θ = 0.97, σ known, defaults");

    let mut c = main_config();
    c.engine = Engine::Gain;
    c.discount = DiscountMode::PerUpdate;
    score(&c, GENTLE)
        .0
        .print("gentle manoeuvre, degree 2, θ = 0.97 per update, gain engine");

    for source in [
        NoiseSource::Differences { window: None },
        NoiseSource::Innovations { window: None },
    ] {
        let mut c = main_config();
        c.noise_sigma = None;
        c.noise_source = source;
        score(&c, GENTLE).0.print(&format!(
            "gentle manoeuvre, degree 2, θ = 0.97, σ estimated by {source:?}"
        ));
    }

    let mut c = main_config();
    c.outliers = OutlierRule::reyneke();
    score(&c, GENTLE)
        .0
        .print("gentle manoeuvre, degree 2, θ = 0.97, σ known, Reyneke gate k = 3");

    score(&main_config(), SHARP)
        .0
        .print("sharp manoeuvre, degree 2, θ = 0.97, σ known, defaults (restart on misfit)");

    let mut c = main_config();
    c.misfit_response = MisfitResponse::Flag;
    score(&c, SHARP)
        .0
        .print("sharp manoeuvre, degree 2, θ = 0.97, σ known, flag only");
}
