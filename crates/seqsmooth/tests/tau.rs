//! `polynomial::tau`: the default `τ`, the median time step within series, one rule for
//! `seqsmooth filter` without `--tau` and Python's `filter_frame` without `tau` (their
//! agreement is tested in `seqsmooth-py/tests/test_frame.py`).

use seqsmooth::polynomial::tau::{default_tau, median_series_step, TAU_SCAN_ROWS, TAU_STEPS};

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

/// Only the first `TAU_STEPS` steps count: 100 steps of 1 then any number of 7 give 1; 49 of 1
/// and 51 of 7 give 7; 50 and 50 the mean of the middle two, whatever follows.
#[test]
fn the_first_steps_decide() {
    let times = |steps: &[(usize, f64)]| {
        let mut t = vec![0.0];
        for &(n, s) in steps {
            for _ in 0..n {
                t.push(t.last().unwrap() + s);
            }
        }
        t
    };
    let one = |t: &[f64]| default_tau(t, &vec![0; t.len()], true).unwrap();
    assert_eq!(one(&times(&[(TAU_STEPS, 1.0), (500, 7.0)])), 1.0);
    assert_eq!(one(&times(&[(49, 1.0), (51, 7.0)])), 7.0);
    assert_eq!(one(&times(&[(50, 1.0), (50, 7.0), (9, 1.0)])), 4.0);
}

/// Rows beyond `TAU_SCAN_ROWS` are not scanned: a first series of single rows that fills the
/// scan leaves no step (an error, the input goes on), and all the rows being single gives 1.
#[test]
fn scan_limit_and_single_rows() {
    let n = TAU_SCAN_ROWS + 10;
    let t: Vec<f64> = (0..n).map(|i| i as f64).collect();
    let series: Vec<usize> = (0..n).collect();
    assert!(default_tau(&t, &series, true)
        .unwrap_err()
        .to_string()
        .contains("give tau"));
    let mut two = series.clone();
    two[n - 1] = n - 2; // a step, but beyond the scan
    assert!(default_tau(&t, &two, true).is_err());
    assert_eq!(default_tau(&t[..5], &series[..5], true).unwrap(), 1.0);
    assert!(default_tau(&t[..5], &series[..5], false).is_err());
    // Repeated times: a median step of 0 is no interval.
    assert!(default_tau(&[0.0, 0.0, 0.0, 0.0], &[0, 1, 0, 1], true).is_err());
}
