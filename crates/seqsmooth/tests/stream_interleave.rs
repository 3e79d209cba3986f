//! Property (proptest, fixed seed): a [`StreamBank`] — the engine of `seqsmooth filter
//! --id-col` — is invariant under the interleaving of its series' rows and under where the
//! chunks are cut: each series' rows equal, bit for bit, that series filtered alone in one
//! batch. Every kind and engine the command runs (expanding and fading memory, exact and gain;
//! fixed memory, adaptive; the automatic filter), degrees 0-6, irregular times on each
//! series' own grid, serial and parallel banks, with the batch kernel
//! ([`PolynomialFilter::update_many_into`]) and with per-row updates and estimates.

use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};
use seqsmooth::polynomial::stream::{Chunk, StreamBank};
use seqsmooth::polynomial::AutomaticFilter;
use seqsmooth::{Engine, Error, ExpandingMemory, FadingMemory, FixedEngine, FixedMemory};
use seqsmooth::{PolynomialFilter, PolynomialState};

/// A filter of any kind the command runs (a few per case: their sizes do not matter).
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
enum Any {
    Expanding(ExpandingMemory),
    Fading(FadingMemory),
    Fixed(FixedMemory),
    Auto(AutomaticFilter),
}

impl Any {
    fn inner(&self) -> &dyn PolynomialFilter {
        match self {
            Any::Expanding(f) => f,
            Any::Fading(f) => f,
            Any::Fixed(f) => f,
            Any::Auto(f) => f,
        }
    }
    fn inner_mut(&mut self) -> &mut dyn PolynomialFilter {
        match self {
            Any::Expanding(f) => f,
            Any::Fading(f) => f,
            Any::Fixed(f) => f,
            Any::Auto(f) => f,
        }
    }
}

impl PolynomialFilter for Any {
    fn degree(&self) -> usize {
        self.inner().degree()
    }
    fn samples(&self) -> u64 {
        self.inner().samples()
    }
    fn update(&mut self, t: f64, y: f64) -> Result<(), Error> {
        self.inner_mut().update(t, y)
    }
    fn estimate_at(&self, t: f64) -> Option<PolynomialState> {
        self.inner().estimate_at(t)
    }
    fn try_estimate_at(&self, t: f64) -> Result<PolynomialState, Error> {
        self.inner().try_estimate_at(t)
    }
    fn last_time(&self) -> Option<f64> {
        self.inner().last_time()
    }
    fn update_many_into(&mut self, t: &[f64], y: &[f64], out: &mut [f64]) -> Result<(), Error> {
        self.inner_mut().update_many_into(t, y, out)
    }
}

/// The filter `kind` (0-5) of degree `m`, noise σ = 1 for its covariance.
fn filter(kind: u8, m: usize) -> Any {
    let engine = |k: u8| {
        if k.is_multiple_of(2) {
            Engine::Exact
        } else {
            Engine::Gain
        }
    };
    let built = match kind {
        0 | 1 => ExpandingMemory::new(m, engine(kind))
            .and_then(|f| f.with_noise_sigma(1.0))
            .map(Any::Expanding),
        2 | 3 => FadingMemory::new(m, 0.9, 0.5, engine(kind))
            .and_then(|f| f.with_noise_sigma(1.0))
            .map(Any::Fading),
        4 => FixedMemory::new(m, m + 4, FixedEngine::Adaptive)
            .and_then(|f| f.with_noise_sigma(1.0))
            .map(Any::Fixed),
        _ => AutomaticFilter::new(m, 0.9, 0.5).map(Any::Auto),
    };
    built.expect("valid settings")
}

/// Per row: the estimate at the row's time and its 1σ (NaN when undetermined), `2(m+1)`
/// values, from one update at a time (as the command with `--sigma` or `--lead`).
fn per_row(f: &mut Any, t: &[f64], y: &[f64], out: &mut [f64]) -> Result<(), Error> {
    let w = 2 * (f.degree() + 1);
    for (i, ((&t, &y), row)) in t.iter().zip(y).zip(out.chunks_exact_mut(w)).enumerate() {
        f.update(t, y).map_err(|e| Error::InBatch {
            index: i,
            source: Box::new(e),
        })?;
        row.fill(f64::NAN);
        if let Some(s) = f.estimate_at(t) {
            let n = s.derivatives.len();
            row[..n].copy_from_slice(&s.derivatives);
            if let Some(sd) = s.std_devs() {
                row[w / 2..w / 2 + sd.len()].copy_from_slice(&sd);
            }
        }
    }
    Ok(())
}

