//! The `seqsmooth` command: polynomial smoothing and prediction filters (Morrison 1969;
//! Reyneke et al. 2012) on CSV and Parquet time series — expanding, fading and fixed memory, the
//! automatic filter, and whole-series (Savitzky–Golay) smoothing; Gauss–Newton fits of radar and
//! polynomial windows; their gains and variance-reduction matrices, and a demo on built-in data.
//! The library behind the binary (`src/main.rs` only dispatches), a thin layer over the
//! `seqsmooth` library: argument parsing ([`args`], a file per subcommand), files ([`io`]: CSV,
//! [`io::parquet`], the outputs), drawing ([`plot`]), one module per subcommand ([`commands`]),
//! and messages ([`error`]).

pub mod args;
pub mod commands;
pub mod error;
pub mod io;
pub mod plot;
