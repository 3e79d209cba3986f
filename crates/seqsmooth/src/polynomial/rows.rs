//! The row runner: a batch of samples through an [`AnyFilter`] to output rows, and the one rule
//! for what a row holds when there is no estimate — the rows of `seqsmooth filter` (and so of
//! `smooth` and `demo`), of Python's `update_many` and of `filter_frame`.
//!
//! Row `i` holds `d0..dM`, the derivatives `x, x', …, x^(m)` at `t_i + lead` from the samples up
//! to `i`; with σ their 1σ `s0..sM` (the square roots of the covariance's diagonal, Morrison
//! (5.5.22) carried to the time); then, with [`RowLayout::trailing`], the kind's cells
//! ([`AnyFilter::trailing_columns`]: fixed memory the rows in the window; the automatic filter
//! the noise σ in use, the outlier and misfit flags as 0/1 and the estimated bias of `d0` that
//! `s0` includes; then [`UPDATE_CELLS`] cells: the final outlier decisions the update made
//! ([`DECISION_CELLS`]) and the degree in use, [`degree_in_use`]).
//!
//! The rule: a row is NaN (an empty cell) where there is no number yet — before the filter has
//! the samples its fit needs (`m + 1`, fixed memory its window), above the degree an estimate
//! has (the automatic filter's while its degree settles), and while the automatic filter
//! withholds its estimate (its noise σ not estimated yet: no estimate without its σ). Once
//! the fit is determined, a row without an estimate is refused ([`Error::NotDetermined`]:
//! with fading memory a discount `θ^(step/τ)` that underflows) and so is a number beyond the
//! double range ([`Error::EstimateOutOfRange`] naming its column); no row holds an infinity.
//! A refusal is [`Error::InBatch`] with its row's index, the rows before it written.

use crate::error::{Error, Param};
use crate::model::PolynomialState;
use crate::numeric::sigma::std_dev;
use crate::polynomial::filter::{check_rows, no_noise_sigma, PolynomialFilter, RowRule};
use crate::polynomial::spec::{AnyFilter, Inner};
use std::collections::VecDeque;

/// The cells of the rows [`AnyFilter::run_rows`] writes and checks at a time (128 KiB: the
/// block's rows are still in the core's cache when they are checked).
const BLOCK_CELLS: usize = 16_384;

/// The automatic filter's first cells after its written ones (with [`RowLayout::trailing`]):
/// how many final outlier decisions the row's update made (on the series' oldest samples still
/// undecided, in order), and their verdicts as bits (`1`: rejected), 32 to a cell, oldest in
/// the lowest bit; read by [`decisions`].
pub const DECISION_CELLS: usize = 3;

/// The automatic filter's cells after its written ones: the [`DECISION_CELLS`], then the degree
/// in use at the row's update (the active degree while it settles; read by
/// [`degree_in_use`]).
pub const UPDATE_CELLS: usize = DECISION_CELLS + 1;

/// The degree in use stored in a row's [`UPDATE_CELLS`] cells (0 where the row holds no
/// update).
///
/// ```
/// use seqsmooth::polynomial::rows::degree_in_use;
/// assert_eq!(degree_in_use(&[1.0, 1.0, 0.0, 2.0]), 2);
/// assert_eq!(degree_in_use(&[f64::NAN; 4]), 0);
/// ```
pub fn degree_in_use(cells: &[f64]) -> usize {
    cells[DECISION_CELLS] as usize
}

/// What a row holds besides `d0..dM`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RowLayout {
    /// The 1σ `s0..sM` after the derivatives.
    pub sigma: bool,
    /// The estimates are at each sample's time plus `lead` (negative: retrodiction).
    pub lead: f64,
    /// The kind's cells after them ([`AnyFilter::trailing_columns`], and the automatic
    /// filter's [`UPDATE_CELLS`]).
    pub trailing: bool,
}

