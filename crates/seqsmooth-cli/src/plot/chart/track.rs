//! The rows a plot is drawn from ([`Track`], [`Row`]) and the rules that read them: the
//! outages ([`is_outage`]), the misfit spans ([`Spans`]), the sample each estimate is compared
//! with under a lead ([`LeadMatcher`]), and the values a row contributes to the panels
//! ([`drawn`]), which a decimated track keeps the extremes of.

use std::collections::VecDeque;

/// The rows of a filter run, column by column (every vector has one entry per row).
#[derive(Clone, Debug, Default)]
pub struct Track {
    /// Sample times.
    pub t: Vec<f64>,
    /// Measured values.
    pub y: Vec<f64>,
    /// `d[k][i]`: the `k`-th derivative estimated at row `i`, where determined.
    pub d: Vec<Vec<Option<f64>>>,
    /// `s[k][i]`: its 1σ, where known (`s[k]` may be missing or empty: no band).
    pub s: Vec<Vec<Option<f64>>>,
    /// `truth[k][i]`: the true `k`-th derivative (`truth[k]` empty or missing: unknown).
    pub truth: Vec<Vec<f64>>,
    /// The noise σ in use at each row (empty: unknown).
    pub noise: Vec<Option<f64>>,
    /// Whether each row's sample was rejected as an outlier (empty: no such column).
    pub rejected: Vec<bool>,
    /// The spans `(from, to)` where the misfit flag is up ([`flag_spans`]).
    pub misfit: Vec<(f64, f64)>,
    /// Of a decimated track, instead: spans `(from, to, share)` each shaded by the share of
    /// its time under the misfit flag (a flag up now and then in every pixel would otherwise
    /// shade the whole plot).
    pub misfit_share: Vec<(f64, f64, f64)>,
    /// Times at which the output switched from expanding to fading memory.
    pub switches: Vec<f64>,
    /// Times at which the memory was restarted on misfit.
    pub restarts: Vec<f64>,
    /// Whether each row is past the start-up (its estimate of the full degree; empty: every
    /// row): the residual and error panels' ranges leave the others out.
    pub settled: Vec<bool>,
    /// Spans `(from, to)` with no samples (a sensor outage: [`outages`]), hatched in every
    /// panel; no curve is drawn across one.
    pub outages: Vec<(f64, f64)>,
    /// The estimates are valid at `t + lead`: drawn there, and compared with the sample at
    /// that time where there is one ([`samples_at_lead`]).
    pub lead: f64,
    /// The sample at each row's estimate time `t + lead` (empty: found in the track itself by
    /// [`samples_at_lead`]); a track of decimated rows carries them.
    pub at: Vec<Option<Sample>>,
    /// Whether each row belongs to the systematic sample the axis ranges' quantiles are taken
    /// over (empty: every row does); the other rows of a decimated track are kept for their
    /// extremes, which would bias the quantiles.
    pub sampled: Vec<bool>,
    /// The rows and rejected samples the track was decimated from (`None`: the track's own).
    pub counts: Option<Counts>,
}

/// How many rows (and rejected samples among them) a decimated track was read from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counts {
    pub rows: usize,
    pub rejected: usize,
}

/// A sample as a row's estimate is compared with it: its time, value, rejection and truth.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Sample {
    pub t: f64,
    pub y: f64,
    pub rejected: bool,
    /// The true derivatives at its time, where known.
    pub truth: Vec<Option<f64>>,
}

/// One row of a [`Track`], as [`Track::push`] takes it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Row {
    pub t: f64,
    pub y: f64,
    pub d: Vec<Option<f64>>,
    pub s: Vec<Option<f64>>,
    pub truth: Vec<f64>,
    pub noise: Option<f64>,
    pub rejected: bool,
    pub settled: bool,
    /// The sample at the estimate's time `t + lead`.
    pub at: Option<Sample>,
}

impl Row {
    /// The row's own sample (what [`Row::at`] is with no lead).
    pub fn sample(&self) -> Sample {
        Sample {
            t: self.t,
            y: self.y,
            rejected: self.rejected,
            truth: self.truth.iter().copied().map(Some).collect(),
        }
    }
}

