//! Per-pixel min/max decimation of a dense series for drawing.
//!
//! A polyline with more points than the plot has pixel columns is drawn as a mess of
//! sub-pixel segments. [`min_max`] keeps, of the points that fall in each pixel column (in
//! time order), the first, the lowest, the highest and the last: at most four per column, so
//! the drawn line is as long as the plot is wide, and every value the column spans is still
//! covered — the envelope, every local extreme and the joins between columns are kept exactly.
//! [`envelope`] draws a dense cloud of samples as the band between each column's lowest and
//! highest value.
//!
//! [`Reducer`] does the same while the rows stream in, in memory bounded by the plot's width
//! (not the input's length): it keeps, per time bin, the first and last row and the rows
//! holding each drawn quantity's lowest and highest value. The time range is not known
//! before the end of a stream (standard input cannot be read twice), so the bins adapt: they
//! start one first step wide from the first time, and whenever a row falls beyond the last
//! bin, neighbouring bins merge pairwise and the width doubles. At the end the bins in use
//! number between half the capacity and the capacity, so with a capacity of four bins per
//! pixel column each bin is at most half a pixel wide. [`Stride`] keeps a systematic sample
//! of a stream (every `2^j`-th item) for the quantiles the axis ranges are made of.

/// The points of `points` (in increasing `x`) kept when drawn across `columns` pixel columns
/// spanning `x0..x1`: per column, its first, lowest, highest and last point, in their order.
/// With no more points than columns (or no usable span) every point is kept.
///
/// The column of `x` is `⌊(x − x0)/(x1 − x0) · columns⌋`, clamped to the plot.
///
/// ```
/// use seqsmooth_cli::plot::decimate::min_max;
/// // 1000 points of a triangle wave drawn in 10 columns: ≤ 40 points, the peaks kept.
/// let pts: Vec<(f64, f64)> = (0..1000)
///     .map(|i| (i as f64, (i % 100) as f64))
///     .collect();
/// let kept = min_max(&pts, (0.0, 1000.0), 10);
/// assert!(kept.len() <= 40);
/// assert!(kept.contains(&(99.0, 99.0)) && kept.contains(&(100.0, 0.0)));
/// assert_eq!((kept[0], kept[kept.len() - 1]), (pts[0], pts[999]));
/// ```
pub fn min_max(points: &[(f64, f64)], (x0, x1): (f64, f64), columns: usize) -> Vec<(f64, f64)> {
    let span = x1 - x0;
    if points.len() <= columns || !(span.is_finite() && span > 0.0) || columns == 0 {
        return points.to_vec();
    }
    let top = (columns - 1) as f64;
    let column = |x: f64| ((x - x0) / span * columns as f64).floor().clamp(0.0, top) as usize;
    let mut out = Vec::with_capacity(4 * columns + 4);
    let mut start = 0;
    while start < points.len() {
        let c = column(points[start].0);
        let end = (start..points.len())
            .find(|&i| column(points[i].0) != c)
            .unwrap_or(points.len());
        let group = &points[start..end];
        let (mut lo, mut hi) = (0, 0);
        for (k, p) in group.iter().enumerate() {
            if p.1 < group[lo].1 {
                lo = k;
            }
            if p.1 > group[hi].1 {
                hi = k;
            }
        }
        let mut keep = [0, lo, hi, group.len() - 1];
        keep.sort_unstable();
        let mut last = None;
        for k in keep {
            if last != Some(k) {
                out.push(group[k]);
                last = Some(k);
            }
        }
        start = end;
    }
    out
}

