//! Unit tests of `filter`: the median time step that sets the default tau.

use seqsmooth_cli::filter::*;

#[test]
fn median_of_steps() {
    let step = |t: &[f64]| median_series_step(t, &vec![0; t.len()]).unwrap_or(1.0);
    assert_eq!(step(&[0.0]), 1.0);
    assert_eq!(step(&[0.0, 2.0]), 2.0);
    assert_eq!(step(&[0.0, 1.0, 3.0, 3.5]), 1.0); // steps 1, 2, 0.5
    assert_eq!(step(&[0.0, 1.0, 3.0, 3.5, 7.5]), 1.5); // steps 0.5, 1, 2, 4
                                                       // Within series: a 0, 1; b 10, 13 → steps 1, 3.
    assert_eq!(
        median_series_step(&[0.0, 10.0, 1.0, 13.0], &[0, 1, 0, 1]),
        Some(2.0)
    );
}
