//! Unit tests of `commands::shared`.

mod runner;
