//! Every filter's `update`, `update_many` and `update_many_into` on arbitrary times, values
//! and parameters: `FixedMemory` (every engine), `ExpandingMemory` and `FadingMemory` (the
//! exact and gain engines), `AutomaticFilter`, and `StreamBank` of any of them; degrees
//! `0..=MAX_DEGREE` (and one above, refused).
//!
//! Checks: a construction, sample or batch is accepted or refused with a typed error; a
//! refused sample (not finite, time not after the previous) is refused; every estimate (and
//! its covariance) is finite once determined; `update_many_into` rows are finite from the
//! sample that determines the estimate; a `StreamBank`'s rows equal, bit for bit, each
//! channel filtered alone.
//!
//! Input: kind, degree, engine and the kind's parameters, the way samples are fed, the
//! number of samples, then their times and values.

use super::check;
use super::input::Input;
use seqsmooth::error::check_sample;
use seqsmooth::polynomial::stream::{Chunk, StreamBank};
use seqsmooth::polynomial::{AutomaticFilter, DiscountMode, SwitchRule, MAX_DEGREE};
use seqsmooth::{Engine, Error, ExpandingMemory, FadingMemory, FixedEngine, FixedMemory};
use seqsmooth::{PolynomialFilter, PolynomialState};

/// A filter of any kind (one type, so that a bank can hold it).
#[derive(Clone, Debug)]
pub enum AnyFilter {
    Expanding(Box<ExpandingMemory>),
    Fading(Box<FadingMemory>),
    /// Fixed memory and its window.
    Fixed(Box<FixedMemory>, usize),
    Auto(Box<AutomaticFilter>),
}

impl AnyFilter {
    fn inner(&self) -> &dyn PolynomialFilter {
        match self {
            AnyFilter::Expanding(f) => f.as_ref(),
            AnyFilter::Fading(f) => f.as_ref(),
            AnyFilter::Fixed(f, _) => f.as_ref(),
            AnyFilter::Auto(f) => f.as_ref(),
        }
    }

    fn inner_mut(&mut self) -> &mut dyn PolynomialFilter {
        match self {
            AnyFilter::Expanding(f) => f.as_mut(),
            AnyFilter::Fading(f) => f.as_mut(),
            AnyFilter::Fixed(f, _) => f.as_mut(),
            AnyFilter::Auto(f) => f.as_mut(),
        }
    }

    /// The samples taken, accepted or not: the automatic filter's [`samples`] counts the
    /// accepted ones only (an outlier it rejects is not), so its rejected ones are added.
    ///
    /// [`samples`]: AutomaticFilter::samples
    fn taken(&self) -> u64 {
        match self {
            AnyFilter::Auto(f) => f.samples() + f.rejected(),
            other => other.samples(),
        }
    }

    /// The samples after which every derivative of the estimate is determined (`None` for
    /// the automatic filter, whose degree settles with the data).
    fn determined_after(&self) -> Option<u64> {
        match self {
            AnyFilter::Expanding(f) => Some(f.degree() as u64 + 1),
            AnyFilter::Fading(f) => Some(f.degree() as u64 + 1),
            AnyFilter::Fixed(f, w) => Some((*w).max(f.degree() + 1) as u64),
            AnyFilter::Auto(_) => None,
        }
    }
}

impl PolynomialFilter for AnyFilter {
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
    fn update_many(&mut self, times: &[f64], values: &[f64]) -> Result<(), Error> {
        self.inner_mut().update_many(times, values)
    }
    fn update_many_into(&mut self, t: &[f64], y: &[f64], out: &mut [f64]) -> Result<(), Error> {
        self.inner_mut().update_many_into(t, y, out)
    }
}

/// A filter decoded from `input`, or the typed error its parameters get.
fn build(input: &mut Input) -> Result<AnyFilter, Error> {
    let kind = input.byte() % 4;
    let m = degree(input);
    let engine = if input.flag() {
        Engine::Gain
    } else {
        Engine::Exact
    };
    let sigma = input.flag().then(|| input.number());
    if check::trace() {
        eprintln!("kind {kind}, degree {m}, {engine:?}, sigma {sigma:?}");
    }
    let built = build_kind(input, kind, m, engine, sigma);
    if check::trace() {
        eprintln!("built: {built:?}");
    }
    built
}

