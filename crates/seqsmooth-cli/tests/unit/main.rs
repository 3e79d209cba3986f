//! Unit tests of the `seqsmooth_cli` library, one module per module of `src` (the command's
//! behaviour end to end is in the other test targets).

mod args;
mod commands;
mod error;
mod io;
mod plot;
mod ranges;
