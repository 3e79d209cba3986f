//! The automatic filter as a [`PolynomialFilter`], for the series bank of `seqsmooth filter`:
//! each update keeps its [`AutoOutput`] (the row's estimate, noise σ and flags). Kept apart so
//! that it goes in one piece once the library's automatic filter is a `PolynomialFilter`.

use seqsmooth::polynomial::automatic::{AutoConfig, AutoOutput, AutomaticFilter};
use seqsmooth::{Error, PolynomialFilter, PolynomialState};

/// The automatic filter and the output of its last update.
#[derive(Clone, Debug)]
pub struct AutoRunner {
    filter: AutomaticFilter,
    /// The output of the last update.
    pub last: Option<AutoOutput>,
}

impl AutoRunner {
    /// The automatic filter of `config`.
    pub fn new(config: AutoConfig) -> Result<Self, Error> {
        Ok(Self {
            filter: AutomaticFilter::new(config)?,
            last: None,
        })
    }
}

impl PolynomialFilter for AutoRunner {
    fn degree(&self) -> usize {
        self.filter.degree()
    }
    fn samples(&self) -> u64 {
        self.filter.samples()
    }
    fn update(&mut self, t: f64, y: f64) -> Result<(), Error> {
        self.last = Some(self.filter.update(t, y)?);
        Ok(())
    }
    fn estimate_at(&self, t: f64) -> Option<PolynomialState> {
        self.filter.estimate_at(t)
    }
    fn last_time(&self) -> Option<f64> {
        self.filter.last_time()
    }
}
