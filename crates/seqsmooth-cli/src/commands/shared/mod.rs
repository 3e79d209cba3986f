//! What more than one subcommand uses, so that no subcommand imports another: the filter of
//! one series and its output cells ([`runner`]: `filter` and `demo`), the rows of a radar
//! (`radar_rows`: `track` and `fit`), a sliding fit's window errors ([`window`]: `fit` and
//! `track`), and the tables of `gains` and `vrf` ([`table`]).

pub(crate) mod radar_rows;
pub mod runner;
pub mod table;
pub mod window;

use seqsmooth::polynomial::tau;

/// Data rows buffered before output starts: the time steps of the `τ` median.
pub const LOOKAHEAD: usize = tau::TAU_STEPS + 1;
