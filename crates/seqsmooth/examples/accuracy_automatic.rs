//! Prints the scores of the automatic filter on the manoeuvring-target scenarios: ±3σ
//! coverage, outlier detection, false alarms, misfit on straight segments and restarts. The
//! tests `tests/automatic_*.rs` assert bounds on the same scores (`tests/common/automatic.rs`,
//! which also describes the scenarios: 100 runs of 2200 samples, fixed seeds).
//!
//! Run: `cargo run --release -p seqsmooth --example accuracy_automatic`

#[path = "../tests/common/mod.rs"]
mod common;

use common::automatic::{main_defaults, main_filter, score, GENTLE, SHARP};
use seqsmooth::polynomial::automatic::{MisfitResponse, NoiseSource, OutlierRule};
use seqsmooth::{DiscountMode, Engine};

fn main() {
    let (s, _) = score(&main_filter(), GENTLE);
    s.print("gentle manoeuvre, degree 2, θ = 0.97, σ known, defaults");

    let c = main_filter()
        .with_engine(Engine::Gain)
        .unwrap()
        .with_discount_mode(DiscountMode::PerUpdate)
        .unwrap();
    score(&c, GENTLE)
        .0
        .print("gentle manoeuvre, degree 2, θ = 0.97 per update, gain engine");

    for source in [
        NoiseSource::Differences { window: None },
        NoiseSource::Innovations { window: None },
    ] {
        let c = main_defaults().with_noise_source(source).unwrap();
        score(&c, GENTLE).0.print(&format!(
            "gentle manoeuvre, degree 2, θ = 0.97, σ estimated by {source:?}"
        ));
    }

    let c = main_filter()
        .with_outlier_rule(OutlierRule::reyneke())
        .unwrap();
    score(&c, GENTLE)
        .0
        .print("gentle manoeuvre, degree 2, θ = 0.97, σ known, Reyneke gate k = 3");

    score(&main_filter(), SHARP)
        .0
        .print("sharp manoeuvre, degree 2, θ = 0.97, σ known, defaults (restart on misfit)");

    let c = main_filter()
        .with_misfit_response(MisfitResponse::Flag)
        .unwrap();
    score(&c, SHARP)
        .0
        .print("sharp manoeuvre, degree 2, θ = 0.97, σ known, flag only");
}
