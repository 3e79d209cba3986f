//! Unit tests of the `seqsmooth_cli` library, one module per module of `src` (the command's
//! behaviour end to end is in the other test targets).

mod args;
mod chart;
mod decimate;
mod demo;
mod error;
mod filter;
mod io;
mod plot;
mod ticks;