/// The batch kernel, `m+1` values per row.
fn batch(f: &mut Any, t: &[f64], y: &[f64], out: &mut [f64]) -> Result<(), Error> {
    f.update_many_into(t, y, out)
}

type Run = fn(&mut Any, &[f64], &[f64], &mut [f64]) -> Result<(), Error>;

/// One series: irregular increasing times from `t0`, values a cubic plus noise.
fn series(t0: f64, steps: &[f64], noise: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let mut t = t0;
    let times: Vec<f64> = steps
        .iter()
        .map(|s| {
            t += s;
            t
        })
        .collect();
    let values = times
        .iter()
        .zip(noise)
        .map(|(&t, e)| {
            let u = t - t0;
            1.0 + u * (0.5 - u * (0.02 + 0.001 * u)) + e
        })
        .collect();
    (times, values)
}

fn config() -> Config {
    Config {
        cases: 192,
        rng_seed: RngSeed::Fixed(20_261_202),
        failure_persistence: None,
        ..Config::default()
    }
}

/// The steps and noise of up to 4 series of 1-40 rows each.
fn all_series() -> impl Strategy<Value = Vec<(f64, Vec<f64>, Vec<f64>)>> {
    let one = (1usize..40).prop_flat_map(|n| {
        (
            -1e3..1e3f64,
            prop::collection::vec(0.05..2.0f64, n),
            prop::collection::vec(-0.1..0.1f64, n),
        )
    });
    prop::collection::vec(one, 1..5)
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn each_series_in_a_bank_equals_it_alone(
        kind in 0u8..6,
        m in 0usize..7,
        specs in all_series(),
        picks in prop::collection::vec(any::<u32>(), 160),
        cuts in prop::collection::vec(1usize..64, 1..6),
        parallel in any::<bool>(),
        rows_one_by_one in any::<bool>(),
    ) {
        let prototype = filter(kind, m);
        let (run, stride): (Run, usize) = if rows_one_by_one {
            (per_row, 2 * (m + 1))
        } else {
            (batch, m + 1)
        };
        let data: Vec<(Vec<f64>, Vec<f64>)> =
            specs.iter().map(|(t0, s, e)| series(*t0, s, e)).collect();
        // Interleave: each row takes the next row of the series a pick names (among those left).
        let mut next = vec![0; data.len()];
        let mut order = Vec::new();
        let total: usize = data.iter().map(|d| d.0.len()).sum();
        for k in 0..total {
            let left: Vec<usize> = (0..data.len()).filter(|&c| next[c] < data[c].0.len()).collect();
            let c = left[picks[k % picks.len()] as usize % left.len()];
            order.push((c, next[c]));
            next[c] += 1;
        }
        let channels: Vec<usize> = order.iter().map(|&(c, _)| c).collect();
        let times: Vec<f64> = order.iter().map(|&(c, i)| data[c].0[i]).collect();
        let values: Vec<f64> = order.iter().map(|&(c, i)| data[c].1[i]).collect();
        // The bank, over chunks cut at the given lengths (cycled).
        let mut bank = StreamBank::growing(prototype.clone()).unwrap();
        let mut out = vec![0.0; total * stride];
        let (mut start, mut k) = (0, 0);
        while start < total {
            let end = (start + cuts[k % cuts.len()]).min(total);
            k += 1;
            let chunk = Chunk {
                channels: &channels[start..end],
                times: &times[start..end],
                values: &values[start..end],
                estimates: &mut out[start * stride..end * stride],
                stride,
            };
            if parallel {
                bank.update_par(chunk, run).unwrap();
            } else {
                bank.update(chunk, run).unwrap();
            }
            start = end;
        }
        for (c, (t, y)) in data.iter().enumerate() {
            let mut alone = prototype.clone();
            let mut expected = vec![0.0; t.len() * stride];
            run(&mut alone, t, y, &mut expected).unwrap();
            let got: Vec<u64> = order
                .iter()
                .enumerate()
                .filter(|(_, &(s, _))| s == c)
                .flat_map(|(row, _)| out[row * stride..(row + 1) * stride].iter().map(|v| v.to_bits()))
                .collect();
            let expected: Vec<u64> = expected.iter().map(|v| v.to_bits()).collect();
            prop_assert_eq!(got, expected, "series {} (kind {}, degree {})", c, kind, m);
        }
    }
}
