//! The `seqsmooth` command: polynomial smoothing and prediction filters (Morrison 1969;
//! Reyneke et al. 2012) on CSV and Parquet time series — expanding, fading and fixed memory, the automatic
//! filter, and whole-series (Savitzky–Golay) smoothing; Gauss–Newton fits of radar and polynomial
//! windows; their gains and variance-reduction
//! matrices, and a demo on built-in data. The library behind the binary (`src/main.rs` only dispatches), a thin layer over the `seqsmooth` library: argument
//! parsing ([`args`]), files ([`io`], [`io::parquet`]), one module per subcommand, and messages ([`error`]).

pub mod args;
pub mod chart;
pub mod decimate;
pub mod demo;
pub mod error;
pub mod filter;
pub mod fit;
pub mod gains;
pub mod io;
pub mod paml;
pub mod plot;
pub mod smooth;
pub mod ticks;
pub mod track;
pub mod vrf;
