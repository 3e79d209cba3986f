//! Unit tests of `filter` and its submodules.

mod fixed_runner;
mod median;
mod rows;
