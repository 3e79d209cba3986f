//! Independent filters of one configuration, one per channel, each on its own timestamps:
//! [`StreamBank`] (the multi-series engine: any [`PolynomialFilter`] per channel).

use super::PolynomialFilter;
use crate::error::Error;
use rayon::prelude::*;

/// Independent filters of one configuration, one per channel, each on its own timestamps (the
/// per-channel-stream counterpart of the even-time banks above, e.g. sensors sampled
/// asynchronously). Each channel's batch goes through
/// [`PolynomialFilter::update_many`]; [`update_all_par`](Self::update_all_par) runs the
/// channels on the rayon pool (the result does not depend on the thread count).
///
/// ```
/// use seqsmooth::polynomial::bank::StreamBank;
/// use seqsmooth::{Engine, FadingMemory, PolynomialFilter};
/// let mut bank = StreamBank::new(FadingMemory::new(1, 0.9, 1.0, Engine::Exact)?, 2)?;
/// let (t0, y0) = (vec![0.0, 1.0, 2.5], vec![0.0, 1.0, 2.5]); // y = t
/// let (t1, y1) = (vec![0.2, 0.4], vec![3.0, 2.0]); // y = 4 - 5t
/// bank.update_all_par(&[(&t0, &y0), (&t1, &y1)])?;
/// let x = bank.channel(1).unwrap().estimate().unwrap();
/// assert!((x.derivatives[0] - 2.0).abs() < 1e-12 && (x.derivatives[1] + 5.0).abs() < 1e-12);
/// # Ok::<(), seqsmooth::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct StreamBank<F> {
    filters: Vec<F>,
}

impl<F: PolynomialFilter + Clone> StreamBank<F> {
    /// `channels` copies of `prototype`, which must not have seen any sample yet.
    pub fn new(prototype: F, channels: usize) -> Result<Self, Error> {
        if channels == 0 {
            return Err(Error::InvalidParameter {
                name: "channels",
                value: "0".into(),
                reason: "a bank needs at least one channel".into(),
            });
        }
        if prototype.samples() > 0 {
            return Err(Error::InvalidParameter {
                name: "prototype",
                value: format!("a filter with {} samples", prototype.samples()),
                reason: "the channels must start empty".into(),
            });
        }
        Ok(Self {
            filters: vec![prototype; channels],
        })
    }

    /// Number of channels.
    pub fn channels(&self) -> usize {
        self.filters.len()
    }

    /// Channel `c`'s filter (its estimate, sample count, …).
    pub fn channel(&self, c: usize) -> Option<&F> {
        self.filters.get(c)
    }

    /// A batch for channel `c` alone.
    pub fn update_channel(&mut self, c: usize, times: &[f64], values: &[f64]) -> Result<(), Error> {
        let n = self.filters.len();
        let f = self
            .filters
            .get_mut(c)
            .ok_or_else(|| Error::InvalidParameter {
                name: "channel",
                value: c.to_string(),
                reason: format!("the bank has {n} channels"),
            })?;
        f.update_many(times, values).map_err(|e| Error::InChannel {
            channel: c,
            source: Box::new(e),
            also_failed: Vec::new(),
        })
    }

    /// One batch `(times, values)` per channel, in channel order, serially. Every channel is
    /// processed; channels with a bad sample stop at it ([`PolynomialFilter::update_many`]) and
    /// the error ([`Error::InChannel`]) gives the first such channel's error and lists the
    /// others.
    pub fn update_all(&mut self, batches: &[(&[f64], &[f64])]) -> Result<(), Error> {
        self.check_batches(batches)?;
        let results: Vec<Result<(), Error>> = self
            .filters
            .iter_mut()
            .zip(batches)
            .map(|(f, (t, y))| f.update_many(t, y))
            .collect();
        first_failure(results)
    }

    /// [`update_all`](Self::update_all) with the channels on the rayon pool.
    pub fn update_all_par(&mut self, batches: &[(&[f64], &[f64])]) -> Result<(), Error>
    where
        F: Send,
    {
        self.check_batches(batches)?;
        let results: Vec<Result<(), Error>> = self
            .filters
            .par_iter_mut()
            .zip(batches.par_iter())
            .map(|(f, (t, y))| f.update_many(t, y))
            .collect();
        first_failure(results)
    }

    fn check_batches(&self, batches: &[(&[f64], &[f64])]) -> Result<(), Error> {
        if batches.len() != self.filters.len() {
            return Err(Error::InvalidParameter {
                name: "batches",
                value: batches.len().to_string(),
                reason: format!("one batch per channel: the bank has {}", self.filters.len()),
            });
        }
        Ok(())
    }
}

/// The first failing channel's error, listing the other failed channels.
fn first_failure(results: Vec<Result<(), Error>>) -> Result<(), Error> {
    let mut failed = results
        .into_iter()
        .enumerate()
        .filter_map(|(c, r)| r.err().map(|e| (c, e)));
    match failed.next() {
        None => Ok(()),
        Some((channel, source)) => Err(Error::InChannel {
            channel,
            source: Box::new(source),
            also_failed: failed.map(|(c, _)| c).collect(),
        }),
    }
}
