//! Independent filters of one configuration, one per channel, each on its own timestamps:
//! [`StreamBank`] (the multi-series engine: any [`PolynomialFilter`] per channel).

use crate::error::{Error, Param};
use crate::polynomial::filter::PolynomialFilter;
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
///
/// Series that appear as they come go through [`update`](Self::update) (serially) or
/// [`update_par`](Self::update_par) (the series on the rayon pool): a chunk of rows, each
/// tagged with its channel, is grouped by channel (a stable counting sort), each channel's rows
/// run as one batch through a per-channel closure (e.g. [`PolynomialFilter::update_many_into`])
/// and the results are scattered back to the rows' order.
#[derive(Clone, Debug)]
pub struct StreamBank<F> {
    filters: Vec<F>,
    /// The filter a new channel starts from.
    prototype: F,
    /// Grouping buffers, kept from call to call.
    scratch: Scratch,
}

/// The buffers of [`StreamBank::update`]: the rows in channel order and their data.
#[derive(Clone, Debug, Default)]
struct Scratch {
    /// Rows in grouped order (indices into the chunk).
    order: Vec<usize>,
    /// Per channel of the chunk, in order of first appearance: channel, first grouped slot.
    groups: Vec<(usize, usize)>,
    /// Per channel: its position in `groups` while grouping, else `usize::MAX`.
    mark: Vec<usize>,
    times: Vec<f64>,
    values: Vec<f64>,
    out: Vec<f64>,
}

impl Scratch {
    /// Groups the rows of `channels` by channel into `order` and `groups` (stable).
    fn group(&mut self, channels: &[usize], count: usize) {
        self.groups.clear();
        self.mark.resize(count, usize::MAX);
        for &c in channels {
            let g = &mut self.mark[c];
            if *g == usize::MAX {
                *g = self.groups.len();
                self.groups.push((c, 0));
            }
            self.groups[*g].1 += 1;
        }
        // Counts to first slots, then each row after the previous ones of its channel.
        let mut next = 0;
        for g in &mut self.groups {
            (g.1, next) = (next, next + g.1);
        }
        let mut cursor: Vec<usize> = self.groups.iter().map(|g| g.1).collect();
        self.order.resize(channels.len(), 0);
        for (i, &c) in channels.iter().enumerate() {
            let k = &mut cursor[self.mark[c]];
            self.order[*k] = i;
            *k += 1;
        }
        for &(c, _) in &self.groups {
            self.mark[c] = usize::MAX;
        }
    }
}

/// Rows of many channels for [`StreamBank::update`]: row `i` is the sample
/// `(times[i], values[i])` of channel `channels[i]`, and its results go to
/// `estimates[i·stride..(i+1)·stride]`.
#[derive(Debug)]
pub struct Chunk<'a> {
    /// The channel of each row.
    pub channels: &'a [usize],
    /// The time of each row.
    pub times: &'a [f64],
    /// The value of each row.
    pub values: &'a [f64],
    /// `stride` results per row, written by the per-channel run.
    pub estimates: &'a mut [f64],
    /// Results per row.
    pub stride: usize,
}

/// One channel's piece of a chunk: channel, filter, times, values, output, rows.
type Work<'a, F> = (
    usize,
    Option<&'a mut F>,
    &'a [f64],
    &'a [f64],
    &'a mut [f64],
    &'a [usize],
);

/// The per-channel work of [`StreamBank::update`]: `(filter, times, values, out)` with `out`
/// holding `stride` values per row; an error in a row is [`Error::InBatch`] with its index.
pub trait ChannelRun<F>:
    Fn(&mut F, &[f64], &[f64], &mut [f64]) -> Result<(), Error> + Sync
{
}
impl<F, R: Fn(&mut F, &[f64], &[f64], &mut [f64]) -> Result<(), Error> + Sync> ChannelRun<F> for R {}

impl<F: PolynomialFilter + Clone> StreamBank<F> {
    /// `channels` copies of `prototype`, which must not have seen any sample yet.
    pub fn new(prototype: F, channels: usize) -> Result<Self, Error> {
        if channels == 0 {
            return Err(Error::InvalidParameter {
                name: Param::Channels,
                value: "0".into(),
                reason: "a bank needs at least one channel".into(),
            });
        }
        if prototype.samples() > 0 {
            return Err(Error::InvalidParameter {
                name: Param::Prototype,
                value: format!("a filter with {} samples", prototype.samples()),
                reason: "the channels must start empty".into(),
            });
        }
        Ok(Self {
            filters: vec![prototype.clone(); channels],
            prototype,
            scratch: Scratch::default(),
        })
    }