/// Degrees `0..=8` from most bytes, any of `0..=MAX_DEGREE + 1` (one above the largest, to see
/// it refused) from the rest: the high degrees cost seconds each, the low ones microseconds.
fn degree(input: &mut Input) -> usize {
    match input.byte() {
        b @ 0..=199 => usize::from(b) % 9,
        b => usize::from(b - 200) % (MAX_DEGREE + 2),
    }
}

fn build_kind(
    input: &mut Input,
    kind: u8,
    m: usize,
    engine: Engine,
    sigma: Option<f64>,
) -> Result<AnyFilter, Error> {
    Ok(match kind {
        0 => {
            let f = ExpandingMemory::new(m, engine)?;
            AnyFilter::Expanding(Box::new(match sigma {
                Some(s) => f.with_noise_sigma(s)?,
                None => f,
            }))
        }
        1 => {
            let (theta, tau) = (theta(input), input.number());
            if check::trace() {
                eprintln!("theta {theta:e}, tau {tau:e}");
            }
            let mut f = FadingMemory::new(m, theta, tau, engine)?;
            if input.flag() {
                f = f.with_discount_mode(DiscountMode::PerUpdate)?;
            }
            f = f.with_switch_rule(switch_rule(input))?;
            AnyFilter::Fading(Box::new(match sigma {
                Some(s) => f.with_noise_sigma(s)?,
                None => f,
            }))
        }
        2 => {
            let window = input.below(64);
            let engine = [
                FixedEngine::Direct,
                FixedEngine::Sliding,
                FixedEngine::Irregular,
                FixedEngine::Adaptive,
            ][input.below(4)];
            let mut f = FixedMemory::new(m, window, engine)?;
            if input.flag() {
                f = f.with_refreshes(input.below(40))?;
            }
            AnyFilter::Fixed(
                Box::new(match sigma {
                    Some(s) => f.with_noise_sigma(s)?,
                    None => f,
                }),
                window,
            )
        }
        _ => {
            let (theta, tau) = (theta(input), input.number());
            if check::trace() {
                eprintln!("theta {theta:e}, tau {tau:e}");
            }
            let f = AutomaticFilter::new(m, theta, tau)?.with_engine(engine)?;
            AnyFilter::Auto(Box::new(match sigma {
                Some(s) => f.with_noise_sigma(s)?,
                None => f,
            }))
        }
    })
}

/// θ: mostly inside `(0, 1)`, near its ends too; sometimes any number.
fn theta(input: &mut Input) -> f64 {
    match input.byte() % 4 {
        0 => input.number(),
        1 => 1.0 - f64::from(input.u16()) * 1e-5 * f64::EPSILON.max(1e-9),
        _ => (f64::from(input.u16()) + 0.5) / 65536.5,
    }
}

fn switch_rule(input: &mut Input) -> SwitchRule {
    match input.byte() % 6 {
        0 => SwitchRule::ColumnMean,
        1 => SwitchRule::Derivative(degree(input)),
        2 => SwitchRule::ExactCrossover,
        3 => SwitchRule::AtSample(u64::from(input.u16())),
        _ => SwitchRule::Position,
    }
}

