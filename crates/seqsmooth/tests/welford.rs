//! `seqsmooth::stats::welford`: the running mean and variance against a two-pass computation,
//! and merging.

mod common;

use common::stats::*;
use seqsmooth::stats::Welford;

#[test]
fn welford_matches_two_pass_and_merges() {
    let mut r = rng(1);
    let x: Vec<f64> = (0..1000).map(|_| 1e6 + 3.0 * gauss(&mut r)).collect();
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (x.len() - 1) as f64;
    let mut w = Welford::new();
    let (mut a, mut b) = (Welford::new(), Welford::new());
    for (k, v) in x.iter().enumerate() {
        w.push(*v).unwrap();
        if k < 333 {
            a.push(*v).unwrap()
        } else {
            b.push(*v).unwrap()
        }
    }
    assert!((w.mean().unwrap() - mean).abs() < 1e-9);
    assert!((w.sample_variance().unwrap() - var).abs() < 1e-9 * var);
    a.merge(&b);
    assert_eq!(a.count(), 1000);
    assert!((a.sample_variance().unwrap() - var).abs() < 1e-9 * var);
    assert!((w.population_variance().unwrap() - var * 999.0 / 1000.0).abs() < 1e-9);
    let mut e = Welford::new();
    assert!(e.mean().is_none() && e.sample_variance().is_none());
    assert!(e.push(f64::NAN).is_err());
    assert_eq!(e.count(), 0);
}