/// The band between the lowest and highest of `points` (in increasing `x`) in each of
/// `columns` pixel columns spanning `x0..x1`, as polygons: each one the columns' highest
/// values at their centres left to right, then their lowest right to left. A new polygon
/// starts where one of `breaks` (spans `(a, b)` of `x`, e.g. outages) lies between two
/// neighbouring columns' points; a polygon of one column is half a column wide on each side.
///
/// ```
/// use seqsmooth_cli::plot::decimate::envelope;
/// let pts: Vec<(f64, f64)> = (0..100).map(|i| (i as f64, (i % 2) as f64)).collect();
/// let polys = envelope(&pts, (0.0, 100.0), 10, &[(49.0, 50.0)]);
/// assert_eq!(polys.len(), 2);
/// // Columns 0-4 then 5-9: the highest value 1, the lowest 0, at the column centres.
/// assert_eq!(polys[0].first(), Some(&(5.0, 1.0)));
/// assert_eq!(polys[0].last(), Some(&(5.0, 0.0)));
/// ```
pub fn envelope(
    points: &[(f64, f64)],
    (x0, x1): (f64, f64),
    columns: usize,
    breaks: &[(f64, f64)],
) -> Vec<Vec<(f64, f64)>> {
    let span = x1 - x0;
    if points.is_empty() || !(span.is_finite() && span > 0.0) || columns == 0 {
        return Vec::new();
    }
    let width = span / columns as f64;
    let top = (columns - 1) as f64;
    let column = |x: f64| ((x - x0) / width).floor().clamp(0.0, top) as usize;
    // Per occupied column: its index, lowest, highest, first and last x.
    let mut cols: Vec<(usize, f64, f64, f64, f64)> = Vec::new();
    for &(x, y) in points {
        let c = column(x);
        match cols.last_mut() {
            Some(last) if last.0 == c => {
                last.1 = last.1.min(y);
                last.2 = last.2.max(y);
                last.4 = x;
            }
            _ => cols.push((c, y, y, x, x)),
        }
    }
    let broken = |a: &(usize, f64, f64, f64, f64), b: &(usize, f64, f64, f64, f64)| {
        breaks.iter().any(|&(s, e)| a.4 <= s && e <= b.3)
    };
    let centre = |c: usize| x0 + (c as f64 + 0.5) * width;
    let mut out = Vec::new();
    let mut start = 0;
    for i in 1..=cols.len() {
        if i < cols.len() && !broken(&cols[i - 1], &cols[i]) {
            continue;
        }
        let run = &cols[start..i];
        let mut xs: Vec<f64> = run.iter().map(|c| centre(c.0)).collect();
        let (mut hi, mut lo): (Vec<f64>, Vec<f64>) = run.iter().map(|c| (c.2, c.1)).unzip();
        if run.len() == 1 {
            xs = vec![xs[0] - 0.5 * width, xs[0] + 0.5 * width];
            hi.push(hi[0]);
            lo.push(lo[0]);
        }
        let mut poly: Vec<(f64, f64)> = xs.iter().copied().zip(hi).collect();
        poly.extend(xs.iter().copied().zip(lo).rev());
        out.push(poly);
        start = i;
    }
    out
}

/// A systematic sample of a stream: the items whose index is a multiple of the stride, which
/// starts at 1 and doubles (dropping every other item held) whenever more than the capacity
/// are held. Every item is kept while the stream is no longer than the capacity.
///
/// ```
/// use seqsmooth_cli::plot::decimate::Stride;
/// let mut s = Stride::new(4);
/// for i in 0..10u64 {
///     s.push(i, i);
/// }
/// let kept: Vec<u64> = s.items().iter().map(|p| p.1).collect();
/// assert_eq!(kept, vec![0, 4, 8]);
/// ```
#[derive(Clone, Debug)]
pub struct Stride<T> {
    capacity: usize,
    stride: u64,
    items: Vec<(u64, T)>,
}

impl<T> Stride<T> {
    /// An empty sample holding at most `capacity` items (at least 1).
    pub fn new(capacity: usize) -> Self {
        Stride {
            capacity: capacity.max(1),
            stride: 1,
            items: Vec::new(),
        }
    }

    /// Whether the item of index `idx` would be kept (to build it only then).
    pub fn wants(&self, idx: u64) -> bool {
        idx.is_multiple_of(self.stride)
    }

    /// Offers the item of index `idx` (indices increase from call to call).
    pub fn push(&mut self, idx: u64, item: T) {
        if !self.wants(idx) {
            return;
        }
        self.items.push((idx, item));
        while self.items.len() > self.capacity {
            self.stride *= 2;
            let stride = self.stride;
            self.items.retain(|(i, _)| i.is_multiple_of(stride));
        }
    }

    /// The items kept, with their indices, in the order offered.
    pub fn items(&self) -> &[(u64, T)] {
        &self.items
    }

    /// The items kept, with their indices.
    pub fn into_items(self) -> Vec<(u64, T)> {
        self.items
    }
}

