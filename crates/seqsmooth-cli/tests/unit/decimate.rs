//! Unit tests of `decimate`: per-pixel min/max decimation keeps the shape of the series.

use rand::{Rng, SeedableRng};
use seqsmooth_cli::decimate::min_max;

/// The pixel column of `x` as `min_max` defines it.
fn column(x: f64, (x0, x1): (f64, f64), columns: usize) -> usize {
    ((x - x0) / (x1 - x0) * columns as f64)
        .floor()
        .clamp(0.0, (columns - 1) as f64) as usize
}

/// A random series: `n` increasing times (irregular steps), a random walk with spikes.
fn series(rng: &mut impl Rng, n: usize) -> Vec<(f64, f64)> {
    let (mut t, mut y) = (rng.gen_range(-1e3..1e3), 0.0);
    (0..n)
        .map(|_| {
            t += rng.gen_range(1e-3..1.0);
            y += rng.gen_range(-1.0..1.0) + if rng.gen_bool(0.01) { 50.0 } else { 0.0 };
            (t, y)
        })
        .collect()
}

/// Every local maximum and minimum of the data (a sample above or below both neighbours)
/// that is the largest or smallest of its pixel column survives, every column keeps its
/// highest and lowest value and its first and last sample, the first and last sample of the
/// series are kept, the kept points are in time order, and there are at most four per column.
#[test]
fn keeps_every_extreme_of_each_pixel_column() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(20121969);
    for case in 0..300 {
        let n = rng.gen_range(2..20_000);
        let columns = rng.gen_range(1..2_000);
        let pts = series(&mut rng, n);
        let span = (
            pts[0].0 - rng.gen_range(0.0..5.0),
            pts[n - 1].0 + rng.gen_range(0.0..5.0),
        );
        let kept = min_max(&pts, span, columns);
        let what = format!("case {case}: {n} points, {columns} columns");
        assert_eq!(kept[0], pts[0], "{what}: first sample");
        assert_eq!(kept[kept.len() - 1], pts[n - 1], "{what}: last sample");
        assert!(
            kept.windows(2).all(|w| w[0].0 < w[1].0),
            "{what}: time order"
        );
        assert!(
            kept.iter().all(|p| pts.contains(p)),
            "{what}: only data points"
        );
        if n <= columns {
            assert_eq!(kept, pts, "{what}: no more points than columns: all kept");
            continue;
        }
        let mut per_column = vec![Vec::new(); columns];
        for &p in &pts {
            per_column[column(p.0, span, columns)].push(p);
        }
        let mut kept_per_column = vec![Vec::new(); columns];
        for &p in &kept {
            kept_per_column[column(p.0, span, columns)].push(p);
        }
        for (c, group) in per_column.iter().enumerate().filter(|(_, g)| !g.is_empty()) {
            let hi = group.iter().map(|p| p.1).fold(f64::MIN, f64::max);
            let lo = group.iter().map(|p| p.1).fold(f64::MAX, f64::min);
            let kept = &kept_per_column[c];
            let has = |v: f64| kept.iter().any(|p| p.1 == v);
            assert!(has(hi) && has(lo), "{what}: column {c} keeps {lo}..{hi}");
            assert!(
                kept.contains(&group[0]),
                "{what}: column {c}'s first sample"
            );
            assert!(
                kept.contains(&group[group.len() - 1]),
                "{what}: column {c}'s last sample"
            );
            assert!(kept.len() <= 4, "{what}: column {c}: {} points", kept.len());
        }
        // Local extremes of the data: each one that is the extreme of its column is kept, and
        // none is lost from view: its value lies within the kept range of its column.
        for i in 1..n - 1 {
            let (a, b, c) = (pts[i - 1].1, pts[i].1, pts[i + 1].1);
            if (b > a && b > c) || (b < a && b < c) {
                let in_col = kept_per_column[column(pts[i].0, span, columns)].iter();
                let (lo, hi) =
                    in_col.fold((f64::MAX, f64::MIN), |(l, h), p| (l.min(p.1), h.max(p.1)));
                assert!(
                    lo <= b && b <= hi,
                    "{what}: local extreme {i} ({b}) outside {lo}..{hi}"
                );
            }
        }
    }
}

#[test]
fn keeps_everything_when_sparse_or_without_a_span() {
    let pts = vec![(0.0, 1.0), (1.0, -1.0), (2.0, 3.0)];
    assert_eq!(min_max(&pts, (0.0, 2.0), 3), pts);
    assert_eq!(min_max(&pts, (1.0, 1.0), 1), pts);
    assert_eq!(min_max(&pts, (0.0, f64::INFINITY), 1), pts);
    assert!(min_max(&[], (0.0, 1.0), 10).is_empty());
}

/// One column: its first, lowest, highest and last points in time order.
#[test]
fn one_column_keeps_first_lowest_highest_last() {
    let pts = vec![(0.0, 5.0), (0.1, 9.0), (0.2, 1.0), (0.3, 4.0), (0.4, 6.0)];
    let kept = min_max(&pts, (0.0, 1.0), 1);
    assert_eq!(kept, vec![(0.0, 5.0), (0.1, 9.0), (0.2, 1.0), (0.4, 6.0)]);
}