/// The final outlier decisions stored in a row's [`DECISION_CELLS`] cells.
///
/// ```
/// use seqsmooth::polynomial::rows::decisions;
/// assert_eq!(decisions(&[3.0, 5.0, 0.0]), vec![true, false, true]);
/// assert!(decisions(&[f64::NAN; 3]).is_empty()); // no update made
/// ```
pub fn decisions(cells: &[f64]) -> Vec<bool> {
    let bits = cells[1] as u64 | ((cells[2] as u64) << 32);
    (0..cells[0] as usize).map(|i| bits >> i & 1 == 1).collect()
}

/// The rule of the automatic filter's final outlier flags over rows: per series, the rows not
/// finally decided yet, oldest first. Each series' decisions (those of each row's update,
/// [`decisions`] of its [`DECISION_CELLS`], then at the end of the series
/// [`AutomaticFilter::finish`](crate::polynomial::AutomaticFilter::finish)) come in its sample
/// order (the review's interpolation test, Morrison §14.8, §7.13), so each one is the verdict
/// on the series' oldest undecided row. Rows are named by any number the caller chooses
/// (their index among all rows, say); the rows of `seqsmooth filter` and of `filter_frame` are flagged by this rule.
///
/// ```
/// use seqsmooth::polynomial::rows::Undecided;
/// let mut open = Undecided::default();
/// let mut flags = [false; 4];
/// open.push(0, 0, &[], |row, r| flags[row] = r); // series 0, row 0: undecided
/// open.push(1, 1, &[], |row, r| flags[row] = r); // series 1, row 1
/// open.push(0, 2, &[true], |row, r| flags[row] = r); // row 2's update rejects row 0
/// open.push(1, 3, &[], |row, r| flags[row] = r);
/// open.decide(1, &[false, true], |row, r| flags[row] = r); // series 1's finish
/// assert_eq!(flags, [true, false, false, true]); // row 2 still waits
/// ```
#[derive(Clone, Debug, Default)]
pub struct Undecided {
    /// Per series, its undecided rows, oldest first.
    open: Vec<VecDeque<usize>>,
}

impl Undecided {
    /// Row `row` of `series` waits for its decision; then the `decided` verdicts its update made
    /// (this row's included) go to the series' oldest waiting rows, through `apply(row,
    /// rejected)`.
    pub fn push(
        &mut self,
        series: usize,
        row: usize,
        decided: &[bool],
        apply: impl FnMut(usize, bool),
    ) {
        if self.open.len() <= series {
            self.open.resize_with(series + 1, VecDeque::new);
        }
        self.open[series].push_back(row);
        self.decide(series, decided, apply);
    }

    /// The `verdicts` (`true`: rejected) on the oldest waiting rows of `series`, in order, each
    /// given to `apply(row, rejected)`; verdicts beyond the waiting rows are ignored.
    pub fn decide(&mut self, series: usize, verdicts: &[bool], mut apply: impl FnMut(usize, bool)) {
        let Some(open) = self.open.get_mut(series) else {
            return;
        };
        for &rejected in verdicts {
            let Some(row) = open.pop_front() else {
                return;
            };
            apply(row, rejected);
        }
    }

    /// Forgets every waiting row (their flags stay the gate's).
    pub fn clear(&mut self) {
        self.open.clear();
    }
}

/// The decisions `verdicts` (at most 64) in the [`DECISION_CELLS`] cells.
fn store_decisions(verdicts: &[bool], cells: &mut [f64]) {
    let bits = verdicts
        .iter()
        .enumerate()
        .fold(0u64, |b, (i, &r)| b | (u64::from(r) << i));
    cells[0] = verdicts.len() as f64;
    cells[1] = (bits & 0xffff_ffff) as f64;
    cells[2] = (bits >> 32) as f64;
}

