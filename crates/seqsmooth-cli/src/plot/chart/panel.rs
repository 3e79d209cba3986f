//! The panels of a plot: what each one shows of a [`Track`] (relative to the estimate, the
//! truth or nothing) and its value range.

use super::track::{quantile, samples_at_lead, Sample, Track};
use super::{padded, widen, Key, Layout};

/// What a panel shows.
#[derive(Clone, Copy, PartialEq)]
pub(super) enum What {
    /// The estimate of derivative `k`, with the samples for `k = 0` and the truth.
    Derivative(usize),
    /// The error `d_k − truth_k` about zero (the truth), with the samples' `y − truth` for
    /// `k = 0`.
    Error(usize),
    /// `y − d0` about zero (the estimate), with `truth − d0`.
    Residual,
}

/// One panel's y data, relative to the estimate (residual panel) or the truth (error panel).
pub(super) struct PanelData {
    pub(super) label: String,
    /// Points: (time, value, rejected).
    pub(super) points: Vec<(f64, f64, bool)>,
    /// The row of each point.
    pub(super) point_rows: Vec<usize>,
    /// Whether each row is past the start-up (the relative panels' range is of those only).
    pub(super) settled: Vec<bool>,
    /// Whether each row is in the sample the ranges' quantiles are taken over.
    pub(super) sampled: Vec<bool>,
    /// The centre line (the estimate, its error, or zero) by row.
    pub(super) line: Vec<Option<f64>>,
    /// The ±3σ half-width by row.
    pub(super) band: Vec<Option<f64>>,
    /// The truth (zero in an error panel, truth − estimate in the residual panel) by row.
    pub(super) truth: Vec<Option<f64>>,
    /// What the truth line is, for the legend.
    pub(super) truth_key: Key,
    /// What the centre line is, for the note on values beyond the axis.
    pub(super) line_name: &'static str,
    /// ±3σ noise lines by row.
    pub(super) noise: Vec<Option<f64>>,
    /// The x offset of the line, band and truth (the lead), and of the truth alone.
    pub(super) shift: f64,
    pub(super) truth_shift: f64,
    pub(super) range: (f64, f64),
    /// Clip points beyond the range to the edge (residual and error panels).
    pub(super) clip_points: bool,
}

/// The panel showing `what` of `track`; `at[i]` is the sample at row `i`'s estimate time.
fn panel(track: &Track, what: What, label: &str, at: &[Option<Sample>]) -> PanelData {
    let n = track.t.len();
    let j = match what {
        What::Derivative(k) | What::Error(k) => k,
        What::Residual => 0,
    };
    let cell = |v: &[Vec<Option<f64>>], i: usize| v.get(j).and_then(|v| v.get(i)).copied()?;
    let truth = |i: usize| track.truth.get(j).and_then(|x| x.get(i)).copied();
    // The sample at row i's estimate time, and the value every row's numbers are relative to.
    let own = |i: usize| at.get(i).and_then(Option::as_ref);
    let truth_at = |i: usize| own(i).and_then(|s| s.truth.get(j).copied().flatten());
    let base = |i: usize| match what {
        What::Derivative(_) => Some(0.0),
        What::Error(_) => truth_at(i),
        What::Residual => own(i).and(cell(&track.d, i)),
    };
    let rejected = |i: usize| track.rejected.get(i) == Some(&true);
    // Each point with its row: (row, time, value, rejected).
    let points: Vec<(usize, (f64, f64, bool))> = match what {
        What::Derivative(0) => (0..n)
            .map(|i| (i, (track.t[i], track.y[i], rejected(i))))
            .collect(),
        What::Error(0) => (0..n)
            .filter_map(|i| truth(i).map(|x| (i, (track.t[i], track.y[i] - x, rejected(i)))))
            .collect(),
        What::Residual => (0..n)
            .filter_map(|i| {
                let s = own(i)?;
                base(i).map(|b| (i, (s.t, s.y - b, s.rejected)))
            })
            .collect(),
        _ => Vec::new(),
    };
    let (point_rows, points) = points.into_iter().unzip();
    // The rows after the start-up (all of them when none is marked settled), and of those
    // the rows the quantiles are taken over.
    let settled = if track.settled.len() == n && track.settled.contains(&true) {
        track.settled.clone()
    } else {
        vec![true; n]
    };
    let sampled = if track.sampled.len() == n {
        track.sampled.clone()
    } else {
        vec![true; n]
    };
    let rows = |f: &dyn Fn(usize, f64) -> Option<f64>| -> Vec<Option<f64>> {
        (0..n).map(|i| base(i).and_then(|b| f(i, b))).collect()
    };
    let relative = what != What::Derivative(j);
    let noise = |i: usize| {
        track
            .noise
            .get(i)
            .copied()
            .flatten()
            .filter(|_| relative && j == 0)
    };
    let mut p = PanelData {
        label: label.to_string(),
        points,
        point_rows,
        settled,
        sampled,
        line: rows(&|i, b| cell(&track.d, i).map(|d| d - b)),
        band: rows(&|i, _| cell(&track.s, i).map(|s| 3.0 * s)),
        truth: match what {
            What::Derivative(_) => (0..n).map(truth).collect(),
            What::Error(_) => rows(&|_, _| Some(0.0)),
            What::Residual => rows(&|i, b| truth_at(i).map(|x| x - b)),
        },
        truth_key: if what == What::Residual {
            Key::TruthError
        } else {
            Key::Truth
        },
        line_name: match what {
            What::Error(_) => "estimate − truth",
            _ => "estimate",
        },
        noise: (0..n).map(|i| noise(i).map(|s| 3.0 * s)).collect(),
        shift: track.lead,
        truth_shift: if relative { track.lead } else { 0.0 },
        range: (0.0, 1.0),
        clip_points: relative,
    };
    p.range = if p.clip_points {
        p.relative_range()
    } else {
        p.derivative_range()
    };
    p
}

