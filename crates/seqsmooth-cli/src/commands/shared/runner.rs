//! The filter of one series of `seqsmooth filter`, of any kind, and the values of its output
//! rows.
//!
//! A row's values are `stride` numbers: `d0..dM`, with `--sigma` (always for the automatic
//! filter) their 1σ `s0..sM` from the covariance, then the kind's trailing cells (fixed memory:
//! the rows in the window; automatic: the noise σ in use, the outlier and misfit flags as
//! 0/1, and the estimated position bias that `s0` includes, empty when `s0..sM` cover the noise
//! only; then [`DECISION_CELLS`] cells not written: the final outlier decisions this row's
//! update made on the series' oldest undecided rows, see [`decisions`]). NaN marks an empty
//! cell: a derivative or 1σ not determined yet.

use crate::args::{name, EngineArg, Kind};
use seqsmooth::polynomial::automatic::AutomaticFilter;
use seqsmooth::{Error, ExpandingMemory, FadingMemory, FixedEngine, FixedMemory, Param};
use seqsmooth::{PolynomialFilter, PolynomialState};

/// A running filter of any kind. Cloning a new one is how each series gets its filter.
#[derive(Clone, Debug)]
pub enum Runner {
    Expanding(Box<ExpandingMemory>),
    Fading(Box<FadingMemory>),
    /// Fixed memory over `window` samples, on any timestamps ([`FixedEngine::Adaptive`]).
    Fixed(Box<FixedMemory>, usize),
    /// The automatic filter (its last update's flags in [`AutomaticFilter::last_output`]).
    Auto(Box<AutomaticFilter>),
}

/// The automatic filter's cells after the written ones: how many final outlier decisions the
/// row's update made (on the series' oldest rows still undecided, in order), and their verdicts
/// as bits (`1`: rejected), 32 to a cell, oldest in the lowest bit.
pub const DECISION_CELLS: usize = 3;

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

/// The decisions stored in `cells` by `store_decisions`.
pub fn decisions(cells: &[f64]) -> Vec<bool> {
    let bits = cells[1] as u64 | ((cells[2] as u64) << 32);
    (0..cells[0] as usize).map(|i| bits >> i & 1 == 1).collect()
}

/// A missing parameter of a filter kind.
fn needs(name: Param, what: &str) -> Error {
    Error::InvalidParameter {
        name,
        value: "(none)".into(),
        reason: format!("{what} needs {name}"),
    }
}

impl Runner {
    /// The filter of `kind` (τ already resolved for fading memory and the automatic filter),
    /// with the noise `sigma` for its covariance (the automatic filter's given noise).
    pub fn build(
        kind: Kind,
        degree: usize,
        theta: Option<f64>,
        tau: f64,
        window: Option<usize>,
        engine: EngineArg,
        sigma: Option<f64>,
    ) -> Result<Self, Error> {
        fn noise<F>(
            f: F,
            sigma: Option<f64>,
            with: fn(F, f64) -> Result<F, Error>,
        ) -> Result<Box<F>, Error> {
            Ok(Box::new(if let Some(s) = sigma { with(f, s)? } else { f }))
        }
        let theta = || theta.ok_or_else(|| needs(Param::Theta, &name(kind)));
        Ok(match kind {
            Kind::Expanding => Runner::Expanding(noise(
                ExpandingMemory::new(degree, engine.into())?,
                sigma,
                ExpandingMemory::with_noise_sigma,
            )?),
            Kind::Fading => Runner::Fading(noise(
                FadingMemory::new(degree, theta()?, tau, engine.into())?,
                sigma,
                FadingMemory::with_noise_sigma,
            )?),
            Kind::Fixed => {
                let window = window.ok_or_else(|| needs(Param::Window, &name(kind)))?;
                let f = FixedMemory::new(degree, window, FixedEngine::Adaptive)?;
                Runner::Fixed(noise(f, sigma, FixedMemory::with_noise_sigma)?, window)
            }
            Kind::Auto => {
                let f = AutomaticFilter::new(degree, theta()?, tau)?.with_engine(engine.into())?;
                Runner::Auto(noise(f, sigma, AutomaticFilter::with_noise_sigma)?)
            }
        })
    }