impl AnyFilter {
    /// The names of the cells after `d0..dM` and `s0..sM` this kind writes with
    /// [`RowLayout::trailing`].
    pub fn trailing_columns(&self) -> &'static [&'static str] {
        match &self.inner {
            Inner::Expanding(_) | Inner::Fading(_) => &[],
            Inner::Fixed(..) => &["window"],
            Inner::Automatic(_) => &["noise", "outlier", "misfit", "bias"],
        }
    }

    /// The cells of a row of `layout`, the automatic filter's [`UPDATE_CELLS`] included.
    pub fn stride(&self, layout: RowLayout) -> usize {
        let trailing = match (&self.inner, layout.trailing) {
            (_, false) => 0,
            (Inner::Automatic(_), true) => self.trailing_columns().len() + UPDATE_CELLS,
            (_, true) => self.trailing_columns().len(),
        };
        ((self.degree() + 1) << usize::from(layout.sigma)) + trailing
    }

    /// Runs the samples `(t[i], y[i])` and writes row `i` of `out` ([`stride`](Self::stride)
    /// cells each) by the module's rule. The expanding- and fading-memory filters without lead
    /// take the batch kernels ([`PolynomialFilter::update_many_into`], with σ
    /// [`PolynomialFilter::update_many_sigma_into`]); the others a sample at a time, each
    /// estimate from [`try_estimate_at`](PolynomialFilter::try_estimate_at). An error is
    /// [`Error::InBatch`] of its row (a sample refused, or a row's estimate refused), the rows
    /// before it written and the samples before it taken.
    ///
    /// ```
    /// use seqsmooth::polynomial::rows::RowLayout;
    /// use seqsmooth::polynomial::spec::{FilterKind, FilterSpec};
    /// let spec = FilterSpec { window: Some(3), sigma: Some(0.1), ..FilterSpec::new(FilterKind::Fixed, 1) };
    /// let mut f = spec.build()?;
    /// let layout = RowLayout { sigma: true, lead: 0.0, trailing: true };
    /// assert_eq!(f.stride(layout), 5); // d0 d1 s0 s1 window
    /// let mut out = [0.0; 20];
    /// f.run_rows(&[0.0, 1.0, 2.0, 3.0], &[1.0, 3.0, 5.0, 7.0], &mut out, layout)?;
    /// assert!(out[5].is_nan() && out[9] == 2.0); // row 1: the window not full yet
    /// assert!((out[16] - 2.0).abs() < 1e-12 && out[19] == 3.0); // row 3: slope 2
    /// # Ok::<(), seqsmooth::Error>(())
    /// ```
    pub fn run_rows(
        &mut self,
        t: &[f64],
        y: &[f64],
        out: &mut [f64],
        layout: RowLayout,
    ) -> Result<(), Error> {
        let stride = self.stride(layout);
        crate::polynomial::filter::check_batch_lengths(t, y)?;
        crate::polynomial::options::check_lead(layout.lead)?;
        if out.len() != t.len() * stride {
            return Err(Error::InvalidParameter {
                name: Param::RowsLength,
                value: out.len().to_string(),
                reason: format!("{} samples need {} cells", t.len(), t.len() * stride),
            });
        }
        // In blocks, so that each block's check reads the rows while they are in cache (the
        // filters give the same numbers in any pieces).
        let block = (BLOCK_CELLS / stride).max(1);
        for (k, (ts, (ys, rows))) in t
            .chunks(block)
            .zip(y.chunks(block).zip(out.chunks_mut(block * stride)))
            .enumerate()
        {
            let offset = k * block;
            self.run_block(ts, ys, rows, layout, stride)
                .map_err(|e| match e {
                    Error::InBatch { index, source } => Error::InBatch {
                        index: index + offset,
                        source,
                    },
                    e => e,
                })?;
        }
        Ok(())
    }

    /// [`run_rows`](Self::run_rows) on one block, the indices of its errors the block's.
    fn run_block(
        &mut self,
        t: &[f64],
        y: &[f64],
        out: &mut [f64],
        layout: RowLayout,
        stride: usize,
    ) -> Result<(), Error> {
        let before = self.rows;
        let written = self.write_rows(t, y, out, layout, stride);
        // The rows up to a refused sample, or up to the row refused while writing, are taken;
        // those before it are checked first, so that the earliest refusal is the batch's.
        let done = ((self.rows - before) as usize).min(match &written {
            Err(Error::InBatch { index, .. }) => *index,
            _ => t.len(),
        });
        // The batch σ kernels check their rows by this rule as they write them, while they
        // are in cache ([`PolynomialFilter::update_many_sigma_into`]): not twice.
        if !self.sigma_kernel_writes(layout) {
            self.check_rows(&out[..done * stride], stride, layout, before)?;
        }
        written
    }

    /// Whether [`write_rows`](Self::write_rows) runs the batch σ kernel
    /// ([`PolynomialFilter::update_many_sigma_into`] of the expanding- and fading-memory
    /// filters), which checks its rows by the module's rule (the same [`RowRule`]: every cell
    /// of a determined row a number, a row without derivatives refused as not determined).
    fn sigma_kernel_writes(&self, layout: RowLayout) -> bool {
        let direct = matches!(self.inner, Inner::Expanding(_) | Inner::Fading(_));
        direct && layout.sigma && layout.lead == 0.0
    }

    /// The rows' numbers, before their check.
    fn write_rows(
        &mut self,
        t: &[f64],
        y: &[f64],
        out: &mut [f64],
        layout: RowLayout,
        stride: usize,
    ) -> Result<(), Error> {
        let RowLayout { sigma, lead, .. } = layout;
        if let (Inner::Expanding(_) | Inner::Fading(_), 0.0) = (&self.inner, lead) {
            return match sigma {
                false => self.update_many_into(t, y, out),
                true => self.update_many_sigma_into(t, y, out),
            };
        }
        // The batch kernels write every cell; here a cell not written is empty.
        out.fill(f64::NAN);
        let written = self.write_each_row(t, y, out, layout, stride);
        // The automatic filter's rows took only what they write of its estimates
        // (`AutomaticFilter::update_row`): its newest output is made whole for anyone after.
        if let Inner::Automatic(f) = &mut self.inner {
            f.complete_output();
        }
        written
    }

    /// [`write_rows`](Self::write_rows) a row at a time (every kind but the expanding- and
    /// fading-memory filters' batch kernels).
    fn write_each_row(
        &mut self,
        t: &[f64],
        y: &[f64],
        out: &mut [f64],
        layout: RowLayout,
        stride: usize,
    ) -> Result<(), Error> {
        let RowLayout { sigma, lead, .. } = layout;
        let width = (self.degree() + 1) << usize::from(sigma);
        let at = |index: usize| {
            move |e: Error| Error::InBatch {
                index,
                source: Box::new(e),
            }
        };
        for (index, ((&t, &y), row)) in t
            .iter()
            .zip(y)
            .zip(out.chunks_exact_mut(stride))
            .enumerate()
        {
            match &mut self.inner {
                // Without a lead only what the rows write of the estimate.
                Inner::Automatic(f) if lead == 0.0 => {
                    f.update_row(t, y).map_err(at(index))?;
                    self.rows += 1;
                }
                _ => self.update(t, y).map_err(at(index))?,
            }
            let (values, extra) = row.split_at_mut(width);
            let trailing = layout.trailing;
            let estimate = match &mut self.inner {
                Inner::Fixed(f, window) => {
                    if trailing {
                        extra[0] = (f.samples() as usize).min(*window) as f64;
                    }
                    reasoned(f.try_estimate_at(t + lead)).map_err(at(index))?
                }
                Inner::Automatic(f) => {
                    let Some(o) = f.last_output() else { continue };
                    let reported = f.reported();
                    if trailing {
                        let bias0 = match reported {
                            Some(r) => r.bias0(),
                            None => o.bias.as_ref().map_or(f64::NAN, |b| b[0]),
                        };
                        extra[..4].copy_from_slice(&[
                            o.noise_sigma.unwrap_or(f64::NAN),
                            f64::from(u8::from(o.outlier)),
                            f64::from(u8::from(o.misfit)),
                            bias0,
                        ]);
                        store_decisions(&o.decided, &mut extra[4..4 + DECISION_CELLS]);
                        extra[4 + DECISION_CELLS] = o.degree as f64;
                    }
                    // The estimate is at t: the update's own, or across a rejected sample the
                    // prediction; with a lead the active filter's, the same way.
                    if lead == 0.0 {
                        match reported {
                            Some(r) => store_reported(r.derivatives(), r.std_devs(), sigma, values),
                            None => store(o.estimate.as_ref(), sigma, values).map_err(at(index))?,
                        }
                        continue;
                    }
                    f.estimate_at(t + lead)
                }
                _ => reasoned(self.try_estimate_at(t + lead)).map_err(at(index))?,
            };
            store(estimate.as_ref(), sigma, values).map_err(at(index))?;
        }
        Ok(())
    }

    /// The module's rule over the `rows` written (the filter's rows before them `before`): the
    /// first refused row as [`Error::InBatch`].
    fn check_rows(
        &self,
        rows: &[f64],
        stride: usize,
        layout: RowLayout,
        before: u64,
    ) -> Result<(), Error> {
        let w = self.degree() + 1;
        // Once determined, a row's derivatives (and their 1σ) are all numbers, except the
        // automatic filter's.
        let all = w << usize::from(layout.sigma);
        let (needed, cells, checked, withheld) = match &self.inner {
            Inner::Fixed(_, window) => ((*window).max(w), w, all, None),
            // The automatic filter's estimate is withheld while its noise cell is empty; its
            // derivatives above the degree it has reached are empty by design. Without its
            // trailing cells a withheld estimate cannot be told: only infinities are refused.
            Inner::Automatic(_) if layout.trailing => (w, 1, 1, Some(all)),
            Inner::Automatic(_) => (usize::MAX, 1, 1, None),
            _ => (w, w, all, None),
        };
        let rule = RowRule {
            stride,
            needed,
            blank: cells,
            checked,
            withheld,
            why: "the fit is not determined in doubles (with fading memory, a tau far shorter \
                  than the steps, or a gap of many tau, lets the discount theta^(step/tau) \
                  underflow)",
        };
        let name = |k: usize| match k {
            k if k < w => format!("d{k}"),
            k if k < all => format!("s{}", k - w),
            k => (self.trailing_columns().get(k - all))
                .map_or("decisions", |c| c)
                .into(),
        };
        check_rows(rows, &rule, before, name)
    }
}

