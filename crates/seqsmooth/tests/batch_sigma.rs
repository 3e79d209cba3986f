//! The batch σ path (`PolynomialFilter::update_many_sigma_into`): each row's derivatives and
//! 1σ equal those of `update` + `try_estimate_at` on the same samples (the covariance of the
//! Joseph recursion, Morrison (12.2.x), kept without a matrix per sample; its steady state held
//! by the plain kernels), for every engine, even and irregular steps and gaps; and its refusals.

use seqsmooth::FixedEngine;
use seqsmooth::{Engine, Error, ExpandingMemory, FadingMemory, FixedMemory, PolynomialFilter};

/// Times with even stretches, jitter and a gap (the steady covariance is left and re-found).
fn samples(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut t = 1.7e9;
    let (mut ts, mut ys) = (Vec::new(), Vec::new());
    for k in 0..n {
        ts.push(t);
        ys.push(3.0 + 0.2 * (t - 1.7e9) + ((k * 7919) % 13) as f64 * 0.1);
        t += match k {
            k if (900..910).contains(&k) => 0.25 + 0.01 * (k % 3) as f64,
            1500 => 7.0,
            _ => 0.25,
        };
    }
    (ts, ys)
}

fn filters() -> Vec<(&'static str, Box<dyn PolynomialFilter>)> {
    let mut out: Vec<(&'static str, Box<dyn PolynomialFilter>)> = Vec::new();
    for m in [0, 1, 2, 4] {
        for engine in [Engine::Gain, Engine::Exact] {
            out.push((
                "fading",
                Box::new(
                    FadingMemory::new(m, 0.9, 0.25, engine)
                        .unwrap()
                        .with_noise_sigma(0.3)
                        .unwrap(),
                ),
            ));
            out.push((
                "expanding",
                Box::new(
                    ExpandingMemory::new(m, engine)
                        .unwrap()
                        .with_noise_sigma(0.3)
                        .unwrap(),
                ),
            ));
        }
        out.push((
            "fixed",
            Box::new(
                FixedMemory::new(m, 31, FixedEngine::Adaptive)
                    .unwrap()
                    .with_noise_sigma(0.3)
                    .unwrap(),
            ),
        ));
    }
    out
}

/// Row by row against `update` + `try_estimate_at`: derivatives and 1σ to 1e-9 relative (the
/// kernels and the per-sample recursion round differently; the covariance's steady state is
/// kept to 4ε per update), NaN rows exactly where there is no estimate.
#[test]
fn batch_sigma_equals_per_sample_estimates() {
    let (t, y) = samples(3000);
    for ((name, mut batch), (_, mut single)) in filters().into_iter().zip(filters()) {
        let w = batch.degree() + 1;
        let mut rows = vec![0.0; t.len() * 2 * w];
        // Two calls: the state carries over.
        let half = 1200 * 2 * w;
        batch
            .update_many_sigma_into(&t[..1200], &y[..1200], &mut rows[..half])
            .unwrap();
        batch
            .update_many_sigma_into(&t[1200..], &y[1200..], &mut rows[half..])
            .unwrap();
        for (i, row) in rows.chunks_exact(2 * w).enumerate() {
            single.update(t[i], y[i]).unwrap();
            match single.try_estimate_at(t[i]) {
                Err(Error::TooFewSamples { .. }) => {
                    assert!(row.iter().all(|v| v.is_nan()), "{name} m {} row {i}", w - 1);
                }
                Ok(s) => {
                    let sd = s.std_devs().unwrap();
                    for k in 0..w {
                        let (d, want) = (row[k], s.derivatives[k]);
                        let scale = want.abs().max(sd[k]);
                        assert!(
                            (d - want).abs() <= 1e-9 * scale,
                            "{name} m {} row {i} d{k}: {d} vs {want}",
                            w - 1
                        );
                        assert!(
                            (row[w + k] - sd[k]).abs() <= 1e-9 * sd[k],
                            "{name} m {} row {i} s{k}: {} vs {}",
                            w - 1,
                            row[w + k],
                            sd[k]
                        );
                    }
                }
                Err(e) => panic!("{name}: {e}"),
            }
        }
    }
}

/// Without a noise σ the first determined sample is the error, the samples up to it taken; a
/// bad sample is named by its index; rows of the wrong length are refused.
#[test]
fn batch_sigma_refusals() {
    let mut f = FadingMemory::new(2, 0.9, 1.0, Engine::Gain).unwrap();
    let t: Vec<f64> = (0..10).map(f64::from).collect();
    let mut rows = vec![0.0; 10 * 6];
    let e = f.update_many_sigma_into(&t, &t, &mut rows).unwrap_err();
    assert!(matches!(e, Error::InBatch { index: 2, .. }), "{e}");
    assert!(e.to_string().contains("sigma"), "{e}");
    assert_eq!(f.samples(), 3);
    let mut f = ExpandingMemory::new(1, Engine::Exact)
        .unwrap()
        .with_noise_sigma(1.0)
        .unwrap();
    let y = [1.0, 2.0, f64::NAN, 4.0];
    let mut rows = vec![0.0; 4 * 4];
    let e = f
        .update_many_sigma_into(&t[..4], &y, &mut rows)
        .unwrap_err();
    assert!(matches!(e, Error::InBatch { index: 2, .. }), "{e}");
    assert!(f
        .update_many_sigma_into(&t[..4], &y, &mut rows[..15])
        .is_err());
}
