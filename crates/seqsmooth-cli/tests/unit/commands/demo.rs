//! Unit tests of `commands::demo`: the built-in track and the plot paths.

use seqsmooth_cli::commands::demo::*;
use std::path::Path;

/// The track is what the module docs say: 400 samples, increasing times, jittered steps,
/// the outage, outliers; the truth is continuous through the turn.
#[test]
fn the_track_is_as_documented() {
    let data = generate();
    assert_eq!(data.len(), SAMPLES);
    assert!(data.windows(2).all(|w| w[1].t > w[0].t));
    assert!(!data
        .iter()
        .any(|p| p.t >= OUTAGE.0 && p.t < OUTAGE.0 + OUTAGE.1));
    let outliers = data.iter().filter(|p| p.outlier).count();
    assert!((3..=20).contains(&outliers), "{outliers}");
    for p in &data {
        let e = (p.y - p.x).abs() / SIGMA;
        if p.outlier {
            assert!(e > OUTLIER_SIZE.0 - 5.0, "{p:?}");
        } else {
            assert!(e < 5.0, "{p:?}");
        }
    }
    for t in [TURN_START, turn_end()] {
        let (a, b) = (truth(t - 1e-9), truth(t + 1e-9));
        assert!((a.0 - b.0).abs() < 1e-5 && (a.1 - b.1).abs() < 1e-5);
    }
    // the velocity is the derivative of the position
    for t in [50.0, 150.0, 170.0, 199.0, 300.0] {
        let h = 1e-4;
        let num = (truth(t + h).0 - truth(t - h).0) / (2.0 * h);
        assert!((num - truth(t).1).abs() < 1e-4, "t = {t}");
    }
    assert_eq!(generate()[123].y, data[123].y, "deterministic");
}

#[test]
fn plot_paths_append_the_extensions() {
    let [a, b] = plot_paths(Path::new("out/run"));
    assert_eq!(
        (a.to_str(), b.to_str()),
        (Some("out/run.png"), Some("out/run.svg"))
    );
    let [a, b] = plot_paths(Path::new("x.svg"));
    assert_eq!((a.to_str(), b.to_str()), (Some("x.png"), Some("x.svg")));
    let [a, _] = plot_paths(Path::new("v1.2"));
    assert_eq!(a.to_str(), Some("v1.2.png"));
}