/// Feeds the samples one by one, checking each step; the automatic filter decides every
/// sample once, in order (its outputs' decisions and `finish`'s).
fn one_by_one(f: &mut AnyFilter, times: &[f64], values: &[f64], lead: f64) {
    let mut decided = 0u64;
    for (&t, &y) in times.iter().zip(values) {
        let valid = check_sample(t, y, f.last_time()).is_ok();
        let before = f.taken();
        match f.update(t, y) {
            Ok(()) => {
                assert!(
                    valid,
                    "accepted the invalid sample ({t}, {y}) after {:?}",
                    f.last_time()
                );
                assert_eq!(f.taken(), before + 1);
                if let AnyFilter::Auto(a) = f {
                    decided += a.last_output().expect("an update").decided.len() as u64;
                    assert!(decided <= f.taken(), "more decisions than samples");
                }
            }
            Err(e) => {
                check::error_message(&e);
                assert_eq!(f.taken(), before, "a refused sample was counted: {e}");
                continue;
            }
        }
        let determined = f.determined_after().is_some_and(|n| f.samples() >= n);
        estimate_or_reason(f, t, determined, "estimate");
        let at = t + lead;
        if at.is_finite() {
            estimate_or_reason(f, at, determined, "estimate at t + lead");
        }
    }
    if let AnyFilter::Auto(a) = f {
        let taken = a.samples() + a.rejected();
        let tail = a.finish();
        decided += tail.len() as u64;
        assert_eq!(decided, taken, "every sample decided once");
        let rejected = tail.iter().filter(|&&r| r).count() as u64;
        assert!(
            a.rejected() >= rejected,
            "finish rejected more than the filter counts"
        );
        assert_eq!(
            a.samples() + a.rejected(),
            taken,
            "finish changed the count of samples"
        );
        if let Some(t) = a.last_time() {
            estimate_or_reason(f, t, false, "estimate after finish");
        }
    }
}

/// The estimate at `t`: finite in every number, or refused with a reason. Once the samples
/// that determine it are in, the reason is not the sample count: the fit is singular in
/// doubles, or a number of it is beyond the double range. `estimate_at` agrees.
fn estimate_or_reason(f: &AnyFilter, t: f64, determined: bool, what: &str) {
    match f.try_estimate_at(t) {
        Ok(s) => {
            check::state(&s, what);
            assert_eq!(f.estimate_at(t).as_ref(), Some(&s), "{what}");
        }
        Err(e) => {
            check::error_message(&e);
            if check::trace() {
                eprintln!("{what}: {e}");
            }
            assert!(
                f.estimate_at(t).is_none(),
                "{what}: {e}, yet estimate_at has one"
            );
            match &e {
                Error::TooFewSamples { .. } if determined => {
                    panic!("{what} after {} samples: {e}", f.samples())
                }
                Error::TooFewSamples { .. }
                | Error::NotDetermined { .. }
                | Error::EstimateOutOfRange { .. } => {}
                other => panic!("{what}: {other:?} is not a reason for no estimate"),
            }
        }
    }
}

/// The rows of `update_many_into`: finite from the sample that determines the estimate (NaN
/// before); the rows up to a refused sample when there is one.
fn rows(f: &AnyFilter, before: u64, rows: &[f64], result: &Result<(), Error>) {
    let w = f.degree() + 1;
    let done = match result {
        Ok(()) => rows.len() / w,
        Err(Error::InBatch { index, .. }) => *index,
        Err(e) => panic!("update_many_into failed with {e:?}, not a sample's error"),
    };
    for (i, row) in rows.chunks_exact(w).take(done).enumerate() {
        let n = before + i as u64 + 1;
        // NaN marks "no estimate" (before determined, or a number beyond the double range);
        // nothing is infinite.
        assert!(!row.iter().any(|v| v.is_infinite()), "row {i}: {row:?}");
        if f.determined_after().is_some_and(|k| n < k) {
            assert!(row.iter().all(|v| v.is_nan()), "row {i} before determined");
        }
    }
}

/// Feeds the samples as batches (cut where the input says), checking each.
fn batches(f: &mut AnyFilter, input: &mut Input, times: &[f64], values: &[f64]) {
    let mut start = 0;
    while start < times.len() {
        let end = (start + 1 + input.below(times.len())).min(times.len());
        let (t, y) = (&times[start..end], &values[start..end]);
        let before = f.taken();
        let into = input.flag();
        let result = if into {
            let mut out = vec![0.0; t.len() * (f.degree() + 1)];
            let r = f.update_many_into(t, y, &mut out);
            rows(f, before, &out, &r);
            r
        } else {
            f.update_many(t, y)
        };
        match result {
            Ok(()) => assert_eq!(f.taken(), before + t.len() as u64),
            Err(e) => {
                check::error_message(&e);
                if let Error::InBatch { index, source } = &e {
                    assert!(f.taken() == before + *index as u64, "{e}");
                    check::error_message(source);
                } else {
                    panic!("a batch refused without the sample's index: {e:?}");
                }
                // Carry on after the refused sample.
                start += match e {
                    Error::InBatch { index, .. } => index + 1,
                    _ => t.len(),
                };
                continue;
            }
        }
        if let Some(t) = f.last_time() {
            let determined = f.determined_after().is_some_and(|n| f.samples() >= n);
            estimate_or_reason(f, t, determined, "estimate after a batch");
        }
        start = end;
    }
}

