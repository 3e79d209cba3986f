//! Unit tests of `filter` and its submodules.

mod rows;
mod runner;