/// The estimate, `None` before the fit is determined, or, once it is, why there is none (the
/// fit singular in doubles, a number beyond the double range).
fn reasoned(estimate: Result<PolynomialState, Error>) -> Result<Option<PolynomialState>, Error> {
    match estimate {
        Ok(s) => Ok(Some(s)),
        Err(Error::TooFewSamples { .. }) => Ok(None),
        Err(e) => Err(e),
    }
}

/// [`store`] of the automatic filter's reported derivatives `x` and their 1σ `sd`
/// (`AutomaticFilter::update_row`): the same cells.
fn store_reported(x: &[f64], sd: &[f64], sigma: bool, values: &mut [f64]) {
    let width = values.len() >> usize::from(sigma);
    let nd = x.len().min(width);
    values[..nd].copy_from_slice(&x[..nd]);
    if sigma {
        values[width..width + nd].copy_from_slice(&sd[..nd]);
    }
}

/// Copies an estimate into a row's cells: derivatives into `values[..m+1]`, and with `sigma`
/// their 1σ into `values[m+1..]` (an estimate without a covariance is refused then). The
/// estimate may be of a lower degree than the cells.
fn store(estimate: Option<&PolynomialState>, sigma: bool, values: &mut [f64]) -> Result<(), Error> {
    let Some(s) = estimate else { return Ok(()) };
    let width = values.len() >> usize::from(sigma);
    let nd = s.derivatives.len().min(width);
    values[..nd].copy_from_slice(&s.derivatives[..nd]);
    if sigma {
        let c = s.covariance.as_ref().ok_or_else(no_noise_sigma)?;
        for (i, v) in values[width..width + c.nrows().min(width)]
            .iter_mut()
            .enumerate()
        {
            *v = std_dev(c[(i, i)]);
        }
    }
    Ok(())
}