impl PanelData {
    /// Every sample, the truth, and the central 98% of the estimates (start-up transients of
    /// the higher derivatives would squash the panel).
    fn derivative_range(&self) -> (f64, f64) {
        let (line, band) = (&self.line, &self.band);
        let mut range = None;
        widen(&mut range, self.points.iter().map(|p| p.1));
        widen(&mut range, self.truth.iter().flatten().copied());
        let sampled = |v: &[Option<f64>]| -> Vec<f64> {
            v.iter()
                .zip(&self.sampled)
                .filter(|r| *r.1)
                .filter_map(|r| *r.0)
                .filter(|v| v.is_finite())
                .collect()
        };
        let est = sampled(line);
        if let (Some(lo), Some(hi)) = (quantile(est.clone(), 0.01), quantile(est, 0.99)) {
            widen(&mut range, [lo, hi]);
        }
        // The band where it is no wider than the spread of the panel (not at start-up).
        if let Some((lo, hi)) = range {
            let span = (hi - lo).max(f64::MIN_POSITIVE);
            if let Some(h) = quantile(sampled(band), 0.9) {
                if h < 0.25 * span {
                    for (l, b) in line.iter().zip(band) {
                        if let (Some(l), Some(b)) = (l, b) {
                            if *b <= h {
                                widen(&mut range, [l - b, l + b]);
                            }
                        }
                    }
                }
            }
        }
        padded(range.unwrap_or((0.0, 1.0)), 0.05)
    }

    /// Symmetric: the 99th percentile of |value| of the accepted samples, every rejected one
    /// up to twice that, the ±3σ noise and the settled band, the truth's and the line's
    /// distance from zero; of the rows past the start-up.
    fn relative_range(&self) -> (f64, f64) {
        let settled = |k: &usize| self.settled[*k] && self.sampled[*k];
        let points = || {
            let rows = self.point_rows.iter();
            rows.zip(&self.points)
                .filter(|(k, _)| settled(k))
                .map(|(_, p)| p)
        };
        let rows = |v: &[Option<f64>]| -> Vec<f64> {
            v.iter()
                .zip(self.settled.iter().zip(&self.sampled))
                .filter(|r| *r.1 .0 && *r.1 .1)
                .filter_map(|r| *r.0)
                .map(f64::abs)
                .collect()
        };
        let q = |v: Vec<f64>, p| quantile(v, p).unwrap_or(0.0);
        let mut r = q(points().filter(|p| !p.2).map(|p| p.1.abs()).collect(), 0.99)
            .max(q(rows(&self.noise), 0.9))
            .max(q(rows(&self.band), 0.9))
            .max(q(rows(&self.truth), 0.99))
            .max(q(rows(&self.line), 0.99));
        let cap = 2.0 * r;
        let rows = self.point_rows.iter().zip(&self.points);
        for (_, p) in rows.filter(|(k, p)| self.settled[**k] && p.2) {
            r = r.max(p.1.abs().min(cap));
        }
        if r <= 0.0 || !r.is_finite() {
            r = 1.0;
        }
        (-1.08 * r, 1.08 * r)
    }
}

/// The panels of `layout` drawn from `track`, top to bottom.
pub(super) fn panels(track: &Track, layout: &Layout) -> Vec<PanelData> {
    let at = if track.at.len() == track.t.len() {
        track.at.clone()
    } else {
        let truth = |j: usize| {
            let col = |x: &Vec<f64>| x.get(j).copied();
            track.truth.iter().map(col).collect()
        };
        let sample = |j: usize| Sample {
            t: track.t[j],
            y: track.y[j],
            rejected: track.rejected.get(j) == Some(&true),
            truth: truth(j),
        };
        let at = samples_at_lead(&track.t, track.lead).into_iter();
        at.map(|j| j.map(sample)).collect()
    };
    let errors = layout.errors.iter().map(|(k, l)| (What::Error(*k), l));
    let derivatives = layout.panels.iter().map(|(k, l)| (What::Derivative(*k), l));
    let residuals = layout.residual_label.iter().map(|l| (What::Residual, l));
    errors
        .chain(derivatives)
        .chain(residuals)
        .map(|(what, label)| panel(track, what, label, &at))
        .collect()
}