impl Track {
    /// Appends `row` (a row of the decimated track when `sampled` is `Some`: whether it is in
    /// the systematic sample).
    pub fn push(&mut self, row: Row, sampled: Option<bool>) {
        let n = self.t.len();
        let grow = |v: &mut Vec<Vec<Option<f64>>>, m: usize| {
            while v.len() < m {
                v.push(vec![None; n]);
            }
        };
        grow(&mut self.d, row.d.len());
        grow(&mut self.s, row.s.len());
        for (k, col) in self.d.iter_mut().enumerate() {
            col.push(row.d.get(k).copied().flatten());
        }
        for (k, col) in self.s.iter_mut().enumerate() {
            col.push(row.s.get(k).copied().flatten());
        }
        while self.truth.len() < row.truth.len() {
            self.truth.push(Vec::new());
        }
        for (k, x) in row.truth.iter().enumerate() {
            self.truth[k].push(*x);
        }
        self.t.push(row.t);
        self.y.push(row.y);
        self.noise.push(row.noise);
        self.rejected.push(row.rejected);
        self.settled.push(row.settled);
        self.at.push(row.at);
        if let Some(s) = sampled {
            self.sampled.push(s);
        }
    }
}

/// The values `row` contributes to the panels — every curve, band edge and point any panel
/// draws of it (NaN where it has none), in a fixed order for rows of the same shape: the
/// sample (accepted, rejected); per derivative `k`, the estimate, its ±3σ band's edges, its 3σ,
/// the truth and the estimate's error against the truth at its time; the residual against the
/// sample at its time (accepted, rejected), the truth there less the estimate, 3σ of the noise;
/// the sample less the truth (accepted, rejected). A decimated track keeps, per half pixel,
/// the rows holding each one's lowest and highest value.
///
/// ```
/// use seqsmooth_cli::plot::chart::{drawn, Row};
/// let row = Row { t: 1.0, y: 5.0, d: vec![Some(4.5)], s: vec![Some(0.5)], ..Row::default() };
/// let mut v = Vec::new();
/// drawn(&row, &mut v);
/// assert_eq!(v[0], 5.0); // an accepted sample
/// assert!(v[1].is_nan()); // no rejected one
/// assert_eq!(&v[2..6], &[4.5, 6.0, 3.0, 1.5]); // d0, d0 ± 3σ, 3σ
/// ```
pub fn drawn(row: &Row, out: &mut Vec<f64>) {
    out.clear();
    let nan = f64::NAN;
    let o = |v: Option<f64>| v.unwrap_or(nan);
    let split = |v: Option<f64>, rejected: bool| {
        let v = o(v);
        if rejected {
            [nan, v]
        } else {
            [v, nan]
        }
    };
    out.extend(split(Some(row.y), row.rejected));
    let at = row.at.as_ref();
    let truth_at = |k: usize| at.and_then(|a| a.truth.get(k).copied().flatten());
    for (k, d) in row.d.iter().enumerate() {
        let s = row.s.get(k).copied().flatten();
        let band = |sign: f64| d.zip(s).map(|(d, s)| d + sign * 3.0 * s);
        out.extend([o(*d), o(band(1.0)), o(band(-1.0)), o(s.map(|s| 3.0 * s))]);
        out.push(o(row.truth.get(k).copied()));
        out.push(o(d.zip(truth_at(k)).map(|(d, x)| d - x)));
    }
    let d0 = row.d.first().copied().flatten();
    let residual = at.zip(d0).map(|(a, d)| a.y - d);
    out.extend(split(residual, at.is_some_and(|a| a.rejected)));
    out.push(o(truth_at(0).zip(d0).map(|(x, d)| x - d)));
    out.push(o(row.noise.map(|s| 3.0 * s)));
    let error = row.truth.first().map(|x| row.y - x);
    out.extend(split(error, row.rejected));
}

/// The value `p`-quantile of the finite `values` (nearest rank), if any.
pub(super) fn quantile(values: impl IntoIterator<Item = f64>, p: f64) -> Option<f64> {
    let mut values: Vec<f64> = values.into_iter().collect();
    values.sort_by(f64::total_cmp);
    let k = (values.len().saturating_sub(1) as f64 * p).round() as usize;
    values.get(k).copied()
}

/// Maximal runs of consecutive indices where `keep` holds.
pub fn runs(n: usize, keep: impl Fn(usize) -> bool) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut start = None;
    for i in 0..=n {
        match (i < n && keep(i), start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                out.push(s..i);
                start = None;
            }
            _ => {}
        }
    }
    out
}

/// An outage is a step between consecutive samples longer than this many typical steps.
pub const OUTAGE_STEPS: f64 = 10.0;

/// The typical step of a series: the median of its `steps` (nearest rank), if any.
pub fn typical_step(steps: impl IntoIterator<Item = f64>) -> Option<f64> {
    quantile(steps, 0.5)
}

