//! Unit tests of `filter` and its submodules.

mod median;
mod rows;
mod runner;
