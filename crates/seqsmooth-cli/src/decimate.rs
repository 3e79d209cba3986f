//! Per-pixel min/max decimation of a dense series for drawing.
//!
//! A polyline with more points than the plot has pixel columns is drawn as a mess of
//! sub-pixel segments. [`min_max`] keeps, of the points that fall in each pixel column (in
//! time order), the first, the lowest, the highest and the last: at most four per column, so
//! the drawn line is as long as the plot is wide, and every value the column spans is still
//! covered — the envelope, every local extreme and the joins between columns are kept exactly.

/// The points of `points` (in increasing `x`) kept when drawn across `columns` pixel columns
/// spanning `x0..x1`: per column, its first, lowest, highest and last point, in their order.
/// With no more points than columns (or no usable span) every point is kept.
///
/// The column of `x` is `⌊(x − x0)/(x1 − x0) · columns⌋`, clamped to the plot.
///
/// ```
/// use seqsmooth_cli::decimate::min_max;
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