    /// The columns after `d0..dM` and `s0..sM` this kind writes.
    pub fn extra_columns(&self) -> &'static [&'static str] {
        match self {
            Runner::Expanding(_) | Runner::Fading(_) => &[],
            Runner::Fixed(..) => &["window"],
            Runner::Auto(_) => &["noise", "outlier", "misfit", "bias"],
        }
    }

    fn filter(&self) -> &dyn PolynomialFilter {
        match self {
            Runner::Expanding(f) => f.as_ref(),
            Runner::Fading(f) => f.as_ref(),
            Runner::Fixed(f, _) => f.as_ref(),
            Runner::Auto(f) => f.as_ref(),
        }
    }

    fn filter_mut(&mut self) -> &mut dyn PolynomialFilter {
        match self {
            Runner::Expanding(f) => f.as_mut(),
            Runner::Fading(f) => f.as_mut(),
            Runner::Fixed(f, _) => f.as_mut(),
            Runner::Auto(f) => f.as_mut(),
        }
    }

    /// Runs the samples `(t[i], y[i])` of one series and writes each row's values (the
    /// estimate at `t[i] + lead`, with 1σ when `sigma`) to `out`, `stride` per row. The
    /// expanding- and fading-memory filters without lead take the batch kernels
    /// ([`PolynomialFilter::update_many_into`], with 1σ
    /// [`PolynomialFilter::update_many_sigma_into`]). An error is [`Error::InBatch`] of its row.
    pub fn run(
        &mut self,
        t: &[f64],
        y: &[f64],
        out: &mut [f64],
        lead: f64,
        sigma: bool,
    ) -> Result<(), Error> {
        out.fill(f64::NAN);
        let w = self.degree() + 1;
        if let (Runner::Expanding(_) | Runner::Fading(_), 0.0) = (&*self, lead) {
            // The library's batch paths: the kernels, and with 1σ its batch σ path (rows of
            // d0..dM, s0..sM), the numbers of Python's `update_many`.
            return match sigma {
                false => self.filter_mut().update_many_into(t, y, out),
                true => self.filter_mut().update_many_sigma_into(t, y, out),
            };
        }
        let stride = out.len().checked_div(t.len()).unwrap_or(0);
        for (index, ((&t, &y), row)) in t
            .iter()
            .zip(y)
            .zip(out.chunks_exact_mut(stride))
            .enumerate()
        {
            self.update(t, y).map_err(|e| Error::InBatch {
                index,
                source: Box::new(e),
            })?;
            let extra = &mut row[w << usize::from(sigma)..];
            let estimate = match &mut *self {
                Runner::Fixed(f, window) => {
                    extra[0] = (f.samples() as usize).min(*window) as f64;
                    reasoned(f.try_estimate_at(t + lead), index)?
                }
                Runner::Auto(f) => {
                    let Some(o) = f.last_output() else { continue };
                    extra[..4].copy_from_slice(&[
                        o.noise_sigma.unwrap_or(f64::NAN),
                        f64::from(u8::from(o.outlier)),
                        f64::from(u8::from(o.misfit)),
                        o.bias.as_ref().map_or(f64::NAN, |b| b[0]),
                    ]);
                    // The cells after the written ones: the final decisions made now.
                    if let Some(cells) = extra.get_mut(4..4 + DECISION_CELLS) {
                        store_decisions(&o.decided, cells);
                    }
                    // The output's estimate is at t: the update's own, or across a rejected
                    // sample the prediction; with a lead the active filter's, the same way.
                    if lead == 0.0 {
                        store(
                            o.estimate.as_ref(),
                            sigma,
                            &mut row[..w << usize::from(sigma)],
                        );
                        continue;
                    }
                    f.estimate_at(t + lead)
                }
                other => reasoned(other.try_estimate_at(t + lead), index)?,
            };
            store(
                estimate.as_ref(),
                sigma,
                &mut row[..w << usize::from(sigma)],
            );
        }
        Ok(())
    }
}

/// Copies an estimate into a row's slots: derivatives into `values[..m+1]`, and with `sigma`
/// their 1σ into `values[m+1..]`. The estimate may be of a lower degree than the slots.
/// The estimate of row `index`, `None` before the fit is determined, or, once it is, why there
/// is none (the fit singular in doubles, a number beyond the double range) as the row's error.
fn reasoned(
    estimate: Result<PolynomialState, Error>,
    index: usize,
) -> Result<Option<PolynomialState>, Error> {
    match estimate {
        Ok(s) => Ok(Some(s)),
        Err(Error::TooFewSamples { .. }) => Ok(None),
        Err(e) => Err(Error::InBatch {
            index,
            source: Box::new(e),
        }),
    }
}

fn store(estimate: Option<&PolynomialState>, sigma: bool, values: &mut [f64]) {
    let Some(s) = estimate else { return };
    let width = values.len() >> usize::from(sigma);
    let nd = s.derivatives.len().min(width);
    values[..nd].copy_from_slice(&s.derivatives[..nd]);
    if let (Some(c), true) = (&s.covariance, sigma) {
        for (i, v) in values[width..width + c.nrows().min(width)]
            .iter_mut()
            .enumerate()
        {
            *v = c[(i, i)].max(0.0).sqrt();
        }
    }
}

impl PolynomialFilter for Runner {
    fn degree(&self) -> usize {
        self.filter().degree()
    }
    fn samples(&self) -> u64 {
        self.filter().samples()
    }
    fn update(&mut self, t: f64, y: f64) -> Result<(), Error> {
        self.filter_mut().update(t, y)
    }
    fn estimate_at(&self, t: f64) -> Option<PolynomialState> {
        self.filter().estimate_at(t)
    }
    fn try_estimate_at(&self, t: f64) -> Result<PolynomialState, seqsmooth::Error> {
        self.filter().try_estimate_at(t)
    }
    fn last_time(&self) -> Option<f64> {
        self.filter().last_time()
    }
}