/// A `StreamBank` of `prototype` over interleaved channels: the rows equal each channel's
/// samples filtered alone, bit for bit.
fn bank(prototype: AnyFilter, input: &mut Input, n: usize) {
    let channels = 1 + input.below(4);
    let per: Vec<(Vec<f64>, Vec<f64>)> = (0..channels)
        .map(|_| {
            let t = input.times(n);
            let y = input.values(&t);
            (t, y)
        })
        .collect();
    // Interleave: each row takes the next sample of a channel the input picks.
    let (mut next, mut order) = (vec![0; channels], Vec::new());
    while order.len() < channels * n {
        let mut c = input.below(channels);
        while next[c] == n {
            c = (c + 1) % channels;
        }
        order.push((c, next[c]));
        next[c] += 1;
    }
    let ch: Vec<usize> = order.iter().map(|&(c, _)| c).collect();
    let t: Vec<f64> = order.iter().map(|&(c, i)| per[c].0[i]).collect();
    let y: Vec<f64> = order.iter().map(|&(c, i)| per[c].1[i]).collect();
    if check::trace() {
        eprintln!("bank: channels {ch:?}\ntimes {t:?}\nvalues {y:?}");
    }
    let stride = prototype.degree() + 1;
    let mut out = vec![0.0; t.len() * stride];
    let mut bank = StreamBank::growing(prototype.clone()).expect("a new filter is a prototype");
    let chunk = Chunk {
        channels: &ch,
        times: &t,
        values: &y,
        estimates: &mut out,
        stride,
    };
    let run = |f: &mut AnyFilter, t: &[f64], y: &[f64], o: &mut [f64]| f.update_many_into(t, y, o);
    let result = if input.flag() {
        bank.update_par(chunk, run)
    } else {
        bank.update(chunk, run)
    };
    if let Err(e) = result {
        return check::error_message(&e);
    }
    for (c, (tc, yc)) in per.iter().enumerate() {
        let mut alone = prototype.clone();
        let mut expected = vec![0.0; tc.len() * stride];
        alone
            .update_many_into(tc, yc, &mut expected)
            .expect("the bank took these samples");
        let got: Vec<u64> = order
            .iter()
            .enumerate()
            .filter(|(_, &(k, _))| k == c)
            .flat_map(|(row, _)| {
                out[row * stride..(row + 1) * stride]
                    .iter()
                    .map(|v| v.to_bits())
            })
            .collect();
        let expected: Vec<u64> = expected.iter().map(|v| v.to_bits()).collect();
        assert_eq!(
            got, expected,
            "channel {c} in the bank differs from it alone"
        );
    }
}

pub fn run(data: &[u8]) {
    let mut input = Input::new(data);
    let filter = match build(&mut input) {
        Ok(f) => f,
        Err(e) => return check::error_message(&e),
    };
    let how = input.byte() % 4;
    let n = input.below(48);
    if how == 3 {
        return bank(filter, &mut input, n.min(16));
    }
    let times = input.times(n);
    let values = input.values(&times);
    if check::trace() {
        eprintln!("how {how}: times {times:?}\nvalues {values:?}");
    }
    let mut f = filter;
    match how {
        0 => {
            let lead = input.number();
            if check::trace() {
                eprintln!("lead {lead}");
            }
            one_by_one(&mut f, &times, &values, lead)
        }
        _ => batches(&mut f, &mut input, &times, &values),
    }
}
