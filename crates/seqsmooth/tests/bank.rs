//! The filter banks against the single-stream filters, parallel against serial, bad input.

use seqsmooth::polynomial::bank::{ExpandingBank, FadingBank};
use seqsmooth::{Engine, ExpandingMemory, FadingMemory, PolynomialFilter};

/// Deterministic data for channel `c` at step `n`: a slow sine of channel-dependent phase and
/// size, a trend, and a cheap pseudo-random term of unit size.
fn sample(c: usize, n: usize) -> f64 {
    let mut s = (c as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (n as u64).wrapping_mul(0xD1B5_4A32_D192_ED03);
    s ^= s >> 29;
    s = s.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    s ^= s >> 32;
    let noise = (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
    let t = n as f64;
    (1.0 + c as f64 % 5.0) * (0.01 * t + c as f64).sin() + 0.001 * t + noise
}

/// Largest difference per derivative, relative to the largest `|x^(k)|` of the single stream
/// over the run, from step `from` on.
fn compare_fading(m: usize, theta: f64, tau: f64, k: usize, steps: usize, from: usize) -> Vec<f64> {
    let mut bank = FadingBank::new(m, theta, tau, k).unwrap();
    let mut singles: Vec<_> = (0..k)
        .map(|_| FadingMemory::new(m, theta, tau, Engine::Gain).unwrap())
        .collect();
    let mut worst = vec![0.0f64; m + 1];
    let mut scale = vec![0.0f64; m + 1];
    let mut y = vec![0.0; k];
    for n in 0..steps {
        for (c, v) in y.iter_mut().enumerate() {
            *v = sample(c, n);
        }
        bank.update(&y).unwrap();
        for (c, f) in singles.iter_mut().enumerate() {
            f.update(n as f64 * tau, y[c]).unwrap();
            if n >= m {
                let want = f.estimate().unwrap().derivatives;
                let got = bank.estimate(c).unwrap();
                for d in 0..=m {
                    scale[d] = scale[d].max(want[d].abs());
                    if n >= from {
                        worst[d] = worst[d].max((got[d] - want[d]).abs());
                    }
                }
            } else {
                assert!(bank.estimate(c).is_none());
            }
        }
    }
    worst.iter().zip(&scale).map(|(w, s)| w / s).collect()
}

#[test]
fn fading_bank_matches_single_streams() {
    for k in [1, 7, 1000] {
        for m in 0..=4 {
            let steps = if k == 1000 { 150 } else { 400 };
            let rel = compare_fading(m, 0.9, 0.5, k, steps, m);
            let max = rel.iter().cloned().fold(0.0, f64::max);
            eprintln!("K = {k}, m = {m}: max relative difference {max:.2e} {rel:?}");
            assert!(max < 1e-11, "K = {k}, m = {m}: {rel:?}");
        }
    }
}

#[test]
fn bank_matches_single_stream_over_long_run() {
    for m in 1..=4 {
        let rel = compare_fading(m, 0.95, 1.0, 2, 10_000, m);
        eprintln!("m = {m}, 1e4 steps: {rel:?}");
        assert!(rel.iter().all(|r| *r < 1e-11), "m = {m}: {rel:?}");
    }
}

#[test]
fn expanding_bank_matches_single_streams() {
    for m in 0..=4 {
        let k = 7;
        let mut bank = ExpandingBank::new(m, 1.0, k).unwrap();
        let mut singles: Vec<_> = (0..k)
            .map(|_| ExpandingMemory::new(m, Engine::Gain).unwrap())
            .collect();
        let mut y = vec![0.0; k];
        let mut worst = 0.0f64;
        for n in 0..300 {
            for (c, v) in y.iter_mut().enumerate() {
                *v = sample(c, n);
            }
            bank.update(&y).unwrap();
            for (c, f) in singles.iter_mut().enumerate() {
                f.update(n as f64, y[c]).unwrap();
                if n >= m {
                    let want = f.estimate().unwrap().derivatives;
                    let got = bank.estimate(c).unwrap();
                    for d in 0..=m {
                        worst = worst.max((got[d] - want[d]).abs() / want[0].abs().max(1.0));
                    }
                }
            }
        }
        eprintln!("expanding m = {m}: {worst:.2e}");
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

/// Channels with their own timestamps: each channel equals a lone filter fed the same data,
/// serial equals parallel, and a bad channel is reported while the others are processed.
#[test]
fn stream_bank_channels_equal_lone_filters() {
    use seqsmooth::polynomial::bank::StreamBank;
    use seqsmooth::Error;
    let k = 9;
    // Channel c: its own irregular grid and length.
    let data: Vec<(Vec<f64>, Vec<f64>)> = (0..k)
        .map(|c| {
            let len = 50 + 37 * c;
            let t: Vec<f64> = (0..len)
                .map(|n| {
                    0.3 * c as f64 + n as f64 * (0.5 + 0.1 * c as f64) + 0.01 * (n as f64).sin()
                })
                .collect();
            let y: Vec<f64> = (0..len).map(|n| sample(c, n)).collect();
            (t, y)
        })
        .collect();
    let batches: Vec<(&[f64], &[f64])> = data
        .iter()
        .map(|(t, y)| (t.as_slice(), y.as_slice()))
        .collect();
    for engine in [Engine::Exact, Engine::Gain] {
        let proto = FadingMemory::new(2, 0.9, 0.5, engine).unwrap();
        let mut serial = StreamBank::new(proto.clone(), k).unwrap();
        let mut parallel = serial.clone();
        serial.update_all(&batches).unwrap();
        parallel.update_all_par(&batches).unwrap();
        for (c, (t, y)) in data.iter().enumerate() {
            let mut lone = proto.clone();
            for (ti, yi) in t.iter().zip(y) {
                lone.update(*ti, *yi).unwrap();
            }
            let want = lone.estimate().unwrap().derivatives;
            let s = serial.channel(c).unwrap().estimate().unwrap().derivatives;
            let p = parallel.channel(c).unwrap().estimate().unwrap().derivatives;
            assert_eq!(s, p, "channel {c}: serial and parallel differ");
            for (a, b) in want.iter().zip(&s) {
                assert!(
                    (a - b).abs() <= 1e-11 * a.abs().max(1.0),
                    "{engine:?} channel {c}: {want:?} {s:?}"
                );
            }
        }
    }
    // Bad input in channels 2 and 5: both stop there, the others are processed.
    let mut bad = data.clone();
    bad[2].1[10] = f64::INFINITY;
    bad[5].0[3] = bad[5].0[2];
    let batches: Vec<(&[f64], &[f64])> = bad
        .iter()
        .map(|(t, y)| (t.as_slice(), y.as_slice()))
        .collect();
    let mut bank = StreamBank::new(ExpandingMemory::new(1, Engine::Exact).unwrap(), k).unwrap();
    let err = bank.update_all_par(&batches).unwrap_err();
    match &err {
        Error::InChannel {
            channel: 2,
            source,
            also_failed,
        } => {
            assert!(
                matches!(**source, Error::InBatch { index: 10, .. }),
                "{err}"
            );
            assert_eq!(also_failed, &vec![5]);
        }
        other => panic!("{other}"),
    }
    assert!(
        err.to_string().contains("channel 2") && err.to_string().contains("[5]"),
        "{err}"
    );
    assert_eq!(bank.channel(2).unwrap().samples(), 10);
    assert_eq!(bank.channel(5).unwrap().samples(), 3);
    assert_eq!(bank.channel(8).unwrap().samples(), data[8].0.len() as u64);
    // Wrong number of batches; a used prototype; no channels.
    assert!(bank.update_all(&batches[..3]).is_err());
    let mut used = ExpandingMemory::new(1, Engine::Exact).unwrap();
    used.update(0.0, 1.0).unwrap();
    assert!(StreamBank::new(used, 3).is_err());
    assert!(StreamBank::new(ExpandingMemory::new(1, Engine::Exact).unwrap(), 0).is_err());
    assert!(bank.update_channel(k, &[1e9], &[0.0]).is_err());
}