/// Whether a step of `step` between consecutive samples is an outage, the typical step being
/// `typical`: longer than [`OUTAGE_STEPS`] of them. No curve is drawn across an outage.
///
/// ```
/// use seqsmooth_cli::plot::chart::is_outage;
/// assert!(is_outage(12.5, 1.0) && !is_outage(9.0, 1.0));
/// ```
pub fn is_outage(step: f64, typical: f64) -> bool {
    step > OUTAGE_STEPS * typical
}

/// The outages of the increasing times `t`: the steps `(t[i-1], t[i])` that [`is_outage`]
/// against the median step.
///
/// ```
/// use seqsmooth_cli::plot::chart::outages;
/// let mut t: Vec<f64> = (0..50).map(f64::from).collect();
/// t.extend((0..50).map(|i| 70.0 + f64::from(i)));
/// assert_eq!(outages(&t), vec![(49.0, 70.0)]);
/// ```
pub fn outages(t: &[f64]) -> Vec<(f64, f64)> {
    let steps = || t.windows(2).map(|w| (w[0], w[1]));
    let Some(typical) = typical_step(steps().map(|(a, b)| b - a)) else {
        return Vec::new();
    };
    steps().filter(|(a, b)| is_outage(b - a, typical)).collect()
}

/// The spans of a flag over rows in time order: each run of flagged rows spans from its
/// first row's time to the time of the row after it (the last row's, at the end). Spans
/// closer than `merge` (e.g. a pixel's width in time) are joined, which bounds their number.
#[derive(Clone, Debug, Default)]
pub struct Spans {
    spans: Vec<(f64, f64)>,
    open: Option<f64>,
    last: Option<f64>,
}

impl Spans {
    /// Takes the next row: its time and flag; spans closer than `merge` are joined.
    pub fn push(&mut self, t: f64, flag: bool, merge: f64) {
        match (self.open, flag) {
            (None, true) => self.open = Some(t),
            (Some(a), false) => {
                self.close(a, t, merge);
                self.open = None;
            }
            _ => {}
        }
        self.last = Some(t);
    }

    fn close(&mut self, a: f64, b: f64, merge: f64) {
        match self.spans.last_mut() {
            Some(last) if a - last.1 <= merge => last.1 = b,
            _ => self.spans.push((a, b)),
        }
    }

    /// The spans, a run still open closed at the last row.
    pub fn finish(mut self, merge: f64) -> Vec<(f64, f64)> {
        if let (Some(a), Some(b)) = (self.open, self.last) {
            self.close(a, b, merge);
        }
        let mut out: Vec<(f64, f64)> = Vec::with_capacity(self.spans.len());
        for s in self.spans {
            match out.last_mut() {
                Some(last) if s.0 - last.1 <= merge => last.1 = s.1,
                _ => out.push(s),
            }
        }
        out
    }
}

/// The spans of `flags` over the rows at times `t` ([`Spans`], none joined).
///
/// ```
/// use seqsmooth_cli::plot::chart::flag_spans;
/// let t = [0.0, 1.0, 2.0, 3.0, 4.0];
/// assert_eq!(flag_spans(&t, &[false, true, true, false, true]), vec![(1.0, 3.0), (4.0, 4.0)]);
/// ```
pub fn flag_spans(t: &[f64], flags: &[bool]) -> Vec<(f64, f64)> {
    let mut spans = Spans::default();
    for (&t, &f) in t.iter().zip(flags) {
        spans.push(t, f, 0.0);
    }
    spans.finish(0.0)
}

/// Steps at the start of a series that set the tolerance of [`LeadMatcher`].
pub const LEAD_HEAD: usize = 1024;

/// Matches each row of a stream in time order with the sample at its estimate's time
/// `t + lead`: the sample whose time is within a thousandth of the typical step of `t + lead`
/// (the median of the first [`LEAD_HEAD`] steps; nearest if two are), or none. It holds only
/// the rows and samples within the lead (and the first steps until they are known).
#[derive(Clone, Debug)]
pub struct LeadMatcher<R, S> {
    lead: f64,
    tol: Option<f64>,
    head: Vec<f64>,
    newest: Option<f64>,
    samples: VecDeque<(f64, S)>,
    pending: VecDeque<(f64, R)>,
    ready: VecDeque<(R, Option<S>)>,
}

impl<R, S: Clone> LeadMatcher<R, S> {
    pub fn new(lead: f64) -> Self {
        LeadMatcher {
            lead,
            tol: None,
            head: Vec::new(),
            newest: None,
            samples: VecDeque::new(),
            pending: VecDeque::new(),
            ready: VecDeque::new(),
        }
    }

