//! Unit tests of `plot::decimate`: per-pixel min/max decimation keeps the shape of the series.

use rand::{Rng, SeedableRng};
use seqsmooth_cli::plot::decimate::{envelope, min_max, Reducer, Stride};

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

/// The streaming reducer against the whole series: over 200 random streams (irregular steps,
/// several channels with gaps and spikes, capacities from 2 to 600 bins), every bin of the
/// final width keeps each channel's lowest and highest value of the data in it (exactly, the
/// value and its row), the first and last row of the series, the rows in order, at most
/// 2 + 2·channels rows per bin; the largest step ending in each bin is the data's, and its
/// weight the sum of its rows'.
#[test]
fn reducer_keeps_every_bins_extremes_of_every_channel() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(1969);
    for case in 0..200 {
        let n = rng.gen_range(1..30_000);
        let capacity = rng.gen_range(2..600);
        let channels = rng.gen_range(1..5);
        let mut t = rng.gen_range(-1e6..1e6);
        let mut rows: Vec<(f64, Vec<f64>)> = Vec::with_capacity(n);
        for _ in 0..n {
            t += if rng.gen_bool(0.001) {
                rng.gen_range(10.0..1e3)
            } else {
                rng.gen_range(1e-3..1.0)
            };
            let v = (0..channels)
                .map(|c| {
                    if rng.gen_bool(0.1 * c as f64) {
                        f64::NAN
                    } else {
                        rng.gen_range(-1.0..1.0) + if rng.gen_bool(0.01) { 50.0 } else { 0.0 }
                    }
                })
                .collect();
            rows.push((t, v));
        }
        let mut r = Reducer::new(capacity);
        // A weight of i mod 3 on row i's bin.
        let weight = |i: usize| (i % 3) as f64;
        for (i, (t, v)) in rows.iter().enumerate() {
            r.push(i as u64, *t, i, v);
            r.weigh(weight(i));
        }
        let out = r.finish();
        let what = format!("case {case}: {n} rows, {capacity} bins, {channels} channels");
        let kept: Vec<usize> = out.rows.iter().map(|r| r.1).collect();
        assert_eq!(kept[0], 0, "{what}: first row");
        assert_eq!(kept[kept.len() - 1], n - 1, "{what}: last row");
        assert!(kept.windows(2).all(|w| w[0] < w[1]), "{what}: order");
        assert!(
            out.rows.iter().all(|r| r.0 as usize == r.1),
            "{what}: indices"
        );
        let origin = rows[0].0;
        let bin = |t: f64| {
            if out.width == 0.0 {
                0
            } else {
                ((((t - origin) / out.width).floor()) as usize)
                    .min(capacity.next_multiple_of(2) - 1)
            }
        };
        let bins = capacity.next_multiple_of(2);
        assert!(
            rows[n - 1].0 - origin < bins as f64 * out.width || n == 1,
            "{what}: the bins cover the range"
        );
        let mut per_bin = vec![Vec::new(); bins];
        for (i, (t, _)) in rows.iter().enumerate() {
            per_bin[bin(*t)].push(i);
        }
        let mut kept_per_bin = vec![Vec::new(); bins];
        for &i in &kept {
            kept_per_bin[bin(rows[i].0)].push(i);
        }
        let mut steps = Vec::new();
        for (b, all) in per_bin.iter().enumerate().filter(|(_, a)| !a.is_empty()) {
            let k = &kept_per_bin[b];
            assert!(
                k.len() <= 2 + 2 * channels,
                "{what}: bin {b} keeps {}",
                k.len()
            );
            for c in 0..channels {
                let vals = |ix: &[usize]| -> (f64, f64) {
                    ix.iter()
                        .map(|&i| rows[i].1[c])
                        .filter(|v| v.is_finite())
                        .fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(v), h.max(v)))
                };
                assert_eq!(vals(all), vals(k), "{what}: bin {b}, channel {c}");
            }
            let ends = all
                .iter()
                .filter(|&&i| i > 0)
                .map(|&i| (rows[i - 1].0, rows[i].0));
            if let Some(s) = ends.max_by(|a, b| (a.1 - a.0).total_cmp(&(b.1 - b.0))) {
                steps.push(s);
            }
        }
        assert_eq!(out.steps, steps, "{what}: largest steps");
        let weights: Vec<(f64, f64, f64)> = per_bin
            .iter()
            .enumerate()
            .map(|(b, all)| {
                let from = origin + b as f64 * out.width;
                (from, from + out.width, all.iter().map(|&i| weight(i)).sum())
            })
            .filter(|w| w.2 > 0.0)
            .collect();
        assert_eq!(out.weights, weights, "{what}: weights");
        if n > 4 * capacity {
            assert!(kept.len() < n, "{what}: decimated");
        }
    }
}