/// The row holding a channel's lowest or highest value in a bin.
#[derive(Clone, Copy, Debug)]
struct Extreme {
    value: f64,
    row: u64,
}

/// One time bin of a [`Reducer`]: its first and last row, the rows holding each channel's
/// extremes, and the largest step between rows that ends in it.
#[derive(Clone, Debug)]
struct Bin<R> {
    first: (u64, R),
    /// The last row, when it is not the first.
    last: Option<(u64, R)>,
    lo: Vec<Option<Extreme>>,
    hi: Vec<Option<Extreme>>,
    /// Rows other than the first and last that hold an extreme (and a few that did).
    kept: Vec<(u64, R)>,
    step: Option<(f64, f64)>,
    /// What [`Reducer::weigh`] added to the bin.
    weight: f64,
}

impl<R> Bin<R> {
    fn new(idx: u64, row: R, values: &[f64]) -> Self {
        let at = |v: &f64| {
            v.is_finite().then_some(Extreme {
                value: *v,
                row: idx,
            })
        };
        let ext: Vec<Option<Extreme>> = values.iter().map(at).collect();
        Bin {
            first: (idx, row),
            last: None,
            lo: ext.clone(),
            hi: ext,
            kept: Vec::new(),
            step: None,
            weight: 0.0,
        }
    }

    fn holds(&self, idx: u64) -> bool {
        let is = |e: &Option<Extreme>| e.is_some_and(|e| e.row == idx);
        self.lo.iter().chain(&self.hi).any(is)
    }

    /// Takes the row `idx` with its channel `values` (NaN: none) as the bin's last.
    fn add(&mut self, idx: u64, row: R, values: &[f64]) {
        for (j, &v) in values.iter().enumerate().filter(|(_, v)| v.is_finite()) {
            let e = Some(Extreme { value: v, row: idx });
            if self.lo[j].is_none_or(|x| v < x.value) {
                self.lo[j] = e;
            }
            if self.hi[j].is_none_or(|x| v > x.value) {
                self.hi[j] = e;
            }
        }
        if let Some(old) = self.last.replace((idx, row)) {
            if self.holds(old.0) {
                self.kept.push(old);
            }
        }
        if self.kept.len() > 2 * self.lo.len() + 8 {
            self.prune();
        }
    }

    fn prune(&mut self) {
        let (lo, hi) = (&self.lo, &self.hi);
        let holds = |idx: u64| lo.iter().chain(hi).any(|e| e.is_some_and(|e| e.row == idx));
        self.kept.retain(|r| holds(r.0));
    }

    /// The bin covering `self` then `next`.
    fn merge(mut self, next: Bin<R>) -> Bin<R> {
        let pick = |a: Option<Extreme>, b: Option<Extreme>, lower: bool| match (a, b) {
            (Some(x), Some(y)) if (y.value < x.value) == lower && y.value != x.value => Some(y),
            (None, y) => y,
            (x, _) => x,
        };
        for j in 0..self.lo.len() {
            self.lo[j] = pick(self.lo[j], next.lo[j], true);
            self.hi[j] = pick(self.hi[j], next.hi[j], false);
        }
        self.step = match (self.step, next.step) {
            (Some(a), Some(b)) if b.1 - b.0 > a.1 - a.0 => Some(b),
            (None, b) => b,
            (a, _) => a,
        };
        self.weight += next.weight;
        self.kept.extend(self.last.take());
        match next.last {
            Some(last) => {
                self.kept.push(next.first);
                self.kept.extend(next.kept);
                self.last = Some(last);
            }
            // A bin of one row: its first is its last.
            None => self.last = Some(next.first),
        }
        self.prune();
        self
    }
}

/// Streaming per-bin min/max decimation of rows in increasing time (see the module docs).
///
/// ```
/// use seqsmooth_cli::plot::decimate::Reducer;
/// // 10⁵ rows of a sawtooth into 100 bins: the first and last rows, and each bin's peak.
/// let mut r = Reducer::new(100);
/// for i in 0..100_000u64 {
///     let v = (i % 1000) as f64;
///     r.push(i, i as f64, i, &[v]);
/// }
/// let kept = r.finish();
/// assert!(kept.rows.len() <= 4 * 100);
/// assert!(kept.rows.iter().any(|&(_, i)| i == 999) && kept.rows[0].1 == 0);
/// assert_eq!(kept.rows.last().map(|r| r.1), Some(99_999));
/// ```
#[derive(Clone, Debug)]
pub struct Reducer<R> {
    capacity: usize,
    origin: Option<f64>,
    /// The bins' width; 0 until the second row.
    width: f64,
    bins: Vec<Option<Bin<R>>>,
    previous: Option<f64>,
    /// The bin of the last row pushed.
    current: usize,
}

