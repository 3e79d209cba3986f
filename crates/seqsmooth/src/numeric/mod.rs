//! Numerical building blocks shared by the engines, banks and fixed-memory filters: one home
//! each for the double-word (error-free) arithmetic ([`double_word`]), the tolerance that
//! decides whether two sampling steps are the same step ([`steps`]), the memo of constants
//! that cost exact arithmetic (`memo`), the dispatch from a
//! run-time state size to code compiled for that size (the crate-internal `unrolled_sizes!`),
//! integer powers inline ([`power`]), a variance read as a reported 1σ ([`sigma`]: NaN kept,
//! a rounding below zero read as 0), and timestamps as seconds since the Unix epoch
//! ([`epoch`]: ticks of any unit, ISO-8601 text; the one rule of every front end).

pub mod double_word;
pub mod epoch;
pub(crate) mod inline;
pub(crate) mod memo;
pub mod power;
pub mod sigma;
pub mod steps;
pub(crate) mod unrolled;
