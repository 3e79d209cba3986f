//! `StreamBank`'s chunked multi-series update against each series' filter run alone: the
//! estimates of every row equal (bit for bit) those of a lone filter fed the series' rows, on
//! interleaved series, series that start late or pause, and chunks of 1, 3 and 64 rows, serial
//! and on rayon; errors name the first failing row and its channel.

use seqsmooth::polynomial::stream::{Chunk, StreamBank};
use seqsmooth::{Engine, Error, ExpandingMemory, FadingMemory, PolynomialFilter};

/// Rows `(channel, t, y)`: channel 0 throughout, channel 1 from row 40 on, channel 2 paused
/// between rows 30 and 90, channel 3 a single late burst; each on its own irregular grid.
fn rows() -> Vec<(usize, f64, f64)> {
    let mut next = [0.0f64; 4];
    let mut out = Vec::new();
    for k in 0..200usize {
        let mut live = vec![0];
        if k >= 40 {
            live.push(1);
        }
        if !(30..90).contains(&k) {
            live.push(2);
        }
        if (150..160).contains(&k) {
            live.push(3);
        }
        let c = live[(k * 7 + k / 3) % live.len()];
        next[c] += 0.5 + ((k * 13) % 7) as f64 / 10.0;
        let t = next[c];
        out.push((
            c,
            t,
            (c as f64 + 1.0) * t.sin() + 0.01 * ((k * 31) % 11) as f64,
        ));
    }
    out
}

/// Each row's d0..dm from the lone filter of its channel: `update` then `estimate`.
fn alone<F: PolynomialFilter + Clone>(proto: &F, rows: &[(usize, f64, f64)]) -> Vec<f64> {
    let w = proto.degree() + 1;
    let mut filters = vec![proto.clone(); 4];
    let mut out = vec![f64::NAN; rows.len() * w];
    for (i, &(c, t, y)) in rows.iter().enumerate() {
        filters[c].update(t, y).unwrap();
        if let Some(s) = filters[c].estimate() {
            out[i * w..(i + 1) * w].copy_from_slice(&s.derivatives);
        }
    }
    out
}

/// The bank's estimates, the rows fed in chunks of `chunk`, with the per-row closure or the
/// batch kernel, serially or on rayon.
fn banked<F: PolynomialFilter + Clone + Send>(
    proto: &F,
    rows: &[(usize, f64, f64)],
    chunk: usize,
    batch: bool,
    parallel: bool,
) -> Vec<f64> {
    let w = proto.degree() + 1;
    let mut bank = StreamBank::growing(proto.clone()).unwrap();
    let mut out = vec![0.0; rows.len() * w];
    for (piece, est) in rows.chunks(chunk).zip(out.chunks_mut(chunk * w)) {
        let ch: Vec<usize> = piece.iter().map(|r| r.0).collect();
        let t: Vec<f64> = piece.iter().map(|r| r.1).collect();
        let y: Vec<f64> = piece.iter().map(|r| r.2).collect();
        let run = move |f: &mut F, t: &[f64], y: &[f64], o: &mut [f64]| {
            if batch {
                return f.update_many_into(t, y, o);
            }
            for (index, ((&t, &y), o)) in t.iter().zip(y).zip(o.chunks_exact_mut(w)).enumerate() {
                f.update(t, y).map_err(|e| Error::InBatch {
                    index,
                    source: Box::new(e),
                })?;
                match f.estimate() {
                    Some(s) => o.copy_from_slice(&s.derivatives),
                    None => o.fill(f64::NAN),
                }
            }
            Ok(())
        };
        let chunk = Chunk {
            channels: &ch,
            times: &t,
            values: &y,
            estimates: est,
            stride: w,
        };
        if parallel {
            bank.update_par(chunk, run).unwrap();
        } else {
            bank.update(chunk, run).unwrap();
        }
    }
    assert_eq!(bank.channels(), 4);
    out
}

fn same(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

#[test]
fn chunked_bank_equals_each_series_alone() {
    let rows = rows();
    let expanding = ExpandingMemory::new(2, Engine::Exact).unwrap();
    let fading = FadingMemory::new(1, 0.9, 0.8, Engine::Exact).unwrap();
    let want_e = alone(&expanding, &rows);
    let want_f = alone(&fading, &rows);
    for chunk in [1, 3, 64] {
        for parallel in [false, true] {
            let got = banked(&expanding, &rows, chunk, false, parallel);
            assert!(
                same(&got, &want_e),
                "expanding, chunk {chunk}, parallel {parallel}"
            );
            let got = banked(&fading, &rows, chunk, false, parallel);
            assert!(
                same(&got, &want_f),
                "fading, chunk {chunk}, parallel {parallel}"
            );
        }
    }
}

/// The batch kernel through the bank equals the same kernel on each series' rows at once.
#[test]
fn chunked_bank_with_batch_kernel_equals_each_series_batch() {
    let rows = rows();
    let proto = FadingMemory::new(2, 0.85, 1.0, Engine::Gain).unwrap();
    let w = 3;
    let mut want = vec![0.0; rows.len() * w];
    for c in 0..4 {
        let idx: Vec<usize> = (0..rows.len()).filter(|&i| rows[i].0 == c).collect();
        let t: Vec<f64> = idx.iter().map(|&i| rows[i].1).collect();
        let y: Vec<f64> = idx.iter().map(|&i| rows[i].2).collect();
        let mut est = vec![0.0; idx.len() * w];
        proto.clone().update_many_into(&t, &y, &mut est).unwrap();
        for (k, &i) in idx.iter().enumerate() {
            want[i * w..(i + 1) * w].copy_from_slice(&est[k * w..(k + 1) * w]);
        }
    }
    // One chunk: each series is one batch, as above.
    let got = banked(&proto, &rows, rows.len(), true, true);
    assert!(same(&got, &want));
}

/// The first bad row in input order is reported with its channel; the rows before it, of
/// every channel, are done, and the channels that failed later are listed.
#[test]
fn errors_name_the_first_failing_row_and_channel() {
    let mut bank = StreamBank::growing(ExpandingMemory::new(0, Engine::Exact).unwrap()).unwrap();
    let ch = [0, 1, 0, 1, 2, 1, 0];
    let t = [0.0, 0.0, 1.0, 1.0, 0.0, 0.5, 0.5]; // row 5 (channel 1), row 6 (channel 0) go back
    let y = [1.0; 7];
    let mut est = [0.0; 7];
    let run =
        |f: &mut ExpandingMemory, t: &[f64], y: &[f64], o: &mut [f64]| f.update_many_into(t, y, o);
    for parallel in [false, true] {
        let mut b = bank.clone();
        let chunk = Chunk {
            channels: &ch,
            times: &t,
            values: &y,
            estimates: &mut est,
            stride: 1,
        };
        let e = if parallel {
            b.update_par(chunk, run)
        } else {
            b.update(chunk, run)
        };
        match e.unwrap_err() {
            Error::InChannel {
                channel,
                source,
                also_failed,
            } => {
                assert_eq!((channel, also_failed), (1, vec![0]));
                assert!(
                    matches!(*source, Error::InBatch { index: 5, .. }),
                    "{source:?}"
                );
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(est[..5], [1.0; 5]);
        assert_eq!(b.channel(2).unwrap().samples(), 1);
    }
    // Wrong lengths are refused before anything runs.
    assert!(bank
        .update(
            Chunk {
                channels: &ch,
                times: &t[..6],
                values: &y,
                estimates: &mut est,
                stride: 1
            },
            run
        )
        .is_err());
    assert_eq!(bank.channels(), 0);
}