    /// A bank of no channels yet: [`update`](Self::update) adds a copy of `prototype` (which
    /// must not have seen any sample) for each new channel, as its rows come.
    ///
    /// ```
    /// use seqsmooth::polynomial::stream::{Chunk, StreamBank};
    /// use seqsmooth::{Engine, ExpandingMemory, PolynomialFilter};
    /// let mut bank = StreamBank::growing(ExpandingMemory::new(1, Engine::Exact)?)?;
    /// // Rows of channels 0 and 1, interleaved; y = t on channel 0, y = 2t on channel 1.
    /// let (ch, t) = ([0, 1, 0, 1, 1], [0.0, 0.0, 1.0, 1.0, 2.0]);
    /// let y = [0.0, 0.0, 1.0, 2.0, 4.0];
    /// let mut est = [0.0f64; 10]; // d0, d1 per row, in row order
    /// let chunk = Chunk { channels: &ch, times: &t, values: &y, estimates: &mut est, stride: 2 };
    /// bank.update_par(chunk, |f, t, y, out| f.update_many_into(t, y, out))?;
    /// assert_eq!(bank.channels(), 2);
    /// assert!(est[0].is_nan() && (est[9] - 2.0).abs() < 1e-12); // row 4: slope 2
    /// # Ok::<(), seqsmooth::Error>(())
    /// ```
    pub fn growing(prototype: F) -> Result<Self, Error> {
        let mut bank = Self::new(prototype, 1)?;
        bank.filters.clear();
        Ok(bank)
    }

    /// Runs a [`Chunk`] of rows (a channel not seen yet starts from the prototype). Each channel's rows,
    /// in order, go to `run(filter, times, values, out)` as one batch, `out` holding `stride`
    /// values per row; they come back in `estimates[i·stride..(i+1)·stride]`. The channels run
    /// one after the other; [`update_par`](Self::update_par) runs them on the rayon pool, with
    /// the same results. On errors every channel still runs up to its own first bad row, and
    /// the error is [`Error::InChannel`] of the channel whose bad row comes first, its source
    /// [`Error::InBatch`] with that row's index in the chunk (the rows before it, of every
    /// channel, are done).
    pub fn update(&mut self, chunk: Chunk<'_>, run: impl ChannelRun<F>) -> Result<(), Error> {
        self.run_chunk(chunk, &run, false, false)
    }

