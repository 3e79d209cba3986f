//! `StreamBank` (channels with their own timestamps) against lone filters.

mod common;

use common::bank::*;
use seqsmooth::{Engine, ExpandingMemory, FadingMemory, PolynomialFilter};

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

/// `update_par_columns` writes `update_par`'s results transposed, bit for bit: 37 interleaved
/// fading series (one row of the chunk from a lone series too), and a chunk of one series.
#[test]
fn columns_are_the_rows_transposed() {
    use seqsmooth::polynomial::stream::{Chunk, StreamBank};
    use seqsmooth::{Engine, FadingMemory, PolynomialFilter};
    for series in [37usize, 1] {
        let n = 2_000;
        let channels: Vec<usize> = (0..n).map(|i| (i * 7 + i / 13) % series).collect();
        let times: Vec<f64> = (0..n).map(|i| 1.7e9 + i as f64 * 0.5).collect();
        let values: Vec<f64> = (0..n).map(|i| ((i * i) % 17) as f64 - 8.0).collect();
        let stride = 3;
        let run = |columns: bool| {
            let f = FadingMemory::new(2, 0.9, 1.0, Engine::Exact).unwrap();
            let mut bank = StreamBank::growing(f).unwrap();
            let mut est = vec![0.0; n * stride];
            let chunk = Chunk {
                channels: &channels,
                times: &times,
                values: &values,
                estimates: &mut est,
                stride,
            };
            let each = |f: &mut FadingMemory, t: &[f64], y: &[f64], out: &mut [f64]| {
                f.update_many_into(t, y, out)
            };
            if columns {
                bank.update_par_columns(chunk, each).unwrap();
            } else {
                bank.update_par(chunk, each).unwrap();
            }
            est
        };
        let (rows, columns) = (run(false), run(true));
        for i in 0..n {
            for k in 0..stride {
                let (a, b) = (rows[i * stride + k], columns[k * n + i]);
                assert!(
                    a.to_bits() == b.to_bits(),
                    "series {series}, row {i}, result {k}"
                );
            }
        }
        assert!(rows[(n - 1) * stride].is_finite());
    }
}