    /// Takes the next row at time `t` with its sample.
    pub fn push(&mut self, t: f64, row: R, sample: S) {
        if let Some(p) = self.newest.replace(t) {
            if self.tol.is_none() {
                self.head.push(t - p);
                if self.head.len() >= LEAD_HEAD {
                    self.settle_tolerance();
                }
            }
        }
        if self.lead == 0.0 {
            self.ready.push_back((row, Some(sample)));
            return;
        }
        self.samples.push_back((t, sample));
        self.pending.push_back((t, row));
        self.resolve(false);
    }

    fn settle_tolerance(&mut self) {
        self.tol = Some(1e-3 * typical_step(self.head.drain(..)).unwrap_or(0.0));
    }

    /// Resolves the pending rows whose match is decided (all of them at the end).
    fn resolve(&mut self, end: bool) {
        let Some(tol) = self.tol else { return };
        let newest = self.newest.unwrap_or(f64::NEG_INFINITY);
        while let Some(&(t, _)) = self.pending.front() {
            let at = t + self.lead;
            if !end && newest <= at + tol {
                break;
            }
            let j = self.samples.partition_point(|s| s.0 < at);
            let near = [j.checked_sub(1), Some(j)]
                .into_iter()
                .flatten()
                .filter(|&j| j < self.samples.len() && (self.samples[j].0 - at).abs() <= tol)
                .min_by(|&a, &b| {
                    let d = |j: usize| (self.samples[j].0 - at).abs();
                    d(a).total_cmp(&d(b))
                });
            let sample = near.map(|j| self.samples[j].1.clone());
            if let Some((_, row)) = self.pending.pop_front() {
                self.ready.push_back((row, sample));
            }
        }
        // Samples no pending or later row can match.
        let oldest = self.pending.front().map_or(newest, |p| p.0);
        while self
            .samples
            .front()
            .is_some_and(|s| s.0 < oldest + self.lead - tol)
        {
            self.samples.pop_front();
        }
    }

    /// The next row whose match is decided, with its sample.
    pub fn pop(&mut self) -> Option<(R, Option<S>)> {
        self.ready.pop_front()
    }

    /// At the end of the stream: decides every row still pending.
    pub fn finish(&mut self) {
        if self.tol.is_none() {
            self.settle_tolerance();
        }
        self.resolve(true);
    }
}

/// The rows whose estimate has a sample at its own time `t + lead` ([`LeadMatcher`]): for
/// each row, the index of that sample (every row itself for `lead = 0`). `t` is strictly
/// increasing.
///
/// ```
/// use seqsmooth_cli::plot::chart::samples_at_lead;
/// let t = [0.0, 0.1, 0.2, 0.30000000000000004, 0.4];
/// assert_eq!(samples_at_lead(&t, 0.2), vec![Some(2), Some(3), Some(4), None, None]);
/// assert_eq!(samples_at_lead(&t, 0.0)[1], Some(1));
/// ```
pub fn samples_at_lead(t: &[f64], lead: f64) -> Vec<Option<usize>> {
    let mut m = LeadMatcher::new(lead);
    let mut out = Vec::with_capacity(t.len());
    for (i, &ti) in t.iter().enumerate() {
        m.push(ti, (), i);
        out.extend(std::iter::from_fn(|| m.pop()).map(|r| r.1));
    }
    m.finish();
    out.extend(std::iter::from_fn(|| m.pop()).map(|r| r.1));
    out
}

/// For each row, whether an outage lies between it and the row before.
pub(super) fn breaks(track: &Track) -> Vec<bool> {
    let t = &track.t;
    let mut out = vec![false; t.len()];
    let mut k = 0;
    for i in 1..t.len() {
        while k < track.outages.len() && track.outages[k].1 <= t[i - 1] {
            k += 1;
        }
        out[i] = track.outages[k..]
            .iter()
            .take_while(|o| o.1 <= t[i])
            .any(|o| t[i - 1] <= o.0);
    }
    out
}

/// `runs` cut where `after[i]` (row `i` follows an outage).
pub(super) fn split_runs(
    runs: Vec<std::ops::Range<usize>>,
    after: &[bool],
) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::with_capacity(runs.len());
    for r in runs {
        let mut start = r.start;
        for (i, &cut) in after.iter().enumerate().take(r.end).skip(r.start + 1) {
            if cut {
                out.push(start..i);
                start = i;
            }
        }
        out.push(start..r.end);
    }
    out
}
