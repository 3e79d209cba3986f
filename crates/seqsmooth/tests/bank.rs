//! The filter banks (`seqsmooth::polynomial::bank`) against the single-stream filters, parallel
//! against serial, bad input.

mod common;

use common::bank::*;
use seqsmooth::polynomial::bank::{ExpandingBank, FadingBank};

#[test]
fn fading_bank_matches_single_streams() {
    for k in [1, 7, 1000] {
        for m in 0..=4 {
            let steps = if k == 1000 { 150 } else { 400 };
            let rel = compare_fading(m, 0.9, 0.5, k, steps, m);
            let max = rel.iter().cloned().fold(0.0, f64::max);
            assert!(max < 1e-11, "K = {k}, m = {m}: {rel:?}");
        }
    }
}

#[test]
fn bank_matches_single_stream_over_long_run() {
    for m in 1..=4 {
        let rel = compare_fading(m, 0.95, 1.0, 2, 10_000, m);
        assert!(rel.iter().all(|r| *r < 1e-11), "m = {m}: {rel:?}");
    }
}

#[test]
fn expanding_bank_matches_single_streams() {
    for m in 0..=4 {
        let worst = compare_expanding(m);
        assert!(worst < 1e-10, "m = {m}: {worst}");
    }
}

#[test]
fn parallel_equals_serial_bit_for_bit() {
    let k = 100_003; // several rayon chunks and a ragged tail
    for m in [0, 2, 4] {
        let mut a = FadingBank::new(m, 0.97, 1.0, k).unwrap();
        let mut b = a.clone();
        let mut ea = ExpandingBank::new(m, 1.0, k).unwrap();
        let mut eb = ea.clone();
        let mut y = vec![0.0; k];
        for n in 0..80 {
            for (c, v) in y.iter_mut().enumerate() {
                *v = sample(c, n);
            }
            a.update(&y).unwrap();
            b.update_par(&y).unwrap();
            ea.update(&y).unwrap();
            eb.update_par(&y).unwrap();
        }
        for d in 0..=m {
            let (ra, rb) = (a.scaled_row(d).unwrap(), b.scaled_row(d).unwrap());
            assert!(ra.iter().zip(rb).all(|(x, y)| x.to_bits() == y.to_bits()));
            let (ra, rb) = (ea.scaled_row(d).unwrap(), eb.scaled_row(d).unwrap());
            assert!(ra.iter().zip(rb).all(|(x, y)| x.to_bits() == y.to_bits()));
        }
    }
}

#[test]
fn bad_input_is_rejected_and_leaves_state_unchanged() {
    let mut bank = FadingBank::new(2, 0.9, 1.0, 5).unwrap();
    bank.update(&[1.0, 2.0, 3.0, 4.0, 5.0]).unwrap();
    bank.update(&[1.5, 2.5, 3.5, 4.5, 5.5]).unwrap();
    bank.update(&[2.0, 3.0, 4.0, 5.0, 6.0]).unwrap();
    let before = bank.clone();
    let err = bank.update(&[1.0, 2.0]).unwrap_err();
    assert!(err.to_string().contains("input length 2"), "{err}");
    let err = bank.update(&[1.0, 2.0, f64::NAN, 4.0, 5.0]).unwrap_err();
    assert!(err.to_string().contains("channel 2"), "{err}");
    let err = bank
        .update_par(&[1.0, 2.0, 3.0, f64::INFINITY, 5.0])
        .unwrap_err();
    assert!(
        err.to_string().contains("channel 3") && err.to_string().contains("inf"),
        "{err}"
    );
    assert_eq!(bank.samples(), before.samples());
    for d in 0..=2 {
        assert_eq!(bank.scaled_row(d), before.scaled_row(d));
    }
    assert!(FadingBank::new(2, 1.0, 1.0, 5).is_err());
    assert!(FadingBank::new(2, 0.9, 0.0, 5).is_err());
    assert!(FadingBank::new(2, 0.9, 1.0, 0).is_err());
    assert!(ExpandingBank::new(99, 1.0, 5).is_err());
    let mut out = vec![0.0; 4];
    assert!(bank.derivative_into(1, &mut out).is_err());
    let mut out = vec![0.0; 5];
    assert!(bank.derivative_into(3, &mut out).is_err());
    bank.derivative_into(1, &mut out).unwrap();
    assert!((out[0] - 0.5).abs() < 1e-12); // slope 0.5 per step
    assert!(bank.estimate(5).is_none());
}

#[test]
fn update_rows_equals_row_by_row_updates() {
    let (k, steps) = (5, 120);
    let matrix: Vec<f64> = (0..steps)
        .flat_map(|n| (0..k).map(move |c| sample(c, n)))
        .collect();
    let mut a = FadingBank::new(2, 0.9, 1.0, k).unwrap();
    let mut b = a.clone();
    a.update_rows(&matrix).unwrap();
    for row in matrix.chunks(k) {
        b.update(row).unwrap();
    }
    assert_eq!(a.samples(), steps as u64);
    for d in 0..=2 {
        assert_eq!(a.scaled_row(d), b.scaled_row(d));
    }
    // A bad row: the rows before it count, the error names it.
    let mut bad = matrix[..3 * k].to_vec();
    bad[2 * k + 1] = f64::NAN;
    let mut c = ExpandingBank::new(1, 1.0, k).unwrap();
    let err = c.update_rows(&bad).unwrap_err();
    assert!(
        matches!(err, seqsmooth::Error::InBatch { index: 2, .. }),
        "{err}"
    );
    assert_eq!(c.samples(), 2);
    assert!(c.update_rows(&bad[..k + 1]).is_err());
    assert_eq!(c.samples(), 2);
}
