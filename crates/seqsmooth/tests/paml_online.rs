//! `paml::SmootherGains` / `OnlineSmoother`: the segment's least-squares fit accumulated one
//! sample at a time. `PolynomialSamples::from_segment` runs on it (and is checked against a
//! direct QR fit in tests/paml_samples.rs); here, that the samples pushed one at a time, in
//! parts or all at once give those numbers, for `N` to 10⁵ and degrees to 8 on irregular
//! Unix-epoch times with varying noise — where the paper's recursion (eq. 35) drifts
//! (examples/accuracy_paml_online.rs); one layout serves many segments; the refusals.

mod common;

use common::paml::direct_fit;
use seqsmooth::paml::{PolynomialSamples, SmootherGains};
use seqsmooth::Error;

fn layout(count: usize) -> (Vec<f64>, Vec<f64>) {
    let mut t = Vec::with_capacity(count);
    let mut now = 1.7e9;
    for j in 0..count {
        now += 4e-4 * (0.5 + ((j * 7919) % 89) as f64 / 89.0);
        t.push(now);
    }
    let sigma = (0..count).map(|j| 0.5 + ((j * 37) % 11) as f64).collect();
    (t, sigma)
}

#[test]
fn online_equals_the_batch_polynomial_samples() {
    for (count, n) in [
        (20usize, 3usize),
        (1_000, 5),
        (1_000, 8),
        (10_000, 5),
        (100_000, 5),
    ] {
        let (t, sigma) = layout(count);
        let t0 = t[0];
        let y: Vec<f64> = t
            .iter()
            .enumerate()
            .map(|(j, &s)| 40.0 * (50.0 * (s - t0)).sin() + ((j * 13) % 7) as f64 - 3.0)
            .collect();
        let gains = SmootherGains::new(&t, &sigma, n).unwrap();
        assert_eq!(gains.len(), count);
        let mut online = gains.smoother();
        for &v in &y {
            online.push(v).unwrap();
        }
        let got = online.polynomial_samples().unwrap();
        let want = PolynomialSamples::from_segment(&t, &y, &sigma, n).unwrap();
        assert_eq!(
            (got.centre, &got.offsets, &got.variances),
            (want.centre, &want.offsets, &want.variances)
        );
        for (k, (a, b)) in got.values.iter().zip(&want.values).enumerate() {
            let sd = want.variances[k].sqrt();
            assert!(
                (a - b).abs() <= 1e-12 * b.abs().max(sd),
                "N {count} n {n} k {k}: {a} {b}"
            );
        }
        // all at once is the same, bit for bit
        let mut all = gains.smoother();
        all.push_all(&y[..count / 3]).unwrap();
        all.push_all(&y[count / 3..]).unwrap();
        assert_eq!(all.polynomial_samples().unwrap(), got);
    }
}

/// One layout (stationary timing), many segments: each segment's own fit, as a direct QR
/// fit gives it (to 1e-9 of each sample's σ).
#[test]
fn one_layout_serves_every_segment() {
    let (t, sigma) = layout(500);
    let gains = SmootherGains::new(&t, &sigma, 4).unwrap();
    for segment in 0..5 {
        let y: Vec<f64> = t
            .iter()
            .map(|s| (segment as f64 + 1.0) * ((s - t[0]) * 20.0).cos())
            .collect();
        let mut s = gains.smoother();
        s.push_all(&y).unwrap();
        let got = s.polynomial_samples().unwrap();
        // against the direct QR fit of this segment (an independent oracle)
        let (want, cov) = direct_fit(&t, &y, &sigma, 4, &got.offsets);
        for k in 0..5 {
            let sd = cov[(k, k)].sqrt();
            assert!(
                (got.values[k] - want[k]).abs() <= 1e-9 * sd,
                "segment {segment} k {k}"
            );
            assert!((got.variances[k] / cov[(k, k)] - 1.0).abs() <= 1e-9);
        }
    }
}

#[test]
fn bad_layouts_and_samples_are_refused() {
    let (t, sigma) = layout(10);
    let gains = SmootherGains::new(&t, &sigma, 2).unwrap();
    let mut s = gains.smoother();
    assert!(matches!(s.push(f64::NAN), Err(Error::NonFinite { .. })));
    assert_eq!(s.taken(), 0);
    assert!(matches!(
        s.polynomial_samples(),
        Err(Error::TooFewSamples { needed: 10, got: 0 })
    ));
    s.push_all(&[1.0; 10]).unwrap();
    assert!(s.push(1.0).is_err());
    assert!(s.push_all(&[1.0]).is_err());
    let mut s = gains.smoother();
    assert!(s.push_all(&[1.0, f64::INFINITY]).is_err());
    assert_eq!(s.taken(), 0);
    // layouts
    let mut back = t.clone();
    back.swap(3, 4);
    assert!(matches!(
        SmootherGains::new(&back, &sigma, 2),
        Err(Error::InBatch { index: 4, .. })
    ));
    let mut bad = sigma.clone();
    bad[5] = 0.0;
    assert!(SmootherGains::new(&t, &bad, 2)
        .unwrap_err()
        .to_string()
        .contains("sample 5"));
    assert!(matches!(
        SmootherGains::new(&t[..2], &sigma[..2], 2),
        Err(Error::TooFewSamples { .. })
    ));
    assert!(SmootherGains::new(&t, &sigma[..9], 2).is_err());
}
