//! What more than one subcommand uses, so that no subcommand imports another: the filter of
//! one series' kind in the library's terms ([`filter_kind`]: `filter` and `demo`), the rows of a radar
//! (`radar_rows`: `track` and `fit`), a sliding fit's window errors ([`window`]: `fit` and
//! `track`), and the tables of `gains` and `vrf` ([`table`]).

pub(crate) mod radar_rows;
pub mod table;
pub mod window;

use crate::args::Kind;
use seqsmooth::polynomial::spec::FilterKind;
use seqsmooth::polynomial::tau;

/// Data rows buffered before output starts: the time steps of the `τ` median.
pub const LOOKAHEAD: usize = tau::TAU_STEPS + 1;

/// The library's filter kind of `--kind`.
pub fn filter_kind(kind: Kind) -> FilterKind {
    match kind {
        Kind::Expanding => FilterKind::Expanding,
        Kind::Fading => FilterKind::Fading,
        Kind::Fixed => FilterKind::Fixed,
        Kind::Auto => FilterKind::Automatic,
    }
}