/// What a [`Reducer`] kept.
#[derive(Clone, Debug)]
pub struct Reduced<R> {
    /// The rows kept, with their indices, in order.
    pub rows: Vec<(u64, R)>,
    /// Per bin, the largest step `(from, to)` between consecutive rows ending in it.
    pub steps: Vec<(f64, f64)>,
    /// The bins' final width.
    pub width: f64,
    /// Per bin with a weight ([`Reducer::weigh`]): its span `(from, to)` and weight.
    pub weights: Vec<(f64, f64, f64)>,
}

impl<R> Reducer<R> {
    /// A reducer of `capacity` bins (at least 2; even).
    pub fn new(capacity: usize) -> Self {
        let capacity = capacity.max(2).next_multiple_of(2);
        Reducer {
            capacity,
            origin: None,
            width: 0.0,
            bins: (0..capacity).map(|_| None).collect(),
            previous: None,
            current: 0,
        }
    }

    /// The bins' current width (0 before the second row).
    pub fn width(&self) -> f64 {
        self.width
    }

    /// Takes row `idx` at time `t` (after the previous row's) with the values of its drawn
    /// channels (the same channels for every row; NaN where a row has none).
    pub fn push(&mut self, idx: u64, t: f64, row: R, values: &[f64]) {
        let origin = *self.origin.get_or_insert(t);
        if self.width == 0.0 && t > origin {
            self.width = t - origin;
        }
        while self.width > 0.0 && t - origin >= self.capacity as f64 * self.width {
            self.halve();
        }
        let b = if self.width > 0.0 {
            (((t - origin) / self.width).floor() as usize).min(self.capacity - 1)
        } else {
            0
        };
        let step = self.previous.replace(t).map(|p| (p, t));
        self.current = b;
        match &mut self.bins[b] {
            Some(bin) => bin.add(idx, row, values),
            slot => *slot = Some(Bin::new(idx, row, values)),
        }
        if let (Some(bin), Some(s)) = (&mut self.bins[b], step) {
            if bin.step.is_none_or(|m| s.1 - s.0 > m.1 - m.0) {
                bin.step = Some(s);
            }
        }
    }

    /// Merges the bins pairwise and doubles their width.
    fn halve(&mut self) {
        let old = std::mem::take(&mut self.bins);
        let mut it = old.into_iter();
        while let (Some(a), Some(b)) = (it.next(), it.next()) {
            self.bins.push(match (a, b) {
                (Some(a), Some(b)) => Some(a.merge(b)),
                (a, b) => a.or(b),
            });
        }
        self.bins.resize_with(self.capacity, || None);
        self.width *= 2.0;
        self.current /= 2;
    }

    /// Adds `amount` to the weight of the last row's bin (e.g. the time it spends under a
    /// flag, to shade each bin by its share).
    pub fn weigh(&mut self, amount: f64) {
        if let Some(bin) = &mut self.bins[self.current] {
            bin.weight += amount;
        }
    }

    /// The rows kept, the largest steps, the bins' width.
    pub fn finish(self) -> Reduced<R> {
        let mut rows = Vec::new();
        let mut steps = Vec::new();
        let mut weights = Vec::new();
        let origin = self.origin.unwrap_or(0.0);
        for (b, bin) in self.bins.into_iter().enumerate() {
            let Some(mut bin) = bin else { continue };
            bin.prune();
            steps.extend(bin.step);
            if bin.weight > 0.0 {
                let from = origin + b as f64 * self.width;
                weights.push((from, from + self.width, bin.weight));
            }
            let start = rows.len();
            rows.push(bin.first);
            rows.extend(bin.kept);
            rows.extend(bin.last);
            rows[start..].sort_by_key(|r| r.0);
        }
        rows.dedup_by_key(|r| r.0);
        Reduced {
            rows,
            steps,
            width: self.width,
            weights,
        }
    }
}