    /// [`update`](Self::update) with the channels on the rayon pool.
    pub fn update_par(&mut self, chunk: Chunk<'_>, run: impl ChannelRun<F>) -> Result<(), Error>
    where
        F: Send,
    {
        self.run_chunk(chunk, &run, true, false)
    }

    /// [`update_par`](Self::update_par) with the results by column: result `k` of row `i` in
    /// `estimates[k·n + i]` (`n` rows), each result's column contiguous (for a data frame's
    /// columns, without a transposition afterwards).
    ///
    /// ```
    /// use seqsmooth::polynomial::stream::{Chunk, StreamBank};
    /// use seqsmooth::{Engine, ExpandingMemory, PolynomialFilter};
    /// let mut bank = StreamBank::growing(ExpandingMemory::new(1, Engine::Exact)?)?;
    /// let (ch, t) = ([0, 1, 0, 1, 1], [0.0, 0.0, 1.0, 1.0, 2.0]);
    /// let y = [0.0, 0.0, 1.0, 2.0, 4.0];
    /// let mut est = [0.0f64; 10]; // d0 of rows 0-4, then d1 of rows 0-4
    /// let chunk = Chunk { channels: &ch, times: &t, values: &y, estimates: &mut est, stride: 2 };
    /// bank.update_par_columns(chunk, |f, t, y, out| f.update_many_into(t, y, out))?;
    /// assert!(est[5].is_nan() && (est[9] - 2.0).abs() < 1e-12); // row 4's slope: 2
    /// # Ok::<(), seqsmooth::Error>(())
    /// ```
    pub fn update_par_columns(
        &mut self,
        chunk: Chunk<'_>,
        run: impl ChannelRun<F>,
    ) -> Result<(), Error>
    where
        F: Send,
    {
        self.run_chunk(chunk, &run, true, true)
    }

    fn run_chunk(
        &mut self,
        chunk: Chunk<'_>,
        run: &dyn ChannelRun<F>,
        parallel: bool,
        columns: bool,
    ) -> Result<(), Error>
    where
        F: Send,
    {
        let Chunk {
            channels,
            times,
            values,
            estimates,
            stride,
        } = chunk;
        let n = channels.len();
        if times.len() != n || values.len() != n || estimates.len() != n * stride {
            return Err(Error::InvalidParameter {
                name: Param::ChunkLengths,
                value: format!(
                    "{n} channels, {} times, {} values",
                    times.len(),
                    values.len()
                ),
                reason: format!("one time, value and {stride} estimates per row"),
            });
        }
        let top = channels.iter().max().map_or(0, |&c| c + 1);
        if top > self.filters.len() {
            self.filters.resize(top, self.prototype.clone());
        }
        let in_row = |c: usize, rows: &dyn Fn(usize) -> usize, e: Error| {
            let (k, source) = match e {
                Error::InBatch { index, source } => (index, source),
                other => (0, Box::new(other)),
            };
            (rows(k), c, source)
        };
        // One channel in the chunk: its rows are the chunk, nothing to group.
        if !columns && channels.iter().all(|&c| c == channels[0]) {
            let Some(&c) = channels.first() else {
                return Ok(());
            };
            return run(&mut self.filters[c], times, values, estimates)
                .map_err(|e| failure(vec![in_row(c, &|k| k, e)]));
        }
        let s = &mut self.scratch;
        s.group(channels, self.filters.len());
        s.times.clear();
        s.times.extend(s.order.iter().map(|&i| times[i]));
        s.values.clear();
        s.values.extend(s.order.iter().map(|&i| values[i]));
        s.out.resize(n * stride, 0.0);
        // One disjoint piece of the grouped buffers per channel, with the channel's filter.
        let mut work = Vec::with_capacity(s.groups.len());
        let mut filters: Vec<Option<&mut F>> = self.filters.iter_mut().map(Some).collect();
        let (mut t, mut y, mut out, mut order) =
            (&s.times[..], &s.values[..], &mut s.out[..], &s.order[..]);
        for (g, &(c, first)) in s.groups.iter().enumerate() {
            let len = s.groups.get(g + 1).map_or(n, |next| next.1) - first;
            let (tg, ty, (og, rest), rows);
            ((tg, t), (ty, y), rows) = (t.split_at(len), y.split_at(len), order.split_at(len));
            (og, rest) = std::mem::take(&mut out).split_at_mut(len * stride);
            (out, order) = (rest, rows.1);
            work.push((c, filters[c].take(), tg, ty, og, rows.0));
        }
        let one = |(c, f, t, y, out, rows): &mut Work<F>| {
            let f = f.as_mut()?;
            run(f, t, y, out).err().map(|e| in_row(*c, &|k| rows[k], e))
        };
        let mut failed: Vec<_> = if parallel {
            work.par_iter_mut()
                .with_min_len(4)
                .filter_map(one)
                .collect()
        } else {
            work.iter_mut().filter_map(one).collect()
        };
        if columns {
            for (&i, e) in s.order.iter().zip(s.out.chunks_exact(stride.max(1))) {
                for (k, &v) in e[..stride].iter().enumerate() {
                    estimates[k * n + i] = v;
                }
            }
        } else {
            for (&i, e) in s.order.iter().zip(s.out.chunks_exact(stride.max(1))) {
                estimates[i * stride..(i + 1) * stride].copy_from_slice(&e[..stride]);
            }
        }
        if failed.is_empty() {
            return Ok(());
        }
        failed.sort_by_key(|f| f.0);
        Err(failure(failed))
    }

    /// A growing bank ([`growing`](Self::growing)) resumed with the channels' filters
    /// `channels` (e.g. read back from a saved state), new channels starting from `prototype`.
    ///
    /// ```
    /// use seqsmooth::polynomial::stream::StreamBank;
    /// use seqsmooth::{Engine, ExpandingMemory, PolynomialFilter};
    /// let proto = ExpandingMemory::new(0, Engine::Exact)?;
    /// let mut a = StreamBank::growing(proto.clone())?;
    /// a.update_channel(0, &[0.0, 1.0], &[2.0, 4.0]).ok(); // a growing bank has no channel yet
    /// let mut one = proto.clone();
    /// one.update_many(&[0.0, 1.0], &[2.0, 4.0])?;
    /// let mut b = StreamBank::resume(proto, vec![one])?;
    /// b.update_channel(0, &[2.0], &[6.0])?;
    /// assert_eq!(b.into_channels()[0].estimate().unwrap().derivatives[0], 4.0);
    /// # Ok::<(), seqsmooth::Error>(())
    /// ```
    pub fn resume(prototype: F, channels: Vec<F>) -> Result<Self, Error> {
        let mut bank = Self::growing(prototype)?;
        bank.filters = channels;
        Ok(bank)
    }

    /// The channels' filters, in channel order (to save them).
    pub fn into_channels(self) -> Vec<F> {
        self.filters
    }

    /// Number of channels.
    pub fn channels(&self) -> usize {
        self.filters.len()
    }

    /// Channel `c`'s filter (its estimate, sample count, …).
    pub fn channel(&self, c: usize) -> Option<&F> {
        self.filters.get(c)
    }

    /// Channel `c`'s filter, to act on between updates (e.g. an automatic filter's
    /// [`finish`](crate::polynomial::AutomaticFilter::finish) at the end of its stream).
    ///
    /// ```
    /// use seqsmooth::polynomial::stream::StreamBank;
    /// use seqsmooth::polynomial::AutomaticFilter;
    /// let mut bank = StreamBank::new(AutomaticFilter::new(1, 0.9, 1.0).unwrap(), 2).unwrap();
    /// bank.update_channel(1, &[0.0, 1.0, 2.0], &[1.0, 2.0, 3.0]).unwrap();
    /// let tail = bank.channel_mut(1).unwrap().finish();
    /// assert!(tail.len() <= 3 && bank.channel_mut(2).is_none());
    /// ```
    pub fn channel_mut(&mut self, c: usize) -> Option<&mut F> {
        self.filters.get_mut(c)
    }

    /// A batch for channel `c` alone.
    pub fn update_channel(&mut self, c: usize, times: &[f64], values: &[f64]) -> Result<(), Error> {
        let n = self.filters.len();
        let f = self
            .filters
            .get_mut(c)
            .ok_or_else(|| Error::InvalidParameter {
                name: Param::Channel,
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
        let each = |(f, (t, y)): (&mut F, &(&[f64], &[f64]))| f.update_many(t, y);
        first_failure(self.filters.iter_mut().zip(batches).map(each).collect())
    }

    /// [`update_all`](Self::update_all) with the channels on the rayon pool.
    pub fn update_all_par(&mut self, batches: &[(&[f64], &[f64])]) -> Result<(), Error>
    where
        F: Send,
    {
        self.check_batches(batches)?;
        let each = |(f, (t, y)): (&mut F, &(&[f64], &[f64]))| f.update_many(t, y);
        first_failure(self.filters.par_iter_mut().zip(batches).map(each).collect())
    }

    fn check_batches(&self, batches: &[(&[f64], &[f64])]) -> Result<(), Error> {
        if batches.len() != self.filters.len() {
            return Err(Error::InvalidParameter {
                name: Param::Batches,
                value: batches.len().to_string(),
                reason: format!("one batch per channel: the bank has {}", self.filters.len()),
            });
        }
        Ok(())
    }
}

/// The error of the failed rows `(row, channel, why)`, first row first: the first one's
/// channel and row, listing the other channels.
fn failure(failed: Vec<(usize, usize, Box<Error>)>) -> Error {
    let mut failed = failed.into_iter();
    let Some((index, channel, source)) = failed.next() else {
        return Error::InvalidParameter {
            name: Param::Failure,
            value: "none".into(),
            reason: "no row failed".into(),
        };
    };
    Error::InChannel {
        channel,
        source: Box::new(Error::InBatch { index, source }),
        also_failed: failed.map(|f| f.1).collect(),
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
