//! The subcommands, one module each (its `run` takes its arguments from [`crate::args`]), and
//! [`shared`], what more than one of them uses. A subcommand imports no other.

pub mod demo;
pub mod filter;
pub mod fit;
pub mod gains;
pub mod paml;
pub mod plot;
pub mod shared;
pub mod smooth;
pub mod track;
pub mod vrf;
