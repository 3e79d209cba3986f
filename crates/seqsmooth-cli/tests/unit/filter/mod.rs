//! Unit tests of `filter` and its submodules.

mod runner;