/// The systematic sample: every item while they fit, then every 2^j-th, never more than the
/// capacity and never fewer than half of it.
#[test]
fn stride_sample_is_systematic_and_bounded() {
    for cap in [1, 2, 7, 64, 1000] {
        for n in [0u64, 1, 5, 63, 64, 65, 1000, 12_345] {
            let mut s = Stride::new(cap);
            for i in 0..n {
                s.push(i, i * 10);
            }
            let items = s.items();
            assert!(items.len() <= cap, "cap {cap}, n {n}");
            if n as usize <= cap {
                assert_eq!(items.len(), n as usize);
            } else {
                assert!(2 * items.len() >= cap, "cap {cap}, n {n}: {}", items.len());
                let stride = items
                    .get(1)
                    .map_or(n.next_power_of_two(), |b| b.0 - items[0].0);
                assert!(stride.is_power_of_two());
                assert!(items
                    .iter()
                    .enumerate()
                    .all(|(k, it)| it.0 == k as u64 * stride));
            }
            assert!(items.iter().all(|it| it.1 == it.0 * 10));
        }
    }
}

/// The envelope of a dense cloud: per column its lowest and highest value, one polygon per
/// stretch between breaks, no polygon point inside a break.
#[test]
fn envelope_spans_each_columns_values_and_breaks_at_gaps() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    let mut pts: Vec<(f64, f64)> = Vec::new();
    let mut x = 0.0;
    while x < 1000.0 {
        x += rng.gen_range(0.01..0.2);
        if (400.0..430.0).contains(&x) {
            continue;
        }
        pts.push((x, rng.gen_range(-3.0..3.0)));
    }
    // The gap as an outage is: from the last point before to the first after.
    let after = pts.iter().position(|p| p.0 >= 430.0).unwrap();
    let gap = (pts[after - 1].0, pts[after].0);
    let polys = envelope(&pts, (0.0, 1000.0), 100, &[gap]);
    assert_eq!(envelope(&pts, (0.0, 1000.0), 100, &[]).len(), 1);
    assert_eq!(polys.len(), 2);
    for poly in &polys {
        let half = poly.len() / 2;
        let (top, bottom) = poly.split_at(half);
        // the top left to right, the bottom right to left, above it
        assert!(top.windows(2).all(|w| w[0].0 < w[1].0));
        for (a, b) in top.iter().zip(bottom.iter().rev()) {
            assert_eq!(a.0, b.0);
            assert!(a.1 >= b.1);
        }
        assert!(poly.iter().all(|p| !(400.0..430.0).contains(&p.0)));
    }
    // Column 3 (x in 30..40): its lowest and highest sample.
    let col: Vec<f64> = pts
        .iter()
        .filter(|p| (30.0..40.0).contains(&p.0))
        .map(|p| p.1)
        .collect();
    let hi = col.iter().copied().fold(f64::MIN, f64::max);
    let lo = col.iter().copied().fold(f64::MAX, f64::min);
    assert!(polys[0].contains(&(35.0, hi)) && polys[0].contains(&(35.0, lo)));
    assert!(envelope(&[], (0.0, 1.0), 10, &[]).is_empty());
}
